//! Bricked voxel grids: what the field samples for a `[[volumes]]` grid, on the CPU and the GPU.
//!
//! The box of a grid's voxels is cut into bricks of 8^3 voxels on the lattice of its blocks
//! ([`SparseVoxels`]); only bricks with a value other than 0 are stored, each with a one-voxel
//! apron on its high sides (9^3 texels, the first voxels of its neighbours), so that trilinear
//! filtering inside one brick reads every texel a sample between two voxel centres needs. A table
//! with one entry per brick of the lattice says where each stored brick is (0: empty). Memory
//! follows the voxels that hold values, not the box: a sparse 1024^3 cloud costs what its bricks
//! cost, plus 4 bytes per 512 voxels of the box for the table. The same layout is uploaded to the
//! GPU (`field.wgsl`, `field_volume_extinction`), whose sampler does the trilinear filtering
//! [`BrickGrid::sample`] specifies; values are stored as half floats, as the GPU holds them.

use glam::{IVec3, UVec3, Vec3};
use half::f16;
use rayon::prelude::*;

use super::sparse::{BLOCK_VOXELS, Block, SparseVoxels};
use super::voxel::VoxelGrid;

/// Voxels along each axis of a brick (one block of [`SparseVoxels`]).
pub const BRICK_VOXELS: u32 = BLOCK_VOXELS as u32;
/// Texels along each axis of a stored brick: its voxels and the apron on the high side.
pub const BRICK_TEXELS: u32 = BRICK_VOXELS + 1;
/// Texels of a stored brick.
pub const BRICK_TEXEL_COUNT: usize = (BRICK_TEXELS * BRICK_TEXELS * BRICK_TEXELS) as usize;
/// Most bricks in a grid's lattice (table entries, 4 bytes each: 64 MiB), a box of 2048^3 voxels.
pub const MAX_LATTICE_BRICKS: u64 = 1 << 24;
/// Most stored bricks of one grid: 730 MiB of half-float texels, 268 million voxels with values
/// (a dense 645^3 box).
pub const MAX_STORED_BRICKS: usize = 1 << 19;

/// Why voxels could not be bricked.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum BrickError {
    /// The box of the voxels is larger than a lattice may be.
    #[error(
        "its voxels span a box of {resolution:?} voxels; at most {MAX_LATTICE_BRICKS} bricks of \
         8^3 voxels (a 2048^3 box) are supported"
    )]
    BoxTooLarge {
        /// Voxels along x, y, z of the box.
        resolution: [u64; 3],
    },
    /// More bricks hold values than a grid may store.
    #[error("{bricks} bricks of 8^3 voxels hold values; at most {MAX_STORED_BRICKS} are supported")]
    TooManyBricks {
        /// Bricks that would be stored (at least).
        bricks: usize,
    },
}

/// A grid of voxels in bricks, sampled over the unit cube of its box.
#[derive(Clone, Debug, PartialEq)]
pub struct BrickGrid {
    /// Voxels along x, y, z of the box.
    pub resolution: [u32; 3],
    /// Where the box's first voxel lies in the brick lattice (each 0..8).
    first_voxel: UVec3,
    /// Bricks along x, y, z of the lattice.
    lattice: UVec3,
    /// Per brick of the lattice (x fastest): 0 when empty, else its stored brick's index + 1.
    table: Vec<u32>,
    /// The stored bricks' texels, [`BRICK_TEXEL_COUNT`] each, x fastest.
    texels: Vec<f16>,
    /// The largest texel of each stored brick.
    brick_max: Vec<f32>,
}

impl BrickGrid {
    /// Bricks a dense grid (its empty blocks left out).
    pub fn from_dense(grid: &VoxelGrid) -> Result<BrickGrid, BrickError> {
        Self::from_sparse(&SparseVoxels::from_dense(grid))
    }

