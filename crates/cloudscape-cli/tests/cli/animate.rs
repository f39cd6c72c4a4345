//! `cloudscape animate`: frame sequences, the GIF preview, and rejected arguments.

use std::path::Path;
use std::process::Command;

use crate::support::{Run, Scratch, TINY, cloudscape};
use cloudscape::image::{HdrImage, LdrImage};

/// Runs `cloudscape animate args...` in `dir`.
fn animate(dir: &Path, args: &[&str]) -> Run {
    cloudscape(dir, &[&["animate"], args].concat(), true)
}

fn flythrough() -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/flythrough.toml");
    path.display().to_string()
}

/// Sizes and delays (1/100 s) of the frames of the GIF at `path`.
fn gif_frames(path: &Path) -> Vec<(u16, u16, u16)> {
    let file = std::fs::File::open(path).expect("open the GIF");
    let mut decoder = gif::DecodeOptions::new().read_info(file).expect("a GIF");
    let mut frames = Vec::new();
    while let Some(frame) = decoder.read_next_frame().expect("a GIF frame") {
        frames.push((frame.width, frame.height, frame.delay));
    }
    frames
}

fn ffmpeg_on_path() -> bool {
    Command::new("ffmpeg").arg("-version").output().is_ok()
}

#[test]
fn animate_writes_the_frames_and_a_gif_of_them() {
    let scratch = Scratch::new("png");
    let mut args = vec![flythrough()];
    args.extend(["--frames", "3", "--fps", "2", "--out", "anim"].map(String::from));
    args.extend(TINY.map(String::from));
    let run = animate(
        scratch.path(),
        &args.iter().map(String::as_str).collect::<Vec<_>>(),
    );
    let messages = run.stderr;
    assert!(run.success, "{messages}");
    assert!(messages.contains("wrote anim/preview.gif"), "{messages}");
    let dir = scratch.join("anim");
    let frames: Vec<LdrImage> = (0..3)
        .map(|i| LdrImage::read_png(&dir.join(format!("frame_{i:04}.png"))).expect("a frame"))
        .collect();
    assert!(frames.iter().all(|f| (f.width, f.height) == (64, 36)));
    assert_ne!(frames[0], frames[1], "the camera did not move");
    assert_ne!(frames[1], frames[2], "the camera did not move");
    assert_eq!(gif_frames(&dir.join("preview.gif")), [(64, 36, 50); 3]);
    assert_eq!(
        dir.join("preview.mp4").exists(),
        ffmpeg_on_path(),
        "{messages}"
    );
}

#[test]
fn animate_writes_exr_and_rebuilds_the_field_when_clouds_grow() {
    let scratch = Scratch::new("exr");
    let growth = "animation.coverage_scale=[{time_s=0,scale=0.5},{time_s=1,scale=2}]";
    let mut args = vec![
        "--frames", "2", "--fps", "1", "--format", "exr", "--out", "anim",
    ];
    args.extend(TINY);
    args.extend(["--set", growth, "--set", "camera.pitch_deg=30"]);
    let run = animate(scratch.path(), &args);
    let messages = run.stderr;
    assert!(run.success, "{messages}");
    assert!(messages.contains("updated for 1 of 2 frames"), "{messages}");
    let read = |i: u32| HdrImage::read(&scratch.join(&format!("anim/frame_{i:04}.exr")));
    let (sparse, dense) = (read(0).expect("frame 0"), read(1).expect("frame 1"));
    // Clouds are grey-white, the sky behind them blue: more cloud, more red for the blue.
    let redness = |image: &HdrImage| {
        let ratios = image.pixels.iter().map(|p| p[0] / p[2].max(1e-6));
        ratios.sum::<f32>() / image.pixels.len() as f32
    };
    let (sparse, dense) = (redness(&sparse), redness(&dense));
    assert!(dense > sparse * 1.15, "{dense} vs {sparse}");
}

#[test]
fn a_static_scene_needs_a_frame_count() {
    let scratch = Scratch::new("static");
    let run = animate(scratch.path(), &["--out", "anim"]);
    let messages = run.stderr;
    assert!(!run.success);
    assert!(messages.contains("give --frames N"), "{messages}");
    assert!(
        !scratch.join("anim").exists(),
        "a rejected run made the directory"
    );
}

#[test]
fn the_frame_rate_must_be_positive() {
    let scratch = Scratch::new("fps");
    let run = animate(
        scratch.path(),
        &["--frames", "2", "--fps", "0", "--out", "anim"],
    );
    let messages = run.stderr;
    assert!(!run.success);
    assert!(messages.contains("allowed > 0"), "{messages}");
}

#[test]
fn animate_temporal_renders_the_frames_with_temporal_reuse() {
    let scratch = Scratch::new("temporal");
    let scene = flythrough();
    let run = |out: &str, extra: &[&str]| {
        let mut args = vec![scene.as_str(), "--frames", "2", "--fps", "24", "--out", out];
        args.extend(TINY);
        args.extend(extra);
        let run = animate(scratch.path(), &args);
        assert!(run.success, "{}", run.stderr);
        run.stderr
    };
    let messages = run("temporal", &["--temporal", "4"]);
    assert!(messages.contains("temporal reuse"), "{messages}");
    run("stills", &[]);
    let read = |dir: &str, i: u32| {
        LdrImage::read_png(&scratch.join(&format!("{dir}/frame_{i:04}.png"))).expect("a frame")
    };
    for i in 0..2 {
        assert_eq!(
            (read("temporal", i).width, read("temporal", i).height),
            (64, 36)
        );
        assert_ne!(
            read("temporal", i),
            read("stills", i),
            "frame {i} was not marched coarsely"
        );
    }
}
