//! The light and the surfaces around the clouds: the sun disc, the sky, the ground and the haze,
//! exactly as the GPU techniques see them (`cloudscape::environment` and `cloudscape::frame`).

use crate::geometry::{ground_distance, up};
use crate::sampling::{
    UNIFORM_HEMISPHERE_PDF, UNIFORM_SPHERE_PDF, uniform_hemisphere, uniform_sphere,
};
pub use cloudscape::environment::SunDisc;
use cloudscape::environment::{SkyModel, SkyRadiance, ViewedEnvironment};
use cloudscape::field::PlanetGeometry;
use cloudscape::frame::Frame;
use glam::{Vec2, Vec3};

/// How far above the ground a path leaving it starts, metres: a few `f32` steps at 200 km from the
/// origin, far below any cloud detail.
const GROUND_OFFSET_M: f32 = 0.05;

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
    /// The atmosphere seen from the camera, exactly as the GPU's environment (None for the
    /// analytic skies, which `sky` and `sun` describe alone).
    pub atmosphere: Option<ViewedEnvironment>,
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
    /// The environment the GPU techniques light with (`light`), seen from `frame`'s camera, with a
    /// ground of albedo `ground_albedo` (None: no ground) over `planet`.
    pub fn new(
        frame: &Frame,
        light: &cloudscape::environment::Environment,
        ground_albedo: Option<Vec3>,
        planet: PlanetGeometry,
    ) -> Environment {
        let sun = (light.sun.irradiance.max_element() > 0.0).then_some(light.sun);
        let atmosphere = (light.sky_model == SkyModel::Atmosphere)
            .then(|| ViewedEnvironment::new(light, frame.camera_position_m));
        Environment {
            sun,
            sky: light.sky,
            planet,
            ground_albedo,
            atmosphere,
        }
    }

    /// Sun irradiance reaching `p` on a surface facing the sun: through the air with the
    /// atmosphere (`environment_sun_irradiance`).
    pub fn sun_irradiance(&self, p: Vec3) -> Vec3 {
        match (&self.atmosphere, &self.sun) {
            (Some(a), _) => a.sun_irradiance(p),
            (None, Some(sun)) => sun.irradiance,
            (None, None) => Vec3::ZERO,
        }
    }

    /// Radiance of the sun's disc seen from `p` along `dir` (zero outside it).
    pub fn sun_disc_radiance(&self, p: Vec3, dir: Vec3) -> Vec3 {
        self.sun.map_or(Vec3::ZERO, |sun| {
            sun.radiance_of(self.sun_irradiance(p), dir)
        })
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

    /// Sky radiance arriving from `dir` (the sun disc excluded), as the camera sees it.
    pub fn sky_radiance(&self, dir: Vec3) -> Vec3 {
        match &self.atmosphere {
            Some(a) => a.sky_radiance(dir),
            None => self.sky.radiance(dir),
        }
    }

    /// What the eye sees of radiance `radiance` from `distance_m` away along `dir` through the
    /// air or haze: the aerial perspective the GPU compositor applies
    /// ([`ViewedEnvironment::aerial_perspective`] at full coverage), the air's sunlit
    /// in-scattering at distance `t` dimmed by `sun_visibility(t)`, the clouds' transmittance
    /// toward the sun there (the GPU reads it from the cloud shadow map: light shafts).
    pub fn through_haze(
        &self,
        radiance: Vec3,
        (dir, distance_m): (Vec3, f32),
        sun_visibility: impl FnMut(f32) -> f32,
    ) -> Vec3 {
        match &self.atmosphere {
            Some(a) => a.aerial_perspective((radiance, 1.0), (dir, distance_m), sun_visibility),
            None => {
                let clear = (-self.sky.haze_per_m * distance_m).exp();
                radiance * clear + self.sky.horizon * (1.0 - clear)
            }
        }
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
