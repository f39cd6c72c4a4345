//! Reading float grids from `.vdb` files (file format versions 222-224, OpenVDB 3 to 12).
//!
//! What is read, in file order (OpenVDB's `io/Archive.cc`, `io/Compression.h`, `tree/RootNode.h`,
//! `tree/InternalNode.h`, `tree/LeafNode.h`, `math/Maps.h`): the header (magic, format and library
//! versions, the grid-offsets flag, a UUID), the file's metadata, the grid descriptors (name,
//! tree type, instance parent, byte offsets); at the chosen grid's offset its compression flags,
//! metadata, transform (a map type name and its `f64` members), the tree's topology (the root's
//! background, tiles and children; per internal node its child and value masks, its tile values,
//! then its children; per leaf its value mask) and then every leaf's values in the same order.
//! Values are zlib- or Blosc-compressed chunks behind an `i64` size (negative: stored raw), of
//! only the active values when the file says so (the inactive ones restored from the background,
//! one or two stored values and a selection mask), and half floats for `_HalfFloat` grids.

use glam::{DVec3, IVec3};

use super::blosc;
use super::cursor::{Cursor, Malformed, Read};
use super::{GRID_SEPARATOR, HALF_FLOAT_SUFFIX, MAGIC, VdbTransform};
use crate::field::brick::MAX_STORED_BRICKS;
use crate::field::sparse::{BLOCK_VALUES, Block, SparseVoxels, block_local};

/// Compression flag: zlib.
pub(super) const COMPRESS_ZIP: u32 = 0x1;
/// Compression flag: only active values are stored.
pub(super) const COMPRESS_ACTIVE_MASK: u32 = 0x2;
/// Compression flag: Blosc.
const COMPRESS_BLOSC: u32 = 0x4;
/// Oldest format read: node-mask compression (OpenVDB 3.0).
const OLDEST_VERSION: u32 = 222;
/// Newest format read.
pub(super) const NEWEST_VERSION: u32 = 224;

/// What the file's header and descriptors say.
pub(super) struct Archive {
    /// The grids, in file order.
    pub grids: Vec<Descriptor>,
}

/// One grid's descriptor.
pub(super) struct Descriptor {
    /// The grid's name (without the suffix that keeps repeated names unique).
    pub name: String,
    /// The tree type, as `Tree_float_5_4_3` (without `_HalfFloat`).
    pub tree_type: String,
    /// Whether the values are stored as half floats.
    pub half: bool,
    /// The unique name of the grid whose tree this one shares ("" when it has its own).
    instance_parent: String,
    /// The unique name (with the suffix).
    unique_name: String,
    /// Byte offset of the grid.
    grid_offset: i64,
}

/// A header problem, before any grid: not a VDB, an unsupported version, or malformed bytes.
pub(super) enum HeaderError {
    NotVdb,
    Version(u32),
    Malformed(Malformed),
}

impl From<Malformed> for HeaderError {
    fn from(m: Malformed) -> Self {
        HeaderError::Malformed(m)
    }
}

impl Archive {
    /// Reads the header and the grid descriptors (each before its grid).
    pub fn parse(bytes: &[u8]) -> Result<Archive, HeaderError> {
        let mut c = Cursor::at(bytes, 0);
        if bytes.len() < 8 || c.i64("the magic number")? != MAGIC {
            return Err(HeaderError::NotVdb);
        }
        let version = c.u32("the format version")?;
        if !(OLDEST_VERSION..=NEWEST_VERSION).contains(&version) {
            return Err(HeaderError::Version(version));
        }
        c.take(8, "the library version")?;
        if c.u8("the grid-offsets flag")? == 0 {
            return c
                .error("a file without grid offsets (written as a stream) is not read")
                .map_err(Into::into);
        }
        c.take(36, "the file's UUID")?;
        skip_metadata(&mut c)?;
        let count = c.count("the grid count", 36)?;
        let grids = (0..count)
            .map(|_| Descriptor::parse(&mut c))
            .collect::<Read<Vec<_>>>()?;
        Ok(Archive { grids })
    }

