//! Sparse voxels: values in blocks of 8^3 voxels on an integer lattice, only where there are any.
//!
//! The blocks are OpenVDB's leaf nodes (Museth 2013, "VDB: High-Resolution Sparse Volumes with
//! Dynamic Topology", ACM TOG 32(3)): origins at multiples of 8, values at `(x << 6) | (y << 3) |
//! z` (z fastest), so a `.vdb` file's leaves are kept as they are read and written back unchanged.
//! A dense [`VoxelGrid`] becomes one by dropping its empty blocks. [`super::brick::BrickGrid`] is
//! built from one for rendering.

use std::collections::HashMap;

use glam::{IVec3, UVec3};

use super::voxel::VoxelGrid;

/// Voxels along each axis of a block (an OpenVDB leaf node: `LeafNode<float, 3>`).
pub const BLOCK_VOXELS: i32 = 8;
/// Voxels in a block.
pub const BLOCK_VALUES: usize = 512;

/// The values of one block of 8^3 voxels.
#[derive(Clone, Debug, PartialEq)]
pub enum Block {
    /// Every voxel's value, at [`block_offset`].
    Voxels(Box<[f32; BLOCK_VALUES]>),
    /// One value for the whole block (an OpenVDB tile).
    Uniform(f32),
}

impl Block {
    /// The value of the voxel at `local` (each coordinate 0..8) in the block.
    pub fn value(&self, local: UVec3) -> f32 {
        match self {
            Block::Voxels(values) => values[block_offset(local)],
            Block::Uniform(value) => *value,
        }
    }

    /// The largest value in the block.
    pub fn max_value(&self) -> f32 {
        match self {
            Block::Voxels(values) => values.iter().copied().fold(f32::MIN, f32::max),
            Block::Uniform(value) => *value,
        }
    }
}

/// Index of the voxel at `local` (each coordinate 0..8) in a block's values: z fastest, as in an
/// OpenVDB leaf (`LeafNode::coordToOffset`).
pub fn block_offset(local: UVec3) -> usize {
    ((local.x << 6) | (local.y << 3) | local.z) as usize
}

/// The voxel at index `offset` of a block's values: the inverse of [`block_offset`].
pub fn block_local(offset: usize) -> UVec3 {
    let i = offset as u32;
    UVec3::new(i >> 6, (i >> 3) & 7, i & 7)
}

/// Voxels with values in 8^3 blocks, and the box of the ones that count (OpenVDB's active voxels).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SparseVoxels {
    /// Smallest voxel index of the box, inclusive.
    pub min: IVec3,
    /// Largest voxel index of the box, inclusive.
    pub max: IVec3,
    /// Blocks by origin (a multiple of 8 on every axis); voxels in no block are 0.
    pub blocks: HashMap<IVec3, Block>,
}

impl SparseVoxels {
    /// The origin of the block holding voxel `v`.
    pub fn block_origin(v: IVec3) -> IVec3 {
        v.div_euclid(IVec3::splat(BLOCK_VOXELS)) * BLOCK_VOXELS
    }

    /// The value of voxel `v` (0 in no block).
    pub fn value(&self, v: IVec3) -> f32 {
        let origin = Self::block_origin(v);
        self.blocks
            .get(&origin)
            .map_or(0.0, |block| block.value((v - origin).as_uvec3()))
    }

    /// Voxels along x, y, z of the box.
    pub fn resolution(&self) -> [u32; 3] {
        (self.max - self.min + 1)
            .max(IVec3::ZERO)
            .as_uvec3()
            .to_array()
    }

    /// Blocks holding their voxels one by one (not uniform).
    pub fn voxel_block_count(&self) -> usize {
        self.blocks
            .values()
            .filter(|b| matches!(b, Block::Voxels(_)))
            .count()
    }

    /// The voxels of a dense grid, its cell `[x, y, z]` at voxel `(x, y, z)`; blocks of zeros are
    /// left out, and the box is the grid's.
    pub fn from_dense(grid: &VoxelGrid) -> SparseVoxels {
        let resolution = UVec3::from_array(grid.resolution);
        let blocks_per_axis = (resolution.as_ivec3() + BLOCK_VOXELS - 1) / BLOCK_VOXELS;
        let mut blocks = HashMap::new();
        for bz in 0..blocks_per_axis.z {
            for by in 0..blocks_per_axis.y {
                for bx in 0..blocks_per_axis.x {
                    let origin = IVec3::new(bx, by, bz) * BLOCK_VOXELS;
                    if let Some(block) = dense_block(grid, origin) {
                        blocks.insert(origin, block);
                    }
                }
            }
        }
        SparseVoxels {
            min: IVec3::ZERO,
            max: resolution.as_ivec3() - 1,
            blocks,
        }
    }
}

/// The block of `grid` at `origin`, None when every value in it is 0.
fn dense_block(grid: &VoxelGrid, origin: IVec3) -> Option<Block> {
    let resolution = UVec3::from_array(grid.resolution);
    let mut values = Box::new([0.0f32; BLOCK_VALUES]);
    let mut any = false;
    for x in 0..BLOCK_VOXELS as u32 {
        for y in 0..BLOCK_VOXELS as u32 {
            for z in 0..BLOCK_VOXELS as u32 {
                let local = UVec3::new(x, y, z);
                let cell = origin.as_uvec3() + local;
                if cell.cmplt(resolution).all() {
                    let value = grid.value(cell.to_array());
                    values[block_offset(local)] = value;
                    any |= value != 0.0;
                }
            }
        }
    }
    any.then_some(Block::Voxels(values))
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn a_dense_grid_keeps_its_values_and_drops_empty_blocks() {
        let grid = VoxelGrid::from_fn([20, 9, 17], Vec3::ZERO, Vec3::ONE, |p| {
            if p.x < 0.4 { p.y + p.z } else { 0.0 }
        });
        let sparse = SparseVoxels::from_dense(&grid);
        assert_eq!(sparse.resolution(), [20, 9, 17]);
        // x < 0.4 of 20 cells: cells 0..8, the first block column only.
        assert!(sparse.blocks.keys().all(|origin| origin.x == 0));
        for (x, y, z) in [(0, 0, 0), (7, 8, 16), (3, 4, 9), (12, 2, 2)] {
            let v = IVec3::new(x, y, z);
            assert_eq!(sparse.value(v), grid.value(v.as_uvec3().to_array()));
        }
        assert_eq!(sparse.value(IVec3::new(-1, 0, 0)), 0.0);
    }

    #[test]
    fn block_offsets_run_z_fastest() {
        assert_eq!(block_offset(UVec3::new(0, 0, 1)), 1);
        assert_eq!(block_offset(UVec3::new(0, 1, 0)), 8);
        assert_eq!(block_offset(UVec3::new(1, 0, 0)), 64);
        assert_eq!(
            block_local(block_offset(UVec3::new(5, 2, 7))),
            UVec3::new(5, 2, 7)
        );
        assert_eq!(
            SparseVoxels::block_origin(IVec3::new(-1, 8, 15)),
            IVec3::new(-8, 8, 8)
        );
    }
}
