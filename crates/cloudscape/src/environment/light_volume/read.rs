//! A frame's light volume solved on the CPU and read as the march reads it: the specification of
//! the GPU passes and of `environment_light_volume_diffuse`.

use super::inputs::{VolumeLight, diffusion};
use super::solve::{DiffuseField, Diffusion};
use super::{DiffuseOptics, LightVolumeGrid, LightVolumeSettings};
use crate::field::CloudField;
use glam::{UVec3, Vec3};

/// Least weight of a cell in the table's interpolation: clear air among clear air still
/// interpolates.
pub const MIN_INTERPOLATION_WEIGHT: f32 = 0.02;

/// A cell's weight when the table is interpolated: its scaled optical thickness across its
/// smallest side, within [`MIN_INTERPOLATION_WEIGHT`]..1, so that a point in the edge of a cloud
/// reads the cloud's cells rather than the clear air beside them, whose radiance mixes the light
/// leaving the cloud with the sky's (`light_volume_weight`; the GPU filters the weighted values and
/// their weights and divides).
pub fn interpolation_weight(extinction_per_m: f32, cell_m: Vec3) -> f32 {
    (extinction_per_m * cell_m.min_element()).clamp(MIN_INTERPOLATION_WEIGHT, 1.0)
}

/// Every cascade's problem and its solution.
pub struct LightVolume {
    /// The cascades' problems, finest first.
    pub cascades: Vec<(Diffusion, DiffuseField)>,
    /// Whether there are clouds (the volume reads zero when not).
    pub enabled: bool,
}

impl LightVolume {
    /// Solves every cascade of `grid` from a cold start with `settings.sweeps` sweeps, as a
    /// frame's first solve does on the GPU.
    pub fn solve(
        grid: &LightVolumeGrid,
        settings: &LightVolumeSettings,
        (field, optics): (&CloudField, DiffuseOptics),
        light: &VolumeLight,
    ) -> LightVolume {
        let cascades = (0..grid.cascades.len())
            .map(|k| {
                let problem = diffusion((grid, k), settings, (field, optics), light);
                let mut solution = problem.cold_field();
                problem.solve(&mut solution, settings.sweeps.max(1), true);
                (problem, solution)
            })
            .collect();
        LightVolume {
            cascades,
            enabled: grid.enabled,
        }
    }

    /// The diffuse light at `p` scattered toward the eye along `toward_eye` (unit), per unit
    /// scattering coefficient: `I0 (1 + 3 g J / I0 . w)` interpolated trilinearly in the cascades
    /// holding `p` (`environment_light_volume_diffuse`).
    pub fn diffuse(&self, p: Vec3, toward_eye: Vec3) -> Vec3 {
        let Some((radiance, current, g)) = self.sample(p) else {
            return Vec3::ZERO;
        };
        radiance * (1.0 + 3.0 * g * current.dot(toward_eye)).max(0.0)
    }

    /// The diffuse irradiance on level ground at `g` from the sky and the clouds above it: what
    /// leaves the grid's bottom face there ([`Diffusion::bottom_irradiance`], bilinear between the
    /// columns' centres) (`environment_light_volume_ground_irradiance`). Under a clear sky it is
    /// the sky's irradiance less what the clear column holds back; under a deck, what the deck
    /// passes on and sends back of the ground's own light; never negative (the diffusion
    /// solution's flux can be, where the P1 approximation fails). None without a volume.
    pub fn ground_irradiance(&self, g: Vec3) -> Option<Vec3> {
        self.enabled.then(|| {
            self.blend_cascades(g, |(problem, solution)| {
                let (base, f) = interpolation_base(problem, g);
                let mut sum = Vec3::ZERO;
                for corner in 0..4u32 {
                    let step = UVec3::new(corner & 1, 0, corner >> 1);
                    let c = (base + step).min(problem.cells - 1).with_y(0);
                    let w = corner_weight(step, f.with_y(0.0));
                    sum += w * problem.bottom_irradiance(solution, c);
                }
                [sum, Vec3::ZERO]
            })[0]
                .max(Vec3::ZERO)
        })
    }

