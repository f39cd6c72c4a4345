//! The ray offsets' dither: a tile of blue noise made by the void-and-cluster method (Ulichney
//! 1993, "The void-and-cluster method for dither array generation", Proc. SPIE 1913), each pixel
//! the rank at which the method placed it, over the tile's pixels.
//!
//! Blue noise has almost no energy at low spatial frequencies and none concentrated in a peak:
//! neighbouring pixels' offsets cover the unit interval evenly, as the R2 dither that it replaces
//! did (Roberts 2018), but without the R2 dither's lattice, a few strong spectral peaks that
//! printed a regular weave over every cloud (and, at a 4x4 temporal grid, a weave four times as
//! coarse). Over frames each pixel's offset advances by the golden ratio (the R1 sequence:
//! `march_ray_offset`), so each frame is a shifted copy of the tile and each pixel's offsets
//! stratify the interval in time.

use crate::gpu::GpuContext;
use std::sync::OnceLock;
use wgpu::util::DeviceExt;

/// Pixels along each side of the tile; the tile repeats over the image.
pub const BLUE_NOISE_SIZE: u32 = 64;

/// Standard deviation of the method's Gaussian energy filter, pixels: Ulichney's 1.5 finds the
/// voids and clusters of a pattern a few pixels apart.
const FILTER_SIGMA_PX: f32 = 1.5;

/// The share of the tile's pixels in the initial binary pattern (Ulichney: under half; a tenth).
const INITIAL_SHARE: f32 = 0.1;

/// The tile, row by row: each pixel's value in `(0, 1)`, `(rank + 1/2) / pixels`, every value once.
pub fn blue_noise_tile() -> &'static [f32] {
    static TILE: OnceLock<Vec<f32>> = OnceLock::new();
    TILE.get_or_init(|| {
        let ranks = ranks(BLUE_NOISE_SIZE as usize);
        let pixels = ranks.len() as f32;
        ranks.iter().map(|&r| (r as f32 + 0.5) / pixels).collect()
    })
}

/// The tile as a texture (`march_blue_noise` in `raymarch.wgsl`), one 32-bit float a texel.
pub fn blue_noise_texture(ctx: &GpuContext) -> wgpu::TextureView {
    let texture = ctx.device.create_texture_with_data(
        &ctx.queue,
        &wgpu::TextureDescriptor {
            label: Some("raymarch blue noise"),
            size: wgpu::Extent3d {
                width: BLUE_NOISE_SIZE,
                height: BLUE_NOISE_SIZE,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::R32Float,
            usage: wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        },
        wgpu::util::TextureDataOrder::LayerMajor,
        bytemuck::cast_slice(blue_noise_tile()),
    );
    texture.create_view(&wgpu::TextureViewDescriptor::default())
}

/// The void-and-cluster ranks of a `size` x `size` tile, row by row.
fn ranks(size: usize) -> Vec<u32> {
    let kernel = toroidal_gaussian(size);
    let mut initial = Pattern::new(size, &kernel);
    for i in 0..((size * size) as f32 * INITIAL_SHARE) as usize {
        let mut p = scatter(i as u32, size * size);
        while initial.ones[p] {
            p = (p + 1) % (size * size);
        }
        initial.set(p, true);
    }
    initial.relax();
    let placed = initial.ones.iter().filter(|&&o| o).count();
    let mut ranks = vec![0; size * size];
    // Phase 1: the initial pattern's points, ranked from the last down, tightest cluster first.
    let mut thinned = initial.clone();
    for rank in (0..placed).rev() {
        let p = thinned.tightest_cluster();
        thinned.set(p, false);
        ranks[p] = rank as u32;
    }
    // Phases 2 and 3: the rest, largest void first (for the minority zeros of phase 3 their
    // tightest cluster is the ones' largest void: the energies of the two sum to a constant).
    for rank in placed..size * size {
        let p = initial.largest_void();
        initial.set(p, true);
        ranks[p] = rank as u32;
    }
    ranks
}

/// A binary pattern on the torus and the filtered energy of its ones at every pixel.
#[derive(Clone)]
struct Pattern<'a> {
    size: usize,
    kernel: &'a [f32],
    ones: Vec<bool>,
    energy: Vec<f32>,
}

