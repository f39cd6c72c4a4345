//! `cloudscape view`: a window to fly through a scene, with live knobs and what each pass costs.
//!
//! The viewer drives the library as a game engine would: [`cloudscape::renderer::CloudRenderer`]
//! on the window's device, a frame per display refresh that never waits for the GPU (statistics
//! and pass times come back a frame late), temporal reuse, and live edits that rebuild only what
//! depends on them.

mod app;
mod camera;
mod frame;
mod keys;
mod knob_ui;
mod live;
mod panel;
mod present;
mod script;
mod stats;
mod viewer;

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;

use crate::common::{GpuArgs, SceneArgs};

/// Arguments of `cloudscape view`.
#[derive(Args, Debug)]
pub struct ViewArgs {
    /// The scene; the window opens at its `render.width` x `render.height` (`--width`,
    /// `--height`).
    #[command(flatten)]
    scene: SceneArgs,
    #[command(flatten)]
    gpu: GpuArgs,
    /// Fraction of the viewport's pixels rendered: 1, 0.5 or 0.25 (default: 1 on a GPU, 0.25 on
    /// a software adapter).
    #[arg(long, value_parser = parse_render_scale)]
    render_scale: Option<f32>,
    /// Temporal reuse: one ray per N x N pixels per frame, 1, 2 or 4, or `off` (default 2).
    #[arg(long, value_name = "N|off", value_parser = parse_temporal)]
    temporal: Option<Temporal>,
    /// Present without waiting for the display's refresh.
    #[arg(long)]
    no_vsync: bool,
    /// Start with the panels hidden (Tab shows them).
    #[arg(long)]
    hide_panels: bool,
    /// Render this many frames, then exit (frames advance the clock by 1/30 s each).
    #[arg(long, value_name = "N")]
    frames: Option<u64>,
    /// With `--frames`: write the last frame's image as this PNG, and as an EXR beside it.
    #[arg(long, value_name = "PATH.png", requires = "frames")]
    screenshot: Option<PathBuf>,
    /// Timed actions: live edits, camera moves, screenshots (see `view/script.rs`).
    #[arg(long, value_name = "FILE.toml")]
    script: Option<PathBuf>,
}

/// `--temporal`: a grid divisor, or off.
#[derive(Clone, Copy, Debug)]
struct Temporal(Option<u32>);

fn parse_temporal(text: &str) -> Result<Temporal, String> {
    if text.eq_ignore_ascii_case("off") {
        return Ok(Temporal(None));
    }
    crate::common::parse_divisor(text).map(|d| Temporal(Some(d)))
}

/// A render scale: 1, 0.5 or 0.25 (also written 1/2, 1/4).
pub fn parse_render_scale(text: &str) -> Result<f32, String> {
    let scale = match text.trim() {
        "1/2" => 0.5,
        "1/4" => 0.25,
        other => other.parse::<f32>().unwrap_or(f32::NAN),
    };
    panel::RENDER_SCALES
        .iter()
        .map(|(s, _)| *s)
        .find(|s| *s == scale)
        .ok_or_else(|| format!("{text} is not a render scale; allowed 1, 0.5 (1/2) or 0.25 (1/4)"))
}

/// Opens the window and runs the viewer until it is closed (or its frames are done).
pub fn run(args: ViewArgs) -> Result<()> {
    let setup = app::Setup::from_args(args)?;
    app::run(setup)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn render_scales_are_one_a_half_or_a_quarter() {
        assert_eq!(parse_render_scale("1"), Ok(1.0));
        assert_eq!(parse_render_scale("1/2"), Ok(0.5));
        assert_eq!(parse_render_scale("0.25"), Ok(0.25));
        let error = parse_render_scale("0.3").unwrap_err();
        assert!(error.contains("allowed 1, 0.5"), "{error}");
        assert_eq!(parse_temporal("off").unwrap().0, None);
        assert_eq!(parse_temporal("4").unwrap().0, Some(4));
        assert!(parse_temporal("3").is_err());
    }
}
