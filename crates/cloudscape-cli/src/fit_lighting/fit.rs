//! Fitting the octaves' factors to the path tracer, and measuring a fit on held-out scenes.

use super::samples::Sample;
use cloudscape::optics::{Octaves, PhaseLobes};
use rayon::prelude::*;

/// Grid points per factor in each round of the search.
const GRID: usize = 11;
/// Rounds of the search, each on a grid a quarter as wide about the best point of the last.
const ROUNDS: usize = 4;

/// How well a model predicts a set of samples.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Score {
    /// Root mean squared error over the mean source: 0 is perfect.
    pub relative_rms: f64,
    /// Mean prediction over mean source: 1 is unbiased.
    pub mean_ratio: f64,
    /// The same ratio in the scene where it is lowest and where it is highest.
    pub scene_ratio_range: (f64, f64),
}

/// `octaves`' prediction of one sample's source.
fn predict(octaves: &Octaves, lobes: &PhaseLobes, s: &Sample) -> f64 {
    f64::from(octaves.scattering(lobes, s.cos_theta, s.tau_sun))
}

/// The score of `octaves` on `samples`.
pub fn score(octaves: &Octaves, lobes: &PhaseLobes, samples: &[Sample]) -> Score {
    let (mut sum_sq, mut sum_pred, mut sum_true) = (0.0, 0.0, 0.0);
    for s in samples {
        let p = predict(octaves, lobes, s);
        sum_sq += (p - f64::from(s.source)).powi(2);
        sum_pred += p;
        sum_true += f64::from(s.source);
    }
    let n = samples.len().max(1) as f64;
    let mut scenes: Vec<u32> = samples.iter().map(|s| s.scene).collect();
    scenes.sort_unstable();
    scenes.dedup();
    let ratios = scenes.iter().map(|&k| {
        let (p, t) = samples
            .iter()
            .filter(|s| s.scene == k)
            .fold((0.0, 0.0), |(p, t), s| {
                (p + predict(octaves, lobes, s), t + f64::from(s.source))
            });
        p / t.max(1e-12)
    });
    let range = ratios.fold((f64::MAX, f64::MIN), |(lo, hi), r| (lo.min(r), hi.max(r)));
    Score {
        relative_rms: (sum_sq / n).sqrt() / (sum_true / n).max(1e-12),
        mean_ratio: sum_pred / sum_true.max(1e-12),
        scene_ratio_range: range,
    }
}

/// The squared error of `octaves` over `samples`.
fn squared_error(octaves: &Octaves, lobes: &PhaseLobes, samples: &[Sample]) -> f64 {
    samples
        .iter()
        .map(|s| (predict(octaves, lobes, s) - f64::from(s.source)).powi(2))
        .sum()
}

/// The factors `(a, b, c)` of `count` octaves that minimise the squared error over `samples`
/// (least squares: the samples' estimates are unbiased, so their mean is what is fitted), found by
/// a grid search over `[0, 1]^3` refined [`ROUNDS`] times about the best point.
pub fn fit_octaves(count: u32, lobes: &PhaseLobes, samples: &[Sample]) -> Octaves {
    let octaves = |[a, b, c]: [f32; 3]| Octaves {
        count,
        attenuation: a,
        contribution: b,
        eccentricity: c,
    };
    let (mut centre, mut half_width) = ([0.5f32; 3], 0.5f32);
    for _ in 0..ROUNDS {
        let axis = |k: usize| {
            (0..GRID).map(move |i| {
                let t = i as f32 / (GRID - 1) as f32;
                (centre[k] + half_width * (2.0 * t - 1.0)).clamp(0.0, 0.99)
            })
        };
        let candidates: Vec<[f32; 3]> = axis(0)
            .flat_map(|a| axis(1).flat_map(move |b| axis(2).map(move |c| [a, b, c])))
            .collect();
        centre = candidates
            .par_iter()
            .map(|&f| (squared_error(&octaves(f), lobes, samples), f))
            .min_by(|x, y| x.0.total_cmp(&y.0))
            .map(|(_, f)| f)
            .unwrap_or(centre);
        half_width /= 4.0;
    }
    octaves(centre)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Samples made by known octaves are fitted back to them.
    #[test]
    fn known_octaves_are_recovered() {
        let lobes = PhaseLobes::approximate_mie(20.0);
        let truth = Octaves {
            count: 4,
            attenuation: 0.3,
            contribution: 0.6,
            eccentricity: 0.5,
        };
        let samples: Vec<Sample> = (0..400)
            .map(|i| {
                let (cos_theta, tau_sun) = ((i % 20) as f32 / 10.0 - 0.95, (i / 20) as f32 * 1.5);
                let source = truth.scattering(&lobes, cos_theta, tau_sun);
                Sample {
                    scene: i % 3,
                    tau_sun,
                    cos_theta,
                    sun_y: 0.5,
                    source,
                    source_error: 0.0,
                }
            })
            .collect();
        let fitted = fit_octaves(4, &lobes, &samples);
        let s = score(&fitted, &lobes, &samples);
        assert!(s.relative_rms < 0.01, "{fitted:?}: {s:?}");
        assert!((fitted.attenuation - 0.3).abs() < 0.02, "{fitted:?}");
        assert!((fitted.contribution - 0.6).abs() < 0.02, "{fitted:?}");
    }
}
