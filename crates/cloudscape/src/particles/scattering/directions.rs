//! Directions of the radiance inside the particle, in the meridian frame of each point (`z` along
//! the light, `x` away from the light's axis through the point, `y` completing it): zenith cells
//! over [0, pi], finer toward the light's direction, where droplets' forward peak keeps multiply
//! scattered light (`theta = pi u^ZENITH_POWER` for `u` uniform), and azimuth cells uniform over
//! [0, pi]. The field is mirror-symmetric about each
//! point's meridian plane, so azimuths in (pi, 2 pi) are the mirror images of the stored ones.
//!
//! Light is scattered between cells by [`PhaseMatrix`]: the phase function integrated over each
//! cell, with the cell a direction lies in taking whatever the others leave, so every row sums to
//! exactly 1 and no energy is gained or lost however peaked the phase function is.

use glam::Vec3;
use rayon::prelude::*;
use std::f32::consts::PI;

use crate::optics::PhaseLobes;

/// The grid of stored directions.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DirectionGrid {
    /// Zenith cells over [0, pi].
    pub zeniths: u32,
    /// Azimuth cells over [0, pi].
    pub azimuths: u32,
}

impl DirectionGrid {
    /// Stored directions.
    pub fn len(&self) -> usize {
        (self.zeniths * self.azimuths) as usize
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The zenith at `u` in [0, 1] across the zenith cells (cell `i` spans `u` in
    /// `[i, i + 1] / zeniths`).
    pub fn zenith_at(u: f32) -> f32 {
        PI * u.powf(ZENITH_POWER)
    }

    /// The inverse of [`Self::zenith_at`].
    pub fn zenith_coordinate(theta: f32) -> f32 {
        (theta / PI).clamp(0.0, 1.0).powf(1.0 / ZENITH_POWER)
    }

    /// Lower and upper zenith of cell row `iz`.
    pub fn zenith_edges(&self, iz: u32) -> (f32, f32) {
        let n = self.zeniths as f32;
        (
            Self::zenith_at(iz as f32 / n),
            Self::zenith_at((iz + 1) as f32 / n),
        )
    }

    /// Azimuth width of a cell, radians.
    pub fn azimuth_step(&self) -> f32 {
        PI / self.azimuths as f32
    }

    /// Zenith and azimuth of the centre of stored direction `d` (zenith-major).
    pub fn angles(&self, d: usize) -> (f32, f32) {
        let (iz, ia) = (d as u32 / self.azimuths, d as u32 % self.azimuths);
        (
            Self::zenith_at((iz as f32 + 0.5) / self.zeniths as f32),
            (ia as f32 + 0.5) * self.azimuth_step(),
        )
    }

    /// The unit vector at zenith `theta` and azimuth `phi` of the meridian frame.
    pub fn vector(theta: f32, phi: f32) -> Vec3 {
        let (st, ct) = theta.sin_cos();
        let (sp, cp) = phi.sin_cos();
        Vec3::new(st * cp, st * sp, ct)
    }

    /// Solid angle of a cell in zenith row `iz`.
    pub fn solid_angle(&self, iz: u32) -> f32 {
        let (lo, hi) = self.zenith_edges(iz);
        self.azimuth_step() * (lo.cos() - hi.cos())
    }
}

/// `M[i][j]`: the fraction of light in stored direction cell `j` (with its mirror image)
/// scattered into the centre of stored cell `i`, per steradian of `i`, times the cell's solid
/// angle: `J_i = sum_j M[i][j] L_j` where `L_j` is the mean radiance in cell `j`.
pub struct PhaseMatrix {
    /// Row-major, `len x len`.
    pub values: Vec<f32>,
    /// Its grid.
    pub grid: DirectionGrid,
}

/// Exponent of the zenith cells' spacing: 1.5 makes the cell about the light's direction 1 degree
/// wide on 32 rows (the mean is 5.6), the one opposite it 8.4 degrees.
pub const ZENITH_POWER: f32 = 1.5;

/// Sub-samples per side of a cell when integrating the phase function over it, far from the
/// scattered direction and near it (within [`NEAR_CELLS`] cell widths).
const FAR_SUBSAMPLES: u32 = 6;
/// See [`FAR_SUBSAMPLES`].
const NEAR_SUBSAMPLES: u32 = 24;
/// Cells whose centre lies within this many mean zenith widths (`pi / zeniths`) of the scattered
/// direction are "near".
const NEAR_CELLS: f32 = 2.5;

impl PhaseMatrix {
    /// Integrates `phase` over every full-sphere cell for every stored direction and folds the
    /// mirror images together.
    pub fn new(grid: DirectionGrid, phase: &PhaseLobes) -> PhaseMatrix {
        let n = grid.len();
        let values = (0..n)
            .into_par_iter()
            .flat_map_iter(|i| row(grid, phase, i))
            .collect();
        PhaseMatrix { values, grid }
    }

    /// `J = M L` for one point's radiance `l` (stored directions), into `j`.
    pub fn apply(&self, l: &[f32], j: &mut [f32]) {
        let n = self.grid.len();
        for (i, out) in j.iter_mut().enumerate() {
            let row = &self.values[i * n..(i + 1) * n];
            *out = row.iter().zip(l).map(|(m, v)| m * v).sum();
        }
    }
}

/// Row `i` of the folded matrix.
fn row(grid: DirectionGrid, phase: &PhaseLobes, i: usize) -> Vec<f32> {
    let (theta_i, phi_i) = grid.angles(i);
    let omega = DirectionGrid::vector(theta_i, phi_i);
    let full_azimuths = 2 * grid.azimuths;
    let own_zenith = i as u32 / grid.azimuths;
    let own_azimuth = i as u32 % grid.azimuths;
    let mut folded = vec![0.0f64; grid.len()];
    let mut total = 0.0f64;
    for iz in 0..grid.zeniths {
        for k in 0..full_azimuths {
            if iz == own_zenith && k == own_azimuth {
                continue;
            }
            let value = cell_integral(grid, phase, omega, iz, k);
            let stored = if k < grid.azimuths {
                k
            } else {
                full_azimuths - 1 - k
            };
            folded[(iz * grid.azimuths + stored) as usize] += value;
            total += value;
        }
    }
    // The cell holding the scattered direction keeps the rest, forward peak included.
    folded[i] += (1.0 - total).max(0.0);
    folded.into_iter().map(|v| v as f32).collect()
}

/// Integral of `phase(omega . w)` over full-sphere cell (zenith `iz`, azimuth `k` over
/// [0, 2 pi)).
fn cell_integral(grid: DirectionGrid, phase: &PhaseLobes, omega: Vec3, iz: u32, k: u32) -> f64 {
    let dp = grid.azimuth_step();
    let (lo, hi) = grid.zenith_edges(iz);
    let dt = hi - lo;
    let centre = DirectionGrid::vector(0.5 * (lo + hi), (k as f32 + 0.5) * dp);
    let near = omega.dot(centre).clamp(-1.0, 1.0).acos() < NEAR_CELLS * PI / grid.zeniths as f32;
    let s = if near {
        NEAR_SUBSAMPLES
    } else {
        FAR_SUBSAMPLES
    };
    let mut sum = 0.0f64;
    for a in 0..s {
        let theta = lo + (a as f32 + 0.5) / s as f32 * dt;
        let weight = f64::from(theta.sin() * dt * dp) / f64::from(s * s);
        for b in 0..s {
            let phi = (k as f32 + (b as f32 + 0.5) / s as f32) * dp;
            let w = DirectionGrid::vector(theta, phi);
            sum += f64::from(phase.eval(omega.dot(w))) * weight;
        }
    }
    sum
}

/// The phase function averaged over each zenith band of the grid about the light's direction:
/// the mean single-scattered radiance of the band per unit of the rest, integrated in 4096 steps
/// of `cos(theta)` per band, finer than the forward peak of cloud droplets.
pub fn band_mean_phase(grid: DirectionGrid, phase: &PhaseLobes) -> Vec<f32> {
    const STEPS: u32 = 4096;
    (0..grid.zeniths)
        .map(|iz| {
            let (lo, hi) = grid.zenith_edges(iz);
            let mut sum = 0.0f64;
            for s in 0..STEPS {
                let theta = lo + (s as f32 + 0.5) / STEPS as f32 * (hi - lo);
                sum += f64::from(phase.eval(theta.cos()) * theta.sin()) * f64::from(hi - lo)
                    / f64::from(STEPS);
            }
            (sum / f64::from(lo.cos() - hi.cos())) as f32
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    const GRID: DirectionGrid = DirectionGrid {
        zeniths: 16,
        azimuths: 8,
    };

    #[test]
    fn cells_tile_the_sphere() {
        let total: f32 = (0..GRID.zeniths)
            .map(|iz| GRID.solid_angle(iz))
            .sum::<f32>()
            * 2.0
            * GRID.azimuths as f32;
        assert!((total - 4.0 * PI).abs() < 1e-4, "{total}");
    }

    #[test]
    fn every_row_conserves_energy_and_isotropic_scattering_spreads_by_solid_angle() {
        let m = PhaseMatrix::new(GRID, &PhaseLobes::approximate_mie(20.0));
        let n = GRID.len();
        for i in 0..n {
            let sum: f32 = m.values[i * n..(i + 1) * n].iter().sum();
            assert!((sum - 1.0).abs() < 1e-4, "row {i} sums to {sum}");
        }
        let iso = PhaseMatrix::new(GRID, &PhaseLobes::henyey_greenstein(0.0));
        for j in 0..n {
            let expected = 2.0 * GRID.solid_angle(j as u32 / GRID.azimuths) / (4.0 * PI);
            assert!((iso.values[j] - expected).abs() < 2e-4, "{j}");
        }
    }

    #[test]
    fn the_band_means_integrate_the_phase_function_to_one() {
        let phase = PhaseLobes::approximate_mie(20.0);
        let bands = band_mean_phase(GRID, &phase);
        let total: f32 = bands
            .iter()
            .enumerate()
            .map(|(iz, p)| p * GRID.solid_angle(iz as u32) * 2.0 * GRID.azimuths as f32)
            .sum();
        assert!((total - 1.0).abs() < 2e-3, "{total}");
        assert!(
            bands[0] > 10.0 * bands[1],
            "the forward peak is in the first band"
        );
    }
}
