//! The air as a participating medium: Rayleigh and Mie scattering and ozone absorption in shells
//! over a spherical planet (Bruneton 2017, "Precomputed Atmospheric Scattering: a New
//! Implementation", and Hillaire 2020, "A Scalable and Production Ready Sky and Atmosphere
//! Rendering Technique"), and the ray geometry of those shells.
//!
//! Positions here are relative to the planet centre ("atmosphere space"); [`Air::position_of`]
//! maps a world point there.

use crate::optics::phase::draine;
use crate::scene::{PlanetShape, Scene};
use glam::Vec3;
use std::f32::consts::PI;

/// `-ln(0.02)`: visibility is the distance at which haze leaves 2 % contrast, so the haze extinction
/// is 3.912 / visibility (Koschmieder 1924).
pub const KOSCHMIEDER_CONTRAST: f32 = 3.912;

/// Earth's ground radius, metres (Bruneton 2017).
pub const EARTH_RADIUS_M: f32 = 6_360_000.0;
/// Height of the top of the atmosphere above the ground, metres (Hillaire 2020: 6460 - 6360 km).
pub const ATMOSPHERE_HEIGHT_M: f32 = 100_000.0;
/// Rayleigh scattering coefficient at sea level for 680, 550 and 440 nm, m^-1 (Bruneton 2017).
pub const RAYLEIGH_SCATTERING_PER_M: Vec3 = Vec3::new(5.802e-6, 13.558e-6, 33.1e-6);
/// Rayleigh density scale height, metres (Bruneton 2017).
pub const RAYLEIGH_SCALE_HEIGHT_M: f32 = 8_000.0;
/// Mie scattering coefficient at sea level of Bruneton's clear air, m^-1 (Bruneton 2017).
pub const MIE_SCATTERING_PER_M: f32 = 3.996e-6;
/// Mie extinction coefficient at sea level of Bruneton's clear air, m^-1 (Bruneton 2017).
pub const MIE_EXTINCTION_PER_M: f32 = 4.44e-6;
/// Mie density scale height, metres (Bruneton 2017).
pub const MIE_SCALE_HEIGHT_M: f32 = 1_200.0;
/// Mean cosine of the aerosols' Cornette-Shanks phase function (Bruneton 2017).
pub const MIE_MEAN_COSINE: f32 = 0.8;
/// Ozone absorption at the peak of its layer for 680, 550 and 440 nm, m^-1 (Bruneton 2017).
pub const OZONE_ABSORPTION_PER_M: Vec3 = Vec3::new(0.650e-6, 1.881e-6, 0.085e-6);
/// Altitude of the peak of ozone's tent profile, metres: 0 at 10 km, 1 at 25 km, 0 at 40 km
/// (Bruneton 2017).
pub const OZONE_PEAK_ALTITUDE_M: f32 = 25_000.0;
/// Half width of ozone's tent profile, metres (Bruneton 2017).
pub const OZONE_HALF_WIDTH_M: f32 = 15_000.0;

/// The air over a spherical planet, everything the sky's look-up tables depend on.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Air {
    /// Radius of the ground, metres.
    pub bottom_radius_m: f32,
    /// Radius of the top of the atmosphere, metres.
    pub top_radius_m: f32,
    /// Rayleigh scattering at the ground, m^-1 (RGB).
    pub rayleigh_scattering_per_m: Vec3,
    /// Mie scattering at the ground, m^-1 (grey).
    pub mie_scattering_per_m: f32,
    /// Mie extinction at the ground, m^-1 (grey).
    pub mie_extinction_per_m: f32,
    /// Ozone absorption at the peak of its layer, m^-1 (RGB).
    pub ozone_absorption_per_m: Vec3,
    /// Mean cosine of the Mie phase function.
    pub mie_g: f32,
    /// Lambertian albedo of the ground, for the light it sends back up into the air.
    pub ground_albedo: Vec3,
    /// Angular radius of the sun's disc, radians: how gradually the planet hides it at sunset.
    pub sun_angular_radius_rad: f32,
    /// Whether the world is flat: world points then sit above the planet's pole, at their height.
    pub flat_world: bool,
}

