//! Shared set-up of the validation tests: analytic media under simple skies.

pub mod adding_doubling;

use cloudscape::environment::SkyRadiance;
use cloudscape::field::PlanetGeometry;
use cloudscape::frame::Frame;
use cloudscape::optics::PhaseLobes;
use cloudscape::scene::{PlanetShape, Scene};
use cloudscape_reference::PathTracer;
use cloudscape_reference::environment::{Environment, SunDisc};
use cloudscape_reference::geometry::Aabb;
use cloudscape_reference::medium::HomogeneousBox;
use cloudscape_reference::rng::Rng;
use cloudscape_reference::tracking::TrackedMedium;
use glam::{UVec2, Vec3};

/// A flat planet (only "up" matters: these scenes have no ground).
pub const FLAT: PlanetGeometry = PlanetGeometry {
    shape: PlanetShape::Flat,
    radius_m: 6_360_000.0,
};

/// A sky of radiance `upper` over the upper hemisphere and `lower` below, without haze.
pub fn two_tone_sky(upper: f32, lower: f32) -> SkyRadiance {
    SkyRadiance {
        zenith: Vec3::splat(upper),
        horizon: Vec3::splat(lower),
        // mu^1e-6 is 1 to within 1e-5 for every mu above 1e-4 and 0 at and below the horizon.
        exponent: 1e-6,
        haze_per_m: 0.0,
    }
}

/// An environment of `sky` and an optional sun, no ground.
pub fn environment(sky: SkyRadiance, sun: Option<SunDisc>) -> Environment {
    Environment {
        sun,
        sky,
        planet: FLAT,
        ground_albedo: None,
        atmosphere: None,
    }
}

/// A sun of irradiance 1 along `direction`, with angular radius `radius_deg` and no limb darkening.
pub fn sun(direction: Vec3, radius_deg: f32) -> SunDisc {
    SunDisc {
        direction,
        irradiance: Vec3::ONE,
        cos_radius: radius_deg.to_radians().cos(),
        limb_darkening: 0.0,
    }
}

/// A path tracer of `medium` in `environment`; the camera is the default scene's at `size`.
pub fn tracer(
    medium: HomogeneousBox,
    phase: PhaseLobes,
    albedo: f32,
    environment: Environment,
    size: UVec2,
) -> PathTracer<HomogeneousBox> {
    PathTracer {
        volume: TrackedMedium::new(medium, 64),
        phase,
        albedo,
        environment,
        frame: Frame::from_scene(&Scene::default(), size),
        max_scattering_orders: cloudscape_reference::integrator::MAX_SCATTERING_EVENTS,
    }
}

/// A slab of optical depth `tau` between y = 0 and y = 100 m, 200 km wide.
pub fn slab(tau: f32) -> HomogeneousBox {
    HomogeneousBox {
        bounds: Aabb {
            min: Vec3::new(-1e5, 0.0, -1e5),
            max: Vec3::new(1e5, 100.0, 1e5),
        },
        extinction_per_m: tau / 100.0,
    }
}

/// Mean and standard error of `n` estimates.
pub fn mean_and_error(n: u64, mut estimate: impl FnMut(&mut Rng) -> f64) -> (f64, f64) {
    let (mut sum, mut sum_sq) = (0.0, 0.0);
    for i in 0..n {
        let x = estimate(&mut Rng::for_sample(0xC10D, 0, i));
        sum += x;
        sum_sq += x * x;
    }
    let mean = sum / n as f64;
    let variance = (sum_sq / n as f64 - mean * mean).max(0.0);
    (mean, (variance / n as f64).sqrt())
}
