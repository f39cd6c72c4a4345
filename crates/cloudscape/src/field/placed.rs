//! Voxel grids from files, placed in the world: `[[volumes]]` of a scene.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::SystemTime;

use glam::Vec3;

use super::brick::BrickGrid;
use super::shared::SharedCache;
use super::voxel::{self, VoxelGrid};
use crate::scene::VolumeGrid;

/// Centre of a `.vol` grid's box unless the scene gives one, metres.
pub const VOL_DEFAULT_CENTER_M: [f32; 3] = [0.0, 2500.0, -6000.0];
/// Size of a `.vol` grid's box unless the scene gives one, metres.
pub const VOL_DEFAULT_SIZE_M: [f32; 3] = [2000.0; 3];

/// A grid read from a file, and where the file puts it.
#[derive(Debug)]
pub struct FileGrid {
    /// The grid, in bricks of half floats as the GPU stores them.
    pub grid: BrickGrid,
    /// The world box the file puts it in (a `.vdb` grid's transform, the `.vol` default): minimum
    /// and maximum corners, metres.
    pub box_m: (Vec3, Vec3),
}

/// A grid read from a file, or the scene key at fault and why.
type Loaded = Result<FileGrid, (&'static str, String)>;

/// What a grid was read from: a field rebuilt for an edit of the scene (coverage, wind) reads no
/// file again that has not changed.
#[derive(PartialEq)]
struct GridFileKey {
    path: PathBuf,
    grid: Option<String>,
    sanitize: bool,
    modified: Option<SystemTime>,
    bytes: u64,
}

/// A density grid placed in an axis-aligned world box.
#[derive(Clone, Debug)]
pub struct PlacedVolume {
    /// The grid, shared by every field built from the same file while one holds it.
    pub source: Arc<FileGrid>,
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
        self.grid().sample(uvw) * self.extinction_per_m
    }

    /// The grid, in bricks of half floats as the GPU stores them.
    pub fn grid(&self) -> &BrickGrid {
        &self.source.grid
    }
}

/// Reads the grid of `volume` from `path` and places it: in the box the scene gives, else where
/// the file puts it. A file some field holds already, unchanged, is not read again. The error
/// names the volume's key at fault and why.
pub(super) fn load(
    volume: &VolumeGrid,
    path: &Path,
) -> Result<PlacedVolume, (&'static str, String)> {
    static CACHE: SharedCache<GridFileKey, FileGrid> = SharedCache::new();
    let metadata = std::fs::metadata(path).ok();
    let key = GridFileKey {
        path: path.to_path_buf(),
        grid: volume.grid.clone(),
        sanitize: volume.sanitize,
        modified: metadata.as_ref().and_then(|m| m.modified().ok()),
        bytes: metadata.map_or(0, |m| m.len()),
    };
    let source = CACHE.get_or_make(key, || read(volume, path))?;
    let (own_min, own_max) = source.box_m;
    let size_m = volume.size_m.map_or(own_max - own_min, Vec3::from);
    let centre_m = volume
        .center_m
        .map_or(0.5 * (own_min + own_max), Vec3::from);
    Ok(PlacedVolume {
        source,
        min_m: centre_m - 0.5 * size_m,
        size_m,
        extinction_per_m: volume.extinction_per_m,
    })
}

/// Reads the grid of `volume` from `path`: a `.vdb` file by its extension, else a `.vol` file.
fn read(volume: &VolumeGrid, path: &Path) -> Loaded {
    let policy = if volume.sanitize {
        voxel::ValuePolicy::Replace
    } else {
        voxel::ValuePolicy::Reject
    };
    let is_vdb = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("vdb"));
    if is_vdb {
        return read_vdb(volume, path, policy);
    }
    if volume.grid.is_some() {
        return Err((
            "grid",
            "names a grid of a .vdb file; a .vol file holds one grid".into(),
        ));
    }
    let dense = VoxelGrid::read_vol_with(path, policy).map_err(|e| ("path", e.to_string()))?;
    let grid =
        BrickGrid::from_dense(&dense).map_err(|e| ("path", format!("{}: {e}", path.display())))?;
    let (centre, size) = (
        Vec3::from(VOL_DEFAULT_CENTER_M),
        Vec3::from(VOL_DEFAULT_SIZE_M),
    );
    Ok(FileGrid {
        grid,
        box_m: (centre - 0.5 * size, centre + 0.5 * size),
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
    Ok(FileGrid {
        grid,
        box_m: vdb.world_box_m(),
    })
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_file_held_by_a_field_is_read_once_until_it_changes() {
        let dir = std::env::temp_dir().join(format!("cloudscape-placed-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("ball.vol");
        let ball = |scale: f32| {
            VoxelGrid::from_fn([9, 9, 9], Vec3::ZERO, Vec3::ONE, move |p| {
                (1.0 - (p - 0.5).length() * 2.0).max(0.0) * scale
            })
        };
        ball(1.0).write_vol(&path).unwrap();
        let volume = VolumeGrid {
            path: "ball.vol".into(),
            ..VolumeGrid::default()
        };
        let first = load(&volume, &path).unwrap();
        let again = load(&volume, &path).unwrap();
        assert!(Arc::ptr_eq(&first.source, &again.source), "read twice");
        // A different file (its length differs) is read again.
        VoxelGrid::from_fn([9, 9, 10], Vec3::ZERO, Vec3::ONE, |_| 0.5)
            .write_vol(&path)
            .unwrap();
        let changed = load(&volume, &path).unwrap();
        std::fs::remove_dir_all(&dir).ok();
        assert!(
            !Arc::ptr_eq(&first.source, &changed.source),
            "a changed file was not read"
        );
        assert_eq!(changed.grid().resolution, [9, 9, 10]);
    }
}
