//! Temporal reuse for the ray marcher (the volumecloud seed, with Horizon Zero Dawn's subset
//! updates): march few rays per frame on a coarse grid, each through a different sub-pixel and at a
//! different offset along the ray every frame, and let a full-resolution history do the rest.

use super::{
    CLOUD_DEPTH_FORMAT, CLOUD_FORMAT, MarchGrid, MarchSettings, RaymarchRenderer, RaymarchTargets,
};
use crate::field::gpu::FieldGpu;
use crate::frame::{FRAME_WGSL, Frame};
use crate::gpu::GpuContext;
use crate::gpu::pipeline::{
    STORAGE_OUTPUT, UNIFORM, bind_group, bind_group_layout, compute_pipeline, dispatch_2d,
    float_texture, storage_texture_2d, texture_2d, uniform_buffer,
};
use bytemuck::{Pod, Zeroable};
use glam::{Mat4, UVec2, UVec4, Vec2, Vec3, Vec4};

const TEMPORAL_WGSL: &str = include_str!("temporal.wgsl");

/// Source of the temporal resolve program.
pub fn resolve_source() -> String {
    [crate::field::gpu::NOISE_WGSL, FRAME_WGSL, TEMPORAL_WGSL].concat()
}

/// How the temporal march trades rays for history.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TemporalSettings {
    /// 1, 2 or 4: march one ray per divisor x divisor block per frame (4 updates 1/16 of the pixels,
    /// as Horizon Zero Dawn does).
    pub divisor: u32,
    /// Weight of new samples per frame at full resolution (the seed's 0.05); a pixel that gets its
    /// own ray every divisor^2 frames blends it in with the weight that decays as much over them.
    pub blend_per_frame: f32,
    /// Half-width of the neighbourhood box the history is clipped to, in standard deviations (the
    /// seed's gamma = 1).
    pub clip_gamma: f32,
    /// A camera jump longer than this (metres) in one frame is a cut: the history restarts.
    pub cut_distance_m: f32,
}

impl Default for TemporalSettings {
    fn default() -> Self {
        TemporalSettings {
            divisor: 2,
            blend_per_frame: 0.05,
            clip_gamma: 1.0,
            cut_distance_m: 1000.0,
        }
    }
}

impl TemporalSettings {
    /// Weight of a pixel's own fresh sample: 1 - (1 - blend)^(divisor^2).
    pub fn fresh_weight(&self) -> f32 {
        1.0 - (1.0 - self.blend_per_frame).powi((self.divisor * self.divisor) as i32)
    }
}

/// The radical inverse of `index` in `base` (Halton 1964): a low-discrepancy sequence in [0, 1).
pub fn halton(mut index: u32, base: u32) -> f32 {
    let (mut result, mut scale) = (0.0, 1.0);
    while index > 0 {
        scale /= base as f32;
        result += scale * (index % base) as f32;
        index /= base;
    }
    result
}

/// The sub-pixel of a `divisor` x `divisor` block that frame `index` marches: blocks are visited in
/// the order of the ordered-dither (Bayer) matrix, so successive frames spread over the block.
pub fn subpixel(index: u32, divisor: u32) -> UVec2 {
    let n = divisor * divisor;
    let rank = index % n;
    (0..n)
        .map(|i| UVec2::new(i % divisor, i / divisor))
        .find(|p| bayer_rank(*p, divisor) == rank)
        .expect("a Bayer matrix holds every rank once")
}

