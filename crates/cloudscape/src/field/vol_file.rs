//! Mitsuba 3 `.vol` files of [`VoxelGrid`]s.
//!
//! The format (Mitsuba 0.6 and 3, `src/volumes/grid.cpp`; see `physics.md`), little endian:
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
//! A [`VoxelGrid`] holds one channel: reading a multi-channel file keeps channel 0. A header is
//! checked against [`MAX_AXIS_CELLS`], [`MAX_VALUE_BYTES`] and the file's length before any value
//! is read, and every value must be a density the GPU can hold (finite, 0..65504, the largest
//! half float), unless [`ValuePolicy::Replace`] is asked for.

use std::fs::File;
use std::io::Read;
use std::path::{Path, PathBuf};

use glam::Vec3;
use half::f16;

use super::voxel::{VoxelGrid, cell_count};
use crate::fsutil::write_bytes_atomically;

/// Most cells along one axis of a grid: WebGPU's guaranteed `maxTextureDimension3D` (the grid is
/// bricked for the GPU, `field/brick.rs`, whose lattice takes a 2048^3 box).
pub const MAX_AXIS_CELLS: u32 = 2048;
/// Most bytes of values (all channels) a `.vol` file may hold: 1 GiB.
pub const MAX_VALUE_BYTES: usize = 1 << 30;

/// What to do with a value that is not a density the GPU can hold (not finite, negative, or
/// above 65504, the largest half float).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ValuePolicy {
    /// Refuse the file, naming the first such value and its cell.
    #[default]
    Reject,
    /// Replace NaN and negative values by 0 (no cloud) and values above 65504 (+inf too) by 65504.
    Replace,
}

