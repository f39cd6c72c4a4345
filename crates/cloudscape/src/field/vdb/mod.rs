//! OpenVDB files (`.vdb`): float grids read as [`SparseVoxels`] and written back.
//!
//! Cloud artists' tools (Houdini, Blender, EmberGen) hand volumes over as OpenVDB files (Museth
//! 2013, "VDB: High-Resolution Sparse Volumes with Dynamic Topology"). This reader follows the
//! format as OpenVDB's own sources define it (`read.rs` lists what it reads): format versions
//! 222-224 (OpenVDB 3 to 12), trees of `float` values in the standard 5-4-3 configuration, full
//! or half precision, uncompressed, zlib or Blosc (LZ4) compressed, with or without active-mask
//! compression, several grids per file (chosen by name) and instanced grids. The grid's transform
//! places it: scale (uniform or per axis) and translation; rotations, shears, mirrors and frusta
//! are refused. The writer (`write.rs`) writes zlib-compressed files with active-mask
//! compression, which OpenVDB reads (the tests read them back with `python3-openvdb`).
//!
//! The only Rust crate that reads the format (`vdb-rs`) reads no more than this, builds Blosc's
//! C library and does not write; both directions are here, in pure Rust.

mod blosc;
mod cursor;
mod read;
mod write;

use std::path::{Path, PathBuf};

use glam::{DVec3, IVec3, Vec3};

use super::sparse::{Block, SparseVoxels, block_local};
use super::voxel::ValuePolicy;
use read::{Archive, GridError, HeaderError};

pub use write::{write_vdb, write_vdb_bytes};

/// The first eight bytes of every `.vdb` file: ` BDV` and four zeros as a little-endian `i64`.
const MAGIC: i64 = 0x5644_4220;
/// The separator OpenVDB puts between a grid's name and the suffix that keeps it unique.
const GRID_SEPARATOR: char = '\u{1e}';
/// The suffix of a tree type whose values are stored as half floats.
const HALF_FLOAT_SUFFIX: &str = "_HalfFloat";
/// The tree type of float grids (root, internal nodes of 32^3 and 16^3, leaves of 8^3).
pub const FLOAT_TREE: &str = "Tree_float_5_4_3";

/// Where a grid's voxels are in the world: voxel `i`'s centre is at `i * voxel_size +
/// translation` (OpenVDB's index-to-world map, axis aligned).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VdbTransform {
    /// Edge of a voxel along x, y, z, world units (metres in cloudscape).
    pub voxel_size: DVec3,
    /// World position of voxel (0, 0, 0)'s centre.
    pub translation: DVec3,
}

/// A float grid of a `.vdb` file.
#[derive(Clone, Debug, PartialEq)]
pub struct VdbGrid {
    /// The grid's name.
    pub name: String,
    /// Where its voxels are in the world.
    pub transform: VdbTransform,
    /// Its values, and the box of its active voxels.
    pub voxels: SparseVoxels,
}

impl VdbGrid {
    /// The world box of the active voxels (their outer faces), metres.
    pub fn world_box_m(&self) -> (Vec3, Vec3) {
        let t = &self.transform;
        let corner = |v: IVec3, half: f64| (v.as_dvec3() + half) * t.voxel_size + t.translation;
        (
            corner(self.voxels.min, -0.5).as_vec3(),
            corner(self.voxels.max, 0.5).as_vec3(),
        )
    }
}

/// Why a `.vdb` file could not be read or written.
#[derive(Debug, thiserror::Error)]
pub enum VdbError {
    /// The file system refused.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The operating system's reason.
        #[source]
        source: std::io::Error,
    },
    /// The file does not start with OpenVDB's magic number.
    #[error("{}: not an OpenVDB file (it does not start with \" BDV\")", path.display())]
    NotVdb {
        /// The file.
        path: PathBuf,
    },
    /// A format version outside 222-224.
    #[error(
        "{}: OpenVDB file format version {found} is not supported (222 to 224: OpenVDB 3 to 12)",
        path.display()
    )]
    Version {
        /// The file.
        path: PathBuf,
        /// The version found.
        found: u32,
    },
    /// Bytes that do not follow the format, or a file that ends early.
    #[error("{}: at byte {offset}: {message}", path.display())]
    Malformed {
        /// The file.
        path: PathBuf,
        /// Byte offset of the problem.
        offset: usize,
        /// What is wrong.
        message: String,
    },
    /// No grid of the name asked for, or no float grid at all.
    #[error("{}: {wanted}; the file holds {available}", path.display())]
    NoGrid {
        /// The file.
        path: PathBuf,
        /// What was looked for.
        wanted: String,
        /// The grids it holds, with their types.
        available: String,
    },
    /// A grid cloudscape cannot render (its type, transform, background or size).
    #[error("{}: grid {grid:?}: {message}", path.display())]
    Unsupported {
        /// The file.
        path: PathBuf,
        /// The grid's name.
        grid: String,
        /// Why.
        message: String,
    },
    /// A value that is not a density.
    #[error(
        "{}: grid {grid:?}: value {value} at voxel {voxel:?} is not allowed; values must be finite \
         and 0..65504 (the largest half float, as the GPU stores them); a volume's `sanitize = \
         true` replaces such values instead",
        path.display()
    )]
    BadValue {
        /// The file.
        path: PathBuf,
        /// The grid's name.
        grid: String,
        /// The voxel's index.
        voxel: [i32; 3],
        /// The value.
        value: f32,
    },
}

