//! Sunlight: next-event estimation over the disc, the continuation leaving through it, and the
//! forward-peak chain.
//!
//! **Why a chain.** Half of a cloud droplet's scattering stays within about 0.3 degrees of the
//! beam (the Henyey-Greenstein lobe of the approximate Mie function, the *peak*; the Draine lobe
//! is the *broad* rest). Deep in a cloud the sunlight is mostly a beam scattered many times within
//! that peak: it fades with about half the optical depth while the unscattered beam, the only
//! light the disc's next-event estimate sees, fades with all of it (e^-5 against e^-10 at optical
//! depth 10). A camera path gathers the peak-scattered beam only when a chain of its segments
//! happens to point within a degree of the sun, and then as a firefly worth hundreds of times its
//! pixel (`docs/lighting.md` logs them).
//!
//! **The split.** Each medium scattering of a path is either in the peak or broad: the phase
//! function is the sum of its two weighted lobes, so the radiance is the sum over paths labelled
//! this way, each term non-negative (a ground bounce is broad). A path ending at the sun is
//! credited to exactly one estimator, by the run of peak scatterings that ends it:
//!
//! - no run (its last scattering is broad): the disc's next-event estimate at its last vertex,
//!   or its continuation leaving through the disc, weighed against each other by the power
//!   heuristic (Veach 1997, section 9.2);
//! - a run that follows a broad scattering (or a ground bounce) at vertex `x`: the forward-peak
//!   chain at `x` ([`PathTracer::peak_chain`]), which draws a direction from a lobe about the sun
//!   (one time in five as the scattering at `x` draws it, so that its weight stays bounded),
//!   follows it to a collision and from there walks the peak lobe alone, estimating the sun at
//!   every vertex of the run; deep in a cloud, where the disc's estimate finds the sun nearly
//!   hidden, it runs only now and then, weighted by the inverse of its chance;
//! - a run that takes in the camera's first vertex (every scattering in the peak, as when the
//!   camera looks near the sun through a cloud): the chain at the first vertex when the run goes
//!   on past it, else the first vertex's disc estimate or its leaving continuation.
//!
//! So the first vertex's estimates take its whole scattering and the later vertices' their broad
//! part: the camera path draws each scattering's lobe by its weight, and only at the first vertex
//! does a continuation drawn from the peak that leaves through the disc count. The chain walks
//! exactly where the peak-scattered beam goes, with a throughput that falls by the peak's weight
//! at each collision (the δ-scaled attenuation, sampled), so the light that made fireflies
//! arrives as many small estimates. Each term of the sum is estimated once and without bias.

use super::{Continuation, Part, PathTracer, Vertex, position, power_heuristic, roulette};
use crate::environment::SunDisc;
use crate::medium::Medium;
use crate::rng::Rng;
use cloudscape::optics::{Lobe, PhaseLobes, henyey_greenstein};
use glam::Vec3;
use std::f32::consts::PI;

/// Asymmetry of the Henyey-Greenstein lobe the chain's first direction is drawn from, about the
/// sun: half of it within 0.36 degrees, the width of the sun disc blurred by the forward peak of
/// 20 um droplets (g = 0.9946, Jendersie & d'Eon 2023), with tails wide enough for the aureole a
/// few peak scatterings spread the beam into.
const CHAIN_FIRST_G: f32 = 0.992;

/// Share of the chain's first directions drawn as the scattering at its vertex draws them (a
/// defensive mixture, Hesterberg 1995): the lobe about the sun alone leaves directions far from
/// the sun with a density far below the broad lobe's weight there, and a chain that starts there
/// and turns toward the sun through the peak's tail was a firefly of 30,000 times its pixel; with
/// the mixture the first weight is at most `1 / CHAIN_OWN_SHARE`.
const CHAIN_OWN_SHARE: f32 = 0.2;

impl<M: Medium> PathTracer<M> {
    /// Next-event estimate of the sun's light scattered at `vertex` toward the path: one
    /// direction uniform over the disc, through the broad part of the scattering, and through the
    /// peak part too at the path's `first` vertex.
    pub(super) fn sun_light(&self, vertex: Vertex, first: bool, rng: &mut Rng) -> DiscEstimate {
        self.disc_light(vertex, rng, |dir, disc_pdf| {
            let weighted = |part: Part| {
                let (value, pdf) = self.part_scattering(vertex, part, dir);
                value * disc_weight(disc_pdf, pdf)
            };
            let broad = weighted(Part::Broad);
            if first {
                broad + weighted(Part::Peak)
            } else {
                broad
            }
        })
    }

    /// The sun disc's radiance seen by the continuation `next` that left the medium from
    /// `origin`, when the path is its own (a broad scattering, or the path's `first`), weighted
    /// against the disc's next-event estimate.
    pub(super) fn sun_reached(&self, origin: Vec3, next: &Continuation, first: bool) -> Vec3 {
        if next.part == Part::Peak && !first {
            return Vec3::ZERO;
        }
        self.leaving_through_disc(origin, next.dir, next.part_pdf)
    }

