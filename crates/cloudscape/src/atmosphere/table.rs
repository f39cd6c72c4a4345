//! A 2D table of RGB values read as a GPU reads a filtered texture: bilinear, clamped to the edge.

use glam::{Vec2, Vec3};

/// Texture coordinate of the unit-range value `x` on a table of `n` texels, so that 0 and 1 fall
/// on the centres of the first and last texel (Bruneton 2017, `GetTextureCoordFromUnitRange`).
pub fn texture_coord(x: f32, n: u32) -> f32 {
    0.5 / n as f32 + x * (1.0 - 1.0 / n as f32)
}

/// The unit-range value at texture coordinate `u`: the inverse of [`texture_coord`].
pub fn unit_range(u: f32, n: u32) -> f32 {
    (u - 0.5 / n as f32) / (1.0 - 1.0 / n as f32)
}

/// Texture coordinates of the centre of texel `(x, y)` of a `size` table.
pub fn texel_centre(x: u32, y: u32, size: (u32, u32)) -> Vec2 {
    Vec2::new(
        (x as f32 + 0.5) / size.0 as f32,
        (y as f32 + 0.5) / size.1 as f32,
    )
}

/// RGB values on a grid, row by row; texel `(x, y)` covers `[x, x + 1] / width` in `u`.
#[derive(Clone, Debug, PartialEq)]
pub struct Table2 {
    /// Texels across.
    pub width: u32,
    /// Texels down.
    pub height: u32,
    /// `width * height` values, row by row.
    pub texels: Vec<Vec3>,
}

impl Table2 {
    /// The table whose texel `(x, y)` is `f` of its centre's texture coordinates.
    pub fn from_fn(width: u32, height: u32, f: impl Fn(Vec2) -> Vec3) -> Table2 {
        let texels = (0..height)
            .flat_map(|y| (0..width).map(move |x| (x, y)))
            .map(|(x, y)| f(texel_centre(x, y, (width, height))))
            .collect();
        Table2 {
            width,
            height,
            texels,
        }
    }

    /// Texel `(x, y)`, clamped to the table.
    pub fn texel(&self, x: i32, y: i32) -> Vec3 {
        let x = x.clamp(0, self.width as i32 - 1) as usize;
        let y = y.clamp(0, self.height as i32 - 1) as usize;
        self.texels[y * self.width as usize + x]
    }

    /// The bilinear sample at texture coordinates `uv`, clamped to the edge: what a linear
    /// sampler with `ClampToEdge` returns.
    pub fn sample(&self, uv: Vec2) -> Vec3 {
        let x = uv.x * self.width as f32 - 0.5;
        let y = uv.y * self.height as f32 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let (x0, y0) = (x0 as i32, y0 as i32);
        let top = self.texel(x0, y0).lerp(self.texel(x0 + 1, y0), fx);
        let bottom = self.texel(x0, y0 + 1).lerp(self.texel(x0 + 1, y0 + 1), fx);
        top.lerp(bottom, fy)
    }

    /// The texels as RGBA `f32`, alpha 1, for upload.
    pub fn to_rgba(&self) -> Vec<[f32; 4]> {
        self.texels
            .iter()
            .map(|t| t.extend(1.0).to_array())
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn texture_coordinates_round_trip_and_hit_texel_centres() {
        assert!((texture_coord(0.0, 64) - 0.5 / 64.0).abs() < 1e-7);
        assert!((texture_coord(1.0, 64) - 63.5 / 64.0).abs() < 1e-7);
        assert!((unit_range(texture_coord(0.3, 32), 32) - 0.3).abs() < 1e-6);
    }

    #[test]
    fn bilinear_sampling_interpolates_and_clamps() {
        let table = Table2::from_fn(4, 2, |uv| Vec3::new(uv.x, uv.y, 1.0));
        let centre = table.sample(Vec2::new(0.5, 0.5));
        assert!((centre - Vec3::new(0.5, 0.5, 1.0)).abs().max_element() < 1e-6);
        assert_eq!(table.sample(Vec2::new(-1.0, 2.0)), table.texel(0, 1));
    }
}
