//! Where a scene uses a model that Mitsuba 3 lacks, the closest thing Mitsuba has.
//!
//! - Phase functions become one or two Henyey-Greenstein lobes with the scene's mean cosine `g`.
//!   By the similarity relations of transport theory (Wyman, Patterson & Wilson 1989, "Similarity
//!   relations for the interaction parameters in radiation transport"), multiply scattered light in
//!   optically thick media depends on the phase function mostly through `(1 - g) sigma_s`, so
//!   keeping `g` keeps the bulk of the cloud right; the shape of the forward peak (the silver
//!   lining) differs.
//! - A gradient sky becomes a constant sky of the same irradiance on a horizontal surface.

use crate::environment::SkyRadiance;
use crate::optics::PhaseLobes;
use crate::scene::{PhaseFunction, Scene, SkyModel};

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
/// The renderer's mixture [`PhaseLobes::from_scene`], `(1 - w_D) HG(g_HG) + w_D Draine(g_D,
/// alpha)`, keeps its HG lobe; its Draine lobe becomes an HG lobe of the Draine lobe's mean cosine.
/// Lobes of zero weight are left out, so:
///
/// - `hg`: one lobe, exact.
/// - `dual_hg`: two lobes, exact (the back lobe is a Draine lobe with `alpha = 0`, which is HG).
/// - `mie`: the Draine lobe of Jendersie & d'Eon 2023 becomes an HG lobe of the same mean cosine,
///   which keeps the total mean cosine (0.879 at 20 um).
pub(crate) fn hg_lobes(phase: &PhaseFunction) -> Vec<HgLobe> {
    let lobes = PhaseLobes::from_scene(phase);
    let draine_alone = PhaseLobes {
        w_draine: 1.0,
        ..lobes
    };
    [
        HgLobe {
            weight: 1.0 - lobes.w_draine,
            g: lobes.g_hg,
        },
        HgLobe {
            weight: lobes.w_draine,
            g: draine_alone.mean_cosine(),
        },
    ]
    .into_iter()
    .filter(|lobe| lobe.weight > 0.0)
    .collect()
}

/// Radiance of a constant sky that gives a horizontal surface the same irradiance as the scene's
/// sky: the cosine-weighted mean of its radiance over the upper hemisphere, `E_up / pi`
/// ([`SkyRadiance::irradiance_up`]). For the gradient `L = H + (Z - H) sin(elevation)^k` this is
/// `H + (Z - H) 2 / (k + 2)`; for the atmosphere, its irradiance table at the camera. A constant
/// sky keeps its radiance exactly (no round trip through
/// `pi`). The lower hemisphere gets the same radiance (hidden by the ground when there is one).
pub(crate) fn constant_sky_radiance(scene: &Scene) -> [f32; 3] {
    match scene.sky.model {
        SkyModel::Constant => scene.sky.radiance,
        SkyModel::Gradient => {
            (SkyRadiance::from_scene(scene).irradiance_up() / std::f32::consts::PI).to_array()
        }
        SkyModel::Atmosphere => {
            let env = crate::environment::Environment::from_scene(scene);
            let camera = glam::Vec3::from_array(scene.camera.position_m);
            let viewed = crate::environment::ViewedEnvironment::new(&env, camera);
            (viewed.sky_irradiance_up(camera) / std::f32::consts::PI).to_array()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::optics::draine;
    use crate::scene::{PhaseModel, Sky};

    /// Midpoint rule over [a, b] with `n` intervals.
    fn integrate(a: f64, b: f64, n: usize, f: impl Fn(f64) -> f64) -> f64 {
        let h = (b - a) / n as f64;
        (0..n).map(|i| f(a + (i as f64 + 0.5) * h)).sum::<f64>() * h
    }

    fn phase(model: PhaseModel) -> PhaseFunction {
        PhaseFunction {
            model,
            ..Default::default()
        }
    }

    #[test]
    fn mie_lobes_keep_the_published_mean_cosine() {
        let lobes = hg_lobes(&phase(PhaseModel::Mie));
        assert_eq!(lobes.len(), 2);
        let mean_cosine: f32 = lobes.iter().map(|lobe| lobe.weight * lobe.g).sum();
        assert!((mean_cosine - 0.879).abs() < 1e-3, "{mean_cosine}");
        assert!((lobes.iter().map(|lobe| lobe.weight).sum::<f32>() - 1.0).abs() < 1e-6);
    }

    #[test]
    fn mie_draine_lobe_becomes_hg_of_its_mean_cosine() {
        let mie = PhaseLobes::approximate_mie(20.0);
        let per_mu = |mu: f64| {
            2.0 * std::f64::consts::PI * f64::from(draine(mie.g_draine, mie.alpha, mu as f32))
        };
        let numeric = integrate(-1.0, 1.0, 200_000, |mu| mu * per_mu(mu));
        let replaced = hg_lobes(&phase(PhaseModel::Mie))[1];
        assert!(
            (f64::from(replaced.g) - numeric).abs() < 1e-4,
            "{replaced:?}"
        );
        assert!((replaced.weight - mie.w_draine).abs() < 1e-7);
    }

    #[test]
    fn hg_and_dual_hg_lobes_are_the_scene_lobes() {
        let single = PhaseFunction {
            g: 0.85,
            ..phase(PhaseModel::Hg)
        };
        assert_eq!(
            hg_lobes(&single),
            [HgLobe {
                weight: 1.0,
                g: 0.85
            }]
        );
        let dual = hg_lobes(&phase(PhaseModel::DualHg));
        assert_eq!(dual.len(), 2);
        assert!((dual[0].weight - 0.7).abs() < 1e-6 && dual[0].g == 0.8);
        assert!((dual[1].weight - 0.3).abs() < 1e-6 && dual[1].g == -0.3);
    }

    #[test]
    fn gradient_sky_becomes_its_cosine_weighted_mean() {
        let mut scene = Scene {
            sky: Sky {
                model: SkyModel::Gradient,
                gradient_exponent: 0.45,
                ..Default::default()
            },
            ..Default::default()
        };
        let sky = &scene.sky;
        let k = f64::from(sky.gradient_exponent);
        let average = constant_sky_radiance(&scene);
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
        scene.sky.model = SkyModel::Constant;
        assert_eq!(constant_sky_radiance(&scene), scene.sky.radiance);
    }
}
