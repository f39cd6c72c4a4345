//! Where a scene uses a model that Mitsuba 3 lacks, the closest thing Mitsuba has.
//!
//! - Phase functions without a Draine lobe of `alpha > 0` (`hg`, `dual_hg`) are one or two
//!   Henyey-Greenstein lobes, which Mitsuba has exactly ([`ExportedPhase::Lobes`]).
//! - The approximate Mie function of Jendersie & d'Eon 2023 (`mie`) becomes a table of
//!   [`PHASE_TABLE_NODES`] values on a regular grid of the scattering cosine
//!   ([`ExportedPhase::Table`], Mitsuba's `tabphase`), which keeps its integral and mean cosine and
//!   spreads its forward peak over one grid step ([`tabulate_phase`]).
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

/// A scene's phase function as Mitsuba gets it.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum ExportedPhase {
    /// Exact: HG lobes whose weights sum to 1 (Mitsuba's `hg`, or `blendphase` of two).
    Lobes(Vec<HgLobe>),
    /// [`tabulate_phase`] at [`PHASE_TABLE_NODES`] nodes, the first at `cos_theta = -1` (Mitsuba's
    /// `tabphase`).
    Table(Vec<f32>),
}

/// Nodes of the phase-function table: a grid step of `2 / 65536 = 3.1e-5` in the scattering
/// cosine, which resolves scattering angles down to `acos(1 - 3.1e-5) = 0.45` deg (the HG lobe of
/// 20 um droplets, `g = 0.9946`, falls to half its peak at 0.24 deg). About 0.8 MB of XML.
pub(crate) const PHASE_TABLE_NODES: usize = 65_537;

/// Simpson intervals per grid cell in [`tabulate_phase`]'s quadrature.
const SIMPSON_INTERVALS: usize = 16;

/// The scene's phase function for Mitsuba, from the renderer's mixture [`PhaseLobes::from_scene`],
/// `(1 - w_D) HG(g_HG) + w_D Draine(g_D, alpha)`:
///
/// - `hg`: one HG lobe, exact.
/// - `dual_hg`: two HG lobes, exact (the back lobe is a Draine lobe with `alpha = 0`, which is HG).
/// - `mie`: the whole mixture tabulated by [`tabulate_phase`].
///
/// Lobes of zero weight are left out.
pub(crate) fn exported_phase(phase: &PhaseFunction) -> ExportedPhase {
    let lobes = PhaseLobes::from_scene(phase);
    if lobes.w_draine > 0.0 && lobes.alpha != 0.0 {
        return ExportedPhase::Table(tabulate_phase(&lobes, PHASE_TABLE_NODES));
    }
    let hg = [
        HgLobe {
            weight: 1.0 - lobes.w_draine,
            g: lobes.g_hg,
        },
        HgLobe {
            weight: lobes.w_draine,
            g: lobes.g_draine,
        },
    ];
    ExportedPhase::Lobes(hg.into_iter().filter(|lobe| lobe.weight > 0.0).collect())
}

