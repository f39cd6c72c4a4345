//! 8-bit RGBA textures on the CPU, sampled exactly as a GPU's linear filter with repeat addressing
//! samples them, so CPU and GPU read the same field.

use glam::{IVec3, UVec3, Vec3, Vec4};

/// A 2D (depth 1) or 3D texture of 8-bit unorm RGBA texels.
#[derive(Clone, Debug, PartialEq)]
pub struct Texture8 {
    /// Width, height and depth in texels.
    pub dims: UVec3,
    /// Texels, x fastest, then y, then z.
    pub texels: Vec<[u8; 4]>,
}

/// Converts 8-bit unorm channels to floats as the GPU does.
pub fn unorm8(t: [u8; 4]) -> Vec4 {
    Vec4::new(t[0] as f32, t[1] as f32, t[2] as f32, t[3] as f32) / 255.0
}

impl Texture8 {
    /// The raw bytes, for upload.
    pub fn bytes(&self) -> &[u8] {
        bytemuck::cast_slice(&self.texels)
    }

    /// The texel at integer coordinates, wrapped into the texture.
    pub fn fetch(&self, t: IVec3) -> Vec4 {
        let d = self.dims.as_ivec3();
        let i = t.x.rem_euclid(d.x) + d.x * (t.y.rem_euclid(d.y) + d.y * t.z.rem_euclid(d.z));
        unorm8(self.texels[i as usize])
    }

    /// Linear-filtered sample at `uvw` in texture units (repeat addressing, texel centres at
    /// (i + 0.5) / n). A 2D texture ignores `uvw.z`.
    pub fn sample(&self, uvw: Vec3) -> Vec4 {
        sample_linear(self.dims, uvw, |t| self.fetch(t))
    }
}

/// Linear filtering (bilinear when `dims.z == 1`) over texels from `fetch`, which must wrap its
/// coordinates: the rule a GPU sampler with linear filtering and repeat addressing follows.
pub fn sample_linear(dims: UVec3, uvw: Vec3, fetch: impl Fn(IVec3) -> Vec4) -> Vec4 {
    let x = uvw * dims.as_vec3() - 0.5;
    let base = x.floor();
    let f = x - base;
    let b = base.as_ivec3();
    let depth_taps = if dims.z == 1 { 1 } else { 2 };
    let mut out = Vec4::ZERO;
    for dz in 0..depth_taps {
        let wz = match (depth_taps, dz) {
            (1, _) => 1.0,
            (_, 0) => 1.0 - f.z,
            _ => f.z,
        };
        for dy in 0..2 {
            let wy = if dy == 1 { f.y } else { 1.0 - f.y };
            for dx in 0..2 {
                let wx = if dx == 1 { f.x } else { 1.0 - f.x };
                let z = if depth_taps == 1 { 0 } else { b.z + dz };
                out += fetch(IVec3::new(b.x + dx, b.y + dy, z)) * (wx * wy * wz);
            }
        }
    }
    out
}