    /// The descriptor with unique name `name`.
    fn by_unique_name(&self, name: &str) -> Option<&Descriptor> {
        self.grids.iter().find(|d| d.unique_name == name)
    }
}

impl Descriptor {
    fn parse(c: &mut Cursor) -> Read<Descriptor> {
        let unique_name = c.string("a grid's name")?;
        let name = unique_name
            .split(GRID_SEPARATOR)
            .next()
            .unwrap_or_default()
            .to_string();
        let stored_type = c.string("a grid's type")?;
        let (tree_type, half) = match stored_type.strip_suffix(HALF_FLOAT_SUFFIX) {
            Some(t) => (t.to_string(), true),
            None => (stored_type, false),
        };
        let instance_parent = c.string("a grid's instance parent")?;
        let grid_offset = c.i64("a grid's offset")?;
        c.i64("a grid's block offset")?;
        // The next descriptor follows this grid (`io::File::readGridDescriptors`).
        let end = c.i64("a grid's end offset")?;
        c.seek(end, "the grid's end")?;
        Ok(Descriptor {
            name,
            tree_type,
            half,
            instance_parent,
            unique_name,
            grid_offset,
        })
    }
}

/// Skips a metadata map: a count, then per entry its name, type name, byte size and bytes.
fn skip_metadata(c: &mut Cursor) -> Read<()> {
    read_metadata(c, "").map(|_| ())
}

/// Reads a metadata map, returning the string value of entry `wanted` (if any).
fn read_metadata(c: &mut Cursor, wanted: &str) -> Read<Option<String>> {
    let count = c.count("a metadata count", 12)?;
    let mut found = None;
    for _ in 0..count {
        let name = c.string("a metadata name")?;
        let kind = c.string("a metadata type")?;
        let size = c.count("a metadata size", 1)?;
        let value = c.take(size, "a metadata value")?;
        if name == wanted && kind == "string" {
            found = Some(String::from_utf8_lossy(value).into_owned());
        }
    }
    Ok(found)
}

/// A grid's problem: malformed bytes, or something cloudscape does not render.
pub(super) enum GridError {
    Malformed(Malformed),
    Unsupported(String),
}

impl From<Malformed> for GridError {
    fn from(m: Malformed) -> Self {
        GridError::Malformed(m)
    }
}

/// What a float grid holds.
pub(super) struct GridData {
    pub transform: VdbTransform,
    pub voxels: SparseVoxels,
}

/// Reads the float grid of `descriptor`.
pub(super) fn read_grid(
    bytes: &[u8],
    archive: &Archive,
    descriptor: &Descriptor,
) -> Result<GridData, GridError> {
    let mut c = Cursor::at(bytes, 0);
    c.seek(descriptor.grid_offset, "the grid")?;
    let compression = c.u32("the grid's compression flags")?;
    let class = read_metadata(&mut c, "class")?;
    if class.as_deref() == Some("level set") {
        return Err(GridError::Unsupported(
            "it is a level set (a surface), not a fog volume of densities; convert it to a fog \
             volume first (Houdini: VDB Convert; OpenVDB: tools::sdfToFogVolume)"
                .into(),
        ));
    }
    let transform = read_transform(&mut c)?;
    let (mut c, compression) = if descriptor.instance_parent.is_empty() {
        (c, compression)
    } else {
        tree_of_parent(bytes, archive, &descriptor.instance_parent)?
    };
    let mut tree = TreeReader {
        c: &mut c,
        compression,
        half: descriptor.half,
        background: 0.0,
    };
    let voxels = tree.read()?;
    Ok(GridData { transform, voxels })
}

