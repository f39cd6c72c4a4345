//! `cloudscape animate`: a scene's frames over scene time, and previews a person can play.

mod ffmpeg;

use crate::common::{GpuArgs, SceneArgs, Stages, parse_divisor, progress_bar, temporal_reuse};
use anyhow::{Context, Result, anyhow};
use clap::{Args, ValueEnum};
use cloudscape::animation::{GifPreview, scene_at, time_range_s};
use cloudscape::frame::Frame;
use cloudscape::gpu::{GpuContext, PassTimer};
use cloudscape::image::LdrImage;
use cloudscape::renderer::{PASS_COUNT, Rendered, Reuse, SceneRenderer};
use cloudscape::scene::{Scene, SceneDocument};
use ffmpeg::Mp4Writer;
use glam::UVec2;
use std::path::{Path, PathBuf};

/// Arguments of `cloudscape animate`.
#[derive(Args, Debug)]
pub struct AnimateArgs {
    #[command(flatten)]
    scene: SceneArgs,
    /// Frames to render [default: enough to reach the end of the scene's animation].
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
    frames: Option<u32>,
    /// Frames per second: frame i shows scene time start + i / fps, and the previews play at it.
    #[arg(long, default_value_t = 24.0, value_parser = parse_fps)]
    fps: f32,
    /// Scene time of the first frame, seconds.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    start_s: f32,
    /// Directory for the frames and previews (created if missing).
    #[arg(long)]
    out: PathBuf,
    /// Frame files: tone-mapped sRGB PNG, or linear HDR radiance OpenEXR.
    #[arg(long, value_enum, default_value_t = FrameFormat::Png)]
    format: FrameFormat,
    /// Largest width of preview.gif in pixels (frames are scaled down to it, never up).
    #[arg(long, default_value_t = 480, value_parser = clap::value_parser!(u32).range(1..))]
    preview_width: u32,
    /// Reuse earlier frames: march one ray per N x N pixels per frame (1, 2 or 4) and reproject
    /// the history for the rest, as a real-time host would (fast; the first frames are coarse).
    #[arg(long, value_name = "N", value_parser = parse_divisor)]
    temporal: Option<u32>,
    #[command(flatten)]
    gpu: GpuArgs,
}

/// The frame file format.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum FrameFormat {
    /// Tone-mapped, sRGB-encoded 8-bit PNG.
    Png,
    /// Linear 32-bit float RGBA OpenEXR.
    Exr,
}

impl FrameFormat {
    fn extension(self) -> &'static str {
        match self {
            FrameFormat::Png => "png",
            FrameFormat::Exr => "exr",
        }
    }

    /// Writes the display image (PNG) or the radiance (EXR) of `images` to `path`.
    fn write(self, images: &Rendered, path: &Path) -> Result<()> {
        match self {
            FrameFormat::Png => images.ldr.write_png(path)?,
            FrameFormat::Exr => images.hdr.write_exr(path)?,
        }
        Ok(())
    }
}

/// Highest frame rate accepted.
const MAX_FPS: f32 = 1000.0;

/// `--fps`: a finite rate above 0 and at most [`MAX_FPS`].
fn parse_fps(text: &str) -> Result<f32, String> {
    let fps: f32 = text.parse().map_err(|e| format!("{e}"))?;
    if fps.is_finite() && fps > 0.0 && fps <= MAX_FPS {
        Ok(fps)
    } else {
        Err(format!(
            "{text} frames per second; allowed > 0 and <= {MAX_FPS}"
        ))
    }
}

/// The frames to render: how many, when, and their file names.
struct Sequence {
    frames: u32,
    start_s: f32,
    fps: f32,
    format: FrameFormat,
    /// Digits of the frame number in file names: at least 4.
    digits: usize,
}

