//! Ray-marched clouds (the volumecloud seed, with Schneider 2015 and Hillaire 2016): a compute pass
//! that writes, per pixel, the radiance the clouds scatter toward the eye (rgb) and the transmittance
//! through them (a), stopping at the host's depth buffer. Composite as `scene * a + rgb`.

use crate::field::gpu::{FIELD_WGSL, FieldGpu, NOISE_WGSL};
use crate::frame::{FRAME_WGSL, Frame};
use crate::gpu::GpuContext;
use crate::gpu::pipeline::{
    UNIFORM, bind_group, bind_group_layout, compute_pipeline, dispatch_2d_repeated,
    storage_binding, storage_buffer, storage_texture_2d, uniform_buffer,
};
use crate::optics::{PHASE_WGSL, PhaseLobes};
use crate::scene::{Quality, Scene};
use bytemuck::{Pod, Zeroable};
use glam::{UVec2, UVec4, Vec4};

pub mod temporal;

const RAYMARCH_WGSL: &str = include_str!("raymarch.wgsl");

/// Format of the cloud target: rgb in-scattered radiance, a transmittance.
pub const CLOUD_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
/// Format of the cloud-depth target.
pub const CLOUD_DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Float;

/// Source of the ray-march program.
pub fn shader_source() -> String {
    [
        NOISE_WGSL,
        FIELD_WGSL,
        FRAME_WGSL,
        PHASE_WGSL,
        RAYMARCH_WGSL,
    ]
    .concat()
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
    /// Multiple-scattering octaves (Wrenninge 2013).
    pub octaves: u32,
    /// Octave factors a (extinction), b (scattering), c (eccentricity).
    pub octave_factors: [f32; 3],
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
        MarchSettings {
            primary_steps: r.primary_steps.unwrap_or(primary),
            light_steps: r.light_steps.unwrap_or(light),
            samples_per_pixel: r.samples_per_pixel.unwrap_or(spp),
            octaves: l.octaves,
            octave_factors: [
                l.octave_attenuation,
                l.octave_contribution,
                l.octave_eccentricity,
            ],
            albedo: l.albedo,
            ambient_scale: l.ambient_scale,
            phase: PhaseLobes::from_scene(&scene.phase),
            empty_space_skipping: r.empty_space_skipping,
        }
    }
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct MarchUniform {
    counts: UVec4,
    octaves: Vec4,
    phase: Vec4,
    ambient: Vec4,
    tile: UVec4,
    flags: UVec4,
    grid: UVec4,
    ray_offset: Vec4,
}

/// Which rays a march traces: one per pixel of a grid at 1/`divisor` of the frame's resolution,
/// through sub-pixel `subpixel` of each block, offset along the ray by white noise (stills) or by a
/// frame's Halton value plus the seed's Bayer pattern (temporal reuse).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MarchGrid {
    /// 1, 2 or 4: the grid has 1/divisor of the frame's pixels along each axis.
    pub divisor: u32,
    /// The pixel of each divisor x divisor block the rays go through.
    pub subpixel: UVec2,
    /// Halton offset along the rays, for temporal reuse; None for independent white noise.
    pub temporal_offset: Option<f32>,
}

impl MarchGrid {
    /// Every pixel, white-noise offsets: stills.
    pub const FULL: MarchGrid = MarchGrid {
        divisor: 1,
        subpixel: UVec2::ZERO,
        temporal_offset: None,
    };

    /// Grid size for a frame of `size` pixels.
    pub fn size(&self, size: UVec2) -> UVec2 {
        (size + self.divisor - 1) / self.divisor
    }
}

/// What the march did, counted on the GPU since the last [`RaymarchRenderer::prepare`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MarchStats {
    /// Pixels marched.
    pub pixels: u32,
    /// Extinction evaluations along view rays, per marched pixel.
    pub density_samples_per_pixel: f64,
}

/// Where the march reads and writes.
pub struct RaymarchTargets<'a> {
    /// The host's depth buffer (Depth32Float, 0 near, 1 far, from `Frame::clip_from_view`).
    pub depth: &'a wgpu::TextureView,
    /// Output, [`CLOUD_FORMAT`] with STORAGE_BINDING, the march grid's size.
    pub clouds: &'a wgpu::TextureView,
    /// Output, [`CLOUD_DEPTH_FORMAT`] with STORAGE_BINDING, the march grid's size: the
    /// transmittance-weighted distance to the cloud in metres (0 where there is none).
    pub cloud_depth: &'a wgpu::TextureView,
}

/// The ray-march pass.
pub struct RaymarchRenderer {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    frame: wgpu::Buffer,
    march: wgpu::Buffer,
    stats: wgpu::Buffer,
    sums: wgpu::Buffer,
    settings: MarchUniform,
}

/// Bytes of one pixel's running sums (`MarchSum` in raymarch.wgsl).
const MARCH_SUM_BYTES: u64 = 32;

/// The counters' and sums' binding.
const READ_WRITE: wgpu::BindingType = storage_binding(false);

