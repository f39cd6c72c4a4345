//! The reference particle: a unit sphere of cloud whose density falls off smoothly from the centre
//! and is modulated by 3D noise in one of the three styles of Yusov 2014 ("Pre-computing optical
//! depth: 3D noise generation": radial falloff + noise, thresholding, pyroclastic).
//!
//! Positions are in particle space: the particle is the unit ball, density is 0 outside it and at
//! most 1 inside. A real particle of radius `R` and peak extinction `sigma` has extinction
//! `sigma * density(p / R)`. `particle_density_with_noise` in `particle.wgsl` is the GPU twin.

use glam::{Vec2, Vec3};

use crate::field::noise::perlin;
use crate::scene::ParticleStyle;

/// Octaves of the particle noise (Yusov's sample code, `../shared/references/peers.md`).
pub const NOISE_OCTAVES: u32 = 4;
/// Frequency ratio between successive octaves (Yusov's sample code).
pub const NOISE_LACUNARITY: f32 = 1.7;
/// Amplitude ratio between successive octaves (Yusov's sample code).
pub const NOISE_GAIN: f32 = 0.7;
/// Lattice cells of the first octave per particle radius. Yusov starts at 0.15 in the units of his
/// 128^3 noise texture; here the first octave's bumps are about as wide as the particle, and the
/// fourth (2.9 cells per radius) is still resolved by the default optical-depth table, whose
/// start points lie 0.1 radius apart.
pub const NOISE_BASE_CELLS_PER_RADIUS: f32 = 0.6;
/// Lattice period of every octave, cells: far more than the particle spans, so nothing repeats.
const NOISE_PERIOD_CELLS: i32 = 64;
/// Smooth style: how strongly the noise modulates the falloff (0: none, 1: down to zero).
const SMOOTH_NOISE_DEPTH: f32 = 0.5;
/// Thresholded style: how strongly the noise modulates the falloff before thresholding.
const THRESHOLD_NOISE_DEPTH: f32 = 0.7;
/// Thresholded style: the noisy falloff is mapped to density by `smoothstep(lo, hi, .)`.
const THRESHOLD_LO: f32 = 0.2;
/// See [`THRESHOLD_LO`].
const THRESHOLD_HI: f32 = 0.4;
/// Pyroclastic style: mean radius of the displaced surface, in particle radii.
const PYROCLASTIC_MEAN_RADIUS: f32 = 0.72;
/// Pyroclastic style: how far the noise displaces the surface, in particle radii.
const PYROCLASTIC_DISPLACEMENT: f32 = 0.2;
/// Pyroclastic style: width of the soft edge of the displaced surface, in particle radii.
const PYROCLASTIC_EDGE: f32 = 0.16;

/// Yusov's metaball falloff `rho(r) = -4/9 r^6 + 17/9 r^4 - 22/9 r^2 + 1` for `r < 1`, else 0
/// (Wyvill, McPheeters & Wyvill 1986, "Data structure for soft objects", quoted by Yusov 2014): 1
/// at the centre, 0 with zero slope at the surface.
pub fn metaball_falloff(r: f32) -> f32 {
    if r >= 1.0 {
        return 0.0;
    }
    let r2 = r * r;
    ((-4.0 / 9.0 * r2 + 17.0 / 9.0) * r2 - 22.0 / 9.0) * r2 + 1.0
}

/// The particle's noise at `p` (particle space): four Perlin octaves with Yusov's lacunarity and
/// gain, normalised by the sum of the amplitudes, so roughly in [-1, 1] (mean 0).
pub fn particle_noise(p: Vec3, seed: u32) -> f32 {
    let mut sum = 0.0;
    let mut amplitude = 1.0;
    let mut total = 0.0;
    let mut cells = NOISE_BASE_CELLS_PER_RADIUS;
    for octave in 0..NOISE_OCTAVES {
        // Offset every octave so the lattices do not share their origin at the particle centre.
        let offset = Vec3::splat(17.0 + 11.0 * octave as f32);
        sum += amplitude * perlin(p * cells + offset, NOISE_PERIOD_CELLS, seed ^ octave);
        total += amplitude;
        amplitude *= NOISE_GAIN;
        cells *= NOISE_LACUNARITY;
    }
    sum / total
}