impl Air {
    /// The air of `scene`: Bruneton's Earth over the scene's planet (Earth's radius for a flat
    /// world), with as much aerosol as `sky.visibility_m` calls for.
    ///
    /// Visibility sets the extinction at the ground: `3.912 / V` (Koschmieder 1924) at 550 nm.
    /// What Rayleigh does not provide there is Mie, `(3.912 / V - rayleigh_g) / mie_extinction`
    /// times Bruneton's aerosol, so a hazy day has a thicker Mie layer of the same shape. Past 217
    /// km (the visibility of Bruneton's air) the aerosol is Bruneton's.
    pub fn from_scene(scene: &Scene) -> Air {
        let flat_world = scene.planet.shape == PlanetShape::Flat;
        let bottom_radius_m = if flat_world {
            EARTH_RADIUS_M
        } else {
            scene.planet.radius_m
        };
        let ground_extinction = KOSCHMIEDER_CONTRAST / scene.sky.visibility_m;
        let mie_scale =
            ((ground_extinction - RAYLEIGH_SCATTERING_PER_M.y) / MIE_EXTINCTION_PER_M).max(1.0);
        Air {
            bottom_radius_m,
            top_radius_m: bottom_radius_m + ATMOSPHERE_HEIGHT_M,
            rayleigh_scattering_per_m: RAYLEIGH_SCATTERING_PER_M,
            mie_scattering_per_m: MIE_SCATTERING_PER_M * mie_scale,
            mie_extinction_per_m: MIE_EXTINCTION_PER_M * mie_scale,
            ozone_absorption_per_m: OZONE_ABSORPTION_PER_M,
            mie_g: MIE_MEAN_COSINE,
            ground_albedo: Vec3::from_array(scene.ground.albedo),
            sun_angular_radius_rad: scene.sun.angular_radius_deg.to_radians(),
            flat_world,
        }
    }

    /// World point `p` in atmosphere space: relative to the planet centre `(0, -R, 0)`, or, for
    /// a flat world, straight above the centre at `p`'s height.
    pub fn position_of(&self, p: Vec3) -> Vec3 {
        let height = Vec3::new(0.0, p.y + self.bottom_radius_m, 0.0);
        if self.flat_world {
            height
        } else {
            Vec3::new(p.x, height.y, p.z)
        }
    }

    /// The medium at radius `r`: Rayleigh scattering, Mie scattering and extinction.
    pub fn at(&self, r: f32) -> AirSample {
        let h = (r - self.bottom_radius_m).max(0.0);
        let rayleigh = (-h / RAYLEIGH_SCALE_HEIGHT_M).exp();
        let mie = (-h / MIE_SCALE_HEIGHT_M).exp();
        let ozone = (1.0 - (h - OZONE_PEAK_ALTITUDE_M).abs() / OZONE_HALF_WIDTH_M).max(0.0);
        let rayleigh_scattering = self.rayleigh_scattering_per_m * rayleigh;
        let mie_scattering = self.mie_scattering_per_m * mie;
        AirSample {
            rayleigh_scattering,
            mie_scattering,
            extinction: rayleigh_scattering
                + Vec3::splat(self.mie_extinction_per_m * mie)
                + self.ozone_absorption_per_m * ozone,
        }
    }

    /// Rayleigh's phase function, `3 / (16 pi) (1 + mu^2)` (Rayleigh 1871), per steradian.
    pub fn rayleigh_phase(cos_theta: f32) -> f32 {
        3.0 / (16.0 * PI) * (1.0 + cos_theta * cos_theta)
    }

    /// The aerosols' Cornette-Shanks phase function (Cornette & Shanks 1992, as Bruneton 2017 and
    /// Hillaire 2020 use it): Draine's with `alpha = 1`.
    pub fn mie_phase(&self, cos_theta: f32) -> f32 {
        draine(self.mie_g, 1.0, cos_theta)
    }

    /// Distance from radius `r` along a ray of cosine `mu` to the top of the atmosphere (inside
    /// it: the far intersection).
    pub fn distance_to_top(&self, r: f32, mu: f32) -> f32 {
        let discriminant = r * r * (mu * mu - 1.0) + self.top_radius_m * self.top_radius_m;
        (-r * mu + discriminant.max(0.0).sqrt()).max(0.0)
    }

