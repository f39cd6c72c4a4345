//! Presenting to the window: the swapchain (resized, minimised, outdated or lost without a crash),
//! the rendered image upscaled into the viewport, and the panels drawn over it.

use std::sync::Arc;

use anyhow::{Result, anyhow};
use cloudscape::gpu::GpuContext;
use winit::window::Window;

/// The panels' triangles and textures of one frame, in physical pixels.
pub struct PanelPaint<'a> {
    /// egui's tessellated shapes.
    pub primitives: &'a [egui::ClippedPrimitive],
    /// Font and image textures to upload or free.
    pub textures: &'a egui::TexturesDelta,
    /// Window size and scale.
    pub screen: &'a egui_wgpu::ScreenDescriptor,
}

/// The rendered image and the window rectangle it fills: origin and size in physical pixels.
pub struct ViewImage<'a> {
    /// The tone-mapped image ([`cloudscape::post::DISPLAY_FORMAT`], sRGB-encoded values).
    pub texture: &'a wgpu::Texture,
    /// Where in the window it goes.
    pub viewport: ([u32; 2], [u32; 2]),
}

/// The swapchain and what draws into it.
pub struct Presenter {
    window: Arc<Window>,
    surface: wgpu::Surface<'static>,
    config: wgpu::SurfaceConfiguration,
    blit: Blit,
    panels: egui_wgpu::Renderer,
    /// The swapchain no longer matches the window: configure it before the next image (not while
    /// an image of it is held).
    stale: bool,
}

impl Presenter {
    /// Configures `surface` for `window` (a format egui and the blit can write as given, when the
    /// surface offers one) with vsync on or off.
    pub fn new(
        ctx: &GpuContext,
        window: Arc<Window>,
        surface: wgpu::Surface<'static>,
        vsync: bool,
    ) -> Result<Presenter> {
        let capabilities = surface.get_capabilities(ctx.adapter());
        let format = egui_wgpu::preferred_framebuffer_format(&capabilities.formats)
            .map_err(|e| anyhow!("the window offers no surface format: {e}"))?;
        let size = window.inner_size();
        let mut config = surface
            .get_default_config(ctx.adapter(), size.width.max(1), size.height.max(1))
            .ok_or_else(|| anyhow!("the adapter cannot present to this window"))?;
        config.format = format;
        config.present_mode = present_mode(vsync);
        let panels = egui_wgpu::Renderer::new(&ctx.device, format, Default::default());
        let mut presenter = Presenter {
            blit: Blit::new(ctx, format),
            window,
            surface,
            config,
            panels,
            stale: false,
        };
        presenter.configure(ctx);
        Ok(presenter)
    }

    /// The format of the window's images.
    pub fn format(&self) -> wgpu::TextureFormat {
        self.config.format
    }

    /// Follows the window's size; a zero size (minimised) is kept until the window is back.
    pub fn resize(&mut self, ctx: &GpuContext, width: u32, height: u32) {
        (self.config.width, self.config.height) = (width, height);
        self.configure(ctx);
    }

    /// Turns vsync on or off.
    pub fn set_vsync(&mut self, ctx: &GpuContext, vsync: bool) {
        self.config.present_mode = present_mode(vsync);
        self.configure(ctx);
    }

    /// Whether the window has an area to draw into (it is not minimised).
    pub fn visible(&self) -> bool {
        self.config.width > 0 && self.config.height > 0
    }

    fn configure(&mut self, ctx: &GpuContext) {
        if self.visible() {
            self.surface.configure(&ctx.device, &self.config);
        }
    }

    /// The next image of the swapchain, or None to skip this frame: the window is minimised or
    /// hidden, the swapchain timed out, or it was outdated or lost (then it is made again for the
    /// next frame).
    pub fn acquire(&mut self, ctx: &GpuContext) -> Option<wgpu::SurfaceTexture> {
        use wgpu::CurrentSurfaceTexture as Current;
        if !self.visible() {
            return None;
        }
        if std::mem::take(&mut self.stale) {
            self.configure(ctx);
        }
        match self.surface.get_current_texture() {
            Current::Success(texture) => Some(texture),
            Current::Suboptimal(texture) => {
                self.stale = true;
                Some(texture)
            }
            Current::Outdated => {
                let size = self.window.inner_size();
                self.resize(ctx, size.width, size.height);
                None
            }
            Current::Lost => {
                self.recreate(ctx);
                None
            }
            Current::Timeout | Current::Occluded | Current::Validation => None,
        }
    }

