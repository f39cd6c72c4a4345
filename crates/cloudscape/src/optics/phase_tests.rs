//! Tests of the phase functions: normalisation, mean cosine, known forms and parameters, and the
//! chi-square goodness of fit of the samplers against the densities.

use super::*;
use crate::optics::test_support::{Pcg32, chi_square_p_value};
use crate::scene::{PhaseFunction, PhaseModel};
use glam::DVec3;

/// Bands of scattering angle, with edges `theta_i = pi (i / n)^3`: narrow near the forward peak.
const THETA_BANDS: usize = 64;
/// Azimuth bins of the chi-square test.
const PHI_BINS: usize = 8;
/// Samples per chi-square test.
const SAMPLES: usize = 200_000;
/// Simpson intervals per band.
const SIMPSON_INTERVALS: usize = 64;

fn theta_edge(i: usize) -> f64 {
    PI * (i as f64 / THETA_BANDS as f64).powi(3)
}

fn theta_band(theta: f64) -> usize {
    (((theta / PI).cbrt() * THETA_BANDS as f64) as usize).min(THETA_BANDS - 1)
}

/// Solid-angle integral `2 pi int f(cos theta) sin theta dtheta` over one band, by Simpson's rule.
fn band_integral(f: &impl Fn(f64) -> f64, theta_lo: f64, theta_hi: f64) -> f64 {
    let h = (theta_hi - theta_lo) / SIMPSON_INTERVALS as f64;
    let integrand = |k: usize| {
        let theta = theta_lo + h * k as f64;
        f(theta.cos()) * theta.sin()
    };
    let interior: f64 = (1..SIMPSON_INTERVALS)
        .map(|k| if k % 2 == 1 { 4.0 } else { 2.0 } * integrand(k))
        .sum();
    2.0 * PI * h / 3.0 * (integrand(0) + interior + integrand(SIMPSON_INTERVALS))
}

/// Integral of `f(mu)` over the whole sphere of directions.
fn sphere_integral(f: impl Fn(f64) -> f64) -> f64 {
    (0..THETA_BANDS)
        .map(|i| band_integral(&f, theta_edge(i), theta_edge(i + 1)))
        .sum()
}

fn draine_only(g: f32, alpha: f32) -> PhaseLobes {
    PhaseLobes {
        g_hg: 0.0,
        g_draine: g,
        alpha,
        w_draine: 1.0,
    }
}

/// Every model the scene can ask for, plus Draine lobes at the edges of the sampler's range.
fn models() -> Vec<(&'static str, PhaseLobes)> {
    vec![
        ("HG(0.8)", PhaseLobes::henyey_greenstein(0.8)),
        ("HG(-0.3)", PhaseLobes::henyey_greenstein(-0.3)),
        ("HG(0)", PhaseLobes::henyey_greenstein(0.0)),
        (
            "dual HG",
            PhaseLobes::dual_henyey_greenstein(0.8, -0.3, 0.7),
        ),
        ("Draine(0.5, 1)", draine_only(0.5, 1.0)),
        ("Draine(0, 3)", draine_only(0.0, 3.0)),
        ("Draine(-0.6, 10)", draine_only(-0.6, 10.0)),
        ("Draine(1e-4, 5)", draine_only(1e-4, 5.0)),
        ("Mie 5um", PhaseLobes::approximate_mie(5.0)),
        ("Mie 20um", PhaseLobes::approximate_mie(20.0)),
        ("Mie 50um", PhaseLobes::approximate_mie(50.0)),
    ]
}

#[test]
fn every_model_integrates_to_one() {
    for (name, lobes) in models() {
        let total = sphere_integral(|mu| lobes.eval_f64(mu));
        assert!((total - 1.0).abs() < 1e-9, "{name}: integral {total}");
    }
}

