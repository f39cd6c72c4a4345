//! The sun's light inside a cloud by the δ-Eddington solution of a slab along the sun: the ray
//! marcher's former multiple-scattering model (`lighting.model = "slab"`), which the light volume
//! (`environment::light_volume`, the same equations solved in 3-D) replaced; its closed form is what
//! the volume's infinite-slab test holds the volume to, and its beam part
//! ([`SunSlab::beam_scattering`]) is what the march adds per sample beside the volume.
//!
//! At a point the march knows the optical depth toward the sun (`tau_sun`, its light samples) and
//! away from it (`tau_back`, to the far side of the layers). The model takes the cloud there as a
//! plane-parallel slab whose normal is the sun's direction, lit at normal incidence, the point at
//! depth `tau_sun` of a slab `tau_sun + tau_back` thick, and solves the radiative transfer in it by
//! the δ-Eddington approximation (Joseph, Wiscombe & Weinman 1976, "The Delta-Eddington
//! Approximation for Radiative Flux Transfer", J. Atmos. Sci. 33):
//!
//! - **δ-scaling.** The forward peak of the droplets (half their scattering within a fraction of a
//!   degree) is taken out of the phase function into a δ, a fraction `f` equal to its second
//!   Legendre moment (Wiscombe 1977, the δ-M method): `tau' = (1 - omega f) tau`,
//!   `omega' = (1 - f) omega / (1 - omega f)`, `g' = (g - f) / (1 - f)`. For 20 um droplets
//!   `f = 0.80`: the diffuse light sees a cloud a fifth as thick, which is why clouds are bright
//!   far inside.
//! - **Two streams.** In the scaled slab the diffuse radiance is `I0(tau) + mu I1(tau)`; the
//!   moments of the transfer equation give `I1' = -3 (1 - omega') I0 + 3 omega' E / (4 pi) e^-tau`
//!   and `I0' = -(1 - omega' g') I1 + 3 omega' g' E / (4 pi) e^-tau`, with Marshak's conditions
//!   (no diffuse light entering either face). [`diffuse_moments`] solves them in closed form.
//! - **The source toward the eye** (per unit irradiance and unit scattering coefficient), for the
//!   cosine `mu` between the view ray and the sun (the light leaving toward the eye travels at
//!   `mu` to the sunlight):
//!   `p(mu) e^-tau_sun` (single scattering, exact)
//!   `+ p_n(mu) (e^-tau'_sun - e^-tau_sun)` (the light the forward peak scattered and the beam
//!   still carries, scattered once more, spread by its `n` scatterings in the peak:
//!   [`SunSlab::peak_beam`])
//!   `+ k (I0 + g mu I1)` (the diffuse field scattered by the whole phase function).
//!
//! A finite cloud loses light through its sides that the infinite slab keeps, so two factors,
//! fitted to the path tracer on generated scenes (`cloudscape fit-lighting`), close the model:
//! `k` scales the diffuse field and the far side counts `tau_back` times [`SunSlab::back_scale`].
//!
//! `slab.wgsl` (the `slab` shader module) holds the GPU twin.

use super::PhaseLobes;
use std::f32::consts::PI;

/// Largest single-scattering albedo the two-stream solution takes: at 1 its two exponential
/// solutions merge into a linear one. At `1 - 1e-6` the solution differs from the linear one by
/// under 1 % at scaled thicknesses below 50, and its terms cancel by a factor of a few hundred,
/// which `f32` keeps to 1e-4.
pub const MAX_TWO_STREAM_ALBEDO: f32 = 1.0 - 1e-6;

/// The δ-Eddington slab model of the sun's light in a cloud, for one phase function and albedo.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SunSlab {
    /// The droplets' phase function.
    pub lobes: PhaseLobes,
    /// Fraction `f` of the scattering taken into the forward δ: the phase function's second
    /// Legendre moment.
    pub peak_fraction: f32,
    /// Single-scattering albedo `omega`, 0..1.
    pub albedo: f32,
    /// Factor `k` of the diffuse field (3D leakage), fitted.
    pub diffuse_scale: f32,
    /// Factor of the optical depth to the far side, fitted.
    pub back_scale: f32,
}

