//! Diffuse reflectance and transmittance of a homogeneous plane-parallel slab by the
//! adding-doubling method (van de Hulst 1980, "Multiple Light Scattering", vol. 1, ch. 4; Prahl
//! 1995, "The Adding-Doubling Method", in Optical-Thermal Response of Laser-Irradiated Tissue):
//! written here independently of the path tracer, to check it.
//!
//! Radiance is discretised at Gauss-Legendre cosines `mu_i` in (0, 1) with weights `w_i`. A layer
//! acts on azimuth-independent incident radiance by a reflection matrix `R` and a transmission
//! matrix `T`. A thin layer of optical depth `d` scatters once: `R_ij = a d / mu_i P(mu_i, -mu_j)
//! w_j` and `T_ij = delta_ij exp(-d / mu_i) + a d / mu_i P(mu_i, mu_j) w_j`, with `P` the phase
//! function integrated over azimuth. Doubling joins two equal layers:
//! `R' = R + T (I - R R)^-1 R T`, `T' = T (I - R R)^-1 T`.

use std::f64::consts::PI;

/// A dense square matrix, row-major.
#[derive(Clone, Debug)]
struct Matrix {
    n: usize,
    a: Vec<f64>,
}

impl Matrix {
    fn from_fn(n: usize, f: impl Fn(usize, usize) -> f64) -> Matrix {
        Matrix {
            n,
            a: (0..n * n).map(|k| f(k / n, k % n)).collect(),
        }
    }

    fn at(&self, i: usize, j: usize) -> f64 {
        self.a[i * self.n + j]
    }

    fn mul(&self, other: &Matrix) -> Matrix {
        Matrix::from_fn(self.n, |i, j| {
            (0..self.n).map(|k| self.at(i, k) * other.at(k, j)).sum()
        })
    }

    fn add(&self, other: &Matrix) -> Matrix {
        Matrix::from_fn(self.n, |i, j| self.at(i, j) + other.at(i, j))
    }

    /// `(I - self)^-1` by Gauss-Jordan elimination with partial pivoting.
    fn inverse_of_identity_minus(&self) -> Matrix {
        let n = self.n;
        let mut m = Matrix::from_fn(n, |i, j| f64::from(i == j) - self.at(i, j));
        let mut inv = Matrix::from_fn(n, |i, j| f64::from(i == j));
        for col in 0..n {
            let pivot = (col..n)
                .max_by(|&x, &y| m.at(x, col).abs().total_cmp(&m.at(y, col).abs()))
                .unwrap();
            for k in 0..n {
                m.a.swap(col * n + k, pivot * n + k);
                inv.a.swap(col * n + k, pivot * n + k);
            }
            let p = m.at(col, col);
            for k in 0..n {
                m.a[col * n + k] /= p;
                inv.a[col * n + k] /= p;
            }
            for row in (0..n).filter(|&r| r != col) {
                let factor = m.at(row, col);
                for k in 0..n {
                    m.a[row * n + k] -= factor * m.at(col, k);
                    inv.a[row * n + k] -= factor * inv.at(col, k);
                }
            }
        }
        inv
    }
}

