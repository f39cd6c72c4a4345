//! `render`, `export` and `bench`: what they write, and how they reject bad input.

use std::collections::BTreeSet;
use std::path::Path;

use crate::support::{Run, Scratch, TINY, cloudscape};
use cloudscape::field::VoxelGrid;
use cloudscape::image::{HdrImage, LdrImage};

/// `cloudscape render [scene] TINY --out out`.
fn render(dir: &Path, scene: Option<&str>, out: &str) -> Run {
    let mut args = vec!["render"];
    args.extend(scene);
    args.extend(TINY);
    args.extend(["--out", out]);
    cloudscape(dir, &args, true)
}

/// Asserts that `run` failed, that its error message holds every piece of `expected`, and that
/// the scratch directory holds exactly the files named in `before`.
fn assert_rejected(scratch: &Scratch, before: &[&str], run: &Run, expected: &[&str]) {
    assert!(!run.success, "should fail; stderr:\n{}", run.stderr);
    for piece in expected {
        assert!(
            run.stderr.contains(piece),
            "{piece:?} missing from:\n{}",
            run.stderr
        );
    }
    let before: BTreeSet<String> = before.iter().map(|name| name.to_string()).collect();
    assert_eq!(scratch.file_names(), before, "a rejected run wrote a file");
}

/// Renders the scene file `toml` (as `scene.toml`) and asserts that it is rejected with every
/// piece of `expected` in the message and no file written.
fn assert_scene_rejected(test: &str, toml: &str, expected: &[&str]) {
    let scratch = Scratch::new(test);
    std::fs::write(scratch.join("scene.toml"), toml).expect("write scene file");
    let run = render(scratch.path(), Some("scene.toml"), "out.png");
    assert_rejected(&scratch, &["scene.toml"], &run, expected);
}

/// Runs `cloudscape args...` in an empty directory and asserts that it is rejected with every
/// piece of `expected` in the message and no file written.
fn assert_args_rejected(test: &str, args: &[&str], gpu: bool, expected: &[&str]) {
    let scratch = Scratch::new(test);
    let run = cloudscape(scratch.path(), args, gpu);
    assert_rejected(&scratch, &[], &run, expected);
}

#[test]
fn render_writes_a_png_of_the_requested_size() {
    let scratch = Scratch::new("render-png");
    let run = render(scratch.path(), None, "out.png");
    assert!(run.success, "{}", run.stderr);
    assert!(run.stderr.contains("adapter: "), "{}", run.stderr);
    assert!(run.stderr.contains("wrote out.png"), "{}", run.stderr);
    let png = LdrImage::read_png(&scratch.join("out.png")).expect("read the PNG");
    assert_eq!((png.width, png.height), (64, 36));
    assert!(
        png.pixels.iter().any(|p| *p != png.pixels[0]),
        "the image is one flat colour"
    );
}

/// The command line is the user's latest word: a METAR report replaces the default scene's layers
/// (which a file giving both would have to choose between), and the render says so.
#[test]
fn a_metar_report_from_the_command_line_replaces_the_scenes_layers() {
    let scratch = Scratch::new("render-metar");
    let report = "weather.metar=\"EGLL 011750Z 24012KT 9999 FEW012 SCT030 BKN045 18/12 Q1012\"";
    let mut args = vec!["render", "--set", report];
    args.extend(TINY);
    let run = cloudscape(scratch.path(), &args, true);
    assert!(run.success, "{}", run.stderr);
    let note = "note: --set weather.metar replaces the scene's layers and sky.visibility_m";
    assert!(run.stderr.contains(note), "{}", run.stderr);
    assert!(scratch.join("cloudscape.png").exists(), "{}", run.stderr);
}

