//! `cloudscape reference`: the path-traced ground truth of a scene, progressive and stoppable.

use crate::common::{SceneArgs, Stages, progress_bar};
use crate::interrupt;
use anyhow::{Result, anyhow};
use clap::Args;
use cloudscape::image::write_image;
use cloudscape_reference::{DEFAULT_MAJORANT_CELLS, PathTracer, ProgressiveRender, RenderStats};
use glam::UVec2;
use std::path::PathBuf;
use std::time::{Duration, Instant};

/// Arguments of `cloudscape reference`.
#[derive(Args, Debug)]
pub struct ReferenceArgs {
    #[command(flatten)]
    scene: SceneArgs,
    /// Samples (paths) per pixel.
    #[arg(long, default_value_t = 256, value_parser = clap::value_parser!(u32).range(1..))]
    spp: u32,
    /// Output image: `.exr` (linear HDR radiance) or `.png` (tone-mapped with the scene's
    /// exposure and tone mapper).
    #[arg(long)]
    out: PathBuf,
    /// Seed of the random numbers: the same seed gives the same image.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Stop after this many seconds of tracing and write the image so far (Ctrl-C does the same).
    #[arg(long, value_name = "SECONDS")]
    time_budget: Option<f64>,
    /// Samples per pixel in each progressive pass.
    #[arg(long, default_value_t = 4, value_parser = clap::value_parser!(u32).range(1..))]
    pass_spp: u32,
}

/// Builds the path tracer, traces passes until done or stopped, writes the image.
pub fn run(args: ReferenceArgs) -> Result<()> {
    let mut stages = Stages::new();
    let doc = stages.run("loading scene", || args.scene.load(&[]))?;
    let scene = &doc.scene;
    let size = UVec2::new(scene.render.width, scene.render.height);
    let tracer = stages.run("building field and majorants", || {
        PathTracer::for_scene(scene, &doc.resolve_path(""), size, DEFAULT_MAJORANT_CELLS)
            .map_err(|e| anyhow!(doc.error_at(&e.key_path, e.message)))
    })?;
    let grid = tracer.volume.grid.dims();
    // Graceful first, then the line a user (or a test) reacts to: a Ctrl-C after it keeps the work.
    interrupt::stop_gracefully();
    eprintln!(
        "path tracing {}x{} at {} spp (majorant grid {}x{}x{})",
        size.x, size.y, args.spp, grid.x, grid.y, grid.z
    );
    let deadline = args.time_budget.and_then(deadline_after);
    let should_stop =
        || interrupt::stop_requested() || deadline.is_some_and(|d| Instant::now() >= d);
    let mut render = ProgressiveRender::new(&tracer, args.seed);
    let bar = progress_bar("tracing");
    bar.set_length(u64::from(args.spp) * u64::from(size.x) * u64::from(size.y));
    stages.run("tracing", || {
        let mut done = 0;
        while done < args.spp && !should_stop() {
            let pass = args.pass_spp.min(args.spp - done);
            render.run_pass(pass, &should_stop, &|n| bar.inc(n));
            done += pass;
        }
        Ok(())
    })?;
    bar.finish_and_clear();
    if should_stop() {
        eprintln!("stopped early: writing the image so far");
    }
    let stats = render.stats();
    stages.run("writing image", || {
        Ok(write_image(
            &args.out,
            &render.image(),
            scene.render.exposure_ev,
            scene.render.tonemap,
        )?)
    })?;
    print_stats(&stats, size);
    eprintln!("wrote {}", args.out.display());
    stages.print();
    Ok(())
}

/// The moment `seconds` from now; None for a budget too large to represent (no limit). A
/// negative or NaN budget is spent at once.
pub fn deadline_after(seconds: f64) -> Option<Instant> {
    let budget = Duration::try_from_secs_f64(seconds.max(0.0)).ok()?;
    Instant::now().checked_add(budget)
}

fn print_stats(stats: &RenderStats, size: UVec2) {
    let pixels = f64::from(size.x) * f64::from(size.y);
    eprintln!(
        "{} samples ({:.1} spp) in {:.2} s: {:.0} samples/s",
        stats.samples,
        stats.samples as f64 / pixels,
        stats.elapsed.as_secs_f64(),
        stats.samples_per_second()
    );
    if stats.non_finite > 0 {
        eprintln!(
            "warning: {} non-finite samples were dropped",
            stats.non_finite
        );
    }
}
