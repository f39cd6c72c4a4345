//! Renderers: [`CloudRenderer`], the clouds on a host's device, depth buffer and scene colour
//! (what a game engine uses), and [`SceneRenderer`], the offline host that the CLI, tests and
//! benchmarks use: a whole scene to an image over the built-in sky, sun and ground.

mod dispatch;
mod host;

pub use dispatch::draws;
pub use host::{CloudRenderer, FieldUpdate, FrameImages, Reuse, needs_update};

use crate::field::{CloudField, FieldError};
use crate::frame::Frame;
use crate::gpu::pipeline::{clear_depth, texture_2d};
use crate::gpu::{GpuContext, PassTimer, readback};
use crate::image::{HdrImage, LdrImage};
use crate::post::{Background, HDR_FORMAT};
use crate::scene::{Scene, Technique};
use crate::technique::TechniqueStats;
use glam::UVec2;
use std::path::Path;
use std::time::{Duration, Instant};

/// Rows of output texels rendered per submission when reporting progress.
const TILE_ROWS: u32 = 32;

/// GPU passes of one frame at most: the environment's (the shadow map, up to five sky tables and
/// the light volume's three), the technique's (up to three), the temporal resolve or the upsampling, compose and display
/// ([`CloudRenderer::pass_names`]); a [`PassTimer`] of this capacity times them all.
pub const PASS_COUNT: u32 = 15;

/// The images of one render.
pub struct Rendered {
    /// Linear HDR radiance.
    pub hdr: HdrImage,
    /// Exposed, tone-mapped, sRGB-encoded.
    pub ldr: LdrImage,
}

/// An offline host's empty scene: a depth buffer with no geometry and a colour never shown, for a
/// host that draws only the clouds and the built-in sky, sun and ground.
pub struct EmptyHost {
    size: UVec2,
    convention: crate::frame::DepthConvention,
    depth: wgpu::TextureView,
    color: wgpu::TextureView,
}

impl EmptyHost {
    /// The empty scene of `frame`: its size and depth convention, the depth cleared to far.
    pub fn new(ctx: &GpuContext, frame: &Frame) -> EmptyHost {
        let size = frame.size;
        use wgpu::TextureUsages as U;
        let usage = U::TEXTURE_BINDING | U::RENDER_ATTACHMENT;
        let depth = texture_2d(ctx, "depth", size, wgpu::TextureFormat::Depth32Float, usage)
            .create_view(&Default::default());
        let color = texture_2d(ctx, "host colour", size, HDR_FORMAT, U::TEXTURE_BINDING)
            .create_view(&Default::default());
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        clear_depth(&mut encoder, &depth, frame.depth.far_value());
        ctx.queue.submit([encoder.finish()]);
        EmptyHost {
            size,
            convention: frame.depth,
            depth,
            color,
        }
    }

    /// Whether this is the empty scene of `frame` (same size and depth convention).
    pub fn fits(&self, frame: &Frame) -> bool {
        self.size == frame.size && self.convention == frame.depth
    }

    /// The depth buffer, for [`CloudRenderer::encode_clouds`].
    pub fn depth(&self) -> &wgpu::TextureView {
        &self.depth
    }

    /// The background, for [`CloudRenderer::encode_finish`].
    pub fn background(&self) -> Background<'_> {
        Background {
            color: &self.color,
            depth: &self.depth,
        }
    }
}

/// Renders scenes with the technique they name over the built-in sky, sun and ground, and reads the
/// images back: an offline host of [`CloudRenderer`] that waits for the GPU to time its frames.
pub struct SceneRenderer {
    clouds: CloudRenderer,
    host: Option<EmptyHost>,
    /// The scene drawn by [`SceneRenderer::render`]: its settings and its frame.
    scene: Scene,
}

impl SceneRenderer {
    /// Builds the field of `scene` (files resolve against `base_dir`) and every pass.
    pub fn new(
        ctx: &GpuContext,
        scene: &Scene,
        base_dir: &Path,
    ) -> Result<SceneRenderer, FieldError> {
        Ok(SceneRenderer {
            clouds: CloudRenderer::new(ctx, scene, base_dir)?,
            host: None,
            scene: scene.clone(),
        })
    }

