//! Precomputed lighting of volumetric particles (Yusov 2014, "Realistic Cloud Rendering Using
//! Pixel Sync"): a reference particle whose optical depth and scattering are baked once into
//! look-up tables, so that the particle technique shades each particle with a few texture reads.
//!
//! - [`density`]: the reference particle, a noisy radial falloff in three styles;
//! - [`optical_depth`]: the 4D optical-depth table (CPU specification), [`gpu`] its GPU bake;
//! - [`scattering`]: single and multiple scattering of the spherically symmetric particle, order by
//!   order;
//! - [`table_file`]: table files and their keys; [`store`]: the shipped tables and the cache;
//! - [`preview`]: orthographic pictures of the particle as the tables shade it;
//! - [`generate`] (CPU specification), [`generate_gpu`]: the particles from the cloud field;
//! - [`occlusion`] (CPU specification), [`occlusion_gpu`]: the seed's tiled light occlusion;
//! - [`blend`], [`render`]: the particle technique's blending and rendering.
//!
//! [`ParticleTableSpec`] gathers, from a scene, every input of the tables.

pub mod blend;
pub mod density;
pub mod generate;
pub mod generate_gpu;
pub mod gpu;
pub(crate) mod grid;
pub mod occlusion;
pub mod occlusion_gpu;
pub mod optical_depth;
pub mod preview;
pub mod render;
pub mod scattering;
pub mod store;
pub mod table_file;
pub(crate) mod tables_gpu;

use crate::optics::PhaseLobes;
use crate::scene::{Scene, TableResolution};
use density::{RadialProfile, ReferenceParticle};
use optical_depth::OpticalDepthLayout;
use scattering::{OrderGrid, ScatteringLayout, SymmetricParticle};

/// Peak extinction of the reference particle without cloud layers, m^-1 (the layers' default).
pub const DEFAULT_EXTINCTION_PER_M: f32 = 0.05;

/// Every input of the particle tables.
#[derive(Clone, Debug, PartialEq)]
pub struct ParticleTableSpec {
    /// The noisy particle (style and seed).
    pub particle: ReferenceParticle,
    /// Its radius, m.
    pub radius_m: f32,
    /// Its peak extinction, m^-1.
    pub extinction_per_m: f32,
    /// Single-scattering albedo.
    pub albedo: f32,
    /// Phase function.
    pub phase: PhaseLobes,
    /// Size of the optical-depth table.
    pub optical_depth: OpticalDepthLayout,
    /// Size of the scattering tables.
    pub scattering: ScatteringLayout,
    /// Resolution of the scattering orders.
    pub orders: OrderGrid,
}

impl ParticleTableSpec {
    /// The tables a scene needs, at the default sizes.
    pub fn from_scene(scene: &Scene) -> ParticleTableSpec {
        let extinction_per_m = scene
            .layers
            .iter()
            .map(|l| l.extinction_per_m)
            .reduce(f32::max)
            .unwrap_or(DEFAULT_EXTINCTION_PER_M);
        ParticleTableSpec {
            particle: ReferenceParticle {
                style: scene.particles.style,
                seed: scene.noise.seed,
            },
            radius_m: scene.particles.radius_m,
            extinction_per_m,
            albedo: scene.lighting.albedo,
            phase: PhaseLobes::from_scene(&scene.phase),
            optical_depth: OpticalDepthLayout::at(scene.particles.table_resolution),
            scattering: ScatteringLayout::at(scene.particles.table_resolution),
            orders: OrderGrid::at(scene.particles.table_resolution),
        }
    }

    /// The spherically symmetric particle of the scattering tables: the noisy particle's density
    /// averaged over directions.
    pub fn symmetric_particle(&self) -> SymmetricParticle {
        SymmetricParticle {
            profile: RadialProfile::of(&self.particle),
            optical_radius: self.extinction_per_m * self.radius_m,
            albedo: self.albedo,
            phase: self.phase,
        }
    }