#[test]
fn render_exr_holds_finite_non_negative_radiance() {
    let scratch = Scratch::new("render-exr");
    let run = render(scratch.path(), None, "out.exr");
    assert!(run.success, "{}", run.stderr);
    let hdr = HdrImage::read(&scratch.join("out.exr")).expect("read the EXR");
    assert_eq!((hdr.width, hdr.height), (64, 36));
    let radiance = hdr.pixels.iter().flat_map(|p| &p[..3]);
    assert!(radiance.clone().all(|v| v.is_finite() && *v >= 0.0));
    assert!(hdr.mean_luminance() > 0.0, "the image is black");
}

#[test]
fn coverage_out_of_range_is_located_in_the_file() {
    let expected = ["scene.toml:2:12", "layers.0.coverage", "allowed 0..1"];
    assert_scene_rejected("coverage", "[[layers]]\ncoverage = 1.5\n", &expected);
}

#[test]
fn unknown_key_is_located_and_the_known_keys_listed() {
    let expected = ["scene.toml:2:1", "unknown field `widht`", "`width`"];
    assert_scene_rejected("unknown-key", "[render]\nwidht = 64\n", &expected);
}

#[test]
fn missing_weather_map_is_located_and_named() {
    let toml = "[weather]\nsource = \"file\"\npath = \"nope.png\"\n";
    let expected = ["scene.toml:3:8", "weather.path", "nope.png"];
    assert_scene_rejected("weather", toml, &expected);
}

#[test]
fn missing_volume_file_is_located_and_named() {
    let toml = "[[volumes]]\npath = \"missing.vol\"\n";
    let expected = ["scene.toml:2:8", "volumes.0.path", "missing.vol"];
    assert_scene_rejected("volume", toml, &expected);
}

#[test]
fn zero_width_is_rejected_with_the_allowed_range() {
    let args = ["render", "--width", "0", "--out", "out.png"];
    let expected = ["--set render.width=0", "render.width", "allowed >= 1"];
    assert_args_rejected("width-zero", &args, true, &expected);
}

#[test]
fn width_above_the_adapters_texture_limit_says_so() {
    let args = ["render", "--width", "100000", "--out", "out.png"];
    let expected = ["render.width", "maximum texture size", "allowed 1.."];
    assert_args_rejected("width-huge", &args, true, &expected);
}

/// Metal exists only on Apple systems.
#[cfg(not(target_vendor = "apple"))]
#[test]
fn missing_backend_says_what_to_install() {
    let args = ["render", "--backend", "metal", "--out", "out.png"];
    let expected = ["no adapter found on backend metal", "apt-get install"];
    assert_args_rejected("metal", &args, false, &expected);
}

#[test]
fn export_writes_a_mitsuba_scene_and_a_readable_grid() {
    let scratch = Scratch::new("export");
    let args = ["export", "--resolution", "16", "--out", "mitsuba"];
    let run = cloudscape(scratch.path(), &args, false);
    assert!(run.success, "{}", run.stderr);
    let xml = std::fs::read_to_string(scratch.join("mitsuba/scene.xml")).expect("read scene.xml");
    assert!(
        xml.contains("<string name=\"filename\" value=\"clouds.vol\"/>"),
        "{xml}"
    );
    let grid = VoxelGrid::read_vol(&scratch.join("mitsuba/clouds.vol")).expect("read clouds.vol");
    assert_eq!(grid.resolution.into_iter().max(), Some(16));
    assert!(grid.max_value() > 0.0, "the exported grid is empty");
}

