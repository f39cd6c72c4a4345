//! The seed's light occlusion (Yusov 2014, "Light occlusion"): the particles are binned from the
//! sun into a light-space grid of tiles, each tile's list is sorted in light order (nearest the
//! sun first), and each particle walks the lists around it up to its own place, summing the
//! optical depth of the particles its ray toward the sun crosses, until the light left is below
//! 1 % (the seed's early exit). This is the CPU specification; `particle_occlusion.wgsl` is its
//! twin, run by [`super::occlusion_gpu`].
//!
//! **The light grid.** One level of tiles per ring of the particle grid, centred on the camera,
//! each level's tiles [`LIGHT_TILE_CELLS`] of its ring's cells wide, so every level lists about as
//! many particles per tile. A particle is listed once, in the tile of its centre on its ring's
//! level (point binning): an occluder reaches at most its radius, 2.2 cells of its ring
//! ([`super::generate::RADIUS_PER_CELL`]), so the particles that can cross a ray toward the sun
//! lie in the 3x3 tiles around the ray on the ray's own level, and (where rings overlap) on the
//! levels next to it, which are half and twice as coarse.
//!
//! **The walk.** The ray from a particle's centre toward the sun is a point in light space. Each
//! list around it is walked from its start (nearest the sun) to the particle's own place (its
//! distance from the sun), adding each occluder's optical depth along the ray's part beyond the
//! particle's own edge (its own body the tables shadow, as the march starts at its edge): the
//! occluder's mass along the chord through the noise-free reference particle
//! ([`ChordProfile::mass`]; the noise averages out over the many occluders of a ray), times its
//! extinction.

use glam::{IVec2, Vec3};

use super::generate::{Generation, OCCLUSION_MAX_DEPTH, Particle};
use super::optical_depth::{ChordProfile, unit_sphere_chord};

/// Particles of a tile that are sorted and walked, at most (the screen tiles' sort serves both): a
/// tile that lists more keeps the nearest the sun, which hide the rest.
pub const LIGHT_TILE_SORTED: u32 = super::render::TILE_SORTED;

/// Side of a light tile, in cells of its level's ring: more than the largest particle radius
/// ([`super::generate::RADIUS_PER_CELL`] cells), so the 3x3 tiles around a ray hold every
/// particle that can cross it.
pub const LIGHT_TILE_CELLS: f32 = 3.0;
/// Bytes of all light-tile lists at most (a storage binding may hold 128 MiB): a tile lists up to
/// this over the tile count, between [`MIN_LIGHT_TILE_CAPACITY`] and [`LIGHT_TILE_SORTED`]
/// entries; a fuller tile leaves the rest out (counted, `LightTileCounts::dropped`).
pub const LIGHT_LIST_BYTES: u64 = 96 << 20;
/// Entries a light tile holds at least: about twice the particles that a tile lists over a deck
/// under a sun 10 degrees high.
pub const MIN_LIGHT_TILE_CAPACITY: u32 = 512;
/// Bits of a sort key that hold the particle's index (as the screen tiles').
const INDEX_BITS: u32 = 20;
/// Levels of the quantised distance from the sun in a key's other 12 bits.
const DEPTH_LEVELS: f32 = 4095.0;

/// Most tiles along a level's side (even) for which `levels` levels of lists of
/// [`MIN_LIGHT_TILE_CAPACITY`] entries fit in [`LIGHT_LIST_BYTES`].
fn max_tiles_per_side(levels: u32) -> u32 {
    let tiles = LIGHT_LIST_BYTES / (4 * u64::from(MIN_LIGHT_TILE_CAPACITY) * u64::from(levels));
    ((tiles as f64).sqrt() as u32) & !1
}

/// The light-space tile grid of a frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightTiles {
    /// Centre of every level (the camera), m.
    pub origin_m: Vec3,
    /// Light-space x axis (unit, across the sun's rays).
    pub right: Vec3,
    /// Light-space y axis (unit, across the sun's rays and `right`).
    pub up: Vec3,
    /// Unit vector toward the sun.
    pub sun: Vec3,
    /// Tile side of the first level, m; each level's is twice the last's.
    pub tile_m: f32,
    /// Tiles along each side of a level.
    pub tiles_per_side: u32,
    /// Levels (the particle grid's rings).
    pub levels: u32,
    /// Largest distance of a listed particle from the light plane through the camera on the
    /// first level, m (twice that on the next, and so on): the range the keys quantise.
    pub depth_range_m: f32,
}

