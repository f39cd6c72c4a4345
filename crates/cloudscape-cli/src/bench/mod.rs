//! `cloudscape bench`: GPU time per pass from timestamp queries, and wall time per frame; with
//! `--flythrough`, the temporal march against the full march and a converged reference over an
//! animated sequence ([`flythrough`]).

mod flythrough;
mod soak;

use crate::common::{GpuArgs, SceneArgs, parse_divisor, temporal_reuse};
use anyhow::{Result, anyhow};
use clap::Args;
use cloudscape::frame::Frame;
use cloudscape::gpu::{GpuContext, PassTimer};
use cloudscape::renderer::{PASS_COUNT, Reuse, SceneRenderer};
use cloudscape::scene::SceneDocument;
use cloudscape::shadow::LightingReuse;
use glam::UVec2;
use serde::Serialize;

/// Arguments of `cloudscape bench`.
#[derive(Args, Debug)]
pub struct BenchArgs {
    #[command(flatten)]
    scene: SceneArgs,
    /// Frames to time (after warm-up frames) [default: 30; with --flythrough 120, spread over the
    /// whole animation].
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
    frames: Option<u32>,
    /// Untimed frames first (pipeline compilation, caches).
    #[arg(long, default_value_t = 3)]
    warmup: u32,
    /// Print the result as JSON on stdout.
    #[arg(long)]
    json: bool,
    /// March one ray per N x N pixels per frame (1, 2 or 4) and reuse history between frames
    /// [default: none; with --flythrough 4].
    #[arg(long, value_name = "N", value_parser = parse_divisor)]
    temporal: Option<u32>,
    /// Time each of these techniques in turn on the same scene, e.g. `raymarch,particles`, and
    /// give their frame times relative to the first [default: the scene's].
    #[arg(long, value_delimiter = ',', value_name = "NAMES")]
    techniques: Vec<String>,
    /// One more run of the first technique with these overrides (comma-separated `KEY=VALUE`),
    /// timed beside the others, e.g. `--variant particles.occlusion_early_exit=false`
    /// (repeatable).
    #[arg(long, value_name = "KEY=VALUE,...")]
    variant: Vec<String>,
    /// A live edit (comma-separated `KEY=VALUE`) made before every other timed frame and undone
    /// before the rest, as a real-time host makes it (the lighting carried across frames): the
    /// largest "prepare (CPU)" is what an edit costs the frame it lands in, e.g. `--technique
    /// sprites --edit layers.0.coverage=0.7`.
    #[arg(long, value_name = "KEY=VALUE,...", conflicts_with_all = ["soak", "flythrough"])]
    edit: Option<String>,
    /// Soak: render at least this many frames at a small size (160x90 unless --width/--height)
    /// with temporal reuse, a moving camera and a live edit every `--soak-edit-every` frames, in
    /// whole cycles of the seven edits (so the end is in the state the start was), and fail if
    /// resident or GPU memory grows over 1 % from the warm-up to the end.
    #[arg(long, value_name = "FRAMES", conflicts_with = "flythrough",
          value_parser = clap::value_parser!(u32).range(1..))]
    soak: Option<u32>,
    /// Frames between two live edits of the soak.
    #[arg(long, value_name = "FRAMES", default_value_t = 250, requires = "soak",
          value_parser = clap::value_parser!(u32).range(1..))]
    soak_edit_every: u32,
    #[command(flatten)]
    flythrough: flythrough::FlythroughArgs,
    #[command(flatten)]
    gpu: GpuArgs,
}

/// Summary of one timed quantity over the frames, milliseconds.
#[derive(Serialize)]
struct Stat {
    name: String,
    mean_ms: f64,
    median_ms: f64,
    min_ms: f64,
    max_ms: f64,
}

impl Stat {
    fn new(name: &str, mut samples: Vec<f64>) -> Stat {
        samples.sort_by(f64::total_cmp);
        let mean = samples.iter().sum::<f64>() / samples.len() as f64;
        Stat {
            name: name.to_string(),
            mean_ms: mean,
            median_ms: samples[samples.len() / 2],
            min_ms: samples[0],
            max_ms: samples[samples.len() - 1],
        }
    }
}