impl Sequence {
    /// `--frames`, or else the frames from `--start-s` through the end of the animation.
    fn new(args: &AnimateArgs, scene: &Scene) -> Result<Sequence> {
        let frames = match args.frames {
            Some(frames) => frames,
            None => frames_to_end(scene, args.start_s, args.fps)?,
        };
        Ok(Sequence {
            frames,
            start_s: args.start_s,
            fps: args.fps,
            format: args.format,
            digits: (frames - 1).to_string().len().max(4),
        })
    }

    /// Scene time of frame `index`, seconds.
    fn time_s(&self, index: u32) -> f32 {
        (f64::from(self.start_s) + f64::from(index) / f64::from(self.fps)) as f32
    }

    /// File name of frame `index`: `frame_0007.png`.
    fn file_name(&self, index: u32) -> String {
        let extension = self.format.extension();
        format!("frame_{index:0width$}.{extension}", width = self.digits)
    }
}

/// Frames from `start_s` through the last keyframe of the scene's animation at `fps`.
fn frames_to_end(scene: &Scene, start_s: f32, fps: f32) -> Result<u32> {
    let (_, end_s) = time_range_s(&scene.animation).ok_or_else(|| {
        anyhow!("the scene has no [animation] paths to set the length; give --frames N")
    })?;
    if end_s < start_s {
        return Err(anyhow!(
            "--start-s {start_s} is after the animation's last keyframe at {end_s} s; give --frames N"
        ));
    }
    let frames = (f64::from(end_s - start_s) * f64::from(fps)).floor() + 1.0;
    u32::try_from(frames as u64).context("too many frames; give --frames N")
}

/// The previews built while frames are rendered.
struct Previews {
    gif: GifPreview,
    mp4: Option<Mp4Writer>,
}

impl Previews {
    /// Starts the GIF, and the MP4 when `ffmpeg` is on PATH.
    fn start(dir: &Path, size: UVec2, args: &AnimateArgs) -> Result<Previews> {
        let gif = GifPreview::new(size, args.preview_width, args.fps)?;
        let mp4 = Mp4Writer::start(&dir.join("preview.mp4"), size, args.fps)?;
        if mp4.is_none() {
            eprintln!("ffmpeg is not on PATH: no preview.mp4 (the GIF is made all the same)");
        }
        Ok(Previews { gif, mp4 })
    }

    /// Adds a frame; an `ffmpeg` that fails is reported and dropped, the GIF goes on.
    fn push(&mut self, frame: &LdrImage) -> Result<()> {
        self.gif.push(frame)?;
        if let Some(Err(error)) = self.mp4.as_mut().map(|mp4| mp4.push(frame)) {
            eprintln!("warning: {error:#}; no preview.mp4");
            self.mp4 = None;
        }
        Ok(())
    }

    /// Writes the GIF and finishes the MP4; the paths written.
    fn finish(self, dir: &Path) -> Result<Vec<PathBuf>> {
        let gif_path = dir.join("preview.gif");
        self.gif.finish(&gif_path)?;
        let mut written = vec![gif_path];
        match self.mp4.map(Mp4Writer::finish) {
            Some(Ok(path)) => written.push(path),
            Some(Err(error)) => eprintln!("warning: {error:#}; no preview.mp4"),
            None => {}
        }
        Ok(written)
    }
}

/// A renderer for the frames of one scene, built once: a still whose layers (whose coverage the
/// animation may change) differ from the last one's is a live edit of its cloud field, which
/// restarts the temporal history.
struct FrameRenderer<'a> {
    ctx: &'a GpuContext,
    doc: &'a SceneDocument,
    renderer: Option<SceneRenderer>,
    /// Temporal reuse and the timer its frames need; None renders every frame as a still.
    temporal: Option<(Reuse, PassTimer)>,
    /// Frames whose cloud field was updated from the one before.
    field_updates: u32,
}

impl<'a> FrameRenderer<'a> {
    fn new(ctx: &'a GpuContext, doc: &'a SceneDocument, temporal: Option<u32>) -> Self {
        FrameRenderer {
            ctx,
            doc,
            renderer: None,
            temporal: temporal.map(|d| (temporal_reuse(d), PassTimer::new(ctx, PASS_COUNT))),
            field_updates: 0,
        }
    }