/// The δ-scaled two-stream slab: what [`diffuse_moments`] solves.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScaledSlab {
    /// Scaled single-scattering albedo `omega'`.
    pub albedo: f32,
    /// Scaled asymmetry `g'`.
    pub asymmetry: f32,
    /// Scaled optical depth of the point under the lit face, along the normal.
    pub depth: f32,
    /// Scaled optical thickness of the slab along the normal.
    pub thickness: f32,
    /// Cosine between the beam and the slab's normal.
    pub incidence: f32,
}

impl SunSlab {
    /// The model for `lobes` and single-scattering `albedo`, with the fitted factors.
    pub fn new(lobes: PhaseLobes, albedo: f32, diffuse_scale: f32, back_scale: f32) -> SunSlab {
        SunSlab {
            lobes,
            peak_fraction: second_legendre_moment(&lobes).clamp(0.0, 0.999),
            albedo: albedo.clamp(0.0, 1.0),
            diffuse_scale,
            back_scale,
        }
    }

    /// `(peak fraction, albedo, diffuse scale, back scale)`: the `params` of `slab.wgsl`'s
    /// `SlabModel` (its `lobes` are [`PhaseLobes::to_gpu`]).
    pub fn params_to_gpu(&self) -> [f32; 4] {
        [
            self.peak_fraction,
            self.albedo,
            self.diffuse_scale,
            self.back_scale,
        ]
    }

    /// The scaled slab along the sun of a point `depth` under the lit face and `back` over the far
    /// one: lit at normal incidence.
    pub fn scaled(&self, depth: f32, back: f32) -> ScaledSlab {
        let (f, omega) = (self.peak_fraction, self.albedo);
        let thinning = 1.0 - omega * f;
        ScaledSlab {
            albedo: ((1.0 - f) * omega / thinning).min(MAX_TWO_STREAM_ALBEDO),
            asymmetry: (self.lobes.mean_cosine() - f) / (1.0 - f),
            depth: thinning * depth,
            thickness: thinning * (depth + self.back_scale * back),
            incidence: 1.0,
        }
    }

    /// The sun's light scattered toward the eye per unit scattering coefficient and unit
    /// irradiance, at `tau_sun` under the sunlit side and `tau_back` over the far one, for the
    /// cosine `cos_theta` between the view ray and the direction to the sun.
    pub fn scattering(&self, cos_theta: f32, tau_sun: f32, tau_back: f32) -> f32 {
        let slab = self.scaled(tau_sun, tau_back);
        let (i0, i1) = diffuse_moments(&slab);
        let diffuse = (i0 + self.lobes.mean_cosine() * cos_theta * i1).max(0.0);
        self.beam_scattering(cos_theta, tau_sun) + self.diffuse_scale * diffuse
    }

    /// The beam's part of [`SunSlab::scattering`]: single scattering, exact, and the forward
    /// peak's light the beam still carries, scattered once more; what the march adds per sample
    /// when the diffuse light comes from the light volume (`slab_beam_scattering`).
    pub fn beam_scattering(&self, cos_theta: f32, tau_sun: f32) -> f32 {
        self.lobes.eval(cos_theta) * (-tau_sun).exp() + self.peak_beam(cos_theta, tau_sun)
    }

