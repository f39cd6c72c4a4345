//! Multiple scattering inside the symmetric particle, order by order (Yusov 2014, "Pre-computing
//! scattering"): an intermediate 4D table over position (radius, angle from the light's axis) and
//! direction ([`DirectionGrid`]) holds each order's radiance `L_n`; `J_{n+1} = albedo M L_n`
//! gathers it through the [`PhaseMatrix`]; `L_{n+1}` integrates `J_{n+1}` along the ray back to
//! the surface. Orders stop when one adds less than [`ORDER_TOLERANCE`] of the scattered power so
//! far; the rest of the series is summed as a geometric tail with the last orders' ratio (the
//! series becomes geometric once the field's shape settles, its ratio the largest eigenvalue of
//! the transport; Bohren 1987 discusses the same limit for slabs).
//!
//! The light's axis makes the field axially symmetric, so each point is stored in its own
//! meridian frame and every direction's zenith is measured from the light: the gather is the same
//! matrix everywhere.

use glam::Vec3;
use rayon::prelude::*;
use std::f32::consts::PI;

use super::directions::{DirectionGrid, PhaseMatrix, band_mean_phase};
use super::medium::{SunDepth, SymmetricParticle, distance_back_to_surface};

/// An order adding less than this fraction of the scattered power so far ends the series (the
/// issue's 0.1 %).
pub const ORDER_TOLERANCE: f32 = 1e-3;
/// Most orders computed before the geometric tail takes over (Yusov's code computes 18).
pub const MAX_ORDERS: u32 = 64;

/// Resolution of the intermediate table.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct OrderGrid {
    /// Radius cells over [0, 1].
    pub radii: u32,
    /// Cells of the angle from the light's axis over [0, pi].
    pub polar: u32,
    /// Directions at each point.
    pub directions: DirectionGrid,
    /// Integration steps per particle radius along rays.
    pub steps_per_radius: u32,
}

impl OrderGrid {
    /// The default: 24 x 32 positions x 32 x 16 directions (Yusov's is 32 x 32 x 32 x 64).
    pub const DEFAULT: OrderGrid = OrderGrid {
        radii: 24,
        polar: 32,
        directions: DirectionGrid {
            zeniths: 32,
            azimuths: 16,
        },
        steps_per_radius: 24,
    };

    fn positions(&self) -> usize {
        (self.radii * self.polar) as usize
    }

    /// The point at the centre of position cell `k` (radius-major), in its meridian frame.
    fn point(&self, k: usize) -> Vec3 {
        let (ir, ip) = (k as u32 / self.polar, k as u32 % self.polar);
        let r = (ir as f32 + 0.5) / self.radii as f32;
        let theta = (ip as f32 + 0.5) / self.polar as f32 * PI;
        Vec3::new(r * theta.sin(), 0.0, r * theta.cos())
    }

    /// Volume of position cell `k` (a ring about the axis), in particle radii cubed.
    fn volume(&self, k: usize) -> f32 {
        let (ir, ip) = (k as u32 / self.polar, k as u32 % self.polar);
        let (r0, r1) = (
            ir as f32 / self.radii as f32,
            (ir + 1) as f32 / self.radii as f32,
        );
        let (t0, t1) = (
            ip as f32 / self.polar as f32 * PI,
            (ip + 1) as f32 / self.polar as f32 * PI,
        );
        2.0 * PI / 3.0 * (r1.powi(3) - r0.powi(3)) * (t0.cos() - t1.cos())
    }
}

/// A quantity over the intermediate table: `values[k * directions + d]`.
#[derive(Clone, Debug, PartialEq)]
pub struct OrderField {
    /// Its grid.
    pub grid: OrderGrid,
    /// Values, position-major.
    pub values: Vec<f32>,
}

impl OrderField {
    fn zeros(grid: OrderGrid) -> OrderField {
        OrderField {
            grid,
            values: vec![0.0; grid.positions() * grid.directions.len()],
        }
    }

