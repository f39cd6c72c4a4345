//! `cloudscape bench`: GPU time per pass from timestamp queries, and wall time per frame.

use crate::common::{GpuArgs, SceneArgs};
use anyhow::{Result, anyhow};
use clap::Args;
use cloudscape::frame::Frame;
use cloudscape::gpu::PassTimer;
use cloudscape::raymarch::temporal::TemporalSettings;
use cloudscape::renderer::{PASSES, Reuse, SceneRenderer};
use glam::UVec2;
use serde::Serialize;

/// Arguments of `cloudscape bench`.
#[derive(Args, Debug)]
pub struct BenchArgs {
    #[command(flatten)]
    scene: SceneArgs,
    /// Frames to time (after warm-up frames).
    #[arg(long, default_value_t = 30, value_parser = clap::value_parser!(u32).range(1..))]
    frames: u32,
    /// Untimed frames first (pipeline compilation, caches).
    #[arg(long, default_value_t = 3)]
    warmup: u32,
    /// Print the result as JSON on stdout.
    #[arg(long)]
    json: bool,
    /// March one ray per N x N pixels per frame (1, 2 or 4) and reuse history between frames.
    #[arg(long, value_name = "N", value_parser = parse_divisor)]
    temporal: Option<u32>,
    #[command(flatten)]
    gpu: GpuArgs,
}

/// A march-grid divisor: 1, 2 or 4.
fn parse_divisor(text: &str) -> Result<u32, String> {
    match text.parse::<u32>() {
        Ok(n @ (1 | 2 | 4)) => Ok(n),
        _ => Err(format!(
            "{text} is not a march-grid divisor; allowed 1, 2 or 4"
        )),
    }
}

/// Summary of one timed quantity over the frames, milliseconds.
#[derive(Serialize)]
struct Stat {
    name: String,
    mean_ms: f64,
    median_ms: f64,
    min_ms: f64,
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
        }
    }
}

#[derive(Serialize)]
struct Report {
    adapter: String,
    width: u32,
    height: u32,
    frames: u32,
    timestamps: bool,
    /// A CPU (software) adapter, whose timestamp queries do not measure shader execution.
    software: bool,
    passes: Vec<Stat>,
    frame_wall: Stat,
    /// Extinction evaluations along view rays per pixel (the last frame).
    density_samples_per_pixel: f64,
}

/// Renders the scene's frame repeatedly, with the jitter advancing, and reports timings.
pub fn run(args: BenchArgs) -> Result<()> {
    let doc = args.scene.load(&[])?;
    let scene = &doc.scene;
    let ctx = args.gpu.open(&doc)?;
    let mut renderer = SceneRenderer::new(&ctx, scene, &doc.resolve_path(""))
        .map_err(|e| anyhow!(doc.error_at(&e.key_path, e.message)))?;
    let mut frame = Frame::from_scene(scene, UVec2::new(scene.render.width, scene.render.height));
    let mut timer = PassTimer::new(&ctx, PASSES.len() as u32);
    let reuse = match args.temporal {
        Some(divisor) => Reuse::Temporal(TemporalSettings {
            divisor,
            ..TemporalSettings::default()
        }),
        None => Reuse::None,
    };
    let mut pass_ms: Vec<Vec<f64>> = vec![Vec::new(); PASSES.len()];
    let mut wall_ms = Vec::new();
    for i in 0..args.warmup + args.frames {
        frame.frame_index = i;
        let wall = renderer.render_frame(&ctx, scene, &frame, reuse, &mut timer);
        if i < args.warmup {
            continue;
        }
        wall_ms.push(wall.as_secs_f64() * 1e3);
        for (label, ms) in timer.read_ms(&ctx) {
            if let Some(k) = PASSES.iter().position(|p| *p == label) {
                pass_ms[k].push(ms);
            }
        }
    }
    let report = Report {
        adapter: ctx.summary(),
        width: frame.size.x,
        height: frame.size.y,
        frames: args.frames,
        timestamps: ctx.has_timestamps(),
        software: ctx.adapter_info().device_type == wgpu::DeviceType::Cpu,
        passes: PASSES
            .iter()
            .zip(pass_ms)
            .filter(|(_, s)| !s.is_empty())
            .map(|(n, s)| Stat::new(n, s))
            .collect(),
        frame_wall: Stat::new("frame (wall)", wall_ms),
        density_samples_per_pixel: renderer.march_stats(&ctx).density_samples_per_pixel,
    };
    print_report(&report, args.json)
}

fn print_report(report: &Report, json: bool) -> Result<()> {
    if json {
        println!("{}", serde_json::to_string_pretty(report)?);
        return Ok(());
    }
    println!(
        "{} at {}x{}, {} frames",
        report.adapter, report.width, report.height, report.frames
    );
    if !report.timestamps {
        println!("(this adapter has no timestamp queries: GPU time per pass is not available)");
    } else if report.software {
        println!(
            "(a software adapter: its timestamps do not time shader execution; trust the wall time)"
        );
    }
    println!(
        "{:<14} {:>10} {:>10} {:>10}",
        "pass", "mean ms", "median ms", "min ms"
    );
    for s in report.passes.iter().chain([&report.frame_wall]) {
        println!(
            "{:<14} {:>10.3} {:>10.3} {:>10.3}",
            s.name, s.mean_ms, s.median_ms, s.min_ms
        );
    }
    let samples = report.density_samples_per_pixel;
    println!("view-ray density samples per pixel: {samples:.1}");
    Ok(())
}
