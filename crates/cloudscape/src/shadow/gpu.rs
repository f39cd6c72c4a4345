//! The cloud shadow map's pass: every texel's two columns through the coarse field, each frame.

use crate::environment::{EnvironmentTable, TablePass};
use crate::frame::Shared;
use crate::gpu::{GpuContext, PassTimer};
use glam::UVec2;

/// Label the pass is timed under.
pub const SHADOW_PASS_NAME: &str = "cloud shadow map";

/// Fills the environment's shadow map from the field (`cloud_shadow.wgsl`).
pub struct CloudShadowPass {
    pass: TablePass,
}

impl CloudShadowPass {
    /// Builds the pipeline against the shared groups.
    pub fn new(ctx: &GpuContext, shared: &Shared) -> CloudShadowPass {
        let d2 = wgpu::TextureViewDimension::D2;
        CloudShadowPass {
            pass: TablePass::new(
                ctx,
                shared,
                ("cloud_shadow", "shadow_build"),
                (SHADOW_PASS_NAME, EnvironmentTable::CloudShadow),
                &[d2, d2],
            ),
        }
    }

    /// Records the pass over the whole map.
    pub fn encode(
        &mut self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        shared: &Shared,
        timer: Option<&mut PassTimer>,
    ) {
        let texels = UVec2::splat(shared.environment.shadow_texels());
        self.pass.encode(ctx, encoder, shared, texels, timer);
    }
}
