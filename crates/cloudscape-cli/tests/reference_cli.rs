//! End-to-end tests of `cloudscape reference` and `cloudscape compare` (CPU only): a tiny voxel
//! cloud is path traced, stopped early, and compared.

use cloudscape::field::VoxelGrid;
use cloudscape::image::HdrImage;
use glam::Vec3;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// A voxel cloud in front of the default camera, without layers (no noise to bake).
const SCENE: &str = r#"
layers = []
[camera]
look_at_m = [0.0, 2500.0, -6000.0]
[[volumes]]
path = "blob.vol"
"#;

/// A scratch directory holding `scene.toml` and `blob.vol`, removed when dropped.
struct Scratch(PathBuf);

impl Scratch {
    fn new(test: &str) -> Scratch {
        let dir =
            std::env::temp_dir().join(format!("cloudscape-ref-cli-{test}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("create scratch dir");
        let blob = VoxelGrid::from_fn([8, 8, 8], Vec3::ZERO, Vec3::ONE, |p| {
            (1.0 - 2.0 * (p - 0.5).length()).max(0.0)
        });
        blob.write_vol(&dir.join("blob.vol")).expect("write grid");
        std::fs::write(dir.join("scene.toml"), SCENE).expect("write scene");
        Scratch(dir)
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

fn cloudscape(dir: &Path, args: &[&str]) -> Output {
    let output = Command::new(env!("CARGO_BIN_EXE_cloudscape"))
        .current_dir(dir)
        .args(args)
        .output()
        .expect("start the cloudscape binary");
    assert!(
        output.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    output
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
    let s = Scratch::new("deterministic");
    for out in ["a.exr", "b.exr"] {
        let run = cloudscape(
            &s.0,
            &[&["reference"], &TINY[..], &["--spp", "2", "--out", out]].concat(),
        );
        assert!(String::from_utf8_lossy(&run.stderr).contains("samples/s"));
    }
    let a = HdrImage::read(&s.0.join("a.exr")).expect("read a");
    assert_eq!(a, HdrImage::read(&s.0.join("b.exr")).expect("read b"));
    assert_eq!((a.width, a.height), (16, 9));
    assert!(
        a.pixels
            .iter()
            .all(|p| p[..3].iter().all(|c| c.is_finite() && *c >= 0.0))
    );
    let run = cloudscape(
        &s.0,
        &["compare", "a.exr", "b.exr", "--json", "--diff", "d.png"],
    );
    let json = String::from_utf8_lossy(&run.stdout);
    assert!(json.contains("\"flip_mean\": 0.0"), "{json}");
    assert!(json.contains("\"luminance_ratio\": 1.0"), "{json}");
    assert!(s.0.join("d.png").exists());
}

#[test]
fn a_spent_time_budget_still_writes_the_image() {
    let s = Scratch::new("budget");
    let args = [
        &["reference"],
        &TINY[..],
        &["--spp", "1000", "--time-budget", "0", "--out", "x.png"],
    ]
    .concat();
    let run = cloudscape(&s.0, &args);
    assert!(String::from_utf8_lossy(&run.stderr).contains("stopped early"));
    assert!(s.0.join("x.png").exists());
}
