//! Density grids on a regular lattice, read from and written to Mitsuba 3 `.vol` files.
//!
//! The `.vol` format (Mitsuba 0.6 and 3, `src/volumes/grid.cpp`; see `physics.md`), little endian:
//!
//! | bytes | content |
//! |---|---|
//! | 0..3 | ASCII `VOL` |
//! | 3 | version, 3 |
//! | 4..8 | `i32` encoding, 1 = float32 |
//! | 8..20 | `i32` resolution x, y, z |
//! | 20..24 | `i32` channel count |
//! | 24..48 | `f32` bounding box: xmin ymin zmin xmax ymax zmax |
//! | 48.. | `f32` values at `((z * yres + y) * xres + x) * channels + c` |
//!
//! A [`VoxelGrid`] holds one channel: reading a multi-channel file keeps channel 0.

use std::path::{Path, PathBuf};

use glam::{UVec3, Vec3};
use rayon::prelude::*;

use crate::fsutil::write_bytes_atomically;

/// The bytes every `.vol` file starts with.
const MAGIC: &[u8; 3] = b"VOL";
/// The only `.vol` version in use (Mitsuba 0.6 and 3).
const VERSION: u8 = 3;
/// Encoding number of 32-bit floats, the only one Mitsuba 3 reads.
const ENCODING_F32: i32 = 1;
/// Bytes before the values: magic, version, encoding, resolution, channels, bounding box.
const HEADER_BYTES: usize = 48;

/// Why a `.vol` file could not be read or written.
#[derive(Debug, thiserror::Error)]
pub enum VoxelError {
    /// The file system refused.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The operating system's reason.
        #[source]
        source: std::io::Error,
    },
    /// The file does not start with `VOL`.
    #[error("{}: not a Mitsuba .vol file (starts with {found:?}, expected \"VOL\")", path.display())]
    BadMagic {
        /// The file.
        path: PathBuf,
        /// Its first bytes, as text where possible.
        found: String,
    },
    /// A version other than 3.
    #[error("{}: .vol version {found} is not supported (expected 3)", path.display())]
    BadVersion {
        /// The file.
        path: PathBuf,
        /// The version byte found.
        found: u8,
    },
    /// An encoding other than float32.
    #[error("{}: .vol encoding {found} is not supported (only 1, float32)", path.display())]
    BadEncoding {
        /// The file.
        path: PathBuf,
        /// The encoding found.
        found: i32,
    },
    /// A resolution or channel count that is not positive, or too large to address.
    #[error(
        "{}: resolution {resolution:?} with {channels} channels is invalid (each must be >= 1) \
         or too large to hold in memory",
        path.display()
    )]
    BadSize {
        /// The file.
        path: PathBuf,
        /// x, y, z resolution as stored.
        resolution: [i32; 3],
        /// Channel count as stored.
        channels: i32,
    },
    /// The file is shorter or longer than its header says.
    #[error("{}: expected {expected} bytes for its header and values, found {found}", path.display())]
    WrongLength {
        /// The file.
        path: PathBuf,
        /// Bytes the header implies.
        expected: usize,
        /// Bytes in the file.
        found: usize,
    },
    /// A grid to write whose value count does not match its resolution.
    #[error("{}: a {resolution:?} grid needs {expected} values, it has {found}", path.display())]
    ValueCount {
        /// The file that was to be written.
        path: PathBuf,
        /// The grid's resolution.
        resolution: [u32; 3],
        /// Values the resolution implies.
        expected: usize,
        /// Values the grid holds.
        found: usize,
    },
}

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
    /// Reads a `.vol` file, keeping channel 0 of multi-channel files.
    pub fn read_vol(path: &Path) -> Result<VoxelGrid, VoxelError> {
        let bytes = std::fs::read(path).map_err(|source| io_error(path, source))?;
        parse_vol(&bytes, path)
    }

    /// Writes a one-channel `.vol` file. The file appears whole or not at all: it is written to a
    /// temporary file beside `path` and renamed.
    pub fn write_vol(&self, path: &Path) -> Result<(), VoxelError> {
        let expected = cell_count(self.resolution);
        if expected != Some(self.values.len()) {
            return Err(VoxelError::ValueCount {
                path: path.to_path_buf(),
                resolution: self.resolution,
                expected: expected.unwrap_or(usize::MAX),
                found: self.values.len(),
            });
        }
        write_bytes_atomically(path, &self.to_vol_bytes()).map_err(|source| io_error(path, source))
    }

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

    fn to_vol_bytes(&self) -> Vec<u8> {
        let mut bytes = Vec::with_capacity(HEADER_BYTES + 4 * self.values.len());
        bytes.extend_from_slice(MAGIC);
        bytes.push(VERSION);
        bytes.extend_from_slice(&ENCODING_F32.to_le_bytes());
        for n in self.resolution {
            bytes.extend_from_slice(&(n as i32).to_le_bytes());
        }
        bytes.extend_from_slice(&1i32.to_le_bytes());
        for coordinate in self
            .bbox_min
            .to_array()
            .into_iter()
            .chain(self.bbox_max.to_array())
        {
            bytes.extend_from_slice(&coordinate.to_le_bytes());
        }
        bytes.extend(self.values.iter().flat_map(|value| value.to_le_bytes()));
        bytes
    }
}