/// The bytes every `.vol` file starts with.
const MAGIC: &[u8; 3] = b"VOL";
/// The only `.vol` version in (Mitsuba 0.6 and 3).
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
        "{}: resolution {resolution:?} with {channels} channels is invalid (each must be >= 1)",
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
    /// A header that claims more than this reader accepts.
    #[error(
        "{}: resolution {resolution:?} with {channels} channels is too large; allowed at most \
         {MAX_AXIS_CELLS} cells along each axis and {MAX_VALUE_BYTES} bytes of values",
        path.display()
    )]
    TooLarge {
        /// The file.
        path: PathBuf,
        /// x, y, z resolution as stored.
        resolution: [u32; 3],
        /// Channel count as stored.
        channels: u32,
    },
    /// A value that is not a density: not finite, negative, or above what a half float holds.
    #[error(
        "{}: value {value} at index {index} (cell x, y, z = {cell:?}) is not allowed; values must \
         be finite and 0..{} (the largest half float, as the GPU stores them); a volume's \
         `sanitize = true` replaces such values instead",
        path.display(), f16::MAX
    )]
    BadValue {
        /// The file.
        path: PathBuf,
        /// Index of the value among the cells, x fastest.
        index: usize,
        /// Its cell.
        cell: [u32; 3],
        /// The value.
        value: f32,
    },
    /// A bounding box corner that is not finite.
    #[error("{}: bounding box {min:?}..{max:?} is not finite", path.display())]
    BadBounds {
        /// The file.
        path: PathBuf,
        /// Minimum corner as stored.
        min: Vec3,
        /// Maximum corner as stored.
        max: Vec3,
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

impl VoxelGrid {
    /// Reads a `.vol` file, keeping channel 0 of multi-channel files; a value that is not a
    /// density is an error ([`ValuePolicy::Reject`]).
    pub fn read_vol(path: &Path) -> Result<VoxelGrid, VoxelError> {
        Self::read_vol_with(path, ValuePolicy::Reject)
    }

    /// Reads a `.vol` file with `policy` for values that are not densities. The header is checked
    /// against the limits and the file's length before the values are read.
    pub fn read_vol_with(path: &Path, policy: ValuePolicy) -> Result<VoxelGrid, VoxelError> {
        let io = |source| io_error(path, source);
        let mut file = File::open(path).map_err(io)?;
        let mut bytes = Vec::with_capacity(HEADER_BYTES);
        (&mut file)
            .take(HEADER_BYTES as u64)
            .read_to_end(&mut bytes)
            .map_err(io)?;
        let header = Header::parse(&bytes, path)?;
        let length = file.metadata().map_err(io)?.len();
        if length != header.file_bytes as u64 {
            return Err(VoxelError::WrongLength {
                path: path.to_path_buf(),
                expected: header.file_bytes,
                found: usize::try_from(length).unwrap_or(usize::MAX),
            });
        }
        bytes.reserve_exact(header.file_bytes - HEADER_BYTES);
        file.read_to_end(&mut bytes).map_err(io)?;
        Self::from_vol_bytes(&bytes, path, policy)
    }

    /// Reads the bytes of a `.vol` file (named `path` in errors) with `policy` for values that are
    /// not densities: for grids a host holds in memory.
    pub fn from_vol_bytes(
        bytes: &[u8],
        path: &Path,
        policy: ValuePolicy,
    ) -> Result<VoxelGrid, VoxelError> {
        let header = Header::parse(bytes, path)?;
        if bytes.len() != header.file_bytes {
            return Err(VoxelError::WrongLength {
                path: path.to_path_buf(),
                expected: header.file_bytes,
                found: bytes.len(),
            });
        }
        let mut grid = VoxelGrid {
            resolution: header.resolution,
            bbox_min: header.bbox_min,
            bbox_max: header.bbox_max,
            values: bytes[HEADER_BYTES..]
                .chunks_exact(header.channels as usize * 4)
                .map(|cell| f32::from_le_bytes(word(cell, 0)))
                .collect(),
        };
        match policy {
            ValuePolicy::Reject => grid.check_values(path)?,
            ValuePolicy::Replace => {
                grid.sanitize();
            }
        }
        Ok(grid)
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

    /// Replaces every value that is not a density ([`ValuePolicy::Replace`]); the number replaced.
    pub fn sanitize(&mut self) -> usize {
        let max = f16::MAX.to_f32();
        let mut replaced = 0;
        for value in self.values.iter_mut().filter(|v| !is_density(**v)) {
            *value = if *value > max { max } else { 0.0 };
            replaced += 1;
        }
        replaced
    }

    /// The first value that is not a density, as an error naming `path`, its index and its cell.
    fn check_values(&self, path: &Path) -> Result<(), VoxelError> {
        let Some(index) = self.values.iter().position(|v| !is_density(*v)) else {
            return Ok(());
        };
        let [nx, ny, _] = self.resolution.map(|n| n as usize);
        let cell = [index % nx, index / nx % ny, index / (nx * ny)].map(|i| i as u32);
        Err(VoxelError::BadValue {
            path: path.to_path_buf(),
            index,
            cell,
            value: self.values[index],
        })
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

/// Whether `value` is a density the GPU holds as it is: finite, >= 0 and at most 65504.
fn is_density(value: f32) -> bool {
    (0.0..=f16::MAX.to_f32()).contains(&value)
}

fn io_error(path: &Path, source: std::io::Error) -> VoxelError {
    VoxelError::Io {
        path: path.to_path_buf(),
        source,
    }
}

/// What a `.vol` header says, checked.
struct Header {
    resolution: [u32; 3],
    channels: u32,
    bbox_min: Vec3,
    bbox_max: Vec3,
    /// Length of the whole file the header implies.
    file_bytes: usize,
}

impl Header {
    /// Reads and checks the header at the start of `bytes` (at least its first 48 bytes).
    fn parse(bytes: &[u8], path: &Path) -> Result<Header, VoxelError> {
        let path_buf = || path.to_path_buf();
        if !bytes.starts_with(MAGIC) {
            let found = String::from_utf8_lossy(&bytes[..bytes.len().min(3)]).into_owned();
            return Err(VoxelError::BadMagic {
                path: path_buf(),
                found,
            });
        }
        if bytes.len() < HEADER_BYTES {
            return Err(VoxelError::WrongLength {
                path: path_buf(),
                expected: HEADER_BYTES,
                found: bytes.len(),
            });
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
        let bad_size = VoxelError::BadSize {
            path: path_buf(),
            resolution: stored_resolution,
            channels: stored_channels,
        };
        let (Some(resolution), Some([channels])) =
            (positive(stored_resolution), positive([stored_channels]))
        else {
            return Err(bad_size);
        };
        let value_bytes = cell_count(resolution)
            .and_then(|cells| cells.checked_mul(channels as usize * 4))
            .filter(|&n| n <= MAX_VALUE_BYTES && resolution.iter().all(|&r| r <= MAX_AXIS_CELLS));
        let Some(value_bytes) = value_bytes else {
            return Err(VoxelError::TooLarge {
                path: path_buf(),
                resolution,
                channels,
            });
        };
        let (bbox_min, bbox_max) = (
            Vec3::new(float_at(24), float_at(28), float_at(32)),
            Vec3::new(float_at(36), float_at(40), float_at(44)),
        );
        if !(bbox_min.is_finite() && bbox_max.is_finite()) {
            return Err(VoxelError::BadBounds {
                path: path_buf(),
                min: bbox_min,
                max: bbox_max,
            });
        }
        Ok(Header {
            resolution,
            channels,
            bbox_min,
            bbox_max,
            file_bytes: HEADER_BYTES + value_bytes,
        })
    }
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
    use crate::field::voxel::tests::ramp_grid;
    use crate::fsutil::ScratchDir;

    fn parse_vol(bytes: &[u8], path: &Path) -> Result<VoxelGrid, VoxelError> {
        VoxelGrid::from_vol_bytes(bytes, path, ValuePolicy::Reject)
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
        assert!(matches!(with(8, &huge), VoxelError::TooLarge { .. }));
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

    /// The ramp's bytes with value `index` replaced by `value`.
    fn with_value(index: usize, value: f32) -> Vec<u8> {
        let mut bytes = ramp_grid().to_vol_bytes();
        let at = HEADER_BYTES + 4 * index;
        bytes[at..at + 4].copy_from_slice(&value.to_le_bytes());
        bytes
    }

    #[test]
    fn a_bad_value_is_named_with_its_index_and_cell() {
        for value in [f32::NAN, f32::INFINITY, -1.0e-3, 7.0e4] {
            let error = parse_vol(&with_value(17, value), Path::new("bad.vol")).unwrap_err();
            assert!(
                matches!(
                    error,
                    VoxelError::BadValue {
                        index: 17,
                        cell: [1, 1, 1],
                        ..
                    }
                ),
                "{value}: {error}"
            );
            let text = error.to_string();
            assert!(text.starts_with("bad.vol: value"), "{text}");
            assert!(
                text.contains("0..65504") && text.contains("sanitize"),
                "{text}"
            );
        }
    }

    #[test]
    fn replacing_bad_values_gives_zero_or_the_largest_half() {
        let mut bytes = with_value(3, f32::NAN);
        bytes[HEADER_BYTES + 20..HEADER_BYTES + 24].copy_from_slice(&(-5.0f32).to_le_bytes());
        bytes[HEADER_BYTES + 40..HEADER_BYTES + 44].copy_from_slice(&f32::INFINITY.to_le_bytes());
        let grid =
            VoxelGrid::from_vol_bytes(&bytes, Path::new("r.vol"), ValuePolicy::Replace).unwrap();
        assert_eq!((grid.values[3], grid.values[5]), (0.0, 0.0));
        assert_eq!(grid.values[10], 65504.0);
        assert_eq!(grid.values[0], ramp_grid().values[0]);
    }

    #[test]
    fn a_huge_header_fails_before_reading_the_values() {
        let dir = ScratchDir::new("voxel-huge");
        let path = dir.join("huge.vol");
        let mut bytes = ramp_grid().to_vol_bytes();
        bytes[8..20].copy_from_slice(bytemuck::cast_slice(&[1024i32, 1024, 1024]));
        std::fs::write(&path, &bytes).unwrap();
        let error = VoxelGrid::read_vol(&path).unwrap_err();
        assert!(matches!(error, VoxelError::TooLarge { .. }), "{error}");
        assert!(error.to_string().contains("1073741824 bytes"), "{error}");
        // Within the bounds but longer than the file: the file's length, before any allocation.
        bytes[8..20].copy_from_slice(bytemuck::cast_slice(&[512i32, 512, 512]));
        std::fs::write(&path, &bytes).unwrap();
        let error = VoxelGrid::read_vol(&path).unwrap_err();
        assert!(
            matches!(error, VoxelError::WrongLength { expected, .. } if expected == 48 + (1 << 29)),
            "{error}"
        );
        bytes[8..20].copy_from_slice(bytemuck::cast_slice(&[4096i32, 1, 1]));
        assert!(matches!(
            parse_vol(&bytes, &path),
            Err(VoxelError::TooLarge { .. })
        ));
    }

    #[test]
    fn a_non_finite_bounding_box_is_rejected() {
        let mut bytes = ramp_grid().to_vol_bytes();
        bytes[28..32].copy_from_slice(&f32::NAN.to_le_bytes());
        assert!(matches!(
            parse_vol(&bytes, Path::new("b.vol")),
            Err(VoxelError::BadBounds { .. })
        ));
    }
}
