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

/// Under an unbroken deck, looking a few degrees down at a black ground from 200 m: every pixel
/// is the air's own light, which the deck shadows from the sun.
const UNDER_A_DECK: &str = r#"
[planet]
shape = "flat"
[camera]
position_m = [0.0, 200.0, 0.0]
pitch_deg = -4.0
fov_y_deg = 6.0
far_m = 20000.0
[sun]
elevation_deg = 40.0
[ground]
albedo = [0.0, 0.0, 0.0]
[[layers]]
bottom_m = 1200.0
thickness_m = 600.0
coverage = 1.0
types = { stratus = 1.0 }
"#;

/// The two renderers' air agrees under a cloud deck: the path tracer's in-scattering sees the
/// clouds' transmittance toward the sun as the GPU's light shafts do (through the cloud shadow
/// map). Lit as if the deck were not there, the path tracer's air is several times brighter.
#[test]
fn the_air_under_a_deck_is_shadowed_in_both_renderers() {
    let s = Scratch::new("air-under-deck");
    std::fs::write(s.join("deck.toml"), UNDER_A_DECK).expect("write scene");
    let size = ["--width", "32", "--height", "18"];
    let gpu = cloudscape(
        s.path(),
        &[&["render", "deck.toml", "--out", "gpu.exr"], &size[..]].concat(),
        true,
    );
    assert!(gpu.success, "{}", gpu.stderr);
    let traced = [&["reference", "deck.toml", "--spp", "2"], &size[..]].concat();
    succeed(s.path(), &[&traced[..], &["--out", "deck.exr"]].concat());
    let clear = [
        &traced[..],
        &["--set", "layers.0.coverage=0", "--out", "clear.exr"],
    ]
    .concat();
    succeed(s.path(), &clear);
    let mean = |name: &str| {
        let image = HdrImage::read(&s.join(name)).expect("read image");
        let sum: f64 = image.pixels.iter().map(|p| f64::from(p[1])).sum();
        sum / image.pixels.len() as f64
    };
    let (gpu, deck, clear) = (mean("gpu.exr"), mean("deck.exr"), mean("clear.exr"));
    assert!(deck > 0.0, "the air under the deck still scatters skylight");
    let ratio = gpu / deck;
    assert!(
        (0.8..1.25).contains(&ratio),
        "GPU {gpu} / path tracer {deck} = {ratio}"
    );
    assert!(
        clear > 1.6 * deck,
        "air without the deck {clear}, under it {deck}"
    );
}
