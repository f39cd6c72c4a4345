//! End-to-end tests of `cloudscape reference` and `cloudscape compare` (CPU only): a tiny voxel
//! cloud is path traced, stopped early, and compared.

use crate::support::{Run, Scratch, cloudscape};
use cloudscape::field::VoxelGrid;
use cloudscape::image::HdrImage;
use glam::Vec3;
use std::path::Path;

/// A voxel cloud in front of the default camera, without layers (no noise to bake).
const SCENE: &str = r#"
layers = []
[camera]
look_at_m = [0.0, 2500.0, -6000.0]
[[volumes]]
path = "blob.vol"
"#;

/// A scratch directory holding `scene.toml` and `blob.vol`.
fn voxel_scratch(test: &str) -> Scratch {
    let scratch = Scratch::new(test);
    let blob = VoxelGrid::from_fn([8, 8, 8], Vec3::ZERO, Vec3::ONE, |p| {
        (1.0 - 2.0 * (p - 0.5).length()).max(0.0)
    });
    blob.write_vol(&scratch.join("blob.vol"))
        .expect("write grid");
    std::fs::write(scratch.join("scene.toml"), SCENE).expect("write scene");
    scratch
}

/// Runs `cloudscape args...` in `dir` and asserts that it succeeds.
fn succeed(dir: &Path, args: &[&str]) -> Run {
    let run = cloudscape(dir, args, false);
    assert!(run.success, "{args:?}: {}", run.stderr);
    run
}

const TINY: [&str; 7] = [
    "scene.toml",
    "--width",
    "16",
    "--height",
    "9",
    "--seed",
    "3",
];

#[test]
fn reference_is_deterministic_and_compares_to_itself_as_zero() {
    let s = voxel_scratch("deterministic");
    for out in ["a.exr", "b.exr"] {
        let run = succeed(
            s.path(),
            &[&["reference"], &TINY[..], &["--spp", "2", "--out", out]].concat(),
        );
        assert!(run.stderr.contains("samples/s"));
    }
    let a = HdrImage::read(&s.join("a.exr")).expect("read a");
    assert_eq!(a, HdrImage::read(&s.join("b.exr")).expect("read b"));
    assert_eq!((a.width, a.height), (16, 9));
    assert!(
        a.pixels
            .iter()
            .all(|p| p[..3].iter().all(|c| c.is_finite() && *c >= 0.0))
    );
    let run = succeed(
        s.path(),
        &["compare", "a.exr", "b.exr", "--json", "--diff", "d.png"],
    );
    let json = run.stdout.clone();
    assert!(json.contains("\"flip_mean\": 0.0"), "{json}");
    assert!(json.contains("\"luminance_ratio\": 1.0"), "{json}");
    assert!(s.join("d.png").exists());
}

#[test]
fn a_spent_time_budget_still_writes_the_image() {
    let s = voxel_scratch("budget");
    let args = [
        &["reference"],
        &TINY[..],
        &["--spp", "1000", "--time-budget", "0", "--out", "x.png"],
    ]
    .concat();
    let run = succeed(s.path(), &args);
    assert!(run.stderr.contains("stopped early"));
    assert!(s.join("x.png").exists());
}