    /// Makes a new surface for the window after the old one was lost.
    fn recreate(&mut self, ctx: &GpuContext) {
        match ctx.create_surface(self.window.clone()) {
            Ok(surface) => {
                self.surface = surface;
                self.configure(ctx);
            }
            Err(error) => eprintln!("warning: {error}; trying again next frame"),
        }
    }

    /// Records the frame into `target`: the image into its viewport, then the panels over it.
    pub fn encode(
        &mut self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        target: &wgpu::TextureView,
        image: Option<&ViewImage>,
        paint: &PanelPaint,
    ) {
        for (id, deltas) in &paint.textures.set {
            for delta in deltas {
                self.panels
                    .update_texture(&ctx.device, &ctx.queue, *id, delta);
            }
        }
        let extra = self.panels.update_buffers(
            &ctx.device,
            &ctx.queue,
            encoder,
            paint.primitives,
            paint.screen,
        );
        debug_assert!(extra.is_empty(), "no paint callbacks are used");
        let mut pass = encoder
            .begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("window"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: target,
                    resolve_target: None,
                    depth_slice: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                ..Default::default()
            })
            .forget_lifetime();
        if let Some(image) = image {
            self.blit.draw(ctx, &mut pass, image);
        }
        self.panels
            .render(&mut pass, paint.primitives, paint.screen);
    }

    /// Frees the panels' textures that egui no longer uses; call after the frame is submitted.
    pub fn free_textures(&mut self, textures: &egui::TexturesDelta) {
        textures
            .free
            .iter()
            .for_each(|id| self.panels.free_texture(id));
    }
}

/// FIFO waits for the display; without vsync the newest frame replaces the queued one, or tears.
fn present_mode(vsync: bool) -> wgpu::PresentMode {
    if vsync {
        wgpu::PresentMode::AutoVsync
    } else {
        wgpu::PresentMode::AutoNoVsync
    }
}

/// The pass that upscales the rendered image into the viewport.
struct Blit {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    sampler: wgpu::Sampler,
    /// The bind group of the image last drawn, remade when the renderer makes a new image.
    bound: Option<(wgpu::Texture, wgpu::BindGroup)>,
}

impl Blit {
    fn new(ctx: &GpuContext, format: wgpu::TextureFormat) -> Blit {
        let device = &ctx.device;
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("blit"),
            source: wgpu::ShaderSource::Wgsl(include_str!("blit.wgsl").into()),
        });
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("blit"),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Float { filterable: true },
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 1,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                    count: None,
                },
            ],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("blit"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let fragment = if format.is_srgb() {
            "blit_linear"
        } else {
            "blit_encoded"
        };
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("blit"),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("blit_vertex"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some(fragment),
                compilation_options: Default::default(),
                targets: &[Some(format.into())],
            }),
            primitive: Default::default(),
            depth_stencil: None,
            multisample: Default::default(),
            multiview_mask: None,
            cache: None,
        });
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("blit"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        });
        Blit {
            pipeline,
            layout,
            sampler,
            bound: None,
        }
    }

    fn draw(&mut self, ctx: &GpuContext, pass: &mut wgpu::RenderPass<'static>, image: &ViewImage) {
        if self.bound.as_ref().is_none_or(|(t, _)| t != image.texture) {
            let view = image.texture.create_view(&Default::default());
            let group = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("blit"),
                layout: &self.layout,
                entries: &[
                    wgpu::BindGroupEntry {
                        binding: 0,
                        resource: wgpu::BindingResource::TextureView(&view),
                    },
                    wgpu::BindGroupEntry {
                        binding: 1,
                        resource: wgpu::BindingResource::Sampler(&self.sampler),
                    },
                ],
            });
            self.bound = Some((image.texture.clone(), group));
        }
        let (_, group) = self.bound.as_ref().expect("bound above");
        let ([x, y], [w, h]) = image.viewport;
        pass.set_viewport(x as f32, y as f32, w as f32, h as f32, 0.0, 1.0);
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, group, &[]);
        pass.draw(0..3, 0..1);
    }
}
