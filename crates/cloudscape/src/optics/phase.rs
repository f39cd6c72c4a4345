//! Phase functions of cloud droplets: evaluation, importance sampling, GPU parameters.
//!
//! Every phase model of a scene is a mixture of one Henyey-Greenstein lobe and one Draine lobe
//! ([`PhaseLobes`]); this covers plain HG, dual-lobe HG (a Draine lobe with `alpha = 0` is HG) and
//! the approximate Mie function of Jendersie & d'Eon 2023.
//!
//! **Sign convention.** `cos_theta = dot(w_before, w_after)`, where both unit vectors point the way
//! light travels, before and after scattering. Forward scattering (light keeps going) is
//! `cos_theta = 1`, and a positive asymmetry `g` means forward scattering.
//!
//! All densities are per steradian: they integrate to 1 over the sphere of directions.
//!
//! The formulas are evaluated in `f64` and rounded to `f32` at the interface, so that the very
//! peaked lobes of cloud droplets (`g` near 0.995) keep their precision near `cos_theta = 1`.

use glam::Vec3;
use std::f64::consts::PI;

/// Smallest droplet diameter, in micrometres, of the approximate-Mie fit (Jendersie & d'Eon 2023).
pub const MIE_FIT_MIN_DIAMETER_UM: f32 = 5.0;
/// Largest droplet diameter, in micrometres, of the approximate-Mie fit (Jendersie & d'Eon 2023).
pub const MIE_FIT_MAX_DIAMETER_UM: f32 = 50.0;

/// Least asymmetry of a Henyey-Greenstein lobe that [`PhaseLobes::diffraction_peak_weight`]
/// counts as the droplets' diffraction peak: such a lobe scatters half its light by under 3
/// degrees (`g = 0.9946`, 20 um droplets: 0.54 degrees), and Jendersie & d'Eon 2023's fit gives its
/// HG lobe at least 0.9707 over the whole 5..50 um range, so every droplet size has a peak.
pub const DIFFRACTION_PEAK_MIN_ASYMMETRY: f32 = 0.97;

/// One of the two lobes of a [`PhaseLobes`] mixture.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Lobe {
    /// The Henyey-Greenstein lobe (for droplets, the narrow diffraction peak).
    HenyeyGreenstein,
    /// The Draine lobe (for droplets, the broad rest).
    Draine,
}

/// A mixture of a Henyey-Greenstein lobe and a Draine lobe:
/// `p(mu) = (1 - w_draine) * HG(g_hg, mu) + w_draine * Draine(g_draine, alpha, mu)`.
///
/// Mixture form and its use for water droplets: Jendersie & d'Eon 2023, "An Approximate Mie
/// Scattering Function for Fog and Cloud Rendering" (SIGGRAPH talk).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PhaseLobes {
    /// Asymmetry of the Henyey-Greenstein lobe, in (-1, 1).
    pub g_hg: f32,
    /// Asymmetry parameter of the Draine lobe, in (-1, 1).
    pub g_draine: f32,
    /// Draine's `alpha` (>= 0): 0 makes the lobe HG, 1 makes it Cornette-Shanks.
    pub alpha: f32,
    /// Weight of the Draine lobe, 0..1.
    pub w_draine: f32,
}

impl PhaseLobes {
    /// A single Henyey-Greenstein lobe of asymmetry `g` in (-1, 1) (Henyey & Greenstein 1941).
    pub fn henyey_greenstein(g: f32) -> Self {
        PhaseLobes {
            g_hg: g,
            g_draine: 0.0,
            alpha: 0.0,
            w_draine: 0.0,
        }
    }

    /// `forward_weight * HG(g_forward) + (1 - forward_weight) * HG(g_back)`; the back lobe is a
    /// Draine lobe with `alpha = 0`, which is exactly HG (Draine 2003).
    pub fn dual_henyey_greenstein(g_forward: f32, g_back: f32, forward_weight: f32) -> Self {
        PhaseLobes {
            g_hg: g_forward,
            g_draine: g_back,
            alpha: 0.0,
            w_draine: 1.0 - forward_weight,
        }
    }

