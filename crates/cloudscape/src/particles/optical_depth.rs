//! The 4D optical-depth table of the reference particle (Yusov 2014, "Pre-computing optical
//! depth"): for every entry point on the unit sphere (zenith, azimuth) and every inward direction
//! (zenith from the inward normal, azimuth about it), the optical mass `integral of density ds`
//! along the chord, in particle radii (0..2). A particle of radius `R` and peak extinction `sigma`
//! has optical depth `sigma * R * value`.
//!
//! The table stores the ratio of that optical mass to the mass of the particle's direction-averaged
//! density along the same chord ([`ChordProfile`], a function of the chord's length alone, which
//! a look-up evaluates at the exact length): the steep fall of the mass toward grazing chords and
//! the style's mean shape are then exact, and only the noise's variation is interpolated.
//!
//! Stored as one 3D texture (x: entry azimuth, repeating; y: entry zenith; z: one slice of
//! direction zeniths per direction azimuth); the hardware filters the first three coordinates and
//! the look-up interpolates between two slices by hand across the fourth, as the seed describes.
//! This module is the CPU specification: the parameterisation, the bake and the look-up, which the
//! GPU twins (`particle.wgsl`, [`super::gpu`]) must match.

use glam::{IVec3, UVec3, Vec2, Vec3, Vec4};
use half::f16;
use std::f32::consts::{FRAC_PI_2, PI, TAU};

use super::density::{NoiseVolume, RadialProfile, ReferenceParticle, uniform_sphere_point};

/// Sizes of the four dimensions of an optical-depth table.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct OpticalDepthLayout {
    /// Entry-point zeniths over [0, pi].
    pub start_zenith: u32,
    /// Entry-point azimuths over [0, 2 pi).
    pub start_azimuth: u32,
    /// Direction zeniths from the inward normal over [0, pi / 2].
    pub dir_zenith: u32,
    /// Direction azimuths about the normal over [0, 2 pi).
    pub dir_azimuth: u32,
}

/// Integration steps along a diameter; shorter chords take proportionally fewer (at least 2).
pub const STEPS_PER_DIAMETER: u32 = 48;

impl OpticalDepthLayout {
    /// The seed's 32x64x32x64 (Yusov 2014, "Resolution"): 4 M entries, 8 MiB as 16-bit floats.
    pub const DEFAULT: OpticalDepthLayout = OpticalDepthLayout {
        start_zenith: 32,
        start_azimuth: 64,
        dir_zenith: 32,
        dir_azimuth: 64,
    };

    /// Width, height and depth of the 3D texture that stores the table.
    pub fn texture_dims(&self) -> UVec3 {
        UVec3::new(
            self.start_azimuth,
            self.start_zenith,
            self.dir_zenith * self.dir_azimuth,
        )
    }

    /// Entries in the table.
    pub fn len(&self) -> usize {
        let d = self.texture_dims();
        (d.x * d.y * d.z) as usize
    }

    /// Whether the table has no entries (never, for a valid layout).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The chord of texel `t` of the texture: its entry point on the unit sphere and its inward
    /// unit direction, at the centres of the texel's cells.
    pub fn texel_ray(&self, t: UVec3) -> (Vec3, Vec3) {
        let start_zenith = (t.y as f32 + 0.5) / self.start_zenith as f32 * PI;
        let start_azimuth = (t.x as f32 + 0.5) / self.start_azimuth as f32 * TAU;
        let (slice, j) = (t.z / self.dir_zenith, t.z % self.dir_zenith);
        let dir_zenith = (j as f32 + 0.5) / self.dir_zenith as f32 * FRAC_PI_2;
        let dir_azimuth = (slice as f32 + 0.5) / self.dir_azimuth as f32 * TAU;
        let frame = EntryFrame::at(start_zenith, start_azimuth);
        (frame.normal, frame.inward(dir_zenith, dir_azimuth))
    }
}

