//! Ray-marched clouds (the volumecloud seed, with Schneider 2015 and Hillaire 2016): a compute pass
//! that writes, per output texel, the radiance the clouds scatter toward the eye, the transmittance
//! through them and the cloud distance ([`crate::output`]), stopping at the host's depth buffer.

mod blue_noise;
pub mod light;

use crate::field::FieldError;
use crate::gpu::GpuContext;
use crate::gpu::PassTimer;
use crate::gpu::late_readback::LateReadback;
use crate::gpu::pipeline::{dispatch_2d_repeated, storage_buffer, uniform_buffer};
use crate::optics::{Octaves, PhaseLobes, SunSlab};
use crate::pass::{BindGroupCache, ComputePass, Shared};
use crate::scene::{LightingModel, Quality, Scene};
use crate::technique::{Draws, FrameInputs, Technique, TechniqueStats, TechniqueTargets};
use bytemuck::{Pod, Zeroable};
use glam::{UVec2, Vec4};
use std::path::Path;

/// Shortest and longest path the march's light samples cover toward the sun, metres: to the top
/// of the layers, within these bounds. Past 4 km of cumulus (optical depth ~ 200 at 0.05 m^-1) a
/// shadow is complete, and longer single-sample segments only add noise.
pub const SUN_PATH_M: (f32, f32) = (50.0, 4000.0);

/// Samples of the march's path away from the sun for `light_steps` toward it: half as many (the
/// far side only shapes the diffuse light, which varies slowly), at least one.
pub fn back_steps(light_steps: u32) -> u32 {
    light_steps.div_ceil(2).max(1)
}

/// Step counts and lighting of the march.
#[derive(Clone, Debug, PartialEq)]
pub struct MarchSettings {
    /// Samples along each view ray.
    pub primary_steps: u32,
    /// Samples toward the sun from each view sample.
    pub light_steps: u32,
    /// Jittered marches averaged per pixel.
    pub samples_per_pixel: u32,
    /// Which model of the sun's multiply scattered light the march uses.
    pub model: LightingModel,
    /// The slab model of it.
    pub slab: SunSlab,
    /// The octave model of it.
    pub octaves: Octaves,
    /// Single-scattering albedo.
    pub albedo: f32,
    /// Scale of sky and ground light.
    pub ambient_scale: f32,
    /// Phase function.
    pub phase: PhaseLobes,
    /// Skip empty space above the clouds with the hi-height pyramid (the image does not change).
    pub empty_space_skipping: bool,
}

impl MarchSettings {
    /// Samples away from the sun from each view sample: the slab model's far side; none for the
    /// octave model, which does not read it.
    pub fn back_steps(&self) -> u32 {
        match self.model {
            LightingModel::Slab => back_steps(self.light_steps),
            LightingModel::Octaves | LightingModel::Volume => 0,
        }
    }

    /// The share of the scattering that keeps light on its way to the eye (the diffraction peak,
    /// [`PhaseLobes::diffraction_peak_weight`]) with the light volume; 0 with the slab and the
    /// octaves, kept as they were fitted and tuned: with the view ray dimmed by the whole
    /// extinction.
    pub fn view_peak_weight(&self) -> f32 {
        match self.model {
            LightingModel::Volume => self.phase.diffraction_peak_weight(),
            LightingModel::Slab | LightingModel::Octaves => 0.0,
        }
    }

    /// Steps of a quality preset: (primary, light, samples per pixel).
    pub fn preset(quality: Quality) -> (u32, u32, u32) {
        match quality {
            Quality::Low => (32, 4, 1),
            Quality::Medium => (64, 5, 1),
            Quality::High => (96, 6, 2),
            Quality::Ultra => (192, 8, 8),
        }
    }

    /// The settings a scene asks for: its preset, overridden by explicit step counts.
    pub fn from_scene(scene: &Scene) -> MarchSettings {
        let r = &scene.render;
        let (primary, light, spp) = Self::preset(r.quality);
        let l = &scene.lighting;
        let light_steps = r.light_steps.unwrap_or(light);
        let phase = PhaseLobes::from_scene(&scene.phase);
        MarchSettings {
            primary_steps: r.primary_steps.unwrap_or(primary),
            light_steps,
            samples_per_pixel: r.samples_per_pixel.unwrap_or(spp),
            model: l.model,
            slab: l.sun_slab(phase),
            octaves: l.octaves(),
            albedo: l.albedo,
            ambient_scale: l.ambient_scale,
            phase,
            empty_space_skipping: r.empty_space_skipping,
        }
    }
}

