//! One frame of the fly-through, measured: the full-resolution march, the temporal march, their
//! converged reference, and, with the camera above the cloud layers, the march with and without
//! empty-space skipping.

use super::flicker::{flicker, mean_change};
use cloudscape::frame::Frame;
use cloudscape::gpu::{GpuContext, PassTimer};
use cloudscape::image::{LdrImage, flip};
use cloudscape::raymarch::MarchSettings;
use cloudscape::renderer::{PASS_COUNT, Reuse, SceneRenderer};
use cloudscape::scene::Scene;
use cloudscape::shadow::LightingReuse;
use glam::UVec2;
use serde::Serialize;
use std::path::PathBuf;
use std::time::Instant;

/// The clock the marches are timed by.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Clock {
    /// GPU timestamp queries around each pass, summed over the frame's passes.
    Timestamps,
    /// Wall time from recording the frame to its completion: for adapters without timestamp
    /// queries, and software adapters, whose timestamps do not time shader execution.
    Wall,
}

impl Clock {
    /// Timestamps where the adapter has them and they time shaders, the wall clock otherwise.
    pub fn of(ctx: &GpuContext) -> Clock {
        if ctx.has_timestamps() && !crate::bench::is_software(ctx) {
            Clock::Timestamps
        } else {
            Clock::Wall
        }
    }
}

/// How each frame's converged reference is rendered: every pixel marched afresh, no temporal
/// reuse, in bands of rows ([`SceneRenderer::render`]).
#[derive(Clone, Copy, Debug, Serialize)]
pub struct ReferenceSteps {
    /// Samples along each view ray.
    pub primary_steps: u32,
    /// Jittered marches averaged per pixel.
    pub samples_per_pixel: u32,
}

impl ReferenceSteps {
    /// `step_factor` times the primary steps `scene` marches with, `samples_per_pixel` samples.
    pub fn new(scene: &Scene, step_factor: u32, samples_per_pixel: u32) -> ReferenceSteps {
        ReferenceSteps {
            primary_steps: MarchSettings::from_scene(scene).primary_steps * step_factor,
            samples_per_pixel,
        }
    }
}

/// One march of a frame against the converged frame.
#[derive(Debug, Serialize)]
pub struct Marched {
    /// GPU time of the frame (by the report's clock), milliseconds.
    pub ms: f64,
    /// Mean LDR FLIP error against the converged frame (none on frames without references).
    pub flip_mean: Option<f32>,
    /// [`mean_change`] from the previous frame (none on the first).
    pub change: Option<f64>,
    /// [`flicker`] from the previous frame (none on the first).
    pub flicker: Option<f64>,
}

/// The converged reference of a frame.
#[derive(Debug, Serialize)]
pub struct Converged {
    /// Wall time of its render, milliseconds.
    pub wall_ms: f64,
    /// [`mean_change`] from the previous frame (none on the first).
    pub change: Option<f64>,
}

/// The full march with empty-space skipping (the hi-height pyramid) off and on.
#[derive(Debug, Serialize)]
pub struct HiHeight {
    /// View-ray density samples per pixel without skipping.
    pub samples_off: f64,
    /// View-ray density samples per pixel with skipping.
    pub samples_on: f64,
    /// GPU time without skipping, milliseconds.
    pub ms_off: f64,
    /// GPU time with skipping, milliseconds.
    pub ms_on: f64,
    /// Mean LDR FLIP error of the image with skipping against the image without.
    pub flip_mean: f32,
}

/// Everything measured on one frame.
#[derive(Debug, Serialize)]
pub struct FrameRecord {
    /// Position in the sequence.
    pub index: u32,
    /// Scene time, seconds.
    pub time_s: f32,
    /// The camera's altitude above the ground, metres.
    pub camera_altitude_m: f32,
    /// The full-resolution march at the scene's step counts (frames with references).
    pub full: Option<Marched>,
    /// The temporal march, run through the sequence in order.
    pub temporal: Marched,
    /// The converged reference (frames with references).
    pub converged: Option<Converged>,
    /// Empty-space skipping off and on, for frames with the camera above every cloud layer.
    pub hiheight: Option<HiHeight>,
}

