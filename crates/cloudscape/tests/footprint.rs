//! Several samples per pixel integrate the pixel's footprint, as the path tracer does: an opaque
//! cube whose edges are far sharper than a pixel shows fractional coverage along its outline with
//! several samples, and almost none with one sample through the pixel's centre.

use cloudscape::field::voxel::VoxelGrid;
use cloudscape::gpu::{GpuContext, read_texture_rgba16f};
use cloudscape::renderer::SceneRenderer;
use cloudscape::scene::SceneDocument;
use glam::Vec3;

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