/// The frame at an entry point of the unit sphere: the outward normal and the tangents along
/// growing zenith and growing azimuth.
struct EntryFrame {
    normal: Vec3,
    tangent_zenith: Vec3,
    tangent_azimuth: Vec3,
}

impl EntryFrame {
    fn at(zenith: f32, azimuth: f32) -> EntryFrame {
        let (sz, cz) = zenith.sin_cos();
        let (sa, ca) = azimuth.sin_cos();
        EntryFrame {
            normal: Vec3::new(sz * ca, sz * sa, cz),
            tangent_zenith: Vec3::new(cz * ca, cz * sa, -sz),
            tangent_azimuth: Vec3::new(-sa, ca, 0.0),
        }
    }

    /// The inward direction at `zenith` from the inward normal and `azimuth` about it.
    fn inward(&self, zenith: f32, azimuth: f32) -> Vec3 {
        let (sz, cz) = zenith.sin_cos();
        let (sa, ca) = azimuth.sin_cos();
        -cz * self.normal + sz * (ca * self.tangent_zenith + sa * self.tangent_azimuth)
    }
}

/// Where the unit ray from `origin` along `dir` is inside the unit ball: `(t_in, t_out)`, or None
/// when it misses.
pub fn unit_sphere_chord(origin: Vec3, dir: Vec3) -> Option<(f32, f32)> {
    let b = origin.dot(dir);
    let c = origin.length_squared() - 1.0;
    let disc = b * b - c;
    (disc > 0.0).then(|| {
        let s = disc.sqrt();
        (-b - s, -b + s)
    })
}

/// Optical mass along the chord from `entry` (on the unit sphere) along the inward `dir`:
/// midpoint rule with [`STEPS_PER_DIAMETER`] steps per diameter over `density`.
pub fn chord_optical_mass(entry: Vec3, dir: Vec3, density: impl Fn(Vec3) -> f32) -> f32 {
    let Some((_, t_out)) = unit_sphere_chord(entry, dir) else {
        return 0.0;
    };
    let length = t_out.max(0.0);
    let steps = ((length * 0.5 * STEPS_PER_DIAMETER as f32).ceil() as u32).max(2);
    let dt = length / steps as f32;
    (0..steps)
        .map(|i| density(entry + dir * ((i as f32 + 0.5) * dt)))
        .sum::<f32>()
        * dt
}

/// The optical mass of the particle's direction-averaged density ([`RadialProfile`]) along a
/// chord of the unit sphere, which depends only on the chord's cosine `u = cos(direction zenith)`
/// (its length is `2 u`): tabulated as the mean density along the chord at [`CHORD_NODES`]
/// values of `u` over [0, 1] and read back linearly.
#[derive(Clone, Debug, PartialEq)]
pub struct ChordProfile {
    /// Mean density along the chord at `u = i / (len - 1)`.
    pub mean_density: Vec<f32>,
}

/// Nodes of a [`ChordProfile`].
pub const CHORD_NODES: usize = 256;
/// Midpoint steps along each chord of a [`ChordProfile`].
const CHORD_STEPS: usize = 128;

impl ChordProfile {
    /// The chord masses of `particle`'s direction-averaged density.
    pub fn of_particle(particle: &ReferenceParticle) -> ChordProfile {
        ChordProfile::of(&RadialProfile::of(particle))
    }

    /// The chord masses of `profile`.
    pub fn of(profile: &RadialProfile) -> ChordProfile {
        let mean_density = (0..CHORD_NODES)
            .map(|i| {
                let u = i as f32 / (CHORD_NODES - 1) as f32;
                let b2 = 1.0 - u * u;
                let sum: f32 = (0..CHORD_STEPS)
                    .map(|k| {
                        let t = ((k as f32 + 0.5) / CHORD_STEPS as f32 * 2.0 - 1.0) * u;
                        profile.at((b2 + t * t).max(0.0).sqrt())
                    })
                    .sum();
                sum / CHORD_STEPS as f32
            })
            .collect();
        ChordProfile { mean_density }
    }

