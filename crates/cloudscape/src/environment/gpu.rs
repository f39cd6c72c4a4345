//! The environment on the GPU: one uniform in a bind group of its own.

use super::Environment;
use crate::gpu::uniform::UniformGroup;
use bytemuck::{Pod, Zeroable};
use glam::Vec3;

/// GPU layout of an [`Environment`]: the `Environment` struct of `environment.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct EnvironmentUniform {
    sun_direction: Vec3,
    sun_cos_angular_radius: f32,
    sun_irradiance: Vec3,
    haze_extinction_per_m: f32,
    sky_zenith_radiance: Vec3,
    sky_gradient_exponent: f32,
    sky_horizon_radiance: Vec3,
    sky_pad: f32,
}

impl EnvironmentUniform {
    /// The uniform of `env`.
    pub fn new(env: &Environment) -> EnvironmentUniform {
        EnvironmentUniform {
            sun_direction: env.sun.direction,
            sun_cos_angular_radius: env.sun.cos_radius,
            sun_irradiance: env.sun.irradiance,
            haze_extinction_per_m: env.sky.haze_per_m,
            sky_zenith_radiance: env.sky.zenith,
            sky_gradient_exponent: env.sky.exponent,
            sky_horizon_radiance: env.sky.horizon,
            sky_pad: 0.0,
        }
    }
}

/// The environment's uniform buffer and bind group ([`crate::shader::ENVIRONMENT_GROUP`]):
/// `EnvironmentGpu::new(ctx, "environment")`, then `write(ctx, &EnvironmentUniform::new(&env))`.
pub type EnvironmentGpu = UniformGroup<EnvironmentUniform>;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu::layout_check::assert_wgsl_layout;

    #[test]
    fn environment_uniform_matches_its_wgsl_layout() {
        assert_wgsl_layout!(
            "probe",
            "Environment",
            EnvironmentUniform {
                sun_direction,
                sun_cos_angular_radius,
                sun_irradiance,
                haze_extinction_per_m,
                sky_zenith_radiance,
                sky_gradient_exponent,
                sky_horizon_radiance,
                sky_pad,
            }
        );
    }
}