/// A cursor at the tree of the grid named `parent` (an instanced grid shares it), and that grid's
/// compression.
fn tree_of_parent<'a>(
    bytes: &'a [u8],
    archive: &Archive,
    parent: &str,
) -> Result<(Cursor<'a>, u32), GridError> {
    let descriptor = archive.by_unique_name(parent).ok_or_else(|| {
        GridError::Unsupported(format!(
            "it shares the tree of grid {parent:?}, which the file lacks"
        ))
    })?;
    if !descriptor.instance_parent.is_empty() {
        return Err(GridError::Unsupported(format!(
            "it shares the tree of grid {parent:?}, itself an instance"
        )));
    }
    let mut c = Cursor::at(bytes, 0);
    c.seek(descriptor.grid_offset, "the instanced grid")?;
    let compression = c.u32("the instanced grid's compression flags")?;
    skip_metadata(&mut c)?;
    read_transform(&mut c)?;
    Ok((c, compression))
}

/// Reads a transform; only axis-aligned ones (scale and translation) are rendered.
fn read_transform(c: &mut Cursor) -> Result<VdbTransform, GridError> {
    let kind = c.string("the transform's type")?;
    let (voxel_size, translation) = match kind.as_str() {
        "UniformScaleMap" | "ScaleMap" => {
            let scale = c.dvec3("the transform's scale")?;
            c.take(4 * 24, "the transform's derived values")?;
            (scale, DVec3::ZERO)
        }
        "UniformScaleTranslateMap" | "ScaleTranslateMap" => {
            let translation = c.dvec3("the transform's translation")?;
            let scale = c.dvec3("the transform's scale")?;
            c.take(4 * 24, "the transform's derived values")?;
            (scale, translation)
        }
        "TranslationMap" => (DVec3::ONE, c.dvec3("the transform's translation")?),
        "AffineMap" => affine_scale_translation(c)?,
        "UnitaryMap" => {
            return Err(GridError::Unsupported(
                "its transform rotates the grid (UnitaryMap); only scale and translation are supported".into(),
            ));
        }
        other => {
            return Err(GridError::Unsupported(format!(
                "its transform is a {other}; only scale and translation are supported"
            )));
        }
    };
    if !(voxel_size.is_finite() && translation.is_finite() && voxel_size.cmpgt(DVec3::ZERO).all()) {
        return Err(GridError::Unsupported(format!(
            "its voxel size {voxel_size} with offset {translation} is not a positive, finite scale \
             (mirrored and degenerate grids are not supported)"
        )));
    }
    Ok(VdbTransform {
        voxel_size,
        translation,
    })
}

/// The scale and translation of an `AffineMap` (a row-major 4x4 matrix that multiplies row
/// vectors: the translation is its last row), refused when it rotates or shears.
fn affine_scale_translation(c: &mut Cursor) -> Result<(DVec3, DVec3), GridError> {
    let mut m = [[0.0f64; 4]; 4];
    for row in &mut m {
        for value in row {
            *value = f64::from_le_bytes(c.array("the transform's matrix")?);
        }
    }
    let scale = DVec3::new(m[0][0], m[1][1], m[2][2]);
    let off_diagonal = (0..3)
        .flat_map(|i| (0..3).filter(move |j| *j != i).map(move |j| (i, j)))
        .map(|(i, j)| m[i][j].abs())
        .fold(0.0, f64::max);
    if off_diagonal > 1e-9 * scale.abs().max_element() {
        return Err(GridError::Unsupported(
            "its transform rotates or shears the grid (AffineMap); only scale and translation are supported"
                .into(),
        ));
    }
    Ok((scale, DVec3::new(m[3][0], m[3][1], m[3][2])))
}

/// A node mask: one bit per child or value, in `u64` words (OpenVDB's `NodeMask`).
struct Mask(Vec<u64>);

impl Mask {
    fn read(c: &mut Cursor, bits: usize, what: &str) -> Read<Mask> {
        let bytes = c.take(bits / 8, what)?;
        Ok(Mask(
            bytes
                .chunks_exact(8)
                .map(|w| u64::from_le_bytes(w.try_into().expect("8 bytes")))
                .collect(),
        ))
    }