    /// Bricks the box of `voxels`; bricks whose texels are all 0 are not stored.
    pub fn from_sparse(voxels: &SparseVoxels) -> Result<BrickGrid, BrickError> {
        let span = (voxels.max.as_i64vec3() - voxels.min.as_i64vec3() + 1).max(glam::I64Vec3::ONE);
        let lattice_origin = SparseVoxels::block_origin(voxels.min);
        let first_voxel = (voxels.min - lattice_origin).as_uvec3();
        let lattice_size = (span + first_voxel.as_i64vec3() + i64::from(BLOCK_VOXELS) - 1)
            / i64::from(BLOCK_VOXELS);
        if lattice_size.element_product() as u64 > MAX_LATTICE_BRICKS {
            return Err(BrickError::BoxTooLarge {
                resolution: span.as_u64vec3().to_array(),
            });
        }
        let lattice = lattice_size.as_uvec3();
        let resolution = span.as_uvec3();
        let candidates = candidate_bricks(voxels, lattice_origin, lattice);
        if candidates.len() > 8 * MAX_STORED_BRICKS {
            return Err(BrickError::TooManyBricks {
                bricks: candidates.len() / 8,
            });
        }
        let layout = Layout {
            lattice_origin,
            first_voxel,
            resolution,
        };
        let bricks: Vec<(u32, Box<[f16]>)> = candidates
            .par_iter()
            .filter_map(|&brick| {
                let texels = brick_texels(voxels, &layout, brick)?;
                Some((linear_index(brick, lattice), texels))
            })
            .collect();
        if bricks.len() > MAX_STORED_BRICKS {
            return Err(BrickError::TooManyBricks {
                bricks: bricks.len(),
            });
        }
        let mut table = vec![0u32; lattice.element_product() as usize];
        let mut texels = Vec::with_capacity(bricks.len() * BRICK_TEXEL_COUNT);
        let mut brick_max = Vec::with_capacity(bricks.len());
        for (slot, (index, values)) in bricks.iter().enumerate() {
            table[*index as usize] = slot as u32 + 1;
            brick_max.push(values.iter().map(|t| t.to_f32()).fold(0.0, f32::max));
            texels.extend_from_slice(values);
        }
        Ok(BrickGrid {
            resolution: resolution.to_array(),
            first_voxel,
            lattice,
            table,
            texels,
            brick_max,
        })
    }

    /// Trilinear interpolation at `uvw` in `[0, 1]^3` over the box, voxel centres at `(i + 0.5) /
    /// n`, clamped to the edge: what [`VoxelGrid::sample`] gives for the same values rounded to
    /// half floats, and what the GPU's linear sampler gives inside one brick.
    pub fn sample(&self, uvw: Vec3) -> f32 {
        let n = UVec3::from_array(self.resolution).as_vec3();
        let texel = (uvw * n - 0.5).clamp(Vec3::ZERO, n - 1.0) + self.first_voxel.as_vec3();
        let brick = (texel / BRICK_VOXELS as f32)
            .floor()
            .as_uvec3()
            .min(self.lattice - 1);
        let slot = self.table[linear_index(brick, self.lattice) as usize];
        if slot == 0 {
            return 0.0;
        }
        let brick_texels =
            &self.texels[(slot as usize - 1) * BRICK_TEXEL_COUNT..][..BRICK_TEXEL_COUNT];
        let local = texel - (brick * BRICK_VOXELS).as_vec3();
        let low = local.floor().as_uvec3().min(UVec3::splat(BRICK_VOXELS - 1));
        let t = local - low.as_vec3();
        let at = |x: u32, y: u32, z: u32| {
            brick_texels[((z * BRICK_TEXELS + y) * BRICK_TEXELS + x) as usize].to_f32()
        };
        let lerp = |a: f32, b: f32, t: f32| a + (b - a) * t;
        let along_x = |y: u32, z: u32| lerp(at(low.x, y, z), at(low.x + 1, y, z), t.x);
        let along_y = |z: u32| lerp(along_x(low.y, z), along_x(low.y + 1, z), t.y);
        lerp(along_y(low.z), along_y(low.z + 1), t.z)
    }

    /// The largest value, or 0 for an empty grid.
    pub fn max_value(&self) -> f32 {
        self.brick_max.iter().copied().fold(0.0, f32::max)
    }

    /// A bound of the values of the voxels `lo..=hi` of the box and of every sample between them:
    /// the largest texel of the bricks they lie in.
    pub fn max_in_voxels(&self, lo: UVec3, hi: UVec3) -> f32 {
        let last = UVec3::from_array(self.resolution) - 1;
        let brick_of = |v: UVec3| (v.min(last) + self.first_voxel) / BRICK_VOXELS;
        let (b0, b1) = (brick_of(lo), brick_of(hi));
        let mut max = 0.0f32;
        for z in b0.z..=b1.z {
            for y in b0.y..=b1.y {
                for x in b0.x..=b1.x {
                    let slot = self.table[linear_index(UVec3::new(x, y, z), self.lattice) as usize];
                    if slot > 0 {
                        max = max.max(self.brick_max[slot as usize - 1]);
                    }
                }
            }
        }
        max
    }

    /// Bricks stored (those holding a value other than 0).
    pub fn stored_bricks(&self) -> usize {
        self.brick_max.len()
    }

