//! The scene's `coverage` is the fraction of the sky a cumulus layer covers.

use cloudscape::field::CloudField;
use cloudscape::scene::Scene;
use glam::Vec3;

/// The default cumulus field with the scene coverage `coverage`.
fn field(coverage: f32) -> CloudField {
    let mut scene = Scene::default();
    scene.layers[0].coverage = coverage;
    CloudField::new(&scene, std::path::Path::new(".")).expect("default field")
}

/// Fraction of `n x n` columns, spaced `spacing_m` apart, whose optical depth through the first
/// layer exceeds 1.
fn cloudy_fraction(field: &CloudField, n: u32, spacing_m: f32) -> f32 {
    let layer = &field.layers[0];
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
    assert_eq!(cloudy_fraction(&field(0.0), 8, 1500.0), 0.0);
    for coverage in [0.25, 0.6] {
        let measured = cloudy_fraction(&field(coverage), 14, 1100.0);
        assert!(
            (measured - coverage).abs() < 0.15,
            "coverage {coverage}: {measured} of the sky is cloudy"
        );
    }
    assert!(cloudy_fraction(&field(1.0), 8, 1500.0) > 0.97);
}

/// Prints the cloudy fraction against the raw coverage threshold: the measurement behind
/// `COVERAGE_CALIBRATION` in field/layer.rs (not a check).
#[test]
#[ignore]
fn print_calibration() {
    let mut f = field(0.5);
    f.bake_noise();
    for threshold in [
        0.05, 0.1, 0.15, 0.2, 0.25, 0.3, 0.35, 0.4, 0.45, 0.5, 0.6, 0.7,
    ] {
        f.layers[0].coverage = threshold;
        println!(
            "threshold {threshold}: cloudy {:.2}",
            cloudy_fraction(&f, 30, 537.0)
        );
    }
}
