//! Density grids on a regular lattice, read from and written to Mitsuba 3 `.vol` files (the
//! format, its limits and its checks are in `vol_file.rs`).

use glam::{UVec3, Vec3};
use rayon::prelude::*;

pub use super::vol_file::{MAX_AXIS_CELLS, MAX_VALUE_BYTES, ValuePolicy, VoxelError};

/// A scalar field sampled at the centres of the cells of a box, one channel.
#[derive(Clone, Debug, PartialEq)]
pub struct VoxelGrid {
    /// Cells along x, y, z.
    pub resolution: [u32; 3],
    /// Minimum corner of the box, metres.
    pub bbox_min: Vec3,
    /// Maximum corner of the box, metres.
    pub bbox_max: Vec3,
    /// Values at index `(z * yres + y) * xres + x` (x fastest, as in a 3D texture upload).
    pub values: Vec<f32>,
}

impl VoxelGrid {
    /// A grid whose values are `f` at each cell centre, in metres; evaluated in parallel.
    pub fn from_fn(
        resolution: [u32; 3],
        bbox_min: Vec3,
        bbox_max: Vec3,
        f: impl Fn(Vec3) -> f32 + Sync,
    ) -> VoxelGrid {
        let [nx, ny, _] = resolution.map(|n| n as usize);
        let cells = UVec3::from_array(resolution).as_vec3();
        let cell_size = (bbox_max - bbox_min) / cells;
        let count = cell_count(resolution).expect("VoxelGrid::from_fn: resolution too large");
        let values = (0..count)
            .into_par_iter()
            .map(|index| {
                let cell = Vec3::new(
                    (index % nx) as f32,
                    (index / nx % ny) as f32,
                    (index / (nx * ny)) as f32,
                );
                f(bbox_min + (cell + 0.5) * cell_size)
            })
            .collect();
        VoxelGrid {
            resolution,
            bbox_min,
            bbox_max,
            values,
        }
    }

    /// Trilinear interpolation at `uvw` in `[0, 1]^3` over the box, texel centres at
    /// `(i + 0.5) / n`, coordinates clamped to the edge: what a GPU sampler with
    /// `ClampToEdge` and `Linear` filtering returns (WebGPU spec, "texture sampling").
    ///
    /// # Panics
    /// When the grid is empty or `values` does not match `resolution`.
    pub fn sample(&self, uvw: Vec3) -> f32 {
        let n = UVec3::from_array(self.resolution);
        let texel = (uvw * n.as_vec3() - 0.5).clamp(Vec3::ZERO, (n - 1).as_vec3());
        let low = texel.floor().as_uvec3();
        let high = (low + 1).min(n - 1);
        let t = texel - low.as_vec3();
        let at = |x: u32, y: u32, z: u32| self.value([x, y, z]);
        let lerp = |a: f32, b: f32, t: f32| a + (b - a) * t;
        let along_x = |y: u32, z: u32| lerp(at(low.x, y, z), at(high.x, y, z), t.x);
        let along_y = |z: u32| lerp(along_x(low.y, z), along_x(high.y, z), t.y);
        lerp(along_y(low.z), along_y(high.z), t.z)
    }

    /// The largest value, or 0 for an empty grid.
    pub fn max_value(&self) -> f32 {
        self.values.iter().copied().reduce(f32::max).unwrap_or(0.0)
    }

    /// The value of cell `[x, y, z]`.
    ///
    /// # Panics
    /// When the cell is outside the grid.
    pub fn value(&self, cell: [u32; 3]) -> f32 {
        let [x, y, z] = cell.map(|i| i as usize);
        let [nx, ny, _] = self.resolution.map(|n| n as usize);
        self.values[(z * ny + y) * nx + x]
    }
}

/// Cells in a grid of `resolution`, or `None` when that does not fit in memory addresses.
pub(super) fn cell_count(resolution: [u32; 3]) -> Option<usize> {
    resolution
        .iter()
        .try_fold(1usize, |count, &n| count.checked_mul(n as usize))
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;

    /// A linear ramp, positive over the box of [`ramp_grid`].
    fn ramp(p: Vec3) -> f32 {
        p.x + 2.0 * p.y - 0.5 * p.z + 200.0
    }

    /// A 4x3x2 grid of a linear ramp over a box off the origin.
    pub(crate) fn ramp_grid() -> VoxelGrid {
        let (min, max) = (Vec3::new(-100.0, 0.0, 50.0), Vec3::new(100.0, 400.0, 250.0));
        VoxelGrid::from_fn([4, 3, 2], min, max, ramp)
    }

    #[test]
    fn from_fn_evaluates_cell_centres_x_fastest() {
        let grid = ramp_grid();
        // Cell [1, 2, 1]: centre x = -100 + 1.5 * 50, y = 2.5 * 400 / 3, z = 50 + 1.5 * 100.
        let centre = Vec3::new(-25.0, 1000.0 / 3.0, 200.0);
        let expected = ramp(centre);
        assert!((grid.values[(3 + 2) * 4 + 1] - expected).abs() < 1e-3);
        assert_eq!(grid.value([1, 2, 1]), grid.values[(3 + 2) * 4 + 1]);
    }

    #[test]
    fn sample_at_texel_centres_returns_the_value() {
        let grid = ramp_grid();
        for (x, y, z) in [(0, 0, 0), (3, 2, 1), (2, 1, 0)] {
            let uvw = (Vec3::new(x as f32, y as f32, z as f32) + 0.5) / Vec3::new(4.0, 3.0, 2.0);
            assert!((grid.sample(uvw) - grid.value([x, y, z])).abs() < 1e-3);
        }
    }

    #[test]
    fn sample_is_trilinear_between_centres_and_clamps_outside() {
        let grid = ramp_grid();
        let corner_mean = [
            [0, 0, 0],
            [1, 0, 0],
            [0, 1, 0],
            [1, 1, 0],
            [0, 0, 1],
            [1, 0, 1],
            [0, 1, 1],
            [1, 1, 1],
        ]
        .map(|cell| grid.value(cell))
        .iter()
        .sum::<f32>()
            / 8.0;
        let midpoint = Vec3::new(1.0 / 4.0, 1.0 / 3.0, 1.0 / 2.0);
        assert!((grid.sample(midpoint) - corner_mean).abs() < 1e-3);
        assert_eq!(grid.sample(Vec3::splat(-1.0)), grid.value([0, 0, 0]));
        assert_eq!(grid.sample(Vec3::splat(2.0)), grid.value([3, 2, 1]));
    }

    #[test]
    fn max_value_finds_the_largest() {
        let grid = ramp_grid();
        assert_eq!(grid.max_value(), grid.value([3, 2, 0]));
    }
}
