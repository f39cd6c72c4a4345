//! Sparse test clouds, shared by the library's and the command-line tool's tests: balls of density
//! in 8^3 blocks of [`SparseVoxels`].

use cloudscape::field::sparse::{Block, SparseVoxels, block_local};
use glam::IVec3;

/// Adds a ball of density falling linearly from `peak` at voxel `centre` to 0 at `radius`
/// voxels, in every block it touches (whole blocks, zeros around the ball).
pub fn add_ball(voxels: &mut SparseVoxels, centre: IVec3, radius: f32, peak: f32) {
    let reach = IVec3::splat(radius as i32 + 1);
    let (lo, hi) = (SparseVoxels::block_origin(centre - reach), centre + reach);
    for bz in (lo.z..=hi.z).step_by(8) {
        for by in (lo.y..=hi.y).step_by(8) {
            for bx in (lo.x..=hi.x).step_by(8) {
                let origin = IVec3::new(bx, by, bz);
                let values = std::array::from_fn(|i| {
                    let v = origin + block_local(i).as_ivec3();
                    (1.0 - (v - centre).as_vec3().length() / radius).max(0.0) * peak
                });
                voxels
                    .blocks
                    .insert(origin, Block::Voxels(Box::new(values)));
            }
        }
    }
}
