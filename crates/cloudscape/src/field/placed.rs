//! Voxel grids from files, placed in the world: `[[volumes]]` of a scene.

use std::path::Path;

use glam::Vec3;

use super::brick::BrickGrid;
use super::voxel::{self, VoxelGrid};
use crate::scene::VolumeGrid;

/// Centre of a `.vol` grid's box unless the scene gives one, metres.
pub const VOL_DEFAULT_CENTER_M: [f32; 3] = [0.0, 2500.0, -6000.0];
/// Size of a `.vol` grid's box unless the scene gives one, metres.
pub const VOL_DEFAULT_SIZE_M: [f32; 3] = [2000.0; 3];

/// A grid read from a file, and the world box (minimum and maximum corners, metres) the file puts
/// it in; or the scene key at fault and why.
type Loaded = Result<(BrickGrid, (Vec3, Vec3)), (&'static str, String)>;

/// A density grid placed in an axis-aligned world box.
#[derive(Clone, Debug)]
pub struct PlacedVolume {
    /// The grid, in bricks of half floats as the GPU stores them.
    pub grid: BrickGrid,
    /// Minimum corner of the box, metres.
    pub min_m: Vec3,
    /// Size of the box, metres.
    pub size_m: Vec3,
    /// Extinction where the grid value is 1, m^-1.
    pub extinction_per_m: f32,
}

impl PlacedVolume {
    /// Extinction at `p`, zero outside the box.
    pub fn extinction_per_m(&self, p: Vec3) -> f32 {
        let uvw = (p - self.min_m) / self.size_m;
        if uvw.cmplt(Vec3::ZERO).any() || uvw.cmpgt(Vec3::ONE).any() {
            return 0.0;
        }
        self.grid.sample(uvw) * self.extinction_per_m
    }
}

/// Reads the grid of `volume` from `path` (a `.vdb` file by its extension, else a `.vol` file)
/// and places it: in the box the scene gives, else where the file puts it (a `.vdb` grid's
/// transform) or the `.vol` default. The error names the volume's key at fault and why.
pub(super) fn load(
    volume: &VolumeGrid,
    path: &Path,
) -> Result<PlacedVolume, (&'static str, String)> {
    let policy = if volume.sanitize {
        voxel::ValuePolicy::Replace
    } else {
        voxel::ValuePolicy::Reject
    };
    let is_vdb = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("vdb"));
    let (grid, (own_min, own_max)) = if is_vdb {
        read_vdb(volume, path, policy)?
    } else {
        if volume.grid.is_some() {
            return Err((
                "grid",
                "names a grid of a .vdb file; a .vol file holds one grid".into(),
            ));
        }
        let dense = VoxelGrid::read_vol_with(path, policy).map_err(|e| ("path", e.to_string()))?;
        let grid = BrickGrid::from_dense(&dense)
            .map_err(|e| ("path", format!("{}: {e}", path.display())))?;
        let (centre, size) = (
            Vec3::from(VOL_DEFAULT_CENTER_M),
            Vec3::from(VOL_DEFAULT_SIZE_M),
        );
        (grid, (centre - 0.5 * size, centre + 0.5 * size))
    };
    let size_m = volume.size_m.map_or(own_max - own_min, Vec3::from);
    let centre_m = volume
        .center_m
        .map_or(0.5 * (own_min + own_max), Vec3::from);
    Ok(PlacedVolume {
        grid,
        min_m: centre_m - 0.5 * size_m,
        size_m,
        extinction_per_m: volume.extinction_per_m,
    })
}

/// A `.vdb` file's grid and the world box its transform gives its active voxels.
#[cfg(feature = "vdb")]
fn read_vdb(volume: &VolumeGrid, path: &Path, policy: voxel::ValuePolicy) -> Loaded {
    let vdb = super::vdb::read_vdb(path, volume.grid.as_deref(), policy).map_err(|e| {
        let key = if matches!(e, super::vdb::VdbError::NoGrid { .. }) && volume.grid.is_some() {
            "grid"
        } else {
            "path"
        };
        (key, e.to_string())
    })?;
    let grid = BrickGrid::from_sparse(&vdb.voxels).map_err(|e| {
        (
            "path",
            format!("{}: grid {:?}: {e}", path.display(), vdb.name),
        )
    })?;
    Ok((grid, vdb.world_box_m()))
}

/// Without the `vdb` feature, a `.vdb` file is refused.
#[cfg(not(feature = "vdb"))]
fn read_vdb(_: &VolumeGrid, path: &Path, _: voxel::ValuePolicy) -> Loaded {
    Err((
        "path",
        format!(
            "{}: reading OpenVDB files needs cloudscape's `vdb` feature",
            path.display()
        ),
    ))
}
