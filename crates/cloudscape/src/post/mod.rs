//! After the technique and temporal reuse: composing the full-resolution cloud output over what
//! lies behind it (the host's geometry, or the sky, sun and ground), with aerial perspective applied
//! once, and tone mapping HDR radiance for display. Each is a compute pass with one entry type,
//! made once; bind groups are remade only when the targets change.

pub mod tonemap;
pub mod upsample;

use crate::frame::{Shared, SharedSlots};
use crate::gpu::pipeline::{
    BindGroupCache, UNFILTERABLE_TEXTURE_2D, UNIFORM, bind_group, bind_group_layout,
    compute_pipeline, dispatch_2d, float_texture, storage_texture_2d, uniform_buffer,
};
use crate::gpu::{GpuContext, PassTimer};
use crate::output::CloudOutput;
use crate::scene::Tonemap;
use bytemuck::{Pod, Zeroable};
use glam::UVec2;

/// Format of the composed HDR image.
pub const HDR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
/// Format of the display image (sRGB-encoded values in a unorm texture, storage-writable everywhere).
pub const DISPLAY_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;

/// What lies behind the clouds: the host's colour and depth at full resolution. Where the depth
/// holds geometry its colour is the background; elsewhere the sky, sun and ground are.
pub struct Background<'a> {
    /// Host scene radiance (any float-sampled colour format).
    pub color: &'a wgpu::TextureView,
    /// Host depth buffer, in the frame's depth convention.
    pub depth: &'a wgpu::TextureView,
}

/// Composes a full-resolution cloud output over the background: `background * a + hazed rgb`.
pub struct Compositor {
    slots: SharedSlots,
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    group: BindGroupCache,
}

impl Compositor {
    /// Builds the pass against the shared groups' layouts.
    pub fn new(ctx: &GpuContext, shared: &Shared) -> Compositor {
        let d2 = wgpu::TextureViewDimension::D2;
        let layout = bind_group_layout(
            &ctx.device,
            "compose",
            &[
                float_texture(d2),
                UNFILTERABLE_TEXTURE_2D,
                UNFILTERABLE_TEXTURE_2D,
                UNFILTERABLE_TEXTURE_2D,
                storage_texture_2d(HDR_FORMAT),
            ],
        );
        let pipeline = compute_pipeline(
            ctx,
            "compose",
            &crate::shader::program("compose"),
            "compose_clouds_over_background",
            &shared.layouts(SharedSlots::of("compose"), &layout),
        );
        Compositor {
            slots: SharedSlots::of("compose"),
            pipeline,
            layout,
            group: BindGroupCache::default(),
        }
    }

    /// Records the composition of `clouds` over `background` into `hdr` ([`HDR_FORMAT`], storage).
    pub fn encode(
        &mut self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        shared: &Shared,
        (clouds, background): (&CloudOutput, &Background),
        hdr: &wgpu::TextureView,
        timer: Option<&mut PassTimer>,
    ) {
        let views = [
            &clouds.radiance,
            &clouds.distance,
            background.color,
            background.depth,
            hdr,
        ];
        let layout = &self.layout;
        let group = self.group.get(&views, || {
            let resources = views.map(wgpu::BindingResource::TextureView);
            bind_group(&ctx.device, layout, &resources)
        });
        let writes = timer.and_then(|t| t.compute_pass_writes("compose"));
        dispatch_2d(
            encoder,
            "compose",
            &self.pipeline,
            &shared.bind_groups(self.slots, group),
            clouds.size,
            writes,
        );
    }
}

/// The `Display` uniform of `display.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct DisplayUniform {
    exposure_scale: f32,
    tonemap_operator: u32,
}

/// Exposure, tone mapping and sRGB encoding into a [`DISPLAY_FORMAT`] texture.
pub struct Display {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    uniform: wgpu::Buffer,
    group: BindGroupCache,
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
            &crate::shader::program("display"),
            "display_hdr_image",
            &[None, None, None, Some(&layout)],
        );
        Display {
            pipeline,
            layout,
            uniform: uniform_buffer(ctx, "display", size_of::<DisplayUniform>() as u64),
            group: BindGroupCache::default(),
        }
    }

    /// Records the mapping of `hdr` into `out` (both `size` pixels).
    pub fn encode(
        &mut self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        (hdr, out, size): (&wgpu::TextureView, &wgpu::TextureView, UVec2),
        (exposure_ev, operator): (f32, Tonemap),
        timer: Option<&mut PassTimer>,
    ) {
        let uniform = DisplayUniform {
            exposure_scale: 2f32.powf(exposure_ev),
            tonemap_operator: operator as u32,
        };
        ctx.queue
            .write_buffer(&self.uniform, 0, bytemuck::bytes_of(&uniform));
        let (layout, buffer) = (&self.layout, &self.uniform);
        let group = self.group.get(&[hdr, out], || {
            bind_group(
                &ctx.device,
                layout,
                &[
                    buffer.as_entire_binding(),
                    wgpu::BindingResource::TextureView(hdr),
                    wgpu::BindingResource::TextureView(out),
                ],
            )
        });
        let writes = timer.and_then(|t| t.compute_pass_writes("display"));
        dispatch_2d(
            encoder,
            "display",
            &self.pipeline,
            &[None, None, None, Some(group)],
            size,
            writes,
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu::layout_check::assert_wgsl_layout;

    #[test]
    fn display_uniform_matches_its_wgsl_layout() {
        assert_wgsl_layout!(
            "display",
            "Display",
            DisplayUniform {
                exposure_scale,
                tonemap_operator,
            }
        );
    }
}