#[test]
fn mean_cosine_matches_quadrature() {
    for (name, lobes) in models() {
        let quadrature = sphere_integral(|mu| mu * lobes.eval_f64(mu));
        let closed_form = f64::from(lobes.mean_cosine());
        assert!(
            (quadrature - closed_form).abs() < 1e-5,
            "{name}: {quadrature} vs {closed_form}"
        );
    }
}

#[test]
fn mie_parameters_match_jendersie_deon_for_20_um() {
    let mie = PhaseLobes::approximate_mie(20.0);
    assert!((mie.g_hg - 0.9946).abs() < 5e-5, "g_HG {}", mie.g_hg);
    assert!((mie.g_draine - 0.5938).abs() < 5e-5, "g_D {}", mie.g_draine);
    assert!((mie.alpha - 27.1).abs() < 0.05, "alpha {}", mie.alpha);
    assert!((mie.w_draine - 0.498).abs() < 5e-4, "w_D {}", mie.w_draine);
    assert!(
        (mie.mean_cosine() - 0.879).abs() < 5e-4,
        "<mu> {}",
        mie.mean_cosine()
    );
}

#[test]
fn mie_clamps_diameter_to_fit_range() {
    assert_eq!(
        PhaseLobes::approximate_mie(1.0),
        PhaseLobes::approximate_mie(5.0)
    );
    assert_eq!(
        PhaseLobes::approximate_mie(90.0),
        PhaseLobes::approximate_mie(50.0)
    );
}

#[test]
fn draine_reduces_to_hg_and_cornette_shanks() {
    for &(g, mu) in &[(0.8f32, 0.3f32), (-0.4, -0.9), (0.5, 1.0), (0.0, 0.2)] {
        let hg = henyey_greenstein(g, mu);
        assert!(
            (draine(g, 0.0, mu) - hg).abs() <= 1e-6 * hg,
            "alpha 0, g {g}, mu {mu}"
        );
        let denom = 1.0 + g * g - 2.0 * g * mu;
        let cornette_shanks = 3.0 / (8.0 * std::f32::consts::PI) * (1.0 - g * g) * (1.0 + mu * mu)
            / ((2.0 + g * g) * denom * denom.sqrt());
        let d = draine(g, 1.0, mu);
        assert!(
            (d - cornette_shanks).abs() <= 1e-5 * cornette_shanks,
            "alpha 1: {d} vs CS"
        );
    }
}

#[test]
fn isotropic_hg_is_one_over_four_pi() {
    let iso = 1.0 / (4.0 * std::f32::consts::PI);
    for mu in [-1.0, 0.0, 0.7, 1.0] {
        assert!((henyey_greenstein(0.0, mu) - iso).abs() < 1e-7);
    }
}

#[test]
fn from_scene_maps_every_model() {
    let with_model = |model| PhaseFunction {
        model,
        ..PhaseFunction::default()
    };
    let p = with_model(PhaseModel::Mie);
    assert_eq!(
        PhaseLobes::from_scene(&p),
        PhaseLobes::approximate_mie(p.droplet_diameter_um)
    );
    let p = with_model(PhaseModel::Hg);
    assert_eq!(
        PhaseLobes::from_scene(&p),
        PhaseLobes::henyey_greenstein(p.g)
    );
    let p = with_model(PhaseModel::DualHg);
    let dual = PhaseLobes::from_scene(&p);
    let mu = 0.4;
    let expected = p.forward_weight * henyey_greenstein(p.g_forward, mu)
        + (1.0 - p.forward_weight) * henyey_greenstein(p.g_back, mu);
    assert!((dual.eval(mu) - expected).abs() < 1e-6 * expected);
}

#[test]
fn scaled_anisotropy_scales_only_the_asymmetries() {
    let mie = PhaseLobes::approximate_mie(20.0);
    let half = mie.scaled_anisotropy(0.5);
    assert_eq!(
        (half.g_hg, half.g_draine),
        (mie.g_hg * 0.5, mie.g_draine * 0.5)
    );
    assert_eq!((half.alpha, half.w_draine), (mie.alpha, mie.w_draine));
    let flat = PhaseLobes::henyey_greenstein(0.9).scaled_anisotropy(0.0);
    assert_eq!(flat.eval(1.0), flat.eval(-1.0));
}

