//! The field's noise textures kept on disk between runs, in the user's cache directory
//! ([`crate::fsutil::cache_dir`], beside the particles' tables): a software adapter
//! spends seconds making them (the default field's three, 5.6 s of a 64x36 still's 7.8 s on
//! llvmpipe with two cores), a read takes milliseconds.
//!
//! A file holds the texels as the generator's buffer lays them out, then their FNV-1a checksum. Its
//! name carries a hash of everything that made it: the generator's whole WGSL program, the noise's
//! kind, seed and layout, and the adapter and its driver (another may round a texel differently).
//! A changed generator or another adapter therefore never reads it, and a file that is short or
//! fails its checksum is made again and replaced.

use crate::stable_hash::{StableHasher, fnv1a};
use std::path::{Path, PathBuf};

/// What made a noise texture: the names of its file.
pub struct NoiseOrigin<'a> {
    /// The texture's name ([`super::noise::NoiseKind::texture_name`]).
    pub name: &'a str,
    /// The noise seed.
    pub seed: u32,
    /// The generator's WGSL program, as the device compiled it.
    pub program: &'a str,
    /// The generator's buffer layout: texels per row (padded), rows, layers.
    pub layout: [u32; 3],
    /// The adapter that ran the generator and its driver, as `wgpu::AdapterInfo`'s `Debug`
    /// prints them.
    pub adapter: &'a str,
}

impl NoiseOrigin<'_> {
    /// The file in `dir` that holds the texels this origin makes.
    pub fn path(&self, dir: &Path) -> PathBuf {
        let mut hash = StableHasher::new();
        hash.str(self.program);
        for n in self.layout {
            hash.u32(n);
        }
        hash.str(self.adapter);
        let name = self.name.replace(' ', "-");
        dir.join(format!("{name}-{}-{:016x}.bin", self.seed, hash.finish()))
    }
}

/// The `len` texels in `path`, when it holds that many and their checksum.
pub fn read(path: &Path, len: usize) -> Option<Vec<u8>> {
    let mut bytes = std::fs::read(path).ok()?;
    if bytes.len() != len + 8 {
        return None;
    }
    let checksum = u64::from_le_bytes(bytes[len..].try_into().ok()?);
    bytes.truncate(len);
    (fnv1a(&bytes) == checksum).then_some(bytes)
}

/// Writes `texels` and their checksum to `path`, whole or not at all. A cache that cannot be
/// written (a read-only home, a full disk) only makes the next run as slow as this one, so a
/// failure is not an error.
pub fn write(path: &Path, texels: &[u8]) {
    if let Some(dir) = path.parent() {
        let _ = std::fs::create_dir_all(dir);
    }
    let mut bytes = Vec::with_capacity(texels.len() + 8);
    bytes.extend_from_slice(texels);
    bytes.extend_from_slice(&fnv1a(texels).to_le_bytes());
    let _ = crate::fsutil::write_bytes_atomically(path, &bytes);
}

#[cfg(test)]
mod tests {
    use super::*;

    fn origin(program: &str) -> NoiseOrigin<'_> {
        NoiseOrigin {
            name: "base noise",
            seed: 7,
            program,
            layout: [64, 64, 64],
            adapter: "llvmpipe",
        }
    }

    #[test]
    fn texels_round_trip_and_a_damaged_file_is_refused() {
        let dir = crate::fsutil::ScratchDir::new("noise-file");
        let path = origin("fn a() {}").path(dir.path());
        let texels: Vec<u8> = (0..1000u32).map(|i| (i * 7 % 251) as u8).collect();
        write(&path, &texels);
        assert_eq!(read(&path, texels.len()), Some(texels.clone()));
        assert_eq!(
            read(&path, texels.len() - 1),
            None,
            "another layout's length"
        );
        let mut damaged = std::fs::read(&path).expect("written");
        damaged[10] ^= 1;
        std::fs::write(&path, &damaged).expect("rewritten");
        assert_eq!(
            read(&path, texels.len()),
            None,
            "a flipped bit fails the checksum"
        );
    }

    #[test]
    fn another_generator_or_seed_names_another_file() {
        let dir = Path::new("cache");
        let one = origin("fn a() {}").path(dir);
        assert_ne!(one, origin("fn b() {}").path(dir));
        assert_ne!(
            one,
            NoiseOrigin {
                seed: 8,
                ..origin("fn a() {}")
            }
            .path(dir)
        );
        assert_ne!(
            one,
            NoiseOrigin {
                layout: [64, 64, 32],
                ..origin("fn a() {}")
            }
            .path(dir)
        );
        assert_ne!(
            one,
            NoiseOrigin {
                adapter: "gl",
                ..origin("fn a() {}")
            }
            .path(dir)
        );
        assert!(one.to_string_lossy().contains("base-noise-7-"));
    }
}
