//! Temporal reuse for any technique (the volumecloud seed, with Horizon Zero Dawn's subset
//! updates): the technique renders few rays per frame on a coarse grid, each through a different
//! sub-pixel and at a different offset along the ray every frame, and this full-resolution resolve
//! upsamples them with depth awareness, reprojects the history at the cloud distance, clips it to
//! the neighbourhood and blends. It reads only the cloud output ([`crate::output`]).

use crate::frame::Frame;
use crate::gpu::pipeline::{dispatch_2d, uniform_buffer};
use crate::gpu::{GpuContext, PassTimer};
use crate::output::{CloudOutput, SampleGrid};
use crate::pass::{BindGroupCache, ComputePass, Shared};
use crate::scene::knobs::Allowed::Between;
use crate::scene::knobs::{Knob, knob};
use bytemuck::{Pod, Zeroable};
use documented::DocumentedFields;
use glam::{Mat4, UVec2, Vec2, Vec3};

/// How temporal reuse trades rays for history.
#[derive(Clone, Copy, Debug, PartialEq, DocumentedFields)]
pub struct TemporalSettings {
    /// 1, 2 or 4: march one ray per divisor x divisor block per frame (4 updates 1/16 of the pixels,
    /// as Horizon Zero Dawn does).
    pub divisor: u32,
    /// Weight of new samples per frame at full resolution (the seed's 0.05): a ray's own pixel,
    /// which gets a ray every divisor^2 frames, blends it in with the weight that decays as much
    /// over them ([`TemporalSettings::fresh_weight`]), and the pixels around it a part of that
    /// falling off with their distance to the ray ([`RAY_SIGMA_PX`]).
    pub blend_per_frame: f32,
    /// Half-width of the neighbourhood box the history is clipped to, in standard deviations (the
    /// seed's gamma = 1).
    pub clip_gamma: f32,
    /// A camera jump longer than this (metres) in one frame is a cut: the history restarts.
    pub cut_distance_m: f32,
    /// The history is trusted where the cloud it shows lies within this fraction of the distance
    /// at which the current estimate puts it; otherwise it shows something else (a disocclusion,
    /// the inside of a cloud the camera has left) and is dropped.
    pub distance_tolerance: f32,
}

impl Default for TemporalSettings {
    fn default() -> Self {
        TemporalSettings {
            divisor: 2,
            blend_per_frame: 0.05,
            clip_gamma: 1.0,
            cut_distance_m: 1000.0,
            distance_tolerance: 0.25,
        }
    }
}

/// The knobs of temporal reuse a host may offer its users (the grid's divisor is a choice of 1, 2
/// or 4, not a range).
#[rustfmt::skip]
pub const KNOBS: &[Knob<TemporalSettings>] = &[
    knob!(TemporalSettings, blend_per_frame, Between(0.01, 1.0), ""),
    knob!(TemporalSettings, clip_gamma, Between(0.25, 4.0), ""),
    knob!(TemporalSettings, cut_distance_m, Between(10.0, 1.0e5), "m"),
    knob!(TemporalSettings, distance_tolerance, Between(0.01, 1.0), ""),
];

impl TemporalSettings {
    /// Weight of a fresh sample at its ray's own pixel: 1 - (1 - blend)^(divisor^2).
    pub fn fresh_weight(&self) -> f32 {
        1.0 - (1.0 - self.blend_per_frame).powi((self.divisor * self.divisor) as i32)
    }

    /// [`TemporalSettings::fresh_weight`] `history_frames` frames after the history began (or
    /// after a leap of the camera): 1 until every pixel of a block has had a ray of its own, so
    /// that each pixel's first own sample replaces what the history held (the interpolation of
    /// the first frame's sparse rays, or a history reprojected from far away) instead of taking a
    /// steady-state share of it; the weight of a running mean's first sample.
    pub fn fresh_weight_after(&self, history_frames: u32) -> f32 {
        match history_frames < self.divisor * self.divisor {
            true => 1.0,
            false => self.fresh_weight(),
        }
    }
}

/// The radical inverse of `index` in `base` (Halton 1964): a low-discrepancy sequence in [0, 1).
pub fn halton(mut index: u32, base: u32) -> f32 {
    let (mut result, mut scale) = (0.0, 1.0);
    while index > 0 {
        scale /= base as f32;
        result += scale * (index % base) as f32;
        index /= base;
    }
    result
}

/// The sub-pixel of a `divisor` x `divisor` block that frame `index` marches: blocks are visited in
/// the order of the ordered-dither (Bayer) matrix, so successive frames spread over the block.
pub fn subpixel(index: u32, divisor: u32) -> UVec2 {
    let n = divisor * divisor;
    let rank = index % n;
    (0..n)
        .map(|i| UVec2::new(i % divisor, i / divisor))
        .find(|p| bayer_rank(*p, divisor) == rank)
        .expect("a Bayer matrix holds every rank once")
}