    /// Approximate Mie scattering by water droplets of effective diameter `droplet_diameter_um`
    /// (micrometres), Jendersie & d'Eon 2023, fit for 5..50 um (values outside are clamped to it):
    /// `g_HG = exp(-0.0990567 / (d - 1.67154))`, `g_D = exp(-2.20679 / (d + 3.91029) - 0.428934)`,
    /// `alpha = exp(3.62489 - 8.29288 / (d + 5.52825))`,
    /// `w_D = exp(-0.599085 / (d - 0.641583) - 0.665888)`.
    pub fn approximate_mie(droplet_diameter_um: f32) -> Self {
        let d = droplet_diameter_um.clamp(MIE_FIT_MIN_DIAMETER_UM, MIE_FIT_MAX_DIAMETER_UM);
        PhaseLobes {
            g_hg: (-0.0990567 / (d - 1.67154)).exp(),
            g_draine: (-2.20679 / (d + 3.91029) - 0.428934).exp(),
            alpha: (3.62489 - 8.29288 / (d + 5.52825)).exp(),
            w_draine: (-0.599085 / (d - 0.641583) - 0.665888).exp(),
        }
    }

    /// Phase function value per steradian for the scattering cosine `cos_theta` (see the module
    /// doc for the sign convention).
    pub fn eval(&self, cos_theta: f32) -> f32 {
        self.eval_f64(f64::from(cos_theta)) as f32
    }

    /// [`Self::eval`] in double precision (the exporter tabulates it for Mitsuba 3).
    pub(crate) fn eval_f64(&self, mu: f64) -> f64 {
        let w = f64::from(self.w_draine);
        (1.0 - w) * hg_f64(f64::from(self.g_hg), mu)
            + w * draine_f64(f64::from(self.g_draine), f64::from(self.alpha), mu)
    }

    /// The share of the scattering that the diffraction peak holds: the Henyey-Greenstein lobe's
    /// weight when the lobe is at least [`DIFFRACTION_PEAK_MIN_ASYMMETRY`] asymmetric, else 0 (a
    /// plain or dual HG model of moderate asymmetry has no peak). Light scattered by the peak keeps
    /// its direction to within a few pixels: the march treats it as not scattered on its way to
    /// the eye (`raymarch.wgsl`, `march_segment`).
    pub fn diffraction_peak_weight(&self) -> f32 {
        if self.g_hg >= DIFFRACTION_PEAK_MIN_ASYMMETRY {
            1.0 - self.w_draine
        } else {
            0.0
        }
    }

    /// The share of `p(cos_theta)` outside a peak of weight `peak_weight` (0 or
    /// [`Self::diffraction_peak_weight`]): `1 - w_p HG(g_hg, mu) / p(mu)`. The GPU twin is
    /// `phase_broad_share`.
    pub fn broad_share(&self, peak_weight: f32, cos_theta: f32) -> f32 {
        let mu = f64::from(cos_theta);
        let peak = f64::from(peak_weight) * hg_f64(f64::from(self.g_hg), mu);
        (1.0 - peak / self.eval_f64(mu)).clamp(0.0, 1.0) as f32
    }

    /// The same lobes with both asymmetries multiplied by `factor`: octave `i` of the
    /// multiple-scattering approximation uses `factor = c^i` (Wrenninge 2013, "Oz: The Great and
    /// Volumetric").
    pub fn scaled_anisotropy(&self, factor: f32) -> Self {
        PhaseLobes {
            g_hg: self.g_hg * factor,
            g_draine: self.g_draine * factor,
            ..*self
        }
    }

    /// Mean cosine `<mu>` of the scattering angle: `g` for HG; for Draine
    /// `g (1 + alpha (3 + 2 g^2) / 5) / (1 + alpha (1 + 2 g^2) / 3)` (Jendersie & d'Eon 2023,
    /// from the HG moments `<mu> = g`, `<mu^3> = (3 g + 2 g^3) / 5`).
    pub fn mean_cosine(&self) -> f32 {
        let (g, a) = (self.g_draine, self.alpha);
        let g2 = g * g;
        let draine_mean =
            g * (1.0 + a * (3.0 + 2.0 * g2) / 5.0) / (1.0 + a * (1.0 + 2.0 * g2) / 3.0);
        (1.0 - self.w_draine) * self.g_hg + self.w_draine * draine_mean
    }