    /// The forward-peak chain from `vertex`: the sunlight that reaches it after a run of peak
    /// scatterings following its scattering (the broad part; the whole of it at the path's
    /// `first` vertex), at most `orders_left` of them. `toward_sun` is what the disc's estimate
    /// at `vertex` found ([`Self::chain_probability`]).
    pub(super) fn peak_chain(
        &self,
        vertex: Vertex,
        (first, orders_left, toward_sun): (bool, u32, &DiscEstimate),
        rng: &mut Rng,
    ) -> Vec3 {
        let Some(sun) = self.environment.sun else {
            return Vec3::ZERO;
        };
        if orders_left == 0 || !self.has_peak() {
            return Vec3::ZERO;
        }
        let chance = self.chain_probability(first, toward_sun.transmittance);
        if chance < 1.0 && rng.next_f32() >= chance {
            return Vec3::ZERO;
        }
        let mut dir = if rng.next_f32() < CHAIN_OWN_SHARE {
            self.own_direction(vertex, first, rng.next_vec3())
        } else {
            PhaseLobes::henyey_greenstein(CHAIN_FIRST_G).sample(sun.direction, rng.next_vec3())
        };
        let first_pdf = (1.0 - CHAIN_OWN_SHARE)
            * henyey_greenstein(CHAIN_FIRST_G, sun.direction.dot(dir))
            + CHAIN_OWN_SHARE * self.own_pdf(vertex, first, dir);
        let mut value = self.part_scattering(vertex, Part::Broad, dir).0;
        if first {
            value += self.part_scattering(vertex, Part::Peak, dir).0;
        }
        if value.max_element() <= 0.0 || first_pdf <= 0.0 {
            return Vec3::ZERO;
        }
        let scale = value / (first_pdf * chance);
        // Throughput relative to `scale`, so that roulette plays on how far the chain has faded.
        let mut relative = Vec3::ONE;
        let mut origin = position(vertex);
        let mut radiance = Vec3::ZERO;
        // Density of the peak lobe for `dir` at the collision it was drawn at; 0 for the first.
        let mut lobe_pdf = 0.0;
        let peak_weight = self.phase.lobe_weight(Lobe::HenyeyGreenstein);
        for _ in 0..orders_left {
            let ground_m = self.environment.ground_distance(origin, dir);
            let Some(t) = self.volume.free_flight(origin, dir, ground_m, rng) else {
                // Leaving before the first collision is the disc's estimate at `vertex`.
                if lobe_pdf > 0.0 && ground_m.is_infinite() {
                    radiance += relative * self.leaving_through_disc(origin, dir, lobe_pdf);
                }
                break;
            };
            let collision = Vertex::Medium {
                position: origin + dir * t,
                dir,
            };
            relative *= self.albedo;
            radiance += relative * self.peak_sun_light(collision, rng).radiance;
            let next = self
                .phase
                .sample_lobe(Lobe::HenyeyGreenstein, dir, rng.next_vec2());
            lobe_pdf = self.phase.lobe_eval(Lobe::HenyeyGreenstein, dir.dot(next));
            relative *= peak_weight;
            if !roulette(&mut relative, rng) {
                break;
            }
            origin = position(collision);
            dir = next;
        }
        scale * radiance
    }

    /// The chain's defensive first direction at `vertex`, drawn as the scattering it is weighted
    /// by: the whole phase function at the path's `first` vertex, the broad lobe after it, the
    /// cosine on the ground.
    fn own_direction(&self, vertex: Vertex, first: bool, u: Vec3) -> Vec3 {
        match vertex {
            Vertex::Medium { dir, .. } if first => self.phase.sample(dir, u),
            Vertex::Medium { dir, .. } => {
                self.phase
                    .sample_lobe(Lobe::Draine, dir, glam::Vec2::new(u.y, u.z))
            }
            Vertex::Ground(g) => {
                crate::sampling::cosine_hemisphere(g.normal, glam::Vec2::new(u.y, u.z))
            }
        }
    }

    /// Density of [`Self::own_direction`] for `next`.
    fn own_pdf(&self, vertex: Vertex, first: bool, next: Vec3) -> f32 {
        match vertex {
            Vertex::Medium { dir, .. } if first => self.phase.eval(dir.dot(next)),
            Vertex::Medium { dir, .. } => self.phase.lobe_eval(Lobe::Draine, dir.dot(next)),
            Vertex::Ground(_) => self.scattering(vertex, next).1,
        }
    }

    /// The disc's next-event estimate at a vertex of the chain, through the peak part alone.
    fn peak_sun_light(&self, vertex: Vertex, rng: &mut Rng) -> DiscEstimate {
        let Vertex::Medium { dir: before, .. } = vertex else {
            return DiscEstimate::NONE;
        };
        self.disc_light(vertex, rng, |dir, disc_pdf| {
            let (value, _) = self.part_scattering(vertex, Part::Peak, dir);
            let lobe_pdf = self
                .phase
                .lobe_eval(Lobe::HenyeyGreenstein, before.dot(dir));
            value * disc_weight(disc_pdf, lobe_pdf)
        })
    }

