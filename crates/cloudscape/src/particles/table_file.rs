//! Table files: a header naming the table, its key and its size, 16-bit float values, and a
//! checksum, so a truncated, stale or corrupt file is recognised as such and never read as a
//! table. The cache keeps one file per key; the tables of the default scene ship with the crate.
//!
//! Layout (little endian): `b"CSLUT\0\0\0"`, format version u32, kind u32, key u64, four u32
//! dimensions, channel count u32, `dims product x channels` f16 values, then the FNV-1a hash
//! (u64) of every byte before it.

use crate::stable_hash::{StableHasher, fnv1a};
use half::f16;
use std::fmt;
use std::path::{Path, PathBuf};

const MAGIC: &[u8; 8] = b"CSLUT\0\0\0";
/// Version of the file layout.
pub const FORMAT_VERSION: u32 = 1;
/// Version of the bake algorithms: part of every key, so a change to how tables are computed
/// makes every cached table stale.
pub const BAKE_VERSION: u32 = 2;
const HEADER_BYTES: usize = 8 + 4 + 4 + 8 + 16 + 4;

/// Which table a file holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TableKind {
    /// The 4D optical-depth table.
    OpticalDepth,
    /// The single- and multiple-scattering tables.
    Scattering,
}

impl TableKind {
    fn code(self) -> u32 {
        match self {
            TableKind::OpticalDepth => 1,
            TableKind::Scattering => 2,
        }
    }

    /// The name of the cache file of the table with `key`.
    pub fn file_name(self, key: u64) -> String {
        let stem = match self {
            TableKind::OpticalDepth => "optical-depth",
            TableKind::Scattering => "scattering",
        };
        format!("{stem}-{key:016x}.cslut")
    }
}

/// A table as stored.
#[derive(Clone, Debug, PartialEq)]
pub struct TableFile {
    /// What it holds.
    pub kind: TableKind,
    /// The key of its inputs.
    pub key: u64,
    /// Its dimensions (unused trailing ones are 1).
    pub dims: [u32; 4],
    /// Values per entry.
    pub channels: u32,
    /// The values, channels interleaved.
    pub values: Vec<f16>,
}

/// What is wrong with a table file.
#[derive(Clone, Debug, PartialEq)]
pub enum TableProblem {
    /// It could not be read.
    Unreadable(String),
    /// It is shorter than its header says.
    Truncated {
        /// Bytes found.
        found: usize,
        /// Bytes its header needs.
        expected: usize,
    },
    /// It is not a table file, or of another format version.
    NotATable,
    /// It holds another kind of table.
    WrongKind,
    /// Its contents do not match its checksum.
    Corrupt,
    /// Its header claims more values than an address space holds.
    TooLarge {
        /// The dimensions it claims.
        dims: [u32; 4],
        /// The channels it claims.
        channels: u32,
    },
    /// It holds a value that is not finite and >= 0 (every table holds ratios or radiances).
    BadValue {
        /// Index of the value, channels interleaved.
        index: usize,
        /// The value.
        value: f32,
    },
    /// Its dimensions or channels are not those its key implies.
    WrongShape {
        /// Dimensions and channels found.
        found: ([u32; 4], u32),
        /// Dimensions and channels expected.
        expected: ([u32; 4], u32),
    },
    /// It was baked for other inputs.
    Stale {
        /// The key it has.
        found: u64,
        /// The key the scene needs.
        expected: u64,
    },
}

impl fmt::Display for TableProblem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            TableProblem::Unreadable(e) => write!(f, "cannot be read: {e}"),
            TableProblem::Truncated { found, expected } => {
                write!(f, "is truncated: {found} bytes of {expected}")
            }
            TableProblem::NotATable => {
                write!(f, "is not a cloudscape table (format {FORMAT_VERSION})")
            }
            TableProblem::WrongKind => write!(f, "holds another kind of table"),
            TableProblem::Corrupt => write!(f, "is corrupt: its checksum does not match"),
            TableProblem::TooLarge { dims, channels } => {
                write!(
                    f,
                    "claims {dims:?} entries of {channels} values: too many to hold"
                )
            }
            TableProblem::BadValue { index, value } => write!(
                f,
                "holds {value} at index {index}; table values must be finite and >= 0"
            ),
            TableProblem::WrongShape { found, expected } => write!(
                f,
                "has {:?} entries of {} values; its key needs {:?} of {}",
                found.0, found.1, expected.0, expected.1
            ),
            TableProblem::Stale { found, expected } => write!(
                f,
                "is stale: baked for inputs {found:016x}, the scene needs {expected:016x}"
            ),
        }
    }
}

/// A table file that cannot be used, by path.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{}: {problem}; rebuild it with `cloudscape bake`", path.display())]
pub struct TableError {
    /// The file.
    pub path: PathBuf,
    /// What is wrong.
    pub problem: TableProblem,
}