    /// The light the forward peak scattered that the beam still carries at `tau_sun`,
    /// `e^-tau' - e^-tau`, scattered toward the eye once more: after a mean `n` scatterings in the
    /// peak (Poisson, given at least one: `n = f tau / (1 - e^(-f tau))`) its spread is that of the
    /// lobes with asymmetries to the power `n + 1` (Henyey-Greenstein lobes convolve so).
    fn peak_beam(&self, cos_theta: f32, tau_sun: f32) -> f32 {
        let in_peak = self.peak_fraction * self.albedo * tau_sun;
        let scattered = (-(tau_sun - in_peak)).exp() - (-tau_sun).exp();
        if scattered <= 0.0 {
            return 0.0;
        }
        let scatterings = in_peak / (1.0 - (-in_peak).exp()).max(1e-20);
        forward_lobes(&self.lobes, scatterings + 1.0).eval(cos_theta) * scattered
    }
}

/// `lobes` with each asymmetry raised to `power` (keeping its sign): the spread of light scattered
/// `power` times in a row.
fn forward_lobes(lobes: &PhaseLobes, power: f32) -> PhaseLobes {
    let raise = |g: f32| g.signum() * g.abs().powf(power);
    PhaseLobes {
        g_hg: raise(lobes.g_hg),
        g_draine: raise(lobes.g_draine),
        ..*lobes
    }
}

/// The moments `(I0, I1)` of the diffuse radiance `I0 + mu I1` at the point of the scaled slab,
/// per unit irradiance of a beam (on a surface facing it) entering its top face at
/// `slab.incidence` (`mu` measured from the normal, pointing into the slab): the Eddington
/// equations' closed-form solution, `I0 = A e^(-lambda (T - t)) + B e^(-lambda t) + P0 e^(-t/mu0)`,
/// `I1 = -l A ... + l B ... + P1 e^(-t/mu0)`, `lambda^2 = 3 (1 - omega) (1 - omega g)`,
/// `l = lambda / (1 - omega g)`, with the beam's particular solution
/// `P0 = mu0^2 s (1 + g - omega g) / (lambda^2 mu0^2 - 1)`, `P1 = mu0 (3 (1 - omega) P0 - s)`,
/// `s = 3 omega / (4 pi)`, and `A, B` from Marshak's conditions `I0 / 2 + I1 / 3 = 0` at the top
/// and `I0 / 2 - I1 / 3 = 0` at the bottom (written with decaying exponentials only, so no
/// thickness overflows). Meador & Weaver 1980 ("Two-Stream Approximations to Radiative Transfer in
/// Planetary Atmospheres", J. Atmos. Sci. 37) give the same system. `slab_diffuse_moments` in
/// `slab.wgsl`.
pub fn diffuse_moments(slab: &ScaledSlab) -> (f32, f32) {
    let (omega, g, mu0) = (slab.albedo, slab.asymmetry, slab.incidence);
    let lambda_sq = 3.0 * (1.0 - omega) * (1.0 - omega * g);
    let lambda = lambda_sq.sqrt();
    // Off the resonance lambda mu0 = 1 of the beam with the homogeneous solution.
    let resonance = lambda_sq * mu0 * mu0 - 1.0;
    let resonance = if resonance.abs() < 1e-3 {
        1e-3
    } else {
        resonance
    };
    let source = 3.0 * omega / (4.0 * PI);
    let p0 = mu0 * mu0 * source * (1.0 + g - omega * g) / resonance;
    let p1 = mu0 * (3.0 * (1.0 - omega) * p0 - source);
    let l = lambda / (1.0 - omega * g);
    let (plus, minus) = (0.5 + l / 3.0, 0.5 - l / 3.0);
    let across = (-lambda * slab.thickness).exp();
    let beam_out = (-slab.thickness / mu0).exp();
    let r_top = -(p0 / 2.0 + p1 / 3.0);
    let r_bottom = -(p0 / 2.0 - p1 / 3.0) * beam_out;
    let det = minus * minus * across * across - plus * plus;
    let a = (r_top * minus * across - plus * r_bottom) / det;
    let b = (minus * across * r_bottom - plus * r_top) / det;
    let (t, thickness) = (slab.depth, slab.thickness);
    let from_bottom = (-lambda * (thickness - t).max(0.0)).exp();
    let from_top = (-lambda * t).exp();
    let beam = (-t / mu0).exp();
    let i0 = a * from_bottom + b * from_top + p0 * beam;
    let i1 = -l * a * from_bottom + l * b * from_top + p1 * beam;
    (i0, i1)
}