    /// Bytes the grid holds: the table, the bricks' texels and their maxima. The GPU holds the
    /// table and the texels.
    pub fn bytes(&self) -> usize {
        self.table.len() * 4 + self.texels.len() * 2 + self.brick_max.len() * 4
    }

    /// Bricks along x, y, z of the lattice.
    pub fn lattice(&self) -> UVec3 {
        self.lattice
    }

    /// Where the box's first voxel lies in the brick lattice (each 0..8).
    pub fn first_voxel(&self) -> UVec3 {
        self.first_voxel
    }

    /// Per brick of the lattice (x fastest): 0 when empty, else its stored brick's index + 1.
    pub fn table(&self) -> &[u32] {
        &self.table
    }

    /// The texels of stored brick `slot` (its table entry - 1): 9^3, x fastest.
    pub fn brick_texels(&self, slot: usize) -> &[f16] {
        &self.texels[slot * BRICK_TEXEL_COUNT..][..BRICK_TEXEL_COUNT]
    }
}

/// Where a grid's voxels lie in its brick lattice.
struct Layout {
    /// The voxel index of the lattice's first voxel.
    lattice_origin: IVec3,
    /// The box's first voxel in the lattice.
    first_voxel: UVec3,
    /// Voxels along x, y, z of the box.
    resolution: UVec3,
}

/// Index of `brick` in a table over `lattice`, x fastest.
fn linear_index(brick: UVec3, lattice: UVec3) -> u32 {
    (brick.z * lattice.y + brick.y) * lattice.x + brick.x
}

/// The lattice bricks whose texels may read a block: each block's own brick and the ones below it
/// on each axis (whose aprons reach into it), sorted and without repeats.
fn candidate_bricks(voxels: &SparseVoxels, lattice_origin: IVec3, lattice: UVec3) -> Vec<UVec3> {
    let mut bricks: Vec<UVec3> = voxels
        .blocks
        .keys()
        .flat_map(|origin| {
            let brick = (*origin - lattice_origin) / BLOCK_VOXELS;
            (0..8).filter_map(move |corner| {
                let below = brick - IVec3::new(corner & 1, (corner >> 1) & 1, corner >> 2);
                let inside =
                    below.cmpge(IVec3::ZERO).all() && below.cmplt(lattice.as_ivec3()).all();
                inside.then(|| below.as_uvec3())
            })
        })
        .collect();
    bricks.sort_unstable_by_key(|b| (b.z, b.y, b.x));
    bricks.dedup();
    bricks
}

