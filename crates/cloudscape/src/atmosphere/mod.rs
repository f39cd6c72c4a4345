//! A physically based atmosphere: Rayleigh, Mie and ozone over a spherical planet, rendered with
//! Hillaire 2020's look-up tables ("A Scalable and Production Ready Sky and Atmosphere Rendering
//! Technique", EGSR 2020) and Bruneton 2017's constants.
//!
//! The environment ([`crate::environment`]) puts it behind the functions every technique lights
//! with, so sun light at a cloud's altitude, sky irradiance and aerial perspective reach all of
//! them unchanged. This CPU implementation is the specification: [`Atmosphere`] holds the same
//! tables the GPU builds (`atmosphere.wgsl`, [`gpu::AtmosphereTables`]) and the path tracer lights
//! with it; tests hold each GPU table to it.

pub(crate) mod luts;
pub(crate) mod medium;
pub(crate) mod table;
mod wgsl;

pub use medium::Air;
pub use wgsl::ATMOSPHERE_WGSL;

use glam::Vec3;
use luts::{IRRADIANCE_SIZE, LocalRay, SkyTables, sun_table_uv};
use std::sync::{Arc, Mutex};
use table::Table2;

/// The atmosphere's tables on the CPU: transmittance, multiple scattering and sky irradiance,
/// for a sun of unit irradiance.
#[derive(Clone, Debug, PartialEq)]
pub struct Atmosphere {
    /// Transmittance and multiple scattering, and the air.
    pub tables: SkyTables,
    /// Irradiance on an upward surface (0) and mean radiance of the sky above it (1).
    pub irradiance: [Table2; 2],
}

impl Atmosphere {
    /// Builds the tables of `air` (about a second in a debug build).
    pub fn new(air: &Air) -> Atmosphere {
        let tables = SkyTables::new(air);
        let irradiance = tables.irradiance_tables();
        Atmosphere { tables, irradiance }
    }

    /// The tables of `air`, built once per process for the last few airs asked for (the path
    /// tracer and tests ask for the same air many times).
    pub fn shared(air: &Air) -> Arc<Atmosphere> {
        static CACHE: Mutex<Vec<Arc<Atmosphere>>> = Mutex::new(Vec::new());
        let mut cache = CACHE.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(found) = cache.iter().find(|a| a.tables.air == *air) {
            return found.clone();
        }
        let built = Arc::new(Atmosphere::new(air));
        if cache.len() >= 4 {
            cache.remove(0);
        }
        cache.push(built.clone());
        built
    }

    /// The air.
    pub fn air(&self) -> &Air {
        &self.tables.air
    }

    /// Radius and unit up of world point `p` in atmosphere space.
    fn radius_up(&self, p: Vec3) -> (f32, Vec3) {
        let q = self.air().position_of(p);
        (q.length(), q.normalize())
    }

    /// Transmittance of the air from world point `p` toward the sun at `sun` (unit), zero once the
    /// sun has set there.
    pub fn sun_transmittance(&self, p: Vec3, sun: Vec3) -> Vec3 {
        let (r, up) = self.radius_up(p);
        self.tables.sun_transmittance(r, up.dot(sun))
    }

    /// Sky irradiance on an upward surface at `p` (index 0) and the mean sky radiance over the
    /// hemisphere above it (index 1), for the sun at `sun`.
    pub fn sky_irradiance(&self, p: Vec3, sun: Vec3, index: usize) -> Vec3 {
        let (r, up) = self.radius_up(p);
        let uv = sun_table_uv(self.air(), r, up.dot(sun), IRRADIANCE_SIZE);
        self.irradiance[index].sample(uv)
    }

    /// The ray from world point `p` along `dir` in the local frame of the tables, with the sun at
    /// `sun`.
    pub fn local_ray(&self, p: Vec3, dir: Vec3, sun: Vec3) -> LocalRay {
        let (r, up) = self.radius_up(p);
        let (elevation, azimuth) = local_angles(up, dir, sun);
        LocalRay::from_angles(r, up.dot(sun), elevation, azimuth)
    }

    /// Aerial perspective over the first `distance_m` of the ray from `p` along `dir`: the light
    /// the air scatters toward `p` and the transmittance, the sun's single scattering dimmed by
    /// `sun_visibility(t)` at distance `t` (the clouds' shadows).
    pub fn aerial_perspective(
        &self,
        (p, dir): (Vec3, Vec3),
        sun: Vec3,
        distance_m: f32,
        sun_visibility: impl FnMut(f32) -> f32,
    ) -> (Vec3, Vec3) {
        let ray = self.local_ray(p, dir, sun);
        self.tables
            .aerial_perspective(ray, distance_m, sun_visibility)
    }
}

/// Elevation of `dir` above the horizontal of `up` and its azimuth from the sun's, radians in
/// `[0, pi]`: the axes of the sky-view table. `atmosphere_local_angles` in `atmosphere.wgsl`.
pub fn local_angles(up: Vec3, dir: Vec3, sun: Vec3) -> (f32, f32) {
    let elevation = dir.dot(up).clamp(-1.0, 1.0).asin();
    let flat_dir = dir - up * dir.dot(up);
    let flat_sun = sun - up * sun.dot(up);
    let azimuth = if flat_dir.length_squared() < 1e-12 || flat_sun.length_squared() < 1e-12 {
        0.0
    } else {
        flat_dir
            .normalize()
            .dot(flat_sun.normalize())
            .clamp(-1.0, 1.0)
            .acos()
    };
    (elevation, azimuth)
}

/// The sky as one point sees it: the sky-view table from there.
#[derive(Clone, Debug, PartialEq)]
pub struct SkyView {
    /// The table, by [`luts::sky_view_uv`].
    pub table: Table2,
    /// Radius of the viewpoint in atmosphere space, metres.
    pub radius_m: f32,
    /// Unit up at the viewpoint.
    pub up: Vec3,
    /// Unit direction toward the sun.
    pub sun: Vec3,
}

impl SkyView {
    /// The sky seen from world point `p` with the sun at `sun`.
    pub fn new(atmosphere: &Atmosphere, p: Vec3, sun: Vec3) -> SkyView {
        let (r, up) = atmosphere.radius_up(p);
        SkyView {
            table: atmosphere.tables.sky_view_table(r, up.dot(sun)),
            radius_m: r,
            up,
            sun,
        }
    }

    /// Sky radiance arriving from `dir` (the sun's disc excluded), for a unit sun.
    pub fn radiance(&self, air: &Air, dir: Vec3) -> Vec3 {
        let (elevation, azimuth) = local_angles(self.up, dir, self.sun);
        self.table
            .sample(luts::sky_view_uv(air, self.radius_m, elevation, azimuth))
    }
}

#[cfg(test)]
mod tests;