impl TableFile {
    /// The file's bytes.
    pub fn encode(&self) -> Vec<u8> {
        let mut bytes = Vec::with_capacity(HEADER_BYTES + self.values.len() * 2 + 8);
        bytes.extend_from_slice(MAGIC);
        bytes.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
        bytes.extend_from_slice(&self.kind.code().to_le_bytes());
        bytes.extend_from_slice(&self.key.to_le_bytes());
        for d in self.dims {
            bytes.extend_from_slice(&d.to_le_bytes());
        }
        bytes.extend_from_slice(&self.channels.to_le_bytes());
        for v in &self.values {
            bytes.extend_from_slice(&v.to_bits().to_le_bytes());
        }
        let checksum = checksum(&bytes);
        bytes.extend_from_slice(&checksum.to_le_bytes());
        bytes
    }

    /// Reads a table of `kind` with `key` from `bytes`.
    pub fn decode(bytes: &[u8], kind: TableKind, key: u64) -> Result<TableFile, TableProblem> {
        if bytes.len() < HEADER_BYTES || &bytes[..8] != MAGIC || u32_at(bytes, 8) != FORMAT_VERSION
        {
            return Err(
                if bytes.len() < HEADER_BYTES && MAGIC.starts_with(&bytes[..bytes.len().min(8)]) {
                    TableProblem::Truncated {
                        found: bytes.len(),
                        expected: HEADER_BYTES,
                    }
                } else {
                    TableProblem::NotATable
                },
            );
        }
        let dims = [
            u32_at(bytes, 24),
            u32_at(bytes, 28),
            u32_at(bytes, 32),
            u32_at(bytes, 36),
        ];
        let channels = u32_at(bytes, 40);
        let expected = dims
            .iter()
            .chain([&channels])
            .try_fold(2usize, |n, &d| n.checked_mul(d as usize))
            .and_then(|n| n.checked_add(HEADER_BYTES + 8))
            .ok_or(TableProblem::TooLarge { dims, channels })?;
        if bytes.len() != expected {
            return Err(TableProblem::Truncated {
                found: bytes.len(),
                expected,
            });
        }
        let body = &bytes[..expected - 8];
        let stored = u64::from_le_bytes(bytes[expected - 8..].try_into().expect("8 bytes"));
        if checksum(body) != stored {
            return Err(TableProblem::Corrupt);
        }
        if u32_at(bytes, 12) != kind.code() {
            return Err(TableProblem::WrongKind);
        }
        let found = u64::from_le_bytes(bytes[16..24].try_into().expect("8 bytes"));
        if found != key {
            return Err(TableProblem::Stale {
                found,
                expected: key,
            });
        }
        let values: Vec<f16> = body[HEADER_BYTES..]
            .chunks_exact(2)
            .map(|c| f16::from_bits(u16::from_le_bytes([c[0], c[1]])))
            .collect();
        if let Some(index) = values
            .iter()
            .position(|v| !(v.is_finite() && v.to_f32() >= 0.0))
        {
            let value = values[index].to_f32();
            return Err(TableProblem::BadValue { index, value });
        }
        Ok(TableFile {
            kind,
            key,
            dims,
            channels,
            values,
        })
    }

    /// The table when its dimensions and channels are `dims` and `channels` (those its key
    /// implies); a file of another shape, though its checksum and key match, is never used.
    pub fn expect_shape(self, dims: [u32; 4], channels: u32) -> Result<TableFile, TableProblem> {
        if (self.dims, self.channels) != (dims, channels) {
            return Err(TableProblem::WrongShape {
                found: (self.dims, self.channels),
                expected: (dims, channels),
            });
        }
        Ok(self)
    }

    /// Reads the table of `kind` with `key` at `path`.
    pub fn read(path: &Path, kind: TableKind, key: u64) -> Result<TableFile, TableError> {
        let bytes = read_bytes(path)?;
        Self::decode(&bytes, kind, key).map_err(|problem| TableError {
            path: path.to_path_buf(),
            problem,
        })
    }

    /// Writes the file atomically (a reader never sees half of it), making its directory.
    pub fn write(&self, path: &Path) -> std::io::Result<()> {
        if let Some(dir) = path.parent() {
            std::fs::create_dir_all(dir)?;
        }
        crate::fsutil::write_bytes_atomically(path, &self.encode())
    }
}

/// The bytes of the file at `path`, or why they cannot be read.
pub(crate) fn read_bytes(path: &Path) -> Result<Vec<u8>, TableError> {
    std::fs::read(path).map_err(|e| TableError {
        path: path.to_path_buf(),
        problem: TableProblem::Unreadable(e.to_string()),
    })
}

fn u32_at(bytes: &[u8], at: usize) -> u32 {
    u32::from_le_bytes(bytes[at..at + 4].try_into().expect("4 bytes"))
}

/// The checksum a table file ends with, of `body`, every byte before it: 64-bit FNV-1a.
pub fn checksum(body: &[u8]) -> u64 {
    fnv1a(body)
}