    /// The optical mass along the chord from `entry` (on the unit sphere) along the inward `dir`.
    pub fn mass(&self, entry: Vec3, dir: Vec3) -> f32 {
        let u = (-entry.dot(dir)).clamp(0.0, 1.0);
        let x = u * (CHORD_NODES - 1) as f32;
        let i = (x as usize).min(CHORD_NODES - 2);
        let f = x - i as f32;
        let m = &self.mean_density;
        2.0 * u * (m[i] + (m[i + 1] - m[i]) * f)
    }

    /// The stored value of a chord: its optical mass over the profile's.
    pub fn ratio(&self, entry: Vec3, dir: Vec3, mass: f32) -> f32 {
        mass / self.mass(entry, dir).max(MIN_PROFILE_MASS)
    }
}

/// Floor of the profile mass a ratio is taken against, particle radii: chords that graze the
/// surface have no mass to speak of.
const MIN_PROFILE_MASS: f32 = 1e-7;

/// A baked optical-depth table, its values (mass ratios) in texture order as 16-bit floats (what
/// the GPU texture holds).
#[derive(Clone, Debug, PartialEq)]
pub struct OpticalDepthTable {
    /// Its dimensions.
    pub layout: OpticalDepthLayout,
    /// Mass ratio ([`ChordProfile::ratio`]) per texel, x fastest, then y, then z.
    pub values: Vec<f16>,
    /// The chord masses the ratios are relative to.
    pub chords: ChordProfile,
}

impl OpticalDepthTable {
    /// Bakes the table on the CPU through `volume` (the specification of the GPU bake).
    pub fn bake_cpu(layout: OpticalDepthLayout, volume: &NoiseVolume) -> OpticalDepthTable {
        use rayon::prelude::*;
        let chords = ChordProfile::of_particle(&volume.particle);
        let dims = layout.texture_dims();
        let values = (0..layout.len())
            .into_par_iter()
            .map(|i| {
                let i = i as u32;
                let t = UVec3::new(i % dims.x, (i / dims.x) % dims.y, i / (dims.x * dims.y));
                let (entry, dir) = layout.texel_ray(t);
                let mass = chord_optical_mass(entry, dir, |p| volume.density(p));
                f16::from_f32(chords.ratio(entry, dir, mass))
            })
            .collect();
        OpticalDepthTable {
            layout,
            values,
            chords,
        }
    }

    /// Optical mass (particle radii) along the chord entering the unit sphere at `entry` along
    /// `dir` (unit), in the particle's own orientation (apply a particle's random rotation to both
    /// before calling). Trilinear across the texture's three axes and linear across direction
    /// azimuth, exactly as `particle_optical_depth_taps` in `particle.wgsl` samples the
    /// texture.
    pub fn lookup(&self, entry: Vec3, dir: Vec3) -> f32 {
        let taps = LookupTaps::new(&self.layout, entry, dir);
        let dims = self.layout.texture_dims();
        let fetch = |t: IVec3| {
            let x = t.x.rem_euclid(dims.x as i32);
            let y = t.y.clamp(0, dims.y as i32 - 1);
            let z = t.z.clamp(0, dims.z as i32 - 1);
            let i = x as u32 + dims.x * (y as u32 + dims.y * z as u32);
            Vec4::splat(self.values[i as usize].to_f32())
        };
        let a = crate::field::texture::sample_linear(dims, taps.uvw[0], fetch).x;
        let b = crate::field::texture::sample_linear(dims, taps.uvw[1], fetch).x;
        (a + (b - a) * taps.weight) * self.chords.mass(entry.normalize(), dir.normalize())
    }
}

/// The two texture coordinates (normalised) of a look-up and the weight of the second.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LookupTaps {
    /// Normalised texture coordinates in the two direction-azimuth slices.
    pub uvw: [Vec3; 2],
    /// Weight of the second slice.
    pub weight: f32,
}

