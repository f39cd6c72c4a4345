//! The radiance estimator: a volumetric path tracer with next-event estimation (pbrt-v4's
//! `VolPathIntegrator` and Mitsuba 3's `volpath` follow the same plan).
//!
//! Per camera sample: delta tracking finds the first real collision (or the ground, or nothing:
//! then the sky and the sun disc are seen directly). At every scattering vertex:
//!
//! - the sun: one direction uniform over its disc, weighted by the phase function (or the
//!   Lambertian BRDF on the ground) and by ratio-tracked transmittance, combined by the power
//!   heuristic with continuations that leave the medium through the disc;
//! - the sky (in the medium): one direction from [`Environment::sample_sky`], combined with the
//!   phase-sampled continuation by the power heuristic (Veach 1997, "Robust Monte Carlo Methods
//!   for Light Transport Simulation", section 9.2); on the ground the cosine-sampled continuation
//!   alone gathers the sky (it already samples the BRDF times cosine exactly);
//! - the continuation: the phase function sampled exactly (or the cosine-weighted hemisphere on
//!   the ground), mixed with a narrow lobe about the sun that finds the forward-scattered aureole.
//!
//! Throughput is multiplied by the single-scattering albedo at each collision and by the ground
//! albedo at each bounce; Russian roulette on a low throughput ends paths without bias. Paths have
//! no practical bounce limit ([`MAX_SCATTERING_EVENTS`]).
//!
//! Haze: the GPU passes blend what the eye sees toward the horizon radiance by the distance of
//! what it sees. Here the primary vertex's radiance is blended by its distance, which is the same
//! blend in expectation; light between vertices is not hazed (as on the GPU).

use crate::environment::{Environment, GroundPoint, SunDisc};
use crate::medium::Medium;
use crate::rng::Rng;
use crate::tracking::TrackedMedium;
use cloudscape::frame::Frame;
use cloudscape::optics::PhaseLobes;
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

/// Scattering events after which a path is abandoned: a guard against endless loops, not a bounce
/// cap (the longest diffusion paths in a 9 km cumulonimbus core take some 10^4 events).
pub const MAX_SCATTERING_EVENTS: u32 = 1 << 20;

/// Where a path scatters.
#[derive(Clone, Copy, Debug)]
enum Vertex {
    /// In the medium at `position`, reached travelling along `dir`.
    Medium { position: Vec3, dir: Vec3 },
    /// On the ground.
    Ground(GroundPoint),
}

/// A continuation direction, the factor it multiplies the throughput by, its density, and the
/// density of sky sampling for it (0 where the sky's next-event estimation did not compete).
struct Continuation {
    dir: Vec3,
    weight: Vec3,
    pdf: f32,
    sky_pdf: f32,
}

/// Everything one path tracer renders: the tracked medium, its optics, the environment and the
/// camera.
pub struct PathTracer<M> {
    /// The clouds and their majorants.
    pub volume: TrackedMedium<M>,
    /// Phase function of the cloud droplets.
    pub phase: PhaseLobes,
    /// Single-scattering albedo sigma_s / sigma_t, 0..1.
    pub albedo: f32,
    /// Sun, sky, ground, haze.
    pub environment: Environment,
    /// Camera (rays, far distance, image size).
    pub frame: Frame,
    /// Scattering orders counted: light scattered more often is dropped (1 gives single
    /// scattering); [`MAX_SCATTERING_EVENTS`] for the full transport.
    pub max_scattering_orders: u32,
}

impl<M: Medium> PathTracer<M> {
    /// One estimate of the radiance through the image point `pixel` (pixel units, y down).
    pub fn radiance(&self, pixel: Vec2, rng: &mut Rng) -> Vec3 {
        let (origin, dir) = self.frame.camera_ray(pixel);
        self.ray_radiance(origin, dir, self.frame.far_m, rng)
    }