    /// Takes `scene` in place of the one drawn, rebuilding only what it changed
    /// ([`CloudRenderer::apply_edit`]; returns what the field update did, if there was one).
    pub fn set_scene(
        &mut self,
        ctx: &GpuContext,
        scene: &Scene,
        base_dir: &Path,
    ) -> Result<Option<FieldUpdate>, FieldError> {
        let update = self.clouds.apply_edit(ctx, scene, base_dir)?;
        self.scene = scene.clone();
        Ok(update)
    }

    /// The CPU field this renderer draws (the specification the GPU follows).
    pub fn field(&self) -> &CloudField {
        self.clouds.field()
    }

    /// The labels of a frame's passes ([`CloudRenderer::pass_names`]).
    pub fn pass_names(&self) -> Vec<&'static str> {
        self.clouds.pass_names()
    }

    /// The renderer a real-time host would drive.
    pub fn clouds(&mut self) -> &mut CloudRenderer {
        &mut self.clouds
    }

    /// What the technique counted during the last render (waits for it).
    pub fn stats(&mut self, ctx: &GpuContext) -> Option<TechniqueStats> {
        ctx.wait_idle();
        self.clouds.stats(ctx)
    }

    fn host(&mut self, ctx: &GpuContext, frame: &Frame) -> &EmptyHost {
        if self.host.as_ref().is_none_or(|h| !h.fits(frame)) {
            self.host = Some(EmptyHost::new(ctx, frame));
        }
        self.host.as_ref().expect("the host was just made")
    }

    /// Renders the scene as it describes itself (its frame, size, steps, exposure), calling
    /// `progress` with the fraction done after each band of rows.
    ///
    /// The ray marcher spreads its `render.samples_per_pixel` over each pixel itself. The
    /// rasterising techniques (particles, sprites) draw the whole frame once per sample, each
    /// through its own point of the pixel ([`Frame::footprint_point`], a sub-pixel shift of the
    /// projection), and the HDR frames are averaged: the pixel's footprint, as the path tracer
    /// integrates it. The samples share one lighting: the first frame makes the environment (shadow
    /// map, sky tables, light volume), and the others redo only the aerial perspective laid over
    /// their view ([`CloudRenderer::begin_shifted_frame`]).
    pub fn render(&mut self, ctx: &GpuContext, mut progress: impl FnMut(f32)) -> Rendered {
        let render = &self.scene.render;
        let frame = Frame::from_scene(&self.scene, UVec2::new(render.width, render.height));
        let samples = match render.technique {
            Technique::Raymarch => 1,
            Technique::Particles | Technique::Sprites => render.samples_per_pixel.unwrap_or(1),
        };
        if samples <= 1 {
            return self.render_in_bands(ctx, (&frame, false), &mut progress);
        }
        let (exposure_ev, tonemap) = (render.exposure_ev, render.tonemap);
        let mut sum = HdrImage::new(frame.size.x, frame.size.y);
        for index in 0..samples {
            let shifted = frame.footprint_sample(index, samples);
            let done = index as f32;
            let hdr = self
                .render_in_bands(ctx, (&shifted, index > 0), &mut |f| {
                    progress((done + f) / samples as f32)
                })
                .hdr;
            sum.add_scaled(&hdr, 1.0 / samples as f32);
        }
        let ldr = sum.to_ldr(exposure_ev, tonemap);
        Rendered { hdr: sum, ldr }
    }

    /// Renders `frame` in bands of [`TILE_ROWS`] output rows, one submission each, calling
    /// `progress` with the fraction done after each; `shifted`: over the environment of the frame
    /// before ([`CloudRenderer::begin_shifted_frame`]).
    fn render_in_bands(
        &mut self,
        ctx: &GpuContext,
        (frame, shifted): (&Frame, bool),
        progress: &mut dyn FnMut(f32),
    ) -> Rendered {
        self.host(ctx, frame);
        let host = self.host.as_ref().expect("made above");
        if shifted {
            self.clouds.begin_shifted_frame(ctx, frame);
        } else {
            self.clouds.begin_frame(ctx, frame, Reuse::None);
        }
        let output = self.clouds.output_size();
        for row in (0..output.y).step_by(TILE_ROWS as usize) {
            let band = (
                UVec2::new(0, row),
                UVec2::new(output.x, TILE_ROWS.min(output.y - row)),
            );
            let mut encoder = ctx.device.create_command_encoder(&Default::default());
            self.clouds
                .encode_clouds(ctx, &mut encoder, &host.depth, Some(band), None);
            ctx.queue.submit([encoder.finish()]);
            ctx.wait_idle();
            progress((row + band.1.y) as f32 / output.y as f32);
        }
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        self.clouds
            .encode_finish(ctx, &mut encoder, &host.background(), None);
        ctx.queue.submit([encoder.finish()]);
        self.images(ctx)
    }

    /// Renders one whole frame in a single submission and returns its wall time (it waits for the
    /// GPU), with per-pass GPU times in `timer` when the adapter has timestamp queries: the unit of
    /// `cloudscape bench` and of sequences. With [`Reuse::Temporal`] the technique renders a coarse
    /// grid and a history carried from frame to frame fills in the rest. Read the images with
    /// [`SceneRenderer::images`].
    pub fn render_frame(
        &mut self,
        ctx: &GpuContext,
        frame: &Frame,
        reuse: Reuse,
        timer: &mut PassTimer,
    ) -> Duration {
        let start = Instant::now();
        timer.reset();
        self.host(ctx, frame);
        let host = self.host.as_ref().expect("made above");
        self.clouds.begin_frame(ctx, frame, reuse);
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        self.clouds
            .encode_clouds(ctx, &mut encoder, &host.depth, None, Some(timer));
        self.clouds
            .encode_finish(ctx, &mut encoder, &host.background(), Some(timer));
        timer.resolve(&mut encoder);
        ctx.queue.submit([encoder.finish()]);
        ctx.wait_idle();
        start.elapsed()
    }

    /// Forgets the temporal history (a camera cut; new weather).
    pub fn reset_history(&mut self) {
        self.clouds.reset_history();
    }

    /// The images of the last frame rendered (waits for it).
    pub fn images(&self, ctx: &GpuContext) -> Rendered {
        read_back(ctx, &self.clouds.images())
    }
}