/// `bench --techniques raymarch,particles,sprites --json`: one report per technique, each with its
/// passes (where the adapter times them) and frame wall time, the particles' and sprites' with
/// their count.
#[test]
fn bench_json_reports_each_pass_and_the_frame_wall_time() {
    let scratch = Scratch::new("bench");
    let mut args = vec!["bench", "--frames", "2", "--warmup", "0", "--json"];
    args.extend(["--techniques", "raymarch,particles,sprites"]);
    args.extend(["--set", "particles.table_resolution=low"]);
    args.extend(["--set", "sprites.distance_m=8000"]);
    args.extend(TINY);
    let run = cloudscape(scratch.path(), &args, true);
    assert!(run.success, "{}", run.stderr);
    let reports: serde_json::Value = serde_json::from_str(&run.stdout).expect("JSON on stdout");
    let reports = reports.as_array().expect("one report per technique");
    assert_eq!(reports.len(), 3);
    for (report, technique) in reports.iter().zip(["raymarch", "particles", "sprites"]) {
        assert_eq!(report["technique"], technique);
        assert_eq!(report["frames"], 2);
        assert_eq!(
            (report["width"].as_u64(), report["height"].as_u64()),
            (Some(64), Some(36))
        );
        let passes: Vec<&str> = report["passes"]
            .as_array()
            .expect("a passes array")
            .iter()
            .filter_map(|pass| pass["name"].as_str())
            .collect();
        let expected: &[&str] = match (report["timestamps"].as_bool(), technique) {
            (Some(true), "raymarch") => &[
                "light volume cells",
                "light volume solve",
                "light volume table",
                "raymarch",
                "compose",
                "display",
            ],
            (Some(true), "sprites") => &[
                "light volume cells",
                "light volume solve",
                "light volume table",
                "sprites: impostors",
                "sprites: draw",
                "sprites: resolve",
                "compose",
                "display",
            ],
            (Some(true), _) => &[
                "light volume cells",
                "light volume solve",
                "light volume table",
                "particles: generate",
                "particles: occlusion",
                "particles: bin",
                "particles: render",
                "upsample",
                "compose",
                "display",
            ],
            _ => &[],
        };
        // Every technique's frame starts with the environment's passes: the shadow map, the sky's
        // static tables (in the first frame: no warm-up here) and its per-frame ones (then the
        // light volume's: every technique reads it).
        let environment = [
            "cloud shadow map",
            "sky: transmittance table",
            "sky: multiple scattering table",
            "sky: irradiance table",
            "sky: view table",
            "sky: aerial perspective",
        ];
        let expected: Vec<&str> = if expected.is_empty() {
            Vec::new()
        } else {
            environment.iter().chain(expected).copied().collect()
        };
        assert_eq!(passes, expected);
        let wall_ms = report["frame_wall"]["mean_ms"]
            .as_f64()
            .expect("frame_wall.mean_ms");
        assert!(wall_ms > 0.0, "{report}");
        // The technique's CPU time per frame, and the first frame's, where the sprites build.
        let prepare = report["prepare_cpu"]["median_ms"].as_f64();
        let first = report["first_prepare_cpu_ms"]
            .as_f64()
            .expect("first prepare");
        assert!(prepare.is_some_and(|ms| ms >= 0.0), "{report}");
        assert!(technique != "sprites" || first > 0.0, "{report}");
        assert_eq!(report["edits"], 0);
    }
    assert!(reports[0]["primitives"].is_null());
    assert!(reports[1]["primitives"].as_u64().is_some_and(|n| n > 1000));
    assert!(reports[2]["primitives"].as_u64().is_some_and(|n| n > 100));
    assert!(scratch.file_names().is_empty(), "bench wrote a file");
}

/// `bench --edit` makes the edit before every other timed frame and undoes it before the rest,
/// and reports the frame an edit lands in as the prepare's largest time.
#[test]
fn bench_edit_makes_and_undoes_a_live_edit_between_frames() {
    let scratch = Scratch::new("bench-edit");
    let mut args = vec![
        "bench",
        "--technique",
        "sprites",
        "--frames",
        "3",
        "--warmup",
        "1",
    ];
    args.extend([
        "--edit",
        "layers.0.coverage=0.2",
        "--temporal",
        "2",
        "--json",
    ]);
    args.extend(["--set", "sprites.distance_m=8000"]);
    args.extend(TINY);
    let run = cloudscape(scratch.path(), &args, true);
    assert!(run.success, "{}", run.stderr);
    let reports: serde_json::Value = serde_json::from_str(&run.stdout).expect("JSON on stdout");
    let report = &reports[0];
    assert_eq!(report["edits"], 3, "{report}");
    let prepare = &report["prepare_cpu"];
    let (median, max) = (prepare["median_ms"].as_f64(), prepare["max_ms"].as_f64());
    assert!(
        median.zip(max).is_some_and(|(m, x)| x >= m && m > 0.0),
        "{report}"
    );
    let bad = cloudscape(
        scratch.path(),
        &["bench", "--edit", "layers.0.coverage=2"],
        true,
    );
    assert!(
        !bad.success && bad.stderr.contains("layers.0.coverage"),
        "{}",
        bad.stderr
    );
}

