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
        let checksum = fnv1a(&bytes);
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
        let count = dims
            .iter()
            .chain([&channels])
            .map(|&d| d as usize)
            .product::<usize>();
        let expected = HEADER_BYTES + count * 2 + 8;
        if bytes.len() != expected {
            return Err(TableProblem::Truncated {
                found: bytes.len(),
                expected,
            });
        }
        let body = &bytes[..expected - 8];
        let stored = u64::from_le_bytes(bytes[expected - 8..].try_into().expect("8 bytes"));
        if fnv1a(body) != stored {
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
        let values = body[HEADER_BYTES..]
            .chunks_exact(2)
            .map(|c| f16::from_bits(u16::from_le_bytes([c[0], c[1]])))
            .collect();
        Ok(TableFile {
            kind,
            key,
            dims,
            channels,
            values,
        })
    }

    /// Reads the table of `kind` with `key` at `path`.
    pub fn read(path: &Path, kind: TableKind, key: u64) -> Result<TableFile, TableError> {
        let error = |problem| TableError {
            path: path.to_path_buf(),
            problem,
        };
        let bytes =
            std::fs::read(path).map_err(|e| error(TableProblem::Unreadable(e.to_string())))?;
        Self::decode(&bytes, kind, key).map_err(error)
    }

    /// Writes the file atomically (a reader never sees half of it), making its directory.
    pub fn write(&self, path: &Path) -> std::io::Result<()> {
        if let Some(dir) = path.parent() {
            std::fs::create_dir_all(dir)?;
        }
        crate::fsutil::write_bytes_atomically(path, &self.encode())
    }
}

fn u32_at(bytes: &[u8], at: usize) -> u32 {
    u32::from_le_bytes(bytes[at..at + 4].try_into().expect("4 bytes"))
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

/// Where table files are cached: `$CLOUDSCAPE_CACHE_DIR`, else `$XDG_CACHE_HOME/cloudscape`, else
/// `~/.cache/cloudscape`, else `cloudscape-cache` in the system's temporary directory.
pub fn cache_dir() -> PathBuf {
    let var = |name: &str| {
        std::env::var_os(name)
            .filter(|v| !v.is_empty())
            .map(PathBuf::from)
    };
    var("CLOUDSCAPE_CACHE_DIR")
        .or_else(|| var("XDG_CACHE_HOME").map(|d| d.join("cloudscape")))
        .or_else(|| var("HOME").map(|d| d.join(".cache").join("cloudscape")))
        .unwrap_or_else(|| std::env::temp_dir().join("cloudscape-cache"))
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
