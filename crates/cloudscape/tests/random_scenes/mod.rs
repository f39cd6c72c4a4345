//! Random in-range scenes for the property tests that no scene gives a non-finite or negative
//! pixel (`finite_pixels.rs` here, `finite_radiance.rs` of the path tracer): every parameter drawn
//! from its documented range (`default.toml`) by proptest with fixed seeds, so runs repeat and a
//! failure shrinks to a minimal scene.

use cloudscape::field::CloudField;
use cloudscape::scene::{Scene, SceneDocument};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestCaseError, TestRng, TestRunner};
use std::path::Path;

/// Draws per case.
const DRAWS: u32 = 2;

/// `key=value` with the value drawn from `range`.
fn float(key: &'static str, range: std::ops::Range<f32>) -> BoxedStrategy<String> {
    range.prop_map(move |v| format!("{key}={v}")).boxed()
}

/// The random part of a scene, as `--set` overrides: sun, camera, the layer, optics, air, planet
/// radius and time.
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

/// The scene of the default file with `overrides`.
pub fn scene(overrides: &[String]) -> Scene {
    SceneDocument::parse("", "case.toml", Path::new("."), overrides)
        .unwrap_or_else(|e| panic!("{e}"))
        .scene
}

/// A field of the default noise, baked and held: while it lives, every field the cases build
/// shares its noise rather than baking its own (the drawn parameters leave the noise seed alone).
pub fn noise_holder() -> CloudField {
    let field = CloudField::new(&scene(&[]), Path::new(".")).expect("the default field builds");
    field.bake_noise();
    field
}

/// Runs `check` on [`DRAWS`] scenes per case, each made of `fixed(case)` and random parameters,
/// with a seed per case; panics with the case and the shrunk failing scene.
pub fn check_cases<C: std::fmt::Debug>(
    cases: &[C],
    seed: u8,
    fixed: impl Fn(&C) -> Vec<String>,
    check: impl Fn(&Scene) -> Result<(), String>,
) {
    for (index, case) in cases.iter().enumerate() {
        let config = Config {
            cases: DRAWS,
            failure_persistence: None,
            ..Config::default()
        };
        let rng = TestRng::from_seed(RngAlgorithm::ChaCha, &[seed + index as u8; 32]);
        let mut runner = TestRunner::new_with_rng(config, rng);
        let result = runner.run(&parameters(), |parameters| {
            let mut overrides = fixed(case);
            overrides.extend(parameters);
            check(&scene(&overrides)).map_err(TestCaseError::fail)
        });
        if let Err(error) = result {
            panic!("{case:?}: {error}");
        }
    }
}

/// The first pixel that is not finite and >= 0 in every channel, as an error.
pub fn finite_non_negative(pixels: &[[f32; 4]]) -> Result<(), String> {
    match pixels
        .iter()
        .position(|p| p.iter().any(|c| !(c.is_finite() && *c >= 0.0)))
    {
        Some(i) => Err(format!("pixel {i} is {:?}", pixels[i])),
        None => Ok(()),
    }
}
