//! The light around the clouds: the sun, the sky and the haze between the eye and what it sees.
//!
//! This is the environment interface every technique and the compositor light with. On the GPU it
//! is bind group [`crate::shader::ENVIRONMENT_GROUP`] and the functions of `environment.wgsl`:
//!
//! - `environment_sun_direction()`, `environment_sun_irradiance(p)`: the sun as it reaches `p`;
//! - `environment_sun_disc_radiance(dir)`: the disc seen by the eye;
//! - `environment_sky_radiance(dir)`, `environment_sky_mean_radiance_up(p)`,
//!   `environment_sky_irradiance_up(p)`: the sky;
//! - `environment_aerial_perspective(radiance, coverage, distance_m)`: the haze, applied once, in
//!   compositing.
//!
//! A physical atmosphere replaces this module's WGSL and uniform behind the same functions, without
//! touching a technique. [`Environment`] is the CPU twin: the path tracer lights with it, and probe
//! tests hold the GPU functions against it.

mod gpu;

pub use gpu::{EnvironmentGpu, EnvironmentUniform};

use crate::frame::direction_from_angles_deg;
use crate::scene::{Scene, SkyModel};
use glam::Vec3;
use std::f32::consts::{PI, TAU};

/// `-ln(0.02)`: visibility is the distance at which haze leaves 2 % contrast, so the haze extinction
/// is 3.912 / visibility (Koschmieder 1924).
pub const KOSCHMIEDER_CONTRAST: f32 = 3.912;

/// The sky's radiance by direction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SkyRadiance {
    /// Radiance straight up.
    pub zenith: Vec3,
    /// Radiance at and below the horizon.
    pub horizon: Vec3,
    /// Blend exponent: `mix(horizon, zenith, mu^exponent)` for mu = dir.y >= 0.
    pub exponent: f32,
    /// Extinction of the haze between the eye and distant objects, m^-1.
    pub haze_per_m: f32,
}

impl SkyRadiance {
    /// The sky of a scene; a constant sky has equal zenith and horizon.
    pub fn from_scene(scene: &Scene) -> SkyRadiance {
        let s = &scene.sky;
        let haze_per_m = KOSCHMIEDER_CONTRAST / s.visibility_m;
        match s.model {
            SkyModel::Constant => SkyRadiance {
                zenith: s.radiance.into(),
                horizon: s.radiance.into(),
                exponent: 1.0,
                haze_per_m,
            },
            SkyModel::Gradient => SkyRadiance {
                zenith: s.zenith_radiance.into(),
                horizon: s.horizon_radiance.into(),
                exponent: s.gradient_exponent,
                haze_per_m,
            },
        }
    }

    /// Radiance arriving from direction `dir` (unit).
    pub fn radiance(&self, dir: Vec3) -> Vec3 {
        self.horizon
            .lerp(self.zenith, dir.y.max(0.0).powf(self.exponent))
    }

    /// Mean radiance over the upper hemisphere, `(1 / 2 pi) int L dw = int_0^1 L(mu) dmu`.
    pub fn mean_radiance_up(&self) -> Vec3 {
        self.horizon.lerp(self.zenith, 1.0 / (1.0 + self.exponent))
    }

    /// Irradiance on an upward-facing surface, `2 pi int_0^1 L(mu) mu dmu`.
    pub fn irradiance_up(&self) -> Vec3 {
        PI * self.horizon.lerp(self.zenith, 2.0 / (2.0 + self.exponent))
    }
}

/// The sun, a uniform disc.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SunDisc {
    /// Unit vector toward the centre of the disc.
    pub direction: Vec3,
    /// Irradiance on a surface facing the sun (the disc's radiance integrated over it).
    pub irradiance: Vec3,
    /// Cosine of the angular radius.
    pub cos_radius: f32,
}

