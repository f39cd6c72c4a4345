//! [`SceneRenderer`]: a whole scene to an image, the entry point for offline use (the CLI, tests,
//! benchmarks). Real-time hosts drive the technique passes ([`crate::raymarch::RaymarchRenderer`])
//! with their own depth buffer and frame instead.

use crate::field::gpu::FieldGpu;
use crate::field::{CloudField, FieldError};
use crate::frame::Frame;
use crate::gpu::timing::PassTimer;
use crate::gpu::{GpuContext, readback};
use crate::image::{HdrImage, LdrImage};
use crate::post::{Background, DISPLAY_FORMAT, Display, HDR_FORMAT};
use crate::raymarch::temporal::{TemporalMarch, TemporalSettings};
use crate::raymarch::{
    CLOUD_DEPTH_FORMAT, CLOUD_FORMAT, MarchGrid, MarchSettings, MarchStats, RaymarchRenderer,
    RaymarchTargets,
};
use crate::scene::Scene;
use glam::UVec2;
use std::path::Path;
use std::time::{Duration, Instant};

/// Rows of pixels marched per submission when reporting progress.
const TILE_ROWS: u32 = 32;

/// Names of the GPU passes of one frame, in order.
pub const PASSES: [&str; 4] = ["raymarch", "temporal resolve", "compose", "display"];

/// Whether a frame reuses earlier frames.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Reuse {
    /// Every pixel marched afresh.
    None,
    /// A coarse march plus reprojected history.
    Temporal(TemporalSettings),
}

/// The images of one render.
pub struct Rendered {
    /// Linear HDR radiance.
    pub hdr: HdrImage,
    /// Exposed, tone-mapped, sRGB-encoded.
    pub ldr: LdrImage,
}

/// The render targets of one frame size.
struct Targets {
    size: UVec2,
    depth: wgpu::TextureView,
    clouds: wgpu::TextureView,
    cloud_depth: wgpu::TextureView,
    hdr: wgpu::Texture,
    ldr: wgpu::Texture,
}

impl Targets {
    fn new(ctx: &GpuContext, size: UVec2) -> Targets {
        let texture = |label, format, usage| {
            ctx.device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size: wgpu::Extent3d {
                    width: size.x,
                    height: size.y,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage,
                view_formats: &[],
            })
        };
        use wgpu::TextureUsages as U;
        let storage = U::STORAGE_BINDING | U::TEXTURE_BINDING | U::COPY_SRC;
        let depth = texture(
            "depth",
            wgpu::TextureFormat::Depth32Float,
            U::TEXTURE_BINDING | U::RENDER_ATTACHMENT,
        );
        clear_depth(ctx, &depth);
        Targets {
            size,
            depth: depth.create_view(&Default::default()),
            clouds: texture("clouds", CLOUD_FORMAT, storage).create_view(&Default::default()),
            cloud_depth: texture("cloud depth", CLOUD_DEPTH_FORMAT, storage)
                .create_view(&Default::default()),
            hdr: texture("hdr", HDR_FORMAT, storage),
            ldr: texture("ldr", DISPLAY_FORMAT, storage),
        }
    }
}

/// A depth buffer with nothing in it (1 = far everywhere).
fn clear_depth(ctx: &GpuContext, depth: &wgpu::Texture) {
    let view = depth.create_view(&Default::default());
    let mut encoder = ctx.device.create_command_encoder(&Default::default());
    encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some("clear depth"),
        color_attachments: &[],
        depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
            view: &view,
            depth_ops: Some(wgpu::Operations {
                load: wgpu::LoadOp::Clear(1.0),
                store: wgpu::StoreOp::Store,
            }),
            stencil_ops: None,
        }),
        ..Default::default()
    });
    ctx.queue.submit([encoder.finish()]);
}

/// Renders scenes with the ray marcher over the built-in sky, sun and ground.
pub struct SceneRenderer {
    field: CloudField,
    field_gpu: FieldGpu,
    raymarch: RaymarchRenderer,
    background: Background,
    display: Display,
    targets: Option<Targets>,
    temporal: Option<TemporalMarch>,
    last_reuse: Reuse,
}

