//! `cloudscape`: render, export and benchmark cloud scenes from the command line.

mod animate;
mod bake;
mod bench;
mod common;
mod compare;
mod export;
mod fit_lighting;
mod interrupt;
mod reference;
mod render;
mod report;
mod runtime_dir;
mod view;

use clap::{Parser, Subcommand};

/// Physically based real-time clouds: render, export and benchmark scenes.
#[derive(Parser)]
#[command(name = "cloudscape", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene (the embedded default when no file is given) to a PNG or EXR image.
    Render(render::RenderArgs),
    /// Write a scene's cloud field as a Mitsuba 3 `.vol` grid plus a Mitsuba scene with the same
    /// camera, sun, sky and phase function.
    Export(export::ExportArgs),
    /// Time the GPU passes of a scene over many frames.
    Bench(bench::BenchArgs),
    /// Path-trace a scene on the CPU: the ground truth the real-time techniques are measured by.
    Reference(reference::ReferenceArgs),
    /// Compare an image with a reference: HDR-FLIP, relative MSE, mean luminance ratio.
    Compare(compare::CompareArgs),
    /// Render the canonical scenes with the ray marcher and the path tracer, compare them, and
    /// write `docs/realism.md`.
    Report(report::ReportArgs),
    /// Fit the ray marcher's models of multiple scattering (slab and octaves) to the path tracer
    /// on generated scenes (none of them canonical) and score the fit on held-out ones.
    FitLighting(fit_lighting::FitLightingArgs),
    /// Render a scene's frames over scene time (camera, sun and coverage paths, wind) to PNG or
    /// EXR files, with an animated GIF preview (and an MP4 when ffmpeg is on PATH).
    Animate(animate::AnimateArgs),
    /// Bake the particle technique's look-up tables (optical depth on the GPU, single and multiple
    /// scattering on the CPU) for a scene into the cache or `--out`, with timings and checks.
    Bake(bake::BakeArgs),
    /// Fly through a scene in a window: every knob live, what each pass costs on screen.
    View(view::ViewArgs),
}

fn main() -> std::process::ExitCode {
    runtime_dir::ensure();
    let cli = Cli::parse();
    if let Err(e) = interrupt::install() {
        eprintln!("error: {e:#}");
        return std::process::ExitCode::FAILURE;
    }
    let result = match cli.command {
        Command::Render(args) => render::run(args),
        Command::Export(args) => export::run(args),
        Command::Bench(args) => bench::run(args),
        Command::Reference(args) => reference::run(args),
        Command::Compare(args) => compare::run(args),
        Command::Report(args) => report::run(args),
        Command::FitLighting(args) => fit_lighting::run(args),
        Command::Animate(args) => animate::run(args),
        Command::Bake(args) => bake::run(args),
        Command::View(args) => view::run(args),
    };
    match result {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            std::process::ExitCode::FAILURE
        }
    }
}
