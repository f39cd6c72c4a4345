//! Tileable 3D noise, the CPU specification of the noise textures.
//!
//! Three textures shape every cloud (Schneider 2015, "The Real-time Volumetric Cloudscapes of Horizon
//! Zero Dawn"): a 128^3 RGBA base (R Perlin-Worley, G/B/A Worley fBm at rising frequencies), a 32^3
//! RGB Worley detail texture that erodes edges, and a 128^2 curl-noise texture that swirls the
//! detail. The GPU generates the same texels from `noise.wgsl`; both use only integer hashing and
//! plain float arithmetic so they agree to the last 8-bit step.

use super::texture::Texture8;
use glam::{IVec3, UVec3, Vec3, Vec4};
use rayon::prelude::*;

/// Which of the three noise textures.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NoiseKind {
    /// 128^3 RGBA: R Perlin-Worley, G/B/A Worley fBm with 4, 8 and 16 cells per tile.
    Base,
    /// 32^3 RGB: Worley fBm with 2, 4 and 8 cells per tile.
    Detail,
    /// 128^2 RG: the divergence-free curl of a 2D Perlin potential, encoded 0..1.
    Curl,
}

impl NoiseKind {
    /// Texels along each side.
    pub fn size(self) -> u32 {
        match self {
            NoiseKind::Base | NoiseKind::Curl => 128,
            NoiseKind::Detail => 32,
        }
    }

    /// Texture depth: the curl texture is 2D.
    pub fn depth(self) -> u32 {
        match self {
            NoiseKind::Curl => 1,
            _ => self.size(),
        }
    }

    /// Name of its texture: its label, and its key among a device's shared textures.
    pub fn texture_name(self) -> &'static str {
        match self {
            NoiseKind::Base => "base noise",
            NoiseKind::Detail => "detail noise",
            NoiseKind::Curl => "curl noise",
        }
    }

    /// Index of this kind in the GPU generator's `kind` switch (see `noise.wgsl`).
    pub fn gpu_index(self) -> u32 {
        self as u32
    }

    /// The 8-bit RGBA texel at integer coordinates (wrapped into the tile).
    pub fn texel(self, seed: u32, texel: IVec3) -> [u8; 4] {
        let n = self.size() as i32;
        let t = IVec3::new(
            texel.x.rem_euclid(n),
            texel.y.rem_euclid(n),
            texel.z.rem_euclid(n),
        );
        let value = match self {
            NoiseKind::Base => base_texel(seed, t),
            NoiseKind::Detail => detail_texel(seed, t),
            NoiseKind::Curl => curl_texel(seed, t),
        };
        value.to_array().map(quantize_unorm8)
    }
}

/// Rounds a 0..1 value to 8-bit unorm as `floor(255 x + 0.5)`, the same rule as `noise.wgsl`.
pub fn quantize_unorm8(x: f32) -> u8 {
    (x.clamp(0.0, 1.0) * 255.0 + 0.5).floor() as u8
}

/// PCG hash (O'Neill 2014) as recommended for GPUs by Jarzynski & Olano 2020, "Hash Functions for
/// GPU Rendering" (JCGT 9(3)): a 32-bit input to a well-mixed 32-bit output.
pub fn pcg_hash(x: u32) -> u32 {
    let state = x.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
    let word = ((state >> ((state >> 28) + 4)) ^ state).wrapping_mul(277_803_737);
    (word >> 22) ^ word
}

/// Hash of an integer lattice point and a seed.
pub fn hash_cell(cell: IVec3, seed: u32) -> u32 {
    let h = pcg_hash(seed ^ pcg_hash(cell.z as u32));
    pcg_hash((cell.x as u32) ^ pcg_hash((cell.y as u32) ^ h))
}

/// The top 24 bits of a hash as a float in [0, 1), exact in f32.
pub fn hash_to_unit(h: u32) -> f32 {
    (h >> 8) as f32 * (1.0 / 16_777_216.0)
}

fn wrap(cell: IVec3, period: i32) -> IVec3 {
    IVec3::new(
        cell.x.rem_euclid(period),
        cell.y.rem_euclid(period),
        cell.z.rem_euclid(period),
    )
}

/// Quintic fade 6t^5 - 15t^4 + 10t^3 (Perlin 2002, "Improving Noise").
fn fade(t: Vec3) -> Vec3 {
    t * t * t * (t * (t * 6.0 - 15.0) + 10.0)
}

