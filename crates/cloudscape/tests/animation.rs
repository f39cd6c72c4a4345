//! Animated scenes: keyframe errors located in the file, the example fly-through, and one renderer
//! drawing stills at different times.

use std::path::Path;

use cloudscape::animation::{scene_at, time_range_s};
use cloudscape::gpu::GpuContext;
use cloudscape::renderer::SceneRenderer;
use cloudscape::scene::{Scene, SceneDocument};
use glam::Vec3;
use scene_support::{assert_rejected, parse};

mod scene_support;

const TWO_CAMERA_KEYS: &str = "\
[[animation.camera_path]]
time_s = 0.0
position_m = [0.0, 30.0, 0.0]

[[animation.camera_path]]
time_s = 2.0
position_m = [100.0, 30.0, 0.0]
";

#[test]
fn keyframe_times_that_do_not_increase_are_located() {
    let text = TWO_CAMERA_KEYS.replace("time_s = 2.0", "time_s = -1.5");
    let words = ["-1.5 s is not after", "strictly increase"];
    assert_rejected(&text, (6, 10), "animation.camera_path.1.time_s", &words);
}

#[test]
fn a_path_of_one_keyframe_is_located() {
    let text = "[animation]\ntime_of_day = [{ time_s = 0.0, sun_elevation_deg = 5.0, sun_azimuth_deg = 90.0 }]\n";
    let words = ["1 keyframe given", "at least 2"];
    assert_rejected(text, (2, 15), "animation.time_of_day", &words);
}

#[test]
fn keyframe_values_out_of_range_are_located() {
    let text = format!("{TWO_CAMERA_KEYS}pitch_deg = 95.0\n");
    assert_rejected(
        &text,
        (8, 13),
        "animation.camera_path.1.pitch_deg",
        &["allowed -90..90"],
    );
}

#[test]
fn a_valid_path_loads_and_a_scene_without_one_is_static() {
    let scene = parse(TWO_CAMERA_KEYS).unwrap().scene;
    assert_eq!(scene.animation.camera_path.len(), 2);
    assert_eq!(scene_at(&scene, 1.0).camera.position_m, [50.0, 30.0, 0.0]);
    assert!(parse("").unwrap().scene.animation.is_static());
}

fn flythrough() -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/flythrough.toml");
    SceneDocument::load(Some(&path), &[])
        .unwrap_or_else(|e| panic!("{e}"))
        .scene
}

/// The camera's position and unit view direction at `time_s`.
fn eye_and_view(scene: &Scene, time_s: f32) -> (Vec3, Vec3) {
    let camera = scene_at(scene, time_s).camera;
    let view = cloudscape::scene::direction_from_angles_deg(camera.pitch_deg, camera.yaw_deg);
    (Vec3::from_array(camera.position_m), view)
}

/// Issue 4 measures temporal reuse on this sequence: it must hold a fast sideways move and a
/// climb from under the layer to above it.
#[test]
fn the_flythrough_moves_fast_sideways_and_climbs_through_the_layer() {
    let scene = flythrough();
    let (start, end) = time_range_s(&scene.animation).expect("an animated scene");
    assert!(end - start >= 5.0, "{start}..{end} s");
    let layer = &scene.layers[0];
    let top_m = layer.bottom_m + layer.thickness_m;
    let altitude = |t| eye_and_view(&scene, t).0.y;
    assert!(altitude(start) < layer.bottom_m && altitude(end) > top_m);
    let dt = 0.05;
    let fastest_sideways_m_per_s = (0..((end - start) / dt) as usize)
        .map(|i| start + i as f32 * dt)
        .map(|t| {
            let ((a, view), (b, _)) = (eye_and_view(&scene, t), eye_and_view(&scene, t + dt));
            let velocity = (b - a) / dt;
            (velocity - view * velocity.dot(view)).length()
        })
        .fold(0.0, f32::max);
    assert!(
        fastest_sideways_m_per_s > 500.0,
        "{fastest_sideways_m_per_s} m/s"
    );
}

/// `cloudscape animate` builds one renderer and renders every still with it: the still's time
/// must reach the field, so that the wind moves the clouds between stills.
#[test]
fn one_renderer_draws_stills_at_any_time() {
    let mut scene = Scene::default();
    scene.render.width = 48;
    scene.render.height = 27;
    scene.render.quality = cloudscape::scene::Quality::Low;
    scene.camera.pitch_deg = 25.0;
    scene.layers[0].wind_m_per_s = [400.0, 0.0];
    let ctx = GpuContext::for_tests();
    let mut renderer = SceneRenderer::new(&ctx, &scene, Path::new(".")).expect("field builds");
    let mut render = |time_s| {
        let still = scene_at(&scene, time_s);
        renderer
            .set_scene(&ctx, &still, Path::new("."))
            .expect("an edit of time only");
        renderer.render(&ctx, |_| {}).ldr
    };
    let first = render(0.0);
    assert_ne!(first, render(10.0), "the wind did not move the clouds");
}
