//! `cloudscape bench --flythrough`: the temporal march measured on an animated sequence, as a
//! player sees it.
//!
//! The scene's animation is rendered at a game's frame rate (`--fps`, 60 frames per second of
//! scene time by default; `--spread` spreads the frames over the whole path instead, a stress with
//! stale history), every frame through the temporal march, its history carried from frame to
//! frame. On runs of [`RUN_FRAMES`] consecutive frames every `--reference-every` frames, the
//! full-resolution march at the scene's step counts is rendered too, and both are timed and
//! compared by FLIP with a converged reference of the same frame, with the frame-to-frame change
//! and flicker of each sequence within the run ([`flicker`]); where the camera is above the cloud
//! layers, the full march with empty-space skipping off and on. Both marches carry their lighting
//! from frame to frame as a real-time host does ([`cloudscape::shadow::LightingReuse::REAL_TIME`]), so their times differ
//! by what temporal reuse saves. The full march renders each of its frames after the temporal march
//! has brought the lighting up to date, so it never pays for a rebuild of the shadow map or a cold
//! solve of the light volume: its time, and the ratio of the two, are conservative.

mod flicker;
mod measure;
mod report;

use super::BenchArgs;
use crate::common::{progress_bar, temporal_reuse};
use anyhow::{Context, Result, anyhow, bail};
use clap::Args;
use cloudscape::animation::{scene_at, time_range_s};
use cloudscape::image::LdrImage;
use cloudscape::raymarch::MarchSettings;
use cloudscape::renderer::SceneRenderer;
use cloudscape::scene::Scene;
use measure::{Clock, FrameRecord, Images, Measurer, ReferenceSteps};
use report::{Report, Setup};
use std::path::{Path, PathBuf};

/// The scene measured when none is given.
const DEFAULT_SCENE: &str = "scenes/flythrough.toml";
/// Frames measured with `--spread` when `--frames` is not given (at `--fps`, the whole path).
const DEFAULT_SPREAD_FRAMES: u32 = 120;
/// Frames between the starts of two runs with references when `--reference-every` is not given, at
/// `--fps` (with `--spread` every frame has its references).
const DEFAULT_REFERENCE_EVERY: u32 = 60;
/// Consecutive frames in each run with references: three, so the flicker of two frame pairs is
/// measured and a strip shows what a player sees over three frames.
pub const RUN_FRAMES: u32 = 3;

/// The temporal march's grid divisor when `--temporal` is not given: one ray per 4x4 pixels per
/// frame, the 1/16 of Horizon Zero Dawn (Schneider 2015, "The real-time volumetric cloudscapes of
/// Horizon Zero Dawn", SIGGRAPH Advances in Real-Time Rendering).
const DEFAULT_DIVISOR: u32 = 4;

/// Arguments of `cloudscape bench --flythrough`.
#[derive(Args, Debug)]
pub struct FlythroughArgs {
    /// Measure the temporal march on the scene's animation (SCENE defaults to
    /// scenes/flythrough.toml): per frame, GPU time and FLIP against a converged frame of the
    /// full-resolution march and of the temporal march, flicker, and empty-space skipping with the
    /// camera above the clouds.
    #[arg(long)]
    pub flythrough: bool,
    /// Primary steps of the converged frames, as a multiple of the scene's.
    #[arg(long, default_value_t = 4, requires = "flythrough",
          value_parser = clap::value_parser!(u32).range(1..=16))]
    reference_step_factor: u32,
    /// Samples per pixel of the converged frames.
    #[arg(long, default_value_t = 8, requires = "flythrough",
          value_parser = clap::value_parser!(u32).range(1..=64))]
    reference_spp: u32,
    /// Frames per second of scene time: the path is rendered as a game at this rate would render
    /// it, from its start, for `--frames` frames [default: the whole path].
    #[arg(long, default_value_t = 60.0, requires = "flythrough", conflicts_with = "spread",
          value_parser = parse_fps)]
    fps: f32,
    /// Spread `--frames` frames (default 120) evenly over the whole path instead: a stress on the
    /// history, which is stale by a large step every frame.
    #[arg(long, requires = "flythrough")]
    spread: bool,
    /// End every N frames with a run of three frames through the full march and converged
    /// references too (after N - 3 frames of history) [default: 60; with --spread 1, every frame].
    #[arg(long, value_name = "N", requires = "flythrough",
          value_parser = clap::value_parser!(u32).range(1..))]
    reference_every: Option<u32>,
    /// Write each run with references here as a PNG: its frames top to bottom, each as full
    /// march, temporal march and converged, left to right.
    #[arg(long, value_name = "DIR", requires = "flythrough")]
    out: Option<PathBuf>,
}