/// The noisy reference particle of one style.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReferenceParticle {
    /// How the noise shapes it.
    pub style: ParticleStyle,
    /// Seed of its noise.
    pub seed: u32,
}

impl ReferenceParticle {
    /// The style's constants, as the GPU reads them.
    pub fn shape(&self) -> ParticleShape {
        let (a, b, c) = match self.style {
            ParticleStyle::Smooth => (SMOOTH_NOISE_DEPTH, 0.0, 0.0),
            ParticleStyle::Thresholded => (THRESHOLD_NOISE_DEPTH, THRESHOLD_LO, THRESHOLD_HI),
            ParticleStyle::Pyroclastic => (
                PYROCLASTIC_MEAN_RADIUS,
                PYROCLASTIC_DISPLACEMENT,
                PYROCLASTIC_EDGE,
            ),
        };
        ParticleShape {
            base_cells: NOISE_BASE_CELLS_PER_RADIUS,
            a,
            b,
            c,
        }
    }

    /// Density at `p` in particle space, 0..1; 0 outside the unit ball.
    pub fn density(&self, p: Vec3) -> f32 {
        self.density_with_noise(p, self.noise_input(p))
    }

    /// The noise the style reads at `p`: the particle noise there, or (pyroclastic) at the
    /// direction of `p`, which displaces the surface radially.
    pub fn noise_input(&self, p: Vec3) -> f32 {
        match self.style {
            ParticleStyle::Pyroclastic => particle_noise(p / p.length().max(1e-6), self.seed),
            _ => particle_noise(p, self.seed),
        }
    }

    /// Density at `p` given the style's noise `n` there ([`Self::noise_input`]): the noise is
    /// smooth and can be interpolated from a grid, the falloff and edges are computed exactly.
    pub fn density_with_noise(&self, p: Vec3, n: f32) -> f32 {
        let r = p.length();
        if r >= 1.0 {
            return 0.0;
        }
        let s = self.shape();
        match self.style {
            ParticleStyle::Smooth => {
                metaball_falloff(r) * (1.0 + s.a * (n - 1.0) * 0.5).clamp(0.0, 1.0)
            }
            ParticleStyle::Thresholded => {
                smoothstep(s.b, s.c, metaball_falloff(r) * (1.0 + s.a * n))
            }
            ParticleStyle::Pyroclastic => ((s.a + s.b * n - r) / s.c).clamp(0.0, 1.0),
        }
    }
}

/// A style's constants (`ParticleShape` in `particle.wgsl`): the first octave's lattice cells
/// per radius and three numbers whose meaning depends on the style (smooth: noise depth;
/// thresholded: noise depth, smoothstep low and high; pyroclastic: mean surface radius,
/// displacement, edge width).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct ParticleShape {
    /// Lattice cells of the first noise octave per particle radius.
    pub base_cells: f32,
    /// First style constant.
    pub a: f32,
    /// Second style constant.
    pub b: f32,
    /// Third style constant.
    pub c: f32,
}

