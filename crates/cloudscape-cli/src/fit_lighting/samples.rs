//! Training data for the ray marcher's lighting: points inside the clouds of generated scenes, with
//! what the march knows there (its light samples toward the sun and away from it, the view and sun
//! directions) and what the path tracer says the clouds scatter there under the sun alone.
//!
//! The scenes are drawn at random (cloud type, cover, extinction, thickness, base, sun) and none is a
//! canonical scene of the realism report, so the report tests the fit on scenes it never saw. The
//! points are where random camera rays first collide with the clouds (delta tracking), so they are
//! spread over the clouds as the march's contributions are: by extinction times transmittance
//! from the eye.

use anyhow::{Result, anyhow};
use cloudscape::raymarch::{MarchSettings, back_steps, light};
use cloudscape::scene::{Quality, SceneDocument};
use cloudscape_reference::rng::Rng;
use cloudscape_reference::sampling::uniform_sphere;
use cloudscape_reference::{DEFAULT_MAJORANT_CELLS, PathTracer};
use glam::{UVec2, Vec3};
use rayon::prelude::*;

/// Distance within which camera rays look for a cloud, metres.
const RAY_REACH_M: f32 = 60_000.0;
/// Side of the square the cameras stand in, metres.
const CAMERA_SPREAD_M: f32 = 30_000.0;

/// One point of the training data.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample {
    /// Training scene it comes from.
    pub scene: u32,
    /// Optical depth toward the sun from the march's light samples (High quality).
    pub tau_sun: f32,
    /// Optical depth away from the sun to the far side of the layers, as the march samples it.
    pub tau_back: f32,
    /// Cosine between the view ray's direction and the sun's.
    pub cos_theta: f32,
    /// Sine of the sun's elevation.
    pub sun_y: f32,
    /// Source radiance per unit extinction and unit sun irradiance: the path tracer's estimate.
    pub source: f32,
    /// Standard error of that estimate.
    pub source_error: f32,
    /// The point, world metres.
    pub point_m: Vec3,
    /// The view ray's direction (from the eye).
    pub direction: Vec3,
    /// The scene's cloud family ([`Family`]).
    pub family: Family,
    /// The light volume's diffuse light there toward the eye, per unit sun irradiance (NaN
    /// outside its finest cascade): filled by [`fill_volume`], not stored.
    pub volume_diffuse: f32,
}

/// The cloud family of a generated scene.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Family {
    /// A stratus deck.
    Stratus,
    /// A stratocumulus deck.
    Stratocumulus,
    /// Cumulus.
    Cumulus,
    /// Cumulonimbus towers among cumulus.
    Cumulonimbus,
}

impl Family {
    /// Every family, in the order the scenes draw them.
    pub const ALL: [Family; 4] = [
        Family::Stratus,
        Family::Stratocumulus,
        Family::Cumulus,
        Family::Cumulonimbus,
    ];

    /// Whether the family forms decks (else towers).
    pub fn is_deck(self) -> bool {
        matches!(self, Family::Stratus | Family::Stratocumulus)
    }
}

/// The generated training scene `index` and its cloud family: a cloud layer and a sun drawn from
/// `index`, lit by the sun alone (no sky, no haze, and a ground of the default albedo only when
/// `ground`), so the light found at a point is the sun's.
pub fn training_scene(index: u32, ground: bool) -> Result<(SceneDocument, Family)> {
    let mut rng = Rng::for_sample(0x5eed, u64::from(index), 0);
    let mut draw = |lo: f32, hi: f32| lo + (hi - lo) * rng.next_f32();
    let elevation = draw(3.0, 87.0);
    let azimuth = draw(0.0, 360.0);
    let coverage = draw(0.15, 0.95);
    let extinction = draw(0.02, 0.09);
    let bottom = draw(800.0, 2300.0);
    let family = Family::ALL[(draw(0.0, 4.0) as usize).min(3)];
    let (types, thickness) = match family {
        Family::Stratus => ("{ stratus = 1.0 }", draw(200.0, 800.0)),
        Family::Stratocumulus => ("{ stratocumulus = 1.0 }", draw(500.0, 1500.0)),
        Family::Cumulus => ("{ cumulus = 1.0 }", draw(1000.0, 3500.0)),
        Family::Cumulonimbus => (
            "{ cumulonimbus = 0.6, cumulus = 0.4 }",
            draw(5000.0, 10000.0),
        ),
    };
    let overrides = [
        format!("sun.elevation_deg={elevation}"),
        format!("sun.azimuth_deg={azimuth}"),
        "sun.irradiance=1.0".into(),
        "sky.model=\"constant\"".into(),
        "sky.radiance=[0.0, 0.0, 0.0]".into(),
        "sky.visibility_m=10000000.0".into(),
        format!("ground.enabled={ground}"),
        format!("layers.0.coverage={coverage}"),
        format!("layers.0.extinction_per_m={extinction}"),
        format!("layers.0.thickness_m={thickness}"),
        format!("layers.0.bottom_m={bottom}"),
        format!("layers.0.types={types}"),
        format!("layers.0.noise_seed={}", 100 + index),
        format!("weather.seed={}", 200 + index),
    ];
    Ok((SceneDocument::load(None, &overrides)?, family))
}

