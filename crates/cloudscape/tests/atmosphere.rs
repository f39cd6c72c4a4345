//! The atmosphere and the clouds' shadows in whole renders: a night is dark but finite, and the
//! shared shadow map darkens the ground under the clouds for every technique.

use cloudscape::gpu::GpuContext;
use cloudscape::image::HdrImage;
use cloudscape::renderer::SceneRenderer;
use cloudscape::scene::{Scene, Technique};
use std::path::Path;

/// Renders scenes at 128 x 72 (HDR) with one renderer, which each new scene updates as a live
/// edit in the viewer does.
struct Renders<'a> {
    ctx: &'a GpuContext,
    renderer: Option<SceneRenderer>,
}

impl<'a> Renders<'a> {
    fn new(ctx: &'a GpuContext) -> Renders<'a> {
        Renders {
            ctx,
            renderer: None,
        }
    }

    /// `scene` at 128 x 72.
    fn render(&mut self, mut scene: Scene) -> HdrImage {
        scene.render.width = 128;
        scene.render.height = 72;
        let (ctx, here) = (self.ctx, Path::new("."));
        let renderer = match &mut self.renderer {
            Some(renderer) => {
                renderer.set_scene(ctx, &scene, here).expect("field builds");
                renderer
            }
            empty => empty.insert(SceneRenderer::new(ctx, &scene, here).expect("field builds")),
        };
        renderer.render(ctx, |_| {}).hdr
    }
}

fn luminance(p: &[f32; 4]) -> f32 {
    0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]
}

fn mean_luminance(image: &HdrImage) -> f32 {
    image.pixels.iter().map(luminance).sum::<f32>() / image.pixels.len() as f32
}

/// With the sun set the sky goes through twilight (the air still lit above the eye) to night
/// (nothing but the air's faint multiple scattering): every pixel stays finite and non-negative.
#[test]
fn twilight_and_night_are_dark_and_finite() {
    let ctx = GpuContext::for_tests();
    let mut renders = Renders::new(&ctx);
    let mut at = |elevation_deg| {
        let mut scene = Scene::default();
        scene.sun.elevation_deg = elevation_deg;
        renders.render(scene)
    };
    let (noon, twilight, night) = (at(30.0), at(-3.0), at(-25.0));
    for (name, image) in [("twilight", &twilight), ("night", &night)] {
        let bad = image
            .pixels
            .iter()
            .filter(|p| p.iter().any(|v| !v.is_finite() || *v < 0.0))
            .count();
        assert_eq!(bad, 0, "{name}: {bad} non-finite or negative pixels");
    }
    let (day, dusk, dark) = (
        mean_luminance(&noon),
        mean_luminance(&twilight),
        mean_luminance(&night),
    );
    assert!(
        dusk > 0.0 && dusk < 0.2 * day,
        "twilight {dusk} vs day {day}"
    );
    assert!(dark < 0.1 * dusk, "night {dark} vs twilight {dusk}");
}

/// Looking down from above the layer, the ground under the clouds' shadows is darker than the
/// same ground under a clear sky, for every technique: the shadow map is shared, read in
/// compositing. Pixels darker than three quarters of the clear view's are shadowed ground (clouds
/// are brighter than the ground; the haze of the 9 km of air between eye and ground fills in part
/// of each shadow). A broken layer shadows a fair share of the view but not all of it.
#[test]
fn cloud_shadows_fall_on_the_ground_for_every_technique() {
    let ctx = GpuContext::for_tests();
    let mut scene = Scene::default();
    scene.camera.position_m = [0.0, 9000.0, 0.0];
    scene.camera.pitch_deg = -60.0;
    scene.sun.elevation_deg = 50.0;
    scene.layers[0].coverage = 0.4;
    let mut clear = scene.clone();
    clear.layers.clear();
    let mut renders = Renders::new(&ctx);
    let clear_view = renders.render(clear);
    for technique in [
        Technique::Raymarch,
        Technique::Particles,
        Technique::Sprites,
    ] {
        let mut cloudy = scene.clone();
        cloudy.render.technique = technique;
        let image = renders.render(cloudy);
        let shadowed = image
            .pixels
            .iter()
            .zip(&clear_view.pixels)
            .filter(|(c, g)| luminance(c) < 0.75 * luminance(g))
            .count() as f32
            / image.pixels.len() as f32;
        println!("{technique:?}: {shadowed} of the view in shadow");
        assert!(
            (0.05..0.8).contains(&shadowed),
            "{technique:?}: {shadowed} of the view in shadow"
        );
    }
}
