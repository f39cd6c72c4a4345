//! After the clouds: composing them over the sky, sun and ground, and tone mapping HDR radiance
//! for display. Each is a compute pass with one entry type.

pub mod tonemap;

use crate::field::gpu::{FIELD_WGSL, FieldGpu, NOISE_WGSL};
use crate::frame::{FRAME_WGSL, Frame};
use crate::gpu::GpuContext;
use crate::gpu::pipeline::{
    UNIFORM, bind_group, bind_group_layout, compute_pipeline, dispatch_2d, float_texture,
    storage_texture_2d, uniform_buffer,
};
use crate::scene::Tonemap;
use wgpu::util::DeviceExt;

const COMPOSE_WGSL: &str = include_str!("compose.wgsl");
const DISPLAY_WGSL: &str = include_str!("display.wgsl");

/// Format of the composed HDR image.
pub const HDR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
/// Format of the display image (sRGB-encoded values in a unorm texture, storage-writable everywhere).
pub const DISPLAY_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;

/// Source of the compose program.
pub fn compose_source() -> String {
    [NOISE_WGSL, FIELD_WGSL, FRAME_WGSL, COMPOSE_WGSL].concat()
}

/// Source of the display program.
pub fn display_source() -> String {
    [tonemap::TONEMAP_WGSL, DISPLAY_WGSL].concat()
}

/// Composes the cloud target over the sky, the sun's disc and the ground in the clouds' shadows.
pub struct Background {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    frame: wgpu::Buffer,
}

impl Background {
    /// Builds the pass against the field's bind group (for the planet's shape).
    pub fn new(ctx: &GpuContext, field: &FieldGpu) -> Background {
        let d2 = wgpu::TextureViewDimension::D2;
        let layout = bind_group_layout(
            &ctx.device,
            "compose",
            &[UNIFORM, float_texture(d2), storage_texture_2d(HDR_FORMAT)],
        );
        let pipeline = compute_pipeline(
            ctx,
            "compose",
            &compose_source(),
            "compose_background",
            &[field.layout(), &layout],
        );
        let frame = uniform_buffer(
            ctx,
            "compose frame",
            size_of::<crate::frame::FrameUniform>() as u64,
        );
        Background {
            pipeline,
            layout,
            frame,
        }
    }

    /// Records `hdr = background * clouds.a + clouds.rgb` for `frame`.
    pub fn encode(
        &self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        field: &FieldGpu,
        frame: &Frame,
        (clouds, hdr): (&wgpu::TextureView, &wgpu::TextureView),
        timestamps: Option<wgpu::ComputePassTimestampWrites>,
    ) {
        ctx.queue
            .write_buffer(&self.frame, 0, bytemuck::bytes_of(&frame.uniform()));
        let group = bind_group(
            &ctx.device,
            &self.layout,
            &[
                self.frame.as_entire_binding(),
                wgpu::BindingResource::TextureView(clouds),
                wgpu::BindingResource::TextureView(hdr),
            ],
        );
        dispatch_2d(
            encoder,
            "compose",
            &self.pipeline,
            &[field.bind_group(), &group],
            frame.size,
            timestamps,
        );
    }
}

/// Exposure, tone mapping and sRGB encoding into a [`DISPLAY_FORMAT`] texture.
pub struct Display {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
}

impl Display {
    /// Builds the pass.
    pub fn new(ctx: &GpuContext) -> Display {
        let layout = bind_group_layout(
            &ctx.device,
            "display",
            &[
                UNIFORM,
                float_texture(wgpu::TextureViewDimension::D2),
                storage_texture_2d(DISPLAY_FORMAT),
            ],
        );
        let pipeline = compute_pipeline(
            ctx,
            "display",
            &display_source(),
            "display_hdr_image",
            &[&layout],
        );
        Display { pipeline, layout }
    }

    /// Records the mapping of `hdr` into `out` (same size).
    pub fn encode(
        &self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        (hdr, out): (&wgpu::TextureView, &wgpu::TextureView),
        size: glam::UVec2,
        (exposure_ev, operator): (f32, Tonemap),
        timestamps: Option<wgpu::ComputePassTimestampWrites>,
    ) {
        let params = [2f32.powf(exposure_ev).to_bits(), operator as u32, 0, 0];
        let uniform = ctx
            .device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("display"),
                contents: bytemuck::cast_slice(&params),
                usage: wgpu::BufferUsages::UNIFORM,
            });
        let group = bind_group(
            &ctx.device,
            &self.layout,
            &[
                uniform.as_entire_binding(),
                wgpu::BindingResource::TextureView(hdr),
                wgpu::BindingResource::TextureView(out),
            ],
        );
        dispatch_2d(
            encoder,
            "display",
            &self.pipeline,
            &[&group],
            size,
            timestamps,
        );
    }
}