/// `scenes/flythrough.toml` of the repository, as an absolute path.
fn flythrough_scene() -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/flythrough.toml");
    path.display().to_string()
}

#[test]
fn bench_flythrough_spread_compares_both_marches_with_converged_frames() {
    let scratch = Scratch::new("bench-flythrough");
    let scene = flythrough_scene();
    let mut args = vec!["bench", "--flythrough", &scene, "--spread", "--frames", "3"];
    args.extend([
        "--warmup",
        "0",
        "--reference-spp",
        "2",
        "--reference-step-factor",
        "2",
    ]);
    args.extend(["--out", "frames", "--json"]);
    args.extend(TINY);
    let run = cloudscape(scratch.path(), &args, true);
    assert!(run.success, "{}", run.stderr);
    let report: serde_json::Value = serde_json::from_str(&run.stdout).expect("JSON on stdout");
    let frames = report["per_frame"].as_array().expect("per-frame records");
    assert_eq!(frames.len(), 3);
    assert_eq!(report["time_range_s"], serde_json::json!([0.0, 10.0]));
    assert!(report["fps"].is_null(), "spread frames have no frame rate");
    for march in ["full", "temporal"] {
        let flip = frames[1][march]["flip_mean"].as_f64().expect("a FLIP mean");
        assert!(flip > 0.0 && flip < 0.5, "{march}: {flip}");
        assert!(
            frames[0][march]["flicker"].is_null(),
            "no flicker on the first frame"
        );
        assert!(frames[1][march]["flicker"].as_f64().is_some(), "{report}");
    }
    // The fly-through ends 1.5 km above the layer's top: skipping is measured there.
    let skipping = &report["empty_space_skipping"];
    let samples = |key: &str| skipping[key].as_f64().expect("samples per pixel");
    assert!(samples("samples_on") < samples("samples_off"), "{skipping}");
    assert_eq!(report["targets"].as_array().map(Vec::len), Some(5));
    let strip = LdrImage::read_png(&scratch.join("frames/frames_0000.png")).expect("a strip");
    assert_eq!((strip.width, strip.height), (3 * 64, 3 * 36));
}

#[test]
fn bench_flythrough_without_a_run_of_references_says_so() {
    let scratch = Scratch::new("bench-flythrough-no-run");
    let scene = flythrough_scene();
    let args = ["bench", "--flythrough", &scene, "--frames", "12"];
    let run = cloudscape(scratch.path(), &args, false);
    assert!(
        !run.success && run.stderr.contains("--reference-every 60 leaves no frame"),
        "{}",
        run.stderr
    );
}

