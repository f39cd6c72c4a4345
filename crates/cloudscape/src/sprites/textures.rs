//! The sheet of 16 puff textures (Wang 2003, "Mix and match 16 textures": solid puffs for cumulus,
//! blurry puffs for stratus, in less video memory than a texture per cloud), in a 4 x 4 grid.
//!
//! The puffs are baked at start, not painted: each is the column density of a small volume of
//! cloud, a cluster of Gaussian blobs eroded by 3-D noise as the field's clouds are (Schneider
//! 2015's `remap(density, erosion (1 - noise), 1, 0, 1)`), integrated along the view axis and
//! normalised to 1 at its densest. Gaussian blobs fall smoothly to nothing, so a puff has no
//! circular edge at any optical depth; the noise gives it internal structure and a ragged rim. In
//! Wang's three families:
//!
//! - tiles 0-7, **solid** puffs for cumulus: four to seven blobs, eroded by Worley noise into
//!   billows (cauliflower edges);
//! - tiles 8-11, **blurry** puffs for stratus: two or three broad, flattened blobs, gently
//!   modulated by Perlin noise;
//! - tiles 12-15, **wispy** puffs: blobs stretched 1.8 times sideways and eroded hard by fine
//!   Perlin noise into streaks.
//!
//! The sprite shader turns column density `c` into opacity `1 - exp(-tau c)` with the sprite's own
//! optical depth `tau`.

use glam::{Vec2, Vec3};
use rayon::prelude::*;

use crate::field::noise::{perlin_fbm01, worley_fbm};

/// Tiles along each side of the sheet.
pub const SHEET_TILES: u32 = 4;
/// Texels along each side of one tile.
pub const TILE_TEXELS: u32 = 64;
/// Texels along each side of the sheet.
pub const SHEET_TEXELS: u32 = SHEET_TILES * TILE_TEXELS;

/// Tiles 0-7: solid puffs (cumulus).
pub const SOLID: u16 = 0x00ff;
/// Tiles 8-11: blurry puffs (stratus).
pub const BLURRY: u16 = 0x0f00;
/// Tiles 12-15: wispy, stretched puffs (altostratus).
pub const WISPY: u16 = 0xf000;

/// Integration steps along the view axis per texel.
const STEPS: u32 = 24;
/// Blob centres lie within this distance of the tile's centre (tile half-width 1).
const CLUSTER_RADIUS: f32 = 0.5;
/// A blob's Gaussian standard deviation per unit of its radius: at the tile's border, the
/// farthest blob has fallen below exp(-1/2 (0.6 / 0.2)^2) = 1 % of its peak.
const SIGMA_PER_RADIUS: f32 = 0.4;
/// Radii (tile half-widths) where the window that takes the puff to zero before the border begins
/// and ends (the outermost texel centres lie at 63/64).
const WINDOW: (f32, f32) = (0.55, 0.97);