    /// Renders `still` as frame `index` of the sequence.
    fn render(&mut self, still: &Scene, index: u32, progress: impl FnMut(f32)) -> Result<Rendered> {
        let located =
            |e: cloudscape::field::FieldError| anyhow!(self.doc.error_at(&e.key_path, e.message));
        let base_dir = self.doc.resolve_path("");
        let renderer = match &mut self.renderer {
            Some(renderer) => {
                let update = renderer
                    .set_scene(self.ctx, still, &base_dir)
                    .map_err(located)?;
                self.field_updates += u32::from(update.is_some());
                renderer
            }
            empty => empty.insert(SceneRenderer::new(self.ctx, still, &base_dir).map_err(located)?),
        };
        let Some((reuse, timer)) = self.temporal.as_mut() else {
            return Ok(renderer.render(self.ctx, progress));
        };
        let size = UVec2::new(still.render.width, still.render.height);
        let frame = Frame {
            frame_index: index,
            ..Frame::from_scene(still, size)
        };
        renderer.render_frame(self.ctx, &frame, *reuse, timer);
        Ok(renderer.images(self.ctx))
    }
}

/// Renders every frame of `sequence`, writing it to `dir` and adding it to `previews`.
fn render_frames(
    frames: &mut FrameRenderer,
    sequence: &Sequence,
    dir: &Path,
    previews: &mut Previews,
) -> Result<()> {
    let bar = progress_bar("frames");
    let total = sequence.frames as f32;
    for index in 0..sequence.frames {
        bar.set_message(format!("frame {}/{}", index + 1, sequence.frames));
        let still = scene_at(&frames.doc.scene, sequence.time_s(index));
        let at = |f: f32| ((index as f32 + f) / total * 1000.0) as u64;
        let images = frames.render(&still, index, |f| bar.set_position(at(f)))?;
        bar.set_position(at(1.0));
        sequence
            .format
            .write(&images, &dir.join(sequence.file_name(index)))?;
        previews.push(&images.ldr)?;
    }
    bar.finish_and_clear();
    Ok(())
}

/// Loads the scene, renders the sequence, and writes the frames and previews.
pub fn run(args: AnimateArgs) -> Result<()> {
    let mut stages = Stages::new();
    let doc = stages.run("loading scene", || args.scene.load(&[]))?;
    let sequence = Sequence::new(&args, &doc.scene)?;
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("creating {}", args.out.display()))?;
    let ctx = stages.run("opening GPU", || args.gpu.open(&doc))?;
    let render = &doc.scene.render;
    let size = UVec2::new(render.width, render.height);
    let reuse = args.temporal.map_or(String::new(), |d| {
        format!(", temporal reuse (one ray per {d}x{d} pixels per frame)")
    });
    eprintln!(
        "rendering {} frames of {}x{} at {} fps from {} s, {:?} quality{reuse}",
        sequence.frames, size.x, size.y, sequence.fps, sequence.start_s, render.quality
    );
    let mut previews = Previews::start(&args.out, size, &args)?;
    let mut frames = FrameRenderer::new(&ctx, &doc, args.temporal);
    stages.run("rendering frames", || {
        render_frames(&mut frames, &sequence, &args.out, &mut previews)
    })?;
    if frames.field_updates > 0 {
        eprintln!(
            "coverage changed: the cloud field was updated for {} of {} frames",
            frames.field_updates, sequence.frames
        );
    }
    let written = stages.run("finishing previews", || previews.finish(&args.out))?;
    let (first, last) = (
        sequence.file_name(0),
        sequence.file_name(sequence.frames - 1),
    );
    eprintln!(
        "wrote {} frames: {}",
        sequence.frames,
        args.out.join(&first).display()
    );
    if sequence.frames > 1 {
        eprintln!("  through {}", args.out.join(&last).display());
    }
    for path in written {
        eprintln!("wrote {}", path.display());
    }
    stages.print();
    Ok(())
}
