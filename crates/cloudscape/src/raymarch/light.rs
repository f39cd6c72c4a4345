//! The ray marcher's light paths from a point in the clouds: the optical depth of the mean field
//! toward the sun, to the top of the layers, and away from it, to where the path leaves them (the
//! slab model's far side), each within [`super::SUN_PATH_M`] and sampled by doubling segments
//! (Schneider 2015's cheap light samples). The CPU twins of `march_light.wgsl`, probed against it.

use super::SUN_PATH_M;
use crate::field::CloudField;
use glam::Vec3;

/// Optical depth toward the sun `sun` (unit) from `p` at time `time_s`: `steps` doubling segments,
/// each sampled at `jitter` of its length: `march_sun_optical_depth` in `march_light.wgsl`.
pub fn sun_optical_depth(
    field: &CloudField,
    p: Vec3,
    sun: Vec3,
    (steps, jitter): (u32, f32),
    time_s: f32,
) -> f32 {
    let length_m = field
        .altitude_range_m()
        .map(|(_, top_m)| to_top_m(field, p, sun, top_m));
    path_depth(field, (p, sun), length_m, (steps, jitter), time_s)
}

/// Optical depth away from the sun `sun` (unit) from `p` to the bottom of the layers (or their top
/// when the path rises), as [`sun_optical_depth`]: `march_back_optical_depth` in
/// `march_light.wgsl`.
pub fn back_optical_depth(
    field: &CloudField,
    p: Vec3,
    sun: Vec3,
    (steps, jitter): (u32, f32),
    time_s: f32,
) -> f32 {
    let away = -sun;
    let length_m = field.altitude_range_m().map(|(bottom_m, top_m)| {
        field
            .planet
            .below(p, away, bottom_m)
            .filter(|&(t0, t1)| t0 <= t1 && t0 > 0.0)
            .map_or_else(|| to_top_m(field, p, away, top_m), |(t0, _)| t0 as f32)
    });
    path_depth(field, (p, away), length_m, (steps, jitter), time_s)
}

/// Distance from `p` along `dir` to where it leaves altitude `top_m` upward (`field_below(..).y`):
/// infinite when it never does, negative when the line never is below it.
fn to_top_m(field: &CloudField, p: Vec3, dir: Vec3, top_m: f32) -> f32 {
    field
        .planet
        .below(p, dir, top_m)
        .map_or(-1.0, |(_, t1)| t1 as f32)
}

/// The mean field's optical depth over `length_m` (None without layers: the longest path) clamped to
/// [`SUN_PATH_M`].
fn path_depth(
    field: &CloudField,
    ray: (Vec3, Vec3),
    length_m: Option<f32>,
    (steps, jitter): (u32, f32),
    time_s: f32,
) -> f32 {
    let length_m = length_m.map_or(SUN_PATH_M.1, |l| l.clamp(SUN_PATH_M.0, SUN_PATH_M.1));
    field.mean_optical_depth(ray, (0.0, length_m, 2.0), (steps, jitter), time_s)
}

/// The march's light paths on the GPU (`march_light.wgsl`), the twin of this module.
pub static MARCH_LIGHT_WGSL: crate::shader::WgslModule = crate::shader::wgsl_module!(
    "march_light",
    "march_light.wgsl",
    [
        &crate::field::gpu::FIELD_WGSL,
        &crate::environment::ENVIRONMENT_WGSL
    ],
    march_light_constants
);

/// The light paths' constants as WGSL: the sun path's bounds ([`super::SUN_PATH_M`]).
fn march_light_constants() -> String {
    use crate::shader::WgslConst::F32;
    crate::shader::wgsl_consts([
        ("MARCH_SUN_PATH_MIN_M", F32(super::SUN_PATH_M.0)),
        ("MARCH_SUN_PATH_MAX_M", F32(super::SUN_PATH_M.1)),
    ])
}
