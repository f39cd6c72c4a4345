//! GPU probes: every WGSL function with a CPU twin, evaluated at given inputs, so tests hold the
//! GPU against the CPU specification.

use crate::gpu::pipeline::storage_buffer;
use crate::gpu::{GpuContext, readback};
use crate::pass::{ComputePass, Shared};
use bytemuck::{Pod, Zeroable};
use glam::Vec4;
use wgpu::util::DeviceExt;

/// A WGSL function and the inputs it reads from a probe's two vec4s `a` and `b`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u32)]
pub enum ProbeFunction {
    /// `field_extinction(a.xyz)`: `CloudField::extinction_per_m`.
    Extinction = 0,
    /// `field_extinction_coarse(a.xyz)`: `CloudField::coarse_extinction_per_m`.
    CoarseExtinction = 1,
    /// `field_optical_depth_mean(a.xyz, b.xyz, span (0, a.w, growth b.w), 16 segments, jitter
    /// 0.5)`: the light paths of the march and the light volume.
    MeanOpticalDepth = 2,
    /// `frame_ray_direction(a.xy)`: `Frame::camera_ray`.
    CameraRay = 3,
    /// `frame_depth_distance(a.xy, depth a.z)`: `Frame::depth_distance_m` (1e30 for none).
    DepthDistance = 4,
    /// `environment_aerial_perspective(a.xyz, coverage a.w, screen uv b.yz, distance b.x)`:
    /// `ViewedEnvironment::aerial_perspective`.
    AerialPerspective = 5,
    /// `environment_sun_disc_radiance(a.xyz)`: `ViewedEnvironment::sun_disc_radiance`.
    SunDiscRadiance = 6,
    /// `environment_sky_radiance(a.xyz)`: `ViewedEnvironment::sky_radiance`.
    SkyRadiance = 7,
    /// `environment_ground_radiance(albedo a.xyz, b.xyz)`: `ViewedEnvironment::ground_radiance`.
    GroundRadiance = 8,
    /// `tonemap_aces(a.xyz)`: `tonemap::aces`.
    ToneMapAces = 9,
    /// `tonemap_agx(a.xyz)`: `tonemap::agx`.
    ToneMapAgx = 10,
    /// `linear_to_srgb(a.xyz)`: `tonemap::linear_to_srgb`.
    LinearToSrgb = 11,
    /// `frame_diffuse_transmittance(a.x)`: `optics::diffuse_transmittance`.
    DiffuseTransmittance = 12,
    /// `phase_eval(phase_scaled(lobes a, factor b.y), cos theta b.x)`:
    /// `PhaseLobes::scaled_anisotropy(factor).eval(cos theta)`.
    Phase = 13,
    /// `field_height_gradient(type a.x, height fraction a.y)`: `profile::height_gradient`.
    HeightGradient = 14,
    /// `environment_sun_irradiance(a.xyz)`: `ViewedEnvironment::sun_irradiance`.
    SunIrradiance = 15,
    /// `environment_sky_irradiance_up(a.xyz)`: `ViewedEnvironment::sky_irradiance_up`.
    SkyIrradianceUp = 16,
    /// `environment_sky_mean_radiance_up(a.xyz)`: `ViewedEnvironment::sky_mean_radiance_up`.
    SkyMeanRadianceUp = 17,
    /// `environment_cloud_sun_optical_depth(a.xyz)`: `CloudShadowMap::optical_depth(p, 0)`.
    CloudSunOpticalDepth = 18,
    /// `environment_cloud_sky_optical_depth(a.xyz)`: `CloudShadowMap::optical_depth(p, 1)`.
    CloudSkyOpticalDepth = 19,
    /// `frame_two_stream_share_from_below(a.x, a.y)`: `optics::two_stream_share_from_below`.
    TwoStreamShareFromBelow = 20,
    /// `phase_octaves(lobes a, factors b.xyz, count c.z, cos theta c.x, tau c.y)`:
    /// `Octaves::scattering`.
    Octaves = 21,
    /// `slab_scattering(SlabModel(lobes a, params b), cos theta c.x, tau_sun c.y, tau_back c.z)`:
    /// `SunSlab::scattering`.
    SunSlab = 22,
    /// `march_sun_optical_depth(a.xyz, steps b.x, jitter b.y)`: `raymarch::light::sun_optical_depth`.
    MarchSunOpticalDepth = 23,
    /// `march_back_optical_depth(a.xyz, steps b.x, jitter b.y)`:
    /// `raymarch::light::back_optical_depth`.
    MarchBackOpticalDepth = 24,
    /// `blend_merge(BlendSegment(a.x, a.y, a.z, b.xyz), BlendSegment(c.x, c.y, c.z, d.xyz))` as
    /// (colour, far_m): `particles::blend::merge`.
    BlendMerge = 25,
    /// `sprite_level(colours a + k^2 b for k = 0..4, heights (c, d.x), h d.y)`:
    /// `sprites::shading::level_at`.
    SpriteLevel = 26,
    /// `environment_sun_disc_pixel_radiance(a.xyz, b.xyz, c.xyz)`:
    /// `ViewedEnvironment::sun_disc_pixel_radiance`.
    SunDiscPixelRadiance = 27,
    /// `environment_light_volume_diffuse(a.xyz, toward the eye b.xyz)`:
    /// `LightVolume::diffuse`.
    LightVolumeDiffuse = 28,
    /// `environment_light_volume_ground_irradiance(a.xyz)`: `LightVolume::ground_irradiance`.
    LightVolumeGroundIrradiance = 29,
    /// `phase_broad_share(lobes a, peak weight b.z, cos theta b.x)`: `PhaseLobes::broad_share`.
    PhaseBroadShare = 30,
    /// `frame_round_to_half(a, u b.x)`: `frame::round_to_half`.
    RoundToHalf = 31,
    /// `frame_footprint_point(index a.x, samples a.y)`: `Frame::footprint_point`.
    FootprintPoint = 32,
}