/// The phase function `lobes` (per steradian, [`PhaseLobes::eval`]) as `nodes >= 2` values on the
/// regular grid `mu_i = -1 + 2 i / (nodes - 1)` of the scattering cosine, for Mitsuba 3's
/// `tabphase`.
///
/// Mitsuba's convention (plugin documentation of `tabphase`) is the renderer's
/// ([`crate::optics::phase`]): the cosine is that between the directions light travels before and
/// after scattering, `1` forward; the nodes are evenly spaced over [-1, 1]; Mitsuba interpolates
/// linearly between them and normalises the result itself.
///
/// Point values cannot follow a droplet's forward peak on a practical grid: the HG lobe of 20 um
/// droplets (`g = 0.9946`) falls to a third of its peak within `1 - mu = 1.5e-5`, and the linear interpolant of point
/// values at 65537 nodes holds 1.10 of the energy (mean cosine 0.890 against 0.879); it takes about
/// 10^6 nodes to come within 0.1 %. So node `i` holds instead the phase function's average against
/// its hat function `hat_i` (the piecewise-linear function that is 1 at `mu_i` and 0 at the other
/// nodes): `v_i = int p hat_i dmu / int hat_i dmu`. The hats sum to 1 and reproduce linear
/// functions, so the interpolant `sum_i v_i hat_i` has exactly the integral of `p`, and its mean
/// cosine is off only by the two half hats at the ends, by less than `h / 3` times their share of
/// the energy for the grid step `h`. The forward peak is spread over the last grid step.
///
/// Measured for 20 um droplets at [`PHASE_TABLE_NODES`] (test
/// `mie_table_keeps_the_integral_and_mean_cosine`, with the `f32` values written): integral
/// `1 - 2e-9`, mean cosine 0.8793090 against the exact 0.8793104 (closed form,
/// [`PhaseLobes::mean_cosine`]); 0.8434240 against 0.8434241 at 5 um and 0.8911907 against 0.8911936
/// at 50 um. The test bounds both differences by 1e-5 over the fit's 5-50 um.
///
/// The hat integrals are Simpson's rule per cell after the substitution `t = ln(1 - mu + x0)`,
/// `x0` the half width `(1 - g)^2 / (2 g)` of the sharpest forward lobe (where the HG denominator
/// `(1 - g)^2 + 2 g (1 - mu)` doubles), which makes the peak smooth in `t`.
pub(crate) fn tabulate_phase(lobes: &PhaseLobes, nodes: usize) -> Vec<f32> {
    assert!(nodes >= 2, "a phase table needs two nodes or more");
    let h = 2.0 / (nodes - 1) as f64;
    let x0 = forward_half_width(lobes);
    let node = |i: usize| -1.0 + h * i as f64;
    let mut hat_integrals = vec![0.0; nodes];
    for cell in 0..nodes - 1 {
        let (left, right) = cell_hat_integrals(lobes, node(cell), node(cell + 1), x0);
        hat_integrals[cell] += left;
        hat_integrals[cell + 1] += right;
    }
    let last = nodes - 1;
    hat_integrals
        .iter()
        .enumerate()
        .map(|(i, integral)| {
            let hat_area = if i == 0 || i == last { h / 2.0 } else { h };
            (integral / hat_area) as f32
        })
        .collect()
}

/// `1 - mu` where the sharpest forward lobe of `lobes` falls to about a third of its peak,
/// `(1 - g)^2 / (2 g)`; 1 when no lobe scatters forward.
fn forward_half_width(lobes: &PhaseLobes) -> f64 {
    [
        (1.0 - lobes.w_draine, lobes.g_hg),
        (lobes.w_draine, lobes.g_draine),
    ]
    .into_iter()
    .filter(|&(weight, g)| weight > 0.0 && g > 0.0)
    .map(|(_, g)| {
        let g = f64::from(g);
        (1.0 - g) * (1.0 - g) / (2.0 * g)
    })
    .fold(1.0, f64::min)
    .max(1e-12)
}