#[test]
fn droplets_of_every_size_have_a_diffraction_peak_and_moderate_lobes_none() {
    for d in [5.0, 10.0, 20.0, 50.0] {
        let mie = PhaseLobes::approximate_mie(d);
        assert_eq!(mie.diffraction_peak_weight(), 1.0 - mie.w_draine, "{d} um");
        assert!(mie.diffraction_peak_weight() > 0.3, "{d} um");
    }
    assert_eq!(
        PhaseLobes::henyey_greenstein(0.85).diffraction_peak_weight(),
        0.0
    );
    let dual = PhaseLobes::dual_henyey_greenstein(0.8, -0.3, 0.9);
    assert_eq!(dual.diffraction_peak_weight(), 0.0);
}

#[test]
fn the_broad_share_leaves_out_the_peak_where_it_scatters() {
    let mie = PhaseLobes::approximate_mie(20.0);
    let peak = mie.diffraction_peak_weight();
    // Toward the sun the peak is nearly all of p; beyond a few degrees nearly none of it.
    assert!(mie.broad_share(peak, 1.0) < 0.01);
    assert!(mie.broad_share(peak, 20f32.to_radians().cos()) > 0.95);
    assert!(mie.broad_share(peak, -1.0) > 0.99);
    // Weighted by p over the sphere, the broad share is the broad lobes' weight.
    let broad = sphere_integral(|mu| {
        let mu = mu as f32;
        f64::from(mie.eval(mu) * mie.broad_share(peak, mu))
    });
    assert!((broad - f64::from(mie.w_draine)).abs() < 1e-3, "{broad}");
    // Without a peak every direction is broad.
    let hg = PhaseLobes::henyey_greenstein(0.85);
    assert_eq!(hg.broad_share(0.0, 1.0), 1.0);
}

#[test]
fn to_gpu_layout_is_g_hg_g_draine_alpha_w() {
    let lobes = PhaseLobes {
        g_hg: 0.9,
        g_draine: 0.5,
        alpha: 20.0,
        w_draine: 0.4,
    };
    assert_eq!(lobes.to_gpu(), [0.9, 0.5, 20.0, 0.4]);
}

/// Scattering angle and azimuth of `out` about `axis`, in double precision (the cross product
/// keeps small angles exact where `acos` of the dot product would not).
fn angles(axis: Vec3, out: Vec3) -> (f64, f64) {
    let (axis, out) = (axis.as_dvec3(), out.as_dvec3());
    let theta = axis.cross(out).length().atan2(axis.dot(out));
    let (t, b) = axis.any_orthonormal_pair();
    let phi = out.dot(b).atan2(out.dot(t)).rem_euclid(2.0 * PI);
    (theta, phi)
}

/// Chi-square p-value of `sampled.sample` against the density of `evaluated`.
fn sampler_p_value(sampled: &PhaseLobes, evaluated: &PhaseLobes, seed: u64) -> f64 {
    let incoming = DVec3::new(0.3, -0.5, 0.8).normalize().as_vec3();
    let mut rng = Pcg32::new(seed, 7);
    let mut observed = vec![0u64; THETA_BANDS * PHI_BINS];
    for _ in 0..SAMPLES {
        let u = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32());
        let out = sampled.sample(incoming, u);
        assert!((out.length() - 1.0).abs() < 1e-5, "sample not unit: {out}");
        let (theta, phi) = angles(incoming, out);
        let phi_bin = ((phi / (2.0 * PI) * PHI_BINS as f64) as usize).min(PHI_BINS - 1);
        observed[theta_band(theta) * PHI_BINS + phi_bin] += 1;
    }
    let density = |mu| evaluated.eval_f64(mu);
    let expected: Vec<f64> = (0..THETA_BANDS)
        .flat_map(|i| {
            let p = band_integral(&density, theta_edge(i), theta_edge(i + 1));
            std::iter::repeat_n(p * SAMPLES as f64 / PHI_BINS as f64, PHI_BINS)
        })
        .collect();
    chi_square_p_value(&observed, &expected)
}