/// The display images of one frame.
pub struct Images {
    /// The full-resolution march.
    pub full: LdrImage,
    /// The temporal march.
    pub temporal: LdrImage,
    /// The converged reference.
    pub converged: LdrImage,
}

/// Luma of the full, temporal and converged images of a frame.
type Lumas = [Vec<f32>; 3];

/// Measures the frames of a sequence in order, carrying the temporal history from one to the next.
pub struct Measurer<'a> {
    ctx: &'a GpuContext,
    renderer: SceneRenderer,
    /// The directory the scene's files resolve against.
    base_dir: PathBuf,
    timer: PassTimer,
    clock: Clock,
    temporal: Reuse,
    reference: ReferenceSteps,
    /// The last frame with references and its lumas.
    previous: Option<(u32, Lumas)>,
}

impl<'a> Measurer<'a> {
    /// Measures with `renderer` (of a scene whose files resolve against `base_dir`), timing by
    /// `clock`, marching `temporal` for the temporal march and `reference` for the converged
    /// frames; the marches carry their lighting across frames ([`LightingReuse::REAL_TIME`], the converged frames lit by the same).
    pub fn new(
        ctx: &'a GpuContext,
        (mut renderer, base_dir): (SceneRenderer, PathBuf),
        clock: Clock,
        (temporal, reference): (Reuse, ReferenceSteps),
    ) -> Measurer<'a> {
        renderer
            .clouds()
            .set_lighting_reuse(Some(LightingReuse::REAL_TIME));
        Measurer {
            ctx,
            renderer,
            base_dir,
            timer: PassTimer::new(ctx, PASS_COUNT),
            clock,
            temporal,
            reference,
            previous: None,
        }
    }

    /// Renders `frames` untimed frames of `still` both ways (pipeline compilation, caches), then
    /// forgets the temporal history.
    pub fn warm_up(&mut self, still: &Scene, frames: u32) {
        for index in 0..frames {
            let frame = frame_of(still, index);
            self.timed(still, &frame, Reuse::None);
            self.timed(still, &frame, self.temporal);
        }
        self.renderer.reset_history();
    }

    /// Measures frame `index` of the sequence, the still `still`: the temporal march, and with
    /// `references` the full march, the converged frame and (above the layers) empty-space
    /// skipping too; `progress` follows the converged render, which takes most of the time.
    pub fn measure(
        &mut self,
        index: u32,
        still: &Scene,
        references: bool,
        progress: impl FnMut(f32),
    ) -> (FrameRecord, Option<Images>) {
        let frame = frame_of(still, index);
        let (temporal_ms, temporal) = self.timed(still, &frame, self.temporal);
        let mut record = FrameRecord {
            index,
            time_s: still.render.time_s,
            camera_altitude_m: self.altitude_m(&frame),
            full: None,
            temporal: Marched {
                ms: temporal_ms,
                flip_mean: None,
                change: None,
                flicker: None,
            },
            converged: None,
            hiheight: None,
        };
        if !references {
            return (record, None);
        }
        let (full_ms, full) = self.timed(still, &frame, Reuse::None);
        let (converged_ms, converged) = self.converged(still, progress);
        record.hiheight = self
            .above_clouds(&frame)
            .then(|| self.hiheight(still, &frame));
        let lumas = [&full, &temporal, &converged].map(LdrImage::luma);
        let steps = match &self.previous {
            Some((last, previous)) if last + 1 == index => Some(changes(previous, &lumas)),
            _ => None,
        };
        self.previous = Some((index, lumas));
        let marched = |ms, image: &LdrImage, k: usize| Marched {
            ms,
            flip_mean: Some(flip_mean(&converged, image)),
            change: steps.map(|(change, _)| change[k]),
            flicker: steps.map(|(_, flicker)| flicker[k]),
        };
        record.full = Some(marched(full_ms, &full, 0));
        record.temporal = marched(temporal_ms, &temporal, 1);
        record.converged = Some(Converged {
            wall_ms: converged_ms,
            change: steps.map(|(change, _)| change[2]),
        });
        let images = Images {
            full,
            temporal,
            converged,
        };
        (record, Some(images))
    }

    /// Makes `still` the renderer's scene. The stills of a fly-through differ from each other in
    /// their frames and in the march's settings only (scenes whose coverage changes are refused),
    /// which a renderer takes without reading a file.
    fn show(&mut self, still: &Scene) {
        self.renderer
            .set_scene(self.ctx, still, &self.base_dir)
            .expect("the fly-through changes only the march's settings");
    }

    /// Renders one whole frame; its time (by the clock) in milliseconds and its display image.
    fn timed(&mut self, still: &Scene, frame: &Frame, reuse: Reuse) -> (f64, LdrImage) {
        self.show(still);
        let (ctx, timer) = (self.ctx, &mut self.timer);
        let wall = self.renderer.render_frame(ctx, frame, reuse, timer);
        let ms = match self.clock {
            Clock::Timestamps => timer.read_ms(ctx).iter().map(|(_, ms)| ms).sum(),
            Clock::Wall => wall.as_secs_f64() * 1e3,
        };
        (ms, self.renderer.images(ctx).ldr)
    }

    /// The converged reference of `still` and the wall time it took, milliseconds. It is lit
    /// as the marches are, by the lighting carried across frames, so that it differs from them
    /// only in the march: what temporal reuse is measured on.
    fn converged(&mut self, still: &Scene, progress: impl FnMut(f32)) -> (f64, LdrImage) {
        let mut reference = still.clone();
        reference.render.primary_steps = Some(self.reference.primary_steps);
        reference.render.samples_per_pixel = Some(self.reference.samples_per_pixel);
        self.show(&reference);
        let start = Instant::now();
        let images = self.renderer.render(self.ctx, progress);
        (start.elapsed().as_secs_f64() * 1e3, images.ldr)
    }

    /// The full march with empty-space skipping off and on.
    fn hiheight(&mut self, still: &Scene, frame: &Frame) -> HiHeight {
        let mut run = |skipping| {
            let mut s = still.clone();
            s.render.empty_space_skipping = skipping;
            let (ms, image) = self.timed(&s, frame, Reuse::None);
            let stats = self.renderer.stats(self.ctx);
            (
                ms,
                image,
                stats.map_or(0.0, |s| s.density_samples_per_pixel),
            )
        };
        let (ms_off, off, samples_off) = run(false);
        let (ms_on, on, samples_on) = run(true);
        HiHeight {
            samples_off,
            samples_on,
            ms_off,
            ms_on,
            flip_mean: flip_mean(&off, &on),
        }
    }

    fn altitude_m(&self, frame: &Frame) -> f32 {
        let field = self.renderer.field();
        field.planet.altitude_m(frame.camera_position_m)
    }

    /// Whether the camera is above the top of every cloud layer (false without layers).
    fn above_clouds(&self, frame: &Frame) -> bool {
        let top_m = self.renderer.field().altitude_range_m().map(|(_, top)| top);
        top_m.is_some_and(|top| self.altitude_m(frame) > top)
    }
}

/// The frame `still` describes, at its render size, as frame `index` of a sequence.
fn frame_of(still: &Scene, index: u32) -> Frame {
    let size = UVec2::new(still.render.width, still.render.height);
    Frame {
        frame_index: index,
        ..Frame::from_scene(still, size)
    }
}

/// The mean LDR FLIP error of `test` against `reference` (the same size: same renderer).
fn flip_mean(reference: &LdrImage, test: &LdrImage) -> f32 {
    flip(reference, test)
        .expect("frames of one renderer have one size")
        .0
        .mean
}

/// From the previous frame's lumas to this frame's: the [`mean_change`] of the full, temporal and
/// converged images, and the [`flicker`] of the full and temporal ones (the converged's is 0).
fn changes(previous: &Lumas, current: &Lumas) -> ([f64; 3], [f64; 3]) {
    let pair = |k: usize| (previous[k].as_slice(), current[k].as_slice());
    (
        [0, 1, 2].map(|k| mean_change(pair(k))),
        [0, 1, 2].map(|k| flicker(pair(k), pair(2))),
    )
}
