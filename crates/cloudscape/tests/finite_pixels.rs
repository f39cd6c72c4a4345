//! No non-finite or negative pixel from any in-range scene: a property test that renders random
//! scenes (every parameter drawn from its documented range) at 48x27 and checks the HDR output.
//! Every technique, sky model, phase function and planet shape is drawn, each pair of them in at
//! least one case (an orthogonal array L9(3^4)); the other parameters come from proptest with a
//! fixed seed, and a failure shrinks to a minimal scene, which is then kept below as a plain test.

mod random_scenes;

use cloudscape::gpu::GpuContext;
use cloudscape::renderer::SceneRenderer;
use cloudscape::scene::Scene;
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

/// What every case sets: its factors, a tiny image, cheap steps, a small weather map and light
/// volume.
fn fixed(case: &[&str; 4]) -> Vec<String> {
    let [technique, sky, phase, planet] = case;
    vec![
        "render.width=48".into(),
        "render.height=27".into(),
        "render.quality=low".into(),
        "weather.resolution=64".into(),
        "shadow.resolution=64".into(),
        "particles.table_resolution=\"low\"".into(),
        // The light volume small too: its size is not drawn, and the default's cold solve would
        // be most of each case's time on a software GPU.
        "lighting.volume_cells_horizontal=16".into(),
        "lighting.volume_cells_vertical=8".into(),
        format!("render.technique=\"{technique}\""),
        format!("sky.model=\"{sky}\""),
        format!("phase.model=\"{phase}\""),
        format!("planet.shape=\"{planet}\""),
    ]
}

/// Renders `scene` with `renderer` (a live edit rebuilds what changed); its HDR pixels.
fn render(ctx: &GpuContext, renderer: &mut SceneRenderer, scene: &Scene) -> Vec<[f32; 4]> {
    renderer
        .set_scene(ctx, scene, Path::new("."))
        .expect("the field builds");
    renderer.render(ctx, |_| {}).hdr.pixels
}

#[test]
fn random_in_range_scenes_render_only_finite_non_negative_pixels() {
    let ctx = GpuContext::for_tests();
    let _noise = random_scenes::noise_holder();
    let first = random_scenes::scene(&fixed(&CASES[0]));
    let renderer = SceneRenderer::new(&ctx, &first, Path::new(".")).expect("the field builds");
    let renderer = RefCell::new(renderer);
    random_scenes::check_cases(&CASES, 1, fixed, |scene| {
        let pixels = render(&ctx, &mut renderer.borrow_mut(), scene);
        random_scenes::finite_non_negative(&pixels)
    });
}