/// The 9^3 texels of `brick` (voxels clamped to the box, as a sampler clamps to the edge), None
/// when every one is 0.
fn brick_texels(voxels: &SparseVoxels, layout: &Layout, brick: UVec3) -> Option<Box<[f16]>> {
    let block_at = |corner: UVec3| {
        let origin = layout.lattice_origin + ((brick + corner) * BRICK_VOXELS).as_ivec3();
        voxels.blocks.get(&origin)
    };
    let corners: [Option<&Block>; 8] = std::array::from_fn(|i| {
        block_at(UVec3::new(i as u32 & 1, (i as u32 >> 1) & 1, i as u32 >> 2))
    });
    let last = layout.resolution.as_ivec3() - 1;
    let first = layout.first_voxel.as_ivec3();
    let mut texels = vec![f16::ZERO; BRICK_TEXEL_COUNT].into_boxed_slice();
    let mut any = false;
    for z in 0..BRICK_TEXELS {
        for y in 0..BRICK_TEXELS {
            for x in 0..BRICK_TEXELS {
                let lattice_voxel = (brick * BRICK_VOXELS + UVec3::new(x, y, z)).as_ivec3();
                let clamped = (lattice_voxel - first).clamp(IVec3::ZERO, last) + first;
                let corner = clamped.as_uvec3() / BRICK_VOXELS - brick;
                let local = clamped.as_uvec3() % BRICK_VOXELS;
                let block = corners[(corner.x | (corner.y << 1) | (corner.z << 2)) as usize];
                let value = f16::from_f32(block.map_or(0.0, |b| b.value(local)));
                any |= value != f16::ZERO;
                texels[((z * BRICK_TEXELS + y) * BRICK_TEXELS + x) as usize] = value;
            }
        }
    }
    any.then_some(texels)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::field::sparse::BLOCK_VALUES;

    /// A grid whose values are a smooth bump, 0 on most of the box.
    fn bump_grid(resolution: [u32; 3]) -> VoxelGrid {
        VoxelGrid::from_fn(resolution, Vec3::ZERO, Vec3::ONE, |p| {
            (1.0 - (p - Vec3::new(0.3, 0.6, 0.45)).length() / 0.3).max(0.0) * 2.5
        })
    }

    fn rounded(grid: &VoxelGrid) -> VoxelGrid {
        let mut grid = grid.clone();
        grid.values
            .iter_mut()
            .for_each(|v| *v = f16::from_f32(*v).to_f32());
        grid
    }

    #[test]
    fn bricks_sample_as_the_dense_grid_everywhere() {
        let dense = rounded(&bump_grid([37, 20, 26]));
        let bricks = BrickGrid::from_dense(&dense).unwrap();
        assert!(bricks.stored_bricks() < bricks.table().len());
        let mut state = 7u32;
        let mut next = || {
            state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (state >> 8) as f32 / (1u32 << 24) as f32 * 1.2 - 0.1
        };
        for _ in 0..20_000 {
            let uvw = Vec3::new(next(), next(), next());
            let (a, b) = (dense.sample(uvw), bricks.sample(uvw));
            assert!((a - b).abs() < 1e-5, "at {uvw}: dense {a}, bricks {b}");
        }
        assert_eq!(bricks.max_value(), dense.max_value());
    }

    #[test]
    fn a_box_off_the_block_lattice_samples_its_own_voxels() {
        let mut values = Box::new([0.0f32; BLOCK_VALUES]);
        values
            .iter_mut()
            .enumerate()
            .for_each(|(i, v)| *v = (i % 7) as f32 * 0.25);
        let mut voxels = SparseVoxels {
            min: IVec3::new(-13, 3, 5),
            max: IVec3::new(-6, 9, 12),
            ..Default::default()
        };
        voxels
            .blocks
            .insert(IVec3::new(-16, 0, 0), Block::Voxels(values.clone()));
        voxels
            .blocks
            .insert(IVec3::new(-8, 8, 8), Block::Uniform(1.5));
        let bricks = BrickGrid::from_sparse(&voxels).unwrap();
        assert_eq!(bricks.resolution, [8, 7, 8]);
        assert_eq!(bricks.first_voxel(), UVec3::new(3, 3, 5));
        let n = Vec3::new(8.0, 7.0, 8.0);
        for v in [
            IVec3::new(-13, 3, 5),
            IVec3::new(-6, 9, 12),
            IVec3::new(-9, 7, 7),
        ] {
            let uvw = ((v - voxels.min).as_vec3() + 0.5) / n;
            assert_eq!(bricks.sample(uvw), voxels.value(v), "voxel {v}");
        }
    }

    #[test]
    fn bounds_cover_every_sample_in_their_voxels() {
        let dense = rounded(&bump_grid([24, 24, 24]));
        let bricks = BrickGrid::from_dense(&dense).unwrap();
        let (lo, hi) = (UVec3::new(2, 9, 4), UVec3::new(9, 17, 13));
        let bound = bricks.max_in_voxels(lo, hi);
        for z in lo.z..=hi.z {
            for y in lo.y..=hi.y {
                for x in lo.x..=hi.x {
                    assert!(dense.value([x, y, z]) <= bound);
                }
            }
        }
        // The bump ends before x = 0.6 of the box: the bricks from voxel 16 on hold nothing.
        assert_eq!(
            bricks.max_in_voxels(UVec3::new(16, 0, 0), UVec3::splat(23)),
            0.0
        );
    }

    #[test]
    fn memory_follows_the_bricks_that_hold_values() {
        let mut voxels = SparseVoxels {
            min: IVec3::ZERO,
            max: IVec3::splat(1023),
            ..Default::default()
        };
        voxels.blocks.insert(IVec3::splat(512), Block::Uniform(1.0));
        let bricks = BrickGrid::from_sparse(&voxels).unwrap();
        // The block, and the 7 bricks below it whose aprons reach into it.
        assert_eq!(bricks.stored_bricks(), 8);
        assert_eq!(
            bricks.bytes(),
            128 * 128 * 128 * 4 + 8 * (BRICK_TEXEL_COUNT * 2 + 4)
        );
    }

    #[test]
    fn a_box_too_large_is_refused() {
        let voxels = SparseVoxels {
            min: IVec3::splat(-1 << 20),
            max: IVec3::splat(1 << 20),
            ..Default::default()
        };
        assert!(matches!(
            BrickGrid::from_sparse(&voxels),
            Err(BrickError::BoxTooLarge { .. })
        ));
    }
}