#[test]
fn samplers_pass_chi_square() {
    let cases = [
        ("HG(0.8)", PhaseLobes::henyey_greenstein(0.8)),
        ("HG(-0.3)", PhaseLobes::henyey_greenstein(-0.3)),
        (
            "dual HG",
            PhaseLobes::dual_henyey_greenstein(0.8, -0.3, 0.7),
        ),
        ("Draine(0.5, 1)", draine_only(0.5, 1.0)),
        ("Draine(0, 3)", draine_only(0.0, 3.0)),
        ("Draine(-0.6, 10)", draine_only(-0.6, 10.0)),
        ("Draine(1e-4, 5)", draine_only(1e-4, 5.0)),
        ("Mie 20um", PhaseLobes::approximate_mie(20.0)),
    ];
    for (seed, (name, lobes)) in cases.iter().enumerate() {
        let p = sampler_p_value(lobes, lobes, seed as u64);
        assert!(p > 0.01, "{name}: chi-square p-value {p}");
    }
}

/// CDF of the Draine lobe at `mu` by Simpson quadrature in `mu` (the lobes tested are smooth).
fn draine_cdf_by_quadrature(g: f64, alpha: f64, mu: f64) -> f64 {
    let intervals = 4000;
    let h = (mu + 1.0) / intervals as f64;
    let f = |k: usize| 2.0 * PI * draine_f64(g, alpha, -1.0 + h * k as f64);
    let interior: f64 = (1..intervals)
        .map(|k| if k % 2 == 1 { 4.0 } else { 2.0 } * f(k))
        .sum();
    h / 3.0 * (f(0) + interior + f(intervals))
}

#[test]
fn draine_sampler_inverts_the_cdf() {
    // Includes the degenerate corners where a closed-form quartic root loses precision.
    let lobes = [
        (0.5938, 27.1),
        (0.5, 1.0),
        (-0.6, 10.0),
        (0.0, 3.0),
        (1e-4, 5.0),
        (0.7, 1e-6),
    ];
    for (g, alpha) in lobes {
        for u in [1e-4, 0.1, 0.5, 0.9, 0.9999] {
            let (mu, _) = cos_sin_from_s(g, sample_draine_s(g, alpha, u));
            let cdf = draine_cdf_by_quadrature(g, alpha, mu);
            assert!(
                (cdf - u).abs() < 1e-9,
                "g {g}, alpha {alpha}, u {u}: CDF(mu) = {cdf}"
            );
        }
    }
}

#[test]
fn chi_square_rejects_a_wrong_sampler() {
    let p = sampler_p_value(
        &PhaseLobes::approximate_mie(20.0),
        &PhaseLobes::approximate_mie(18.0),
        3,
    );
    assert!(
        p < 1e-6,
        "a Mie 20um sampler passed against the 18um density: p = {p}"
    );
}

#[test]
fn sampled_cosine_follows_sign_convention() {
    let incoming = Vec3::new(0.0, 0.0, 1.0);
    // u.y = 0 is the start of the CDF (backscatter), u.y -> 1 its end (forward scatter).
    for lobes in [PhaseLobes::henyey_greenstein(0.8), draine_only(0.5, 1.0)] {
        let back = lobes.sample(incoming, Vec3::new(0.99, 0.0, 0.3));
        let forward = lobes.sample(incoming, Vec3::new(0.99, 0.999_999, 0.3));
        assert!(back.dot(incoming) < -0.9999, "{back}");
        assert!(forward.dot(incoming) > 0.9999, "{forward}");
    }
}
