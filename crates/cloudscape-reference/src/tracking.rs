//! Null-collision tracking through a medium bounded by a [`MajorantGrid`]: delta tracking for
//! free-flight distances (Woodcock et al. 1965) and ratio tracking for transmittance (Novák,
//! Selle & Jarosz 2014, "Residual Ratio Tracking for Estimating Attenuation in Participating
//! Media"), both unbiased for any majorant that is never exceeded.

use crate::majorant::MajorantGrid;
use crate::medium::Medium;
use crate::rng::Rng;
use glam::Vec3;
use std::ops::ControlFlow;

/// Below this transmittance, ratio tracking plays Russian roulette: it survives with probability
/// `T / threshold` at `T = threshold`, which keeps the estimate unbiased and stops hopeless walks
/// through thick cores early.
const RATIO_ROULETTE_THRESHOLD: f32 = 0.1;

/// A medium with its majorant grid.
pub struct TrackedMedium<M> {
    /// The medium.
    pub medium: M,
    /// Its majorants.
    pub grid: MajorantGrid,
}

impl<M: Medium> TrackedMedium<M> {
    /// Builds the majorant grid of `medium` with about `max_cells` cells.
    pub fn new(medium: M, max_cells: usize) -> TrackedMedium<M> {
        let grid = MajorantGrid::build(&medium, max_cells);
        TrackedMedium { medium, grid }
    }

    /// Visits tentative collisions along the ray within `[0, t_max]`: distances between them are
    /// exponential with the local majorant's rate; `collide` gets the distance and the ratio
    /// `sigma_t / majorant` there.
    fn track<R>(
        &self,
        origin: Vec3,
        dir: Vec3,
        t_max: f32,
        rng: &mut Rng,
        mut collide: impl FnMut(f32, f32, &mut Rng) -> ControlFlow<R>,
    ) -> ControlFlow<R> {
        self.grid.walk(origin, dir, t_max, |segment| {
            let mut t = segment.start;
            loop {
                t += rng.next_optical_depth() / segment.majorant_per_m;
                if t >= segment.end {
                    return ControlFlow::Continue(());
                }
                let sigma = self.medium.extinction_per_m(origin + dir * t);
                collide(t, sigma / segment.majorant_per_m, rng)?;
            }
        })
    }

    /// Delta tracking: the distance to the first real collision along the ray, distributed with
    /// density `sigma_t(t) exp(-tau(0, t))`, or None when the ray leaves `[0, t_max]` first (with
    /// probability equal to the transmittance). A tentative collision is real with probability
    /// `sigma_t / majorant`.
    pub fn free_flight(&self, origin: Vec3, dir: Vec3, t_max: f32, rng: &mut Rng) -> Option<f32> {
        let flow = self.track(origin, dir, t_max, rng, |t, ratio, rng| {
            if rng.next_f32() < ratio {
                ControlFlow::Break(t)
            } else {
                ControlFlow::Continue(())
            }
        });
        match flow {
            ControlFlow::Break(t) => Some(t),
            ControlFlow::Continue(()) => None,
        }
    }

    /// Ratio tracking: an unbiased estimate of the transmittance `exp(-tau(0, t_max))`, the product
    /// of `1 - sigma_t / majorant` over tentative collisions, with Russian roulette below
    /// [`RATIO_ROULETTE_THRESHOLD`].
    pub fn transmittance(&self, origin: Vec3, dir: Vec3, t_max: f32, rng: &mut Rng) -> f32 {
        let mut transmittance = 1.0;
        let _ = self.track(origin, dir, t_max, rng, |_, ratio, rng| {
            transmittance *= (1.0 - ratio).max(0.0);
            if transmittance < RATIO_ROULETTE_THRESHOLD {
                if rng.next_f32() * RATIO_ROULETTE_THRESHOLD >= transmittance {
                    transmittance = 0.0;
                    return ControlFlow::Break(());
                }
                transmittance = RATIO_ROULETTE_THRESHOLD;
            }
            ControlFlow::Continue(())
        });
        transmittance
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Aabb;
    use crate::medium::HomogeneousBox;

    /// A 10 m cube of extinction 0.2 m^-1 inside a 4x4x4 grid whose cells are looser than needed.
    fn cube() -> TrackedMedium<HomogeneousBox> {
        let medium = HomogeneousBox {
            bounds: Aabb {
                min: Vec3::ZERO,
                max: Vec3::splat(10.0),
            },
            extinction_per_m: 0.2,
        };
        TrackedMedium::new(medium, 64)
    }

    #[test]
    fn free_flight_escapes_with_the_beer_lambert_probability() {
        let m = cube();
        let (o, d) = (Vec3::new(-1.0, 5.0, 5.0), Vec3::X);
        let n = 40_000;
        let mut escaped = 0;
        let mut mean_depth = 0.0;
        for i in 0..n {
            let mut rng = Rng::for_sample(1, 0, i);
            match m.free_flight(o, d, 100.0, &mut rng) {
                None => escaped += 1,
                Some(t) => mean_depth += f64::from(t - 1.0),
            }
        }
        let p = escaped as f64 / n as f64;
        let expected = (-2.0f64).exp();
        // Binomial standard error sqrt(p (1 - p) / n) = 0.0017.
        assert!((p - expected).abs() < 0.007, "{p} vs {expected}");
        // Mean depth of the collisions: the truncated exponential's mean.
        let collided = (n - escaped) as f64;
        let truncated_mean = 1.0 / 0.2 - 10.0 * expected / (1.0 - expected);
        assert!(
            (mean_depth / collided - truncated_mean).abs() < 0.06,
            "{} vs {truncated_mean}",
            mean_depth / collided
        );
    }

    #[test]
    fn ratio_tracking_is_unbiased_and_bounded() {
        let m = cube();
        let (o, d) = (Vec3::new(5.0, 5.0, -3.0), Vec3::Z);
        let n = 20_000;
        let estimates: Vec<f32> = (0..n)
            .map(|i| m.transmittance(o, d, 1e3, &mut Rng::for_sample(2, 0, i)))
            .collect();
        assert!(estimates.iter().all(|t| (0.0..=1.0).contains(t)));
        let mean = estimates.iter().map(|&t| f64::from(t)).sum::<f64>() / n as f64;
        assert!((mean - (-2.0f64).exp()).abs() < 0.005, "{mean}");
        // A ray that stops halfway through sees half the optical depth.
        let half = (0..n)
            .map(|i| f64::from(m.transmittance(o, d, 8.0, &mut Rng::for_sample(3, 0, i))))
            .sum::<f64>()
            / n as f64;
        assert!((half - (-1.0f64).exp()).abs() < 0.006, "{half}");
    }
}