    /// Distance from radius `r` along a ray of cosine `mu` to the ground (the near intersection).
    pub fn distance_to_ground(&self, r: f32, mu: f32) -> f32 {
        let discriminant = r * r * (mu * mu - 1.0) + self.bottom_radius_m * self.bottom_radius_m;
        (-r * mu - discriminant.max(0.0).sqrt()).max(0.0)
    }

    /// Whether a ray from radius `r` with cosine `mu` hits the ground.
    pub fn hits_ground(&self, r: f32, mu: f32) -> bool {
        mu < 0.0 && r * r * (mu * mu - 1.0) + self.bottom_radius_m * self.bottom_radius_m >= 0.0
    }

    /// Where a ray from radius `r` with cosine `mu` leaves the air: the ground or the top.
    pub fn distance_to_boundary(&self, r: f32, mu: f32) -> f32 {
        if self.hits_ground(r, mu) {
            self.distance_to_ground(r, mu)
        } else {
            self.distance_to_top(r, mu)
        }
    }
}

/// The air's optical properties at one point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AirSample {
    /// Rayleigh scattering, m^-1.
    pub rayleigh_scattering: Vec3,
    /// Mie scattering, m^-1 (grey).
    pub mie_scattering: f32,
    /// Extinction of all three, m^-1.
    pub extinction: Vec3,
}

impl AirSample {
    /// Total scattering, m^-1.
    pub fn scattering(&self) -> Vec3 {
        self.rayleigh_scattering + Vec3::splat(self.mie_scattering)
    }
}

/// Radius and view cosine of the point `t` along a ray from radius `r` with cosine `mu`
/// (Bruneton 2017, the law of cosines).
pub fn advance(r: f32, mu: f32, t: f32) -> (f32, f32) {
    let r_t = (t * t + 2.0 * r * mu * t + r * r).max(0.0).sqrt();
    (r_t, ((r * mu + t) / r_t.max(1.0)).clamp(-1.0, 1.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ray_distances_agree_with_the_geometry() {
        let air = Air::from_scene(&Scene::default());
        let r = air.bottom_radius_m + 1000.0;
        assert!((air.distance_to_top(r, 1.0) - (ATMOSPHERE_HEIGHT_M - 1000.0)).abs() < 1.0);
        assert!((air.distance_to_ground(r, -1.0) - 1000.0).abs() < 1.0);
        assert!(!air.hits_ground(r, 0.0));
        assert!(air.hits_ground(r, -0.1));
        let t = air.distance_to_top(r, 0.3);
        let (r_t, _) = advance(r, 0.3, t);
        assert!((r_t - air.top_radius_m).abs() < 2.0, "{r_t}");
    }

    #[test]
    fn visibility_sets_the_ground_extinction() {
        let mut scene = Scene::default();
        scene.sky.visibility_m = 20_000.0;
        let air = Air::from_scene(&scene);
        let green = air.at(air.bottom_radius_m).extinction.y;
        assert!(
            (green * 20_000.0 - KOSCHMIEDER_CONTRAST).abs() < 1e-3,
            "{green}"
        );
        scene.sky.visibility_m = 10_000_000.0;
        let clear = Air::from_scene(&scene);
        assert_eq!(clear.mie_extinction_per_m, MIE_EXTINCTION_PER_M);
    }

    #[test]
    fn the_phase_functions_are_normalised() {
        let air = Air::from_scene(&Scene::default());
        let n = 20_000;
        let (mut rayleigh, mut mie) = (0.0, 0.0);
        for i in 0..n {
            let mu = -1.0 + 2.0 * (i as f32 + 0.5) / n as f32;
            rayleigh += Air::rayleigh_phase(mu) * 2.0 * PI * 2.0 / n as f32;
            mie += air.mie_phase(mu) * 2.0 * PI * 2.0 / n as f32;
        }
        assert!((rayleigh - 1.0).abs() < 1e-3 && (mie - 1.0).abs() < 1e-2);
    }
}