/// Parses a frame rate: positive and at most 1000 frames per second.
fn parse_fps(text: &str) -> Result<f32, String> {
    let fps: f32 = text.parse().map_err(|e| format!("{e}"))?;
    if fps > 0.0 && fps <= 1000.0 {
        Ok(fps)
    } else {
        Err(format!("{fps} is not a frame rate in (0, 1000]"))
    }
}

/// Measures the fly-through and prints the report.
pub fn run(mut args: BenchArgs) -> Result<()> {
    let scene_path = args
        .scene
        .scene
        .get_or_insert_with(|| PathBuf::from(DEFAULT_SCENE))
        .display()
        .to_string();
    let doc = args.scene.load(&[])?;
    let scene = &doc.scene;
    let fly = &args.flythrough;
    let pacing = match fly.spread {
        true => Pacing::Spread(args.frames.unwrap_or(DEFAULT_SPREAD_FRAMES)),
        false => Pacing::Fps(fly.fps, args.frames),
    };
    let times = frame_times_s(scene, pacing)?;
    let reference_every = fly.reference_every.unwrap_or(match pacing {
        Pacing::Spread(_) => 1,
        Pacing::Fps(..) => DEFAULT_REFERENCE_EVERY,
    });
    let runs = Runs {
        every: reference_every,
    };
    if !(0..times.len()).any(|i| runs.has_references(i)) {
        bail!(
            "--reference-every {reference_every} leaves no frame with references in {} frames: \
             give at least {RUN_FRAMES} frames per run (--reference-every {RUN_FRAMES}..={})",
            times.len(),
            times.len()
        );
    }
    let ctx = args.gpu.open(&doc)?;
    let base_dir = doc.resolve_path("");
    let renderer = SceneRenderer::new(&ctx, scene, &base_dir)
        .map_err(|e| anyhow!(doc.error_at(&e.key_path, e.message)))?;
    let divisor = args.temporal.unwrap_or(DEFAULT_DIVISOR);
    let setup = Setup {
        adapter: ctx.summary(),
        scene: scene_path,
        width: scene.render.width,
        height: scene.render.height,
        time_range_s: (times[0], times[times.len() - 1]),
        fps: match pacing {
            Pacing::Fps(fps, _) => Some(fps),
            Pacing::Spread(_) => None,
        },
        reference_every,
        clock: Clock::of(&ctx),
        primary_steps: MarchSettings::from_scene(scene).primary_steps,
        temporal_divisor: divisor,
        reference: ReferenceSteps::new(scene, fly.reference_step_factor, fly.reference_spp),
    };
    let marches = (temporal_reuse(divisor), setup.reference);
    let mut measurer = Measurer::new(&ctx, (renderer, base_dir), setup.clock, marches);
    measurer.warm_up(&scene_at(scene, times[0]), args.warmup);
    let records = measure_all(&mut measurer, scene, (&times, runs), fly.out.as_deref())?;
    Report::new(setup, records).print(args.json)
}

/// How the frames are placed on the scene's animation.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Pacing {
    /// At this many frames per second of scene time from its start: this many frames, or the
    /// whole path.
    Fps(f32, Option<u32>),
    /// This many frames spread evenly from its first keyframe to its last.
    Spread(u32),
}

