//! Where a scene uses a model that Mitsuba 3 lacks, the closest thing Mitsuba has.
//!
//! - Phase functions become one or two Henyey-Greenstein lobes with the scene's mean cosine `g`.
//!   By the similarity relations of transport theory (Wyman, Patterson & Wilson 1989, "Similarity
//!   relations for the interaction parameters in radiation transport"), multiply scattered light in
//!   optically thick media depends on the phase function mostly through `(1 - g) sigma_s`, so
//!   keeping `g` keeps the bulk of the cloud right; the shape of the forward peak (the silver
//!   lining) differs.
//! - A gradient sky becomes a constant sky of the same irradiance on a horizontal surface.

use crate::scene::{PhaseFunction, PhaseModel, Sky, SkyModel};

/// One Henyey-Greenstein lobe of a phase-function mixture.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct HgLobe {
    /// Share of the scattered energy in this lobe, 0..1.
    pub weight: f32,
    /// Asymmetry (mean cosine) of the lobe, -1..1.
    pub g: f32,
}

/// The scene's phase function as HG lobes whose weights sum to 1 and whose weighted mean cosine is
/// the scene phase function's.
///
/// - `hg`: one lobe, exact.
/// - `dual_hg`: two lobes, exact.
/// - `mie`: the approximate Mie fit of Jendersie & d'Eon 2023 is `(1 - w_D) HG(g_HG) + w_D
///   Draine(g_D, alpha)`; its Draine lobe is replaced by an HG lobe of the same mean cosine
///   ([`draine_mean_cosine`]), which keeps the total mean cosine (0.879 at 20 um).
pub(crate) fn hg_lobes(phase: &PhaseFunction) -> Vec<HgLobe> {
    match phase.model {
        PhaseModel::Hg => vec![HgLobe {
            weight: 1.0,
            g: phase.g,
        }],
        PhaseModel::DualHg => vec![
            HgLobe {
                weight: phase.forward_weight,
                g: phase.g_forward,
            },
            HgLobe {
                weight: 1.0 - phase.forward_weight,
                g: phase.g_back,
            },
        ],
        PhaseModel::Mie => {
            let fit = MieFit::for_diameter_um(phase.droplet_diameter_um);
            vec![
                HgLobe {
                    weight: 1.0 - fit.draine_weight,
                    g: fit.g_hg,
                },
                HgLobe {
                    weight: fit.draine_weight,
                    g: draine_mean_cosine(fit.g_draine, fit.alpha),
                },
            ]
        }
    }
}

/// Parameters of the approximate Mie phase function for water droplets (Jendersie & d'Eon 2023,
/// "An Approximate Mie Scattering Function for Fog and Cloud Rendering", fit for diameters
/// 5..50 um; numbers in `physics.md`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct MieFit {
    /// Asymmetry of the HG lobe.
    pub g_hg: f32,
    /// Asymmetry parameter of the Draine lobe.
    pub g_draine: f32,
    /// Draine's `alpha`.
    pub alpha: f32,
    /// Weight of the Draine lobe, `w_D`.
    pub draine_weight: f32,
}

impl MieFit {
    /// The fit at an effective droplet diameter in micrometres.
    pub(crate) fn for_diameter_um(d: f32) -> MieFit {
        MieFit {
            g_hg: (-0.0990567 / (d - 1.67154)).exp(),
            g_draine: (-2.20679 / (d + 3.91029) - 0.428934).exp(),
            alpha: (3.62489 - 8.29288 / (d + 5.52825)).exp(),
            draine_weight: (-0.599085 / (d - 0.641583) - 0.665888).exp(),
        }
    }
}

/// Mean cosine of Draine's phase function `HG(g) (1 + alpha mu^2) / (1 + alpha (1 + 2 g^2) / 3)`
/// (Draine 2003, "Scattering by Interstellar Dust Grains. I").
///
/// From the Legendre moments of HG, `<P_l> = g^l`: `<mu^2>_HG = (1 + 2 g^2) / 3` and
/// `<mu^3>_HG = g (3 + 2 g^2) / 5`, so `<mu>_D = (g + alpha <mu^3>_HG) / (1 + alpha <mu^2>_HG)`.
pub(crate) fn draine_mean_cosine(g: f32, alpha: f32) -> f32 {
    let second_moment = (1.0 + 2.0 * g * g) / 3.0;
    let third_moment = g * (3.0 + 2.0 * g * g) / 5.0;
    (g + alpha * third_moment) / (1.0 + alpha * second_moment)
}

