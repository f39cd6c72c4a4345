//! The spherically symmetric particle whose scattering is tabulated, in particle space (unit
//! radius, extinction per particle radius), lit by a directional light travelling along `+z`.

use glam::{Vec2, Vec3};

use crate::optics::PhaseLobes;
use crate::particles::density::RadialProfile;

/// The tabulated particle: its radial density profile, optical radius, albedo and phase function.
#[derive(Clone, Debug, PartialEq)]
pub struct SymmetricParticle {
    /// Density by radius, 0..1.
    pub profile: RadialProfile,
    /// Peak extinction times the radius, `sigma_max R` (dimensionless).
    pub optical_radius: f32,
    /// Single-scattering albedo.
    pub albedo: f32,
    /// Phase function.
    pub phase: PhaseLobes,
}

impl SymmetricParticle {
    /// Extinction per particle radius at `p` (particle space).
    pub fn extinction(&self, p: Vec3) -> f32 {
        self.optical_radius * self.profile.at(p.length())
    }
}

/// Optical depth from the light (at `z = -infinity`) to every point, tabulated over cylinder
/// coordinates `rho = |p.xy|` in [0, 1] and `z` in [-1, 1] and read back bilinearly.
pub struct SunDepth {
    values: Vec<f32>,
}

/// Nodes of [`SunDepth`] across `rho` (endpoints included).
const SUN_RHO_NODES: usize = 129;
/// Nodes of [`SunDepth`] across `z` (endpoints included).
const SUN_Z_NODES: usize = 257;
/// Integration sub-steps per `z` cell of [`SunDepth`] (midpoint rule).
const SUN_SUBSTEPS: usize = 8;

impl SunDepth {
    /// Integrates the particle's extinction along every line parallel to `z`.
    pub fn new(particle: &SymmetricParticle) -> SunDepth {
        let dz = 2.0 / (SUN_Z_NODES - 1) as f32;
        let mut values = vec![0.0; SUN_RHO_NODES * SUN_Z_NODES];
        for i in 0..SUN_RHO_NODES {
            let rho = i as f32 / (SUN_RHO_NODES - 1) as f32;
            let mut tau = 0.0;
            for j in 1..SUN_Z_NODES {
                let z0 = -1.0 + (j - 1) as f32 * dz;
                for k in 0..SUN_SUBSTEPS {
                    let z = z0 + (k as f32 + 0.5) * dz / SUN_SUBSTEPS as f32;
                    tau += particle.extinction(Vec3::new(rho, 0.0, z)) * dz / SUN_SUBSTEPS as f32;
                }
                values[i * SUN_Z_NODES + j] = tau;
            }
        }
        SunDepth { values }
    }

    /// Optical depth toward the light from `p`.
    pub fn at(&self, p: Vec3) -> f32 {
        let rho = Vec2::new(p.x, p.y).length();
        if rho >= 1.0 {
            return 0.0;
        }
        let x = rho * (SUN_RHO_NODES - 1) as f32;
        let y = ((p.z + 1.0) * 0.5).clamp(0.0, 1.0) * (SUN_Z_NODES - 1) as f32;
        let (i, j) = (
            (x as usize).min(SUN_RHO_NODES - 2),
            (y as usize).min(SUN_Z_NODES - 2),
        );
        let (fx, fy) = (x - i as f32, y - j as f32);
        let v = |a: usize, b: usize| self.values[a * SUN_Z_NODES + b];
        let lo = v(i, j) + (v(i + 1, j) - v(i, j)) * fx;
        let hi = v(i, j + 1) + (v(i + 1, j + 1) - v(i, j + 1)) * fx;
        lo + (hi - lo) * fy
    }
}

/// The exit distance of the ray from `p` (inside the unit ball) along `-dir`: how far back along
/// `dir` light can have come from within the particle.
pub fn distance_back_to_surface(p: Vec3, dir: Vec3) -> f32 {
    let b = p.dot(dir);
    let c = p.length_squared() - 1.0;
    (b + (b * b - c).max(0.0).sqrt()).max(0.0)
}