impl SunDisc {
    /// Radiance seen in direction `dir`: `E / Omega` inside the disc of solid angle
    /// `Omega = 2 pi (1 - cos r)`, zero outside and for a point sun. The compositor draws this
    /// disc and the path tracer sees it.
    pub fn radiance(&self, dir: Vec3) -> Vec3 {
        let solid_angle = TAU * (1.0 - self.cos_radius);
        if solid_angle > 0.0 && dir.dot(self.direction) >= self.cos_radius {
            self.irradiance / solid_angle
        } else {
            Vec3::ZERO
        }
    }
}

/// Sun, sky and haze: the CPU twin of `environment.wgsl`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Environment {
    /// The sun.
    pub sun: SunDisc,
    /// The sky and its haze.
    pub sky: SkyRadiance,
}

impl Environment {
    /// The environment a scene describes.
    pub fn from_scene(scene: &Scene) -> Environment {
        let s = &scene.sun;
        Environment {
            sun: SunDisc {
                direction: direction_from_angles_deg(s.elevation_deg, s.azimuth_deg),
                irradiance: Vec3::from_array(s.color) * s.irradiance,
                cos_radius: s.angular_radius_deg.to_radians().cos(),
            },
            sky: SkyRadiance::from_scene(scene),
        }
    }

    /// What the eye sees of `radiance` (scattered by something covering fraction `coverage` of
    /// the pixel) from `distance_m` away through the haze: it fades toward the horizon radiance by
    /// `exp(-haze distance)` (Koschmieder 1924), weighted by the coverage.
    pub fn aerial_perspective(&self, radiance: Vec3, coverage: f32, distance_m: f32) -> Vec3 {
        let clear = (-self.sky.haze_per_m * distance_m).exp();
        radiance * clear + self.sky.horizon * coverage * (1.0 - clear)
    }

    /// Radiance leaving a Lambertian ground of `albedo` under the unshadowed sun and sky:
    /// `albedo / pi * (E_sun max(0, sun.y) + E_sky)`.
    pub fn ground_radiance(&self, albedo: Vec3) -> Vec3 {
        let irradiance =
            self.sun.irradiance * self.sun.direction.y.max(0.0) + self.sky.irradiance_up();
        albedo * irradiance / PI
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sky_moments_match_quadrature() {
        let sky = SkyRadiance {
            zenith: Vec3::new(0.1, 0.2, 0.5),
            horizon: Vec3::new(0.4, 0.5, 0.6),
            exponent: 0.45,
            haze_per_m: 0.0,
        };
        let n = 20_000;
        let (mut mean, mut irr) = (Vec3::ZERO, Vec3::ZERO);
        for i in 0..n {
            let mu = (i as f32 + 0.5) / n as f32;
            let l = sky.radiance(Vec3::new((1.0 - mu * mu).sqrt(), mu, 0.0));
            mean += l / n as f32;
            irr += l * mu * 2.0 * PI / n as f32;
        }
        assert!(mean.abs_diff_eq(sky.mean_radiance_up(), 1e-3));
        assert!(irr.abs_diff_eq(sky.irradiance_up(), 1e-3));
    }

    #[test]
    fn the_sun_disc_integrates_to_the_sun_irradiance() {
        let env = Environment::from_scene(&Scene::default());
        let sun = env.sun;
        // Integrate the disc's radiance over a cap slightly wider than it, in cos theta.
        let (n, cap) = (200_000, 1.0 - 2.0 * (1.0 - sun.cos_radius));
        let frame = glam::Mat3::from_quat(glam::Quat::from_rotation_arc(Vec3::Y, sun.direction));
        let mut total = Vec3::ZERO;
        for i in 0..n {
            let mu = cap + (1.0 - cap) * (i as f32 + 0.5) / n as f32;
            let dir = frame * Vec3::new((1.0 - mu * mu).max(0.0).sqrt(), mu, 0.0);
            total += sun.radiance(dir) * TAU * (1.0 - cap) / n as f32;
        }
        // f32 resolves cos theta near 1 to about 6e-8, 0.5 % of the disc's 1 - cos r = 1.1e-5.
        let relative = (total - sun.irradiance).abs().max_element() / sun.irradiance.max_element();
        assert!(relative < 0.02, "{total} vs {}", sun.irradiance);
    }
}