    /// Importance-samples the direction after scattering, exactly distributed as [`Self::eval`].
    ///
    /// `incoming_dir` is the unit direction light travels before scattering; `u` holds three
    /// uniform numbers in [0, 1): `u.x` picks the lobe by weight ([`Self::lobe_for`]), `u.y` the
    /// scattering angle by inverting that lobe's CDF, `u.z` the azimuth. Returns a unit vector.
    pub fn sample(&self, incoming_dir: Vec3, u: Vec3) -> Vec3 {
        self.sample_lobe(self.lobe_for(u.x), incoming_dir, glam::Vec2::new(u.y, u.z))
    }

    /// The lobe [`Self::sample`] draws from for the uniform number `u` in [0, 1): the Draine lobe
    /// with probability `w_draine`.
    pub fn lobe_for(&self, u: f32) -> Lobe {
        if u < self.w_draine {
            Lobe::Draine
        } else {
            Lobe::HenyeyGreenstein
        }
    }

    /// Weight of `lobe` in the mixture, 0..1.
    pub fn lobe_weight(&self, lobe: Lobe) -> f32 {
        match lobe {
            Lobe::Draine => self.w_draine,
            Lobe::HenyeyGreenstein => 1.0 - self.w_draine,
        }
    }

    /// Density of `lobe` alone (normalised over the sphere) for the scattering cosine
    /// `cos_theta`; [`Self::eval`] is the weighted sum of the two.
    pub fn lobe_eval(&self, lobe: Lobe, cos_theta: f32) -> f32 {
        let mu = f64::from(cos_theta);
        let value = match lobe {
            Lobe::Draine => draine_f64(f64::from(self.g_draine), f64::from(self.alpha), mu),
            Lobe::HenyeyGreenstein => hg_f64(f64::from(self.g_hg), mu),
        };
        value as f32
    }

    /// Samples a direction from `lobe` alone, distributed as [`Self::lobe_eval`]: `u.x` inverts
    /// the lobe's CDF, `u.y` picks the azimuth.
    pub fn sample_lobe(&self, lobe: Lobe, incoming_dir: Vec3, u: glam::Vec2) -> Vec3 {
        let uniform = f64::from(u.x);
        let (g, s) = match lobe {
            Lobe::Draine => {
                let g = f64::from(self.g_draine);
                (g, sample_draine_s(g, f64::from(self.alpha), uniform))
            }
            Lobe::HenyeyGreenstein => {
                let g = f64::from(self.g_hg);
                (g, sample_hg_s(g, uniform))
            }
        };
        let (cos_theta, sin_theta) = cos_sin_from_s(g, s);
        rotate_about(
            incoming_dir,
            cos_theta as f32,
            sin_theta as f32,
            std::f32::consts::TAU * u.y,
        )
    }

    /// `(g_hg, g_draine, alpha, w_draine)`, the layout `phase_eval` in `phase.wgsl` expects.
    pub fn to_gpu(&self) -> [f32; 4] {
        [self.g_hg, self.g_draine, self.alpha, self.w_draine]
    }
}

/// Wrenninge's multiple-scattering octaves (Wrenninge 2013, "Oz: The Great and Volumetric"): light
/// scattered `i` more times is approximated by a copy of single scattering whose optical depth,
/// weight and phase asymmetry are scaled by `a^i`, `b^i` and `c^i`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Octaves {
    /// Octaves summed, 1 (single scattering) or more.
    pub count: u32,
    /// Extinction factor `a`: octave `i` sees `a^i` of the optical depth to the sun.
    pub attenuation: f32,
    /// Scattering factor `b`: octave `i` scatters `b^i` of the light.
    pub contribution: f32,
    /// Eccentricity factor `c`: octave `i`'s asymmetries are scaled by `c^i`.
    pub eccentricity: f32,
}

impl Octaves {
    /// Sun light scattered at optical depth `tau` from the sun per unit scattering coefficient
    /// and unit irradiance, for the scattering cosine `cos_theta`:
    /// `sum_i b^i p(c^i g, cos_theta) exp(-a^i tau)`. `phase_octaves` in `phase.wgsl`.
    pub fn scattering(&self, lobes: &PhaseLobes, cos_theta: f32, tau: f32) -> f32 {
        let (mut sum, mut weight, mut extinction, mut anisotropy) = (0.0, 1.0, 1.0, 1.0);
        for _ in 0..self.count {
            let p = lobes.scaled_anisotropy(anisotropy).eval(cos_theta);
            sum += weight * p * (-extinction * tau).exp();
            weight *= self.contribution;
            extinction *= self.attenuation;
            anisotropy *= self.eccentricity;
        }
        sum
    }