/// Reads grid `wanted` of the `.vdb` file at `path` (None: the first float grid), with `policy`
/// for values that are not densities.
pub fn read_vdb(
    path: &Path,
    wanted: Option<&str>,
    policy: ValuePolicy,
) -> Result<VdbGrid, VdbError> {
    let bytes = std::fs::read(path).map_err(|source| VdbError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    read_vdb_bytes(&bytes, path, wanted, policy)
}

/// Reads grid `wanted` (None: the first float grid) from the bytes of a `.vdb` file (named
/// `path` in errors), with `policy` for values that are not densities.
pub fn read_vdb_bytes(
    bytes: &[u8],
    path: &Path,
    wanted: Option<&str>,
    policy: ValuePolicy,
) -> Result<VdbGrid, VdbError> {
    let path_buf = || path.to_path_buf();
    let archive = Archive::parse(bytes).map_err(|e| match e {
        HeaderError::NotVdb => VdbError::NotVdb { path: path_buf() },
        HeaderError::Version(found) => VdbError::Version {
            path: path_buf(),
            found,
        },
        HeaderError::Malformed(m) => VdbError::Malformed {
            path: path_buf(),
            offset: m.offset,
            message: m.message,
        },
    })?;
    let descriptor = choose_grid(&archive, wanted).map_err(|wanted| VdbError::NoGrid {
        path: path_buf(),
        wanted,
        available: available(&archive),
    })?;
    let name = descriptor.name.clone();
    let unsupported = |message: String| VdbError::Unsupported {
        path: path_buf(),
        grid: name.clone(),
        message,
    };
    if descriptor.tree_type != FLOAT_TREE {
        return Err(unsupported(format!(
            "its tree is a {}; only float grids ({FLOAT_TREE}) hold densities",
            descriptor.tree_type
        )));
    }
    let data = read::read_grid(bytes, &archive, descriptor).map_err(|e| match e {
        GridError::Malformed(m) => VdbError::Malformed {
            path: path_buf(),
            offset: m.offset,
            message: m.message,
        },
        GridError::Unsupported(message) => unsupported(message),
    })?;
    let mut voxels = data.voxels;
    if voxels.max.cmplt(voxels.min).any() {
        return Err(unsupported("it has no active voxels".into()));
    }
    if let Some((voxel, value)) = apply_policy(&mut voxels, policy) {
        return Err(VdbError::BadValue {
            path: path_buf(),
            grid: name,
            voxel: voxel.to_array(),
            value,
        });
    }
    Ok(VdbGrid {
        name,
        transform: data.transform,
        voxels,
    })
}

/// The grid named `wanted`, or the first float grid; else what was looked for.
fn choose_grid<'a>(
    archive: &'a Archive,
    wanted: Option<&str>,
) -> Result<&'a read::Descriptor, String> {
    match wanted {
        Some(name) => archive
            .grids
            .iter()
            .find(|d| d.name == name)
            .ok_or_else(|| format!("no grid is named {name:?}")),
        None => archive
            .grids
            .iter()
            .find(|d| d.tree_type == FLOAT_TREE)
            .ok_or_else(|| "no float grid".to_string()),
    }
}

/// The grids of a file as `"density" (Tree_float_5_4_3), ...`.
fn available(archive: &Archive) -> String {
    if archive.grids.is_empty() {
        return "no grid".into();
    }
    archive
        .grids
        .iter()
        .map(|d| {
            let half = if d.half { ", half" } else { "" };
            format!("{:?} ({}{half})", d.name, d.tree_type)
        })
        .collect::<Vec<_>>()
        .join(", ")
}

/// Whether `value` is a density the GPU holds: finite, 0..65504.
fn is_density(value: f32) -> bool {
    (0.0..=half::f16::MAX.to_f32()).contains(&value)
}

/// Applies `policy` to every value: the first value that is not a density (and its voxel) under
/// [`ValuePolicy::Reject`]; under [`ValuePolicy::Replace`], NaN and negative values become 0 and
/// values above 65504 become 65504.
fn apply_policy(voxels: &mut SparseVoxels, policy: ValuePolicy) -> Option<(IVec3, f32)> {
    let max = half::f16::MAX.to_f32();
    let fix = |v: &mut f32| *v = if *v > max { max } else { 0.0 };
    let mut origins: Vec<IVec3> = voxels.blocks.keys().copied().collect();
    origins.sort_by_key(|o| o.to_array());
    for origin in origins {
        let block = voxels.blocks.get_mut(&origin).expect("a listed block");
        match block {
            Block::Uniform(v) if !is_density(*v) => match policy {
                ValuePolicy::Reject => return Some((origin, *v)),
                ValuePolicy::Replace => fix(v),
            },
            Block::Voxels(values) => {
                for (i, v) in values
                    .iter_mut()
                    .enumerate()
                    .filter(|(_, v)| !is_density(**v))
                {
                    match policy {
                        ValuePolicy::Reject => {
                            return Some((origin + block_local(i).as_ivec3(), *v));
                        }
                        ValuePolicy::Replace => fix(v),
                    }
                }
            }
            Block::Uniform(_) => {}
        }
    }
    None
}