/// The march's entry points: with the slab's or the octaves' light, and reading the light volume.
const ENTRIES: [&str; 2] = ["march_clouds", "march_clouds_volume"];

/// `March::lighting_model` of the light volume.
const LIGHTING_MODEL_VOLUME: u32 = 2;

/// The `March` uniform of `raymarch.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct MarchUniform {
    primary_steps: u32,
    light_steps: u32,
    samples_per_pixel: u32,
    octaves: u32,
    octave_attenuation: f32,
    octave_contribution: f32,
    octave_eccentricity: f32,
    albedo: f32,
    phase_lobes: Vec4,
    ambient_scale: f32,
    empty_space_skipping: u32,
    tile_width: u32,
    lighting_model: u32,
    tile_origin: UVec2,
    back_steps: u32,
    view_peak_weight: f32,
    slab_params: Vec4,
}

impl MarchUniform {
    fn new(settings: &MarchSettings) -> MarchUniform {
        let [a, b, c] = settings.octaves.factors();
        MarchUniform {
            primary_steps: settings.primary_steps,
            light_steps: settings.light_steps,
            samples_per_pixel: settings.samples_per_pixel,
            octaves: settings.octaves.count,
            octave_attenuation: a,
            octave_contribution: b,
            octave_eccentricity: c,
            albedo: settings.albedo,
            phase_lobes: Vec4::from_array(settings.phase.to_gpu()),
            ambient_scale: settings.ambient_scale,
            empty_space_skipping: settings.empty_space_skipping as u32,
            lighting_model: match settings.model {
                LightingModel::Slab => 0,
                LightingModel::Octaves => 1,
                LightingModel::Volume => LIGHTING_MODEL_VOLUME,
            },
            back_steps: settings.back_steps(),
            view_peak_weight: settings.view_peak_weight(),
            slab_params: Vec4::from_array(settings.slab.params_to_gpu()),
            ..MarchUniform::zeroed()
        }
    }
}

/// One pixel's running sums while the march is dispatched once per sample (`MarchSum`).
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct MarchSum {
    radiance_transmittance: Vec4,
    distance_m: f32,
    samples: u32,
    reserved: UVec2,
}

/// Bytes of the counters: view-ray density samples, texels marched.
const STATS_BYTES: u64 = 8;

/// The ray marcher: one compute pass, made once.
pub struct RaymarchRenderer {
    pass: ComputePass,
    march: wgpu::Buffer,
    stats: wgpu::Buffer,
    stats_readback: LateReadback,
    sums: wgpu::Buffer,
    /// The ray offsets' dither ([`blue_noise`]).
    blue_noise: wgpu::TextureView,
    group: BindGroupCache,
    settings: MarchUniform,
}

impl RaymarchRenderer {
    /// Builds the pipeline against the shared groups' layouts.
    pub fn new(ctx: &GpuContext, shared: &Shared) -> RaymarchRenderer {
        RaymarchRenderer {
            pass: ComputePass::new(ctx, shared, "raymarch", &RAYMARCH_WGSL, &ENTRIES),
            march: uniform_buffer(ctx, "raymarch settings", size_of::<MarchUniform>() as u64),
            stats: storage_buffer(ctx, "raymarch stats", STATS_BYTES),
            stats_readback: LateReadback::new(ctx, "raymarch stats readback", STATS_BYTES),
            sums: storage_buffer(ctx, "raymarch sums", size_of::<MarchSum>() as u64),
            blue_noise: blue_noise::blue_noise_texture(ctx),
            group: BindGroupCache::default(),
            settings: MarchUniform::zeroed(),
        }
    }

    /// Uploads the settings for the next [`Technique::encode`].
    pub fn set_settings(&mut self, ctx: &GpuContext, settings: &MarchSettings) {
        self.settings = MarchUniform::new(settings);
        ctx.queue
            .write_buffer(&self.march, 0, bytemuck::bytes_of(&self.settings));
    }

    /// Makes the per-pixel sums buffer hold `texels` texels.
    fn ensure_sums(&mut self, ctx: &GpuContext, texels: u32) {
        let bytes = size_of::<MarchSum>() as u64 * u64::from(texels);
        if self.settings.samples_per_pixel > 1 && self.sums.size() < bytes {
            self.sums = storage_buffer(ctx, "raymarch sums", bytes);
            self.group.clear();
        }
    }
}

/// What the ray marcher draws: the field, layers and voxel grids.
pub const DRAWS: Draws = Draws {
    layers: true,
    voxel_grids: true,
    sprite_clouds: false,
};