/// The second Legendre moment `<P2(mu)> = (3 <mu^2> - 1) / 2` of `lobes`: `g^2` for an HG lobe;
/// for Draine's, `<mu^2> = (<mu^2>_HG + alpha <mu^4>_HG) / (1 + alpha (1 + 2 g^2) / 3)` with the
/// HG moments `<mu^2> = (1 + 2 g^2) / 3` and `<mu^4> = (7 + 20 g^2 + 8 g^4) / 35` (from
/// `<P_n> = g^n`; Draine 2003 normalises the same way).
pub fn second_legendre_moment(lobes: &PhaseLobes) -> f32 {
    let hg = lobes.g_hg * lobes.g_hg;
    let (g, alpha) = (lobes.g_draine, lobes.alpha);
    let g2 = g * g;
    let mu2_hg = (1.0 + 2.0 * g2) / 3.0;
    let mu4_hg = (7.0 + 20.0 * g2 + 8.0 * g2 * g2) / 35.0;
    let mu2 = (mu2_hg + alpha * mu4_hg) / (1.0 + alpha * (1.0 + 2.0 * g2) / 3.0);
    let draine = (3.0 * mu2 - 1.0) / 2.0;
    (1.0 - lobes.w_draine) * hg + lobes.w_draine * draine
}

/// The two-stream slab on the GPU (`slab.wgsl`), the twin of this module.
pub static SLAB_WGSL: crate::shader::WgslModule = crate::shader::wgsl_module!(
    "slab",
    "slab.wgsl",
    [&crate::shader::MATH_WGSL, &super::phase::PHASE_WGSL],
    slab_constants
);

