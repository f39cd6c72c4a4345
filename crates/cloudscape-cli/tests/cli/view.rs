//! `view` in a real window on a virtual X server (Xvfb), on the test adapter: it renders its
//! frames, writes its screenshot and exits; the screenshot matches a golden by FLIP, a scripted
//! knob change changes it, and a saved scene renders exactly as it was viewed.
//!
//! The window is 320x180 at render scale 1/2 (160x90 rendered) with the panels hidden, low quality,
//! one ray per 2x2 pixels per frame (or none, for the saved scene).

use std::path::Path;

use crate::golden;
use crate::support::{Run, Scratch, command, run};
use crate::xvfb::Xvfb;
use cloudscape::image::{HdrImage, LdrImage, flip};

/// Frames of a run with temporal reuse: enough for the history (a 2x2 grid) to fill in.
const FRAMES: &str = "24";

/// `cloudscape view` with the test window and `args` for `frames` frames, in `dir`, on its own X
/// server; None when the machine has no X server to give it (see [`Xvfb::start`]).
fn view(dir: &Path, frames: &str, args: &[&str]) -> Option<Run> {
    let xvfb = Xvfb::start()?;
    let mut all = vec![
        "view",
        "--width",
        "320",
        "--height",
        "180",
        "--render-scale",
        "0.5",
        "--hide-panels",
        "--set",
        "render.quality=low",
        "--frames",
        frames,
    ];
    all.extend(args);
    let mut command = command(dir, &all, true);
    command
        .env("DISPLAY", &xvfb.display)
        .env_remove("WAYLAND_DISPLAY");
    let run = run(command);
    assert!(run.success, "view failed:\n{}", run.stderr);
    Some(run)
}

/// Writes `text` as `name` in the scratch directory.
fn write(scratch: &Scratch, name: &str, text: &str) {
    std::fs::write(scratch.join(name), text).expect("write a test file");
}

#[test]
fn view_renders_its_frames_in_a_window_and_matches_its_golden() {
    let scratch = Scratch::new("view-golden");
    let args = ["--temporal", "2", "--screenshot", "shot.png"];
    let Some(run) = view(scratch.path(), FRAMES, &args) else {
        return;
    };
    assert!(run.stderr.contains("adapter: "), "{}", run.stderr);
    let shot = LdrImage::read_png(&scratch.join("shot.png")).expect("the screenshot");
    assert_eq!((shot.width, shot.height), (160, 90));
    let hdr = HdrImage::read(&scratch.join("shot.exr")).expect("the EXR screenshot");
    assert_eq!((hdr.width, hdr.height), (160, 90));
    assert!(hdr.mean_luminance() > 0.0, "the EXR is black");
    golden::check("view_default", &shot);
}

#[test]
fn a_scripted_coverage_change_changes_the_image() {
    let scratch = Scratch::new("view-coverage");
    let script = "[[at]]\nframe = 2\nset = [\"layers.0.coverage=0.95\"]\n";
    write(&scratch, "script.toml", script);
    let args = [
        "--temporal",
        "2",
        "--script",
        "script.toml",
        "--screenshot",
        "shot.png",
    ];
    if view(scratch.path(), FRAMES, &args).is_none() {
        return;
    }
    let changed = LdrImage::read_png(&scratch.join("shot.png")).expect("the screenshot");
    let golden_path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/golden/view_default.png");
    let unchanged = LdrImage::read_png(&golden_path).expect("the golden of the unchanged scene");
    let (stats, _) = flip(&unchanged, &changed).expect("same size");
    eprintln!("coverage 0.45 -> 0.95: FLIP mean {:.4}", stats.mean);
    assert!(
        stats.mean > 0.1,
        "coverage 0.45 -> 0.95 changed the image by FLIP {:.4} only",
        stats.mean
    );
}

#[test]
fn a_saved_scene_renders_exactly_as_it_was_viewed() {
    let scratch = Scratch::new("view-save");
    let script = "[[at]]\nframe = 0\nset = [\"layers.0.coverage=0.6\", \"sun.elevation_deg=12\"]\n\
                  camera = { position_m = [300, 800, 200], yaw_deg = 150, pitch_deg = 12 }\n\
                  hold = [\"w\", \"e\"]\n\
                  [[at]]\nframe = 5\nset = [\"render.exposure_ev=0.5\"]\nhold = []\n\
                  [[at]]\nframe = 9\nscreenshot = \"viewed.png\"\nsave = \"saved.toml\"\n";
    write(&scratch, "script.toml", script);
    let args = ["--script", "script.toml", "--temporal", "off"];
    // Its script ends at frame 9; without temporal reuse each frame solves the lighting anew.
    if view(scratch.path(), "10", &args).is_none() {
        return;
    }
    let render = run(command(
        scratch.path(),
        &["render", "saved.toml", "--out", "rendered.png"],
        true,
    ));
    assert!(render.success, "{}", render.stderr);
    let viewed = LdrImage::read_png(&scratch.join("viewed.png")).expect("the screenshot");
    let rendered = LdrImage::read_png(&scratch.join("rendered.png")).expect("the render");
    assert_eq!((rendered.width, rendered.height), (160, 90));
    assert!(viewed == rendered, "the saved scene renders differently");
    let saved = std::fs::read_to_string(scratch.join("saved.toml")).expect("the saved scene");
    assert!(saved.contains("exposure_ev = 0.5"), "{saved}");
}

#[test]
fn the_render_follows_the_window_when_it_is_resized() {
    let scratch = Scratch::new("view-resize");
    write(
        &scratch,
        "script.toml",
        "[[at]]\nframe = 3\nwindow_size = [240, 100]\n",
    );
    let args = ["--script", "script.toml", "--screenshot", "shot.png"];
    if view(scratch.path(), FRAMES, &args).is_none() {
        return;
    }
    let shot = LdrImage::read_png(&scratch.join("shot.png")).expect("the screenshot");
    assert_eq!((shot.width, shot.height), (120, 50));
}