impl RaymarchRenderer {
    /// Builds the pipeline against the field's bind group layout.
    pub fn new(ctx: &GpuContext, field: &FieldGpu) -> RaymarchRenderer {
        let depth = wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Float { filterable: false },
            view_dimension: wgpu::TextureViewDimension::D2,
            multisampled: false,
        };
        let layout = bind_group_layout(
            &ctx.device,
            "raymarch",
            &[
                UNIFORM,
                UNIFORM,
                depth,
                storage_texture_2d(CLOUD_FORMAT),
                READ_WRITE,
                storage_texture_2d(CLOUD_DEPTH_FORMAT),
                READ_WRITE,
            ],
        );
        let pipeline = compute_pipeline(
            ctx,
            "raymarch",
            &shader_source(),
            "march_clouds",
            &[field.layout(), &layout],
        );
        let buffer = |label, size| uniform_buffer(ctx, label, size);
        RaymarchRenderer {
            pipeline,
            layout,
            frame: buffer(
                "raymarch frame",
                size_of::<crate::frame::FrameUniform>() as u64,
            ),
            march: buffer("raymarch settings", size_of::<MarchUniform>() as u64),
            stats: storage_buffer(ctx, "raymarch stats", 8),
            sums: storage_buffer(ctx, "raymarch sums", MARCH_SUM_BYTES),
            settings: MarchUniform::zeroed(),
        }
    }

    /// Reads back the counters of the work submitted since the last `prepare` (waits for it).
    pub fn stats(&self, ctx: &GpuContext) -> MarchStats {
        let counts = crate::gpu::read_buffer::<u32>(ctx, &self.stats);
        let (samples, pixels) = (counts[0], counts[1]);
        MarchStats {
            pixels,
            density_samples_per_pixel: samples as f64 / pixels.max(1) as f64,
        }
    }

    /// Uploads the frame and settings for the next [`RaymarchRenderer::encode`].
    pub fn prepare(
        &mut self,
        ctx: &GpuContext,
        frame: &Frame,
        settings: &MarchSettings,
        grid: &MarchGrid,
    ) {
        let [a, b, c] = settings.octave_factors;
        self.settings = MarchUniform {
            counts: UVec4::new(
                settings.primary_steps,
                settings.light_steps,
                settings.samples_per_pixel,
                settings.octaves,
            ),
            octaves: Vec4::new(a, b, c, settings.albedo),
            phase: Vec4::from_array(settings.phase.to_gpu()),
            ambient: Vec4::new(settings.ambient_scale, 0.0, 0.0, 0.0),
            tile: UVec4::ZERO,
            flags: UVec4::new(settings.empty_space_skipping as u32, 0, 0, 0),
            grid: UVec4::new(
                grid.divisor,
                grid.subpixel.x,
                grid.subpixel.y,
                grid.temporal_offset.is_some() as u32,
            ),
            ray_offset: Vec4::new(grid.temporal_offset.unwrap_or(0.0), 0.0, 0.0, 0.0),
        };
        ctx.queue
            .write_buffer(&self.stats, 0, bytemuck::bytes_of(&[0u32; 2]));
        ctx.queue
            .write_buffer(&self.frame, 0, bytemuck::bytes_of(&frame.uniform()));
        ctx.queue
            .write_buffer(&self.march, 0, bytemuck::bytes_of(&self.settings));
    }

    /// Records the march over the pixel rectangle at `origin` of `size` pixels (the whole frame, or
    /// one tile of it so long renders can report progress between submissions), one dispatch per
    /// sample per pixel. A tile's origin is uploaded now, so submit each tile before encoding the
    /// next.
    pub fn encode(
        &mut self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        field: &FieldGpu,
        targets: &RaymarchTargets,
        (origin, size): (UVec2, UVec2),
        timestamps: Option<wgpu::ComputePassTimestampWrites>,
    ) {
        let tile = UVec4::new(origin.x, origin.y, size.x, 0);
        if self.settings.tile != tile {
            self.settings.tile = tile;
            ctx.queue
                .write_buffer(&self.march, 0, bytemuck::bytes_of(&self.settings));
        }
        let samples = self.settings.counts.z;
        let sums_bytes = MARCH_SUM_BYTES * u64::from(size.x * size.y);
        if samples > 1 && self.sums.size() < sums_bytes {
            self.sums = storage_buffer(ctx, "raymarch sums", sums_bytes);
        }
        let group = bind_group(
            &ctx.device,
            &self.layout,
            &[
                self.frame.as_entire_binding(),
                self.march.as_entire_binding(),
                wgpu::BindingResource::TextureView(targets.depth),
                wgpu::BindingResource::TextureView(targets.clouds),
                self.stats.as_entire_binding(),
                wgpu::BindingResource::TextureView(targets.cloud_depth),
                self.sums.as_entire_binding(),
            ],
        );
        dispatch_2d_repeated(
            encoder,
            "raymarch",
            &self.pipeline,
            &[field.bind_group(), &group],
            (size, samples),
            timestamps,
        );
    }
}
