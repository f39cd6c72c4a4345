//! Where the particle tables come from: the scattering tables of the default scene ship with the
//! crate; any other scene's are looked up in the cache by their key and baked (and cached) when
//! absent. A cached file that is truncated, corrupt or stale is reported and replaced, never used.

use half::f16;
use std::path::{Path, PathBuf};

use super::ParticleTableSpec;
use super::density::ReferenceParticle;
use super::optical_depth::{ChordProfile, OpticalDepthLayout, OpticalDepthTable};
use super::scattering::{BakeReport, Progress, ScatteringLayout, ScatteringTables};
use super::table_file::{TableError, TableFile, TableKind, TableProblem, read_bytes};

/// The scattering tables of the default scene (`cloudscape bake` of it writes this file).
pub const SHIPPED_SCATTERING: &[u8] = include_bytes!("tables/default-scattering.cslut");

/// Where tables came from.
#[derive(Debug)]
pub enum TableOrigin {
    /// The tables shipped with the crate.
    Shipped,
    /// A cached file.
    Cached(PathBuf),
    /// Baked now and written to `path`; `replaced` says what was wrong with the file there.
    Baked {
        /// The file written.
        path: PathBuf,
        /// The unusable file it replaced, if any.
        replaced: Option<TableError>,
        /// What the bake did.
        report: BakeReport,
    },
}

/// A directory of cached tables.
pub struct TableStore {
    /// The directory.
    pub dir: PathBuf,
}

impl TableStore {
    /// The store in `dir`.
    pub fn new(dir: impl Into<PathBuf>) -> TableStore {
        TableStore { dir: dir.into() }
    }

    /// The store in the user's cache directory ([`crate::fsutil::cache_dir`]).
    pub fn user_cache() -> TableStore {
        TableStore::new(crate::fsutil::cache_dir())
    }

    /// The path of the scattering tables with `key`.
    pub fn scattering_path(&self, key: u64) -> PathBuf {
        self.dir.join(TableKind::Scattering.file_name(key))
    }

    /// The path of the optical-depth table with `key`.
    pub fn optical_depth_path(&self, key: u64) -> PathBuf {
        self.dir.join(TableKind::OpticalDepth.file_name(key))
    }

    /// The scattering tables of `spec`: shipped, cached, or baked now and cached.
    pub fn scattering(
        &self,
        spec: &ParticleTableSpec,
        progress: Progress,
    ) -> std::io::Result<(ScatteringTables, TableOrigin)> {
        let key = spec.scattering_key();
        if let Ok(tables) = scattering_from_bytes(SHIPPED_SCATTERING, spec) {
            return Ok((tables, TableOrigin::Shipped));
        }
        let path = self.scattering_path(key);
        let read = read_bytes(&path).and_then(|bytes| {
            scattering_from_bytes(&bytes, spec).map_err(|problem| TableError {
                path: path.clone(),
                problem,
            })
        });
        let replaced = match read {
            Ok(tables) => return Ok((tables, TableOrigin::Cached(path))),
            Err(TableError {
                problem: TableProblem::Unreadable(_),
                ..
            }) if !path.exists() => None,
            Err(e) => Some(e),
        };
        let (tables, report) = bake_scattering(spec, progress);
        scattering_file(&tables, key).write(&path)?;
        Ok((
            tables,
            TableOrigin::Baked {
                path,
                replaced,
                report,
            },
        ))
    }
}

/// Bakes the scattering tables of `spec`.
pub fn bake_scattering(
    spec: &ParticleTableSpec,
    progress: Progress,
) -> (ScatteringTables, BakeReport) {
    let particle = spec.symmetric_particle();
    ScatteringTables::bake(&particle, spec.scattering, spec.orders, progress)
}

/// The file of scattering tables with `key`: single and multiple interleaved.
pub fn scattering_file(tables: &ScatteringTables, key: u64) -> TableFile {
    let d = tables.layout.texture_dims();
    TableFile {
        kind: TableKind::Scattering,
        key,
        dims: [d.x, d.y, d.z, 1],
        channels: 2,
        values: tables
            .single
            .iter()
            .zip(&tables.multiple)
            .flat_map(|(s, m)| [f16::from_f32(*s), f16::from_f32(*m)])
            .collect(),
    }
}

/// The scattering tables a file holds.
pub fn scattering_from_file(file: &TableFile) -> ScatteringTables {
    let layout = ScatteringLayout {
        view_azimuth: file.dims[0],
        view_zenith: file.dims[1],
        entry: file.dims[2],
    };
    let pairs = file.values.chunks_exact(2);
    ScatteringTables {
        layout,
        single: pairs.clone().map(|p| p[0].to_f32()).collect(),
        multiple: pairs.map(|p| p[1].to_f32()).collect(),
    }
}

/// The file of an optical-depth table with `key`.
pub fn optical_depth_file(table: &OpticalDepthTable, key: u64) -> TableFile {
    let l = table.layout;
    TableFile {
        kind: TableKind::OpticalDepth,
        key,
        dims: [l.start_zenith, l.start_azimuth, l.dir_zenith, l.dir_azimuth],
        channels: 1,
        values: table.values.clone(),
    }
}

/// The optical-depth table a file holds, for `particle` (whose chord masses its ratios are
/// relative to; the file's key names the particle).
pub fn optical_depth_from_file(
    file: &TableFile,
    particle: &ReferenceParticle,
) -> OpticalDepthTable {
    let [start_zenith, start_azimuth, dir_zenith, dir_azimuth] = file.dims;
    OpticalDepthTable {
        layout: OpticalDepthLayout {
            start_zenith,
            start_azimuth,
            dir_zenith,
            dir_azimuth,
        },
        values: file.values.clone(),
        chords: ChordProfile::of_particle(particle),
    }
}

/// Reads the optical-depth table of `spec` at `path`.
pub fn read_optical_depth(
    path: &Path,
    spec: &ParticleTableSpec,
) -> Result<OpticalDepthTable, TableError> {
    read_bytes(path).and_then(|bytes| {
        optical_depth_from_bytes(&bytes, spec).map_err(|problem| TableError {
            path: path.to_path_buf(),
            problem,
        })
    })
}

/// The scattering tables of `spec` in the bytes of a table file: of its kind, key and shape,
/// whole, and holding only finite values >= 0.
pub fn scattering_from_bytes(
    bytes: &[u8],
    spec: &ParticleTableSpec,
) -> Result<ScatteringTables, TableProblem> {
    let d = spec.scattering.texture_dims();
    TableFile::decode(bytes, TableKind::Scattering, spec.scattering_key())
        .and_then(|file| file.expect_shape([d.x, d.y, d.z, 1], 2))
        .map(|file| scattering_from_file(&file))
}

/// The optical-depth table of `spec` in the bytes of a table file, checked as
/// [`scattering_from_bytes`] checks.
pub fn optical_depth_from_bytes(
    bytes: &[u8],
    spec: &ParticleTableSpec,
) -> Result<OpticalDepthTable, TableProblem> {
    let l = spec.optical_depth;
    let dims = [l.start_zenith, l.start_azimuth, l.dir_zenith, l.dir_azimuth];
    TableFile::decode(bytes, TableKind::OpticalDepth, spec.optical_depth_key())
        .and_then(|file| file.expect_shape(dims, 1))
        .map(|file| optical_depth_from_file(&file, &spec.particle))
}