    /// One estimate of the radiance arriving at `origin` from direction `-dir` (what a camera at
    /// `origin` looking along `dir` sees), with the medium and the ground seen no farther than
    /// `far_m` (as the GPU techniques march no farther than the camera's far distance).
    pub fn ray_radiance(&self, origin: Vec3, dir: Vec3, far_m: f32, rng: &mut Rng) -> Vec3 {
        let env = &self.environment;
        let ground_m = env.ground_distance(origin, dir);
        let t_max = far_m.min(ground_m);
        let (vertex, distance_m) = match self.volume.free_flight(origin, dir, t_max, rng) {
            Some(t) => (
                Vertex::Medium {
                    position: origin + dir * t,
                    dir,
                },
                t,
            ),
            None if ground_m.is_finite() && ground_m <= far_m => (
                Vertex::Ground(env.ground_point(origin + dir * ground_m)),
                ground_m,
            ),
            None => {
                return env.sky_radiance(dir) + env.sun_disc_radiance(origin, dir);
            }
        };
        env.through_haze(self.path_radiance(vertex, rng), dir, distance_m)
    }

    /// Radiance leaving `vertex` toward where the path came from.
    fn path_radiance(&self, mut vertex: Vertex, rng: &mut Rng) -> Vec3 {
        let mut throughput = Vec3::ONE;
        let mut radiance = Vec3::ZERO;
        for events in 0..self.max_scattering_orders.min(MAX_SCATTERING_EVENTS) {
            if matches!(vertex, Vertex::Medium { .. }) {
                throughput *= self.albedo;
            }
            let guided = events < SUN_GUIDED_EVENTS;
            radiance += throughput
                * (self.sun_light(vertex, guided, rng) + self.sky_light(vertex, guided, rng));
            let next = self.continue_from(vertex, guided, rng);
            throughput *= next.weight;
            if !roulette(&mut throughput, rng) {
                break;
            }
            let origin = position(vertex);
            let ground_m = self.environment.ground_distance(origin, next.dir);
            vertex = match self.volume.free_flight(origin, next.dir, ground_m, rng) {
                Some(t) => Vertex::Medium {
                    position: origin + next.dir * t,
                    dir: next.dir,
                },
                None if ground_m.is_finite() => {
                    Vertex::Ground(self.environment.ground_point(origin + next.dir * ground_m))
                }
                None => {
                    let weight = power_heuristic(next.pdf, next.sky_pdf);
                    radiance += throughput * self.environment.sky_radiance(next.dir) * weight;
                    radiance += throughput * self.sun_reached(origin, next.dir, next.pdf);
                    break;
                }
            };
        }
        radiance
    }

    /// Transmittance from `origin` toward `dir` to infinity; zero when the ground is in the way.
    fn visibility(&self, origin: Vec3, dir: Vec3, rng: &mut Rng) -> f32 {
        if self.environment.ground_distance(origin, dir).is_finite() {
            return 0.0;
        }
        self.volume.transmittance(origin, dir, f32::INFINITY, rng)
    }

    /// Next-event estimate of the sun's light scattered at `vertex` toward the path, weighted
    /// against the continuation's chance of reaching the disc by the power heuristic (the
    /// continuation's share is [`Self::sun_reached`]). Without the weighting, a phase function
    /// whose forward peak is narrower than the disc (cloud droplets' is about 0.3 degrees) turns
    /// the rare vertices whose path points at the sun into fireflies.
    fn sun_light(&self, vertex: Vertex, guided: bool, rng: &mut Rng) -> Vec3 {
        let Some(sun) = self.environment.sun else {
            return Vec3::ZERO;
        };
        let dir = crate::sampling::uniform_cone(sun.direction, sun.cos_radius, rng.next_vec2());
        let (scattering, continuation_pdf) = self.scattering(vertex, guided, dir);
        if scattering.max_element() <= 0.0 {
            return Vec3::ZERO;
        }
        // Uniform over the disc: radiance E / Omega over density 1 / Omega leaves E.
        let weight = match sun_disc_pdf(&sun) {
            Some(pdf) => power_heuristic(pdf, continuation_pdf),
            None => 1.0,
        };
        let p = position(vertex);
        self.environment.sun_irradiance(p) * scattering * (weight * self.visibility(p, dir, rng))
    }