impl LookupTaps {
    /// The taps of the chord entering at `entry` along `dir` (both normalised here).
    pub fn new(layout: &OpticalDepthLayout, entry: Vec3, dir: Vec3) -> LookupTaps {
        let n = entry.normalize();
        let dir = dir.normalize();
        let start_zenith = n.z.clamp(-1.0, 1.0).acos();
        let start_azimuth = n.y.atan2(n.x);
        let frame = EntryFrame::at(start_zenith, start_azimuth);
        let dir_zenith = (-dir.dot(n)).clamp(0.0, 1.0).acos();
        let dir_azimuth = dir
            .dot(frame.tangent_azimuth)
            .atan2(dir.dot(frame.tangent_zenith));
        let dims = layout.texture_dims().as_vec3();
        let x = start_azimuth / TAU;
        let y = start_zenith / PI;
        let zenith_texel = (dir_zenith / FRAC_PI_2 * layout.dir_zenith as f32)
            .clamp(0.5, layout.dir_zenith as f32 - 0.5);
        let slice = (dir_azimuth / TAU).rem_euclid(1.0) * layout.dir_azimuth as f32 - 0.5;
        let first = slice.floor();
        let weight = slice - first;
        let k0 = (first as i32).rem_euclid(layout.dir_azimuth as i32) as f32;
        let k1 = (k0 + 1.0) % layout.dir_azimuth as f32;
        let w = |k: f32| (k * layout.dir_zenith as f32 + zenith_texel) / dims.z;
        LookupTaps {
            uvw: [Vec3::new(x, y, w(k0)), Vec3::new(x, y, w(k1))],
            weight,
        }
    }
}

/// Relative errors of table look-ups against direct integration.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LookupAccuracy {
    /// Chords compared.
    pub chords: u32,
    /// Mean relative error.
    pub mean: f32,
    /// Root-mean-square relative error.
    pub rms: f32,
    /// 95th-percentile relative error.
    pub p95: f32,
    /// Largest relative error.
    pub max: f32,
}

/// Shortest chord compared by [`lookup_accuracy`]: 5 % of the diameter, in particle radii.
pub const MIN_COMPARED_CHORD: f32 = 0.1;
/// Integration steps along a diameter of the direct integration [`lookup_accuracy`] compares
/// against: eight times the bake's.
const REFERENCE_STEPS_PER_DIAMETER: f32 = 512.0;

/// Compares `lookup(entry, dir)` with the optical mass of `density` integrated directly along
/// `chords` pseudo-random chords (entry points uniform on the sphere, directions uniform over
/// the inward hemisphere) no shorter than [`MIN_COMPARED_CHORD`].
pub fn lookup_accuracy(
    chords: u32,
    density: impl Fn(Vec3) -> f32 + Sync,
    lookup: impl Fn(Vec3, Vec3) -> f32 + Sync,
) -> LookupAccuracy {
    use rayon::prelude::*;
    let mut errors: Vec<f32> = random_chords(chords)
        .into_par_iter()
        .map(|(entry, dir)| {
            let length = -2.0 * entry.dot(dir);
            let steps = (length * 0.5 * REFERENCE_STEPS_PER_DIAMETER)
                .ceil()
                .max(2.0);
            let dt = length / steps;
            let exact: f32 = (0..steps as u32)
                .map(|i| density(entry + dir * ((i as f32 + 0.5) * dt)))
                .sum::<f32>()
                * dt;
            let got = lookup(entry, dir);
            (got - exact).abs() / exact.max(1e-3 * length)
        })
        .collect();
    errors.sort_by(f32::total_cmp);
    let n = errors.len().max(1) as f32;
    LookupAccuracy {
        chords: errors.len() as u32,
        mean: errors.iter().sum::<f32>() / n,
        rms: (errors.iter().map(|e| e * e).sum::<f32>() / n).sqrt(),
        p95: errors.get((0.95 * n) as usize).copied().unwrap_or(0.0),
        max: errors.last().copied().unwrap_or(0.0),
    }
}

