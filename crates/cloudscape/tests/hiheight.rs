//! Empty-space skipping with the hi-height pyramid changes the work, not the image.

use cloudscape::gpu::GpuContext;
use cloudscape::image::HdrImage;
use cloudscape::renderer::SceneRenderer;
use cloudscape::scene::SceneDocument;
use std::path::Path;

/// Renders the layer from `view` with skipping on, then off (a live edit of the same renderer);
/// returns each image with its view-ray density samples per pixel.
fn render(view: &[&str]) -> [(HdrImage, f64); 2] {
    let ctx = GpuContext::for_tests();
    let mut renderer = None;
    [true, false].map(|skipping| {
        let mut overrides: Vec<String> = view.iter().map(|s| s.to_string()).collect();
        overrides.extend(
            [
                "render.width=128",
                "render.height=72",
                "render.quality=medium",
            ]
            .map(String::from),
        );
        overrides.push(format!("render.empty_space_skipping={skipping}"));
        let doc = SceneDocument::parse("", "hi-height test", Path::new("."), &overrides)
            .expect("valid scene");
        let renderer: &mut SceneRenderer = match &mut renderer {
            Some(renderer) => renderer,
            empty => {
                empty.insert(SceneRenderer::new(&ctx, &doc.scene, Path::new(".")).expect("field"))
            }
        };
        renderer
            .set_scene(&ctx, &doc.scene, Path::new("."))
            .expect("field");
        let image = renderer.render(&ctx, |_| {}).hdr;
        let stats = renderer.stats(&ctx).expect("the frame was counted");
        (image, stats.density_samples_per_pixel)
    })
}

fn largest_difference(a: &HdrImage, b: &HdrImage) -> f32 {
    a.pixels
        .iter()
        .zip(&b.pixels)
        .flat_map(|(p, q)| (0..3).map(move |c| (p[c] - q[c]).abs() / (q[c].abs() + 0.05)))
        .fold(0.0, f32::max)
}

#[test]
fn skipping_keeps_the_image_and_saves_samples_above_the_layer() {
    let above = ["camera.position_m=[0,6500,0]", "camera.pitch_deg=-35"];
    let [(with, samples_with), (without, samples_without)] = render(&above);
    eprintln!(
        "above the layer: {samples_without:.1} -> {samples_with:.1} density samples per pixel"
    );
    assert_eq!(
        largest_difference(&with, &without),
        0.0,
        "the same strata are sampled: the image must not change"
    );
    assert!(
        samples_with * 3.0 <= samples_without,
        "{samples_without:.1} -> {samples_with:.1} samples per pixel"
    );
}

#[test]
fn skipping_keeps_the_image_from_the_ground() {
    let [(with, samples_with), (without, samples_without)] = render(&[]);
    eprintln!(
        "from the ground: {samples_without:.1} -> {samples_with:.1} density samples per pixel"
    );
    assert_eq!(largest_difference(&with, &without), 0.0);
    assert!(samples_with <= samples_without);
}

/// Long grazing rays times several samples per pixel once overran llvmpipe's cap on the loop
/// iterations of one invocation, and only with skipping on: 8-pixel rows came out wrong.
#[test]
fn skipping_keeps_the_image_on_grazing_rays_with_several_samples() {
    let grazing = [
        "camera.pitch_deg=22",
        "render.samples_per_pixel=8",
        "render.primary_steps=64",
    ];
    let [(with, _), (without, _)] = render(&grazing);
    assert_eq!(largest_difference(&with, &without), 0.0);
}