/// Radiance of a constant sky that gives a horizontal surface the same irradiance as `sky`.
///
/// The constant sky is itself. The gradient sky is taken as `L(mu) = H + (Z - H) mu^k` over the
/// upper hemisphere, with `mu` the sine of the elevation, `H` and `Z` the horizon and zenith
/// radiance and `k` the gradient exponent. Its cosine-weighted mean, `E / pi = 2 integral_0^1
/// L(mu) mu dmu`, is `H + (Z - H) 2 / (k + 2)`. The lower hemisphere gets the same radiance
/// (hidden by the ground when there is one).
pub(crate) fn constant_sky_radiance(sky: &Sky) -> [f32; 3] {
    match sky.model {
        SkyModel::Constant => sky.radiance,
        SkyModel::Gradient => {
            let zenith_share = 2.0 / (sky.gradient_exponent + 2.0);
            std::array::from_fn(|c| {
                let (horizon, zenith) = (sky.horizon_radiance[c], sky.zenith_radiance[c]);
                horizon + (zenith - horizon) * zenith_share
            })
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Midpoint rule over mu in [a, b] with `n` intervals.
    fn integrate(a: f64, b: f64, n: usize, f: impl Fn(f64) -> f64) -> f64 {
        let h = (b - a) / n as f64;
        (0..n).map(|i| f(a + (i as f64 + 0.5) * h)).sum::<f64>() * h
    }

    #[test]
    fn draine_mean_cosine_matches_numerical_integration() {
        let (g, alpha) = (0.5938f64, 27.1f64);
        let hg = |mu: f64| (1.0 - g * g) / (1.0 + g * g - 2.0 * g * mu).powf(1.5);
        let weight = |mu: f64| hg(mu) * (1.0 + alpha * mu * mu);
        let numeric = integrate(-1.0, 1.0, 200_000, |mu| mu * weight(mu))
            / integrate(-1.0, 1.0, 200_000, weight);
        assert!((f64::from(draine_mean_cosine(g as f32, alpha as f32)) - numeric).abs() < 1e-4);
    }

    #[test]
    fn mie_lobes_keep_the_published_mean_cosine() {
        let phase = PhaseFunction {
            model: PhaseModel::Mie,
            droplet_diameter_um: 20.0,
            ..Default::default()
        };
        let fit = MieFit::for_diameter_um(20.0);
        assert!((fit.g_hg - 0.9946).abs() < 1e-4 && (fit.g_draine - 0.5938).abs() < 1e-4);
        assert!((fit.alpha - 27.1).abs() < 0.05 && (fit.draine_weight - 0.498).abs() < 1e-3);
        let lobes = hg_lobes(&phase);
        let mean_cosine: f32 = lobes.iter().map(|lobe| lobe.weight * lobe.g).sum();
        assert!((mean_cosine - 0.879).abs() < 1e-3, "{mean_cosine}");
        assert!((lobes.iter().map(|lobe| lobe.weight).sum::<f32>() - 1.0).abs() < 1e-6);
    }

    #[test]
    fn dual_hg_lobes_are_the_scene_lobes() {
        let phase = PhaseFunction {
            model: PhaseModel::DualHg,
            ..Default::default()
        };
        let lobes = hg_lobes(&phase);
        assert_eq!(
            lobes[0],
            HgLobe {
                weight: 0.7,
                g: 0.8
            }
        );
        assert!((lobes[1].weight - 0.3).abs() < 1e-6 && lobes[1].g == -0.3);
    }

    #[test]
    fn gradient_sky_average_matches_numerical_integration() {
        let sky = Sky {
            model: SkyModel::Gradient,
            gradient_exponent: 0.45,
            ..Default::default()
        };
        let k = f64::from(sky.gradient_exponent);
        let average = constant_sky_radiance(&sky);
        let channels = sky
            .horizon_radiance
            .iter()
            .zip(&sky.zenith_radiance)
            .zip(average);
        for ((&horizon, &zenith), average) in channels {
            let (h, z) = (f64::from(horizon), f64::from(zenith));
            let numeric = 2.0 * integrate(0.0, 1.0, 100_000, |mu| (h + (z - h) * mu.powf(k)) * mu);
            assert!((f64::from(average) - numeric).abs() < 1e-5);
        }
        let constant = Sky {
            model: SkyModel::Constant,
            ..sky
        };
        assert_eq!(constant_sky_radiance(&constant), constant.radiance);
    }
}
