//! Fitting the ray marcher's lighting models to the path tracer, and measuring a fit on held-out
//! scenes.

use super::samples::Sample;
use cloudscape::optics::{Octaves, PhaseLobes, SunSlab};
use rayon::prelude::*;

/// Grid points per factor in each round of the search.
const GRID: usize = 11;
/// Rounds of the search, each on a grid a quarter as wide about the best point of the last.
const ROUNDS: usize = 4;

/// A model of the sun's light the march adds at a point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Model {
    /// Multiple-scattering octaves, with the phase function they scale.
    Octaves(Octaves, PhaseLobes),
    /// The δ-Eddington slab along the sun.
    Slab(SunSlab),
    /// The light volume for the diffuse light, the slab's beam part per sample.
    Volume(SunSlab),
}

impl Model {
    /// The model's prediction of one sample's source.
    fn predict(&self, s: &Sample) -> f64 {
        f64::from(match self {
            Model::Octaves(octaves, lobes) => octaves.scattering(lobes, s.cos_theta, s.tau_sun),
            Model::Slab(slab) => slab.scattering(s.cos_theta, s.tau_sun, s.tau_back),
            Model::Volume(slab) => slab.beam_scattering(s.cos_theta, s.tau_sun) + s.volume_diffuse,
        })
    }

    /// The squared error of the model over `samples`.
    fn squared_error(&self, samples: &[Sample]) -> f64 {
        samples
            .iter()
            .map(|s| (self.predict(s) - f64::from(s.source)).powi(2))
            .sum()
    }
}

/// Where in the clouds a sample lies, for the per-class figures.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Class {
    /// Inside a deck (stratus, stratocumulus), an optical depth of at least 3 below its sunlit
    /// side.
    DeckInterior,
    /// The side of a tower (cumulus, cumulonimbus) seen level (the view within 20 degrees of the
    /// horizon), not against the sun.
    TowerSide,
    /// A body seen against the sun (within 60 degrees of it), at least an optical depth of 3
    /// from its sunlit side.
    BacklitBody,
    /// Anywhere else.
    Other,
}

impl Class {
    /// The classes in the order the tables print them.
    pub const ALL: [Class; 4] = [
        Class::DeckInterior,
        Class::TowerSide,
        Class::BacklitBody,
        Class::Other,
    ];

    /// The class of sample `s`.
    pub fn of(s: &Sample) -> Class {
        if s.cos_theta > 0.5 && s.tau_sun >= 3.0 {
            Class::BacklitBody
        } else if s.family.is_deck() && s.tau_sun >= 3.0 {
            Class::DeckInterior
        } else if !s.family.is_deck() && s.direction.y.abs() < 0.34 && s.cos_theta < 0.5 {
            Class::TowerSide
        } else {
            Class::Other
        }
    }

    /// "deck interior".
    pub fn name(self) -> &'static str {
        match self {
            Class::DeckInterior => "deck interior",
            Class::TowerSide => "tower side",
            Class::BacklitBody => "backlit body",
            Class::Other => "other",
        }
    }
}

/// Mean prediction over mean source of `model` on the samples of `class`, and their count.
pub fn class_ratio(model: &Model, samples: &[Sample], class: Class) -> (f64, usize) {
    let (mut p, mut t, mut n) = (0.0, 0.0, 0);
    for s in samples.iter().filter(|s| Class::of(s) == class) {
        p += model.predict(s);
        t += f64::from(s.source);
        n += 1;
    }
    (p / t.max(1e-12), n)
}

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