    /// Next-event estimate of the sun at `vertex` by one direction uniform over its disc:
    /// `scattering(dir, disc density)` is the weighted scattering factor toward it.
    fn disc_light(
        &self,
        vertex: Vertex,
        rng: &mut Rng,
        scattering: impl Fn(Vec3, Option<f32>) -> Vec3,
    ) -> DiscEstimate {
        let Some(sun) = self.environment.sun else {
            return DiscEstimate::NONE;
        };
        let dir = crate::sampling::uniform_cone(sun.direction, sun.cos_radius, rng.next_vec2());
        let value = scattering(dir, sun_disc_pdf(&sun));
        if value.max_element() <= 0.0 {
            return DiscEstimate::NONE;
        }
        let p = position(vertex);
        let transmittance = self.visibility(p, dir, rng);
        DiscEstimate {
            // Uniform over the disc: radiance E / Omega over density 1 / Omega leaves E.
            radiance: self.environment.sun_irradiance(p) * value * transmittance,
            transmittance: Some(transmittance),
        }
    }

    /// Probability of running the chain from a vertex: 1 at the path's `first` vertex, else
    /// `T^(1 - w) / 0.1` within [[`CHAIN_MIN_PROBABILITY`], 1], where `T` is the disc's estimate
    /// of the transmittance toward the sun there and `w` the peak's weight: `T^(1 - w)` is about
    /// what the peak-scattered beam keeps (it fades with the δ-scaled optical depth), so the deep
    /// vertices of long diffusion paths, whose chains find little, run one in ten (weighted by
    /// the inverse, so the estimate stays unbiased: Russian roulette, Arvo & Kirk 1990).
    fn chain_probability(&self, first: bool, transmittance: Option<f32>) -> f32 {
        match (first, transmittance) {
            (false, Some(t)) => {
                let keeps = t.powf(1.0 - self.phase.lobe_weight(Lobe::HenyeyGreenstein));
                (keeps / 0.1).clamp(CHAIN_MIN_PROBABILITY, 1.0)
            }
            _ => 1.0,
        }
    }
}

/// A next-event estimate of the sun, and the transmittance toward it that it traced (None where
/// nothing scatters toward the sun, so nothing was traced).
pub(super) struct DiscEstimate {
    /// The sunlight scattered toward the path.
    pub radiance: Vec3,
    /// The ratio-tracked transmittance toward the sampled point of the disc.
    pub transmittance: Option<f32>,
}

impl DiscEstimate {
    /// No light, nothing traced.
    const NONE: DiscEstimate = DiscEstimate {
        radiance: Vec3::ZERO,
        transmittance: None,
    };
}

/// Smallest probability of running the forward-peak chain from a vertex after the first.
const CHAIN_MIN_PROBABILITY: f32 = 0.1;

impl<M: Medium> PathTracer<M> {
    /// At `vertex`, for leaving toward `next`: the `part` of the scattering factor (phase
    /// function, or BRDF times cosine on the ground, which is all broad) and the joint density
    /// with which the path's continuation draws that part and `next`.
    fn part_scattering(&self, vertex: Vertex, part: Part, next: Vec3) -> (Vec3, f32) {
        match (vertex, part) {
            (Vertex::Medium { dir, .. }, _) => {
                let p = self.part_phase(part, dir.dot(next));
                (Vec3::splat(p), p)
            }
            (Vertex::Ground(_), Part::Broad) => self.scattering(vertex, next),
            (Vertex::Ground(_), Part::Peak) => (Vec3::ZERO, 0.0),
        }
    }

    /// The sun disc's radiance seen from `origin` along `dir` by a direction drawn with density
    /// `pdf`, weighted against the disc's next-event estimate.
    fn leaving_through_disc(&self, origin: Vec3, dir: Vec3, pdf: f32) -> Vec3 {
        let Some(sun) = self.environment.sun else {
            return Vec3::ZERO;
        };
        let radiance = self.environment.sun_disc_radiance(origin, dir);
        match sun_disc_pdf(&sun) {
            Some(disc_pdf) if radiance.max_element() > 0.0 => {
                radiance * power_heuristic(pdf, disc_pdf)
            }
            _ => Vec3::ZERO,
        }
    }
}

/// Density of the sun's next-event directions (uniform over the disc), None for a point sun.
fn sun_disc_pdf(sun: &SunDisc) -> Option<f32> {
    let solid_angle = 2.0 * PI * (1.0 - sun.cos_radius);
    (solid_angle > 0.0).then(|| 1.0 / solid_angle)
}

/// Power-heuristic weight of the disc's next-event estimate against a continuation that draws
/// the same direction with density `pdf`; a point sun (no disc density) can only be sampled.
fn disc_weight(disc_pdf: Option<f32>, pdf: f32) -> f32 {
    disc_pdf.map_or(1.0, |d| power_heuristic(d, pdf))
}
