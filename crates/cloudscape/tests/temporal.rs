//! Temporal reuse: converges on a still view, recovers quickly after a fast move (no lasting
//! ghosts), and restarts on a camera cut.

use cloudscape::frame::Frame;
use cloudscape::gpu::{GpuContext, PassTimer};
use cloudscape::image::{LdrImage, flip};
use cloudscape::renderer::{PASS_COUNT, Reuse, SceneRenderer};
use cloudscape::scene::{Scene, SceneDocument};
use cloudscape::temporal::TemporalSettings;
use glam::{UVec2, Vec3};
use std::path::Path;

const SIZE: UVec2 = UVec2::new(128, 72);

fn scene() -> Scene {
    let overrides = [
        "render.quality=medium",
        "camera.pitch_deg=22",
        "render.width=128",
        "render.height=72",
    ]
    .map(String::from);
    SceneDocument::parse("", "temporal test", Path::new("."), &overrides)
        .expect("valid")
        .scene
}

/// The converged reference of `frame`: every pixel marched with many samples.
fn converged(ctx: &GpuContext, scene: &Scene, frame: &Frame) -> LdrImage {
    let mut still = scene.clone();
    still.render.samples_per_pixel = Some(8);
    still.render.primary_steps = Some(128);
    let mut renderer = SceneRenderer::new(ctx, &still, Path::new(".")).expect("field");
    let mut timer = PassTimer::new(ctx, PASS_COUNT);
    renderer.render_frame(ctx, frame, Reuse::None, &mut timer);
    renderer.images(ctx).ldr
}

struct Sequence {
    renderer: SceneRenderer,
    timer: PassTimer,
    reuse: Reuse,
    index: u32,
}

impl Sequence {
    fn new(ctx: &GpuContext, scene: &Scene, divisor: u32) -> Sequence {
        Sequence {
            renderer: SceneRenderer::new(ctx, scene, Path::new(".")).expect("field"),
            timer: PassTimer::new(ctx, PASS_COUNT),
            reuse: Reuse::Temporal(TemporalSettings {
                divisor,
                ..TemporalSettings::default()
            }),
            index: 0,
        }
    }

    fn frame(&mut self, ctx: &GpuContext, scene: &Scene, camera: Vec3) -> LdrImage {
        let mut s = scene.clone();
        s.camera.position_m = camera.to_array();
        let mut frame = Frame::from_scene(&s, SIZE);
        frame.frame_index = self.index;
        self.index += 1;
        self.renderer
            .render_frame(ctx, &frame, self.reuse, &mut self.timer);
        self.renderer.images(ctx).ldr
    }
}

fn flip_mean(a: &LdrImage, b: &LdrImage) -> f32 {
    flip(a, b).expect("same size").0.mean
}

#[test]
fn converges_on_a_still_view_and_recovers_after_a_fast_move() {
    let ctx = GpuContext::for_tests();
    let scene = scene();
    let start = Vec3::from_array(scene.camera.position_m);
    let moved = start + Vec3::new(400.0, 0.0, 0.0); // 400 m sideways in one frame: not a cut
    let frame_at = |p: Vec3| {
        let mut s = scene.clone();
        s.camera.position_m = p.to_array();
        Frame::from_scene(&s, SIZE)
    };
    let reference_start = converged(&ctx, &scene, &frame_at(start));
    let reference_moved = converged(&ctx, &scene, &frame_at(moved));
    let mut seq = Sequence::new(&ctx, &scene, 2);
    let first_image = seq.frame(&ctx, &scene, start);
    let first = flip_mean(&first_image, &reference_start);
    let mut settled = first;
    let mut last = first_image.clone();
    for _ in 0..15 {
        last = seq.frame(&ctx, &scene, start);
        settled = flip_mean(&last, &reference_start);
    }
    if std::env::var_os("DUMP").is_some() {
        first_image
            .write_png(Path::new("/tmp/r/t_first.png"))
            .unwrap();
        last.write_png(Path::new("/tmp/r/t_last.png")).unwrap();
        reference_start
            .write_png(Path::new("/tmp/r/t_ref.png"))
            .unwrap();
    }
    eprintln!("still view: FLIP {first:.4} on the first frame, {settled:.4} after 16");
    assert!(
        settled < 0.8 * first,
        "history must reduce the error of a still view: {first} -> {settled}"
    );
    let jump = flip_mean(&seq.frame(&ctx, &scene, moved), &reference_moved);
    let mut after = jump;
    for _ in 0..7 {
        after = flip_mean(&seq.frame(&ctx, &scene, moved), &reference_moved);
    }
    eprintln!("after a 400 m jump: FLIP {jump:.4}, 8 frames later {after:.4}");
    assert!(
        after < settled * 1.5 + 0.01,
        "ghosts must fade within 8 frames: {after} vs settled {settled}"
    );
}

#[test]
fn a_camera_cut_restarts_the_history() {
    let ctx = GpuContext::for_tests();
    let scene = scene();
    let start = Vec3::from_array(scene.camera.position_m);
    let far = start + Vec3::new(5000.0, 0.0, 3000.0);
    let mut warm = Sequence::new(&ctx, &scene, 2);
    for _ in 0..4 {
        warm.frame(&ctx, &scene, start);
    }
    let cut = warm.frame(&ctx, &scene, far);
    // A fresh sequence whose first frame is at the same place with the same frame index.
    let mut fresh = Sequence::new(&ctx, &scene, 2);
    fresh.index = 4;
    let first = fresh.frame(&ctx, &scene, far);
    assert!(
        cut == first,
        "after a cut no history may leak into the image"
    );
}
