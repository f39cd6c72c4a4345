//! The environment's passes of a frame: the clouds' shadow map, then (with the atmosphere) the
//! sky's tables, then the light volume (when the technique reads it), before any technique reads
//! them.

use super::atmosphere_passes::{AtmospherePasses, FRAME_PASS_NAMES, TABLE_PASS_NAMES};
use super::light_volume::{
    LIGHT_VOLUME_PASS_NAMES, LightVolumeGrid, LightVolumePass, LightVolumeSettings,
};
use super::shadow_pass::{CloudShadowPass, SHADOW_PASS_NAME};
use super::{Environment, EnvironmentGpu, SkyModel};
use crate::gpu::{GpuContext, PassTimer};
use crate::pass::Shared;

/// The shadow-map pass and the atmosphere's table passes, made once.
pub struct EnvironmentPasses {
    shadow: CloudShadowPass,
    atmosphere: AtmospherePasses,
    light_volume: LightVolumePass,
}

/// The light volume a frame solves: its grid, its settings, and whether it may start from the
/// last frame's solution.
pub type FrameLightVolume<'a> = (&'a LightVolumeGrid, &'a LightVolumeSettings, bool);

impl EnvironmentPasses {
    /// Builds the pipelines against the shared groups.
    pub fn new(ctx: &GpuContext, shared: &Shared) -> EnvironmentPasses {
        EnvironmentPasses {
            shadow: CloudShadowPass::new(ctx, shared),
            atmosphere: AtmospherePasses::new(ctx, shared),
            light_volume: LightVolumePass::new(ctx, shared),
        }
    }

    /// Labels of a frame's environment passes, in order, for `env`: the shadow map, with the
    /// atmosphere the static tables (only in frames where the air changed) and the per-frame
    /// ones, and the light volume's when `light_volume`.
    pub fn pass_names(env: &Environment, light_volume: bool) -> Vec<&'static str> {
        let mut names = vec![SHADOW_PASS_NAME];
        if env.sky_model == SkyModel::Atmosphere {
            names.extend(TABLE_PASS_NAMES);
            names.extend(FRAME_PASS_NAMES);
        }
        if light_volume {
            names.extend(LIGHT_VOLUME_PASS_NAMES);
        }
        names
    }

    /// Records the frame's passes for `env` (the uniform already written) into the environment's
    /// tables: the shadow map when `build_shadow` (else the one built before is read), the sky's
    /// tables, and the light volume when the frame has one.
    pub fn encode(
        &mut self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        groups: (&Shared, &EnvironmentGpu),
        (env, build_shadow, light_volume): (&Environment, bool, Option<FrameLightVolume>),
        mut timer: Option<&mut PassTimer>,
    ) {
        if build_shadow {
            self.shadow
                .encode(ctx, encoder, groups, timer.as_deref_mut());
        }
        if env.sky_model == SkyModel::Atmosphere {
            self.atmosphere
                .encode(ctx, encoder, groups, &env.air, timer.as_deref_mut());
        }
        if let Some(volume) = light_volume {
            self.light_volume
                .encode(ctx, encoder, groups, volume, timer);
        }
    }
}
