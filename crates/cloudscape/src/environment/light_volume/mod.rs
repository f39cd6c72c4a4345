//! The light volume: the diffuse (multiply scattered) light of the sun, the sky and the ground in
//! the clouds, solved in 3-D on grids that follow the camera, for every technique to read
//! (`lighting.model = "volume"`).
//!
//! The ray marcher's slab model ([`crate::optics::slab`]) knows the optical depths toward and away
//! from the sun on one line and nothing to the sides. The volume solves the same δ-Eddington
//! equations on a grid instead ([`solve`]): light diffuses sideways out of lit faces into shadowed
//! ones, escapes through a finite cloud's sides, enters from the sky through the gaps and comes
//! back up from the ground. Exact single scattering and the forward peak stay in the march, per
//! sample; only the diffuse field comes from here.
//!
//! **Cascades.** Cascade `c` is a box centred under the viewpoint, `extent_m 4^c` to each side,
//! spanning the clouds' heights, of `cells_horizontal^2 x cells_vertical` cells, snapped to whole
//! cells so that it stays put while the camera moves within one. A point reads the finest cascade
//! it lies in.
//!
//! **Per cell** ([`inputs`]): the δ-scaled extinction, the mean field (`CloudField::mean_extinction_per_m`) at eight points
//! of the cell, and the scaled sun beam's irradiance, the sun's irradiance there through the air
//! times `exp(-tau')` of the mean field toward the sun. **Solve**: line relaxation, warm-started
//! from the last frame's solution when the grid has not moved, and from that solution scrolled by
//! whole cells when it was recentred ([`LightVolumeGrid::shift_cells_from`]). **Read**: the march scatters
//! `I0 + g w . I1` toward the eye along `w` (`environment_light_volume_diffuse`): per cell the
//! volume stores `I0` (RGB) and the current `J = I1 / 3` over `I0` (of luminance).
//!
//! The GPU twin is `light_volume.wgsl` ([`LightVolumePass`]); the tests hold it to this module.

pub mod inputs;
mod pass;
mod read;
pub mod solve;
#[cfg(test)]
mod tests;

pub use pass::{
    CELL_SLICES, LIGHT_VOLUME_PASS_NAMES, LIGHT_VOLUME_WGSL, LightVolumePass, WARM_TURN_FRAMES,
};
pub use read::{CASCADE_BLEND_CELLS, LightVolume};
pub use solve::{Boundaries, DiffuseField, Diffusion};

use crate::field::CloudField;
use crate::optics::SunSlab;
use crate::scene::{PlanetShape, Scene};
use glam::{IVec2, UVec3, Vec3};

/// Most cascades a volume holds.
pub const MAX_CASCADES: u32 = 4;
/// Each cascade reaches this many times as far as the one inside it.
pub const CASCADE_SCALE: f32 = 4.0;
/// The table's parts along z, each the cascades' cells side by side: the radiance `I0`, the
/// current over it, and the ground's diffuse irradiance under each column (its bottom row).
pub const TABLE_PARTS: u32 = 3;

/// The droplets' optics after δ-scaling (Wiscombe 1977's δ-M, as [`SunSlab::scaled`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DiffuseOptics {
    /// Scaled single-scattering albedo `omega'`.
    pub albedo: f32,
    /// Scaled asymmetry `g'`.
    pub asymmetry: f32,
    /// `1 - omega f`: scaled over true extinction.
    pub thinning: f32,
    /// The true phase function's mean cosine `g`: how the diffuse field scatters toward the eye.
    pub mean_cosine: f32,
}

impl DiffuseOptics {
    /// The scaled optics of `slab`'s droplets.
    pub fn of(slab: &SunSlab) -> DiffuseOptics {
        let scaled = slab.scaled(1.0, 0.0);
        DiffuseOptics {
            albedo: scaled.albedo,
            asymmetry: scaled.asymmetry,
            thinning: scaled.depth,
            mean_cosine: slab.lobes.mean_cosine(),
        }
    }

    /// As the GPU holds them: `(albedo, asymmetry, thinning, mean cosine)`.
    pub fn to_gpu(&self) -> [f32; 4] {
        [self.albedo, self.asymmetry, self.thinning, self.mean_cosine]
    }
}

/// Size and cost of the volume (`[lighting]`'s `volume_*` keys).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightVolumeSettings {
    /// Cells along x and z.
    pub cells_horizontal: u32,
    /// Cells along y, through the clouds' heights.
    pub cells_vertical: u32,
    /// Half width of the finest cascade, metres.
    pub extent_m: f32,
    /// Cascades, 1..=[`MAX_CASCADES`].
    pub cascades: u32,
    /// Sweeps of a cold start (the grid new or moved).
    pub sweeps: u32,
    /// Sweeps a warm turn gives the one cascade it solves (the cascades take turns).
    pub warm_sweeps: u32,
    /// Samples of the mean field toward the sun per cell.
    pub beam_steps: u32,
}

