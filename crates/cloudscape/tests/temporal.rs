//! Temporal reuse: converges on a still view, recovers quickly after a fast move (no lasting
//! ghosts), and restarts on a camera cut.

use cloudscape::frame::Frame;
use cloudscape::gpu::{GpuContext, PassTimer};
use cloudscape::image::{HdrImage, LdrImage, flip};
use cloudscape::renderer::{PASS_COUNT, Rendered, Reuse, SceneRenderer};
use cloudscape::scene::{Scene, SceneDocument};
use cloudscape::shadow::LightingReuse;
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
    /// A sequence that carries its lighting across frames as a game does
    /// ([`LightingReuse::REAL_TIME`]): what these tests follow is the image's history, and a
    /// light volume solved cold every frame would be most of a frame's cost on a software GPU.
    fn new(ctx: &GpuContext, scene: &Scene, divisor: u32) -> Sequence {
        let mut renderer = SceneRenderer::new(ctx, scene, Path::new(".")).expect("field");
        renderer
            .clouds()
            .set_lighting_reuse(Some(LightingReuse::REAL_TIME));
        Sequence {
            renderer,
            timer: PassTimer::new(ctx, PASS_COUNT),
            reuse: Reuse::Temporal(TemporalSettings {
                divisor,
                ..TemporalSettings::default()
            }),
            index: 0,
        }
    }

    fn frame(&mut self, ctx: &GpuContext, scene: &Scene, camera: Vec3) -> LdrImage {
        self.rendered(ctx, scene, camera).ldr
    }

    fn rendered(&mut self, ctx: &GpuContext, scene: &Scene, camera: Vec3) -> Rendered {
        let mut s = scene.clone();
        s.camera.position_m = camera.to_array();
        let mut frame = Frame::from_scene(&s, SIZE);
        frame.frame_index = self.index;
        self.index += 1;
        self.renderer
            .render_frame(ctx, &frame, self.reuse, &mut self.timer);
        self.renderer.images(ctx)
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
    for _ in 0..15 {
        settled = flip_mean(&seq.frame(&ctx, &scene, start), &reference_start);
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

/// Mean luminance (Rec. 709) of an HDR image.
fn mean_luminance(image: &HdrImage) -> f64 {
    let sum: f64 = (image.pixels.iter())
        .map(|[r, g, b, _]| f64::from(0.2126 * r + 0.7152 * g + 0.0722 * b))
        .sum();
    sum / image.pixels.len() as f64
}

#[test]
fn a_still_history_settles_on_the_mean_of_its_own_march() {
    let ctx = GpuContext::for_tests();
    let scene = scene();
    let camera = Vec3::from_array(scene.camera.position_m);
    // One ray per pixel per frame: every pixel's history is a running mean with a weight of 0.05
    // a frame, whose updates are a small part of a half float's step on bright clouds. A bias of
    // the rounding builds up over about 1 / 0.05 frames: after 40, 87 % of it shows.
    let mut temporal = Sequence::new(&ctx, &scene, 1);
    let mut settled = 0.0;
    for _ in 0..40 {
        settled = mean_luminance(&temporal.rendered(&ctx, &scene, camera).hdr);
    }
    // The same renderer marches the full frames, its lighting carried as the history's was.
    temporal.reuse = Reuse::None;
    let frames = 8;
    let marched = (0..frames)
        .map(|_| mean_luminance(&temporal.rendered(&ctx, &scene, camera).hdr))
        .sum::<f64>()
        / f64::from(frames);
    let drift = settled / marched - 1.0;
    eprintln!(
        "still history against its march's mean: {:+.4} %",
        100.0 * drift
    );
    assert!(
        drift.abs() < 5.0e-4,
        "the history settles {:+.4} % off its own march's mean",
        100.0 * drift
    );
}

/// How strongly the difference of `image` from `reference` shows a `period` x `period` pattern:
/// the standard deviation, over the period's pixel classes (x mod period, y mod period), of the
/// class's mean high-pass difference in luma (the difference less its 3x3 mean). An update grid
/// that prints itself makes the error of some classes larger than that of others; noise and blur
/// do not favour any class.
fn grid_contrast(image: &LdrImage, reference: &LdrImage, period: usize) -> f64 {
    let (w, h) = (image.width as usize, image.height as usize);
    let (a, b) = (image.luma(), reference.luma());
    let diff = |x: usize, y: usize| f64::from(a[y * w + x] - b[y * w + x]);
    let mut sums = vec![(0.0f64, 0u32); period * period];
    for y in 1..h - 1 {
        for x in 1..w - 1 {
            let around: f64 = (0..9).map(|k| diff(x + k % 3 - 1, y + k / 3 - 1)).sum();
            let class = &mut sums[(y % period) * period + x % period];
            class.0 += diff(x, y) - around / 9.0;
            class.1 += 1;
        }
    }
    let means: Vec<f64> = sums.iter().map(|(s, n)| s / f64::from(*n)).collect();
    let mean = means.iter().sum::<f64>() / means.len() as f64;
    (means.iter().map(|m| (m - mean).powi(2)).sum::<f64>() / means.len() as f64).sqrt()
}

#[test]
fn neither_the_update_grid_nor_blurred_edges_show_while_the_camera_moves() {
    let ctx = GpuContext::for_tests();
    let scene = scene();
    let start = Vec3::from_array(scene.camera.position_m);
    // 60 frames per second at 300 m/s sideways: the history moves every frame.
    let step = Vec3::new(5.0, 0.0, 0.0);
    let mut temporal = Sequence::new(&ctx, &scene, 4);
    let mut full = Sequence::new(&ctx, &scene, 4);
    full.reuse = Reuse::None;
    let mut images = None;
    for k in 0..24 {
        let camera = start + step * k as f32;
        images = Some((
            temporal.frame(&ctx, &scene, camera),
            full.frame(&ctx, &scene, camera),
        ));
    }
    let (last, marched) = images.expect("frames");
    let mut at_end = scene.clone();
    at_end.camera.position_m = (start + step * 23.0).to_array();
    let reference = converged(&ctx, &scene, &Frame::from_scene(&at_end, SIZE));
    let shown = grid_contrast(&last, &reference, 4);
    let natural = grid_contrast(&marched, &reference, 4);
    eprintln!("4x4 pattern in the error: temporal {shown:.5}, full march {natural:.5}");
    let (temporal_flip, full_flip) = (
        flip_mean(&reference, &last),
        flip_mean(&reference, &marched),
    );
    eprintln!("FLIP against converged: temporal {temporal_flip:.4}, full march {full_flip:.4}");
    // The moving clouds' edges: between rays the estimate takes the samples on the history's side
    // of an edge (`upsample_cloud_guided`); blended across it, as wide as the grid's spacing, the
    // temporal march scored 1.29 times the full march's FLIP here (1.18 guided).
    assert!(
        temporal_flip < 1.24 * full_flip,
        "moving edges blur: temporal FLIP {temporal_flip} against the full march's {full_flip}"
    );
    assert!(
        shown < 1.5 * natural,
        "the 4x4 update grid shows: {shown} against {natural} in the full march's error"
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

#[test]
fn lighting_carried_across_frames_keeps_the_image_of_a_still() {
    use cloudscape::environment::light_volume::{CELL_SLICES, WARM_TURN_FRAMES};
    let ctx = GpuContext::for_tests();
    let scene = scene();
    let before = Frame::from_scene(&scene, SIZE);
    // A minute later the wind has carried the clouds 500 m.
    let later = Frame {
        time_s: before.time_s + 60.0,
        ..before.clone()
    };
    let mut timer = PassTimer::new(&ctx, PASS_COUNT);
    let mut still = SceneRenderer::new(&ctx, &scene, Path::new(".")).expect("field");
    still.render_frame(&ctx, &later, Reuse::None, &mut timer);
    let reference = still.images(&ctx).ldr;
    // Lit before, then carried over to the later frames: the light volume's cells updated a slice
    // a frame (every slice comes round), the solve warm-started, the shadow map rebuilt as it drifts.
    let mut carried = SceneRenderer::new(&ctx, &scene, Path::new(".")).expect("field");
    carried
        .clouds()
        .set_lighting_reuse(Some(LightingReuse::REAL_TIME));
    carried.render_frame(&ctx, &before, Reuse::None, &mut timer);
    // Each turn of frames solves one cascade and updates a slice of its cells: twice round them
    // all. The frames between march a ray per 4x4 pixels (the lighting is what they carry), the
    // last one every pixel.
    let between = Reuse::Temporal(TemporalSettings {
        divisor: 4,
        ..TemporalSettings::default()
    });
    for _ in 1..2 * CELL_SLICES * scene.lighting.volume_cascades * WARM_TURN_FRAMES {
        carried.render_frame(&ctx, &later, between, &mut timer);
    }
    carried.render_frame(&ctx, &later, Reuse::None, &mut timer);
    let error = flip_mean(&carried.images(&ctx).ldr, &reference);
    eprintln!("carried lighting against the still: FLIP {error:.4}");
    assert!(
        error < 0.02,
        "carried lighting drifts from the still's: {error}"
    );
}