/// Rank of `p` in the `size` x `size` Bayer matrix (size a power of two), built by interleaving the
/// bits of x ^ y and y (Bayer 1973).
fn bayer_rank(p: UVec2, size: u32) -> u32 {
    let bits = size.trailing_zeros();
    (0..bits).fold(0, |rank, b| {
        let x = (p.x >> b) & 1;
        let y = (p.y >> b) & 1;
        rank | (((x ^ y) << 1 | y) << (2 * (bits - 1 - b)))
    })
}

/// The `Temporal` uniform of `temporal.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct TemporalUniform {
    prev_clip_from_world: Mat4,
    prev_camera_position_m: Vec3,
    history_valid: u32,
    wind_shift_m: Vec2,
    fresh_weight: f32,
    clip_gamma: f32,
    distance_tolerance: f32,
    reserved_0: u32,
    reserved_1: UVec2,
}

/// What the previous frame looked like, for reprojection.
#[derive(Clone, Copy, Debug)]
struct PreviousFrame {
    clip_from_world: Mat4,
    camera_m: Vec3,
    time_s: f32,
    /// Frames resolved since the history began or the camera last leapt.
    history_frames: u32,
}

/// A camera step longer than this fraction of [`TemporalSettings::cut_distance_m`] is a leap: the
/// history is kept (it is not a cut), but most of it is reprojected from far away, so the
/// fresh samples' weights start again as after a cut ([`TemporalSettings::fresh_weight_after`]).
const LEAP_FRACTION: f32 = 0.1;

/// The temporal resolve pass and its two full-resolution histories (ping-pong), each with the
/// cloud distance its pixels show.
pub struct TemporalResolve {
    pass: ComputePass,
    settings: TemporalSettings,
    uniform: wgpu::Buffer,
    sampler: wgpu::Sampler,
    history: Option<[CloudOutput; 2]>,
    groups: BindGroupCache,
    previous: Option<PreviousFrame>,
    latest: usize,
}

impl TemporalResolve {
    /// Builds the pass against the shared groups' layouts.
    pub fn new(ctx: &GpuContext, shared: &Shared, settings: TemporalSettings) -> TemporalResolve {
        let sampler = ctx.device.create_sampler(&wgpu::SamplerDescriptor {
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        });
        TemporalResolve {
            pass: ComputePass::new(
                ctx,
                shared,
                "temporal resolve",
                &TEMPORAL_WGSL,
                &["resolve_clouds"],
            ),
            settings,
            uniform: uniform_buffer(ctx, "temporal", size_of::<TemporalUniform>() as u64),
            sampler,
            history: None,
            groups: Default::default(),
            previous: None,
            latest: 0,
        }
    }

    /// Forgets the history: the next frame starts afresh (camera cuts, new weather).
    pub fn reset(&mut self) {
        self.previous = None;
    }

    /// The history written last: the resolved full-resolution output (None before any frame).
    pub fn latest(&self) -> Option<&CloudOutput> {
        self.history.as_ref().map(|h| &h[self.latest])
    }

    /// The settings in use.
    pub fn settings(&self) -> &TemporalSettings {
        &self.settings
    }

    /// The rays frame `frame_index` renders: its sub-pixel of each block (Bayer order); their
    /// offsets along the rays follow the frame index (`march_ray_offset`, `raymarch.wgsl`). The frame
    /// index must advance every frame.
    pub fn grid(&self, frame_index: u32) -> SampleGrid {
        let divisor = self.settings.divisor;
        SampleGrid {
            divisor,
            subpixel: subpixel(frame_index, divisor),
        }
    }

    /// Records the resolve of this frame's coarse output `current` (rendered on
    /// [`TemporalResolve::grid`]) into the full-resolution history; returns the result, valid once
    /// the encoder is submitted. `wind_m_per_s` is the clouds' motion.
    pub fn encode(
        &mut self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        shared: &Shared,
        (frame, wind_m_per_s): (&Frame, Vec2),
        (current, host_depth): (&CloudOutput, &wgpu::TextureView),
        timer: Option<&mut PassTimer>,
    ) -> &CloudOutput {
        self.ensure_history(ctx, frame.size);
        self.write_uniform(ctx, frame, wind_m_per_s);
        let (read, write) = (self.latest, 1 - self.latest);
        let history = self.history.as_ref().expect("ensure_history made it");
        let (pass, uniform, sampler) = (&self.pass, &self.uniform, &self.sampler);
        let views = [
            &current.radiance,
            &current.distance,
            &history[read].radiance,
            host_depth,
            &history[write].radiance,
            &history[read].distance,
            &history[write].distance,
        ];
        let group = self.groups.get(&views, || {
            use wgpu::BindingResource::{Sampler, TextureView};
            pass.group.bind(
                ctx,
                &[
                    ("temporal", uniform.as_entire_binding()),
                    ("coarse_clouds", TextureView(views[0])),
                    ("coarse_distance", TextureView(views[1])),
                    ("history_in", TextureView(views[2])),
                    ("history_linear", Sampler(sampler)),
                    ("temporal_host_depth", TextureView(views[3])),
                    ("history_out", TextureView(views[4])),
                    ("history_distance_in", TextureView(views[5])),
                    ("history_distance_out", TextureView(views[6])),
                ],
            )
        });
        let writes = timer.and_then(|t| t.compute_pass_writes("temporal resolve"));
        dispatch_2d(
            encoder,
            "temporal resolve",
            pass.main(),
            &shared.bind_groups(pass.slots, group),
            frame.size,
            writes,
        );
        self.latest = write;
        &history[write]
    }

