//! Writing a float grid as a `.vdb` file OpenVDB reads: format 224, one grid, zlib compression of
//! the active values (active: every voxel whose value is not 0, as in a fog volume), the layout
//! `read.rs` reads.

use std::collections::BTreeMap;
use std::io::Write as _;
use std::path::Path;

use glam::IVec3;

use super::read::{COMPRESS_ACTIVE_MASK, COMPRESS_ZIP, NEWEST_VERSION};
use super::{FLOAT_TREE, MAGIC, VdbError, VdbGrid};
use crate::field::sparse::{BLOCK_VALUES, Block};
use crate::fsutil::write_bytes_atomically;
use crate::stable_hash::fnv1a;

/// The OpenVDB library version the files claim (the oldest that writes format 224 as here).
const LIBRARY_VERSION: [u32; 2] = [6, 2];

/// Writes `grid` as a `.vdb` file at `path`, whole or not at all.
pub fn write_vdb(path: &Path, grid: &VdbGrid) -> Result<(), VdbError> {
    write_bytes_atomically(path, &write_vdb_bytes(grid)).map_err(|source| VdbError::Io {
        path: path.to_path_buf(),
        source,
    })
}

/// The bytes of a `.vdb` file holding `grid`.
pub fn write_vdb_bytes(grid: &VdbGrid) -> Vec<u8> {
    let tree = tree_bytes(grid);
    let mut out = Bytes::default();
    out.i64(MAGIC);
    out.u32(NEWEST_VERSION);
    LIBRARY_VERSION.iter().for_each(|v| out.u32(*v));
    out.0.push(1); // grid offsets follow
    out.0.extend(uuid(&tree.all).as_bytes());
    out.u32(0); // file metadata
    out.u32(1); // grids
    out.string(&grid.name);
    out.string(FLOAT_TREE);
    out.string(""); // no instance parent
    let grid_offset = out.0.len() as i64 + 24;
    out.i64(grid_offset);
    out.i64(grid_offset + tree.buffers_at as i64);
    out.i64(grid_offset + tree.all.len() as i64);
    out.0.extend(&tree.all);
    out.0
}

/// A grid's bytes from its compression flags on, and where its leaf values begin.
struct TreeBytes {
    all: Vec<u8>,
    buffers_at: usize,
}

/// Leaves by root child, lower internal node and leaf, each in OpenVDB's order (the root's by
/// coordinate, the internal nodes' by bit index: x slowest).
type Nodes = BTreeMap<[i32; 3], BTreeMap<usize, BTreeMap<usize, IVec3>>>;

/// Voxels along an edge of a root child and of a lower internal node.
const UPPER_EDGE: i32 = 4096;
const LOWER_EDGE: i32 = 128;

/// Bit index of the child at `origin` in an internal node of `edge` voxels a side whose children
/// are `child_edge` a side.
fn child_index(origin: IVec3, edge: i32, child_edge: i32) -> usize {
    let per_axis = edge / child_edge;
    let local = origin.rem_euclid(IVec3::splat(edge)) / child_edge;
    ((local.x * per_axis + local.y) * per_axis + local.z) as usize
}