/// Over the grid cell `[a, b]`: `(int p (b - mu) / (b - a) dmu, int p (mu - a) / (b - a) dmu)`,
/// the parts of the hat integrals of its left and right node, by Simpson's rule in
/// `t = ln(1 - mu + x0)` (`mu = 1 + x0 - e^t`, `dmu = -e^t dt`).
fn cell_hat_integrals(lobes: &PhaseLobes, a: f64, b: f64, x0: f64) -> (f64, f64) {
    let (t_low, t_high) = ((1.0 - b + x0).ln(), (1.0 - a + x0).ln());
    let step = (t_high - t_low) / SIMPSON_INTERVALS as f64;
    let (mut left, mut right) = (0.0, 0.0);
    for k in 0..=SIMPSON_INTERVALS {
        let simpson = match k {
            0 | SIMPSON_INTERVALS => 1.0,
            _ if k % 2 == 1 => 4.0,
            _ => 2.0,
        };
        let e = (t_low + step * k as f64).exp();
        let mu = (1.0 + x0 - e).clamp(a, b);
        let weighted = simpson * e * lobes.eval_f64(mu);
        left += weighted * (b - mu);
        right += weighted * (mu - a);
    }
    let scale = step / 3.0 / (b - a);
    (left * scale, right * scale)
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

    /// Integral over the sphere and mean cosine of the function Mitsuba builds from `table`: the
    /// linear interpolant between evenly spaced nodes over [-1, 1] (exact for each linear piece).
    fn interpolant_moments(table: &[f32]) -> (f64, f64) {
        let h = 2.0 / (table.len() - 1) as f64;
        let (mut integral, mut moment) = (0.0, 0.0);
        for (i, pair) in table.windows(2).enumerate() {
            let (v0, v1) = (f64::from(pair[0]), f64::from(pair[1]));
            let (a, b) = (-1.0 + h * i as f64, -1.0 + h * (i + 1) as f64);
            integral += h * (v0 + v1) / 2.0;
            moment += h * (v0 * (2.0 * a + b) + v1 * (a + 2.0 * b)) / 6.0;
        }
        let tau = 2.0 * std::f64::consts::PI;
        (tau * integral, moment / integral)
    }

    fn table(exported: ExportedPhase) -> Vec<f32> {
        match exported {
            ExportedPhase::Table(values) => values,
            ExportedPhase::Lobes(lobes) => panic!("expected a table, got {lobes:?}"),
        }
    }

    #[test]
    fn mie_table_keeps_the_integral_and_mean_cosine() {
        for diameter in [5.0, 20.0, 50.0] {
            let lobes = PhaseLobes::approximate_mie(diameter);
            let values = tabulate_phase(&lobes, PHASE_TABLE_NODES);
            let (integral, mean_cosine) = interpolant_moments(&values);
            let exact = f64::from(lobes.mean_cosine());
            println!(
                "{diameter} um: integral {integral:.10}, mean cosine {mean_cosine:.7} vs {exact:.7}"
            );
            assert!((integral - 1.0).abs() < 1e-5, "{diameter} um: {integral}");
            assert!(
                (mean_cosine - exact).abs() < 1e-5,
                "{diameter} um: {mean_cosine} vs {exact}"
            );
        }
    }

    #[test]
    fn mie_table_runs_from_back_to_forward_and_matches_the_function_away_from_the_peak() {
        let values = table(exported_phase(&phase(PhaseModel::Mie)));
        assert_eq!(values.len(), PHASE_TABLE_NODES);
        let lobes = PhaseLobes::approximate_mie(20.0);
        let h = 2.0 / (PHASE_TABLE_NODES - 1) as f32;
        for i in [0, 1000, PHASE_TABLE_NODES / 2, 60_000] {
            let mu = -1.0 + h * i as f32;
            let exact = lobes.eval(mu);
            assert!(
                (values[i] / exact - 1.0).abs() < 1e-4,
                "mu {mu}: {} vs {exact}",
                values[i]
            );
        }
        // At the forward node the peak is averaged over the last grid step: far above the
        // back-scattering value, below the point value.
        let forward = values[PHASE_TABLE_NODES - 1];
        assert!(
            forward > 1e4 * values[0] && forward < lobes.eval(1.0),
            "{forward}"
        );
    }

    #[test]
    fn hg_and_dual_hg_are_the_scene_lobes() {
        let single = PhaseFunction {
            g: 0.85,
            ..phase(PhaseModel::Hg)
        };
        assert_eq!(
            exported_phase(&single),
            ExportedPhase::Lobes(vec![HgLobe {
                weight: 1.0,
                g: 0.85
            }])
        );
        let ExportedPhase::Lobes(dual) = exported_phase(&phase(PhaseModel::DualHg)) else {
            panic!("dual HG is exact as HG lobes");
        };
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
