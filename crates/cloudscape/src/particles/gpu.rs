//! The optical-depth table baked on the GPU (`particle_bake.wgsl`), the twin of
//! [`OpticalDepthTable::bake_cpu`]: the particle's noise into a voxel buffer, the chords through
//! it into a 16-bit float 3D texture. Switching the particle's noise style rebakes it in one
//! submission.

use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use half::f16;
use wgpu::util::DeviceExt;

use super::density::{ParticleShape, ReferenceParticle};
use super::optical_depth::{
    ChordProfile, OpticalDepthLayout, OpticalDepthTable, STEPS_PER_DIAMETER,
};
use crate::gpu::GpuContext;
use crate::gpu::pipeline::storage_buffer;
use crate::pass::ComputePass;

/// Format of the optical-depth texture: filterable 16-bit floats on every backend.
pub const OPTICAL_DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R16Float;

/// Voxels per side of the noise volume the chords are integrated through: 64^3 resolves the
/// noise's fourth octave (2.9 cells per radius) with 11 voxels per cell.
pub const NOISE_VOLUME_SIZE: u32 = 64;

/// The `ParticleBake` uniform of `particle_bake.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct ParticleBake {
    table_dims: [u32; 4],
    shape: ParticleShape,
    style: u32,
    seed: u32,
    volume_size: u32,
    row_pitch_words: u32,
    steps_per_diameter: u32,
    query_count: u32,
    reserved: [u32; 2],
}

/// The baked table on the GPU: a 3D texture laid out as [`OpticalDepthLayout::texture_dims`],
/// and the sampler the look-up needs (linear; repeating across entry azimuth, clamped elsewhere).
pub struct OpticalDepthLut {
    /// Its dimensions.
    pub layout: OpticalDepthLayout,
    /// The table.
    pub texture: wgpu::Texture,
    /// The sampler `particle_optical_depth_taps` expects.
    pub sampler: wgpu::Sampler,
    /// The chord masses the table's ratios are relative to.
    pub chords: ChordProfile,
    /// [`Self::chords`] on the GPU, a storage buffer of `f32` mean densities.
    pub chord_buffer: wgpu::Buffer,
}

/// The bake's pipelines, made once and reused for every rebake.
pub struct OpticalDepthBaker {
    pass: ComputePass,
}

impl OpticalDepthBaker {
    /// Compiles the bake's programs.
    pub fn new(ctx: &GpuContext) -> OpticalDepthBaker {
        OpticalDepthBaker {
            pass: ComputePass::standalone(
                ctx,
                "particle bake",
                &PARTICLE_BAKE_WGSL,
                &[
                    "bake_particle_noise",
                    "bake_optical_depth",
                    "probe_optical_depth",
                ],
            ),
        }
    }

    /// Bakes the table of `particle` at `layout` (submitted, not waited for).
    pub fn bake(
        &self,
        ctx: &GpuContext,
        particle: &ReferenceParticle,
        layout: OpticalDepthLayout,
    ) -> OpticalDepthLut {
        let dims = layout.texture_dims();
        let row_pitch_words = (dims.x * 2).next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) / 4;
        let uniform = bake_uniform(particle, layout, row_pitch_words, 0);
        let n = NOISE_VOLUME_SIZE;
        let voxels = storage_buffer(ctx, "particle noise", u64::from(n * n * n) * 4);
        let words = storage_buffer(
            ctx,
            "optical depth",
            u64::from(row_pitch_words * dims.y * dims.z) * 4,
        );
        let chords = ChordProfile::of_particle(particle);
        let lut = create_lut(ctx, layout, chords);
        let group = self.group(ctx, &uniform, &voxels, &words, &lut);
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            pass.set_bind_group(crate::shader::PASS_GROUP, &group, &[]);
            pass.set_pipeline(self.pass.pipeline("bake_particle_noise"));
            pass.dispatch_workgroups(n.div_ceil(4), n.div_ceil(4), n.div_ceil(4));
            pass.set_pipeline(self.pass.pipeline("bake_optical_depth"));
            pass.dispatch_workgroups(dims.x.div_ceil(2).div_ceil(8), dims.y.div_ceil(8), dims.z);
        }
        encoder.copy_buffer_to_texture(
            wgpu::TexelCopyBufferInfo {
                buffer: &words,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(row_pitch_words * 4),
                    rows_per_image: Some(dims.y),
                },
            },
            lut.texture.as_image_copy(),
            extent(dims),
        );
        ctx.queue.submit([encoder.finish()]);
        lut
    }

    /// Looks up `chords` (entry point, inward direction) in `lut` through the WGSL look-up and
    /// the texture's hardware filtering, chord `i` as particle `i` sees it (turned by
    /// [`super::optical_depth::particle_rotation`]`(i)`): what a shading pass reads. Waits for
    /// the GPU.
    pub fn probe(
        &self,
        ctx: &GpuContext,
        lut: &OpticalDepthLut,
        chords: &[(Vec3, Vec3)],
    ) -> Vec<f32> {
        let count = chords.len() as u32;
        let particle = ReferenceParticle {
            style: crate::scene::ParticleStyle::Smooth,
            seed: 0,
        };
        let uniform = bake_uniform(&particle, lut.layout, 0, count);
        let mut data: Vec<f32> = chords
            .iter()
            .flat_map(|(e, d)| [e.x, e.y, e.z, d.x, d.y, d.z])
            .collect();
        data.resize(data.len() + chords.len(), 0.0);
        let queries = ctx
            .device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("optical depth probe"),
                contents: bytemuck::cast_slice(&data),
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            });
        let unused = storage_buffer(ctx, "unused", 4);
        let group = self.group(ctx, &uniform, &queries, &unused, lut);
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            pass.set_bind_group(crate::shader::PASS_GROUP, &group, &[]);
            pass.set_pipeline(self.pass.pipeline("probe_optical_depth"));
            pass.dispatch_workgroups(count.div_ceil(64), 1, 1);
        }
        ctx.queue.submit([encoder.finish()]);
        let all: Vec<f32> = crate::gpu::readback::read_buffer(ctx, &queries);
        all[6 * chords.len()..].to_vec()
    }

    fn group(
        &self,
        ctx: &GpuContext,
        uniform: &ParticleBake,
        voxels: &wgpu::Buffer,
        words: &wgpu::Buffer,
        lut: &OpticalDepthLut,
    ) -> wgpu::BindGroup {
        let uniform = ctx
            .device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("particle bake"),
                contents: bytemuck::bytes_of(uniform),
                usage: wgpu::BufferUsages::UNIFORM,
            });
        let view = lut.texture.create_view(&Default::default());
        self.pass.group.bind(
            ctx,
            &[
                ("bake", uniform.as_entire_binding()),
                ("noise_voxels", voxels.as_entire_binding()),
                ("optical_depth_words", words.as_entire_binding()),
                (
                    "optical_depth_lut",
                    wgpu::BindingResource::TextureView(&view),
                ),
                (
                    "optical_depth_sampler",
                    wgpu::BindingResource::Sampler(&lut.sampler),
                ),
                ("chord_mean_density", lut.chord_buffer.as_entire_binding()),
            ],
        )
    }
}