impl Technique for RaymarchRenderer {
    fn name(&self) -> &'static str {
        "raymarch"
    }

    fn draws(&self) -> Draws {
        DRAWS
    }

    fn pass_names(&self) -> &'static [&'static str] {
        &["raymarch"]
    }

    fn reads_light_volume(&self) -> bool {
        self.settings.lighting_model == LIGHTING_MODEL_VOLUME
    }

    fn configure(&mut self, ctx: &GpuContext, scene: &Scene, _: &Path) -> Result<(), FieldError> {
        self.set_settings(ctx, &MarchSettings::from_scene(scene));
        Ok(())
    }

    fn prepare(&mut self, _: &GpuContext, _: &FrameInputs) {}

    fn encode_frame_setup(
        &mut self,
        _: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        _: &Shared,
        _: &TechniqueTargets,
        _: Option<&mut PassTimer>,
    ) {
        encoder.clear_buffer(&self.stats, 0, None);
    }

    fn encode(
        &mut self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        shared: &Shared,
        targets: &TechniqueTargets,
        (origin, size): (UVec2, UVec2),
        timer: Option<(&mut PassTimer, &str)>,
    ) {
        if self.settings.tile_origin != origin || self.settings.tile_width != size.x {
            self.settings.tile_origin = origin;
            self.settings.tile_width = size.x;
            ctx.queue
                .write_buffer(&self.march, 0, bytemuck::bytes_of(&self.settings));
        }
        self.ensure_sums(ctx, size.x * size.y);
        let entry = ENTRIES[usize::from(self.reads_light_volume())];
        let (march, stats, sums, pass) = (&self.march, &self.stats, &self.sums, &self.pass);
        let blue_noise = &self.blue_noise;
        let output = targets.output;
        let group = self.group.get(
            &[targets.host_depth, &output.radiance, &output.distance],
            || {
                use wgpu::BindingResource::TextureView;
                pass.group.bind(
                    ctx,
                    &[
                        ("march", march.as_entire_binding()),
                        ("host_depth", TextureView(targets.host_depth)),
                        ("cloud_out", TextureView(&output.radiance)),
                        ("march_stats", stats.as_entire_binding()),
                        ("cloud_distance_out", TextureView(&output.distance)),
                        ("march_sums", sums.as_entire_binding()),
                        ("march_blue_noise", TextureView(blue_noise)),
                    ],
                )
            },
        );
        let writes = timer.and_then(|(t, label)| t.compute_pass_writes(label));
        dispatch_2d_repeated(
            encoder,
            "raymarch",
            pass.pipeline(entry),
            &shared.bind_groups(pass.slots, group),
            (size, self.settings.samples_per_pixel),
            writes,
        );
    }

    fn finish_frame(&mut self, encoder: &mut wgpu::CommandEncoder) {
        self.stats_readback.copy(encoder, &self.stats);
    }

    fn stats(&mut self, ctx: &GpuContext) -> Option<TechniqueStats> {
        let bytes = self.stats_readback.latest(ctx)?;
        let counts: &[u32] = bytemuck::cast_slice(bytes);
        let (samples, pixels) = (counts[0], counts[1]);
        Some(TechniqueStats {
            pixels,
            density_samples_per_pixel: f64::from(samples) / f64::from(pixels.max(1)),
            primitives: None,
        })
    }
}

/// The ray marcher's pass (`raymarch.wgsl`).
pub static RAYMARCH_WGSL: crate::shader::WgslModule = crate::shader::wgsl_module!(
    "raymarch",
    "raymarch.wgsl",
    [
        &crate::field::gpu::HIHEIGHT_WGSL,
        &crate::frame::FRAME_WGSL,
        &crate::environment::ENVIRONMENT_WGSL,
        &crate::optics::phase::PHASE_WGSL,
        &crate::optics::slab::SLAB_WGSL,
        &light::MARCH_LIGHT_WGSL
    ]
);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu::layout_check::assert_wgsl_layout;

    #[test]
    fn march_uniforms_match_their_wgsl_layouts() {
        assert_wgsl_layout!(
            &crate::raymarch::RAYMARCH_WGSL,
            "March",
            MarchUniform {
                primary_steps,
                light_steps,
                samples_per_pixel,
                octaves,
                octave_attenuation,
                octave_contribution,
                octave_eccentricity,
                albedo,
                phase_lobes,
                ambient_scale,
                empty_space_skipping,
                tile_width,
                lighting_model,
                tile_origin,
                back_steps,
                view_peak_weight,
                slab_params,
            }
        );
        assert_wgsl_layout!(
            &crate::raymarch::RAYMARCH_WGSL,
            "MarchSum",
            MarchSum {
                radiance_transmittance,
                distance_m,
                samples,
                reserved,
            }
        );
    }
}