/// One of the 12 cube-edge gradients of Perlin 2002, chosen by hash.
fn gradient(h: u32) -> Vec3 {
    const G: [[f32; 3]; 12] = [
        [1.0, 1.0, 0.0],
        [-1.0, 1.0, 0.0],
        [1.0, -1.0, 0.0],
        [-1.0, -1.0, 0.0],
        [1.0, 0.0, 1.0],
        [-1.0, 0.0, 1.0],
        [1.0, 0.0, -1.0],
        [-1.0, 0.0, -1.0],
        [0.0, 1.0, 1.0],
        [0.0, -1.0, 1.0],
        [0.0, 1.0, -1.0],
        [0.0, -1.0, -1.0],
    ];
    Vec3::from_array(G[(h % 12) as usize])
}

/// Periodic Perlin gradient noise (Perlin 2002) at `p` in lattice units, period `period` cells;
/// roughly in [-1, 1].
pub fn perlin(p: Vec3, period: i32, seed: u32) -> f32 {
    let cell = p.floor();
    let f = p - cell;
    let c = cell.as_ivec3();
    let u = fade(f);
    let corner = |dx: i32, dy: i32, dz: i32| {
        let o = IVec3::new(dx, dy, dz);
        gradient(hash_cell(wrap(c + o, period), seed)).dot(f - o.as_vec3())
    };
    let x00 = lerp(corner(0, 0, 0), corner(1, 0, 0), u.x);
    let x10 = lerp(corner(0, 1, 0), corner(1, 1, 0), u.x);
    let x01 = lerp(corner(0, 0, 1), corner(1, 0, 1), u.x);
    let x11 = lerp(corner(0, 1, 1), corner(1, 1, 1), u.x);
    lerp(lerp(x00, x10, u.y), lerp(x01, x11, u.y), u.z)
}

/// Periodic Worley cellular noise (Worley 1996) at `p` in cell units: one feature point per cell,
/// returns `1 - min(1, F1)` so it is 1 at feature points and falls off between them.
pub fn worley(p: Vec3, period: i32, seed: u32) -> f32 {
    let cell = p.floor();
    let c = cell.as_ivec3();
    let mut nearest_sq = 1.0e9_f32;
    for dz in -1..=1 {
        for dy in -1..=1 {
            for dx in -1..=1 {
                let o = IVec3::new(dx, dy, dz);
                let h = hash_cell(wrap(c + o, period), seed);
                let feature = Vec3::new(
                    hash_to_unit(h),
                    hash_to_unit(pcg_hash(h)),
                    hash_to_unit(pcg_hash(h ^ 0x9e37_79b9)),
                );
                let d = cell + o.as_vec3() + feature - p;
                nearest_sq = nearest_sq.min(d.dot(d));
            }
        }
    }
    1.0 - nearest_sq.sqrt().min(1.0)
}

/// Three Worley octaves at `cells`, `2 cells`, `4 cells` per tile, weighted 0.625 / 0.25 / 0.125
/// (Schneider 2015). `uvw` is in tile units [0, 1).
pub fn worley_fbm(uvw: Vec3, cells: i32, seed: u32) -> f32 {
    0.625 * worley(uvw * cells as f32, cells, seed)
        + 0.25 * worley(uvw * (2 * cells) as f32, 2 * cells, seed ^ 0x51)
        + 0.125 * worley(uvw * (4 * cells) as f32, 4 * cells, seed ^ 0xa3)
}

/// Three Perlin octaves at `cells`, `2 cells`, `4 cells` per tile, amplitudes 1, 1/2, 1/4, mapped
/// to 0..1 by the soft saturation `0.5 + 0.5 tanh(2 PERLIN_CONTRAST sum)` (slope PERLIN_CONTRAST
/// at 0). Perlin noise has a standard deviation of only about 0.2, so the contrast spreads the fBm
/// over the whole range, where coverage can carve it. A hard clamp would leave plateaus at exactly
/// 1, which `remap(shape, 1 - c, 1, 0, 1)` fills completely at any coverage c above 0: hard-edged
/// boxes of full density where the weather map fades out.
pub fn perlin_fbm01(uvw: Vec3, cells: i32, seed: u32) -> f32 {
    let sum = perlin(uvw * cells as f32, cells, seed)
        + 0.5 * perlin(uvw * (2 * cells) as f32, 2 * cells, seed ^ 0x51)
        + 0.25 * perlin(uvw * (4 * cells) as f32, 4 * cells, seed ^ 0xa3);
    0.5 + 0.5 * (2.0 * PERLIN_CONTRAST * sum).tanh()
}

/// Gain from the Perlin fBm sum to its 0..1 encoding at the middle of the range.
pub const PERLIN_CONTRAST: f32 = 1.2;

/// Gain from the curl potential's central differences to the encoded velocity.
const CURL_GAIN: f32 = 2.0;