    fn write_uniform(&mut self, ctx: &GpuContext, frame: &Frame, wind_m_per_s: Vec2) {
        let clip_from_world = frame.clip_from_world();
        let cut = self.previous.is_some_and(|p| {
            p.camera_m.distance(frame.camera_position_m) > self.settings.cut_distance_m
        });
        let previous = if cut { None } else { self.previous };
        let s = &self.settings;
        let leap = previous.is_some_and(|p| {
            p.camera_m.distance(frame.camera_position_m) > LEAP_FRACTION * s.cut_distance_m
        });
        let history_frames = previous.map_or(0, |p| if leap { 0 } else { p.history_frames + 1 });
        let uniform = TemporalUniform {
            prev_clip_from_world: previous.map_or(clip_from_world, |p| p.clip_from_world),
            prev_camera_position_m: previous.map_or(frame.camera_position_m, |p| p.camera_m),
            history_valid: previous.is_some() as u32,
            wind_shift_m: wind_m_per_s * previous.map_or(0.0, |p| frame.time_s - p.time_s),
            fresh_weight: s.fresh_weight_after(history_frames),
            clip_gamma: s.clip_gamma,
            distance_tolerance: s.distance_tolerance,
            reserved_0: 0,
            reserved_1: UVec2::ZERO,
        };
        ctx.queue
            .write_buffer(&self.uniform, 0, bytemuck::bytes_of(&uniform));
        self.previous = Some(PreviousFrame {
            clip_from_world,
            camera_m: frame.camera_position_m,
            time_s: frame.time_s,
            history_frames,
        });
    }

    fn ensure_history(&mut self, ctx: &GpuContext, size: UVec2) {
        if self.history.as_ref().is_some_and(|h| h[0].size == size) {
            return;
        }
        self.history = Some([
            CloudOutput::new(ctx, "cloud history a", size),
            CloudOutput::new(ctx, "cloud history b", size),
        ]);
        self.previous = None;
    }
}

/// Depth-aware upsampling of a coarse cloud output (`upsample.wgsl`), for every pass that reads one.
pub static UPSAMPLE_WGSL: crate::shader::WgslModule =
    crate::shader::wgsl_module!("upsample", "upsample.wgsl", [&crate::frame::FRAME_WGSL]);

/// The temporal reconstruction pass (`temporal.wgsl`).
pub static TEMPORAL_WGSL: crate::shader::WgslModule = crate::shader::wgsl_module!(
    "temporal",
    "temporal.wgsl",
    [
        &crate::frame::FRAME_WGSL,
        &UPSAMPLE_WGSL,
        &crate::field::noise::NOISE_WGSL
    ],
    temporal_constants
);

/// Width (standard deviation, pixels) of the bump over which a new sample is blended into the
/// history around its ray (`temporal_new_weight`) where the history holds still: narrow, so that a
/// pixel between rays takes little of the interpolated estimate, which blurs features thinner
/// than the rays' spacing (a thin cloud on the horizon lost half its contrast at 0.75 px: every
/// pixel's steady state mixed its own samples with interpolations across it). The pixel lattice
/// does not show because every pixel meets its own ray once per divisor^2 frames, and from the
/// start ([`TemporalSettings::fresh_weight_after`]).
pub const RAY_SIGMA_PX: f32 = 0.4;

/// The bump's width where the camera's step has moved the history [`CLIP_MOTION_PX`] or more by
/// parallax since the previous frame: such a history is clipped, and the estimate between rays is
/// the better guess over more of the pixels around each ray. Fly-through FLIP of the 4x4 march
/// over the first 240 frames: 0.0378 at 0.4 px, 0.0308 at 1.2 px, 0.0302 at 2 px. Where the
/// history moves, the bump's peak rises from the fresh weight to 1 as well (`temporal_new_weight`):
/// the view changes under a moving camera, and a history that lags it leaves a haze (climbing
/// toward a cloud base, the 4x4 march was 0.0025 brighter in LDR luma than the converged frame over
/// the base). FLIP over the same frames with the peak raised halfway, and all the way: 4x4 0.0297,
/// 0.0296; 2x2 0.0198, 0.0190 (flicker 0.36x, 0.41x the full march's).
pub const MOVING_RAY_SIGMA_PX: f32 = 2.0;