    /// The factors `(a, b, c)` as `phase_octaves` takes them.
    pub fn factors(&self) -> [f32; 3] {
        [self.attenuation, self.contribution, self.eccentricity]
    }
}

/// Henyey-Greenstein phase function per steradian (Henyey & Greenstein 1941):
/// `(1 - g^2) / (4 pi (1 + g^2 - 2 g mu)^(3/2))`, `g` in (-1, 1).
pub fn henyey_greenstein(g: f32, cos_theta: f32) -> f32 {
    hg_f64(f64::from(g), f64::from(cos_theta)) as f32
}

/// Draine phase function per steradian (Draine 2003, "Scattering by Interstellar Dust Grains"):
/// `HG(g, mu) (1 + alpha mu^2) / (1 + alpha (1 + 2 g^2) / 3)`. `alpha = 0` gives HG and
/// `alpha = 1` Cornette-Shanks.
pub fn draine(g: f32, alpha: f32, cos_theta: f32) -> f32 {
    draine_f64(f64::from(g), f64::from(alpha), f64::from(cos_theta)) as f32
}

fn hg_f64(g: f64, mu: f64) -> f64 {
    let denom = hg_denominator(g, mu);
    (1.0 - g * g) / (4.0 * PI * denom * denom.sqrt())
}

/// `1 + g^2 - 2 g mu`, written as `(1 - g)^2 + 2 g (1 - mu)` for `g >= 0` and as
/// `(1 + g)^2 - 2 g (1 + mu)` for `g < 0`: both sums of non-negative terms, so the value stays
/// accurate at the peak of a strongly anisotropic lobe (`phase.wgsl` uses the same form in `f32`).
fn hg_denominator(g: f64, mu: f64) -> f64 {
    if g >= 0.0 {
        (1.0 - g) * (1.0 - g) + 2.0 * g * (1.0 - mu)
    } else {
        (1.0 + g) * (1.0 + g) - 2.0 * g * (1.0 + mu)
    }
}

fn draine_f64(g: f64, alpha: f64, mu: f64) -> f64 {
    hg_f64(g, mu) * (1.0 + alpha * mu * mu) / (1.0 + alpha * (1.0 + 2.0 * g * g) / 3.0)
}

// Sampling works in the variable `s`, defined by `sqrt(1 + g^2 - 2 g mu) = 1 + g s`: `s` runs from
// 1 (mu = -1) to -1 (mu = 1) and `mu = -s + g (1 - s^2) / 2`. In `s` the CDFs of HG and Draine
// are rational with no `1/g` factors, so they stay well conditioned for every `g` in (-1, 1).

/// Inverse CDF of HG in the variable `s`: `s = (1 - g - 2u) / (1 - g + 2 g u)` (the classic HG
/// inversion, Henyey & Greenstein 1941, rewritten in `s`).
fn sample_hg_s(g: f64, u: f64) -> f64 {
    (1.0 - g - 2.0 * u) / (1.0 - g + 2.0 * g * u)
}

/// Iterations that bound the safeguarded Newton solve; it converges in 3-8 in practice.
const DRAINE_MAX_ITERATIONS: usize = 64;
/// Convergence tolerance in `s`, far below `f32` resolution.
const DRAINE_TOLERANCE_S: f64 = 1e-13;