/// The slab's constants as WGSL.
fn slab_constants() -> String {
    crate::shader::wgsl_consts([(
        "SLAB_MAX_TWO_STREAM_ALBEDO",
        crate::shader::WgslConst::F32(MAX_TWO_STREAM_ALBEDO),
    )])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The second moment matches a quadrature of the phase function itself.
    #[test]
    fn the_peak_fraction_is_the_phase_functions_second_moment() {
        for lobes in [
            PhaseLobes::approximate_mie(20.0),
            PhaseLobes::approximate_mie(8.0),
            PhaseLobes::henyey_greenstein(0.8),
            PhaseLobes::dual_henyey_greenstein(0.85, -0.3, 0.9),
        ] {
            // Midpoint rule in s = 1 - mu, finer toward the forward peak.
            let n = 400_000;
            let mut sum = 0.0f64;
            for i in 0..n {
                let u = (i as f64 + 0.5) / n as f64;
                let (s, ds) = (2.0 * u.powi(4), 8.0 * u.powi(3) / n as f64);
                let mu = 1.0 - s;
                let p = f64::from(lobes.eval(mu as f32));
                sum += 2.0 * std::f64::consts::PI * p * (1.5 * mu * mu - 0.5) * ds;
            }
            let moment = second_legendre_moment(&lobes);
            assert!(
                (f64::from(moment) - sum).abs() < 2e-3,
                "{lobes:?}: {moment} vs {sum}"
            );
        }
    }

    /// Without absorption the solution is the linear one derived for `omega = 1`:
    /// `I1 = C1 - k e^-t`, `I0 = C0 - (1 - g) C1 t - k e^-t` with `k = 3 / (4 pi)`,
    /// `C1 = k (1 - e^-T + 2/3 (1 + e^-T)) / (4/3 + (1 - g) T)`, `C0 = k - 2/3 (C1 - k)`.
    #[test]
    fn the_conservative_limit_is_the_linear_solution() {
        let k = 3.0 / (4.0 * std::f64::consts::PI);
        for (t, thickness, g) in [
            (0.0, 5.0, 0.4),
            (1.0, 2.0, 0.4),
            (3.0, 30.0, 0.0),
            (20.0, 40.0, 0.6),
        ] {
            let e_t = f64::exp(-thickness);
            let c1 =
                k * (1.0 - e_t + 2.0 / 3.0 * (1.0 + e_t)) / (4.0 / 3.0 + (1.0 - g) * thickness);
            let c0 = k - 2.0 / 3.0 * (c1 - k);
            let i0 = c0 - (1.0 - g) * c1 * t - k * f64::exp(-t);
            let i1 = c1 - k * f64::exp(-t);
            let slab = ScaledSlab {
                albedo: MAX_TWO_STREAM_ALBEDO,
                asymmetry: g as f32,
                depth: t as f32,
                thickness: thickness as f32,
                incidence: 1.0,
            };
            let (a0, a1) = diffuse_moments(&slab);
            let tolerance = 1e-2 * k;
            assert!(
                (f64::from(a0) - i0).abs() < tolerance,
                "I0 {a0} vs {i0} at {t}/{thickness}"
            );
            assert!(
                (f64::from(a1) - i1).abs() < tolerance,
                "I1 {a1} vs {i1} at {t}/{thickness}"
            );
        }
    }

    /// Energy: without absorption the net downward flux of beam plus diffuse light is the same at
    /// every depth (`F = mu0 e^(-t/mu0) + 4 pi I1 / 3`), at normal and at oblique incidence.
    #[test]
    fn without_absorption_the_net_flux_is_conserved() {
        for incidence in [1.0, 0.5, 0.1] {
            flux_is_conserved(incidence);
        }
    }

    fn flux_is_conserved(incidence: f32) {
        let flux = |t: f32| {
            let slab = ScaledSlab {
                albedo: MAX_TWO_STREAM_ALBEDO,
                asymmetry: 0.4,
                depth: t,
                thickness: 12.0,
                incidence,
            };
            incidence * (-t / incidence).exp() + 4.0 * PI * diffuse_moments(&slab).1 / 3.0
        };
        let at_top = flux(0.0);
        for t in [1.0, 4.0, 9.0, 12.0] {
            assert!(
                (flux(t) - at_top).abs() < 2e-3,
                "{t}: {} vs {at_top}",
                flux(t)
            );
        }
        assert!(at_top > 0.0 && at_top < 1.0);
    }

    /// Absorption only removes light, and a slab of no thickness scatters only once.
    #[test]
    fn absorption_darkens_and_a_wisp_scatters_once() {
        let lobes = PhaseLobes::approximate_mie(20.0);
        let white = SunSlab::new(lobes, 1.0, 1.0, 1.0);
        let grey = SunSlab::new(lobes, 0.9, 1.0, 1.0);
        for (mu, tau_sun, tau_back) in [(0.3, 2.0, 20.0), (-0.5, 10.0, 5.0), (0.9, 0.5, 50.0)] {
            assert!(
                grey.scattering(mu, tau_sun, tau_back) < white.scattering(mu, tau_sun, tau_back)
            );
        }
        let wisp = white.scattering(0.2, 0.0, 0.0);
        assert!((wisp - lobes.eval(0.2)).abs() < 1e-6 * lobes.eval(0.2).max(1.0));
    }

    /// Deep inside a thick cloud the diffuse light outlives the beam by orders of magnitude: the
    /// octave model's failure that this model exists to fix.
    #[test]
    fn the_diffuse_light_outlives_the_beam() {
        let slab = SunSlab::new(PhaseLobes::approximate_mie(20.0), 1.0, 1.0, 1.0);
        let deep = slab.scattering(0.0, 60.0, 60.0);
        assert!(deep > 0.01, "{deep}");
        assert!(deep > 1e6 * (-60.0f32).exp());
    }
}