/// Hermite step from 0 at `lo` to 1 at `hi` (either order).
fn smoothstep(lo: f32, hi: f32, x: f32) -> f32 {
    let t = ((x - lo) / (hi - lo)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// How one puff family is baked.
#[derive(Clone, Copy, Debug)]
struct Family {
    /// Number of blobs, (min, max).
    blobs: (u32, u32),
    /// Blob radius, (min, max), in tile half-widths.
    radius: (f32, f32),
    /// Vertical squash of blob offsets (stratus puffs are flat).
    flatten: f32,
    /// Horizontal stretch of the whole puff.
    stretch: f32,
    /// The noise modulates the blobs by `smoothstep(lo, hi, noise)`: a low `lo` keeps most of
    /// the matter (billows), a high one cuts it into streaks (wisps).
    modulation: (f32, f32),
    /// Noise cells per tile; Worley (billows) or Perlin (wisps).
    cells: i32,
    worley: bool,
}

/// The family of tile `index` (0..16).
fn family(index: u32) -> Family {
    match index {
        0..8 => Family {
            blobs: (4, 7),
            radius: (0.45, 0.65),
            flatten: 0.8,
            stretch: 1.0,
            modulation: (-0.2, 0.9),
            cells: 4,
            worley: true,
        },
        8..12 => Family {
            blobs: (2, 3),
            radius: (0.6, 0.75),
            flatten: 0.4,
            stretch: 1.0,
            modulation: (-0.6, 1.0),
            cells: 3,
            worley: false,
        },
        _ => Family {
            blobs: (3, 5),
            radius: (0.38, 0.48),
            flatten: 0.5,
            stretch: 1.6,
            modulation: (-0.3, 1.0),
            cells: 4,
            worley: false,
        },
    }
}

/// The tile of `mask` (a set of tiles) that `u` in [0, 1) picks, each set tile equally likely.
pub fn texture_in(mask: u16, u: f32) -> u32 {
    let set: Vec<u32> = (0..16).filter(|i| mask & (1 << i) != 0).collect();
    let pick = ((u * set.len() as f32) as usize).min(set.len() - 1);
    set[pick]
}

/// The sheet, baked once per process (about 0.1 s on two cores).
pub fn sheet() -> &'static [u8] {
    static SHEET: std::sync::OnceLock<Vec<u8>> = std::sync::OnceLock::new();
    SHEET.get_or_init(bake_sheet)
}

/// The puffs' mean normalised column density over their tile (the share of a sprite's quad its
/// puff's matter fills): what a sprite's optical depth is scaled by to hold a given mass.
pub fn mean_cover() -> f32 {
    static MEAN: std::sync::OnceLock<f32> = std::sync::OnceLock::new();
    *MEAN.get_or_init(|| {
        let sheet = sheet();
        sheet.iter().map(|&c| f32::from(c)).sum::<f32>() / (255.0 * sheet.len() as f32)
    })
}

/// The whole sheet, row-major, one byte of normalised column density per texel.
fn bake_sheet() -> Vec<u8> {
    let tiles: Vec<Vec<u8>> = (0..SHEET_TILES * SHEET_TILES)
        .into_par_iter()
        .map(|i| Puff::new(i).bake())
        .collect();
    let mut sheet = vec![0u8; (SHEET_TEXELS * SHEET_TEXELS) as usize];
    for (i, tile) in tiles.iter().enumerate() {
        let (tx, ty) = (i as u32 % SHEET_TILES, i as u32 / SHEET_TILES);
        for y in 0..TILE_TEXELS {
            let row = ((ty * TILE_TEXELS + y) * SHEET_TEXELS + tx * TILE_TEXELS) as usize;
            let src = (y * TILE_TEXELS) as usize;
            sheet[row..row + TILE_TEXELS as usize]
                .copy_from_slice(&tile[src..src + TILE_TEXELS as usize]);
        }
    }
    sheet
}

/// The sheet as a picture: each puff at the highest optical depth a sprite gets
/// ([`super::shading::MAX_SPRITE_OPTICAL_DEPTH`]), white over a sky blue, `scale` pixels per
/// texel (for documentation and for judging the puffs by eye).
pub fn puff_sheet_preview(scale: u32) -> crate::image::LdrImage {
    const SKY: [f32; 3] = [70.0, 120.0, 190.0];
    let sheet = sheet();
    let tau = super::shading::MAX_SPRITE_OPTICAL_DEPTH;
    let side = SHEET_TEXELS * scale.max(1);
    let pixels = (0..side * side)
        .map(|i| {
            let (x, y) = ((i % side) / scale.max(1), (i / side) / scale.max(1));
            let c = f32::from(sheet[(y * SHEET_TEXELS + x) as usize]) / 255.0;
            let alpha = 1.0 - (-tau * c).exp();
            let [r, g, b] = SKY.map(|s| (s + (255.0 - s) * alpha).round() as u8);
            [r, g, b, 255]
        })
        .collect();
    crate::image::LdrImage {
        width: side,
        height: side,
        pixels,
    }
}

/// One puff: its family, its blobs (centre, standard deviation) and its noise seed.
struct Puff {
    family: Family,
    blobs: Vec<(Vec3, f32)>,
    seed: u32,
}

impl Puff {
    /// Puff `index` of the sheet: blobs drawn from a PCG hash of the index.
    fn new(index: u32) -> Puff {
        let family = family(index);
        let seed = 101 + index * 7919;
        let u = |k: u32, lane: u32| super::model::unit_random(seed, k, lane);
        let (lo, hi) = family.blobs;
        let count = lo + ((hi - lo + 1) as f32 * u(0, 0)) as u32;
        let blobs = (1..=count)
            .map(|k| {
                // A point in the unit ball (by rejection-free spherical coordinates), squashed.
                let (r, z, a) = (
                    u(k, 0).cbrt(),
                    2.0 * u(k, 1) - 1.0,
                    std::f32::consts::TAU * u(k, 2),
                );
                let s = (1.0 - z * z).sqrt();
                let offset = Vec3::new(s * a.cos(), z * family.flatten, s * a.sin()) * r;
                let radius = family.radius.0 + (family.radius.1 - family.radius.0) * u(k, 3);
                // The first blob sits at the centre, so every puff is densest near it.
                let centre = if k == 1 {
                    Vec3::ZERO
                } else {
                    offset * CLUSTER_RADIUS
                };
                (centre, radius * SIGMA_PER_RADIUS)
            })
            .collect();
        Puff {
            family,
            blobs,
            seed,
        }
    }

    /// The tile: column density normalised to 1 at its densest, one byte per texel.
    fn bake(&self) -> Vec<u8> {
        let n = TILE_TEXELS;
        let columns: Vec<f32> = (0..n * n)
            .map(|i| {
                let t = (Vec2::new((i % n) as f32, (i / n) as f32) + 0.5) / n as f32;
                self.column(t * 2.0 - 1.0)
            })
            .collect();
        let peak = columns.iter().copied().fold(1e-6f32, f32::max);
        columns
            .iter()
            .map(|c| (c / peak * 255.0).round() as u8)
            .collect()
    }

    /// Density at `p` in tile space (the tile spans [-1, 1] across, x stretched): the blobs,
    /// modulated by the family's noise, and a window that takes the last of the Gaussians' tails
    /// smoothly to zero before the tile's border.
    fn density(&self, p: Vec3) -> f32 {
        let q = Vec3::new(p.x / self.family.stretch, p.y, p.z);
        let blobs: f32 = self
            .blobs
            .iter()
            .map(|&(c, sigma)| (-(q - c).length_squared() / (2.0 * sigma * sigma)).exp())
            .sum();
        let uvw = q * 0.5 + 0.5;
        let noise = match self.family.worley {
            true => worley_fbm(uvw, self.family.cells, self.seed),
            false => perlin_fbm01(uvw, self.family.cells, self.seed),
        };
        let (lo, hi) = self.family.modulation;
        let modulation = smoothstep(lo, hi, noise);
        let window = smoothstep(WINDOW.1, WINDOW.0, Vec2::new(p.x, p.y).length());
        blobs.min(1.0) * modulation * window
    }

    /// Density integrated along z through `xy` (midpoint rule over the tile's depth).
    fn column(&self, xy: Vec2) -> f32 {
        let dz = 2.0 / STEPS as f32;
        (0..STEPS)
            .map(|k| self.density(xy.extend(-1.0 + (k as f32 + 0.5) * dz)) * dz)
            .sum()
    }
}

/// Opacity of `tile` (normalised column densities, row-major) at optical depth `tau` where it is
/// densest, bilinearly sampled at `uv` in [0, 1]^2 as the GPU samples it.
#[cfg(test)]
fn opacity_at(tile: &[f32], tau: f32, uv: Vec2) -> f32 {
    let n = TILE_TEXELS as i32;
    let p = uv * n as f32 - 0.5;
    let (i, f) = (p.floor().as_ivec2(), p - p.floor());
    let at = |x: i32, y: i32| tile[(y.clamp(0, n - 1) * n + x.clamp(0, n - 1)) as usize];
    let top = at(i.x, i.y) * (1.0 - f.x) + at(i.x + 1, i.y) * f.x;
    let bottom = at(i.x, i.y + 1) * (1.0 - f.x) + at(i.x + 1, i.y + 1) * f.x;
    1.0 - (-tau * (top * (1.0 - f.y) + bottom * f.y)).exp()
}

/// The sharpest rise of opacity per 1/64 of the tile's width across a puff's rim, at optical depth
/// `tau`: along 64 rays from the tile's centre, walked in from the border until the opacity first
/// reaches 1/2, the largest step between samples 1/64 of the width apart.
#[cfg(test)]
fn sharpest_rim_step(tile: &[f32], tau: f32) -> f32 {
    const RAYS: u32 = 64;
    const SAMPLES: u32 = 32;
    let mut sharpest = 0.0f32;
    for r in 0..RAYS {
        let a = std::f32::consts::TAU * r as f32 / RAYS as f32;
        let dir = Vec2::new(a.cos(), a.sin());
        let at = |k: u32| {
            opacity_at(
                tile,
                tau,
                Vec2::splat(0.5) + dir * (0.5 * k as f32 / SAMPLES as f32),
            )
        };
        let mut outer = at(SAMPLES);
        for k in (0..SAMPLES).rev() {
            let inner = at(k);
            sharpest = sharpest.max(inner - outer);
            if inner >= 0.5 {
                break;
            }
            outer = inner;
        }
    }
    sharpest
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tile_of(sheet: &[u8], index: u32) -> Vec<f32> {
        let (tx, ty) = (index % SHEET_TILES, index / SHEET_TILES);
        (0..TILE_TEXELS * TILE_TEXELS)
            .map(|i| {
                let (x, y) = (
                    tx * TILE_TEXELS + i % TILE_TEXELS,
                    ty * TILE_TEXELS + i / TILE_TEXELS,
                );
                sheet[(y * SHEET_TEXELS + x) as usize] as f32 / 255.0
            })
            .collect()
    }

    #[test]
    fn sixteen_distinct_puffs_transparent_at_their_borders_solid_ones_denser_than_blurry() {
        let sheet = bake_sheet();
        let tiles: Vec<Vec<f32>> = (0..16).map(|i| tile_of(&sheet, i)).collect();
        let n = TILE_TEXELS as usize;
        for (i, t) in tiles.iter().enumerate() {
            let border =
                (0..n).flat_map(|k| [t[k], t[(n - 1) * n + k], t[k * n], t[k * n + n - 1]]);
            assert!(border.fold(0.0f32, f32::max) == 0.0, "tile {i} bleeds");
            let centre = t[n / 2 * n + n / 2].max(t[(n / 2 - 1) * n + n / 2 - 1]);
            assert!(
                centre > 0.3,
                "tile {i} is nearly empty at its centre: {centre}"
            );
            for (j, u) in tiles.iter().enumerate().skip(i + 1) {
                assert_ne!(t, u, "tiles {i} and {j}");
            }
        }
        // Solid puffs hold their density over more of their area than wispy ones.
        let dense = |t: &Vec<f32>| t.iter().filter(|&&a| a > 0.5).count();
        let solid = (0..8).map(|i| dense(&tiles[i])).sum::<usize>() / 8;
        let wispy = (12..16).map(|i| dense(&tiles[i])).sum::<usize>() / 4;
        assert!(solid > wispy, "{solid} {wispy}");
    }

    /// A puff's rim is soft at the highest optical depth a sprite gets: opacity never rises by more
    /// than 0.16 over 1/64 of the tile's width, so a rim takes a tenth of the puff to rise (the
    /// puffs of the old sheet, the column density of
    /// a sphere, rise by more than 0.3 at their rim).
    #[test]
    fn puffs_have_soft_rims_at_the_highest_optical_depth() {
        let sheet = bake_sheet();
        let tau = super::super::shading::MAX_SPRITE_OPTICAL_DEPTH;
        for i in 0..16 {
            let step = sharpest_rim_step(&tile_of(&sheet, i), tau);
            assert!(step < 0.16, "tile {i}: opacity rises by {step} at its rim");
        }
        // The measure bites: the column density of a sphere has a hard rim.
        let n = TILE_TEXELS as f32;
        let sphere: Vec<f32> = (0..TILE_TEXELS * TILE_TEXELS)
            .map(|i| {
                let p = (Vec2::new((i % TILE_TEXELS) as f32, (i / TILE_TEXELS) as f32) + 0.5) / n;
                (1.0 - ((p * 2.0 - 1.0) * 1.08).length_squared())
                    .max(0.0)
                    .sqrt()
            })
            .collect();
        let disc = sharpest_rim_step(&sphere, tau);
        assert!(disc > 0.3, "{disc}");
    }

    #[test]
    fn texture_picks_stay_in_their_set() {
        for u in [0.0, 0.3, 0.999] {
            assert!(BLURRY & (1 << texture_in(BLURRY, u)) != 0);
        }
        assert_eq!(texture_in(SOLID, 0.0), 0);
        assert_eq!(texture_in(SOLID, 0.999), 7);
    }
}
