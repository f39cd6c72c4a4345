//! Several samples per pixel integrate the pixel's footprint, as the path tracer does: an opaque
//! cube whose edges are far sharper than a pixel shows fractional coverage along its outline with
//! several samples, and almost none with one sample through the pixel's centre.

use cloudscape::field::voxel::VoxelGrid;
use cloudscape::frame::Frame;
use cloudscape::gpu::{GpuContext, PassTimer, read_texture_rgba16f};
use cloudscape::image::{HdrImage, flip};
use cloudscape::renderer::{PASS_COUNT, Reuse, SceneRenderer};
use cloudscape::scene::SceneDocument;
use glam::{UVec2, Vec3};

const SCENE: &str = r#"
layers = []

[camera]
position_m = [0.0, 2000.0, 0.0]
look_at_m = [7.0, 2003.0, -1000.0]
fov_y_deg = 12.0

[render]
width = 96
height = 54

[[volumes]]
path = "cube.vol"
center_m = [0.0, 2000.0, -1000.0]
size_m = [90.0, 60.0, 90.0]
extinction_per_m = 2.0
"#;

/// Pixels of the cloud output whose transmittance is neither clear nor opaque, with
/// `samples_per_pixel` samples.
fn partly_covered(ctx: &GpuContext, dir: &std::path::Path, samples_per_pixel: u32) -> usize {
    let overrides = [format!("render.samples_per_pixel={samples_per_pixel}")];
    let doc = SceneDocument::parse(SCENE, "footprint", dir, &overrides).expect("valid scene");
    let mut renderer = SceneRenderer::new(ctx, &doc.scene, dir).expect("the cube loads");
    renderer.render(ctx, |_| {});
    let output = renderer.clouds().images().clouds.radiance_texture().clone();
    let pixels = read_texture_rgba16f(ctx, &output);
    let opaque = pixels.iter().filter(|p| p[3] < 0.02).count();
    assert!(opaque > 200, "the cube covers a block of pixels: {opaque}");
    pixels.iter().filter(|p| p[3] > 0.1 && p[3] < 0.9).count()
}

#[test]
fn samples_spread_over_the_pixel_find_the_cube_s_edges() {
    let dir = std::env::temp_dir().join(format!("cloudscape-footprint-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    VoxelGrid::from_fn([64, 64, 64], Vec3::ZERO, Vec3::ONE, |_| 1.0)
        .write_vol(&dir.join("cube.vol"))
        .expect("write the cube");
    let ctx = GpuContext::for_tests();
    let centre_only = partly_covered(&ctx, &dir, 1);
    let footprint = partly_covered(&ctx, &dir, 16);
    eprintln!("partly covered pixels: {centre_only} with 1 sample, {footprint} with 16");
    assert!(
        footprint >= 40 && footprint >= 4 * centre_only.max(1),
        "16 samples over the pixel see the outline: {footprint} against {centre_only}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// The rasterising techniques integrate the footprint by drawing the frame once per sample, each
/// shifted to its own point of the pixel: with 8 samples the particles' picture changes along the
/// clouds' outlines (it would not if the frames were not shifted) while its mean brightness stays.
#[test]
fn particles_average_frames_shifted_over_the_pixel() {
    let ctx = GpuContext::for_tests();
    let render = |samples: u32| {
        let overrides = [
            "render.technique=particles".to_string(),
            "render.width=96".to_string(),
            "render.height=54".to_string(),
            format!("render.samples_per_pixel={samples}"),
        ];
        let doc = SceneDocument::parse("", "footprint", std::path::Path::new("."), &overrides)
            .expect("valid scene");
        let mut renderer = SceneRenderer::new(&ctx, &doc.scene, std::path::Path::new("."))
            .expect("the default field");
        renderer.render(&ctx, |_| {}).hdr
    };
    let (one, eight) = (render(1), render(8));
    let changed = one
        .pixels
        .iter()
        .zip(&eight.pixels)
        .filter(|(a, b)| (a[1] - b[1]).abs() > 0.02 * a[1].abs().max(1e-3))
        .count();
    let ratio = eight.mean_luminance() / one.mean_luminance();
    eprintln!("{changed} pixels changed, mean luminance ratio {ratio}");
    assert!(changed >= 50, "only {changed} pixels changed");
    assert!(
        (0.97..1.03).contains(&ratio),
        "mean luminance ratio {ratio}"
    );
}

/// A rasterising technique's samples share the first sample's lighting (shadow map, light volume;
/// `CloudRenderer::begin_shifted_frame`) and redo only the aerial perspective laid over the view:
/// the still is the mean of its shifted frames each lit afresh. The sprites are deterministic, so
/// the two agree to the last bit but for the mean's rounding; an aerial perspective kept from
/// the first shift put its light shafts a fraction of a pixel off (FLIP 0.0039 at 256x144).
#[test]
fn shifted_samples_share_the_lighting_and_follow_the_view() {
    let ctx = GpuContext::for_tests();
    let samples = 2;
    let overrides = [
        "render.technique=sprites".to_string(),
        "render.width=64".to_string(),
        "render.height=36".to_string(),
        format!("render.samples_per_pixel={samples}"),
        // A small light volume: what is tested is which frame makes it, not its size.
        "lighting.volume_cells_horizontal=16".to_string(),
        "lighting.volume_cells_vertical=8".to_string(),
    ];
    let here = std::path::Path::new(".");
    let doc = SceneDocument::parse("", "footprint", here, &overrides).expect("valid scene");
    let mut renderer = SceneRenderer::new(&ctx, &doc.scene, here).expect("the default field");
    let still = renderer.render(&ctx, |_| {}).hdr;
    let frame = Frame::from_scene(&doc.scene, UVec2::new(64, 36));
    let mut timer = PassTimer::new(&ctx, PASS_COUNT);
    let mut mean = HdrImage::new(64, 36);
    for index in 0..samples {
        // A whole frame begun afresh: without lighting reuse it makes its own lighting.
        let sample = frame.footprint_sample(index, samples);
        renderer.render_frame(&ctx, &sample, Reuse::None, &mut timer);
        mean.add_scaled(&renderer.images(&ctx).hdr, 1.0 / samples as f32);
    }
    let ldr =
        |image: &HdrImage| image.to_ldr(doc.scene.render.exposure_ev, doc.scene.render.tonemap);
    let (stats, _) = flip(&ldr(&mean), &ldr(&still)).expect("same size");
    eprintln!(
        "FLIP of the still against its samples lit afresh: {}",
        stats.mean
    );
    assert!(stats.mean < 5.0e-4, "FLIP {}", stats.mean);
}

/// A shifted frame keeps the eye of the frame before: one that moves it is refused.
#[test]
#[should_panic(expected = "a shifted frame keeps the eye")]
fn a_shifted_frame_that_moves_the_eye_is_refused() {
    let ctx = GpuContext::for_tests();
    let overrides = [
        "render.width=32".to_string(),
        "render.height=18".to_string(),
    ];
    let here = std::path::Path::new(".");
    let doc = SceneDocument::parse("", "footprint", here, &overrides).expect("valid scene");
    let mut renderer = SceneRenderer::new(&ctx, &doc.scene, here).expect("the default field");
    let frame = Frame::from_scene(&doc.scene, UVec2::new(32, 18));
    let clouds = renderer.clouds();
    clouds.begin_frame(&ctx, &frame, Reuse::None);
    let moved = Frame {
        camera_position_m: frame.camera_position_m + Vec3::X,
        ..frame.clone()
    };
    clouds.begin_shifted_frame(&ctx, &moved);
}