impl<'a> Pattern<'a> {
    fn new(size: usize, kernel: &'a [f32]) -> Pattern<'a> {
        Pattern {
            size,
            kernel,
            ones: vec![false; size * size],
            energy: vec![0.0; size * size],
        }
    }

    /// Sets pixel `p` to `one`, updating every pixel's energy.
    fn set(&mut self, p: usize, one: bool) {
        self.ones[p] = one;
        let sign = if one { 1.0 } else { -1.0 };
        let (n, (px, py)) = (self.size, (p % self.size, p / self.size));
        for (q, e) in self.energy.iter_mut().enumerate() {
            let (dx, dy) = ((q % n + n - px) % n, (q / n + n - py) % n);
            *e += sign * self.kernel[dy * n + dx];
        }
    }

    /// The one with the most energy: the centre of the tightest cluster.
    fn tightest_cluster(&self) -> usize {
        self.extreme(true, |a, b| a > b)
    }

    /// The zero with the least energy: the centre of the largest void.
    fn largest_void(&self) -> usize {
        self.extreme(false, |a, b| a < b)
    }

    fn extreme(&self, among: bool, better: fn(f32, f32) -> bool) -> usize {
        let mut best = None;
        for (p, (&one, &e)) in self.ones.iter().zip(&self.energy).enumerate() {
            if one == among && best.is_none_or(|(_, b)| better(e, b)) {
                best = Some((p, e));
            }
        }
        best.expect("the pattern has a pixel of each kind").0
    }

    /// Moves the tightest cluster's point to the largest void until that would put it back where
    /// it was: the initial pattern's points spread evenly (within as many moves as it has pixels,
    /// should two states alternate).
    fn relax(&mut self) {
        for _ in 0..self.ones.len() {
            let cluster = self.tightest_cluster();
            self.set(cluster, false);
            let void = self.largest_void();
            self.set(void, true);
            if void == cluster {
                return;
            }
        }
    }
}

/// `exp(-r^2 / 2 sigma^2)` at every offset of a `size` x `size` torus, row by row.
fn toroidal_gaussian(size: usize) -> Vec<f32> {
    let wrap = |d: usize| d.min(size - d) as f32;
    (0..size * size)
        .map(|i| {
            let r2 = wrap(i % size).powi(2) + wrap(i / size).powi(2);
            (-r2 / (2.0 * FILTER_SIGMA_PX * FILTER_SIGMA_PX)).exp()
        })
        .collect()
}

/// A pixel of `pixels` for the initial pattern's `i`-th point, scattered by a hash (the PCG
/// output permutation, O'Neill 2014): a fixed pattern, the same in every build.
fn scatter(i: u32, pixels: usize) -> usize {
    let state = i.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
    let word = ((state >> ((state >> 28) + 4)) ^ state).wrapping_mul(277_803_737);
    ((word >> 22) ^ word) as usize % pixels
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Power spectrum of a `size` x `size` tile with its mean removed (a separable DFT).
    fn power_spectrum(tile: &[f32], size: usize) -> Vec<f32> {
        let mean = tile.iter().sum::<f32>() / tile.len() as f32;
        let twiddle = |k: usize, x: usize| {
            let a = -2.0 * std::f32::consts::PI * (k * x % size) as f32 / size as f32;
            (a.cos(), a.sin())
        };
        let mut rows = vec![(0.0f32, 0.0f32); size * size];
        for y in 0..size {
            for k in 0..size {
                let mut s = (0.0, 0.0);
                for x in 0..size {
                    let (c, si) = twiddle(k, x);
                    let v = tile[y * size + x] - mean;
                    s = (s.0 + v * c, s.1 + v * si);
                }
                rows[y * size + k] = s;
            }
        }
        let mut power = vec![0.0; size * size];
        for kx in 0..size {
            for ky in 0..size {
                let mut s = (0.0, 0.0);
                for y in 0..size {
                    let (c, si) = twiddle(ky, y);
                    let (re, im) = rows[y * size + kx];
                    s = (s.0 + re * c - im * si, s.1 + re * si + im * c);
                }
                power[ky * size + kx] = s.0 * s.0 + s.1 * s.1;
            }
        }
        power
    }

    /// Mean power at frequencies below `cutoff` (cycles per pixel, radially) and the strongest
    /// frequency's power, each over the mean power of all frequencies but zero.
    fn low_and_peak(tile: &[f32], size: usize, cutoff: f32) -> (f32, f32) {
        let power = power_spectrum(tile, size);
        let mean = power.iter().sum::<f32>() / (power.len() - 1) as f32;
        let freq = |k: usize| k.min(size - k) as f32 / size as f32;
        let low: Vec<f32> = (1..power.len())
            .filter(|&i| freq(i % size).hypot(freq(i / size)) < cutoff)
            .map(|i| power[i])
            .collect();
        let peak = power.iter().skip(1).fold(0.0f32, |a, &b| a.max(b));
        (
            low.iter().sum::<f32>() / low.len() as f32 / mean,
            peak / mean,
        )
    }

    #[test]
    fn the_tile_holds_every_rank_once() {
        let mut values = blue_noise_tile().to_vec();
        values.sort_by(f32::total_cmp);
        let pixels = values.len() as f32;
        assert_eq!(values.len(), (BLUE_NOISE_SIZE * BLUE_NOISE_SIZE) as usize);
        for (rank, v) in values.iter().enumerate() {
            assert_eq!(*v, (rank as f32 + 0.5) / pixels);
        }
    }

    /// Blue: a tenth of the mean power below an eighth of a cycle per pixel (white noise has all of
    /// it) and no frequency above 50 times the mean (the strongest of a noise spectrum's 4095
    /// frequencies is about ten times it); the R2 dither it replaced puts its power in a lattice's
    /// few peaks, 400 times the mean, which this bound refuses.
    #[test]
    fn the_tile_is_blue_noise_without_a_lattice() {
        let size = BLUE_NOISE_SIZE as usize;
        let (low, peak) = low_and_peak(blue_noise_tile(), size, 0.125);
        assert!(low < 0.1, "low-frequency power {low} of the mean");
        assert!(peak < 50.0, "strongest frequency {peak} times the mean");
        let step = crate::frame::FOOTPRINT_STEP;
        let r2: Vec<f32> = (0..size * size)
            .map(|i| ((i % size) as f64 * step[0] + (i / size) as f64 * step[1]).fract() as f32)
            .collect();
        let (_, r2_peak) = low_and_peak(&r2, size, 0.125);
        assert!(
            r2_peak > 50.0,
            "the R2 dither's peak {r2_peak} passes the bound"
        );
    }
}