/// Cells in a grid of `resolution`, or `None` when that does not fit in memory addresses.
fn cell_count(resolution: [u32; 3]) -> Option<usize> {
    resolution
        .iter()
        .try_fold(1usize, |count, &n| count.checked_mul(n as usize))
}

fn io_error(path: &Path, source: std::io::Error) -> VoxelError {
    VoxelError::Io {
        path: path.to_path_buf(),
        source,
    }
}

fn parse_vol(bytes: &[u8], path: &Path) -> Result<VoxelGrid, VoxelError> {
    let path_buf = || path.to_path_buf();
    let wrong_length = |expected| VoxelError::WrongLength {
        path: path_buf(),
        expected,
        found: bytes.len(),
    };
    if !bytes.starts_with(MAGIC) {
        let found = String::from_utf8_lossy(&bytes[..bytes.len().min(3)]).into_owned();
        return Err(VoxelError::BadMagic {
            path: path_buf(),
            found,
        });
    }
    if bytes.len() < HEADER_BYTES {
        return Err(wrong_length(HEADER_BYTES));
    }
    if bytes[3] != VERSION {
        return Err(VoxelError::BadVersion {
            path: path_buf(),
            found: bytes[3],
        });
    }
    let int_at = |offset: usize| i32::from_le_bytes(word(bytes, offset));
    let float_at = |offset: usize| f32::from_le_bytes(word(bytes, offset));
    let encoding = int_at(4);
    if encoding != ENCODING_F32 {
        return Err(VoxelError::BadEncoding {
            path: path_buf(),
            found: encoding,
        });
    }
    let stored_resolution = [int_at(8), int_at(12), int_at(16)];
    let stored_channels = int_at(20);
    let bad_size = || VoxelError::BadSize {
        path: path_buf(),
        resolution: stored_resolution,
        channels: stored_channels,
    };
    let resolution = positive(stored_resolution).ok_or_else(bad_size)?;
    let [channels] = positive([stored_channels]).ok_or_else(bad_size)?;
    let values_bytes = cell_count(resolution)
        .and_then(|cells| cells.checked_mul(channels as usize * 4))
        .ok_or_else(bad_size)?;
    let expected = values_bytes
        .checked_add(HEADER_BYTES)
        .ok_or_else(bad_size)?;
    if bytes.len() != expected {
        return Err(wrong_length(expected));
    }
    let values = bytes[HEADER_BYTES..]
        .chunks_exact(channels as usize * 4)
        .map(|cell| f32::from_le_bytes(word(cell, 0)))
        .collect();
    Ok(VoxelGrid {
        resolution,
        bbox_min: Vec3::new(float_at(24), float_at(28), float_at(32)),
        bbox_max: Vec3::new(float_at(36), float_at(40), float_at(44)),
        values,
    })
}

/// The 4 bytes at `offset`; the caller has checked the length.
fn word(bytes: &[u8], offset: usize) -> [u8; 4] {
    [
        bytes[offset],
        bytes[offset + 1],
        bytes[offset + 2],
        bytes[offset + 3],
    ]
}

