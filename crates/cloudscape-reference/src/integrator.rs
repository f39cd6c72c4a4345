//! The radiance estimator: a volumetric path tracer with next-event estimation (pbrt-v4's
//! `VolPathIntegrator` and Mitsuba 3's `volpath` follow the same plan).
//!
//! Per camera sample: delta tracking finds the first real collision (or the ground, or nothing:
//! then the sky and the sun disc are seen directly). At every scattering vertex:
//!
//! - the sun: one direction uniform over its disc, weighted by the phase function (or the
//!   Lambertian BRDF on the ground) and by ratio-tracked transmittance;
//! - the sun's forward peak, probed: one direction from a narrow lobe about the sun, followed to
//!   its next collision, where the sun is estimated as above ([`PathTracer::peak_probe`]);
//! - the sky (in the medium): one direction from [`Environment::sample_sky`], combined with the
//!   phase-sampled continuation by the power heuristic (Veach 1997, "Robust Monte Carlo Methods
//!   for Light Transport Simulation", section 9.2); on the ground the cosine-sampled continuation
//!   alone gathers the sky (it already samples the BRDF times cosine exactly);
//! - the continuation: the phase function sampled exactly (or the cosine-weighted hemisphere on
//!   the ground), so the throughput only ever falls.
//!
//! Sunlight reaches a path in three ways that overlap, and each path that sees the sun is weighted
//! against all three by the power heuristic ([`SunStrategies`]): the disc sampled from the vertex
//! before the sun, the continuation from that vertex leaving through the disc, and the probe from
//! the vertex before it.
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

    /// One estimate of the source function at `position` for light leaving toward `-dir`: the
    /// radiance the medium there scatters per unit extinction (the single-scattering albedo times
    /// the phase-weighted incident radiance), every order included. It is what a ray marcher's
    /// sample adds per unit optical depth, and what its lighting models are fitted to.
    pub fn source_radiance(&self, position: Vec3, dir: Vec3, rng: &mut Rng) -> Vec3 {
        self.path_radiance(Vertex::Medium { position, dir }, rng)
    }

    /// Radiance leaving `vertex` toward where the path came from.
    fn path_radiance(&self, mut vertex: Vertex, rng: &mut Rng) -> Vec3 {
        let mut throughput = Vec3::ONE;
        let mut radiance = Vec3::ZERO;
        let mut arrival = Arrival::FROM_CAMERA;
        for _ in 0..self.max_scattering_orders.min(MAX_SCATTERING_EVENTS) {
            if matches!(vertex, Vertex::Medium { .. }) {
                throughput *= self.albedo;
            }
            let sun = self.sun_light(vertex, arrival, Strategy::Disc, rng);
            let probe = self.peak_probe(vertex, rng);
            radiance += throughput * (sun + probe + self.sky_light(vertex, rng));
            let next = self.continue_from(vertex, rng);
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
                    radiance += throughput * self.sun_reached(origin, next.dir, next.pdf, arrival);
                    break;
                }
            };
            arrival = Arrival {
                continuation_pdf: next.pdf,
                probe_pdf: self.probe_pdf(next.dir),
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

    /// Next-event estimate of the sun's light scattered at `vertex` (reached by `arrival`) toward
    /// the path: one direction uniform over the disc, weighted as `strategy` among the ways
    /// sunlight reaches the path ([`SunStrategies`]).
    fn sun_light(
        &self,
        vertex: Vertex,
        arrival: Arrival,
        strategy: Strategy,
        rng: &mut Rng,
    ) -> Vec3 {
        let Some(sun) = self.environment.sun else {
            return Vec3::ZERO;
        };
        let dir = crate::sampling::uniform_cone(sun.direction, sun.cos_radius, rng.next_vec2());
        let (scattering, leave_pdf) = self.scattering(vertex, dir);
        if scattering.max_element() <= 0.0 {
            return Vec3::ZERO;
        }
        // Uniform over the disc: radiance E / Omega over density 1 / Omega leaves E.
        let weight = SunStrategies::new(&sun, arrival, leave_pdf).weight(strategy);
        if weight <= 0.0 {
            return Vec3::ZERO;
        }
        let p = position(vertex);
        self.environment.sun_irradiance(p) * scattering * (weight * self.visibility(p, dir, rng))
    }

    /// The sun disc's radiance seen by a continuation that left the medium from `origin` (reached
    /// by `arrival`) along `dir`, drawn with density `pdf`, weighted against the other ways
    /// sunlight reaches the path.
    fn sun_reached(&self, origin: Vec3, dir: Vec3, pdf: f32, arrival: Arrival) -> Vec3 {
        let Some(sun) = self.environment.sun else {
            return Vec3::ZERO;
        };
        let radiance = self.environment.sun_disc_radiance(origin, dir);
        if radiance.max_element() <= 0.0 {
            return Vec3::ZERO;
        }
        radiance * SunStrategies::new(&sun, arrival, pdf).weight(Strategy::Leaving)
    }

    /// Probes the forward peak of the sun: the light that reaches `vertex` after one more
    /// scattering within a few tenths of a degree of the sun's direction.
    ///
    /// Half of a cloud droplet's scattering stays within about 0.3 degrees (its diffraction
    /// peak), so at a collision whose path happens to point at the sun the disc's next-event
    /// estimate is thousands of times the usual one: a firefly, and the aureole of every deep
    /// vertex is made of them. The probe draws that direction on purpose, from a
    /// Henyey-Greenstein lobe about the sun ([`SUN_PROBE_G`]), follows it by delta tracking to its
    /// next collision and estimates the sun there; the regular estimate at such a collision gives
    /// way to it by the power heuristic, since the lobe draws those directions far more often than
    /// the phase function does. It is a dead end (the path goes on from `vertex` by its own
    /// continuation), so unlike a continuation mixed with the lobe it never multiplies the
    /// throughput by more than one. One-sample MIS over sampling techniques: Veach 1997,
    /// section 9.2.
    fn peak_probe(&self, vertex: Vertex, rng: &mut Rng) -> Vec3 {
        let Some(sun) = self.environment.sun else {
            return Vec3::ZERO;
        };
        let lobe = PhaseLobes::henyey_greenstein(SUN_PROBE_G);
        let dir = lobe.sample(sun.direction, rng.next_vec3());
        let (value, continuation_pdf) = self.scattering(vertex, dir);
        let probe_pdf = self.probe_pdf(dir);
        if value.max_element() <= 0.0 || probe_pdf <= 0.0 {
            return Vec3::ZERO;
        }
        let origin = position(vertex);
        let ground_m = self.environment.ground_distance(origin, dir);
        let Some(t) = self.volume.free_flight(origin, dir, ground_m, rng) else {
            return Vec3::ZERO;
        };
        let collision = Vertex::Medium {
            position: origin + dir * t,
            dir,
        };
        let arrival = Arrival {
            continuation_pdf,
            probe_pdf,
        };
        value * (self.albedo / probe_pdf) * self.sun_light(collision, arrival, Strategy::Probe, rng)
    }

    /// Density with which [`Self::peak_probe`] draws `dir`; 0 without a sun.
    fn probe_pdf(&self, dir: Vec3) -> f32 {
        self.environment.sun.map_or(0.0, |sun| {
            cloudscape::optics::henyey_greenstein(SUN_PROBE_G, sun.direction.dot(dir))
        })
    }

    /// Next-event estimate of the sky's light scattered at a medium vertex, weighted against
    /// the continuation's sampling by the power heuristic.
    fn sky_light(&self, vertex: Vertex, rng: &mut Rng) -> Vec3 {
        let Vertex::Medium { position, .. } = vertex else {
            return Vec3::ZERO;
        };
        let (sky_dir, sky_pdf) = self.environment.sample_sky(position, rng.next_vec2());
        let (phase, continuation_pdf) = self.scattering(vertex, sky_dir);
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

    /// At `vertex`, for leaving toward `next`: the scattering factor (phase function, or BRDF
    /// times cosine) and the density with which the continuation draws `next`.
    fn scattering(&self, vertex: Vertex, next: Vec3) -> (Vec3, f32) {
        match vertex {
            Vertex::Medium { dir, .. } => {
                let p = self.phase.eval(dir.dot(next));
                (Vec3::splat(p), p)
            }
            Vertex::Ground(g) => {
                let cos = g.normal.dot(next).max(0.0);
                (self.ground_brdf() * cos, cos / PI)
            }
        }
    }

    /// Samples the direction a path leaves `vertex` in: the phase function exactly, or the
    /// cosine-weighted hemisphere on the ground; the throughput weight `f / pdf` is 1 (the albedo
    /// on the ground).
    fn continue_from(&self, vertex: Vertex, rng: &mut Rng) -> Continuation {
        let dir = match vertex {
            Vertex::Medium { dir, .. } => self.phase.sample(dir, rng.next_vec3()),
            Vertex::Ground(g) => crate::sampling::cosine_hemisphere(g.normal, rng.next_vec2()),
        };
        let (value, pdf) = self.scattering(vertex, dir);
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

/// How a path arrived at a vertex, as the vertex before saw it: the density its continuation drew
/// the direction with, and the density [`PathTracer::peak_probe`] would have drawn it with.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Arrival {
    continuation_pdf: f32,
    probe_pdf: f32,
}

impl Arrival {
    /// The camera's ray: fixed, so no probe could have drawn it.
    const FROM_CAMERA: Arrival = Arrival {
        continuation_pdf: 1.0,
        probe_pdf: 0.0,
    };
}

/// The ways a path ending `vertex before -> vertex -> sun` is drawn.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Strategy {
    /// Arrival by the continuation, the sun's direction from the disc (next-event estimation).
    Disc,
    /// Arrival by the continuation, the sun's direction by the continuation leaving the medium.
    Leaving,
    /// Arrival by the probe, the sun's direction from the disc.
    Probe,
}

/// The densities of one sunlit path under each [`Strategy`], for the power heuristic (Veach
/// 1997, section 9.2): each strategy's density is the product of the densities of the path's last
/// two directions under it.
struct SunStrategies {
    disc: f32,
    leaving: f32,
    probe: f32,
}

impl SunStrategies {
    /// The path that arrived by `arrival` and leaves toward the sun in a direction the vertex's
    /// continuation draws with density `leave_pdf`. A point sun has no disc to draw or leave
    /// through: its next-event estimate is a delta (density 1 against 0 for leaving).
    fn new(sun: &SunDisc, arrival: Arrival, leave_pdf: f32) -> SunStrategies {
        let (disc_pdf, leave_pdf) = sun_disc_pdf(sun).map_or((1.0, 0.0), |d| (d, leave_pdf));
        SunStrategies {
            disc: arrival.continuation_pdf * disc_pdf,
            leaving: arrival.continuation_pdf * leave_pdf,
            probe: arrival.probe_pdf * disc_pdf,
        }
    }

    /// The power-heuristic weight of `strategy`.
    fn weight(&self, strategy: Strategy) -> f32 {
        let own = match strategy {
            Strategy::Disc => self.disc,
            Strategy::Leaving => self.leaving,
            Strategy::Probe => self.probe,
        };
        let sum = self.disc * self.disc + self.leaving * self.leaving + self.probe * self.probe;
        if sum > 0.0 { own * own / sum } else { 0.0 }
    }
}

/// Asymmetry of the Henyey-Greenstein lobe of the sun probe: half its peak within 0.36 degrees of
/// the sun, the width of the sun disc blurred by the forward peak of 20 um droplets (whose HG lobe
/// has g = 0.9946, Jendersie & d'Eon 2023), and wider than that peak, so the ratio of the peak to
/// the lobe stays bounded.
const SUN_PROBE_G: f32 = 0.992;

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