    fn is_on(&self, i: usize) -> bool {
        self.0[i / 64] >> (i % 64) & 1 == 1
    }

    fn count_on(&self) -> usize {
        self.0.iter().map(|w| w.count_ones() as usize).sum()
    }

    fn on(&self) -> impl Iterator<Item = usize> + '_ {
        (0..self.0.len() * 64).filter(|i| self.is_on(*i))
    }
}

/// An internal node's topology: its tiles and its children.
struct Internal<C> {
    origin: IVec3,
    tiles: Vec<(IVec3, f32, bool)>,
    children: Vec<C>,
}

/// A leaf's origin (its values come later).
struct LeafOrigin(IVec3);

/// Reads a tree of `Tree_float_5_4_3`: the root, internal nodes of 32^3 and 16^3 children, leaves
/// of 8^3 voxels.
struct TreeReader<'c, 'a> {
    c: &'c mut Cursor<'a>,
    compression: u32,
    half: bool,
    background: f32,
}

/// Voxels along an edge of what a root child covers (32 * 16 * 8).
const ROOT_CHILD_VOXELS: i32 = 4096;

impl TreeReader<'_, '_> {
    fn read(&mut self) -> Result<SparseVoxels, GridError> {
        let buffers = self.c.i32("the tree's buffer count")?;
        if buffers != 1 {
            return self
                .c
                .error(format!("a tree with {buffers} buffers (1 expected)"))
                .map_err(Into::into);
        }
        self.background = self.c.f32("the background value")?;
        if self.background != 0.0 {
            return Err(GridError::Unsupported(format!(
                "its background value is {}; a fog volume's is 0 (is it a level set?)",
                self.background
            )));
        }
        let tile_count = self.c.count("the root's tile count", 17)?;
        let child_count = self.c.count("the root's child count", 12 + 2 * 4096)?;
        let mut voxels = Voxels::default();
        for _ in 0..tile_count {
            let origin = self.c.ivec3("a root tile")?;
            let value = self.c.f32("a root tile")?;
            let active = self.c.u8("a root tile")? != 0;
            voxels.tile(origin, ROOT_CHILD_VOXELS, value, active)?;
        }
        let mut children = (0..child_count)
            .map(|_| {
                let origin = self.c.ivec3("a root child's origin")?;
                self.internal(origin, 5, |reader, origin| {
                    reader.internal(origin, 4, Self::leaf)
                })
            })
            .collect::<Result<Vec<_>, GridError>>()?;
        children.sort_by_key(|n| n.origin.to_array());
        for upper in &children {
            voxels.tiles(upper, 128)?;
            for lower in &upper.children {
                voxels.tiles(lower, 8)?;
                for leaf in &lower.children {
                    let (mask, values) = self.leaf_values()?;
                    voxels.leaf(leaf.0, &mask, values)?;
                }
            }
        }
        Ok(voxels.done())
    }

    /// An internal node of `2^log2_children` children per axis, its children read by `child`.
    fn internal<C>(
        &mut self,
        origin: IVec3,
        log2_children: u32,
        child: impl Fn(&mut Self, IVec3) -> Result<C, GridError> + Copy,
    ) -> Result<Internal<C>, GridError> {
        let count = 1usize << (3 * log2_children);
        let child_mask = Mask::read(self.c, count, "an internal node's child mask")?;
        let value_mask = Mask::read(self.c, count, "an internal node's value mask")?;
        let values = self.values(count, &value_mask)?;
        let child_voxels = if log2_children == 5 { 128 } else { 8 };
        let local = |i: usize| {
            let n = log2_children;
            let i = i as i32;
            IVec3::new(i >> (2 * n), (i >> n) & ((1 << n) - 1), i & ((1 << n) - 1)) * child_voxels
        };
        let tiles = (0..count)
            .filter(|i| !child_mask.is_on(*i))
            .filter(|i| values[*i] != 0.0 || value_mask.is_on(*i))
            .map(|i| (origin + local(i), values[i], value_mask.is_on(i)))
            .collect();
        let children = child_mask
            .on()
            .map(|i| child(self, origin + local(i)))
            .collect::<Result<Vec<_>, GridError>>()?;
        Ok(Internal {
            origin,
            tiles,
            children,
        })
    }