    /// Key of the optical-depth table: the particle, the table's size and the bake's resolution
    /// (the table is in particle radii, so the radius and extinction do not enter).
    pub fn optical_depth_key(&self) -> u64 {
        let l = self.optical_depth;
        let mut h = table_file::KeyHasher::new("optical depth");
        self.hash_particle(&mut h);
        for v in [l.start_zenith, l.start_azimuth, l.dir_zenith, l.dir_azimuth] {
            h.u32(v);
        }
        h.u32(gpu::NOISE_VOLUME_SIZE);
        h.u32(optical_depth::STEPS_PER_DIAMETER);
        h.finish()
    }

    /// Key of the scattering tables: everything the bake reads.
    pub fn scattering_key(&self) -> u64 {
        let mut h = table_file::KeyHasher::new("scattering");
        self.hash_particle(&mut h);
        h.f32(scattering::orders::ORDER_TOLERANCE);
        h.u32(scattering::orders::MAX_ORDERS);
        h.f32(self.radius_m * self.extinction_per_m);
        h.f32(self.albedo);
        for v in self.phase.to_gpu() {
            h.f32(v);
        }
        let (s, o) = (self.scattering, self.orders);
        for v in [s.entry, s.view_zenith, s.view_azimuth, o.radii, o.polar] {
            h.u32(v);
        }
        for v in [
            o.directions.zeniths,
            o.directions.azimuths,
            o.steps_per_radius,
        ] {
            h.u32(v);
        }
        h.finish()
    }

    /// The particle's style, seed and every constant of its density.
    fn hash_particle(&self, h: &mut table_file::KeyHasher) {
        let shape = self.particle.shape();
        h.u32(self.particle.style.gpu_index());
        h.u32(self.particle.seed);
        for v in [shape.base_cells, shape.a, shape.b, shape.c] {
            h.f32(v);
        }
        h.u32(density::NOISE_OCTAVES);
        h.f32(density::NOISE_LACUNARITY);
        h.f32(density::NOISE_GAIN);
    }
}

impl OpticalDepthLayout {
    /// The layout of a resolution: the standard one is the seed's, the others halve or double
    /// the entry-point angles (the texture's depth, direction zeniths x azimuths, stays within
    /// the 2048 every adapter supports).
    pub fn at(resolution: TableResolution) -> OpticalDepthLayout {
        let d = OpticalDepthLayout::DEFAULT;
        match resolution {
            TableResolution::Low => OpticalDepthLayout {
                start_zenith: 16,
                start_azimuth: 32,
                dir_zenith: 16,
                dir_azimuth: 32,
            },
            TableResolution::Standard => d,
            TableResolution::High => OpticalDepthLayout {
                start_zenith: 2 * d.start_zenith,
                start_azimuth: 2 * d.start_azimuth,
                ..d
            },
        }
    }
}

impl ScatteringLayout {
    /// The layout of a resolution: every axis halved or doubled from the default.
    pub fn at(resolution: TableResolution) -> ScatteringLayout {
        let d = ScatteringLayout::DEFAULT;
        let scale = |f: fn(u32) -> u32| ScatteringLayout {
            entry: f(d.entry),
            view_zenith: f(d.view_zenith),
            view_azimuth: f(d.view_azimuth),
        };
        match resolution {
            TableResolution::Low => scale(|n| n / 2),
            TableResolution::Standard => d,
            TableResolution::High => scale(|n| n * 2),
        }
    }
}

impl OrderGrid {
    /// The intermediate grid of a resolution: every axis halved or times 1.5 from the default.
    pub fn at(resolution: TableResolution) -> OrderGrid {
        let d = OrderGrid::DEFAULT;
        let scale = |f: fn(u32) -> u32| OrderGrid {
            radii: f(d.radii),
            polar: f(d.polar),
            directions: scattering::directions::DirectionGrid {
                zeniths: f(d.directions.zeniths),
                azimuths: f(d.directions.azimuths),
            },
            steps_per_radius: f(d.steps_per_radius),
        };
        match resolution {
            TableResolution::Low => scale(|n| n / 2),
            TableResolution::Standard => d,
            TableResolution::High => scale(|n| n * 3 / 2),
        }
    }
}