#[derive(Serialize)]
struct Report {
    technique: String,
    adapter: String,
    width: u32,
    height: u32,
    frames: u32,
    timestamps: bool,
    /// A CPU (software) adapter, whose timestamp queries do not measure shader execution.
    software: bool,
    passes: Vec<Stat>,
    frame_wall: Stat,
    /// CPU time of the technique's per-frame preparation (sorting, building what it makes on the
    /// CPU, reading back what it asked the GPU).
    prepare_cpu: Stat,
    /// The first frame's preparation, ms: everything the technique builds on the CPU for a scene
    /// (the sprites' clouds).
    first_prepare_cpu_ms: f64,
    /// Extinction evaluations along view rays per pixel (the last frame; for particles,
    /// particle segments blended per pixel; for sprites, layers of sprites per pixel).
    density_samples_per_pixel: f64,
    /// Particles (or other primitives) drawn in the last frame.
    primitives: Option<u32>,
    /// Live edits made and undone during the timed frames (`--edit`).
    edits: u32,
}

/// Runs the soak with `--soak`, the fly-through measurement with `--flythrough`, the
/// repeated-frame timing otherwise.
pub fn run(args: BenchArgs) -> Result<()> {
    if let Some(frames) = args.soak {
        soak::run(&args, frames)
    } else if args.flythrough.flythrough {
        flythrough::run(args)
    } else {
        run_repeated(args)
    }
}

/// Times every technique asked for (the scene's by default) one after the other in this run, and
/// prints each one's report and their frame times relative to the first.
fn run_repeated(args: BenchArgs) -> Result<()> {
    let mut overrides: Vec<Vec<String>> = if args.techniques.is_empty() {
        vec![Vec::new()]
    } else {
        let set = |t: &String| vec![format!("render.technique={t}")];
        args.techniques.iter().map(set).collect()
    };
    for variant in &args.variant {
        let mut extra = overrides[0].clone();
        extra.extend(variant.split(',').map(str::to_string));
        overrides.push(extra);
    }
    let first = args.scene.load(&overrides[0])?;
    let ctx = args.gpu.open(&first)?;
    let reports = overrides
        .iter()
        .map(|extra| time_frames(&args, &ctx, extra))
        .collect::<Result<Vec<Report>>>()?;
    if args.json {
        println!("{}", serde_json::to_string_pretty(&reports)?);
        return Ok(());
    }
    for report in &reports {
        print_report(report);
    }
    if reports.len() > 1 {
        let base = reports[0].frame_wall.median_ms;
        println!(
            "median frame wall time relative to {}:",
            reports[0].technique
        );
        for r in &reports {
            println!("  {:<40} {:.3}", r.technique, r.frame_wall.median_ms / base);
        }
    }
    Ok(())
}