    /// The sun disc's radiance seen by a continuation that left the medium from `origin` along
    /// `dir` (drawn with density `pdf`), weighted against the sun's next-event estimate.
    fn sun_reached(&self, origin: Vec3, dir: Vec3, pdf: f32) -> Vec3 {
        let Some(sun) = self.environment.sun else {
            return Vec3::ZERO;
        };
        match sun_disc_pdf(&sun) {
            Some(light_pdf) if dir.dot(sun.direction) >= sun.cos_radius => {
                self.environment.sun_disc_radiance(origin, dir) * power_heuristic(pdf, light_pdf)
            }
            _ => Vec3::ZERO,
        }
    }

    /// Next-event estimate of the sky's light scattered at a medium vertex, weighted against
    /// the continuation's sampling by the power heuristic.
    fn sky_light(&self, vertex: Vertex, guided: bool, rng: &mut Rng) -> Vec3 {
        let Vertex::Medium { position, .. } = vertex else {
            return Vec3::ZERO;
        };
        let (sky_dir, sky_pdf) = self.environment.sample_sky(position, rng.next_vec2());
        let (phase, continuation_pdf) = self.scattering(vertex, guided, sky_dir);
        let weight = power_heuristic(sky_pdf, continuation_pdf);
        if weight <= 0.0 {
            return Vec3::ZERO;
        }
        let transmittance = self.visibility(position, sky_dir, rng);
        self.environment.sky_radiance(sky_dir) * phase * (weight * transmittance / sky_pdf)
    }

    /// Lambertian BRDF of the ground, `albedo / pi`.
    fn ground_brdf(&self) -> Vec3 {
        self.environment.ground_albedo.unwrap_or(Vec3::ZERO) / PI
    }

    /// The sun lobe that continuations are partly drawn from: its direction and shape; None
    /// without a sun or where the vertex is not `guided`.
    fn sun_guide(&self, guided: bool) -> Option<(Vec3, PhaseLobes)> {
        let sun = self.environment.sun.filter(|_| guided)?;
        Some((sun.direction, PhaseLobes::henyey_greenstein(SUN_GUIDE_G)))
    }

    /// At `vertex`, for leaving toward `next`: the scattering factor (phase function, or BRDF
    /// times cosine) and the density of the continuation sampling, the mixture of the vertex's
    /// own sampling and the sun lobe.
    fn scattering(&self, vertex: Vertex, guided: bool, next: Vec3) -> (Vec3, f32) {
        let (value, own_pdf) = match vertex {
            Vertex::Medium { dir, .. } => {
                let p = self.phase.eval(dir.dot(next));
                (Vec3::splat(p), p)
            }
            Vertex::Ground(g) => {
                let cos = g.normal.dot(next).max(0.0);
                (self.ground_brdf() * cos, cos / PI)
            }
        };
        let pdf = match self.sun_guide(guided) {
            Some((toward, lobe)) => {
                SUN_GUIDE_PROBABILITY * lobe.eval(toward.dot(next))
                    + (1.0 - SUN_GUIDE_PROBABILITY) * own_pdf
            }
            None => own_pdf,
        };
        (value, pdf)
    }