#[test]
fn bench_flythrough_at_a_frame_rate_marches_every_frame_and_references_runs() {
    let scratch = Scratch::new("bench-flythrough-fps");
    let scene = flythrough_scene();
    let mut args = vec![
        "bench",
        "--flythrough",
        &scene,
        "--fps",
        "30",
        "--frames",
        "4",
    ];
    args.extend(["--reference-every", "4", "--warmup", "0"]);
    args.extend([
        "--reference-spp",
        "1",
        "--reference-step-factor",
        "1",
        "--json",
    ]);
    args.extend(TINY);
    let run = cloudscape(scratch.path(), &args, true);
    assert!(run.success, "{}", run.stderr);
    let report: serde_json::Value = serde_json::from_str(&run.stdout).expect("JSON on stdout");
    assert_eq!(report["fps"], serde_json::json!(30.0));
    let frames = report["per_frame"].as_array().expect("per-frame records");
    let times: Vec<f64> = frames
        .iter()
        .map(|f| f["time_s"].as_f64().unwrap())
        .collect();
    assert!(
        (times[3] - 0.1).abs() < 1e-5,
        "frames 1/30 s apart: {times:?}"
    );
    // Frame 0 only through the temporal march; the run of three after it with references.
    assert!(frames[0]["full"].is_null() && frames[0]["temporal"]["flip_mean"].is_null());
    assert!(
        frames[0]["temporal"]["ms"]
            .as_f64()
            .is_some_and(|ms| ms > 0.0)
    );
    for frame in &frames[1..] {
        assert!(frame["full"]["flip_mean"].as_f64().is_some(), "{frame}");
    }
    assert!(
        frames[1]["temporal"]["flicker"].is_null(),
        "no pair before the run"
    );
    assert!(
        frames[2]["temporal"]["flicker"].as_f64().is_some(),
        "{report}"
    );
}

#[test]
fn bench_flythrough_without_a_scene_looks_for_the_flythrough_scene() {
    let args = ["bench", "--flythrough"];
    assert_args_rejected(
        "bench-flythrough-default",
        &args,
        true,
        &["scenes/flythrough.toml"],
    );
}

#[test]
fn flythrough_options_need_flythrough() {
    let args = ["bench", "--reference-spp", "4"];
    assert_args_rejected("bench-reference-spp", &args, false, &["--flythrough"]);
}

#[test]
fn export_sprites_writes_a_model_that_a_scene_renders_and_a_broken_one_is_located() {
    let scratch = Scratch::new("export_sprites");
    let scene = "[sprites]\ndistance_m = 4000.0\n";
    std::fs::write(scratch.join("scene.toml"), scene).expect("write scene");
    let run = cloudscape(
        scratch.path(),
        &["export", "scene.toml", "--sprites", "clouds.sprites.toml"],
        false,
    );
    assert!(run.success, "{}", run.stderr);
    let model = std::fs::read_to_string(scratch.join("clouds.sprites.toml")).expect("written");
    assert!(model.contains("format = \"cloudscape sprite model\""));
    let drawn = "layers = []\n[render]\ntechnique = \"sprites\"\n[sprites]\nfield_clouds = false\n\
        model = \"clouds.sprites.toml\"\n";
    std::fs::write(scratch.join("drawn.toml"), drawn).expect("write scene");
    let run = render(scratch.path(), Some("drawn.toml"), "drawn.png");
    assert!(run.success, "{}", run.stderr);
    let clear = drawn.replace("model = \"clouds.sprites.toml\"\n", "");
    std::fs::write(scratch.join("clear.toml"), clear).expect("write scene");
    let run = render(scratch.path(), Some("clear.toml"), "clear.png");
    assert!(run.success, "{}", run.stderr);
    let read = |name: &str| LdrImage::read_png(&scratch.join(name)).expect("a PNG");
    assert_ne!(
        read("drawn.png").pixels,
        read("clear.png").pixels,
        "the model drew nothing"
    );
    // A sprite with a texture past the sheet: the model file's line and key, and no image.
    let broken = model.replacen("texture = ", "texture = 9", 1);
    std::fs::write(scratch.join("clouds.sprites.toml"), broken).expect("write model");
    std::fs::remove_file(scratch.join("drawn.png")).expect("remove");
    let run = render(scratch.path(), Some("drawn.toml"), "drawn.png");
    let before = [
        "clear.png",
        "clear.toml",
        "clouds.sprites.toml",
        "drawn.toml",
        "scene.toml",
    ];
    assert_rejected(
        &scratch,
        &before,
        &run,
        &[
            "sprites.model",
            "clouds.sprites.toml:",
            "clouds.0.sprites.0.texture",
            "allowed 0..15",
        ],
    );
}