    /// A leaf's topology: its value mask (read again with its values).
    fn leaf(&mut self, origin: IVec3) -> Result<LeafOrigin, GridError> {
        self.c.take(BLOCK_VALUES / 8, "a leaf's value mask")?;
        Ok(LeafOrigin(origin))
    }

    /// A leaf's value mask and values.
    fn leaf_values(&mut self) -> Result<(Mask, Vec<f32>), GridError> {
        let mask = Mask::read(self.c, BLOCK_VALUES, "a leaf's value mask")?;
        let values = self.values(BLOCK_VALUES, &mask)?;
        Ok((mask, values))
    }

    /// `count` values stored under `mask` (`io::readCompressedValues`).
    fn values(&mut self, count: usize, mask: &Mask) -> Result<Vec<f32>, GridError> {
        let c = &mut *self.c;
        let metadata = c.u8("the values' mask compression")?;
        if metadata > 6 {
            return c
                .error(format!("mask compression {metadata} (0 to 6 expected)"))
                .map_err(Into::into);
        }
        let background = self.background;
        let mut inactive = [
            if metadata == 0 {
                background
            } else {
                -background
            },
            background,
        ];
        if matches!(metadata, 2 | 4 | 5) {
            inactive[0] = c.f32("an inactive value")?;
        }
        if metadata == 5 {
            inactive[1] = c.f32("an inactive value")?;
        }
        let selection = if matches!(metadata, 3..=5) {
            Some(Mask::read(c, count, "the inactive values' selection mask")?)
        } else {
            None
        };
        let masked = self.compression & COMPRESS_ACTIVE_MASK != 0 && metadata != 6;
        let stored_count = if masked { mask.count_on() } else { count };
        let stored = self.data(stored_count)?;
        if stored_count == count {
            return Ok(stored);
        }
        let mut stored = stored.into_iter();
        Ok((0..count)
            .map(|i| match (mask.is_on(i), &selection) {
                (true, _) => stored.next().expect("one stored value per active bit"),
                (false, Some(s)) if s.is_on(i) => inactive[1],
                (false, _) => inactive[0],
            })
            .collect())
    }

    /// `count` values, compressed as the grid says (`io::readData`, `HalfReader`).
    fn data(&mut self, count: usize) -> Result<Vec<f32>, GridError> {
        // `HalfReader` reads nothing at all for no values; full floats keep their chunk's size.
        if self.half && count == 0 {
            return Ok(Vec::new());
        }
        let value_bytes = if self.half { 2 } else { 4 };
        let bytes = count * value_bytes;
        let c = &mut *self.c;
        let raw = if self.compression & (COMPRESS_BLOSC | COMPRESS_ZIP) != 0 {
            let size = c.i64("a compressed chunk's size")?;
            if size <= 0 {
                if size.unsigned_abs() != bytes as u64 {
                    return c
                        .error(format!(
                            "a raw chunk of {} bytes where {bytes} were expected",
                            -size
                        ))
                        .map_err(Into::into);
                }
                c.take(bytes, "a raw chunk")?.to_vec()
            } else {
                let at = c.offset();
                let chunk = c.take(size as usize, "a compressed chunk")?;
                let decoded = if self.compression & COMPRESS_BLOSC != 0 {
                    blosc::decompress(chunk, bytes)
                } else {
                    inflate(chunk, bytes)
                };
                decoded.map_err(|message| Malformed {
                    offset: at,
                    message,
                })?
            }
        } else {
            c.take(bytes, "uncompressed values")?.to_vec()
        };
        Ok(if self.half {
            raw.chunks_exact(2)
                .map(|h| half::f16::from_le_bytes([h[0], h[1]]).to_f32())
                .collect()
        } else {
            raw.chunks_exact(4)
                .map(|w| f32::from_le_bytes(w.try_into().expect("4 bytes")))
                .collect()
        })
    }
}

