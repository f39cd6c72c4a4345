//! The ground under the clouds: the path tracer's light leaving the ground of a generated scene
//! (lit by the sun alone) at points under cloud, against what the compositor gives there with the
//! light volume (the δ-scaled sun beam through the clouds and the volume's diffuse light from
//! their bases) and with the shadow map alone (the sun dimmed by the clouds' diffuse
//! transmittance, `optics::diffuse_transmittance`).

use super::samples::{mean_and_error, training_scene};
use anyhow::{Result, anyhow};
use cloudscape::environment::light_volume::inputs::VolumeLight;
use cloudscape::environment::light_volume::{
    DiffuseOptics, LightVolume, LightVolumeGrid, LightVolumeSettings,
};
use cloudscape::environment::{Environment, ViewedEnvironment};
use cloudscape::field::CloudField;
use cloudscape::optics::{PhaseLobes, diffuse_transmittance};
use cloudscape_reference::rng::Rng;
use cloudscape_reference::{DEFAULT_MAJORANT_CELLS, PathTracer};
use glam::{UVec2, Vec3};
use rayon::prelude::*;
use std::f32::consts::PI;

/// Least optical depth of the clouds straight above a ground point "under cloud".
pub const MIN_OPTICAL_DEPTH_ABOVE: f32 = 3.0;
/// Candidate points drawn per point kept.
const CANDIDATES_PER_POINT: u32 = 20;
/// Coarse samples of the clouds along a vertical or slant line through the layers.
const LINE_STEPS: u32 = 64;

/// A ground point under cloud in a generated scene, with the path tracer's estimate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GroundSample {
    /// Generated scene it comes from.
    pub scene: u32,
    /// The point on the ground, world metres.
    pub point_m: Vec3,
    /// Radiance leaving the ground per unit sun irradiance: the path tracer's estimate.
    pub radiance: f32,
    /// Standard error of that estimate.
    pub error: f32,
}

/// What each model gives at a sample, per unit sun irradiance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GroundPrediction {
    /// The light volume's ground (`compose_ground` with a volume).
    pub volume: f32,
    /// The shadow map's diffuse transmittance (`compose_ground` without one).
    pub shadow_map: f32,
}

/// Up to `points` ground points under cloud within `reach_m` of the origin in scene `index`, each
/// estimated with `paths` paths.
pub fn ground_samples(
    index: u32,
    (points, paths): (u32, u32),
    reach_m: f32,
) -> Result<Vec<GroundSample>> {
    let (doc, _) = training_scene(index, true)?;
    let tracer = PathTracer::for_scene(
        &doc.scene,
        &doc.resolve_path(""),
        UVec2::ONE,
        DEFAULT_MAJORANT_CELLS,
    )
    .map_err(|e| anyhow!(doc.error_at(&e.key_path, e.message)))?;
    let field = tracer.volume.medium.field();
    let Some(range) = field.altitude_range_m() else {
        return Ok(Vec::new());
    };
    let mut rng = Rng::for_sample(0x9a0d, u64::from(index), 0);
    let under: Vec<Vec3> = (0..points * CANDIDATES_PER_POINT)
        .map(|_| {
            let xz = (rng.next_vec2() * 2.0 - 1.0) * reach_m;
            Vec3::new(xz.x, 0.0, xz.y)
        })
        .filter(|&g| optical_depth_along(field, g, Vec3::Y, range) >= MIN_OPTICAL_DEPTH_ABOVE)
        .take(points as usize)
        .collect();
    Ok(under
        .into_par_iter()
        .enumerate()
        .map(|(i, g)| {
            let mut rng = Rng::for_sample(0x9a0e, u64::from(index) << 32 | i as u64, 0);
            let down = || {
                tracer
                    .ray_radiance(g + Vec3::Y, Vec3::NEG_Y, 10.0, &mut rng)
                    .y
            };
            let (radiance, error) = mean_and_error(paths, down);
            GroundSample {
                scene: index,
                point_m: g,
                radiance,
                error,
            }
        })
        .collect())
}

/// The coarse field's optical depth along `dir` (unit, upward) from ground point `g` across the
/// layers' altitudes `(bottom_m, top_m)`.
fn optical_depth_along(
    field: &CloudField,
    g: Vec3,
    dir: Vec3,
    (bottom_m, top_m): (f32, f32),
) -> f32 {
    let rise = dir.y.max(0.02);
    field.coarse_optical_depth(
        (g, dir),
        (bottom_m / rise, (top_m - bottom_m) / rise, 1.0),
        (LINE_STEPS, 0.5),
        0.0,
    )
}

/// Each model's light leaving the ground at `samples` of scene `index` (the volume solved with the
/// ground, around the origin).
pub fn predict(index: u32, samples: &[GroundSample]) -> Result<Vec<GroundPrediction>> {
    let (doc, _) = training_scene(index, true)?;
    let scene = &doc.scene;
    let field = CloudField::new(scene, &doc.resolve_path(""))
        .map_err(|e| anyhow!(doc.error_at(&e.key_path, e.message)))?;
    let settings = LightVolumeSettings::from_scene(scene);
    let grid = LightVolumeGrid::new(&settings, &field, Vec3::ZERO);
    let env = Environment::from_scene(scene);
    let viewed = ViewedEnvironment::new(&env, Vec3::ZERO);
    let frame = cloudscape::frame::FrameSettings::from_scene(scene);
    let albedo = frame.ground_albedo.expect("the scene has a ground").y;
    let light = VolumeLight {
        environment: &viewed,
        ground_albedo: frame.ground_albedo,
        time_s: 0.0,
    };
    let optics = DiffuseOptics::of(
        &scene
            .lighting
            .sun_slab(PhaseLobes::from_scene(&scene.phase)),
    );
    let volume = LightVolume::solve(&grid, &settings, (&field, optics), &light);
    let sun = env.sun.direction;
    let range = field.altitude_range_m().unwrap_or((0.0, 0.0));
    Ok(samples
        .iter()
        .map(|s| {
            let g = s.point_m;
            let tau = optical_depth_along(&field, g, sun, range);
            let sun_irradiance = viewed.sun_irradiance(g).y * sun.y.max(0.0);
            let diffuse = volume.ground_irradiance(g).map_or(0.0, |e| e.y);
            let beam = sun_irradiance * (-optics.thinning * tau).exp();
            let dimmed = sun_irradiance * diffuse_transmittance(tau, frame.cloud_mean_cosine);
            GroundPrediction {
                volume: albedo / PI * (beam + diffuse),
                shadow_map: albedo / PI * dimmed,
            }
        })
        .collect())
}

/// Columns of a ground samples file.
const HEADER: &str = "scene,x_m,z_m,radiance,error";

/// Writes `samples` to `path`.
pub fn write(path: &std::path::Path, samples: &[GroundSample]) -> Result<()> {
    let mut text = format!("{HEADER}\n");
    for s in samples {
        let p = s.point_m;
        text += &format!("{},{},{},{},{}\n", s.scene, p.x, p.z, s.radiance, s.error);
    }
    std::fs::write(path, text).map_err(|e| anyhow!("{}: {e}", path.display()))
}

/// The samples in `path`; None when it is missing or not a ground samples file.
pub fn read(path: &std::path::Path) -> Option<Vec<GroundSample>> {
    super::csv_rows(path, HEADER)?
        .into_iter()
        .map(|v| {
            (v.len() == 5).then(|| GroundSample {
                scene: v[0] as u32,
                point_m: Vec3::new(v[1], 0.0, v[2]),
                radiance: v[3],
                error: v[4],
            })
        })
        .collect()
}