/// `points` camera rays into training scene `index`, each collision estimated with `paths` paths.
pub fn scene_samples(index: u32, points: u32, paths: u32) -> Result<Vec<Sample>> {
    let (doc, family) = training_scene(index, false)?;
    let tracer = PathTracer::for_scene(
        &doc.scene,
        &doc.resolve_path(""),
        UVec2::ONE,
        DEFAULT_MAJORANT_CELLS,
    )
    .map_err(|e| anyhow!(doc.error_at(&e.key_path, e.message)))?;
    let light_steps = MarchSettings::preset(Quality::High).1;
    let samples = (0..points)
        .into_par_iter()
        .filter_map(|i| {
            let mut rng = Rng::for_sample(0xf17, u64::from(index) << 32 | u64::from(i), 0);
            sample(&tracer, (index, family, light_steps, paths), &mut rng)
        })
        .collect();
    Ok(samples)
}

/// One camera ray's collision and its estimate; None when the ray meets no cloud.
fn sample(
    tracer: &PathTracer<cloudscape_reference::CloudMedium>,
    (index, family, light_steps, paths): (u32, Family, u32, u32),
    rng: &mut Rng,
) -> Option<Sample> {
    let field = tracer.volume.medium.field();
    let (bottom_m, top_m) = field.altitude_range_m()?;
    let sun = tracer.environment.sun?.direction;
    let (origin, dir) = camera_ray((bottom_m, top_m), rng);
    let t = tracer.volume.free_flight(origin, dir, RAY_REACH_M, rng)?;
    let p = origin + dir * t;
    // The march's light samples, at the middle of each segment.
    let tau_sun = light::sun_optical_depth(field, p, sun, (light_steps, 0.5), 0.0);
    let tau_back = light::back_optical_depth(field, p, sun, (back_steps(light_steps), 0.5), 0.0);
    let (source, source_error) = mean_and_error(paths, || tracer.source_radiance(p, dir, rng).y);
    Some(Sample {
        scene: index,
        tau_sun,
        tau_back,
        cos_theta: dir.dot(sun),
        sun_y: sun.y,
        source,
        source_error,
        point_m: p,
        direction: dir,
        family,
        volume_diffuse: f32::NAN,
    })
}

/// The mean of `paths` estimates and its standard error.
pub fn mean_and_error(paths: u32, mut estimate: impl FnMut() -> f32) -> (f32, f32) {
    let (mut sum, mut sum_sq) = (0.0f64, 0.0f64);
    for _ in 0..paths {
        let v = f64::from(estimate());
        sum += v;
        sum_sq += v * v;
    }
    let n = f64::from(paths);
    let mean = sum / n;
    (
        mean as f32,
        ((sum_sq / n - mean * mean).max(0.0) / n).sqrt() as f32,
    )
}

/// Solves the light volume of training scene `index` (the scene's own settings, centred over the
/// middle of the cameras' square) and reads it at each of `samples` inside its finest cascade.
pub fn fill_volume(index: u32, samples: &mut [Sample]) -> Result<()> {
    use cloudscape::environment::light_volume::inputs::VolumeLight;
    use cloudscape::environment::light_volume::{
        DiffuseOptics, LightVolume, LightVolumeGrid, LightVolumeSettings,
    };
    use cloudscape::environment::{Environment, ViewedEnvironment};
    let (doc, _) = training_scene(index, false)?;
    let scene = &doc.scene;
    let field = cloudscape::field::CloudField::new(scene, &doc.resolve_path(""))
        .map_err(|e| anyhow!(doc.error_at(&e.key_path, e.message)))?;
    let settings = LightVolumeSettings::from_scene(scene);
    let grid = LightVolumeGrid::new(&settings, &field, Vec3::ZERO);
    let env = Environment::from_scene(scene);
    let viewed = ViewedEnvironment::new(&env, Vec3::ZERO);
    let light = VolumeLight {
        environment: &viewed,
        ground_albedo: None,
        time_s: 0.0,
    };
    let lobes = cloudscape::optics::PhaseLobes::from_scene(&scene.phase);
    let optics = DiffuseOptics::of(&scene.lighting.sun_slab(lobes));
    let volume = LightVolume::solve(&grid, &settings, (&field, optics), &light);
    let reach = settings.extent_m;
    for s in samples {
        let inside = s.point_m.x.abs() < reach && s.point_m.z.abs() < reach;
        s.volume_diffuse = if inside {
            volume.diffuse(s.point_m, -s.direction).y
        } else {
            f32::NAN
        };
    }
    Ok(())
}

/// A camera ray: from the ground looking up, from inside the layers, or from above looking down.
fn camera_ray((bottom_m, top_m): (f32, f32), rng: &mut Rng) -> (Vec3, Vec3) {
    let place = rng.next_f32();
    let d = uniform_sphere(rng.next_vec2());
    let xz = (rng.next_vec2() - 0.5) * CAMERA_SPREAD_M;
    let (altitude, dir) = if place < 0.4 {
        (30.0, Vec3::new(d.x, d.y.abs().max(0.03), d.z).normalize())
    } else if place < 0.7 {
        (bottom_m + (top_m - bottom_m) * rng.next_f32(), d)
    } else {
        let above = top_m + 300.0 + 3000.0 * rng.next_f32();
        (above, Vec3::new(d.x, -d.y.abs().max(0.03), d.z).normalize())
    };
    (Vec3::new(xz.x, altitude, xz.y), dir)
}