impl LightTiles {
    /// The grid for generation `g` (its grid, camera, sun and band).
    pub fn new(g: &Generation) -> LightTiles {
        let (bottom, top) = g.band_m;
        let vertical_reach_m = (top - g.camera_m.y)
            .abs()
            .max((bottom - g.camera_m.y).abs());
        let sun = g.sun_direction.normalize();
        let right = sun.any_orthonormal_vector();
        // A ring's square, seen along any sun, lies within its half-diagonal of the camera's
        // ray; the band's height adds to that; one more tile each side for the jitter.
        let half_diagonal_m =
            0.5 * std::f32::consts::SQRT_2 * g.grid.ring_cells as f32 * g.grid.inner_cell_m;
        let half_m = half_diagonal_m + vertical_reach_m;
        // Wider tiles where that many would not fit the lists' memory (a band much taller than
        // the cells are wide).
        let max_half_tiles = (max_tiles_per_side(g.grid.rings) / 2 - 1) as f32;
        let tile_m = (LIGHT_TILE_CELLS * g.grid.inner_cell_m).max(half_m / max_half_tiles);
        LightTiles {
            origin_m: g.camera_m,
            right,
            up: sun.cross(right),
            sun,
            tile_m,
            tiles_per_side: 2 * ((half_m / tile_m).ceil() as u32 + 1),
            levels: g.grid.rings,
            depth_range_m: half_m,
        }
    }

    /// Tiles over all levels.
    pub fn tile_count(&self) -> u32 {
        self.levels * self.tiles_per_side * self.tiles_per_side
    }

    /// Entries one tile's list holds ([`LIGHT_LIST_BYTES`] over the tiles, within
    /// [`MIN_LIGHT_TILE_CAPACITY`]..=[`LIGHT_TILE_SORTED`]).
    pub fn tile_capacity(&self) -> u32 {
        let fit = LIGHT_LIST_BYTES / (4 * u64::from(self.tile_count()));
        fit.clamp(
            u64::from(MIN_LIGHT_TILE_CAPACITY),
            u64::from(LIGHT_TILE_SORTED),
        ) as u32
    }

    /// Scale of `level` relative to the first.
    fn scale(level: u32) -> f32 {
        (1u32 << level) as f32
    }

    /// The tile (column, row) of `p` on `level`, unclamped.
    pub fn tile_of(&self, p: Vec3, level: u32) -> IVec2 {
        let d = p - self.origin_m;
        let at =
            glam::Vec2::new(d.dot(self.right), d.dot(self.up)) / (self.tile_m * Self::scale(level));
        (at + 0.5 * self.tiles_per_side as f32).floor().as_ivec2()
    }

    /// The index of tile `tile` of `level`, or None outside the level.
    pub fn tile_index(&self, tile: IVec2, level: u32) -> Option<u32> {
        let n = self.tiles_per_side as i32;
        let inside = level < self.levels
            && tile.cmpge(IVec2::ZERO).all()
            && tile.cmplt(IVec2::splat(n)).all();
        inside.then(|| {
            (level * self.tiles_per_side + tile.y as u32) * self.tiles_per_side + tile.x as u32
        })
    }

    /// The distance of `p` from the light plane through the camera, m (larger farther from the
    /// sun).
    pub fn from_sun(&self, p: Vec3) -> f32 {
        -(p - self.origin_m).dot(self.sun)
    }

    /// [`LightTiles::from_sun`] quantised over `level`'s range into 12 bits.
    pub fn depth_level(&self, p: Vec3, level: u32) -> u32 {
        let range = self.depth_range_m * Self::scale(level);
        (((self.from_sun(p) / range + 1.0) * 0.5).clamp(0.0, 1.0) * DEPTH_LEVELS) as u32
    }