    /// Multilinear value at point `q` (particle space) for the direction `omega` (unit, particle
    /// space with the light along `+z`).
    pub fn sample(&self, q: Vec3, omega: Vec3) -> f32 {
        let g = &self.grid;
        let rho = q.x.hypot(q.y);
        let r = q.length();
        let polar = rho.atan2(q.z);
        // The direction in q's meridian frame: the same zenith, the azimuth less q's own.
        let zenith = omega.z.clamp(-1.0, 1.0).acos();
        let relative = if rho > 1e-6 {
            omega.y.atan2(omega.x) - q.y.atan2(q.x)
        } else {
            omega.y.atan2(omega.x)
        };
        let azimuth = (relative + PI).rem_euclid(2.0 * PI) - PI;
        let coords = [
            cell_coordinate(r, 1.0, g.radii),
            cell_coordinate(polar, PI, g.polar),
            cell_coordinate(
                DirectionGrid::zenith_coordinate(zenith),
                1.0,
                g.directions.zeniths,
            ),
            cell_coordinate(azimuth.abs(), PI, g.directions.azimuths),
        ];
        let dims = [
            g.radii,
            g.polar,
            g.directions.zeniths,
            g.directions.azimuths,
        ];
        let mut sum = 0.0;
        for corner in 0..16u32 {
            let mut index = 0usize;
            let mut weight = 1.0;
            for axis in 0..4 {
                let (i0, f) = coords[axis];
                let high = (corner >> axis) & 1 == 1;
                let i = if high {
                    (i0 + 1).min(dims[axis] - 1)
                } else {
                    i0
                };
                weight *= if high { f } else { 1.0 - f };
                index = index * dims[axis] as usize + i as usize;
            }
            if weight > 0.0 {
                sum += weight * self.values[index];
            }
        }
        sum
    }

    /// Scattered power of the field taken as a source `J`: `sum sigma J dV dOmega` (mirror
    /// images included).
    fn power(&self, particle: &SymmetricParticle) -> f64 {
        let g = &self.grid;
        let n = g.directions.len();
        (0..g.positions())
            .map(|k| {
                let w = f64::from(particle.extinction(g.point(k)) * g.volume(k));
                let row = &self.values[k * n..(k + 1) * n];
                let s: f64 = row
                    .iter()
                    .enumerate()
                    .map(|(d, v)| {
                        f64::from(
                            *v * 2.0 * g.directions.solid_angle(d as u32 / g.directions.azimuths),
                        )
                    })
                    .sum();
                w * s
            })
            .sum()
    }
}

/// Cell index and fraction toward the next cell of `x` on `cells` cells over [0, range], clamped
/// to the first and last centres.
fn cell_coordinate(x: f32, range: f32, cells: u32) -> (u32, f32) {
    let t = (x / range * cells as f32 - 0.5).clamp(0.0, (cells - 1) as f32);
    let i = (t.floor() as u32).min(cells.saturating_sub(2));
    (i, (t - i as f32).min(1.0))
}

/// Integrates a source along the ray arriving at `p` travelling along `omega` from the particle's
/// surface: `sum T (1 - exp(-sigma ds)) source(q)` over midpoint steps (exact for piecewise
/// constant extinction and source).
pub fn integrate_back(
    particle: &SymmetricParticle,
    p: Vec3,
    omega: Vec3,
    steps_per_radius: u32,
    source: impl Fn(Vec3) -> f32,
) -> f32 {
    let length = distance_back_to_surface(p, omega);
    let steps = ((length * steps_per_radius as f32).ceil() as u32).max(1);
    let ds = length / steps as f32;
    let mut transmittance = 1.0;
    let mut sum = 0.0;
    for i in 0..steps {
        let q = p - omega * ((i as f32 + 0.5) * ds);
        let step = (-particle.extinction(q) * ds).exp();
        sum += transmittance * (1.0 - step) * source(q);
        transmittance *= step;
    }
    sum
}