/// Reads a frame's composed HDR and tone-mapped images back (waits for the GPU).
pub fn read_back(ctx: &GpuContext, images: &FrameImages) -> Rendered {
    let (width, height) = (images.hdr.width(), images.hdr.height());
    let hdr = HdrImage {
        width,
        height,
        pixels: readback::read_texture_rgba16f(ctx, images.hdr),
    };
    let bytes = readback::read_texture(ctx, images.ldr);
    let ldr = LdrImage {
        width,
        height,
        pixels: bytemuck::cast_slice(&bytes).to_vec(),
    };
    Rendered { hdr, ldr }
}

/// The root WGSL module of every program the crate builds (each with entry points), for tools and
/// tests: every `.wgsl` file of the crate is reached from one of them.
pub static PROGRAMS: &[&crate::shader::WgslModule] = &[
    &crate::field::gpu::NOISE_GEN_WGSL,
    &crate::field::read_gpu::FIELD_READ_WGSL,
    &crate::environment::ATMOSPHERE_LUTS_WGSL,
    &crate::environment::ATMOSPHERE_AERIAL_WGSL,
    &crate::environment::CLOUD_SHADOW_WGSL,
    &crate::environment::light_volume::LIGHT_VOLUME_WGSL,
    &crate::raymarch::RAYMARCH_WGSL,
    &crate::temporal::TEMPORAL_WGSL,
    &crate::post::upsample::UPSAMPLE_STILL_WGSL,
    &crate::post::COMPOSE_WGSL,
    &crate::post::DISPLAY_WGSL,
    &crate::probe::PROBE_WGSL,
    &crate::particles::gpu::PARTICLE_BAKE_WGSL,
    &crate::particles::generate_gpu::PARTICLE_GENERATE_WGSL,
    &crate::particles::occlusion_gpu::PARTICLE_OCCLUSION_WGSL,
    &crate::particles::render::PARTICLE_RENDER_WGSL,
    &crate::sprites::render::SPRITE_RENDER_WGSL,
    &crate::sprites::render::SPRITE_IMPOSTOR_WGSL,
    &crate::sprites::render::SPRITE_RESOLVE_WGSL,
];
