//! The cloud shadow map's pass: every texel's two columns through the coarse field, each frame.

use super::{EnvironmentGpu, EnvironmentTable, TablePass};
use crate::gpu::{GpuContext, PassTimer};
use crate::pass::Shared;
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
        CloudShadowPass {
            pass: TablePass::new(
                ctx,
                shared,
                (&CLOUD_SHADOW_WGSL, "shadow_build"),
                (SHADOW_PASS_NAME, EnvironmentTable::CloudShadow),
            ),
        }
    }

    /// Records the pass over the whole map.
    pub fn encode(
        &mut self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        groups: (&Shared, &EnvironmentGpu),
        timer: Option<&mut PassTimer>,
    ) {
        let texels = UVec2::splat(groups.1.shadow_texels());
        self.pass.encode(ctx, encoder, groups, texels, timer);
    }
}

/// The pass that renders the clouds' shadow map (`cloud_shadow.wgsl`).
pub static CLOUD_SHADOW_WGSL: crate::shader::WgslModule = crate::shader::wgsl_module!(
    "cloud_shadow",
    "cloud_shadow.wgsl",
    [
        &crate::shader::MATH_WGSL,
        &crate::field::gpu::FIELD_WGSL,
        &super::ENVIRONMENT_WGSL
    ]
);