impl LightVolumeSettings {
    /// The settings of a scene.
    pub fn from_scene(scene: &Scene) -> LightVolumeSettings {
        let l = &scene.lighting;
        LightVolumeSettings {
            cells_horizontal: l.volume_cells_horizontal,
            cells_vertical: l.volume_cells_vertical,
            extent_m: l.volume_extent_m,
            cascades: l.volume_cascades.clamp(1, MAX_CASCADES),
            sweeps: l.volume_sweeps,
            warm_sweeps: l.volume_warm_sweeps,
            beam_steps: l.volume_beam_steps,
        }
    }

    /// Cells of one cascade.
    pub fn cells(&self) -> UVec3 {
        let h = self.cells_horizontal;
        UVec3::new(h, self.cells_vertical, h)
    }
}

/// Where one cascade's cells lie.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightVolumeCascade {
    /// Lowest corner, world metres.
    pub min_m: Vec3,
    /// Size of a cell, metres.
    pub cell_m: Vec3,
}

impl LightVolumeCascade {
    /// Centre of cell `c`.
    pub fn centre(&self, c: UVec3) -> Vec3 {
        self.min_m + (c.as_vec3() + 0.5) * self.cell_m
    }
}

/// The cascades of one frame.
#[derive(Clone, Debug, PartialEq)]
pub struct LightVolumeGrid {
    /// Cells of each cascade.
    pub cells: UVec3,
    /// The cascades, finest first.
    pub cascades: Vec<LightVolumeCascade>,
    /// Whether there are clouds to light (the volume reads zero when not).
    pub enabled: bool,
}

impl LightVolumeGrid {
    /// The cascades of `settings` around `viewpoint_m`, through `field`'s heights.
    pub fn new(settings: &LightVolumeSettings, field: &CloudField, viewpoint_m: Vec3) -> Self {
        let (bottom_m, top_m, enabled) = field.cloud_heights();
        let cells = settings.cells();
        let cascades = (0..settings.cascades)
            .map(|c| {
                let half_m = settings.extent_m * CASCADE_SCALE.powi(c as i32);
                let cell_xz = 2.0 * half_m / cells.x as f32;
                // On a sphere the layers sink by d^2 / 2R at distance d.
                let reach = half_m * std::f32::consts::SQRT_2;
                let drop = match field.planet.shape {
                    PlanetShape::Flat => 0.0,
                    PlanetShape::Spherical => reach * reach / (2.0 * field.planet.radius_m),
                };
                let snap = |v: f32| ((v - half_m) / cell_xz).floor() * cell_xz;
                let low = bottom_m - drop;
                LightVolumeCascade {
                    min_m: Vec3::new(snap(viewpoint_m.x), low, snap(viewpoint_m.z)),
                    cell_m: Vec3::new(cell_xz, (top_m - low).max(1.0) / cells.y as f32, cell_xz),
                }
            })
            .collect();
        LightVolumeGrid {
            cells,
            cascades,
            enabled,
        }
    }

    /// Whether this grid, solved for an earlier frame, still serves a frame that would place
    /// `fresh`: the same cells through the same heights, and every cascade within
    /// [`RECENTRE_CELLS`] cells of where `fresh` puts it. A real-time host keeps it, and its
    /// solution stays warm, where recentring on every cell the eye crosses would start the solve
    /// cold each time.
    pub fn still_serves(&self, fresh: &LightVolumeGrid) -> bool {
        let near = |(kept, new): (&LightVolumeCascade, &LightVolumeCascade)| {
            let offset = (kept.min_m - new.min_m).abs();
            kept.cell_m == new.cell_m
                && kept.min_m.y == new.min_m.y
                && offset.x.max(offset.z) <= RECENTRE_CELLS * new.cell_m.x
        };
        self.cells == fresh.cells
            && self.enabled == fresh.enabled
            && self.cascades.len() == fresh.cascades.len()
            && self.cascades.iter().zip(&fresh.cascades).all(near)
    }

    /// Where each cascade's cells lay in `solved`, an earlier grid of the same cells through the
    /// same heights, as whole cells along x and z: cell `c` of this grid is cell `c + shift` of
    /// `solved`. None when the two grids do not line up (other cells, sizes or heights), when a
    /// recentred grid cannot start from the old solution.
    pub fn shift_cells_from(&self, solved: &LightVolumeGrid) -> Option<Vec<IVec2>> {
        let same = self.cells == solved.cells
            && self.enabled == solved.enabled
            && self.cascades.len() == solved.cascades.len();
        let shift = |(new, old): (&LightVolumeCascade, &LightVolumeCascade)| {
            let cells = (new.min_m - old.min_m) / new.cell_m;
            let whole = cells.round();
            let lines_up = new.cell_m == old.cell_m
                && new.min_m.y == old.min_m.y
                && (cells - whole).abs().max_element() < 1e-3;
            lines_up.then(|| IVec2::new(whole.x as i32, whole.z as i32))
        };
        let shifts = self.cascades.iter().zip(&solved.cascades).map(shift);
        same.then(|| shifts.collect::<Option<Vec<_>>>()).flatten()
    }
}

/// How many cells (of its finest cascade, 333 m in the default scene) the eye may move from where
/// a kept grid was centred before a real-time host recentres it ([`LightVolumeGrid::still_serves`]):
/// a twelfth of the cascade's half-width, so the eye always has most of the fine cascade around it.
pub const RECENTRE_CELLS: f32 = 4.0;