/// Rank of `p` in the `size` x `size` Bayer matrix (size a power of two), built by interleaving the
/// bits of x ^ y and y (Bayer 1973).
fn bayer_rank(p: UVec2, size: u32) -> u32 {
    let bits = size.trailing_zeros();
    (0..bits).fold(0, |rank, b| {
        let x = (p.x >> b) & 1;
        let y = (p.y >> b) & 1;
        rank | (((x ^ y) << 1 | y) << (2 * (bits - 1 - b)))
    })
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct TemporalUniform {
    prev_clip_from_world: Mat4,
    prev_camera_m: Vec4,
    wind_shift_m: Vec4,
    blend: Vec4,
    grid: UVec4,
}

/// What the previous frame looked like, for reprojection.
#[derive(Clone, Copy, Debug)]
struct PreviousFrame {
    clip_from_world: Mat4,
    camera_m: Vec3,
    time_s: f32,
}

/// A march grid's targets and the two full-resolution history buffers, with the cloud distance
/// each history pixel shows.
struct Buffers {
    size: UVec2,
    clouds: wgpu::TextureView,
    cloud_depth: wgpu::TextureView,
    history: [wgpu::TextureView; 2],
    history_depth: [wgpu::TextureView; 2],
}

/// The temporal ray march: a [`RaymarchRenderer`] on a coarse grid plus the resolve pass.
pub struct TemporalMarch {
    settings: TemporalSettings,
    march: RaymarchRenderer,
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    uniform: wgpu::Buffer,
    frame_uniform: wgpu::Buffer,
    sampler: wgpu::Sampler,
    buffers: Option<Buffers>,
    previous: Option<PreviousFrame>,
    latest: usize,
}

impl TemporalMarch {
    /// Builds the passes against the field's bind group layout.
    pub fn new(ctx: &GpuContext, field: &FieldGpu, settings: TemporalSettings) -> TemporalMarch {
        use wgpu::TextureViewDimension::D2;
        let unfilterable = wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Float { filterable: false },
            view_dimension: D2,
            multisampled: false,
        };
        let sampler_type = wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering);
        let types = [
            UNIFORM,
            UNIFORM,
            float_texture(D2),
            unfilterable,
            float_texture(D2),
            sampler_type,
            unfilterable,
            storage_texture_2d(CLOUD_FORMAT),
            unfilterable,
            storage_texture_2d(CLOUD_DEPTH_FORMAT),
        ];
        let layout = bind_group_layout(&ctx.device, "temporal resolve", &types);
        let pipeline = compute_pipeline(
            ctx,
            "temporal resolve",
            &resolve_source(),
            "resolve_clouds",
            &[&layout],
        );
        let buffer = |label, size| uniform_buffer(ctx, label, size);
        let sampler = ctx.device.create_sampler(&wgpu::SamplerDescriptor {
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        });
        TemporalMarch {
            settings,
            march: RaymarchRenderer::new(ctx, field),
            pipeline,
            layout,
            uniform: buffer("temporal", size_of::<TemporalUniform>() as u64),
            frame_uniform: buffer(
                "temporal frame",
                size_of::<crate::frame::FrameUniform>() as u64,
            ),
            sampler,
            buffers: None,
            previous: None,
            latest: 0,
        }
    }

    /// Forgets the history: the next frame starts afresh (camera cuts, new weather).
    pub fn reset(&mut self) {
        self.previous = None;
    }

    /// The settings in use.
    pub fn settings(&self) -> &TemporalSettings {
        &self.settings
    }

    /// Records this frame's march and resolve; returns the full-resolution result (radiance,
    /// transmittance), valid once the encoder is submitted. The frame's `frame_index` picks the
    /// sub-pixel and the ray offset, so it must advance every frame. `wind_m_per_s` is the clouds'
    /// motion.
    pub fn encode(
        &mut self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        field: &FieldGpu,
        (frame, settings, wind_m_per_s): (&Frame, &MarchSettings, Vec2),
        host_depth: &wgpu::TextureView,
        timestamps: [Option<wgpu::ComputePassTimestampWrites>; 2],
    ) -> &wgpu::TextureView {
        let divisor = self.settings.divisor;
        let grid = MarchGrid {
            divisor,
            subpixel: subpixel(frame.frame_index, divisor),
            temporal_offset: Some(halton(frame.frame_index % 64 + 1, 3)),
        };
        self.ensure_buffers(ctx, frame.size, &grid);
        let clip_from_world = frame.clip_from_view * frame.view_from_world;
        let cut = self.previous.is_some_and(|p| {
            p.camera_m.distance(frame.camera_position_m) > self.settings.cut_distance_m
        });
        let previous = if cut { None } else { self.previous };
        let uniform = TemporalUniform {
            prev_clip_from_world: previous.map_or(clip_from_world, |p| p.clip_from_world),
            prev_camera_m: previous
                .map_or(frame.camera_position_m, |p| p.camera_m)
                .extend(0.0),
            wind_shift_m: (wind_m_per_s * previous.map_or(0.0, |p| frame.time_s - p.time_s))
                .extend(0.0)
                .extend(0.0),
            blend: Vec4::new(
                self.settings.fresh_weight(),
                self.settings.clip_gamma,
                0.0,
                0.0,
            ),
            grid: UVec4::new(
                divisor,
                grid.subpixel.x,
                grid.subpixel.y,
                previous.is_some() as u32,
            ),
        };
        ctx.queue
            .write_buffer(&self.uniform, 0, bytemuck::bytes_of(&uniform));
        ctx.queue
            .write_buffer(&self.frame_uniform, 0, bytemuck::bytes_of(&frame.uniform()));
        self.march.prepare(ctx, frame, settings, &grid);
        let buffers = self.buffers.as_ref().expect("ensure_buffers made them");
        let targets = RaymarchTargets {
            depth: host_depth,
            clouds: &buffers.clouds,
            cloud_depth: &buffers.cloud_depth,
        };
        let [march_writes, resolve_writes] = timestamps;
        self.march.encode(
            ctx,
            encoder,
            field,
            &targets,
            (UVec2::ZERO, grid.size(frame.size)),
            march_writes,
        );
        let (read, write) = (self.latest, 1 - self.latest);
        let group = bind_group(
            &ctx.device,
            &self.layout,
            &[
                self.frame_uniform.as_entire_binding(),
                self.uniform.as_entire_binding(),
                wgpu::BindingResource::TextureView(&buffers.clouds),
                wgpu::BindingResource::TextureView(&buffers.cloud_depth),
                wgpu::BindingResource::TextureView(&buffers.history[read]),
                wgpu::BindingResource::Sampler(&self.sampler),
                wgpu::BindingResource::TextureView(host_depth),
                wgpu::BindingResource::TextureView(&buffers.history[write]),
                wgpu::BindingResource::TextureView(&buffers.history_depth[read]),
                wgpu::BindingResource::TextureView(&buffers.history_depth[write]),
            ],
        );
        dispatch_2d(
            encoder,
            "temporal resolve",
            &self.pipeline,
            &[&group],
            frame.size,
            resolve_writes,
        );
        self.latest = write;
        self.previous = Some(PreviousFrame {
            clip_from_world,
            camera_m: frame.camera_position_m,
            time_s: frame.time_s,
        });

        &buffers.history[write]
    }

    /// What the march counted in the last frame.
    pub fn stats(&self, ctx: &GpuContext) -> super::MarchStats {
        self.march.stats(ctx)
    }

    fn ensure_buffers(&mut self, ctx: &GpuContext, size: UVec2, grid: &MarchGrid) {
        if self.buffers.as_ref().is_some_and(|b| b.size == size) {
            return;
        }
        let texture = |label, size: UVec2, format| {
            texture_2d(ctx, label, size, format, STORAGE_OUTPUT).create_view(&Default::default())
        };
        let grid_size = grid.size(size);
        self.buffers = Some(Buffers {
            size,
            clouds: texture("march grid clouds", grid_size, CLOUD_FORMAT),
            cloud_depth: texture("march grid cloud depth", grid_size, CLOUD_DEPTH_FORMAT),
            history: [
                texture("cloud history a", size, CLOUD_FORMAT),
                texture("cloud history b", size, CLOUD_FORMAT),
            ],
            history_depth: [
                texture("cloud history depth a", size, CLOUD_DEPTH_FORMAT),
                texture("cloud history depth b", size, CLOUD_DEPTH_FORMAT),
            ],
        });
        self.previous = None;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn halton_is_the_radical_inverse() {
        assert_eq!(halton(1, 2), 0.5);
        assert_eq!(halton(2, 2), 0.25);
        assert_eq!(halton(3, 2), 0.75);
        assert!((halton(1, 3) - 1.0 / 3.0).abs() < 1e-7);
        assert!((halton(5, 3) - 7.0 / 9.0).abs() < 1e-6);
    }

    #[test]
    fn subpixels_visit_every_pixel_of_a_block_once() {
        for divisor in [1, 2, 4] {
            let mut seen: Vec<UVec2> = (0..divisor * divisor)
                .map(|i| subpixel(i, divisor))
                .collect();
            seen.sort_by_key(|p| (p.y, p.x));
            seen.dedup();
            assert_eq!(seen.len() as u32, divisor * divisor);
        }
        // Consecutive frames land far apart in the block (ordered dither), not side by side.
        assert_eq!(subpixel(0, 2), UVec2::new(0, 0));
        assert_eq!(subpixel(1, 2), UVec2::new(1, 1));
    }

    #[test]
    fn fresh_weight_decays_as_the_per_frame_blend_would() {
        let s = TemporalSettings {
            divisor: 4,
            ..TemporalSettings::default()
        };
        assert!((s.fresh_weight() - (1.0 - 0.95f32.powi(16))).abs() < 1e-6);
        assert!((TemporalSettings { divisor: 1, ..s }.fresh_weight() - 0.05).abs() < 1e-6);
    }
}
