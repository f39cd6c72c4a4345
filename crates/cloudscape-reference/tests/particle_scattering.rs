//! The particle technique's shipped scattering tables against the transport solved in full on
//! the same (spherically symmetric) particle under the same sun, by light tracing through the
//! path tracer's medium (`cloudscape_reference::light_tracer`): single scattering alone, and
//! everything, from the front, the side and the back.

use cloudscape::particles::ParticleTableSpec;
use cloudscape::particles::preview::DiscView;
use cloudscape::particles::scattering::ScatteringTables;
use cloudscape::particles::store::{SHIPPED_SCATTERING, bake_scattering, scattering_from_file};
use cloudscape::particles::table_file::{TableFile, TableKind};
use cloudscape::scene::{PhaseModel, Scene, TableResolution};
use cloudscape_reference::PathTracer;
use cloudscape_reference::light_tracer::{OrthographicView, light_trace};
use glam::{Quat, Vec3};

/// Angles between the view direction and the direction the light travels, degrees: front-lit
/// (the sun behind the eye), side-lit, back-lit, and the silver lining with the sun 10 degrees
/// from the particle.
const VIEW_ANGLES_DEG: [(&str, f32); 6] = [
    ("front-lit", 15.0),
    ("front-side-lit", 60.0),
    ("side-lit", 90.0),
    ("back-side-lit", 125.0),
    ("back-lit", 155.0),
    ("silver lining", 170.0),
];
/// Pixels per side of each view of the particle's disc.
const PIXELS: u32 = 10;
/// Table look-ups per pixel side when averaging the tables over a pixel.
const SUBSAMPLES: u32 = 6;
/// Photons traced (shared by all views).
const PHOTONS: u64 = 400_000;

/// Relative RMS difference of `estimate` from `expected` over the pixels whose centre is within
/// 0.95 of the particle's radius.
fn relative_rms(expected: &[f64], estimate: &[f64]) -> f64 {
    let inside = |k: usize| {
        let (i, j) = ((k as u32 % PIXELS) as f32, (k as u32 / PIXELS) as f32);
        let a = (i + 0.5) / PIXELS as f32 * 2.0 - 1.0;
        let b = (j + 0.5) / PIXELS as f32 * 2.0 - 1.0;
        a * a + b * b < 0.95 * 0.95
    };
    let (mut num, mut den) = (0.0, 0.0);
    for k in (0..expected.len()).filter(|k| inside(*k)) {
        num += (expected[k] - estimate[k]).powi(2);
        den += expected[k].powi(2);
    }
    (num / den).sqrt()
}

/// Light traces `spec`'s symmetric particle in the six views and compares `tables` with it; the
/// worst relative RMS errors of single scattering and of everything.
fn compare(spec: &ParticleTableSpec, tables: &ScatteringTables, photons: u64) -> (f64, f64) {
    let light = Vec3::new(0.2, -0.9, 0.3).normalize();
    let tracer = PathTracer::for_particle(spec, true, light);
    let axis = light.any_orthonormal_vector();
    let views: Vec<OrthographicView> = VIEW_ANGLES_DEG
        .iter()
        .map(|(_, angle)| OrthographicView {
            disc: DiscView {
                dir: Quat::from_axis_angle(axis, angle.to_radians()) * light,
                pixels: PIXELS,
            },
            centre_m: Vec3::ZERO,
            half_extent_m: spec.radius_m,
        })
        .collect();
    let traced = light_trace(&tracer, Vec3::ZERO, spec.radius_m, &views, photons, 7);
    let mut worst = (0.0f64, 0.0f64);
    for (((name, angle), view), image) in VIEW_ANGLES_DEG.iter().zip(&views).zip(&traced) {
        let (single, total) = view.disc.scattering(tables, &spec.phase, light, SUBSAMPLES);
        let wide = |v: Vec<f32>| v.into_iter().map(f64::from).collect::<Vec<f64>>();
        let (single, total) = (wide(single), wide(total));
        let e_single = relative_rms(&image.single, &single);
        let e_total = relative_rms(&image.total, &total);
        let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
        eprintln!(
            "{name:>15} ({angle:>5.1} deg): single {:.2} %, total {:.2} % (mean traced {:.5} / {:.5}, tables {:.5} / {:.5})",
            100.0 * e_single,
            100.0 * e_total,
            mean(&image.single),
            mean(&image.total),
            mean(&single),
            mean(&total)
        );
        worst = (worst.0.max(e_single), worst.1.max(e_total));
    }
    worst
}

#[test]
fn shipped_tables_match_single_scattering_from_front_side_and_back() {
    let spec = ParticleTableSpec::from_scene(&Scene::default());
    let file = TableFile::decode(
        SHIPPED_SCATTERING,
        TableKind::Scattering,
        spec.scattering_key(),
    )
    .expect("the shipped tables are the default scene's: rebake them with `cloudscape bake`");
    let (single, _) = compare(&spec, &scattering_from_file(&file), PHOTONS);
    assert!(
        single < 0.05,
        "single scattering: relative RMS error {single}"
    );
}

#[test]
fn baked_tables_match_the_full_transport_from_front_side_and_back() {
    let mut scene = Scene::default();
    scene.phase.model = PhaseModel::Hg;
    scene.particles.table_resolution = TableResolution::Standard;
    let spec = ParticleTableSpec::from_scene(&scene);
    let (tables, _) = bake_scattering(&spec, &mut |_, _| {});
    let (single, total) = compare(&spec, &tables, 4 * PHOTONS);
    assert!(
        single < 0.05,
        "single scattering: relative RMS error {single}"
    );
    assert!(total < 0.10, "total: relative RMS error {total}");
}