impl SceneRenderer {
    /// Builds the field of `scene` (files resolve against `base_dir`) and every pass.
    pub fn new(
        ctx: &GpuContext,
        scene: &Scene,
        base_dir: &Path,
    ) -> Result<SceneRenderer, FieldError> {
        let field = CloudField::new(scene, base_dir)?;
        let field_gpu = FieldGpu::new(ctx, &field);
        let raymarch = RaymarchRenderer::new(ctx, &field_gpu);
        let background = Background::new(ctx, &field_gpu);
        let display = Display::new(ctx);
        Ok(SceneRenderer {
            field,
            field_gpu,
            raymarch,
            background,
            display,
            targets: None,
            temporal: None,
            last_reuse: Reuse::None,
        })
    }

    /// The CPU field this renderer draws (the specification the GPU follows).
    pub fn field(&self) -> &CloudField {
        &self.field
    }

    /// What the ray marcher counted during the last render.
    pub fn march_stats(&self, ctx: &GpuContext) -> MarchStats {
        match (&self.temporal, self.last_reuse) {
            (Some(t), Reuse::Temporal(_)) => t.stats(ctx),
            _ => self.raymarch.stats(ctx),
        }
    }

    /// The field's GPU resources.
    pub fn field_gpu(&self) -> &FieldGpu {
        &self.field_gpu
    }

    fn targets(&mut self, ctx: &GpuContext, size: UVec2) -> &Targets {
        if self.targets.as_ref().is_none_or(|t| t.size != size) {
            self.targets = Some(Targets::new(ctx, size));
        }
        self.targets.as_ref().expect("targets were just created")
    }

    /// Renders `scene` as it describes itself (size, steps, exposure), calling `progress` with the
    /// fraction done after each band of rows.
    pub fn render(
        &mut self,
        ctx: &GpuContext,
        scene: &Scene,
        mut progress: impl FnMut(f32),
    ) -> Rendered {
        let size = UVec2::new(scene.render.width, scene.render.height);
        let frame = Frame::from_scene(scene, size);
        self.last_reuse = Reuse::None;
        self.prepare(ctx, &frame, &MarchSettings::from_scene(scene));
        for row in (0..size.y).step_by(TILE_ROWS as usize) {
            let band = (
                UVec2::new(0, row),
                UVec2::new(size.x, TILE_ROWS.min(size.y - row)),
            );
            let mut encoder = ctx.device.create_command_encoder(&Default::default());
            self.encode_march(ctx, &mut encoder, band, None);
            ctx.queue.submit([encoder.finish()]);
            ctx.wait_idle();
            progress((row + band.1.y) as f32 / size.y as f32);
        }
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        self.encode_post(
            ctx,
            &mut encoder,
            &frame,
            None,
            (scene.render.exposure_ev, scene.render.tonemap),
            None,
        );
        ctx.queue.submit([encoder.finish()]);
        self.read_images(ctx)
    }