/// A zlib stream (`io::unzipFromStream`) of exactly `bytes` bytes.
fn inflate(chunk: &[u8], bytes: usize) -> Result<Vec<u8>, String> {
    use std::io::Read as _;
    let mut out = Vec::with_capacity(bytes);
    flate2::read::ZlibDecoder::new(chunk)
        .take(bytes as u64 + 1)
        .read_to_end(&mut out)
        .map_err(|e| format!("a zlib chunk does not decode: {e}"))?;
    if out.len() != bytes {
        return Err(format!(
            "a zlib chunk of {} bytes where {bytes} were expected",
            out.len()
        ));
    }
    Ok(out)
}

/// The blocks and active box being gathered from a tree.
#[derive(Default)]
struct Voxels {
    sparse: SparseVoxels,
    active: Option<(IVec3, IVec3)>,
}

impl Voxels {
    fn include(&mut self, lo: IVec3, hi: IVec3) {
        self.active = Some(match self.active {
            Some((a, b)) => (a.min(lo), b.max(hi)),
            None => (lo, hi),
        });
    }

    /// The tiles of an internal node, each `edge` voxels a side.
    fn tiles<C>(&mut self, node: &Internal<C>, edge: i32) -> Result<(), GridError> {
        node.tiles
            .iter()
            .try_for_each(|&(origin, value, active)| self.tile(origin, edge, value, active))
    }

    /// A tile of `edge` voxels a side: uniform blocks where its value is not 0.
    fn tile(
        &mut self,
        origin: IVec3,
        edge: i32,
        value: f32,
        active: bool,
    ) -> Result<(), GridError> {
        if active {
            self.include(origin, origin + edge - 1);
        }
        if value == 0.0 {
            return Ok(());
        }
        let per_axis = (edge / 8) as usize;
        if self.sparse.blocks.len() + per_axis.pow(3) > MAX_STORED_BRICKS {
            return Err(GridError::Unsupported(format!(
                "a tile of {edge}^3 voxels with value {value} would fill more than \
                 {MAX_STORED_BRICKS} blocks of 8^3 voxels"
            )));
        }
        for z in (0..edge).step_by(8) {
            for y in (0..edge).step_by(8) {
                for x in (0..edge).step_by(8) {
                    self.sparse
                        .blocks
                        .insert(origin + IVec3::new(x, y, z), Block::Uniform(value));
                }
            }
        }
        Ok(())
    }

    /// A leaf's values and its active voxels.
    fn leaf(&mut self, origin: IVec3, mask: &Mask, values: Vec<f32>) -> Result<(), GridError> {
        for i in mask.on() {
            let v = origin + block_local(i).as_ivec3();
            self.include(v, v);
        }
        if self.sparse.blocks.len() >= MAX_STORED_BRICKS {
            return Err(GridError::Unsupported(format!(
                "it has more than {MAX_STORED_BRICKS} leaves of 8^3 voxels"
            )));
        }
        let values: Box<[f32; BLOCK_VALUES]> =
            values.into_boxed_slice().try_into().expect("512 values");
        self.sparse.blocks.insert(origin, Block::Voxels(values));
        Ok(())
    }

    fn done(mut self) -> SparseVoxels {
        let (min, max) = self.active.unwrap_or((IVec3::ZERO, IVec3::splat(-1)));
        self.sparse.min = min;
        self.sparse.max = max;
        self.sparse
    }
}
