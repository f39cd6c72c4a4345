//! The cloud-output contract: what every technique writes, and all that temporal reuse,
//! upsampling and compositing read.
//!
//! Per output texel, for the ray through the pixel the frame's [`SampleGrid`] names:
//! - premultiplied radiance the clouds scatter toward the eye (rgb) and the transmittance through
//!   them (a), in [`CLOUD_FORMAT`]; composite as `behind * a + rgb`;
//! - the representative distance of the cloud in metres (transmittance-weighted mean along the ray,
//!   0 where there is no cloud), in [`CLOUD_DISTANCE_FORMAT`]; aerial perspective is applied there.
//!
//! The radiance is not hazed: haze is the compositor's, applied once at the cloud distance.
//!
//! After temporal reuse ([`crate::temporal`]) a texel may lie a little outside those ranges
//! (radiance below 0, transmittance outside [0, 1]) at sharp edges: the history keeps the ringing
//! of its bicubic resampling, which averages out over frames where a clamp every frame would
//! bias it. Clamp what you show, as the compositor does.

use crate::gpu::GpuContext;
use crate::gpu::pipeline::{STORAGE_OUTPUT, texture_2d};
use glam::UVec2;

/// Format of the radiance and transmittance texture.
pub const CLOUD_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
/// Format of the cloud-distance texture (metres).
pub const CLOUD_DISTANCE_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Float;

/// Which rays an output holds: one per pixel of a grid at 1/`divisor` of the frame's resolution,
/// through sub-pixel `subpixel` of each block (the rays' offsets along them follow the frame index:
/// `march_ray_offset` in `raymarch.wgsl`). This is the frame's jitter; [`crate::frame::FrameGpu`]
/// carries it to every technique.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SampleGrid {
    /// 1, 2 or 4: the grid has 1/divisor of the frame's pixels along each axis.
    pub divisor: u32,
    /// The pixel of each divisor x divisor block the rays go through.
    pub subpixel: UVec2,
}

impl SampleGrid {
    /// Every pixel: stills.
    pub const FULL: SampleGrid = SampleGrid {
        divisor: 1,
        subpixel: UVec2::ZERO,
    };

    /// Grid size for a frame of `size` pixels.
    pub fn size(&self, size: UVec2) -> UVec2 {
        (size + self.divisor - 1) / self.divisor
    }
}

/// The two textures of one cloud output, with STORAGE_BINDING (techniques write them),
/// TEXTURE_BINDING (the shared passes read them) and COPY_SRC (readback).
pub struct CloudOutput {
    /// Size in texels.
    pub size: UVec2,
    /// Premultiplied radiance (rgb) and transmittance (a), [`CLOUD_FORMAT`].
    pub radiance: wgpu::TextureView,
    /// Cloud distance in metres, [`CLOUD_DISTANCE_FORMAT`].
    pub distance: wgpu::TextureView,
    radiance_texture: wgpu::Texture,
}

impl CloudOutput {
    /// An output of `size` texels.
    pub fn new(ctx: &GpuContext, label: &str, size: UVec2) -> CloudOutput {
        let radiance_texture = texture_2d(ctx, label, size, CLOUD_FORMAT, STORAGE_OUTPUT);
        let distance = texture_2d(ctx, label, size, CLOUD_DISTANCE_FORMAT, STORAGE_OUTPUT);
        CloudOutput {
            size,
            radiance: radiance_texture.create_view(&Default::default()),
            distance: distance.create_view(&Default::default()),
            radiance_texture,
        }
    }

    /// The radiance and transmittance texture, for readback.
    pub fn radiance_texture(&self) -> &wgpu::Texture {
        &self.radiance_texture
    }
}
