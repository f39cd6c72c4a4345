//! After the technique and temporal reuse: composing the full-resolution cloud output over what
//! lies behind it (the host's geometry, or the sky, sun and ground), with aerial perspective applied
//! once, and tone mapping HDR radiance for display. Each is a compute pass with one entry type,
//! made once; bind groups are remade only when the targets change.

pub mod tonemap;
pub(crate) mod upsample;

use crate::gpu::pipeline::{dispatch_2d, uniform_buffer};
use crate::gpu::{GpuContext, PassTimer};
use crate::output::CloudOutput;
use crate::pass::{BindGroupCache, ComputePass, Shared};
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
    pass: ComputePass,
    group: BindGroupCache,
}

impl Compositor {
    /// Builds the pass against the shared groups' layouts.
    pub fn new(ctx: &GpuContext, shared: &Shared) -> Compositor {
        let entry = "compose_clouds_over_background";
        Compositor {
            pass: ComputePass::new(ctx, shared, "compose", &COMPOSE_WGSL, &[entry]),
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
        let pass = &self.pass;
        let group = self.group.get(&views, || {
            let names = [
                "compose_clouds",
                "compose_cloud_distance",
                "compose_host_color",
                "compose_host_depth",
                "compose_out",
            ];
            let resources = views.map(wgpu::BindingResource::TextureView);
            pass.group
                .bind(ctx, &names.into_iter().zip(resources).collect::<Vec<_>>())
        });
        let writes = timer.and_then(|t| t.compute_pass_writes("compose"));
        dispatch_2d(
            encoder,
            "compose",
            pass.main(),
            &shared.bind_groups(pass.slots, group),
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
    pass: ComputePass,
    uniform: wgpu::Buffer,
    group: BindGroupCache,
}

impl Display {
    /// Builds the pass.
    pub fn new(ctx: &GpuContext) -> Display {
        Display {
            pass: ComputePass::standalone(ctx, "display", &DISPLAY_WGSL, &["display_hdr_image"]),
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
        let (pass, buffer) = (&self.pass, &self.uniform);
        let group = self.group.get(&[hdr, out], || {
            use wgpu::BindingResource::TextureView;
            pass.group.bind(
                ctx,
                &[
                    ("display", buffer.as_entire_binding()),
                    ("display_hdr", TextureView(hdr)),
                    ("display_out", TextureView(out)),
                ],
            )
        });
        let writes = timer.and_then(|t| t.compute_pass_writes("display"));
        dispatch_2d(
            encoder,
            "display",
            pass.main(),
            &[None, None, None, Some(group)],
            size,
            writes,
        );
    }
}

/// The pass that composes the clouds over the sky and the host's image (`compose.wgsl`).
pub static COMPOSE_WGSL: crate::shader::WgslModule = crate::shader::wgsl_module!(
    "compose",
    "compose.wgsl",
    [
        &crate::shader::MATH_WGSL,
        &crate::field::gpu::FIELD_WGSL,
        &crate::frame::FRAME_WGSL,
        &crate::environment::ENVIRONMENT_WGSL
    ]
);

/// The pass that tone-maps the composed image for display (`display.wgsl`).
pub static DISPLAY_WGSL: crate::shader::WgslModule =
    crate::shader::wgsl_module!("display", "display.wgsl", [&tonemap::TONEMAP_WGSL]);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu::layout_check::assert_wgsl_layout;

    #[test]
    fn display_uniform_matches_its_wgsl_layout() {
        assert_wgsl_layout!(
            &crate::post::DISPLAY_WGSL,
            "Display",
            DisplayUniform {
                exposure_scale,
                tonemap_operator,
            }
        );
    }
}