    /// The sort key of particle `index` at `p` on `level`: its depth level (nearest the sun
    /// first), then its index.
    pub fn key(&self, p: Vec3, index: u32, level: u32) -> u32 {
        (self.depth_level(p, level) << INDEX_BITS) | index
    }
}

/// The optical depth of `occluder` along the ray from `from` toward the sun (`sun`, unit), past
/// `start_m` (the walking particle's own edge): its extinction times the noise-free reference
/// particle's mass along the chord's part past the start (`particle_segment` in
/// `particle_render.wgsl` shades a chord the same way).
pub fn occluder_optical_depth(
    occluder: &Particle,
    (from, start_m): (Vec3, f32),
    sun: Vec3,
    sigma_max_per_m: f32,
    chord: &ChordProfile,
) -> f32 {
    let radii = Vec3::new(occluder.radius_m, occluder.height_m, occluder.radius_m);
    let lo = (from - occluder.centre_m) / radii;
    let ld = sun / radii;
    let scale = ld.length();
    let dir = ld / scale;
    let Some((t0, t1)) = unit_sphere_chord(lo, dir) else {
        return 0.0;
    };
    let start = start_m * scale;
    if t1 <= start {
        return 0.0;
    }
    let entry = (lo + t0 * dir).normalize();
    let kept = (t1 - t0.max(start)) / (t1 - t0);
    sigma_max_per_m * occluder.density * chord.mass(entry, dir) / scale * kept
}

/// How far particle `p` reaches from its centre toward the sun (`sun`, unit), m: where its ray
/// toward the sun leaves it (the tables already shadow its own body, as the march starts at its
/// edge).
pub fn own_extent_toward(p: &Particle, sun: Vec3) -> f32 {
    1.0 / (sun / Vec3::new(p.radius_m, p.height_m, p.radius_m)).length()
}

/// What the walk needs besides the particles.
#[derive(Clone, Copy, Debug)]
pub struct Walk<'a> {
    /// The light grid.
    pub tiles: &'a LightTiles,
    /// Extinction of density 1, m^-1.
    pub sigma_max_per_m: f32,
    /// The reference particle's chord masses.
    pub chord: &'a ChordProfile,
    /// Whether a walk stops once the optical depth passes [`OCCLUSION_MAX_DEPTH`].
    pub early_exit: bool,
}

/// Each tile's sorted list of keys (every tile of every level), as the GPU's sort leaves them:
/// the nearest [`LIGHT_TILE_SORTED`] of the particles whose centre lies in the tile.
pub fn light_tile_lists(particles: &[Particle], tiles: &LightTiles) -> Vec<Vec<u32>> {
    let mut lists = vec![Vec::new(); tiles.tile_count() as usize];
    for (index, p) in particles.iter().enumerate() {
        let level = p.ring;
        if p.density <= 0.0 {
            continue;
        }
        if let Some(tile) = tiles.tile_index(tiles.tile_of(p.centre_m, level), level) {
            lists[tile as usize].push(tiles.key(p.centre_m, index as u32, level));
        }
    }
    for list in &mut lists {
        list.sort_unstable();
        list.truncate(LIGHT_TILE_SORTED as usize);
    }
    lists
}

/// The walking particle: its centre, where its ray leaves it (m from the centre), and its
/// distance from the sun's plane through the camera, m.
#[derive(Clone, Copy, Debug)]
struct Walker {
    centre_m: Vec3,
    start_m: f32,
    from_sun_m: f32,
}

/// The walk so far: optical depth and list entries walked.
pub type Progress = (f32, u32);

/// Walks one tile's sorted list up to the walker's place: every entry of a smaller depth level,
/// and of its own level those nearer the sun (by exact distance, so that the walk does not
/// depend on the order generation listed the particles in).
fn walk_list(
    particles: &[Particle],
    list: &[u32],
    (with, level, me): (&Walk, u32, &Walker),
    (mut tau, mut walked): Progress,
) -> Progress {
    let tiles = with.tiles;
    let own_level = tiles.depth_level(me.centre_m, level);
    for &key in list {
        let depth_level = key >> INDEX_BITS;
        if depth_level > own_level || (with.early_exit && tau > OCCLUSION_MAX_DEPTH) {
            break;
        }
        let occluder = &particles[(key & ((1 << INDEX_BITS) - 1)) as usize];
        if depth_level == own_level && tiles.from_sun(occluder.centre_m) >= me.from_sun_m {
            continue;
        }
        let ray = (me.centre_m, me.start_m);
        tau += occluder_optical_depth(occluder, ray, tiles.sun, with.sigma_max_per_m, with.chord);
        walked += 1;
    }
    (tau, walked)
}

