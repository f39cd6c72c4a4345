//! Depth-aware upsampling for frames without temporal reuse (Yusov 2014, "Low-resolution
//! rendering"): a technique that renders at 1/2 or 1/4 resolution writes a coarse output, and this
//! pass turns it into the full-resolution output compositing reads, with `upsample.wgsl`'s
//! bilateral weights (the temporal resolve uses the same estimate).

use crate::gpu::pipeline::dispatch_2d;
use crate::gpu::{GpuContext, PassTimer};
use crate::output::CloudOutput;
use crate::pass::{BindGroupCache, ComputePass, Shared};

/// The label the pass is timed under.
pub const UPSAMPLE_PASS: &str = "upsample";

/// The upsampling pass, made once.
pub struct Upsampler {
    pass: ComputePass,
    group: BindGroupCache,
}

impl Upsampler {
    /// Builds the pass against the shared groups' layouts.
    pub fn new(ctx: &GpuContext, shared: &Shared) -> Upsampler {
        Upsampler {
            pass: ComputePass::new(
                ctx,
                shared,
                UPSAMPLE_PASS,
                &UPSAMPLE_STILL_WGSL,
                &["upsample_clouds"],
            ),
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
        let pass = &self.pass;
        let views = [host_depth, &coarse.radiance, &full.radiance];
        let group = self.group.get(&views, || {
            use wgpu::BindingResource::TextureView;
            pass.group.bind(
                ctx,
                &[
                    ("upsample_host_depth", TextureView(host_depth)),
                    ("coarse_clouds", TextureView(&coarse.radiance)),
                    ("coarse_distance", TextureView(&coarse.distance)),
                    ("upsampled_clouds", TextureView(&full.radiance)),
                    ("upsampled_distance", TextureView(&full.distance)),
                ],
            )
        });
        let writes = timer.and_then(|t| t.compute_pass_writes(UPSAMPLE_PASS));
        let groups = shared.bind_groups(pass.slots, group);
        dispatch_2d(
            encoder,
            UPSAMPLE_PASS,
            pass.main(),
            &groups,
            full.size,
            writes,
        );
    }
}

/// The still-frame upsampling pass (`post/upsample.wgsl`).
pub static UPSAMPLE_STILL_WGSL: crate::shader::WgslModule = crate::shader::wgsl_module!(
    "upsample_still",
    "upsample.wgsl",
    [&crate::frame::FRAME_WGSL, &crate::temporal::UPSAMPLE_WGSL]
);
