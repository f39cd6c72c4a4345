//! The particle tables on the GPU, as the particle technique binds them: the optical-depth table
//! baked on the GPU ([`OpticalDepthLut`]) and the scattering tables, shipped, cached or baked on
//! the CPU ([`super::store::TableStore`]) and uploaded as one two-channel 3D texture
//! ([`ScatteringLut`]).

use half::f16;
use wgpu::util::DeviceExt;

use super::ParticleTableSpec;
use super::density::RadialProfile;
use super::gpu::{OpticalDepthBaker, OpticalDepthLut};
use super::scattering::{Progress, ScatteringTables};
use super::store::TableStore;
use crate::gpu::GpuContext;

/// Format of the scattering texture: single (r) and multiple (g) scattering, filterable
/// everywhere.
pub const SCATTERING_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rg16Float;

/// The scattering tables as a 3D texture of [`super::scattering::ScatteringLayout::texture_dims`]
/// and the linear, clamping sampler `particle_scattering` reads it with.
pub struct ScatteringLut {
    /// The texture.
    pub texture: wgpu::Texture,
    /// Linear, clamped on every axis.
    pub sampler: wgpu::Sampler,
}

impl ScatteringLut {
    /// Uploads `tables`.
    pub fn new(ctx: &GpuContext, tables: &ScatteringTables) -> ScatteringLut {
        let dims = tables.layout.texture_dims();
        let texels: Vec<f16> = tables
            .single
            .iter()
            .zip(&tables.multiple)
            .flat_map(|(s, m)| [f16::from_f32(*s), f16::from_f32(*m)])
            .collect();
        let texture = ctx.device.create_texture_with_data(
            &ctx.queue,
            &wgpu::TextureDescriptor {
                label: Some("particle scattering"),
                size: wgpu::Extent3d {
                    width: dims.x,
                    height: dims.y,
                    depth_or_array_layers: dims.z,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D3,
                format: SCATTERING_FORMAT,
                usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_SRC,
                view_formats: &[],
            },
            wgpu::util::TextureDataOrder::LayerMajor,
            bytemuck::cast_slice(&texels),
        );
        let sampler = ctx.device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("particle scattering"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        });
        ScatteringLut { texture, sampler }
    }
}

/// Every table of one [`ParticleTableSpec`], on the GPU.
pub struct ParticleTables {
    /// What they were made for.
    pub spec: ParticleTableSpec,
    /// The optical-depth table.
    pub optical_depth: OpticalDepthLut,
    /// The scattering tables.
    pub scattering: ScatteringLut,
    /// The reference particle's mean density over its ball (mass-conserving particle density).
    pub mean_density: f32,
}

impl ParticleTables {
    /// The tables of `spec`: the optical depth baked on the GPU now, the scattering from `store`
    /// (shipped, cached or baked; a cache that cannot be written only costs a bake next time).
    pub fn new(
        ctx: &GpuContext,
        spec: &ParticleTableSpec,
        store: &TableStore,
        progress: Progress,
    ) -> ParticleTables {
        let optical_depth =
            OpticalDepthBaker::new(ctx).bake(ctx, &spec.particle, spec.optical_depth);
        let scattering = match store.scattering(spec, progress) {
            Ok((tables, _)) => tables,
            Err(_) => super::store::bake_scattering(spec, &mut |_, _| {}).0,
        };
        ParticleTables {
            spec: spec.clone(),
            optical_depth,
            scattering: ScatteringLut::new(ctx, &scattering),
            mean_density: RadialProfile::of(&spec.particle).volume_mean(),
        }
    }
}