/// Gauss-Legendre nodes and weights on (0, 1), by Newton's method on the Legendre polynomial
/// (Press et al., "Numerical Recipes", section 4.6).
fn gauss_legendre_unit(n: usize) -> Vec<(f64, f64)> {
    (0..n)
        .map(|i| {
            let mut x = (PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
            let mut derivative = 0.0;
            for _ in 0..100 {
                let (mut p0, mut p1) = (1.0, x);
                for k in 2..=n {
                    let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                    p0 = p1;
                    p1 = p2;
                }
                derivative = n as f64 * (x * p1 - p0) / (x * x - 1.0);
                let dx = p1 / derivative;
                x -= dx;
                if dx.abs() < 1e-15 {
                    break;
                }
            }
            let weight = 2.0 / ((1.0 - x * x) * derivative * derivative);
            (0.5 * (x + 1.0), 0.5 * weight)
        })
        .collect()
}

/// A homogeneous slab.
pub struct Slab {
    /// Optical depth.
    pub optical_depth: f64,
    /// Single-scattering albedo.
    pub albedo: f64,
    /// Henyey-Greenstein asymmetry.
    pub g: f64,
}

/// Henyey-Greenstein phase function per steradian (Henyey & Greenstein 1941).
fn hg(g: f64, cos_theta: f64) -> f64 {
    (1.0 - g * g) / (4.0 * PI * (1.0 + g * g - 2.0 * g * cos_theta).powf(1.5))
}

/// The phase function integrated over the azimuth difference (trapezoid rule, exact to rounding
/// for this smooth periodic integrand).
fn azimuthal_phase(g: f64, mu: f64, mu_prime: f64) -> f64 {
    let steps = 720;
    let s = ((1.0 - mu * mu) * (1.0 - mu_prime * mu_prime)).sqrt();
    (0..steps)
        .map(|k| {
            hg(
                g,
                mu * mu_prime + s * (2.0 * PI * k as f64 / steps as f64).cos(),
            )
        })
        .sum::<f64>()
        * 2.0
        * PI
        / steps as f64
}

/// Reflectance and transmittance `(R, T)` of the slab for radiance 1 from every direction of
/// the upper hemisphere: outgoing flux over the incident flux `pi`. `T` includes the light that
/// crosses unscattered. `n` is the number of quadrature cosines.
pub fn diffuse_reflectance_transmittance(slab: &Slab, n: usize) -> (f64, f64) {
    let nodes = gauss_legendre_unit(n);
    let doublings = (slab.optical_depth / 1e-6).log2().ceil().max(0.0) as i32;
    let d = slab.optical_depth / 2f64.powi(doublings);
    let scatter = |i: usize, j: usize, sign: f64| {
        let (mu_i, (mu_j, w_j)) = (nodes[i].0, nodes[j]);
        slab.albedo * d / mu_i * azimuthal_phase(slab.g, mu_i, sign * mu_j) * w_j
    };
    let mut r = Matrix::from_fn(n, |i, j| scatter(i, j, -1.0));
    let mut t = Matrix::from_fn(n, |i, j| {
        let direct = if i == j { (-d / nodes[i].0).exp() } else { 0.0 };
        direct + scatter(i, j, 1.0)
    });
    for _ in 0..doublings {
        let x = r.mul(&r).inverse_of_identity_minus();
        let t_x = t.mul(&x);
        r = r.add(&t_x.mul(&r).mul(&t));
        t = t_x.mul(&t);
    }
    let flux = |m: &Matrix| {
        (0..n)
            .map(|i| 2.0 * PI * nodes[i].1 * nodes[i].0 * (0..n).map(|j| m.at(i, j)).sum::<f64>())
            .sum::<f64>()
            / PI
    };
    (flux(&r), flux(&t))
}

#[test]
fn quadrature_integrates_polynomials_exactly() {
    let nodes = gauss_legendre_unit(8);
    let integral: f64 = nodes.iter().map(|(x, w)| w * x.powi(9)).sum();
    assert!((integral - 0.1).abs() < 1e-13, "{integral}");
}

#[test]
fn adding_doubling_conserves_energy_and_matches_the_direct_beam() {
    let conservative = Slab {
        optical_depth: 2.0,
        albedo: 1.0,
        g: 0.7,
    };
    let (r, t) = diffuse_reflectance_transmittance(&conservative, 24);
    assert!((r + t - 1.0).abs() < 2e-4, "{r} + {t}");
    // Without scattering only the direct beam crosses: T = 2 E3(tau), E3(1) = 0.1096920
    // (Abramowitz & Stegun 1964, table 5.1).
    let absorbing = Slab {
        optical_depth: 1.0,
        albedo: 0.0,
        g: 0.0,
    };
    let (r, t) = diffuse_reflectance_transmittance(&absorbing, 24);
    assert_eq!(r, 0.0);
    assert!((t - 2.0 * 0.1096920).abs() < 1e-6, "{t}");
    // Converged in the quadrature.
    let (r32, _) = diffuse_reflectance_transmittance(&conservative, 32);
    let (r16, _) = diffuse_reflectance_transmittance(&conservative, 16);
    assert!((r32 - r16).abs() < 1e-3, "{r16} vs {r32}");
}
