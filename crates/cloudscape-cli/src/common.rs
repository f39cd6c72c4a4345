//! Arguments and steps every subcommand shares: the scene, `--set` overrides, the GPU.

use anyhow::{Context, Result, anyhow};
use clap::Args;
use cloudscape::gpu::{Backend, GpuContext, GpuOptions};
use cloudscape::renderer::Reuse;
use cloudscape::scene::SceneDocument;
use cloudscape::temporal::TemporalSettings;
use indicatif::{ProgressBar, ProgressStyle};
use std::path::PathBuf;
use std::time::{Duration, Instant};

/// The scene to use and changes to it.
#[derive(Args, Debug)]
pub struct SceneArgs {
    /// Scene file (TOML); the embedded default scene when absent.
    pub scene: Option<PathBuf>,
    /// Override a scene value, e.g. `--set layers.0.coverage=0.7` (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub overrides: Vec<String>,
    /// Image width in pixels (same as `--set render.width=W`).
    #[arg(long)]
    pub width: Option<u32>,
    /// Image height in pixels (same as `--set render.height=H`).
    #[arg(long)]
    pub height: Option<u32>,
    /// Renderer: raymarch, particles or sprites (same as `--set render.technique=NAME`).
    #[arg(long, value_name = "NAME")]
    pub technique: Option<String>,
}

impl SceneArgs {
    /// Every override, in order: `--set`, then `--width`, `--height` and `--technique` as the
    /// `--set` they stand for.
    pub fn all_overrides(&self) -> Vec<String> {
        let mut overrides = self.overrides.clone();
        overrides.extend(self.width.map(|w| format!("render.width={w}")));
        overrides.extend(self.height.map(|h| format!("render.height={h}")));
        overrides.extend(
            self.technique
                .as_ref()
                .map(|t| format!("render.technique={t}")),
        );
        overrides
    }

    /// Loads and validates the scene with every override applied, then `extra`, and prints on
    /// stderr what the overrides replaced without naming it.
    pub fn load(&self, extra: &[String]) -> Result<SceneDocument> {
        let mut overrides = self.all_overrides();
        overrides.extend_from_slice(extra);
        let document = SceneDocument::load(self.scene.as_deref(), &overrides)?;
        print_notes(&document);
        Ok(document)
    }
}

/// Prints each of the document's notes (what its overrides replaced) as one line on stderr, and
/// one for voxel grids the scene's technique does not draw.
pub fn print_notes(document: &SceneDocument) {
    for note in document.notes() {
        eprintln!("note: {note}");
    }
    let scene = &document.scene;
    let technique = scene.render.technique;
    if !scene.volumes.is_empty() && !cloudscape::renderer::draws(technique).voxel_grids {
        eprintln!(
            "note: {} do not draw the scene's [[volumes]] grids; the ray marcher does \
             (--technique raymarch)",
            technique.name()
        );
    }
}

/// Which GPU to use.
#[derive(Args, Debug)]
pub struct GpuArgs {
    /// Graphics API: vulkan, gl, metal or dx12 (default: the best available).
    #[arg(long)]
    pub backend: Option<Backend>,
    /// Use the first adapter whose name contains this text (case-insensitive).
    #[arg(long, value_name = "SUBSTRING")]
    pub adapter: Option<String>,
}

impl GpuArgs {
    /// The adapter choice these arguments ask for.
    pub fn options(&self) -> GpuOptions {
        GpuOptions {
            backend: self.backend,
            adapter_substring: self.adapter.clone(),
        }
    }

    /// Opens the GPU, prints which adapter it is, and checks the scene's image fits its limits.
    pub fn open(&self, doc: &SceneDocument) -> Result<GpuContext> {
        let ctx = GpuContext::new(&self.options())?;
        eprintln!("adapter: {}", ctx.summary());
        let max = ctx.max_texture_dimension_2d();
        for (key, value) in [
            ("render.width", doc.scene.render.width),
            ("render.height", doc.scene.render.height),
        ] {
            if value > max {
                return Err(anyhow!(doc.error_at(
                    key,
                    format!(
                        "{value} is above this adapter's maximum texture size; allowed 1..{max}"
                    )
                )));
            }
        }
        Ok(ctx)
    }
}

/// Times named stages and prints them at the end.
pub struct Stages {
    start: Instant,
    done: Vec<(&'static str, Duration)>,
}

impl Stages {
    /// Starts timing.
    pub fn new() -> Stages {
        Stages {
            start: Instant::now(),
            done: Vec::new(),
        }
    }

    /// Runs `f` as the stage `name`.
    pub fn run<T>(&mut self, name: &'static str, f: impl FnOnce() -> Result<T>) -> Result<T> {
        let t = Instant::now();
        let out = f().with_context(|| format!("while {name}"))?;
        self.done.push((name, t.elapsed()));
        Ok(out)
    }

    /// Prints each stage's time and the total.
    pub fn print(&self) {
        for (name, d) in &self.done {
            eprintln!("  {name:<22} {:>9.3} s", d.as_secs_f64());
        }
        eprintln!(
            "  {:<22} {:>9.3} s",
            "total",
            self.start.elapsed().as_secs_f64()
        );
    }
}

/// A progress bar with a percentage and ETA (hidden when stderr is not a terminal).
pub fn progress_bar(message: &'static str) -> ProgressBar {
    let bar = ProgressBar::new(1000);
    let style = ProgressStyle::with_template(
        "{msg:>12} [{bar:40.cyan/blue}] {percent:>3}% {elapsed_precise} ETA {eta}",
    )
    .expect("the template is valid")
    .progress_chars("=> ");
    bar.set_style(style);
    bar.set_message(message);
    bar
}

/// `--temporal N`: a march-grid divisor, 1, 2 or 4.
pub fn parse_divisor(text: &str) -> Result<u32, String> {
    match text.parse::<u32>() {
        Ok(n @ (1 | 2 | 4)) => Ok(n),
        _ => Err(format!(
            "{text} is not a march-grid divisor; allowed 1, 2 or 4"
        )),
    }
}

/// Temporal reuse marching one ray per `divisor` x `divisor` pixels per frame, otherwise the
/// default settings.
pub fn temporal_reuse(divisor: u32) -> Reuse {
    Reuse::Temporal(TemporalSettings {
        divisor,
        ..TemporalSettings::default()
    })
}