/// Renders the scene (with `extra` overrides) repeatedly, with the jitter advancing, and reports
/// timings.
fn time_frames(args: &BenchArgs, ctx: &GpuContext, extra: &[String]) -> Result<Report> {
    let frames = args.frames.unwrap_or(30);
    let doc = args.scene.load(extra)?;
    let edited = edited_scene(args, extra)?;
    let scene = &doc.scene;
    let mut renderer = SceneRenderer::new(ctx, scene, &doc.resolve_path(""))
        .map_err(|e| anyhow!(doc.error_at(&e.key_path, e.message)))?;
    let mut frame = Frame::from_scene(scene, UVec2::new(scene.render.width, scene.render.height));
    let mut timer = PassTimer::new(ctx, PASS_COUNT);
    let names = renderer.pass_names();
    let reuse = args.temporal.map_or(Reuse::None, temporal_reuse);
    if edited.is_some() {
        renderer
            .clouds()
            .set_lighting_reuse(Some(LightingReuse::REAL_TIME));
    }
    let mut pass_ms: Vec<Vec<f64>> = vec![Vec::new(); names.len()];
    let (mut wall_ms, mut prepare_ms, mut first_prepare_cpu_ms) = (Vec::new(), Vec::new(), 0.0);
    let mut edits = 0;
    for i in 0..args.warmup + frames {
        frame.frame_index = i;
        if let Some(edited) = edited.as_ref().filter(|_| i >= args.warmup) {
            let now = if (i - args.warmup).is_multiple_of(2) {
                edited
            } else {
                &doc
            };
            renderer
                .set_scene(ctx, &now.scene, &now.resolve_path(""))
                .map_err(|e| anyhow!(now.error_at(&e.key_path, e.message)))?;
            edits += 1;
        }
        let wall = renderer.render_frame(ctx, &frame, reuse, &mut timer);
        let prepare = renderer.clouds().prepare_time().as_secs_f64() * 1e3;
        if i == 0 {
            first_prepare_cpu_ms = prepare;
        }
        if i < args.warmup {
            continue;
        }
        wall_ms.push(wall.as_secs_f64() * 1e3);
        prepare_ms.push(prepare);
        for (label, ms) in timer.read_ms(ctx) {
            if let Some(k) = names.iter().position(|p| *p == label) {
                pass_ms[k].push(ms);
            }
        }
    }
    let stats = renderer.stats(ctx);
    let variant = extra.iter().filter(|o| !o.starts_with("render.technique="));
    let label = std::iter::once(scene.render.technique.name().to_string())
        .chain(variant.cloned())
        .collect::<Vec<_>>()
        .join(" ");
    Ok(Report {
        technique: label,
        adapter: ctx.summary(),
        width: frame.size.x,
        height: frame.size.y,
        frames,
        timestamps: ctx.has_timestamps(),
        software: is_software(ctx),
        passes: names
            .iter()
            .zip(pass_ms)
            .filter(|(_, s)| !s.is_empty())
            .map(|(n, s)| Stat::new(n, s))
            .collect(),
        frame_wall: Stat::new("frame (wall)", wall_ms),
        prepare_cpu: Stat::new("prepare (CPU)", prepare_ms),
        first_prepare_cpu_ms,
        density_samples_per_pixel: stats.map_or(0.0, |s| s.density_samples_per_pixel),
        primitives: stats.and_then(|s| s.primitives),
        edits,
    })
}

/// The scene with `extra` and `--edit`'s overrides, when there is an edit.
fn edited_scene(args: &BenchArgs, extra: &[String]) -> Result<Option<SceneDocument>> {
    let Some(edit) = &args.edit else {
        return Ok(None);
    };
    let edit = edit.split(',').map(str::to_string);
    let overrides: Vec<String> = extra.iter().cloned().chain(edit).collect();
    Ok(Some(args.scene.load(&overrides)?))
}

/// Whether the adapter is a CPU (software) one, whose timestamp queries do not time shaders.
fn is_software(ctx: &GpuContext) -> bool {
    ctx.adapter_info().device_type == wgpu::DeviceType::Cpu
}

fn print_report(report: &Report) {
    println!(
        "{} on {} at {}x{}, {} frames",
        report.technique, report.adapter, report.width, report.height, report.frames
    );
    if !report.timestamps {
        println!("(this adapter has no timestamp queries: GPU time per pass is not available)");
    } else if report.software {
        println!(
            "(a software adapter: its timestamps do not time shader execution; trust the wall time)"
        );
    }
    println!(
        "{:<22} {:>10} {:>10} {:>10} {:>10}",
        "pass", "mean ms", "median ms", "min ms", "max ms"
    );
    for s in report
        .passes
        .iter()
        .chain([&report.frame_wall, &report.prepare_cpu])
    {
        println!(
            "{:<22} {:>10.3} {:>10.3} {:>10.3} {:>10.3}",
            s.name, s.mean_ms, s.median_ms, s.min_ms, s.max_ms
        );
    }
    println!(
        "first frame's prepare (CPU): {:.1} ms (what the technique builds on the CPU for the scene)",
        report.first_prepare_cpu_ms
    );
    if report.edits > 0 {
        println!(
            "live edits: {} (made and undone in turn, one before each timed frame)",
            report.edits
        );
    }
    let samples = report.density_samples_per_pixel;
    match report.primitives {
        Some(n) => println!("primitives drawn: {n}; blended per pixel: {samples:.1}"),
        None => println!("view-ray density samples per pixel: {samples:.1}"),
    }
}