impl OpticalDepthLut {
    /// Reads the table back (waits for the GPU).
    pub fn read(&self, ctx: &GpuContext) -> OpticalDepthTable {
        let bytes = crate::gpu::readback::read_texture(ctx, &self.texture);
        OpticalDepthTable {
            layout: self.layout,
            values: bytemuck::pod_collect_to_vec::<u8, f16>(&bytes),
            chords: self.chords.clone(),
        }
    }
}

fn bake_uniform(
    particle: &ReferenceParticle,
    layout: OpticalDepthLayout,
    row_pitch_words: u32,
    query_count: u32,
) -> ParticleBake {
    ParticleBake {
        table_dims: [
            layout.start_zenith,
            layout.start_azimuth,
            layout.dir_zenith,
            layout.dir_azimuth,
        ],
        shape: particle.shape(),
        style: particle.style.gpu_index(),
        seed: particle.seed,
        volume_size: NOISE_VOLUME_SIZE,
        row_pitch_words,
        steps_per_diameter: STEPS_PER_DIAMETER,
        query_count,
        reserved: [0; 2],
    }
}

fn extent(dims: glam::UVec3) -> wgpu::Extent3d {
    wgpu::Extent3d {
        width: dims.x,
        height: dims.y,
        depth_or_array_layers: dims.z,
    }
}

fn create_lut(
    ctx: &GpuContext,
    layout: OpticalDepthLayout,
    chords: ChordProfile,
) -> OpticalDepthLut {
    let chord_buffer = ctx
        .device
        .create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("particle chord masses"),
            contents: bytemuck::cast_slice(&chords.mean_density),
            usage: wgpu::BufferUsages::STORAGE,
        });
    let texture = ctx.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("particle optical depth"),
        size: extent(layout.texture_dims()),
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D3,
        format: OPTICAL_DEPTH_FORMAT,
        usage: wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::COPY_DST
            | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    });
    let sampler = ctx.device.create_sampler(&wgpu::SamplerDescriptor {
        label: Some("particle optical depth"),
        address_mode_u: wgpu::AddressMode::Repeat,
        address_mode_v: wgpu::AddressMode::ClampToEdge,
        address_mode_w: wgpu::AddressMode::ClampToEdge,
        mag_filter: wgpu::FilterMode::Linear,
        min_filter: wgpu::FilterMode::Linear,
        ..Default::default()
    });
    OpticalDepthLut {
        layout,
        texture,
        sampler,
        chords,
        chord_buffer,
    }
}

/// The reference particle on the GPU (`particle.wgsl`).
pub static PARTICLE_WGSL: crate::shader::WgslModule = crate::shader::wgsl_module!(
    "particle",
    "particle.wgsl",
    [&crate::shader::MATH_WGSL, &crate::field::noise::NOISE_WGSL]
);

/// The optical-depth table's look-up (`particle_lookup.wgsl`).
pub static PARTICLE_LOOKUP_WGSL: crate::shader::WgslModule = crate::shader::wgsl_module!(
    "particle_lookup",
    "particle_lookup.wgsl",
    [&crate::shader::MATH_WGSL, &PARTICLE_WGSL]
);

/// The sort of a tile's particle keys in workgroup memory (`particle_tiles.wgsl`): the screen
/// tiles' and the light tiles'.
pub static PARTICLE_TILES_WGSL: crate::shader::WgslModule =
    crate::shader::wgsl_module!("particle_tiles", "particle_tiles.wgsl", []);

/// The passes that bake the optical-depth table (`particle_bake.wgsl`).
pub static PARTICLE_BAKE_WGSL: crate::shader::WgslModule = crate::shader::wgsl_module!(
    "particle_bake",
    "particle_bake.wgsl",
    [
        &crate::shader::MATH_WGSL,
        &PARTICLE_WGSL,
        &PARTICLE_LOOKUP_WGSL
    ]
);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu::layout_check::assert_wgsl_layout;

    #[test]
    fn the_bake_uniform_matches_its_wgsl_layout() {
        assert_wgsl_layout!(
            &crate::particles::gpu::PARTICLE_BAKE_WGSL,
            "ParticleBake",
            ParticleBake {
                table_dims,
                shape,
                style,
                seed,
                volume_size,
                row_pitch_words,
                steps_per_diameter,
                query_count,
                reserved,
            }
        );
    }
}