/// The values as `u32` when every one is at least 1.
fn positive<const N: usize>(values: [i32; N]) -> Option<[u32; N]> {
    values
        .iter()
        .all(|&v| v >= 1)
        .then(|| values.map(|v| v as u32))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fsutil::ScratchDir;

    fn ramp_grid() -> VoxelGrid {
        let (min, max) = (Vec3::new(-100.0, 0.0, 50.0), Vec3::new(100.0, 400.0, 250.0));
        VoxelGrid::from_fn([4, 3, 2], min, max, |p| p.x + 2.0 * p.y - 0.5 * p.z)
    }

    #[test]
    fn round_trip_keeps_everything() {
        let grid = ramp_grid();
        let dir = ScratchDir::new("voxel-round-trip");
        let path = dir.join("ramp.vol");
        grid.write_vol(&path).unwrap();
        assert_eq!(std::fs::metadata(&path).unwrap().len(), 48 + 4 * 24);
        assert_eq!(VoxelGrid::read_vol(&path).unwrap(), grid);
    }

    #[test]
    fn from_fn_evaluates_cell_centres_x_fastest() {
        let grid = ramp_grid();
        // Cell [1, 2, 1]: centre x = -100 + 1.5 * 50, y = 2.5 * 400 / 3, z = 50 + 1.5 * 100.
        let centre = Vec3::new(-25.0, 1000.0 / 3.0, 200.0);
        let expected = centre.x + 2.0 * centre.y - 0.5 * centre.z;
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

    #[test]
    fn multi_channel_files_keep_channel_zero() {
        let mut bytes = ramp_grid().to_vol_bytes()[..HEADER_BYTES].to_vec();
        bytes[8..24].copy_from_slice(bytemuck::cast_slice(&[2i32, 1, 1, 3]));
        bytes.extend(bytemuck::cast_slice(&[1.0f32, 9.0, 9.0, 2.0, 9.0, 9.0]));
        let grid = parse_vol(&bytes, Path::new("rgb.vol")).unwrap();
        assert_eq!(grid.values, vec![1.0, 2.0]);
    }

    #[test]
    fn truncated_file_is_rejected_with_its_path() {
        let dir = ScratchDir::new("voxel-truncated");
        let path = dir.join("short.vol");
        let bytes = ramp_grid().to_vol_bytes();
        std::fs::write(&path, &bytes[..bytes.len() - 4]).unwrap();
        let error = VoxelGrid::read_vol(&path).unwrap_err();
        assert!(matches!(
            error,
            VoxelError::WrongLength {
                expected: 144,
                found: 140,
                ..
            }
        ));
        assert!(error.to_string().contains("short.vol"));
    }

    #[test]
    fn wrong_magic_version_encoding_and_size_are_rejected() {
        let good = ramp_grid().to_vol_bytes();
        let with = |offset: usize, patch: &[u8]| {
            let mut bytes = good.clone();
            bytes[offset..offset + patch.len()].copy_from_slice(patch);
            parse_vol(&bytes, Path::new("bad.vol")).unwrap_err()
        };
        assert!(matches!(with(0, b"PNG"), VoxelError::BadMagic { .. }));
        assert!(matches!(
            with(3, &[4]),
            VoxelError::BadVersion { found: 4, .. }
        ));
        assert!(matches!(
            with(4, &2i32.to_le_bytes()),
            VoxelError::BadEncoding { found: 2, .. }
        ));
        assert!(matches!(
            with(12, &0i32.to_le_bytes()),
            VoxelError::BadSize { .. }
        ));
        let huge = [i32::MAX; 4].map(i32::to_le_bytes).concat();
        assert!(matches!(with(8, &huge), VoxelError::BadSize { .. }));
    }

    #[test]
    fn write_refuses_mismatched_values_and_leaves_no_file() {
        let mut grid = ramp_grid();
        grid.values.pop();
        let dir = ScratchDir::new("voxel-mismatch");
        let path = dir.join("bad.vol");
        assert!(matches!(
            grid.write_vol(&path),
            Err(VoxelError::ValueCount {
                expected: 24,
                found: 23,
                ..
            })
        ));
        assert!(dir.entries().is_empty());
    }
}