/// Builds a table key from its inputs, each written in a fixed byte order.
pub struct KeyHasher(StableHasher);

impl KeyHasher {
    /// A key for the table called `name`, under the current [`BAKE_VERSION`].
    pub fn new(name: &str) -> KeyHasher {
        let mut hasher = StableHasher::new();
        hasher.bytes(name.as_bytes()).u32(BAKE_VERSION);
        KeyHasher(hasher)
    }

    /// Adds an integer input.
    pub fn u32(&mut self, v: u32) {
        self.0.u32(v);
    }

    /// Adds a float input (by its bits).
    pub fn f32(&mut self, v: f32) {
        self.u32(v.to_bits());
    }

    /// The key.
    pub fn finish(&self) -> u64 {
        self.0.finish()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table() -> TableFile {
        TableFile {
            kind: TableKind::Scattering,
            key: 42,
            dims: [3, 2, 2, 1],
            channels: 2,
            values: (0..24).map(|i| f16::from_f32(i as f32 * 0.5)).collect(),
        }
    }

    #[test]
    fn a_table_round_trips() {
        let t = table();
        assert_eq!(TableFile::decode(&t.encode(), t.kind, 42), Ok(t));
    }

    #[test]
    fn truncated_corrupt_stale_and_foreign_files_are_named_as_such() {
        let bytes = table().encode();
        let decode = |b: &[u8]| TableFile::decode(b, TableKind::Scattering, 42).unwrap_err();
        assert!(matches!(
            decode(&bytes[..bytes.len() - 3]),
            TableProblem::Truncated { .. }
        ));
        assert!(matches!(
            decode(&bytes[..10]),
            TableProblem::Truncated { .. }
        ));
        let mut flipped = bytes.clone();
        flipped[HEADER_BYTES + 5] ^= 0x10;
        assert_eq!(decode(&flipped), TableProblem::Corrupt);
        assert!(matches!(
            TableFile::decode(&bytes, TableKind::Scattering, 7),
            Err(TableProblem::Stale {
                found: 42,
                expected: 7
            })
        ));
        assert_eq!(
            TableFile::decode(&bytes, TableKind::OpticalDepth, 42),
            Err(TableProblem::WrongKind)
        );
        assert_eq!(
            decode(b"P6 640 480 255 and more bytes than a header"),
            TableProblem::NotATable
        );
    }

    /// `bytes` with the checksum made right again after an edit.
    fn resealed(mut bytes: Vec<u8>) -> Vec<u8> {
        let body = bytes.len() - 8;
        let sum = checksum(&bytes[..body]);
        bytes[body..].copy_from_slice(&sum.to_le_bytes());
        bytes
    }

    #[test]
    fn a_bad_value_a_wrong_shape_and_a_huge_header_are_refused() {
        let mut bytes = table().encode();
        bytes[HEADER_BYTES + 6..HEADER_BYTES + 8]
            .copy_from_slice(&f16::NAN.to_bits().to_le_bytes());
        let decode = |b: &[u8]| TableFile::decode(b, TableKind::Scattering, 42);
        assert!(matches!(
            decode(&resealed(bytes.clone())),
            Err(TableProblem::BadValue { index: 3, value }) if value.is_nan()
        ));
        let negative = f16::from_f32(-1.0).to_bits().to_le_bytes();
        bytes[HEADER_BYTES + 6..HEADER_BYTES + 8].copy_from_slice(&negative);
        assert_eq!(
            decode(&resealed(bytes)),
            Err(TableProblem::BadValue {
                index: 3,
                value: -1.0
            })
        );
        let shape = table().expect_shape([3, 2, 2, 1], 1).unwrap_err();
        assert!(
            shape
                .to_string()
                .contains("its key needs [3, 2, 2, 1] of 1"),
            "{shape}"
        );
        let mut huge = table().encode();
        huge[24..44].copy_from_slice(&[u32::MAX; 5].map(u32::to_le_bytes).concat());
        assert!(matches!(decode(&huge), Err(TableProblem::TooLarge { .. })));
    }

    #[test]
    fn errors_name_the_file_and_the_rebuild() {
        let e = TableFile::read(Path::new("/nonexistent/t.cslut"), TableKind::Scattering, 1)
            .unwrap_err();
        let text = e.to_string();
        assert!(
            text.starts_with("/nonexistent/t.cslut: cannot be read"),
            "{text}"
        );
        assert!(
            text.ends_with("rebuild it with `cloudscape bake`"),
            "{text}"
        );
    }

    #[test]
    fn keys_depend_on_every_input_and_the_name() {
        let key = |name: &str, v: f32| {
            let mut h = KeyHasher::new(name);
            h.f32(v);
            h.finish()
        };
        assert_eq!(key("a", 1.0), key("a", 1.0));
        assert_ne!(key("a", 1.0), key("a", 1.0001));
        assert_ne!(key("a", 1.0), key("b", 1.0));
    }
}