fn tree_bytes(grid: &VdbGrid) -> TreeBytes {
    let mut nodes = Nodes::new();
    let mut leaves = BTreeMap::new();
    for (origin, block) in &grid.voxels.blocks {
        let values = leaf_values(block);
        if values.iter().all(|v| *v == 0.0) {
            continue;
        }
        let upper = origin.div_euclid(IVec3::splat(UPPER_EDGE)) * UPPER_EDGE;
        nodes
            .entry(upper.to_array())
            .or_default()
            .entry(child_index(*origin, UPPER_EDGE, LOWER_EDGE))
            .or_default()
            .insert(child_index(*origin, LOWER_EDGE, 8), *origin);
        leaves.insert(origin.to_array(), values);
    }
    let mut out = Bytes::default();
    out.u32(COMPRESS_ZIP | COMPRESS_ACTIVE_MASK);
    out.u32(2); // grid metadata: its class and name
    for (name, value) in [("class", "fog volume"), ("name", grid.name.as_str())] {
        out.string(name);
        out.string("string");
        out.string(value);
    }
    out.string("ScaleTranslateMap");
    let t = grid.transform;
    for v in [
        t.translation,
        t.voxel_size,
        t.voxel_size,
        1.0 / t.voxel_size,
    ] {
        out.dvec3(v);
    }
    out.dvec3(1.0 / (t.voxel_size * t.voxel_size));
    out.dvec3(0.5 / t.voxel_size);
    out.i32(1); // buffers
    out.f32(0.0); // background
    out.u32(0); // root tiles
    out.u32(nodes.len() as u32);
    for (origin, lowers) in &nodes {
        origin.iter().for_each(|c| out.i32(*c));
        out.mask(lowers.keys().copied(), 1 << 15);
        out.empty_node_values(1 << 15);
        for leaves_of_lower in lowers.values() {
            out.mask(leaves_of_lower.keys().copied(), 1 << 12);
            out.empty_node_values(1 << 12);
            for leaf in leaves_of_lower.values() {
                out.mask(active(&leaves[&leaf.to_array()]), BLOCK_VALUES);
            }
        }
    }
    let buffers_at = out.0.len();
    for leaf in nodes
        .values()
        .flat_map(|l| l.values())
        .flat_map(|l| l.values())
    {
        let values = &leaves[&leaf.to_array()];
        out.mask(active(values), BLOCK_VALUES);
        out.0.push(0); // inactive values are the background
        let stored: Vec<u8> = values
            .iter()
            .filter(|v| **v != 0.0)
            .flat_map(|v| v.to_le_bytes())
            .collect();
        out.zipped(&stored);
    }
    TreeBytes {
        all: out.0,
        buffers_at,
    }
}

/// A block's 512 values.
fn leaf_values(block: &Block) -> [f32; BLOCK_VALUES] {
    match block {
        Block::Voxels(values) => **values,
        Block::Uniform(value) => [*value; BLOCK_VALUES],
    }
}

/// The indices of a leaf's active (non-zero) values.
fn active(values: &[f32; BLOCK_VALUES]) -> impl Iterator<Item = usize> + '_ {
    values
        .iter()
        .enumerate()
        .filter(|(_, v)| **v != 0.0)
        .map(|(i, _)| i)
}

/// A UUID-shaped name for a file, from the hash of its tree.
fn uuid(tree: &[u8]) -> String {
    let h = format!(
        "{:016x}{:016x}",
        fnv1a(tree),
        fnv1a(&fnv1a(tree).to_le_bytes())
    );
    format!(
        "{}-{}-{}-{}-{}",
        &h[0..8],
        &h[8..12],
        &h[12..16],
        &h[16..20],
        &h[20..32]
    )
}

/// Bytes being written, little endian.
#[derive(Default)]
struct Bytes(Vec<u8>);

impl Bytes {
    fn u32(&mut self, v: u32) {
        self.0.extend(v.to_le_bytes());
    }
    fn i32(&mut self, v: i32) {
        self.0.extend(v.to_le_bytes());
    }
    fn i64(&mut self, v: i64) {
        self.0.extend(v.to_le_bytes());
    }
    fn f32(&mut self, v: f32) {
        self.0.extend(v.to_le_bytes());
    }
    fn dvec3(&mut self, v: glam::DVec3) {
        v.to_array()
            .iter()
            .for_each(|c| self.0.extend(c.to_le_bytes()));
    }
    fn string(&mut self, s: &str) {
        self.u32(s.len() as u32);
        self.0.extend(s.as_bytes());
    }

    /// A node mask of `bits` bits with the bits `on` set.
    fn mask(&mut self, on: impl Iterator<Item = usize>, bits: usize) {
        let mut words = vec![0u64; bits / 64];
        on.for_each(|i| words[i / 64] |= 1 << (i % 64));
        words.iter().for_each(|w| self.0.extend(w.to_le_bytes()));
    }

    /// An internal node's values when it has no tiles: all inactive and the background, so none
    /// is stored.
    fn empty_node_values(&mut self, bits: usize) {
        self.mask(std::iter::empty(), bits);
        self.0.push(0);
        self.zipped(&[]);
    }

    /// A zlib chunk behind its `i64` size (`io::zipToStream`).
    fn zipped(&mut self, raw: &[u8]) {
        if raw.is_empty() {
            self.i64(0);
            return;
        }
        let mut encoder =
            flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::default());
        encoder.write_all(raw).expect("writing to memory");
        let zipped = encoder.finish().expect("writing to memory");
        self.i64(zipped.len() as i64);
        self.0.extend(zipped);
    }
}