/// The inputs of one evaluation.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct ProbeInput {
    /// First argument vector.
    pub a: Vec4,
    /// Second argument vector.
    pub b: Vec4,
    /// Third argument vector.
    pub c: Vec4,
    /// Fourth argument vector.
    pub d: Vec4,
}

/// The probe pipeline, built against the shared groups.
pub struct Probe {
    pass: ComputePass,
}

impl Probe {
    /// Builds the pipeline.
    pub fn new(ctx: &GpuContext, shared: &Shared) -> Probe {
        Probe {
            pass: ComputePass::new(ctx, shared, "probe", &PROBE_WGSL, &["probe_functions"]),
        }
    }

    /// `function` at every input, as the GPU computes it with the shared groups' current contents
    /// (waits for the result).
    pub fn run(
        &self,
        ctx: &GpuContext,
        shared: &Shared,
        function: ProbeFunction,
        inputs: &[ProbeInput],
    ) -> Vec<Vec4> {
        let device = &ctx.device;
        let init = |label, contents: &[u8], usage| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents,
                usage,
            })
        };
        let uniform = init(
            "probe function",
            bytemuck::bytes_of(&[function as u32, 0, 0, 0]),
            wgpu::BufferUsages::UNIFORM,
        );
        let input = init(
            "probe inputs",
            bytemuck::cast_slice(inputs),
            wgpu::BufferUsages::STORAGE,
        );
        let output = storage_buffer(ctx, "probe outputs", (inputs.len().max(1) * 16) as u64);
        let group = self.pass.group.bind(
            ctx,
            &[
                ("probe", uniform.as_entire_binding()),
                ("probe_inputs", input.as_entire_binding()),
                ("probe_outputs", output.as_entire_binding()),
            ],
        );
        let mut encoder = device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            pass.set_pipeline(self.pass.main());
            for (slot, g) in shared
                .bind_groups(self.pass.slots, &group)
                .iter()
                .enumerate()
            {
                if let Some(g) = g {
                    pass.set_bind_group(slot as u32, *g, &[]);
                }
            }
            pass.dispatch_workgroups(inputs.len().div_ceil(64) as u32, 1, 1);
        }
        ctx.queue.submit([encoder.finish()]);
        readback::read_buffer::<Vec4>(ctx, &output)
    }
}

/// The probe pass (`probe.wgsl`): WGSL functions evaluated at chosen inputs, compared with their CPU twins.
pub static PROBE_WGSL: crate::shader::WgslModule = crate::shader::wgsl_module!(
    "probe",
    "probe.wgsl",
    [
        &crate::field::gpu::HIHEIGHT_WGSL,
        &crate::frame::FRAME_WGSL,
        &crate::environment::ENVIRONMENT_WGSL,
        &crate::post::tonemap::TONEMAP_WGSL,
        &crate::optics::phase::PHASE_WGSL,
        &crate::optics::slab::SLAB_WGSL,
        &crate::raymarch::light::MARCH_LIGHT_WGSL,
        &crate::particles::blend::PARTICLE_BLEND_WGSL,
        &crate::sprites::views::SPRITE_WGSL
    ]
);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu::layout_check::assert_wgsl_layout;

    #[test]
    fn probe_inputs_match_their_wgsl_layout() {
        assert_wgsl_layout!(
            &crate::probe::PROBE_WGSL,
            "ProbeInput",
            ProbeInput { a, b, c, d }
        );
    }
}
