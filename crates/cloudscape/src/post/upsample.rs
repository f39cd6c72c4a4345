//! Depth-aware upsampling for frames without temporal reuse (Yusov 2014, "Low-resolution
//! rendering"): a technique that renders at 1/2 or 1/4 resolution writes a coarse output, and this
//! pass turns it into the full-resolution output compositing reads, with `upsample.wgsl`'s
//! bilateral weights (the temporal resolve uses the same estimate).

use crate::frame::{Shared, SharedSlots};
use crate::gpu::pipeline::{
    BindGroupCache, UNFILTERABLE_TEXTURE_2D, bind_group, bind_group_layout, compute_pipeline,
    dispatch_2d, storage_texture_2d,
};
use crate::gpu::{GpuContext, PassTimer};
use crate::output::{CLOUD_DISTANCE_FORMAT, CLOUD_FORMAT, CloudOutput};

/// The label the pass is timed under.
pub const UPSAMPLE_PASS: &str = "upsample";

/// The upsampling pass, made once.
pub struct Upsampler {
    slots: SharedSlots,
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    group: BindGroupCache,
}

impl Upsampler {
    /// Builds the pass against the shared groups' layouts.
    pub fn new(ctx: &GpuContext, shared: &Shared) -> Upsampler {
        let layout = bind_group_layout(
            &ctx.device,
            UPSAMPLE_PASS,
            &[
                UNFILTERABLE_TEXTURE_2D,
                UNFILTERABLE_TEXTURE_2D,
                UNFILTERABLE_TEXTURE_2D,
                storage_texture_2d(CLOUD_FORMAT),
                storage_texture_2d(CLOUD_DISTANCE_FORMAT),
            ],
        );
        let slots = SharedSlots::of("upsample_still");
        let pipeline = compute_pipeline(
            ctx,
            UPSAMPLE_PASS,
            &crate::shader::program("upsample_still"),
            "upsample_clouds",
            &shared.layouts(slots, &layout),
        );
        Upsampler {
            slots,
            pipeline,
            layout,
            group: BindGroupCache::default(),
        }
    }

    /// Records the pass: `coarse` upsampled into `full` (the frame's resolution) against
    /// `host_depth`.
    pub fn encode(
        &mut self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        shared: &Shared,
        (coarse, full, host_depth): (&CloudOutput, &CloudOutput, &wgpu::TextureView),
        timer: Option<&mut PassTimer>,
    ) {
        let layout = &self.layout;
        let views = [host_depth, &coarse.radiance, &full.radiance];
        let group = self.group.get(&views, || {
            bind_group(
                &ctx.device,
                layout,
                &[
                    wgpu::BindingResource::TextureView(host_depth),
                    wgpu::BindingResource::TextureView(&coarse.radiance),
                    wgpu::BindingResource::TextureView(&coarse.distance),
                    wgpu::BindingResource::TextureView(&full.radiance),
                    wgpu::BindingResource::TextureView(&full.distance),
                ],
            )
        });
        let writes = timer.and_then(|t| t.compute_pass_writes(UPSAMPLE_PASS));
        let groups = shared.bind_groups(self.slots, group);
        dispatch_2d(
            encoder,
            UPSAMPLE_PASS,
            &self.pipeline,
            &groups,
            full.size,
            writes,
        );
    }
}