/// The optical depth toward the sun of particle `index` (the walk of the lists of the 3x3 tiles
/// around its ray on its level and the levels next to it), and the list entries it walked.
pub fn walk_to_sun(
    particles: &[Particle],
    lists: &[Vec<u32>],
    with: &Walk,
    index: u32,
) -> Progress {
    let p = &particles[index as usize];
    let tiles = with.tiles;
    let me = Walker {
        centre_m: p.centre_m,
        start_m: own_extent_toward(p, tiles.sun),
        from_sun_m: tiles.from_sun(p.centre_m),
    };
    let mut progress = (0.0, 0);
    for level in p.ring.saturating_sub(1)..=(p.ring + 1).min(tiles.levels - 1) {
        let centre = tiles.tile_of(p.centre_m, level);
        for k in 0..9 {
            let tile = tiles.tile_index(centre + IVec2::new(k % 3 - 1, k / 3 - 1), level);
            if let Some(tile) = tile {
                progress = walk_list(
                    particles,
                    &lists[tile as usize],
                    (with, level, &me),
                    progress,
                );
            }
        }
    }
    progress
}

/// Sets every particle's `sun_optical_depth` by the walk, and returns the entries walked.
pub fn occlude(particles: &mut [Particle], with: &Walk) -> u64 {
    use rayon::prelude::*;
    let lists = light_tile_lists(particles, with.tiles);
    let walks: Vec<Progress> = (0..particles.len() as u32)
        .into_par_iter()
        .map(|i| walk_to_sun(particles, &lists, with, i))
        .collect();
    for (p, (tau, _)) in particles.iter_mut().zip(&walks) {
        p.sun_optical_depth = *tau;
    }
    walks.iter().map(|&(_, n)| u64::from(n)).sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::SceneDocument;

    /// Whatever the grid and the band, the light tiles' lists fit in their memory, at least
    /// [`MIN_LIGHT_TILE_CAPACITY`] entries a tile, and cover every ring's particles.
    #[test]
    fn the_light_tiles_fit_their_memory_for_any_grid() {
        for (rings, ring_cells, distance_m, thickness_m) in [
            (5, 136, 200_000.0, 2200.0),
            (8, 512, 1000.0, 10_000.0),
            (1, 16, 1000.0, 10_000.0),
            (8, 512, 1.0e6, 300.0),
        ] {
            let overrides = [
                format!("particles.rings={rings}"),
                format!("particles.ring_cells={ring_cells}"),
                format!("particles.distance_m={distance_m}"),
                format!("layers.0.thickness_m={thickness_m}"),
            ];
            let scene = SceneDocument::load(None, &overrides).expect("valid").scene;
            let tiles = LightTiles::new(&Generation::from_scene(&scene, 0.2));
            let bytes = 4 * u64::from(tiles.tile_count()) * u64::from(tiles.tile_capacity());
            assert!(bytes <= LIGHT_LIST_BYTES, "{tiles:?}: {bytes} bytes");
            assert!(tiles.tile_capacity() >= MIN_LIGHT_TILE_CAPACITY);
            let ring_half_m = 0.5 * ring_cells as f32 * scene_cell_m(&scene);
            let level_half_m = 0.5 * tiles.tiles_per_side as f32 * tiles.tile_m;
            assert!(
                level_half_m >= std::f32::consts::SQRT_2 * ring_half_m,
                "{tiles:?}"
            );
        }
    }

    fn scene_cell_m(scene: &crate::scene::Scene) -> f32 {
        crate::particles::grid::RingGrid::from_scene(scene).inner_cell_m
    }
}