/// `count` deterministic pseudo-random chords (entry point, inward unit direction) of at least
/// [`MIN_COMPARED_CHORD`].
pub fn random_chords(count: u32) -> Vec<(Vec3, Vec3)> {
    use crate::field::noise::{hash_to_unit, pcg_hash};
    let mut out = Vec::with_capacity(count as usize);
    let mut state = 0x9e37_79b9u32;
    let mut next = || {
        state = pcg_hash(state);
        hash_to_unit(state)
    };
    while out.len() < count as usize {
        let entry = uniform_sphere_point(Vec2::new(next(), next()));
        let local = uniform_sphere_point(Vec2::new(next(), next()));
        let dir = if local.dot(entry) > 0.0 {
            -local
        } else {
            local
        };
        if -2.0 * entry.dot(dir) >= MIN_COMPARED_CHORD {
            out.push((entry, dir));
        }
    }
    out
}

/// The random orientation of particle `id`, uniform over all rotations (Shoemake 1992, "Uniform
/// random rotations", Graphics Gems III): applied to a look-up's entry point and direction, it
/// makes every particle's noise different although they share one table.
pub fn particle_rotation(id: u32) -> glam::Quat {
    use crate::field::noise::{hash_to_unit, pcg_hash};
    let h1 = pcg_hash(id ^ 0x2c1b_3c6d);
    let h2 = pcg_hash(h1);
    let h3 = pcg_hash(h2);
    let (u1, u2, u3) = (hash_to_unit(h1), hash_to_unit(h2), hash_to_unit(h3));
    let (a, b) = ((1.0 - u1).sqrt(), u1.sqrt());
    let (s2, c2) = (TAU * u2).sin_cos();
    let (s3, c3) = (TAU * u3).sin_cos();
    glam::Quat::from_xyzw(a * s2, a * c2, b * s3, b * c3).normalize()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn texel_rays_enter_the_sphere_and_the_look_up_finds_their_texel() {
        let layout = OpticalDepthLayout {
            start_zenith: 8,
            start_azimuth: 16,
            dir_zenith: 8,
            dir_azimuth: 16,
        };
        let dims = layout.texture_dims();
        for t in [
            UVec3::new(0, 0, 0),
            UVec3::new(5, 3, 17),
            UVec3::new(15, 7, 127),
        ] {
            let (entry, dir) = layout.texel_ray(t);
            assert!((entry.length() - 1.0).abs() < 1e-5 && dir.dot(entry) < 0.0);
            let taps = LookupTaps::new(&layout, entry, dir);
            let mut texel = taps.uvw[0] * dims.as_vec3() - 0.5;
            // Entry azimuth repeats.
            texel.x = (texel.x + 0.5).rem_euclid(dims.x as f32) - 0.5;
            assert!(taps.weight.abs() < 1e-3, "{taps:?}");
            assert!(
                (texel - t.as_vec3()).abs().max_element() < 1e-2,
                "{texel} vs {t}"
            );
        }
    }

    #[test]
    fn particle_rotations_are_rotations_and_differ() {
        let a = particle_rotation(1);
        let b = particle_rotation(2);
        assert!((a.length() - 1.0).abs() < 1e-5);
        assert!(a.angle_between(b) > 0.1);
        // Uniform: the rotated pole has no preferred direction on average.
        let mean: Vec3 = (0..4000)
            .map(|i| particle_rotation(i) * Vec3::Z)
            .sum::<Vec3>()
            / 4000.0;
        assert!(mean.length() < 0.05, "{mean}");
    }

    #[test]
    fn chord_profiles_integrate_their_radial_profile() {
        let particle = super::super::density::ReferenceParticle {
            style: crate::scene::ParticleStyle::Smooth,
            seed: 3,
        };
        let profile = RadialProfile::of(&particle);
        let chords = ChordProfile::of(&profile);
        for (entry, dir) in random_chords(50) {
            let direct = chord_optical_mass(entry, dir, |p| profile.at(p.length()));
            let tabulated = chords.mass(entry, dir);
            assert!(
                (direct - tabulated).abs() < 0.01 * direct + 1e-4,
                "{direct} vs {tabulated}"
            );
        }
    }
}
