//! Test helpers: a deterministic RNG, the chi-square goodness-of-fit test, WGSL validation.

/// PCG32 (O'Neill 2014, "PCG: A Family of Simple Fast Space-Efficient Statistically Good
/// Algorithms for Random Number Generation"), XSH-RR output on a 64-bit LCG.
pub struct Pcg32 {
    state: u64,
    increment: u64,
}

impl Pcg32 {
    const MULTIPLIER: u64 = 6364136223846793005;

    /// A generator for `seed` on stream `stream` (the reference seeding procedure).
    pub fn new(seed: u64, stream: u64) -> Self {
        let mut rng = Pcg32 {
            state: 0,
            increment: (stream << 1) | 1,
        };
        rng.next_u32();
        rng.state = rng.state.wrapping_add(seed);
        rng.next_u32();
        rng
    }

    /// The next 32 uniformly distributed bits.
    pub fn next_u32(&mut self) -> u32 {
        let old = self.state;
        self.state = old
            .wrapping_mul(Self::MULTIPLIER)
            .wrapping_add(self.increment);
        let xorshifted = (((old >> 18) ^ old) >> 27) as u32;
        xorshifted.rotate_right((old >> 59) as u32)
    }

    /// A uniform number in [0, 1) with 24 random bits.
    pub fn next_f32(&mut self) -> f32 {
        (self.next_u32() >> 8) as f32 * (1.0 / 16_777_216.0)
    }
}

/// Expected count below which bins are pooled, the usual rule for the chi-square approximation.
const MIN_EXPECTED_COUNT: f64 = 5.0;

/// p-value of Pearson's chi-square test of `observed` counts against `expected` counts.
///
/// Bins are visited by increasing expectation and pooled until each pool expects at least
/// [`MIN_EXPECTED_COUNT`] (as in Mitsuba's chi-square test of samplers); a leftover pool is
/// counted as it is. Degrees of freedom: pooled bins minus one.
pub fn chi_square_p_value(observed: &[u64], expected: &[f64]) -> f64 {
    assert_eq!(observed.len(), expected.len());
    let mut order: Vec<usize> = (0..expected.len()).collect();
    order.sort_by(|&a, &b| expected[a].total_cmp(&expected[b]));
    let (mut chi2, mut bins) = (0.0, 0usize);
    let (mut pool_observed, mut pool_expected) = (0.0, 0.0);
    for (n, &i) in order.iter().enumerate() {
        pool_observed += observed[i] as f64;
        pool_expected += expected[i];
        if pool_expected >= MIN_EXPECTED_COUNT || n + 1 == order.len() {
            let diff = pool_observed - pool_expected;
            chi2 += diff * diff / pool_expected;
            bins += 1;
            (pool_observed, pool_expected) = (0.0, 0.0);
        }
    }
    let dof = bins.saturating_sub(1).max(1);
    upper_regularized_gamma(dof as f64 / 2.0, chi2 / 2.0)
}

/// `ln Gamma(a)` for `a` a positive multiple of 1/2 (all a chi-square test needs), exactly by
/// the recurrence `Gamma(a + 1) = a Gamma(a)` from `Gamma(1) = 1` or `Gamma(1/2) = sqrt(pi)`.
fn ln_gamma_half_integer(a: f64) -> f64 {
    assert!(
        a > 0.0 && (2.0 * a).fract() == 0.0,
        "a must be a positive multiple of 1/2"
    );
    let mut x = if a.fract() == 0.0 { 1.0 } else { 0.5 };
    let mut ln = if x == 1.0 {
        0.0
    } else {
        0.5 * std::f64::consts::PI.ln()
    };
    while x < a {
        ln += x.ln();
        x += 1.0;
    }
    ln
}

/// Iteration cap and tolerance of the incomplete-gamma series and continued fraction.
const GAMMA_MAX_TERMS: usize = 10_000;
const GAMMA_EPS: f64 = 1e-15;

/// Upper regularized incomplete gamma `Q(a, x) = Gamma(a, x) / Gamma(a)`: the series of
/// `P = 1 - Q` for `x < a + 1`, else the continued fraction of `Q` by the modified Lentz method
/// (Press et al. 2007, "Numerical Recipes", 3rd ed., section 6.2).
fn upper_regularized_gamma(a: f64, x: f64) -> f64 {
    if x <= 0.0 {
        return 1.0;
    }
    let ln_prefactor = a * x.ln() - x - ln_gamma_half_integer(a);
    if x < a + 1.0 {
        let (mut term, mut sum, mut ap) = (1.0 / a, 1.0 / a, a);
        for _ in 0..GAMMA_MAX_TERMS {
            ap += 1.0;
            term *= x / ap;
            sum += term;
            if term.abs() < sum.abs() * GAMMA_EPS {
                break;
            }
        }
        1.0 - sum * ln_prefactor.exp()
    } else {
        let tiny = 1e-300;
        let mut b = x + 1.0 - a;
        let (mut c, mut d) = (1.0 / tiny, 1.0 / b);
        let mut h = d;
        for i in 1..GAMMA_MAX_TERMS {
            let an = -(i as f64) * (i as f64 - a);
            b += 2.0;
            d = an * d + b;
            d = if d.abs() < tiny { 1.0 / tiny } else { 1.0 / d };
            c = b + an / c;
            if c.abs() < tiny {
                c = tiny;
            }
            let delta = d * c;
            h *= delta;
            if (delta - 1.0).abs() < GAMMA_EPS {
                break;
            }
        }
        ln_prefactor.exp() * h
    }
}

mod tests {
    use super::*;

    #[test]
    fn chi_square_survival_matches_known_values() {
        // chi2 = 3.841 at 1 dof and 18.307 at 10 dof are the 5% critical values; chi2 = dof
        // at 2 dof has p = exp(-1).
        let cases = [
            (1.0, 3.841459, 0.05),
            (10.0, 18.307038, 0.05),
            (2.0, 2.0, (-1.0f64).exp()),
        ];
        for (dof, chi2, p) in cases {
            let q = upper_regularized_gamma(dof / 2.0, chi2 / 2.0);
            assert!((q - p).abs() < 1e-6, "dof {dof}: {q} vs {p}");
        }
        // A large-dof case through the continued fraction: median of chi2(500) is about 499.33.
        assert!((upper_regularized_gamma(250.0, 499.3337 / 2.0) - 0.5).abs() < 1e-3);
    }

    #[test]
    fn pcg32_matches_reference_sequence() {
        // First outputs of the PCG reference implementation (pcg32-demo) for seed 42, stream 54.
        let mut rng = Pcg32::new(42, 54);
        let expected = [
            0xa15c02b7, 0x7b47f409, 0xba1d3330, 0x83d2f293, 0xbfa4784b, 0xcbed606e,
        ];
        for value in expected {
            assert_eq!(rng.next_u32(), value);
        }
    }
}