    /// Renders one whole frame in a single submission and returns its wall time, with per-pass GPU
    /// times in `timer` when the adapter has timestamp queries: the unit of `cloudscape bench` and
    /// of sequences. With [`Reuse::Temporal`] the march runs on a coarse grid and a history carried
    /// from frame to frame fills in the rest. Read the images with [`SceneRenderer::images`].
    pub fn render_frame(
        &mut self,
        ctx: &GpuContext,
        scene: &Scene,
        frame: &Frame,
        reuse: Reuse,
        timer: &mut PassTimer,
    ) -> Duration {
        let start = Instant::now();
        timer.reset();
        self.last_reuse = reuse;
        let settings = MarchSettings::from_scene(scene);
        self.field_gpu.set_time(ctx, &self.field, frame.time_s);
        self.targets(ctx, frame.size);
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        let clouds = match reuse {
            Reuse::None => {
                self.raymarch
                    .prepare(ctx, frame, &settings, &MarchGrid::FULL);
                self.encode_march(
                    ctx,
                    &mut encoder,
                    (UVec2::ZERO, frame.size),
                    timer.compute_pass_writes(PASSES[0]),
                );
                None
            }
            Reuse::Temporal(temporal) => {
                if self
                    .temporal
                    .as_ref()
                    .is_none_or(|t| *t.settings() != temporal)
                {
                    self.temporal = Some(TemporalMarch::new(ctx, &self.field_gpu, temporal));
                }
                let t = self.targets.as_ref().expect("targets were just made");
                let march = self
                    .temporal
                    .as_mut()
                    .expect("temporal march was just made");
                let wind = self
                    .field
                    .layers
                    .first()
                    .map_or(glam::Vec2::ZERO, |l| l.wind_m_per_s);
                let writes = timer.compute_pass_writes_pair(PASSES[0], PASSES[1]);
                Some(
                    march
                        .encode(
                            ctx,
                            &mut encoder,
                            &self.field_gpu,
                            (frame, &settings, wind),
                            &t.depth,
                            writes,
                        )
                        .clone(),
                )
            }
        };
        self.encode_post(
            ctx,
            &mut encoder,
            frame,
            clouds.as_ref(),
            (scene.render.exposure_ev, scene.render.tonemap),
            Some(timer),
        );
        timer.resolve(&mut encoder);
        ctx.queue.submit([encoder.finish()]);
        ctx.wait_idle();
        start.elapsed()
    }

    /// Forgets the temporal history (a camera cut; new weather).
    pub fn reset_history(&mut self) {
        if let Some(t) = self.temporal.as_mut() {
            t.reset();
        }
    }

    /// The images of the last frame rendered.
    pub fn images(&self, ctx: &GpuContext) -> Rendered {
        self.read_images(ctx)
    }

    fn prepare(&mut self, ctx: &GpuContext, frame: &Frame, settings: &MarchSettings) {
        self.field_gpu.set_time(ctx, &self.field, frame.time_s);
        self.targets(ctx, frame.size);
        self.raymarch
            .prepare(ctx, frame, settings, &MarchGrid::FULL);
    }

    fn encode_march(
        &mut self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        band: (UVec2, UVec2),
        writes: Option<wgpu::ComputePassTimestampWrites>,
    ) {
        let t = self.targets.as_ref().expect("prepare creates the targets");
        let targets = RaymarchTargets {
            depth: &t.depth,
            clouds: &t.clouds,
            cloud_depth: &t.cloud_depth,
        };
        self.raymarch
            .encode(ctx, encoder, &self.field_gpu, &targets, band, writes);
    }

    /// Composes `clouds` (the still march's target when None) over the background and maps it for
    /// display.
    fn encode_post(
        &self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        frame: &Frame,
        clouds: Option<&wgpu::TextureView>,
        display: (f32, crate::scene::Tonemap),
        mut timer: Option<&mut PassTimer>,
    ) {
        let t = self.targets.as_ref().expect("prepare creates the targets");
        let hdr = t.hdr.create_view(&Default::default());
        let ldr = t.ldr.create_view(&Default::default());
        let writes = timer
            .as_deref_mut()
            .and_then(|t| t.compute_pass_writes(PASSES[2]));
        self.background.encode(
            ctx,
            encoder,
            &self.field_gpu,
            frame,
            (clouds.unwrap_or(&t.clouds), &hdr),
            writes,
        );
        let writes = timer.and_then(|t| t.compute_pass_writes(PASSES[3]));
        self.display
            .encode(ctx, encoder, (&hdr, &ldr), frame.size, display, writes);
    }

    fn read_images(&self, ctx: &GpuContext) -> Rendered {
        let t = self.targets.as_ref().expect("render creates the targets");
        let (w, h) = (t.size.x, t.size.y);
        let hdr = HdrImage {
            width: w,
            height: h,
            pixels: readback::read_texture_rgba16f(ctx, &t.hdr),
        };
        let bytes = readback::read_texture(ctx, &t.ldr);
        let ldr = LdrImage {
            width: w,
            height: h,
            pixels: bytemuck::cast_slice(&bytes).to_vec(),
        };
        Rendered { hdr, ldr }
    }
}