/// Which frames have the full march and converged references: runs of [`RUN_FRAMES`] consecutive
/// frames (all of them when `every` is smaller), one starting every `every` frames.
#[derive(Clone, Copy, Debug)]
struct Runs {
    every: u32,
}

impl Runs {
    /// Whether frame `index` is measured against its references: the last [`RUN_FRAMES`] of every
    /// `every` frames, so that the first run comes after a history has built up, as in a game.
    fn has_references(&self, index: usize) -> bool {
        (index as u32 + RUN_FRAMES) % self.every < RUN_FRAMES
    }

    /// The first frame of the strip frame `index` is shown in: the start of its run, or of its
    /// group of [`RUN_FRAMES`] when every frame has references.
    fn strip_start(&self, index: usize) -> usize {
        let period = self.every.max(RUN_FRAMES) as usize;
        index - (index + RUN_FRAMES as usize) % period
    }
}

/// Scene times of the frames `pacing` places on the scene's animation, seconds.
fn frame_times_s(scene: &Scene, pacing: Pacing) -> Result<Vec<f32>> {
    let Some((start, end)) = time_range_s(&scene.animation) else {
        bail!("the scene has no [animation] paths to fly through (see {DEFAULT_SCENE})");
    };
    if !scene.animation.coverage_scale.is_empty() {
        bail!(
            "--flythrough does not take scenes whose coverage changes: the cloud field, and with it \
             the temporal history, would be rebuilt on every frame"
        );
    }
    let (step_s, frames) = match pacing {
        Pacing::Spread(frames) => ((end - start) / (frames.max(2) - 1) as f32, frames),
        Pacing::Fps(fps, frames) => {
            let whole = ((end - start) * fps).floor() as u32 + 1;
            (1.0 / fps, frames.unwrap_or(whole))
        }
    };
    Ok((0..frames).map(|i| start + step_s * i as f32).collect())
}