/// `value` mapped from [lo0, hi0] to [lo1, hi1] (Schneider 2015's `Remap`).
pub fn remap(value: f32, lo0: f32, hi0: f32, lo1: f32, hi1: f32) -> f32 {
    lo1 + (value - lo0) * (hi1 - lo1) / (hi0 - lo0)
}

/// Linear interpolation.
pub fn lerp(a: f32, b: f32, t: f32) -> f32 {
    a + (b - a) * t
}

fn texel_centre(texel: IVec3, size: u32) -> Vec3 {
    (texel.as_vec3() + 0.5) / size as f32
}

/// Base texel: R Perlin-Worley (Perlin fBm remapped by an inverted Worley fBm, Schneider 2015),
/// G/B/A Worley fBm at 4, 8 and 16 cells per tile.
fn base_texel(seed: u32, texel: IVec3) -> Vec4 {
    let uvw = texel_centre(texel, NoiseKind::Base.size());
    let g = worley_fbm(uvw, 4, seed ^ 0x1000);
    let b = worley_fbm(uvw, 8, seed ^ 0x2000);
    let a = worley_fbm(uvw, 16, seed ^ 0x3000);
    let p = perlin_fbm01(uvw, 4, seed ^ 0x4000);
    let perlin_worley = remap(p, g - 1.0, 1.0, 0.0, 1.0);
    Vec4::new(perlin_worley, g, b, a)
}

/// Detail texel: Worley fBm at 2, 4 and 8 cells per tile.
fn detail_texel(seed: u32, texel: IVec3) -> Vec4 {
    let uvw = texel_centre(texel, NoiseKind::Detail.size());
    let r = worley_fbm(uvw, 2, seed ^ 0x5000);
    let g = worley_fbm(uvw, 4, seed ^ 0x6000);
    let b = worley_fbm(uvw, 8, seed ^ 0x7000);
    Vec4::new(r, g, b, 1.0)
}

/// Curl texel: the curl (d psi/dy, -d psi/dx) of a periodic 2D Perlin fBm potential psi, by central
/// differences one texel apart, scaled and encoded as 0.5 + 0.5 v (Bridson et al. 2007, "Curl-Noise
/// for Procedural Fluid Flow").
fn curl_texel(seed: u32, texel: IVec3) -> Vec4 {
    let n = NoiseKind::Curl.size();
    let psi = |dx: i32, dy: i32| {
        let uv = texel_centre(texel + IVec3::new(dx, dy, 0), n);
        perlin_fbm01(Vec3::new(uv.x, uv.y, 0.0), 4, seed ^ 0x8000)
    };
    let scale = CURL_GAIN;
    let vx = (psi(0, 1) - psi(0, -1)) * scale;
    let vy = -(psi(1, 0) - psi(-1, 0)) * scale;
    Vec4::new(0.5 + 0.5 * vx, 0.5 + 0.5 * vy, 0.5, 1.0)
}

impl NoiseKind {
    /// Texture dimensions (width, height, depth).
    pub fn dims(self) -> UVec3 {
        UVec3::new(self.size(), self.size(), self.depth())
    }

    /// Computes every texel on all cores. The base texture takes seconds in a release build; the
    /// GPU makes its own copy in milliseconds, so only CPU renderers need this.
    pub fn bake(self, seed: u32) -> Texture8 {
        let dims = self.dims();
        let (w, h) = (dims.x as i32, dims.y as i32);
        let texels = (0..dims.element_product() as i32)
            .into_par_iter()
            .map(|i| self.texel(seed, IVec3::new(i % w, (i / w) % h, i / (w * h))))
            .collect();
        Texture8 { dims, texels }
    }
}

