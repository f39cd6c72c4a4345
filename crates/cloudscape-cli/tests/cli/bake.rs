//! `bake`: both tables written where asked, with their timings, sizes and checks.

use crate::support::{Scratch, cloudscape};
use cloudscape::particles::ParticleTableSpec;
use cloudscape::particles::store::{TableStore, read_optical_depth};
use cloudscape::particles::table_file::{TableFile, TableKind};
use cloudscape::scene::{Scene, TableResolution};

#[test]
fn bake_writes_both_tables_and_reports_their_cost_and_accuracy() {
    let scratch = Scratch::new("bake");
    let run = cloudscape(
        scratch.path(),
        &[
            "bake",
            "--set",
            "particles.table_resolution=low",
            "--out",
            "tables",
        ],
        true,
    );
    assert!(run.success, "{}", run.stderr);
    for piece in [
        "optical depth 16x32x16x32 (262144 entries, 512 KiB): GPU ",
        "look-up vs direct integration, 10000 chords",
        "scattering 32x16x16 x 2 tables",
        "% of the light in",
    ] {
        assert!(
            run.stdout.contains(piece),
            "{piece:?} missing from:\n{}",
            run.stdout
        );
    }
    let mut scene = Scene::default();
    scene.particles.table_resolution = TableResolution::Low;
    let spec = ParticleTableSpec::from_scene(&scene);
    let store = TableStore::new(scratch.join("tables"));
    let table = read_optical_depth(&store.optical_depth_path(spec.optical_depth_key()), &spec)
        .expect("the optical-depth table is written under its key");
    assert_eq!(table.layout, spec.optical_depth);
    TableFile::read(
        &store.scattering_path(spec.scattering_key()),
        TableKind::Scattering,
        spec.scattering_key(),
    )
    .expect("the scattering tables are written under their key");
}