/// The score of `model` on `samples`.
pub fn score(model: &Model, samples: &[Sample]) -> Score {
    let (mut sum_sq, mut sum_pred, mut sum_true) = (0.0, 0.0, 0.0);
    for s in samples {
        let p = model.predict(s);
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
                (p + model.predict(s), t + f64::from(s.source))
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

/// The factors within `bounds` that minimise `error`: a grid search refined [`ROUNDS`] times,
/// each round on a grid a quarter as wide about the best point of the last.
fn grid_search<const N: usize>(
    bounds: [(f32, f32); N],
    error: impl Fn([f32; N]) -> f64 + Sync,
) -> [f32; N] {
    let mut centre = bounds.map(|(lo, hi)| 0.5 * (lo + hi));
    let mut half_width = bounds.map(|(lo, hi)| 0.5 * (hi - lo));
    for _ in 0..ROUNDS {
        let candidates: Vec<[f32; N]> = (0..GRID.pow(N as u32))
            .map(|index| {
                std::array::from_fn(|k| {
                    let step = index / GRID.pow(k as u32) % GRID;
                    let t = step as f32 / (GRID - 1) as f32;
                    (centre[k] + half_width[k] * (2.0 * t - 1.0)).clamp(bounds[k].0, bounds[k].1)
                })
            })
            .collect();
        centre = candidates
            .par_iter()
            .map(|&f| (error(f), f))
            .min_by(|x, y| x.0.total_cmp(&y.0))
            .map(|(_, f)| f)
            .unwrap_or(centre);
        half_width = half_width.map(|w| w / 4.0);
    }
    centre
}

/// The factors `(a, b, c)` of `count` octaves that minimise the squared error over `samples`
/// (least squares: the samples' estimates are unbiased, so their mean is what is fitted).
pub fn fit_octaves(count: u32, lobes: &PhaseLobes, samples: &[Sample]) -> Octaves {
    let octaves = |[a, b, c]: [f32; 3]| Octaves {
        count,
        attenuation: a,
        contribution: b,
        eccentricity: c,
    };
    let bounds = [(0.0, 0.99); 3];
    let best = grid_search(bounds, |f| {
        Model::Octaves(octaves(f), *lobes).squared_error(samples)
    });
    octaves(best)
}

/// The slab model's diffuse and far-side factors that minimise the squared error over `samples`,
/// for `lobes` and `albedo`.
pub fn fit_slab(lobes: PhaseLobes, albedo: f32, samples: &[Sample]) -> SunSlab {
    let slab = |[diffuse, back]: [f32; 2]| SunSlab::new(lobes, albedo, diffuse, back);
    let bounds = [(0.0, 2.0), (0.0, 2.0)];
    slab(grid_search(bounds, |f| {
        Model::Slab(slab(f)).squared_error(samples)
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Samples on a grid of scattering cosines and optical depths, their source from `truth`.
    fn samples_of(truth: impl Fn(&Sample) -> f32) -> Vec<Sample> {
        (0..400)
            .map(|i| {
                let (cos_theta, tau_sun) = ((i % 20) as f32 / 10.0 - 0.95, (i / 20) as f32 * 1.5);
                let tau_back = ((i * 7) % 30) as f32;
                let mut sample = Sample {
                    scene: i % 3,
                    tau_sun,
                    tau_back,
                    cos_theta,
                    sun_y: 0.5,
                    source: 0.0,
                    source_error: 0.0,
                    point_m: glam::Vec3::ZERO,
                    direction: glam::Vec3::X,
                    family: super::super::samples::Family::Cumulus,
                    volume_diffuse: f32::NAN,
                };
                sample.source = truth(&sample);
                sample
            })
            .collect()
    }

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
        let samples = samples_of(|s| truth.scattering(&lobes, s.cos_theta, s.tau_sun));
        let fitted = fit_octaves(4, &lobes, &samples);
        let s = score(&Model::Octaves(fitted, lobes), &samples);
        assert!(s.relative_rms < 0.01, "{fitted:?}: {s:?}");
        assert!((fitted.attenuation - 0.3).abs() < 0.02, "{fitted:?}");
        assert!((fitted.contribution - 0.6).abs() < 0.02, "{fitted:?}");
    }

    /// Samples made by a known slab are fitted back to it.
    #[test]
    fn a_known_slab_is_recovered() {
        let lobes = PhaseLobes::approximate_mie(20.0);
        let truth = SunSlab::new(lobes, 1.0, 0.7, 0.4);
        let samples = samples_of(|s| truth.scattering(s.cos_theta, s.tau_sun, s.tau_back));
        let fitted = fit_slab(lobes, 1.0, &samples);
        let s = score(&Model::Slab(fitted), &samples);
        assert!(s.relative_rms < 0.01, "{fitted:?}: {s:?}");
        assert!((fitted.diffuse_scale - 0.7).abs() < 0.02, "{fitted:?}");
        assert!((fitted.back_scale - 0.4).abs() < 0.05, "{fitted:?}");
    }
}