    /// Samples the direction a path leaves `vertex` in: the phase function (or the cosine-weighted
    /// hemisphere on the ground), or with probability [`SUN_GUIDE_PROBABILITY`] a narrow lobe
    /// about the sun. The sun lobe finds the bright aureole that the forward peak of cloud
    /// droplets makes around the sun in thin cloud, which the other sampling finds only rarely
    /// and then as a firefly; the throughput weight `f / (mixture pdf)` keeps it unbiased
    /// (one-sample multiple importance sampling, Veach 1997, section 9.2.4). Only the first
    /// [`SUN_GUIDED_EVENTS`] vertices of a path are `guided`: the weight `f / pdf` of the
    /// mixture is up to `1 / (1 - p)` away from the sun, and over the hundreds of bounces of a
    /// cloud path such factors would multiply into fireflies.
    fn continue_from(&self, vertex: Vertex, guided: bool, rng: &mut Rng) -> Continuation {
        let guide = self.sun_guide(guided);
        let dir = match (guide, vertex) {
            (Some((toward, lobe)), _) if rng.next_f32() < SUN_GUIDE_PROBABILITY => {
                lobe.sample(toward, rng.next_vec3())
            }
            (_, Vertex::Medium { dir, .. }) => self.phase.sample(dir, rng.next_vec3()),
            (_, Vertex::Ground(g)) => crate::sampling::cosine_hemisphere(g.normal, rng.next_vec2()),
        };
        let (value, pdf) = self.scattering(vertex, guided, dir);
        let sky_pdf = match vertex {
            Vertex::Medium { position, .. } => self.environment.sky_pdf(position, dir),
            Vertex::Ground(_) => 0.0,
        };
        Continuation {
            dir,
            weight: if pdf > 0.0 { value / pdf } else { Vec3::ZERO },
            pdf,
            sky_pdf,
        }
    }
}

/// Probability of drawing a continuation from the sun lobe instead of the vertex's own sampling.
const SUN_GUIDE_PROBABILITY: f32 = 0.25;
/// Vertices of a path (counted from the first) whose continuation is partly drawn from the sun lobe:
/// the ground and the cloud surfaces first seen, where the aureole shows.
const SUN_GUIDED_EVENTS: u32 = 2;
/// Asymmetry of the Henyey-Greenstein sun lobe: half its peak within 0.36 degrees of the sun, the
/// width of the sun disc blurred by the forward peak of 20 um droplets.
const SUN_GUIDE_G: f32 = 0.992;

/// Below this largest throughput component, paths play Russian roulette.
const ROULETTE_THRESHOLD: f32 = 0.25;

/// Russian roulette (Arvo & Kirk 1990, "Particle Transport and Image Synthesis"): a path whose
/// throughput `beta` has fallen below [`ROULETTE_THRESHOLD`] survives with probability
/// `max(beta) / threshold` and then carries `beta * threshold / max(beta)`, which keeps every
/// estimate unbiased. Returns whether the path goes on.
pub(crate) fn roulette(throughput: &mut Vec3, rng: &mut Rng) -> bool {
    let largest = throughput.max_element();
    if largest >= ROULETTE_THRESHOLD {
        return true;
    }
    let survival = largest / ROULETTE_THRESHOLD;
    if survival <= 0.0 || rng.next_f32() >= survival {
        return false;
    }
    *throughput /= survival;
    true
}

/// Where paths leave a vertex from.
fn position(vertex: Vertex) -> Vec3 {
    match vertex {
        Vertex::Medium { position, .. } => position,
        Vertex::Ground(g) => g.position,
    }
}

/// Density of the sun's next-event directions (uniform over the disc), None for a point sun.
fn sun_disc_pdf(sun: &SunDisc) -> Option<f32> {
    let solid_angle = 2.0 * PI * (1.0 - sun.cos_radius);
    (solid_angle > 0.0).then(|| 1.0 / solid_angle)
}

/// Power heuristic with exponent 2 (Veach 1997): the weight of a sample drawn with density `a`
/// when density `b` could also have drawn it.
fn power_heuristic(a: f32, b: f32) -> f32 {
    let (a2, b2) = (a * a, b * b);
    if a2 + b2 > 0.0 { a2 / (a2 + b2) } else { 0.0 }
}