/// Exact inverse CDF of Draine's phase function in the variable `s`.
///
/// Integrating the Draine density (Jendersie & d'Eon 2023, whose closed-form CDF this is) over
/// `s` gives `F(s) = u` as the quartic `P(s) = (1 - g)(1 - s) Q(s) - 24 N u (1 + g s) = 0` with
/// `Q(s) = a g (1 + g) s^3 + a (1 + g)(4 + g) s^2 + a (1 + g)(4 - 5 g) s + a (3 g^2 - 5 g + 4) + 12`
/// and `N = 1 + a (1 + 2 g^2) / 3`. Its one root in [-1, 1] is found by Newton's method kept
/// inside a bisection bracket: unlike Jendersie & d'Eon's closed-form quartic root it stays well
/// conditioned as `g -> 0` or `alpha -> 0` (where the quartic degenerates to a cubic or to HG).
fn sample_draine_s(g: f64, alpha: f64, u: f64) -> f64 {
    let quartic = DraineQuartic::new(g, alpha, u);
    // P(-1) = 24 N (1 - g)(1 - u) >= 0 and P(1) = -24 N u (1 + g) <= 0.
    let (mut lo, mut hi) = (-1.0_f64, 1.0_f64);
    let mut s = sample_hg_s(g, u);
    for _ in 0..DRAINE_MAX_ITERATIONS {
        let (p, dp) = quartic.value_and_slope(s);
        if p > 0.0 {
            lo = s;
        } else {
            hi = s;
        }
        let newton = s - p / dp;
        let next = if newton > lo && newton < hi {
            newton
        } else {
            0.5 * (lo + hi)
        };
        let converged = (next - s).abs() < DRAINE_TOLERANCE_S;
        s = next;
        if converged || hi - lo < DRAINE_TOLERANCE_S {
            break;
        }
    }
    s
}

/// The quartic `P(s)` of [`sample_draine_s`] for one `(g, alpha, u)`.
struct DraineQuartic {
    one_minus_g: f64,
    /// Coefficients of `Q(s)`, constant term first.
    q: [f64; 4],
    /// `24 N u`.
    rhs: f64,
    g: f64,
}

impl DraineQuartic {
    fn new(g: f64, a: f64, u: f64) -> Self {
        let n = 1.0 + a * (1.0 + 2.0 * g * g) / 3.0;
        let q = [
            a * (3.0 * g * g - 5.0 * g + 4.0) + 12.0,
            a * (1.0 + g) * (4.0 - 5.0 * g),
            a * (1.0 + g) * (4.0 + g),
            a * g * (1.0 + g),
        ];
        DraineQuartic {
            one_minus_g: 1.0 - g,
            q,
            rhs: 24.0 * n * u,
            g,
        }
    }

    /// `(P(s), dP/ds)`.
    fn value_and_slope(&self, s: f64) -> (f64, f64) {
        let [q0, q1, q2, q3] = self.q;
        let q = ((q3 * s + q2) * s + q1) * s + q0;
        let dq = (3.0 * q3 * s + 2.0 * q2) * s + q1;
        let p = self.one_minus_g * (1.0 - s) * q - self.rhs * (1.0 + self.g * s);
        let dp = self.one_minus_g * ((1.0 - s) * dq - q) - self.rhs * self.g;
        (p, dp)
    }
}

/// `(cos theta, sin theta)` from `s`, without cancellation near `mu = +-1`:
/// `1 - mu = (1 + s)(1 - g (1 - s) / 2)` and `1 + mu = (1 - s)(1 + g (1 + s) / 2)`.
fn cos_sin_from_s(g: f64, s: f64) -> (f64, f64) {
    let s = s.clamp(-1.0, 1.0);
    let one_minus_mu = (1.0 + s) * (1.0 - 0.5 * g * (1.0 - s));
    let one_plus_mu = (1.0 - s) * (1.0 + 0.5 * g * (1.0 + s));
    let cos_theta = 0.5 * (one_plus_mu - one_minus_mu);
    (cos_theta, (one_minus_mu * one_plus_mu).max(0.0).sqrt())
}

/// The unit vector at angle `theta` from `axis` (unit) and azimuth `phi_rad` about it.
fn rotate_about(axis: Vec3, cos_theta: f32, sin_theta: f32, phi_rad: f32) -> Vec3 {
    let (tangent, bitangent) = axis.any_orthonormal_pair();
    let (sin_phi, cos_phi) = phi_rad.sin_cos();
    (tangent * cos_phi + bitangent * sin_phi) * sin_theta + axis * cos_theta
}

/// The phase functions on the GPU (`phase.wgsl`), twins of this module's.
pub static PHASE_WGSL: crate::shader::WgslModule =
    crate::shader::wgsl_module!("phase", "phase.wgsl", [&crate::shader::MATH_WGSL]);

#[cfg(test)]
#[path = "phase_tests.rs"]
mod tests;