/// Measures every frame in order with a progress bar, writing each run with references to `out`
/// as a strip ([`stack`] of [`side_by_side`] frames).
fn measure_all(
    measurer: &mut Measurer,
    scene: &Scene,
    (times, runs): (&[f32], Runs),
    out: Option<&Path>,
) -> Result<Vec<FrameRecord>> {
    if let Some(dir) = out {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    let bar = progress_bar("frames");
    let total = times.len() as f32;
    let mut records = Vec::with_capacity(times.len());
    let (mut strip, mut strips) = (Vec::new(), 0);
    for (index, &time_s) in times.iter().enumerate() {
        bar.set_message(format!("frame {}/{}", index + 1, times.len()));
        let at = |f: f32| ((index as f32 + f) / total * 1000.0) as u64;
        let still = scene_at(scene, time_s);
        let references = runs.has_references(index);
        let (record, images) = measurer.measure(index as u32, &still, references, |f| {
            bar.set_position(at(f))
        });
        if let (Some(dir), Some(images)) = (out, images) {
            strip.push(side_by_side(&images));
            let next = index + 1;
            let ends = next == times.len()
                || !runs.has_references(next)
                || runs.strip_start(next) != runs.strip_start(index);
            if ends {
                let path = dir.join(format!("frames_{:04}.png", runs.strip_start(index)));
                stack(&std::mem::take(&mut strip)).write_png(&path)?;
                strips += 1;
            }
        }
        bar.set_position(at(1.0));
        records.push(record);
    }
    bar.finish_and_clear();
    if let Some(dir) = out {
        eprintln!(
            "wrote {strips} strips to {} (top to bottom: consecutive frames; left to right: full \
             march, temporal march, converged)",
            dir.display()
        );
    }
    Ok(records)
}

/// The full, temporal and converged images of a frame next to each other, left to right.
fn side_by_side(images: &Images) -> LdrImage {
    let row = [&images.full, &images.temporal, &images.converged];
    let (width, height) = (images.full.width as usize, images.full.height);
    let pixels = (0..height as usize)
        .flat_map(|y| row.map(|image| &image.pixels[y * width..(y + 1) * width]))
        .flatten()
        .copied()
        .collect();
    LdrImage {
        width: images.full.width * row.len() as u32,
        height,
        pixels,
    }
}

/// Images of one width stacked top to bottom.
fn stack(rows: &[LdrImage]) -> LdrImage {
    LdrImage {
        width: rows.first().map_or(0, |r| r.width),
        height: rows.iter().map(|r| r.height).sum(),
        pixels: rows.iter().flat_map(|r| r.pixels.iter().copied()).collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spread_frames_span_the_animation_evenly() {
        let key = |time_s| cloudscape::scene::SunKey::at_angles(time_s, 30.0, 180.0);
        let mut scene = Scene::default();
        scene.animation.time_of_day = vec![key(1.0), key(3.0)];
        let times = |pacing| frame_times_s(&scene, pacing).unwrap();
        assert_eq!(times(Pacing::Spread(5)), [1.0, 1.5, 2.0, 2.5, 3.0]);
        assert_eq!(times(Pacing::Spread(1)), [1.0]);
        let error = frame_times_s(&Scene::default(), Pacing::Spread(5)).unwrap_err();
        assert!(error.to_string().contains("no [animation]"), "{error}");
    }

    #[test]
    fn paced_frames_step_by_the_frame_period_from_the_start() {
        let key = |time_s| cloudscape::scene::SunKey::at_angles(time_s, 30.0, 180.0);
        let mut scene = Scene::default();
        scene.animation.time_of_day = vec![key(1.0), key(3.0)];
        let whole = frame_times_s(&scene, Pacing::Fps(4.0, None)).unwrap();
        assert_eq!(whole, [1.0, 1.25, 1.5, 1.75, 2.0, 2.25, 2.5, 2.75, 3.0]);
        let first = frame_times_s(&scene, Pacing::Fps(60.0, Some(3))).unwrap();
        assert_eq!(first.len(), 3);
        assert!((first[2] - (1.0 + 2.0 / 60.0)).abs() < 1e-6, "{first:?}");
    }

    #[test]
    fn runs_of_three_frames_have_references() {
        let runs = Runs { every: 30 };
        let with: Vec<usize> = (0..64).filter(|&i| runs.has_references(i)).collect();
        assert_eq!(with, [27, 28, 29, 57, 58, 59]);
        assert_eq!(runs.strip_start(58), 57);
        let every = Runs { every: 1 };
        assert!((0..10).all(|i| every.has_references(i)));
        assert_eq!(
            every.strip_start(5),
            3,
            "groups of three when every frame has them"
        );
    }

    /// A grey image of `width` x `height` pixels of value `v`.
    fn grey(v: u8, width: u32, height: u32) -> LdrImage {
        LdrImage {
            width,
            height,
            pixels: vec![[v, v, v, 255]; (width * height) as usize],
        }
    }

    #[test]
    fn stack_puts_rows_top_to_bottom() {
        let stacked = stack(&[grey(1, 2, 1), grey(2, 2, 1)]);
        assert_eq!((stacked.width, stacked.height), (2, 2));
        assert_eq!(stacked.pixels[2][0], 2);
    }

    #[test]
    fn side_by_side_puts_the_images_left_to_right() {
        let image = |v: u8| grey(v, 2, 2);
        let images = Images {
            full: image(1),
            temporal: image(2),
            converged: image(3),
        };
        let strip = side_by_side(&images);
        assert_eq!((strip.width, strip.height), (6, 2));
        let row: Vec<u8> = strip.pixels[..6].iter().map(|p| p[0]).collect();
        assert_eq!(row, [1, 1, 2, 2, 3, 3]);
    }
}