/// What the order iteration produced.
pub struct MultipleScattering {
    /// `sum_{n >= 2} J_n` per unit irradiance of the light (albedo included), sr^-1.
    pub source: OrderField,
    /// Orders computed before the tail.
    pub orders: u32,
    /// Ratio of the last two orders' power, used for the tail.
    pub ratio: f32,
}

/// Runs the orders; `progress(order)` is called after each.
pub fn multiple_scattering(
    particle: &SymmetricParticle,
    grid: OrderGrid,
    sun: &SunDepth,
    progress: &mut dyn FnMut(u32),
) -> MultipleScattering {
    let matrix = PhaseMatrix::new(grid.directions, &particle.phase);
    let bands = band_mean_phase(grid.directions, &particle.phase);
    let steps = grid.steps_per_radius;
    // L_1: single scattering, with the phase function averaged over each cell.
    let mut radiance = transport(grid, |p, omega, d| {
        let band = d / grid.directions.azimuths as usize;
        particle.albedo
            * bands[band]
            * integrate_back(particle, p, omega, steps, |q| (-sun.at(q)).exp())
    });
    let mut sum = OrderField::zeros(grid);
    let mut previous_power = single_scattered_power(particle, grid, sun);
    let mut total_power = previous_power;
    let mut order = 1;
    let mut ratio;
    loop {
        order += 1;
        let source = gather(&matrix, &radiance, particle.albedo);
        let power = source.power(particle);
        ratio = if previous_power > 0.0 {
            (power / previous_power) as f32
        } else {
            0.0
        };
        previous_power = power;
        total_power += power;
        progress(order);
        let done = power < f64::from(ORDER_TOLERANCE) * total_power || order == MAX_ORDERS;
        // The orders after the last one computed, summed as a geometric series.
        let weight = if done && ratio < 1.0 {
            1.0 / (1.0 - ratio)
        } else {
            1.0
        };
        for (s, v) in sum.values.iter_mut().zip(&source.values) {
            *s += weight * v;
        }
        if done {
            break;
        }
        radiance = transport(grid, |p, omega, _| {
            integrate_back(particle, p, omega, steps, |q| source.sample(q, omega))
        });
    }
    MultipleScattering {
        source: sum,
        orders: order,
        ratio,
    }
}

/// Power scattered once: `albedo sum sigma exp(-tau_sun) dV` per unit irradiance.
fn single_scattered_power(particle: &SymmetricParticle, grid: OrderGrid, sun: &SunDepth) -> f64 {
    (0..grid.positions())
        .map(|k| {
            let p = grid.point(k);
            f64::from(
                particle.albedo * particle.extinction(p) * (-sun.at(p)).exp() * grid.volume(k),
            )
        })
        .sum()
}

/// `J = albedo M L` at every position.
fn gather(matrix: &PhaseMatrix, radiance: &OrderField, albedo: f32) -> OrderField {
    let n = matrix.grid.len();
    let mut out = OrderField::zeros(radiance.grid);
    out.values
        .par_chunks_mut(n)
        .zip(radiance.values.par_chunks(n))
        .for_each(|(j, l)| {
            matrix.apply(l, j);
            j.iter_mut().for_each(|v| *v *= albedo);
        });
    out
}

/// The field whose value at every stored point and direction is `f(point, direction, d)`.
fn transport(grid: OrderGrid, f: impl Fn(Vec3, Vec3, usize) -> f32 + Sync) -> OrderField {
    let n = grid.directions.len();
    let mut out = OrderField::zeros(grid);
    out.values
        .par_chunks_mut(n)
        .enumerate()
        .for_each(|(k, row)| {
            let p = grid.point(k);
            for (d, v) in row.iter_mut().enumerate() {
                let (theta, phi) = grid.directions.angles(d);
                *v = f(p, DirectionGrid::vector(theta, phi), d);
            }
        });
    out
}