/// Hermite smoothstep, as WGSL's `smoothstep`.
fn smoothstep(lo: f32, hi: f32, x: f32) -> f32 {
    let t = ((x - lo) / (hi - lo)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// A particle's noise ([`ReferenceParticle::noise_input`]) sampled on a regular grid over the
/// cube `[-1, 1]^3` and read back by trilinear interpolation, so chords through the particle cost
/// a few reads per step; the falloff and edges are evaluated exactly at each step
/// ([`Self::density`]). Both the CPU and the GPU bake integrate through it.
#[derive(Clone, Debug, PartialEq)]
pub struct NoiseVolume {
    /// The particle.
    pub particle: ReferenceParticle,
    /// Voxels per side.
    pub size: u32,
    /// Noise at voxel centres `-1 + (i + 0.5) 2 / size`, x fastest.
    pub values: Vec<f32>,
}

impl NoiseVolume {
    /// The noise of `particle` at every voxel centre (in parallel).
    pub fn bake(particle: &ReferenceParticle, size: u32) -> NoiseVolume {
        use rayon::prelude::*;
        let n = size as usize;
        let values = (0..n * n * n)
            .into_par_iter()
            .map(|i| particle.noise_input(voxel_centre(i, size)))
            .collect();
        NoiseVolume {
            particle: *particle,
            size,
            values,
        }
    }

    /// The particle's density at `p` with the noise interpolated from the grid.
    pub fn density(&self, p: Vec3) -> f32 {
        self.particle.density_with_noise(p, self.sample(p))
    }

    /// Trilinear noise at `p` (particle space), clamped to the edge voxels; the GPU twin is
    /// `volume_noise` in `particle_bake.wgsl`.
    pub fn sample(&self, p: Vec3) -> f32 {
        let n = self.size as i32;
        let fetch = |t: glam::IVec3| {
            let c = t.clamp(glam::IVec3::ZERO, glam::IVec3::splat(n - 1));
            glam::Vec4::splat(self.values[(c.x + n * (c.y + n * c.z)) as usize])
        };
        crate::field::texture::sample_linear(glam::UVec3::splat(self.size), (p + 1.0) * 0.5, fetch)
            .x
    }
}

/// Centre of voxel `index` (x fastest) of a grid of `size^3` over `[-1, 1]^3`.
fn voxel_centre(index: usize, size: u32) -> Vec3 {
    let n = size as usize;
    let i = glam::UVec3::new(
        (index % n) as u32,
        ((index / n) % n) as u32,
        (index / (n * n)) as u32,
    );
    (i.as_vec3() + 0.5) * (2.0 / size as f32) - 1.0
}

/// The spherically symmetric particle whose scattering is tabulated: the noisy particle's density
/// averaged over the directions at each radius, tabulated at `RADIAL_SAMPLES` radii and read back
/// linearly. For the smooth style without noise this is close to the metaball falloff.
#[derive(Clone, Debug, PartialEq)]
pub struct RadialProfile {
    /// Mean density at radii `(i + 0.5) / len`.
    pub density: Vec<f32>,
}

/// Radii of a [`RadialProfile`].
pub const RADIAL_SAMPLES: usize = 64;
/// Directions averaged per radius of a [`RadialProfile`] (a Fibonacci sphere).
const RADIAL_DIRECTIONS: usize = 1024;

impl RadialProfile {
    /// The direction-averaged density of `particle`.
    pub fn of(particle: &ReferenceParticle) -> RadialProfile {
        use rayon::prelude::*;
        let density = (0..RADIAL_SAMPLES)
            .into_par_iter()
            .map(|i| {
                let r = (i as f32 + 0.5) / RADIAL_SAMPLES as f32;
                let sum: f32 = (0..RADIAL_DIRECTIONS)
                    .map(|k| particle.density(fibonacci_direction(k, RADIAL_DIRECTIONS) * r))
                    .sum();
                sum / RADIAL_DIRECTIONS as f32
            })
            .collect();
        RadialProfile { density }
    }

    /// Density at radius `r` (particle radii): linear between samples, the centre sample below the
    /// first, and falling linearly to 0 between the last sample and the surface.
    pub fn at(&self, r: f32) -> f32 {
        let n = self.density.len();
        if r >= 1.0 {
            return 0.0;
        }
        let x = r * n as f32 - 0.5;
        if x <= 0.0 {
            return self.density[0];
        }
        let i = x.floor() as usize;
        let f = x - i as f32;
        let next = self.density.get(i + 1).copied().unwrap_or(0.0);
        self.density[i] + (next - self.density[i]) * f
    }
}

impl RadialProfile {
    /// Mean density over the unit ball, `integral of rho(r) 3 r^2 dr` over [0, 1] (0.195 for the
    /// bare metaball falloff): the particle's mass relative to a uniform ball of density 1.
    pub fn volume_mean(&self) -> f32 {
        let n = 4 * self.density.len();
        (0..n)
            .map(|i| {
                let r = (i as f32 + 0.5) / n as f32;
                self.at(r) * 3.0 * r * r / n as f32
            })
            .sum()
    }

    /// The largest density at any radius in `[r0, r1]` (an exact bound of [`Self::at`], which
    /// is linear between samples).
    pub fn max_between(&self, r0: f32, r1: f32) -> f32 {
        let n = self.density.len() as f32;
        let first = ((r0 * n - 0.5).ceil().max(0.0)) as usize;
        let last = ((r1 * n - 0.5).floor().max(-1.0) + 1.0) as usize;
        let inner = self.density[first.min(self.density.len())..last.min(self.density.len())]
            .iter()
            .copied()
            .fold(0.0, f32::max);
        inner.max(self.at(r0)).max(self.at(r1))
    }
}

/// A uniform point on the unit sphere from two uniform numbers in [0, 1).
pub fn uniform_sphere_point(u: Vec2) -> Vec3 {
    let z = 1.0 - 2.0 * u.x;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let (s, c) = (std::f32::consts::TAU * u.y).sin_cos();
    Vec3::new(r * c, r * s, z)
}

/// A uniform point in the unit disc from two uniform numbers in [0, 1) (`r = sqrt(u.x)`).
pub fn uniform_disc_point(u: Vec2) -> Vec2 {
    let (s, c) = (std::f32::consts::TAU * u.y).sin_cos();
    Vec2::new(c, s) * u.x.sqrt()
}

/// Direction `k` of `count` spread evenly over the sphere (the Fibonacci lattice, González 2010,
/// "Measurement of areas on a sphere using Fibonacci and latitude-longitude lattices").
pub fn fibonacci_direction(k: usize, count: usize) -> Vec3 {
    let z = 1.0 - (2.0 * k as f32 + 1.0) / count as f32;
    let phi = 2.0 * std::f32::consts::PI * crate::field::GOLDEN_RATIO_CONJUGATE * k as f32;
    let s = (1.0 - z * z).max(0.0).sqrt();
    Vec3::new(s * phi.cos(), s * phi.sin(), z)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn particle(style: ParticleStyle) -> ReferenceParticle {
        ReferenceParticle { style, seed: 3 }
    }

    #[test]
    fn metaball_is_one_at_the_centre_and_vanishes_smoothly_at_the_surface() {
        assert_eq!(metaball_falloff(0.0), 1.0);
        assert!(metaball_falloff(1.0).abs() < 1e-6);
        assert!(metaball_falloff(0.999).abs() < 1e-5, "zero slope at r = 1");
        let mut last = 1.0;
        for i in 1..100 {
            let v = metaball_falloff(i as f32 / 100.0);
            assert!(v < last, "monotonic");
            last = v;
        }
    }

    #[test]
    fn every_style_is_within_0_1_and_zero_outside_the_ball() {
        for style in [
            ParticleStyle::Smooth,
            ParticleStyle::Thresholded,
            ParticleStyle::Pyroclastic,
        ] {
            let p = particle(style);
            let mut mean = 0.0;
            for k in 0..4000 {
                let d = fibonacci_direction(k, 4000);
                let r = (k as f32 * 0.618).fract() * 1.2;
                let v = p.density(d * r);
                assert!((0.0..=1.0).contains(&v), "{style:?} {v}");
                if r >= 1.0 {
                    assert_eq!(v, 0.0);
                }
                mean += v;
            }
            assert!(mean / 4000.0 > 0.1, "{style:?} is not empty");
        }
    }

    #[test]
    fn noise_makes_the_styles_differ_and_is_seeded() {
        let a = particle(ParticleStyle::Smooth);
        let b = ReferenceParticle { seed: 4, ..a };
        let p = Vec3::new(0.3, -0.2, 0.4);
        assert_ne!(a.density(p), b.density(p));
        let n: Vec<f32> = (0..500)
            .map(|k| particle_noise(fibonacci_direction(k, 500) * 0.7, 3))
            .collect();
        let spread =
            n.iter().cloned().fold(f32::MIN, f32::max) - n.iter().cloned().fold(f32::MAX, f32::min);
        assert!(
            spread > 0.3,
            "the noise varies across the particle: {spread}"
        );
    }

    #[test]
    fn the_volume_reproduces_the_density_and_the_profile_its_mean() {
        let p = particle(ParticleStyle::Smooth);
        let volume = NoiseVolume::bake(&p, 48);
        let mut err = 0.0;
        for k in 0..500 {
            let q = fibonacci_direction(k, 500) * 0.6;
            err += (volume.density(q) - p.density(q)).abs();
        }
        assert!(err / 500.0 < 0.01, "mean trilinear error {}", err / 500.0);
        let profile = RadialProfile::of(&p);
        assert!(profile.at(0.05) > profile.at(0.5) && profile.at(0.5) > profile.at(0.95));
        assert_eq!(profile.at(1.0), 0.0);
    }
}
