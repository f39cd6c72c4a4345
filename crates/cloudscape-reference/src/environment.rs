//! The light and the surfaces around the clouds: the sun disc, the sky, the ground and the haze,
//! exactly as the frame of the GPU techniques defines them (`cloudscape::frame::Frame`).

use crate::geometry::{ground_distance, up};
use crate::sampling::{
    UNIFORM_HEMISPHERE_PDF, UNIFORM_SPHERE_PDF, uniform_hemisphere, uniform_sphere,
};
use cloudscape::field::PlanetGeometry;
use cloudscape::frame::{Frame, SkyRadiance};
use glam::{Vec2, Vec3};
use std::f32::consts::TAU;

/// How far above the ground a path leaving it starts, metres: a few `f32` steps at 200 km from the
/// origin, far below any cloud detail.
const GROUND_OFFSET_M: f32 = 0.05;

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
    /// `Omega = 2 pi (1 - cos r)`, zero outside and for a point sun.
    pub fn radiance(&self, dir: Vec3) -> Vec3 {
        let solid_angle = TAU * (1.0 - self.cos_radius);
        if solid_angle > 0.0 && dir.dot(self.direction) >= self.cos_radius {
            self.irradiance / solid_angle
        } else {
            Vec3::ZERO
        }
    }
}

/// Sun, sky, ground and haze.
#[derive(Clone, Debug, PartialEq)]
pub struct Environment {
    /// The sun; None when its irradiance is zero.
    pub sun: Option<SunDisc>,
    /// Sky radiance by direction, and the haze extinction.
    pub sky: SkyRadiance,
    /// The planet (for the ground and for "up").
    pub planet: PlanetGeometry,
    /// Lambertian albedo of the ground; None without a ground.
    pub ground_albedo: Option<Vec3>,
}

/// A point on the ground, lifted by [`GROUND_OFFSET_M`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GroundPoint {
    /// Where paths leave from.
    pub position: Vec3,
    /// Unit normal.
    pub normal: Vec3,
}

impl Environment {
    /// The environment of a frame over `planet`.
    pub fn from_frame(frame: &Frame, planet: PlanetGeometry) -> Environment {
        let sun = (frame.sun_irradiance.max_element() > 0.0).then(|| SunDisc {
            direction: frame.sun_direction,
            irradiance: frame.sun_irradiance,
            cos_radius: frame.sun_angular_radius_rad.cos(),
        });
        Environment {
            sun,
            sky: frame.sky,
            planet,
            ground_albedo: frame.ground_albedo,
        }
    }

    /// Distance to the ground along the ray, infinite without a ground or when it is missed.
    pub fn ground_distance(&self, origin: Vec3, dir: Vec3) -> f32 {
        if self.ground_albedo.is_none() {
            return f32::INFINITY;
        }
        ground_distance(&self.planet, origin, dir)
    }

    /// The ground point near `p` (a ray's hit), with its normal.
    pub fn ground_point(&self, p: Vec3) -> GroundPoint {
        let normal = up(&self.planet, p);
        let lifted = p + normal * (GROUND_OFFSET_M - self.planet.altitude_m(p));
        GroundPoint {
            position: lifted,
            normal,
        }
    }

    /// Sky radiance arriving from `dir` (the sun disc excluded).
    pub fn sky_radiance(&self, dir: Vec3) -> Vec3 {
        self.sky.radiance(dir)
    }

    /// What the eye sees of radiance `radiance` from `distance_m` away through the haze: it
    /// fades toward the horizon radiance by `exp(-haze distance)` (Koschmieder 1924), the same
    /// blend the GPU compose and ray-march passes apply (`frame_haze` in `frame.wgsl`).
    pub fn through_haze(&self, radiance: Vec3, distance_m: f32) -> Vec3 {
        let clear = (-self.sky.haze_per_m * distance_m).exp();
        radiance * clear + self.sky.horizon * (1.0 - clear)
    }

    /// A direction toward the sky for next-event estimation at `p`: uniform over the hemisphere
    /// above `p` when there is a ground (which hides everything below: from a point above a
    /// convex ground, no direction above its horizontal hits the ground), uniform over the sphere
    /// otherwise. Returns the direction and its density.
    pub fn sample_sky(&self, p: Vec3, u: Vec2) -> (Vec3, f32) {
        if self.ground_albedo.is_some() {
            (
                uniform_hemisphere(up(&self.planet, p), u),
                UNIFORM_HEMISPHERE_PDF,
            )
        } else {
            (uniform_sphere(u), UNIFORM_SPHERE_PDF)
        }
    }

    /// Density of [`Environment::sample_sky`] at `p` for `dir`, per steradian.
    pub fn sky_pdf(&self, p: Vec3, dir: Vec3) -> f32 {
        if self.ground_albedo.is_none() {
            UNIFORM_SPHERE_PDF
        } else if dir.dot(up(&self.planet, p)) > 0.0 {
            UNIFORM_HEMISPHERE_PDF
        } else {
            0.0
        }
    }
}
