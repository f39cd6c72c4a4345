//! No non-finite or negative pixel from any in-range scene: a property test that renders random
//! scenes (every parameter drawn from its documented range) at 48x27 and checks the HDR output.
//! Every technique, sky model, phase function and planet shape is drawn, each pair of them in at
//! least one case (an orthogonal array L9(3^4)); the other parameters come from proptest with a
//! fixed seed, and a failure shrinks to a minimal scene, which is then kept below as a plain test.

use cloudscape::gpu::GpuContext;
use cloudscape::renderer::SceneRenderer;
use cloudscape::scene::{Scene, SceneDocument};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestCaseError, TestRng, TestRunner};
use std::cell::RefCell;
use std::path::Path;

/// Technique, sky model, phase model and planet shape of each case: every pair of levels of any
/// two factors appears in some row (L9; the planet's third level folds onto spherical).
const CASES: [[&str; 4]; 9] = [
    ["raymarch", "atmosphere", "mie", "spherical"],
    ["raymarch", "gradient", "hg", "flat"],
    ["raymarch", "constant", "dual_hg", "spherical"],
    ["particles", "atmosphere", "hg", "spherical"],
    ["particles", "gradient", "dual_hg", "spherical"],
    ["particles", "constant", "mie", "flat"],
    ["sprites", "atmosphere", "dual_hg", "flat"],
    ["sprites", "gradient", "mie", "spherical"],
    ["sprites", "constant", "hg", "spherical"],
];

/// What every case sets: a tiny image, cheap steps and a small weather map.
const FIXED: [&str; 6] = [
    "render.width=48",
    "render.height=27",
    "render.quality=low",
    "weather.resolution=64",
    "shadow.resolution=64",
    "particles.table_resolution=\"low\"",
];

/// A scene parameter drawn from its documented range, as an override.
fn float(key: &'static str, range: std::ops::Range<f32>) -> BoxedStrategy<String> {
    range.prop_map(move |v| format!("{key}={v}")).boxed()
}

/// The random part of a case: sun, camera, layer, optics, air and time.
fn parameters() -> impl Strategy<Value = Vec<String>> {
    let position = (-5000.0f32..5000.0, 10.0f32..9000.0, -5000.0f32..5000.0)
        .prop_map(|(x, y, z)| format!("camera.position_m=[{x},{y},{z}]"));
    vec![
        float("sun.elevation_deg", -20.0..90.0),
        float("sun.azimuth_deg", 0.0..360.0),
        position.boxed(),
        float("camera.yaw_deg", 0.0..360.0),
        float("camera.pitch_deg", -60.0..89.0),
        float("layers.0.bottom_m", 0.0..6000.0),
        float("layers.0.thickness_m", 10.0..6000.0),
        float("layers.0.coverage", 0.0..1.0),
        float("layers.0.extinction_per_m", 0.0..1.0),
        float("lighting.albedo", 0.0..1.0),
        float("lighting.ambient_scale", 0.0..4.0),
        float("phase.droplet_diameter_um", 5.0..50.0),
        float("phase.g", -0.99..0.99),
        float("phase.g_forward", -0.99..0.99),
        float("phase.g_back", -0.99..0.99),
        float("phase.forward_weight", 0.0..1.0),
        float("sky.visibility_m", 100.0..1.0e7),
        float("planet.radius_m", 1.0e3..1.0e8),
        float("render.time_s", 0.0..3600.0),
    ]
}

/// The scene of `case` with `parameters`.
fn scene(case: &[&str; 4], parameters: &[String]) -> Scene {
    let [technique, sky, phase, planet] = case;
    let mut overrides: Vec<String> = FIXED.iter().map(|s| s.to_string()).collect();
    overrides.extend([
        format!("render.technique=\"{technique}\""),
        format!("sky.model=\"{sky}\""),
        format!("phase.model=\"{phase}\""),
        format!("planet.shape=\"{planet}\""),
    ]);
    overrides.extend_from_slice(parameters);
    SceneDocument::parse("", "case.toml", Path::new("."), &overrides)
        .unwrap_or_else(|e| panic!("{e}"))
        .scene
}

/// Renders `scene` and returns the first pixel that is not finite and >= 0, with its index.
fn first_bad_pixel(
    ctx: &GpuContext,
    renderer: &mut SceneRenderer,
    scene: &Scene,
) -> Option<(usize, [f32; 4])> {
    renderer
        .clouds()
        .update_scene(ctx, scene, Path::new("."))
        .expect("the field builds");
    let images = renderer.render(ctx, scene, |_| {});
    images
        .hdr
        .pixels
        .iter()
        .position(|p| p.iter().any(|c| !(c.is_finite() && *c >= 0.0)))
        .map(|i| (i, images.hdr.pixels[i]))
}

/// A renderer to reuse across cases (live edits rebuild what changes).
fn renderer(ctx: &GpuContext) -> SceneRenderer {
    let first = scene(&CASES[0], &[]);
    SceneRenderer::new(ctx, &first, Path::new(".")).expect("the default field builds")
}

#[test]
fn random_in_range_scenes_render_only_finite_non_negative_pixels() {
    let ctx = GpuContext::for_tests();
    let renderer = RefCell::new(renderer(&ctx));
    for (index, case) in CASES.iter().enumerate() {
        let config = Config {
            cases: 2,
            failure_persistence: None,
            ..Config::default()
        };
        let seed = [index as u8 + 1; 32];
        let rng = TestRng::from_seed(RngAlgorithm::ChaCha, &seed);
        let mut runner = TestRunner::new_with_rng(config, rng);
        let result = runner.run(&parameters(), |parameters| {
            let scene = scene(case, &parameters);
            match first_bad_pixel(&ctx, &mut renderer.borrow_mut(), &scene) {
                None => Ok(()),
                Some((i, pixel)) => Err(TestCaseError::fail(format!("pixel {i} is {pixel:?}"))),
            }
        });
        if let Err(error) = result {
            panic!("{case:?}: {error}");
        }
    }
}
