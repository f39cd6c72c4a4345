//! `cloudscape bench --flythrough`: the temporal march measured on an animated sequence.
//!
//! For every frame of the scene's animation (spread evenly over it), in order: the full-resolution
//! march at the scene's step counts and the temporal march (its history carried from frame to
//! frame), each timed and compared by FLIP with a converged reference of the same frame; the
//! frame-to-frame change and flicker of each sequence ([`flicker`]); and, where the camera is above
//! the cloud layers, the full march with empty-space skipping off and on.

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
/// Frames measured when `--frames` is not given.
const DEFAULT_FRAMES: u32 = 120;
/// The temporal march's grid divisor when `--temporal` is not given: one ray per 4x4 pixels per
/// frame, the 1/16 of Horizon Zero Dawn (Schneider 2015, "The real-time volumetric cloudscapes of
/// Horizon Zero Dawn", SIGGRAPH Advances in Real-Time Rendering).
const DEFAULT_DIVISOR: u32 = 4;
/// Frames written with `--out`.
const SHOWN_FRAMES: usize = 6;

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
    /// Write six frames here as PNGs: full march, temporal march and converged side by side.
    #[arg(long, value_name = "DIR", requires = "flythrough")]
    out: Option<PathBuf>,
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
    let times = frame_times_s(scene, args.frames.unwrap_or(DEFAULT_FRAMES))?;
    let ctx = args.gpu.open(&doc)?;
    let base_dir = doc.resolve_path("");
    let renderer = SceneRenderer::new(&ctx, scene, &base_dir)
        .map_err(|e| anyhow!(doc.error_at(&e.key_path, e.message)))?;
    let fly = &args.flythrough;
    let divisor = args.temporal.unwrap_or(DEFAULT_DIVISOR);
    let setup = Setup {
        adapter: ctx.summary(),
        scene: scene_path,
        width: scene.render.width,
        height: scene.render.height,
        time_range_s: (times[0], times[times.len() - 1]),
        clock: Clock::of(&ctx),
        primary_steps: MarchSettings::from_scene(scene).primary_steps,
        temporal_divisor: divisor,
        reference: ReferenceSteps::new(scene, fly.reference_step_factor, fly.reference_spp),
    };
    let marches = (temporal_reuse(divisor), setup.reference);
    let mut measurer = Measurer::new(&ctx, (renderer, base_dir), setup.clock, marches);
    measurer.warm_up(&scene_at(scene, times[0]), args.warmup);
    let records = measure_all(&mut measurer, scene, &times, fly.out.as_deref())?;
    Report::new(setup, records).print(args.json)
}

/// Scene times of `frames` frames spread evenly from the first keyframe of the scene's animation to
/// its last, seconds.
fn frame_times_s(scene: &Scene, frames: u32) -> Result<Vec<f32>> {
    let Some((start, end)) = time_range_s(&scene.animation) else {
        bail!("the scene has no [animation] paths to fly through (see {DEFAULT_SCENE})");
    };
    if !scene.animation.coverage_scale.is_empty() {
        bail!(
            "--flythrough does not take scenes whose coverage changes: the cloud field, and with it \
             the temporal history, would be rebuilt on every frame"
        );
    }
    let step_s = (end - start) / (frames.max(2) - 1) as f32;
    Ok((0..frames).map(|i| start + step_s * i as f32).collect())
}

/// Measures every frame in order with a progress bar, writing the [`shown`] ones to `out`.
fn measure_all(
    measurer: &mut Measurer,
    scene: &Scene,
    times: &[f32],
    out: Option<&Path>,
) -> Result<Vec<FrameRecord>> {
    if let Some(dir) = out {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    let bar = progress_bar("frames");
    let total = times.len() as f32;
    let mut records = Vec::with_capacity(times.len());
    for (index, &time_s) in times.iter().enumerate() {
        bar.set_message(format!("frame {}/{}", index + 1, times.len()));
        let at = |f: f32| ((index as f32 + f) / total * 1000.0) as u64;
        let still = scene_at(scene, time_s);
        let (record, images) = measurer.measure(index as u32, &still, |f| bar.set_position(at(f)));
        if let Some(dir) = out.filter(|_| shown(times.len()).contains(&index)) {
            let path = dir.join(format!("frame_{index:04}.png"));
            side_by_side(&images).write_png(&path)?;
        }
        records.push(record);
    }
    bar.finish_and_clear();
    if let Some(dir) = out {
        eprintln!(
            "wrote {} frames to {} (left to right: full march, temporal march, converged)",
            shown(times.len()).len(),
            dir.display()
        );
    }
    Ok(records)
}

/// The indices of up to [`SHOWN_FRAMES`] frames spread evenly over `frames`, first and last
/// included.
fn shown(frames: usize) -> Vec<usize> {
    let last = frames.saturating_sub(1);
    let mut indices: Vec<usize> = (0..SHOWN_FRAMES)
        .map(|k| k * last / (SHOWN_FRAMES - 1))
        .collect();
    indices.dedup();
    indices
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_span_the_animation_evenly() {
        let key = |time_s| cloudscape::scene::SunKey::at_angles(time_s, 30.0, 180.0);
        let mut scene = Scene::default();
        scene.animation.time_of_day = vec![key(1.0), key(3.0)];
        assert_eq!(frame_times_s(&scene, 5).unwrap(), [1.0, 1.5, 2.0, 2.5, 3.0]);
        assert_eq!(frame_times_s(&scene, 1).unwrap(), [1.0]);
        let error = frame_times_s(&Scene::default(), 5).unwrap_err();
        assert!(error.to_string().contains("no [animation]"), "{error}");
    }

    #[test]
    fn shown_frames_include_the_first_and_last() {
        assert_eq!(shown(120), [0, 23, 47, 71, 95, 119]);
        assert_eq!(shown(3), [0, 1, 2]);
        assert_eq!(shown(1), [0]);
    }

    #[test]
    fn side_by_side_puts_the_images_left_to_right() {
        let image = |v: u8| LdrImage {
            width: 2,
            height: 2,
            pixels: vec![[v, v, v, 255]; 4],
        };
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
