//! Each cell's inputs from the cloud field and the environment: the CPU twin of
//! `light_volume_cells` in `light_volume.wgsl`.

use super::solve::{Boundaries, Diffusion};
use super::{DiffuseOptics, LightVolumeCascade, LightVolumeGrid, LightVolumeSettings};
use crate::environment::ViewedEnvironment;
use crate::field::CloudField;
use glam::{UVec3, Vec3};
use rayon::prelude::*;
use std::f32::consts::PI;

/// Growth of the beam's segments from one to the next toward the sun: fine near the cell, where
/// the field shades it most, longer far away.
pub const BEAM_GROWTH: f32 = 1.1;
/// Longest path of the beam toward the sun, metres (a low sun's path to the top of the layers).
pub const BEAM_PATH_MAX_M: f32 = 16000.0;
/// Lowest sun height the beam's path length follows (the path stays bounded).
pub const BEAM_MIN_SUN_Y: f32 = 0.02;

/// The offsets of a cell's eight extinction samples, in cells from its centre.
pub const CELL_SAMPLE_OFFSET: f32 = 0.25;

/// What a frame's volume needs besides the field: the sun, the light around the clouds and the
/// ground, at scene time `time_s`.
pub struct VolumeLight<'a> {
    /// The environment seen from the viewpoint.
    pub environment: &'a ViewedEnvironment,
    /// Lambertian ground albedo; None without a ground.
    pub ground_albedo: Option<Vec3>,
    /// Scene time, seconds.
    pub time_s: f32,
}

/// The diffusion problem of cascade `index` of `grid`.
pub fn diffusion(
    (grid, index): (&LightVolumeGrid, usize),
    settings: &LightVolumeSettings,
    (field, optics): (&CloudField, DiffuseOptics),
    light: &VolumeLight,
) -> Diffusion {
    let cascade = grid.cascades[index];
    let cells = grid.cells;
    let top_m = cascade.min_m.y + cascade.cell_m.y * cells.y as f32;
    let sun = light.environment.env.sun.direction;
    let count = cells.x * cells.y * cells.z;
    let inputs: Vec<[f32; 4]> = (0..count)
        .into_par_iter()
        .map(|i| {
            let c = UVec3::new(
                i % cells.x,
                (i / cells.x) % cells.y,
                i / (cells.x * cells.y),
            );
            let cell = (&cascade, c, top_m);
            cell_inputs(cell, settings.beam_steps, (field, optics), light)
        })
        .collect();
    let environment = light.environment;
    Diffusion {
        cascade,
        cells,
        optics,
        inputs: if grid.enabled {
            inputs
        } else {
            vec![[0.0; 4]; inputs.len()]
        },
        beam_direction: -sun,
        boundaries: Boundaries {
            sky_down: environment.sky_irradiance_up(environment.viewpoint_m) / PI,
            ground_albedo: light.ground_albedo,
            sky_up: environment.sky_radiance(Vec3::NEG_Y),
        },
    }
}

/// Cell `c`'s δ-scaled extinction (w) and scaled beam (xyz) (`light_volume_cell`).
fn cell_inputs(
    (cascade, c, top_m): (&LightVolumeCascade, UVec3, f32),
    beam_steps: u32,
    (field, optics): (&CloudField, DiffuseOptics),
    light: &VolumeLight,
) -> [f32; 4] {
    let p = cascade.centre(c);
    let mut sum = 0.0;
    for k in 0..8u32 {
        let corner = Vec3::new((k & 1) as f32, ((k >> 1) & 1) as f32, ((k >> 2) & 1) as f32);
        let offset = (corner * 2.0 - 1.0) * CELL_SAMPLE_OFFSET * cascade.cell_m;
        sum += field.mean_extinction_per_m(p + offset, light.time_s);
    }
    let extinction = optics.thinning * sum / 8.0;
    let sun = light.environment.env.sun.direction;
    let length_m = ((top_m - p.y) / sun.y.max(BEAM_MIN_SUN_Y)).clamp(0.0, BEAM_PATH_MAX_M);
    let tau = field.mean_optical_depth(
        (p, sun),
        (0.0, length_m, BEAM_GROWTH),
        (beam_steps, 0.5),
        light.time_s,
    );
    let beam = light.environment.sun_irradiance(p) * (-optics.thinning * tau).exp();
    [beam.x, beam.y, beam.z, extinction]
}