/// How far (pixels) the camera's step must have moved the history by parallax (against the far
/// background) since the previous frame for it to be clipped to the current neighbourhood in
/// full; less clips it in proportion. A still or turning view keeps its history as it is (its
/// reprojection is exact), so features thinner than the grid's spacing, which this frame's rays
/// miss, stay (clipping would keep them only at this frame's rays: the grid's pattern).
pub const CLIP_MOTION_PX: f32 = 2.0;

/// The coarsest grid whose estimate between rays is guided by the history (`upsample_cloud_guided`)
/// and the finer ones' is not. At 4x4 the bilinear estimate blurs a moving edge over 4 px, wider
/// than the moving bump (2 px), and the guide puts the edge where the history has it: fly-through
/// FLIP 0.0302 -> 0.0283 (`docs/temporal.md`, "Edges that keep up"). At 2x2 the blur is 2 px and
/// the guide's lag (it prefers rays like the history) weighs more: 0.0227 -> 0.0235 (300 frames).
pub const GUIDED_DIVISOR: u32 = 4;

/// Seed of the white noise by which the history is rounded to half floats at random
/// (`frame_round_to_half`), apart from every other hash of the pixels.
const ROUNDING_SEED: u32 = 0x7e4a_1d35;

/// The resolve's constants as WGSL.
fn temporal_constants() -> String {
    use crate::shader::WgslConst::{F32, U32};
    crate::shader::wgsl_consts([
        ("TEMPORAL_RAY_SIGMA_PX", F32(RAY_SIGMA_PX)),
        ("TEMPORAL_CLIP_MOTION_PX", F32(CLIP_MOTION_PX)),
        ("TEMPORAL_MOVING_RAY_SIGMA_PX", F32(MOVING_RAY_SIGMA_PX)),
        ("TEMPORAL_ROUNDING_SEED", U32(ROUNDING_SEED)),
        ("TEMPORAL_GUIDED_DIVISOR", U32(GUIDED_DIVISOR)),
    ])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu::layout_check::assert_wgsl_layout;

    #[test]
    fn temporal_uniform_matches_its_wgsl_layout() {
        assert_wgsl_layout!(
            &crate::temporal::TEMPORAL_WGSL,
            "Temporal",
            TemporalUniform {
                prev_clip_from_world,
                prev_camera_position_m,
                history_valid,
                wind_shift_m,
                fresh_weight,
                clip_gamma,
                distance_tolerance,
                reserved_0,
                reserved_1,
            }
        );
    }

    #[test]
    fn halton_is_the_radical_inverse() {
        assert_eq!(halton(1, 2), 0.5);
        assert_eq!(halton(2, 2), 0.25);
        assert_eq!(halton(3, 2), 0.75);
        assert!((halton(1, 3) - 1.0 / 3.0).abs() < 1e-7);
        assert!((halton(5, 3) - 7.0 / 9.0).abs() < 1e-6);
    }

    #[test]
    fn first_own_samples_replace_the_history_then_blend() {
        let s = TemporalSettings {
            divisor: 4,
            ..TemporalSettings::default()
        };
        assert!((0..16).all(|frames| s.fresh_weight_after(frames) == 1.0));
        assert_eq!(s.fresh_weight_after(16), s.fresh_weight());
        assert!(s.fresh_weight() < 0.6);
    }

    #[test]
    fn subpixels_visit_every_pixel_of_a_block_once() {
        for divisor in [1, 2, 4] {
            let mut seen: Vec<UVec2> = (0..divisor * divisor)
                .map(|i| subpixel(i, divisor))
                .collect();
            seen.sort_by_key(|p| (p.y, p.x));
            seen.dedup();
            assert_eq!(seen.len() as u32, divisor * divisor);
        }
        // Consecutive frames land far apart in the block (ordered dither), not side by side.
        assert_eq!(subpixel(0, 2), UVec2::new(0, 0));
        assert_eq!(subpixel(1, 2), UVec2::new(1, 1));
    }

    #[test]
    fn fresh_weight_decays_as_the_per_frame_blend_would() {
        let s = TemporalSettings {
            divisor: 4,
            ..TemporalSettings::default()
        };
        assert!((s.fresh_weight() - (1.0 - 0.95f32.powi(16))).abs() < 1e-6);
        assert!((TemporalSettings { divisor: 1, ..s }.fresh_weight() - 0.05).abs() < 1e-6);
    }
}
