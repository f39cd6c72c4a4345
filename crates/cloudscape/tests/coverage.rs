//! The scene's `coverage` is the fraction of the sky a cumulus layer covers.

use cloudscape::field::CloudField;
use cloudscape::scene::Scene;
use glam::Vec3;

/// Fraction of `n x n` columns, spaced `spacing_m` apart, whose optical depth through the layer
/// exceeds 1.
fn cloudy_fraction(coverage: f32, n: u32, spacing_m: f32) -> f32 {
    let mut scene = Scene::default();
    scene.layers[0].coverage = coverage;
    let field = CloudField::new(&scene, std::path::Path::new(".")).expect("default field");
    let layer = &scene.layers[0];
    let steps = 40;
    let dz = layer.thickness_m / steps as f32;
    let cloudy = (0..n * n)
        .filter(|i| {
            let (x, z) = ((i % n) as f32 * spacing_m, (i / n) as f32 * spacing_m);
            let tau: f32 = (0..steps)
                .map(|k| {
                    field.extinction_per_m(
                        Vec3::new(x, layer.bottom_m + (k as f32 + 0.5) * dz, z),
                        0.0,
                    ) * dz
                })
                .sum();
            tau > 1.0
        })
        .count();
    cloudy as f32 / (n * n) as f32
}

#[test]
fn coverage_is_the_cloudy_fraction_of_the_sky() {
    assert_eq!(cloudy_fraction(0.0, 8, 1500.0), 0.0);
    for coverage in [0.25, 0.6] {
        let measured = cloudy_fraction(coverage, 14, 1100.0);
        assert!(
            (measured - coverage).abs() < 0.15,
            "coverage {coverage}: {measured} of the sky is cloudy"
        );
    }
    assert!(cloudy_fraction(1.0, 8, 1500.0) > 0.97);
}

/// Prints the calibration curve behind `COVERAGE_CALIBRATION` (a measurement, not a check).
#[test]
#[ignore]
fn print_calibration() {
    for c in [0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9] {
        println!("coverage {c}: cloudy {:.2}", cloudy_fraction(c, 30, 537.0));
    }
}
