//! No non-finite or negative pixel from the path tracer on any in-range scene: random scenes
//! (parameters drawn from their documented ranges by proptest, fixed seeds) at 48x27 and 2 samples
//! per pixel, every sky model, phase function and planet shape in turn (each pair in some case), and
//! no sample dropped as non-finite on the way.

#[path = "../../cloudscape/tests/random_scenes/mod.rs"]
mod random_scenes;

use cloudscape::scene::Scene;
use cloudscape_reference::{PathTracer, ProgressiveRender};
use glam::UVec2;
use std::path::Path;

/// Sky model, phase model and planet shape of each case: every pair of levels appears.
const CASES: [[&str; 3]; 6] = [
    ["atmosphere", "mie", "spherical"],
    ["atmosphere", "hg", "flat"],
    ["gradient", "hg", "spherical"],
    ["gradient", "dual_hg", "flat"],
    ["constant", "dual_hg", "spherical"],
    ["constant", "mie", "flat"],
];

const SIZE: UVec2 = UVec2::new(48, 27);
/// Majorant cells: few, so building the grid is cheap; tracking stays exact, only slower.
const MAJORANT_CELLS: usize = 1 << 12;

fn fixed(case: &[&str; 3]) -> Vec<String> {
    let [sky, phase, planet] = case;
    vec![
        "weather.resolution=32".into(),
        format!("sky.model=\"{sky}\""),
        format!("phase.model=\"{phase}\""),
        format!("planet.shape=\"{planet}\""),
    ]
}

/// Path-traces `scene` at 2 spp: dropped samples, or the first bad pixel.
fn trace(scene: &Scene) -> Result<(), String> {
    let tracer = PathTracer::for_scene(scene, Path::new("."), SIZE, MAJORANT_CELLS)
        .map_err(|e| e.to_string())?;
    let mut render = ProgressiveRender::new(&tracer, 7);
    render.run_pass(2, &|| false, &|_| {});
    let dropped = render.stats().non_finite;
    if dropped > 0 {
        return Err(format!("{dropped} non-finite samples"));
    }
    random_scenes::finite_non_negative(&render.image().pixels)
}

#[test]
fn random_in_range_scenes_trace_only_finite_non_negative_radiance() {
    let _noise = random_scenes::noise_holder();
    random_scenes::check_cases(&CASES, 101, fixed, trace);
}