    /// `I0`, the current over it and the droplets' mean cosine at `p` (clamped into each cascade,
    /// so that points below the grid read its bottom cells; the cascades blended by
    /// [`LightVolume::blend_cascades`]), each cell weighted by its optical thickness; None without
    /// a volume.
    fn sample(&self, p: Vec3) -> Option<(Vec3, Vec3, f32)> {
        if !self.enabled {
            return None;
        }
        let [radiance, current] = self.blend_cascades(p, |cascade| Self::sample_in(cascade, p));
        let g = self.cascades[0].0.optics.mean_cosine;
        Some((radiance, current, g))
    }

    /// `I0` and the current over it at `p` in one cascade.
    fn sample_in((problem, solution): &(Diffusion, DiffuseField), p: Vec3) -> [Vec3; 2] {
        let (base, f) = interpolation_base(problem, p);
        let (mut radiance, mut current, mut weights) = (Vec3::ZERO, Vec3::ZERO, 0.0);
        for corner in 0..8u32 {
            let step = UVec3::new(corner & 1, (corner >> 1) & 1, (corner >> 2) & 1);
            let c = (base + step).min(problem.cells - 1);
            let i = problem.index(c);
            let w = corner_weight(step, f)
                * interpolation_weight(problem.inputs[i][3], problem.cascade.cell_m);
            radiance += w * solution.radiance[i];
            current += w * problem.relative_current(solution, c);
            weights += w;
        }
        [radiance / weights, current / weights]
    }

    /// `read`'s values at `p` from the cascades, finest first: each cascade's weighted by
    /// [`cascade_weight`] of what the finer ones left, the coarsest taking the rest, so that the
    /// light passes from a cascade to the next over [`CASCADE_BLEND_CELLS`] rather than at a seam
    /// (`environment_light_volume_blend`).
    fn blend_cascades(
        &self,
        p: Vec3,
        read: impl Fn(&(Diffusion, DiffuseField)) -> [Vec3; 2],
    ) -> [Vec3; 2] {
        let (mut sum, mut left) = ([Vec3::ZERO; 2], 1.0);
        for (k, cascade) in self.cascades.iter().enumerate() {
            let last = k + 1 == self.cascades.len();
            let w = if last {
                1.0
            } else {
                cascade_weight(&cascade.0, p)
            };
            if w > 0.0 {
                let values = read(cascade);
                for (s, v) in sum.iter_mut().zip(values) {
                    *s += left * w * v;
                }
                left *= 1.0 - w;
            }
            if left <= 0.0 {
                break;
            }
        }
        sum
    }
}

/// Cells of a cascade, inward from its sides, over which the next coarser one hands over to it.
pub const CASCADE_BLEND_CELLS: f32 = 4.0;

/// How much a cascade's own value counts at `p`: 1 from [`CASCADE_BLEND_CELLS`] inside its sides
/// (measured from its outermost cells' centres) inward, falling linearly to 0 at them.
fn cascade_weight(problem: &Diffusion, p: Vec3) -> f32 {
    let n = problem.cells.as_vec3();
    let local = (p - problem.cascade.min_m) / problem.cascade.cell_m;
    let inside = (local.x - 0.5)
        .min(local.z - 0.5)
        .min(n.x - 0.5 - local.x)
        .min(n.z - 0.5 - local.z);
    (inside / CASCADE_BLEND_CELLS).clamp(0.0, 1.0)
}

/// The cell below and behind `p` in `problem`'s grid (`p` clamped to the cells' centres) and the
/// fractions of the way to the next cell along each axis.
fn interpolation_base(problem: &Diffusion, p: Vec3) -> (UVec3, Vec3) {
    let n = problem.cells.as_vec3();
    let local = ((p - problem.cascade.min_m) / problem.cascade.cell_m)
        .clamp(Vec3::splat(0.5), n - 0.5)
        - 0.5;
    let base = local.floor().as_uvec3().min(problem.cells - 1);
    (base, local - base.as_vec3())
}

/// The trilinear weight of the corner `step` (0 or 1 per axis) at fractions `f`.
fn corner_weight(step: UVec3, f: Vec3) -> f32 {
    Vec3::select(step.cmpeq(UVec3::ONE), f, Vec3::ONE - f).element_product()
}
