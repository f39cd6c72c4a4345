//! The reference particle of the particle technique (`cloudscape::particles`) as a medium: one
//! ball of cloud, noisy or spherically symmetric, so that its precomputed tables can be checked
//! against the full transport. [`PathTracer::for_particle`] lights it by a sun alone.

use crate::environment::{Environment, SunDisc};
use crate::geometry::Aabb;
use crate::integrator::PathTracer;
use crate::medium::{Medium, Support};
use crate::tracking::TrackedMedium;
use cloudscape::environment::SkyRadiance;
use cloudscape::field::PlanetGeometry;
use cloudscape::frame::Frame;
use cloudscape::particles::ParticleTableSpec;
use cloudscape::particles::density::{RadialProfile, ReferenceParticle};
use cloudscape::scene::{PlanetShape, Scene};
use glam::{UVec2, Vec3};

/// The density inside the particle.
#[derive(Clone, Debug, PartialEq)]
pub enum ParticleShape {
    /// The noisy particle, as the optical-depth table sees it.
    Noisy(ReferenceParticle),
    /// The spherically symmetric particle of the scattering tables.
    Symmetric(RadialProfile),
}

/// One particle of radius `radius_m` centred at `centre_m`.
#[derive(Clone, Debug, PartialEq)]
pub struct ParticleMedium {
    /// Its density.
    pub shape: ParticleShape,
    /// Centre, m.
    pub centre_m: Vec3,
    /// Radius, m.
    pub radius_m: f32,
    /// Extinction where the density is 1, m^-1.
    pub extinction_per_m: f32,
}

impl Medium for ParticleMedium {
    fn extinction_per_m(&self, p: Vec3) -> f32 {
        let local = (p - self.centre_m) / self.radius_m;
        let density = match &self.shape {
            ParticleShape::Noisy(particle) => particle.density(local),
            ParticleShape::Symmetric(profile) => profile.at(local.length()),
        };
        self.extinction_per_m * density
    }

    fn max_extinction_in_box(&self, b: &Aabb) -> f32 {
        let nearest = self.centre_m.clamp(b.min, b.max).distance(self.centre_m);
        if nearest >= self.radius_m {
            return 0.0;
        }
        let farthest = (self.centre_m - b.min)
            .abs()
            .max((self.centre_m - b.max).abs())
            .length();
        let bound = match &self.shape {
            ParticleShape::Noisy(_) => 1.0,
            ParticleShape::Symmetric(profile) => {
                profile.max_between(nearest / self.radius_m, farthest / self.radius_m)
            }
        };
        self.extinction_per_m * bound
    }

    fn support(&self) -> Support {
        Support {
            grid_box: Aabb {
                min: self.centre_m - self.radius_m,
                max: self.centre_m + self.radius_m,
            },
            shell: None,
        }
    }
}

/// Majorant cells over one particle: 32^3.
const PARTICLE_MAJORANT_CELLS: usize = 1 << 15;

impl PathTracer<ParticleMedium> {
    /// The particle of `spec` (noisy, or symmetric as the scattering tables assume) at the
    /// origin, lit by a sun of unit irradiance shining along `light_dir` (the way its light
    /// travels), with a black sky and no ground: what the particle tables describe.
    pub fn for_particle(
        spec: &ParticleTableSpec,
        symmetric: bool,
        light_dir: Vec3,
    ) -> PathTracer<ParticleMedium> {
        let shape = if symmetric {
            ParticleShape::Symmetric(spec.symmetric_particle().profile)
        } else {
            ParticleShape::Noisy(spec.particle)
        };
        let medium = ParticleMedium {
            shape,
            centre_m: Vec3::ZERO,
            radius_m: spec.radius_m,
            extinction_per_m: spec.extinction_per_m,
        };
        let black = SkyRadiance {
            zenith: Vec3::ZERO,
            horizon: Vec3::ZERO,
            exponent: 1.0,
            haze_per_m: 0.0,
        };
        let environment = Environment {
            sun: Some(SunDisc {
                direction: -light_dir.normalize(),
                irradiance: Vec3::ONE,
                // The real sun (Bruneton 2017): as directional as the tables resolve, and wide
                // enough that sun and phase sampling share the forward peak without fireflies.
                cos_radius: 0.2679f32.to_radians().cos(),
                limb_darkening: 0.0,
            }),
            sky: black,
            planet: PlanetGeometry {
                shape: PlanetShape::Flat,
                radius_m: 6_360_000.0,
            },
            ground_albedo: None,
            atmosphere: None,
        };
        PathTracer {
            volume: TrackedMedium::new(medium, PARTICLE_MAJORANT_CELLS),
            phase: spec.phase,
            albedo: spec.albedo,
            environment,
            frame: Frame::from_scene(&Scene::default(), UVec2::ONE),
            max_scattering_orders: crate::integrator::MAX_SCATTERING_EVENTS,
        }
    }
}
