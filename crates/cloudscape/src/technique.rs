//! The technique trait: one way of turning the cloud field into the [`CloudOutput`] contract.
//!
//! A technique reads the shared groups ([`Shared`]: field, frame, environment) and the host's
//! depth buffer, and writes radiance, transmittance and cloud distance for the rays of the frame's
//! [`crate::output::SampleGrid`]. It never draws the sky, applies haze, tone-maps or keeps history:
//! temporal reuse, upsampling and compositing serve every technique from its output.

use crate::environment::Environment;
use crate::field::{CloudField, FieldError};
use crate::frame::Frame;
use crate::gpu::{GpuContext, PassTimer};
use crate::output::{CloudOutput, SampleGrid};
use crate::pass::Shared;
use crate::scene::Scene;
use glam::UVec2;
use std::path::Path;

/// What a technique counted in a frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TechniqueStats {
    /// Output texels written.
    pub pixels: u32,
    /// Extinction evaluations along view rays per texel (for particles: particle segments
    /// blended per texel; for sprites: layers of sprites per texel, from their projected areas).
    pub density_samples_per_pixel: f64,
    /// Primitives drawn (particles, sprites); None for techniques without them.
    pub primitives: Option<u32>,
}

/// Which of a scene's clouds a technique draws.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Draws {
    /// The cloud layers of the field (`[[layers]]`, or a METAR report's).
    pub layers: bool,
    /// Voxel grids (`[[volumes]]`).
    pub voxel_grids: bool,
    /// Hand-made sprite clouds (`[[sprite_clouds]]`) and sprite model files (`sprites.model`).
    pub sprite_clouds: bool,
}

impl Draws {
    /// Whether `scene` holds any cloud of a kind drawn.
    pub fn any_of(&self, scene: &Scene) -> bool {
        let sprite_clouds = !scene.sprite_clouds.is_empty() || scene.sprites.model.is_some();
        (self.layers && !scene.layers.is_empty())
            || (self.voxel_grids && !scene.volumes.is_empty())
            || (self.sprite_clouds && sprite_clouds)
    }
}

/// What a frame is made of, on the CPU: the field, the host's view, sun and clock, the environment
/// they make and the sample grid of the output. Techniques that work on the CPU (generating
/// particles, sprites) read the camera here, as the host set it. The scene is not here: a
/// technique reads it in [`Technique::configure`], not per frame.
#[derive(Clone, Copy)]
pub struct FrameInputs<'a> {
    /// The cloud field (the CPU specification).
    pub field: &'a CloudField,
    /// The host's camera, projection, depth convention, sun and time.
    pub frame: &'a Frame,
    /// The frame's sun, sky and haze.
    pub environment: &'a Environment,
    /// The rays the output holds.
    pub grid: &'a SampleGrid,
    /// The shared GPU groups as this frame set them (the field at the frame's time), for work
    /// whose result the CPU needs before encoding (reading the field at many points).
    pub shared: Shared<'a>,
    /// Whether the host renders a stream of frames and carries work across them (it set
    /// [`crate::shadow::LightingReuse`]): a technique may spread remaking what an edit changed
    /// over frames, drawing what it had until it is replaced. A still (false) is complete.
    pub real_time: bool,
}

/// Where a technique reads and writes.
pub struct TechniqueTargets<'a> {
    /// The host's depth buffer (Depth32Float, at the frame's full resolution, in the frame's
    /// [`crate::frame::DepthConvention`]).
    pub host_depth: &'a wgpu::TextureView,
    /// The output, at the sample grid's resolution.
    pub output: &'a CloudOutput,
}

/// One way of rendering the clouds. Made once; [`Technique::prepare`] and [`Technique::encode`]
/// every frame allocate nothing. Send and Sync, so that a host (a game engine's render thread) can
/// keep a renderer in shared state.
pub trait Technique: Send + Sync {
    /// The scene-file name (`render.technique`).
    fn name(&self) -> &'static str;

    /// Which clouds it draws.
    fn draws(&self) -> Draws;

    /// The labels its passes are timed under, in the order it records them.
    fn pass_names(&self) -> &'static [&'static str];

    /// The resolution divisor (1, 2 or 4) of its output in frames without temporal reuse; the
    /// shared upsampling brings it to full resolution.
    fn still_divisor(&self) -> u32 {
        1
    }

    /// Takes the scene's settings (steps, lighting, phase function, its own section) and reads
    /// the files they name that only it draws (a sprite model; relative paths resolve against
    /// `base_dir`; an unreadable one is an error at its scene key). Called when the technique is
    /// built and after every edit of the scene, never per frame.
    fn configure(
        &mut self,
        ctx: &GpuContext,
        scene: &Scene,
        base_dir: &Path,
    ) -> Result<(), FieldError>;

    /// Takes this frame's view, sun and clock.
    fn prepare(&mut self, ctx: &GpuContext, inputs: &FrameInputs);

    /// Records what a frame does once, before any of its rays: making its particles, rendering
    /// impostors, clearing counters. The renderer calls it once per frame, before the frame's
    /// first [`Technique::encode`]; its passes are timed under their own names.
    fn encode_frame_setup(
        &mut self,
        _ctx: &GpuContext,
        _encoder: &mut wgpu::CommandEncoder,
        _shared: &Shared,
        _targets: &TechniqueTargets,
        _timer: Option<&mut PassTimer>,
    ) {
    }

    /// Records the technique over the output texels `region` (origin, size): the whole output, or
    /// one band of it when a long render reports progress (then submit each band before encoding
    /// the next). Passes are timed under `label` when `timer` is given.
    fn encode(
        &mut self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        shared: &Shared,
        targets: &TechniqueTargets,
        region: (UVec2, UVec2),
        timer: Option<(&mut PassTimer, &str)>,
    );

    /// Marks the end of a frame's encoding: copies its statistics out, to be read without waiting.
    fn finish_frame(&mut self, encoder: &mut wgpu::CommandEncoder);

    /// The statistics of the newest frame the GPU has finished (never waits; None before any).
    /// Whether the technique reads the environment's light volume (the frame solves it then).
    fn reads_light_volume(&self) -> bool {
        false
    }

    fn stats(&mut self, ctx: &GpuContext) -> Option<TechniqueStats>;
}