/// The hash and value noise the field and the particles share (`noise.wgsl`).
pub static NOISE_WGSL: crate::shader::WgslModule =
    crate::shader::wgsl_module!("noise", "noise.wgsl", []);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn noise_tiles_seamlessly() {
        for kind in [NoiseKind::Base, NoiseKind::Detail, NoiseKind::Curl] {
            let n = kind.size() as i32;
            for t in [IVec3::new(0, 3, 0), IVec3::new(5, 0, 0)] {
                let t = if kind == NoiseKind::Curl {
                    t.with_z(0)
                } else {
                    t
                };
                assert_eq!(
                    kind.texel(7, t),
                    kind.texel(7, t + IVec3::new(n, -n, 0)),
                    "{kind:?}"
                );
            }
        }
        // Worley and Perlin are continuous across the tile seam.
        let eps = 1e-4;
        let (a, b) = (Vec3::new(1.0 - eps, 0.3, 0.6), Vec3::new(eps, 0.3, 0.6));
        assert!((worley_fbm(a, 4, 1) - worley_fbm(b, 4, 1)).abs() < 1e-2);
        assert!((perlin_fbm01(a, 4, 1) - perlin_fbm01(b, 4, 1)).abs() < 1e-2);
    }

    #[test]
    fn perlin_is_zero_on_lattice_and_zero_mean() {
        assert_eq!(perlin(Vec3::new(3.0, 1.0, 2.0), 8, 9), 0.0);
        let mut sum = 0.0;
        let mut sum_sq = 0.0;
        let n = 4000;
        for i in 0..n {
            let p = Vec3::new(
                hash_to_unit(pcg_hash(i)),
                hash_to_unit(pcg_hash(i + 77_777)),
                0.37,
            ) * 8.0;
            let v = perlin(p, 8, 5);
            assert!((-1.2..=1.2).contains(&v));
            sum += v;
            sum_sq += v * v;
        }
        let mean = sum / n as f32;
        let std = (sum_sq / n as f32 - mean * mean).sqrt();
        assert!(mean.abs() < 0.03, "mean {mean}");
        assert!((0.1..0.5).contains(&std), "std {std}");
    }

    /// Plateaus at exactly 1 in the Perlin-Worley channel become boxes of full density wherever
    /// the coverage is above 0 (see [`perlin_fbm01`]): the channel must almost never saturate,
    /// while still spanning most of its range.
    #[test]
    fn perlin_worley_spans_the_range_without_saturating() {
        let n = 20_000;
        let (mut saturated, mut hi) = (0, 0_u8);
        for i in 0..n {
            let texel = IVec3::new(
                (pcg_hash(i) % 128) as i32,
                (pcg_hash(i + 50_000) % 128) as i32,
                (pcg_hash(i + 90_000) % 128) as i32,
            );
            let perlin_worley = NoiseKind::Base.texel(3, texel)[0];
            saturated += u32::from(perlin_worley == 255);
            hi = hi.max(perlin_worley);
        }
        assert!(saturated * 1000 < n, "{saturated} of {n} texels at 1");
        assert!(hi > 240, "the channel only reaches {hi}");
    }

    #[test]
    fn worley_peaks_at_features_and_spans_range() {
        let (mut lo, mut hi) = (1.0_f32, 0.0_f32);
        for i in 0..3000 {
            let p = Vec3::new(
                hash_to_unit(pcg_hash(i)),
                hash_to_unit(pcg_hash(i + 10_000)),
                hash_to_unit(pcg_hash(i + 20_000)),
            );
            let v = worley(p * 4.0, 4, 2);
            lo = lo.min(v);
            hi = hi.max(v);
        }
        assert!(hi > 0.9 && lo < 0.35, "range {lo}..{hi}");
    }

    #[test]
    fn curl_field_is_divergence_free() {
        // Central-difference divergence of the decoded curl texture is small against its magnitude.
        let decode = |x: i32, y: i32| {
            let t = NoiseKind::Curl.texel(4, IVec3::new(x, y, 0));
            (
                t[0] as f32 / 255.0 * 2.0 - 1.0,
                t[1] as f32 / 255.0 * 2.0 - 1.0,
            )
        };
        let (mut div, mut mag) = (0.0, 0.0);
        for y in 0..32 {
            for x in 0..32 {
                let d = (decode(x + 1, y).0 - decode(x - 1, y).0)
                    + (decode(x, y + 1).1 - decode(x, y - 1).1);
                let g = (decode(x + 1, y).0 - decode(x - 1, y).0).abs()
                    + (decode(x, y + 1).0 - decode(x, y - 1).0).abs();
                div += d.abs();
                mag += g;
            }
        }
        assert!(div < 0.35 * mag, "divergence {div} vs gradient {mag}");
    }

    #[test]
    fn sampler_hits_texel_centres_and_interpolates() {
        let tex = NoiseKind::Detail.bake(3);
        let n = 32.0;
        let t0 = crate::field::texture::unorm8(NoiseKind::Detail.texel(3, IVec3::new(4, 5, 6)));
        let t1 = crate::field::texture::unorm8(NoiseKind::Detail.texel(3, IVec3::new(5, 5, 6)));
        let centre = |x: f32| Vec3::new(x, 5.5, 6.5) / n;
        assert!((tex.sample(centre(4.5)) - t0).abs().max_element() < 1e-6);
        assert!(
            (tex.sample(centre(5.0)) - (t0 + t1) * 0.5)
                .abs()
                .max_element()
                < 1e-6
        );
        // Repeat addressing: one tile over is the same sample.
        assert!((tex.sample(centre(4.5) + Vec3::X) - t0).abs().max_element() < 1e-5);
    }
}
