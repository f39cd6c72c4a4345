//! The camera-centred cell grid particles are generated in (Yusov 2014, "Cell grid"): concentric
//! square rings of `ring_cells` x `ring_cells` columns, each ring's cells twice the size of the inner
//! ring's, every ring past the first skipping the centre the inner ring covers, and several
//! particles stacked in each column across the layer band.
//!
//! Each ring's cells are fixed in the world (a lattice of its cell size) and the ring follows the
//! camera by whole cells, so a particle never moves as the camera does: cells only enter and leave
//! at the ring's edge. They enter and leave with zero weight: a particle's weight (its density
//! scale) cross-fades from a ring to the next over a band that both rings cover whatever the
//! camera's position within a cell ([`RingGrid::weight`]), so the grid does not pop.
//! `particle_generate.wgsl` is the twin of every function here.

use crate::scene::Scene;

/// Most particle layers a cell stacks.
pub const MAX_LAYERS: u32 = 16;
use glam::{IVec2, Vec2};

/// Largest offset of a particle from its cell's centre, as a fraction of the cell, along each axis
/// (the jitter that breaks up the lattice).
pub const CELL_JITTER: f32 = 0.25;

/// The ring cell grid of a scene.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RingGrid {
    /// Number of rings.
    pub rings: u32,
    /// Columns along each side of a ring (even).
    pub ring_cells: u32,
    /// Particles stacked in each column.
    pub cell_layers: u32,
    /// Cell size of the inner ring, m.
    pub inner_cell_m: f32,
}

/// One column of the grid around a camera.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Column {
    /// Its ring.
    pub ring: u32,
    /// Its cell in the ring's world-fixed lattice.
    pub lattice: IVec2,
    /// Centre of the cell, metres (x east, z south).
    pub centre_m: Vec2,
    /// Cell size, m.
    pub cell_m: f32,
}

impl RingGrid {
    /// The grid a scene's `[particles]` asks for: its cell size makes the outer ring's fade end
    /// at `distance_m`; `cell_layers = 0` stacks as many layers as make the inner ring's cells
    /// about as tall as they are wide across the scene's layer band (Yusov's 4 layers over his
    /// 700 m band of 184 m cells), 1..16.
    pub fn from_scene(scene: &Scene) -> RingGrid {
        let particles = &scene.particles;
        let mut grid = RingGrid {
            rings: particles.rings,
            ring_cells: particles.ring_cells,
            cell_layers: particles.cell_layers,
            inner_cell_m: 1.0,
        };
        grid.inner_cell_m = particles.distance_m / grid.outer_reach_cells();
        if grid.cell_layers == 0 {
            let bottom = scene.layers.iter().map(|l| l.bottom_m).reduce(f32::min);
            let top = scene
                .layers
                .iter()
                .map(|l| l.bottom_m + l.thickness_m)
                .reduce(f32::max);
            let band_m = top.zip(bottom).map_or(0.0, |(t, b)| t - b);
            grid.cell_layers = ((band_m / grid.inner_cell_m).round() as u32).clamp(1, MAX_LAYERS);
        }
        grid
    }

    /// Columns over all rings (the hole cells included: they are skipped, not removed).
    pub fn column_count(&self) -> u32 {
        self.rings * self.ring_cells * self.ring_cells
    }

    /// Most particles the grid can hold.
    pub fn max_particles(&self) -> u32 {
        self.column_count() * self.cell_layers
    }

    /// Cell size of `ring`, m.
    pub fn cell_m(&self, ring: u32) -> f32 {
        self.inner_cell_m * (1u32 << ring) as f32
    }

    /// Half the side of the centre a ring past the first skips, in its own cells: the inner ring's
    /// side less the 4 fading cells on each side, halved twice (inner cells are half the size).
    fn hole_half_cells(&self) -> f32 {
        (self.ring_cells as f32 / 2.0 - 4.0) / 2.0
    }

    /// The Chebyshev distance from the camera (in a ring's cells) where its particles start to
    /// fade into the next ring's, and where they are gone. Inside the start every particle the
    /// next ring skips lies (its hole, displaced by the ring's snapping and the jitter); before the
    /// end every particle of this ring exists, wherever the camera is within its cell.
    pub fn fade_band_cells(&self) -> (f32, f32) {
        let start = 2.0 * (self.hole_half_cells() + CELL_JITTER);
        let end = self.ring_cells as f32 / 2.0 - 1.0 - CELL_JITTER;
        (start, end)
    }

    /// How far the outer ring reaches, in inner cells: its fade ends there.
    fn outer_reach_cells(&self) -> f32 {
        self.fade_band_cells().1 * (1u32 << (self.rings - 1)) as f32
    }

    /// Column `index` (ring-major, then z, then x) around a camera at `camera_m` (x, z), or None
    /// where its ring skips its centre.
    pub fn column(&self, index: u32, camera_m: Vec2) -> Option<Column> {
        let n = self.ring_cells;
        let ring = index / (n * n);
        let (i, j) = (index % n, (index / n) % n);
        let half = (n / 2) as i32;
        let offset = IVec2::new(i as i32 - half, j as i32 - half);
        if ring > 0 {
            let hole = self.hole_half_cells() as i32;
            if (-hole..hole).contains(&offset.x) && (-hole..hole).contains(&offset.y) {
                return None;
            }
        }
        let cell_m = self.cell_m(ring);
        let snapped = (camera_m / cell_m + 0.5).floor().as_ivec2();
        let lattice = snapped + offset;
        Some(Column {
            ring,
            lattice,
            centre_m: (lattice.as_vec2() + 0.5) * cell_m,
            cell_m,
        })
    }

    /// Weight of a particle of `ring` at `position_m` (x, z) seen from `camera_m`: 1 inside the
    /// ring, cross-fading with the rings inside and outside it over [`Self::fade_band_cells`], and
    /// fading out over the outer ring's last fifth, where the flat far layer takes over.
    pub fn weight(&self, ring: u32, position_m: Vec2, camera_m: Vec2) -> f32 {
        let (start, end) = self.fade_band_cells();
        let d = (position_m - camera_m).abs().max_element() / self.cell_m(ring);
        let mut weight = 1.0;
        if ring > 0 {
            weight *= smoothstep(start / 2.0, end / 2.0, d);
        }
        if ring + 1 < self.rings {
            weight *= 1.0 - smoothstep(start, end, d);
        } else {
            weight *= 1.0 - smoothstep(0.8 * end, end, d);
        }
        weight
    }

    /// Where the particle grid's weight has faded to nothing, m from the camera (Chebyshev).
    pub fn reach_m(&self) -> f32 {
        self.outer_reach_cells() * self.inner_cell_m
    }
}

/// Hermite smoothstep of `x` between `edge0` and `edge1` (WGSL's `smoothstep`).
pub fn smoothstep(edge0: f32, edge1: f32, x: f32) -> f32 {
    let t = ((x - edge0) / (edge1 - edge0)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid() -> RingGrid {
        RingGrid::from_scene(&Scene::default())
    }

    #[test]
    fn the_default_grid_is_yusovs() {
        let g = grid();
        assert!((g.inner_cell_m - 184.0).abs() < 6.0, "{}", g.inner_cell_m);
        assert!((g.reach_m() - 200_000.0).abs() < 1.0);
        let holes = (0..g.column_count())
            .filter(|&i| g.column(i, Vec2::ZERO).is_none())
            .count();
        assert_eq!(holes, 4 * 64 * 64);
        assert_eq!(
            g.column_count() as usize - holes,
            76_096,
            "peers.md: 76,096 cells"
        );
        assert_eq!(
            g.cell_layers, 12,
            "cells as tall as wide across the 2200 m band"
        );
        let mut yusov = Scene::default();
        yusov.layers[0].thickness_m = 700.0;
        assert_eq!(
            RingGrid::from_scene(&yusov).cell_layers,
            4,
            "Yusov's 4 over 700 m"
        );
    }

    /// Sum of the weights of every ring's particles at a point: 1 wherever the grid reaches, for
    /// any camera position within its cells, so moving the camera never pops a particle.
    #[test]
    fn ring_weights_cross_fade_to_one_and_cells_exist_wherever_they_weigh() {
        let g = grid();
        for camera in [
            Vec2::ZERO,
            Vec2::new(91.0, -47.0),
            Vec2::new(-3000.3, 1234.5),
        ] {
            for k in 0..300 {
                let angle = k as f32 * 0.37;
                let distance = 150_000.0 * (k as f32 / 300.0);
                let p = camera + distance * Vec2::new(angle.cos(), angle.sin());
                let total: f32 = (0..g.rings).map(|r| g.weight(r, p, camera)).sum();
                assert!((total - 1.0).abs() < 1e-4, "{total} at {p} from {camera}");
                for ring in 0..g.rings {
                    let (cell, q) = particle_near(&g, ring, p);
                    if g.weight(ring, q, camera) > 0.0 {
                        assert!(
                            column_exists(&g, ring, cell, camera),
                            "ring {ring} lacks {q}"
                        );
                    }
                }
            }
        }
    }

    /// The lattice cell of `ring` holding `p`, and the particle position of that cell nearest `p`.
    fn particle_near(g: &RingGrid, ring: u32, p: Vec2) -> (IVec2, Vec2) {
        let cell_m = g.cell_m(ring);
        let cell = (p / cell_m).floor().as_ivec2();
        let centre = (cell.as_vec2() + 0.5) * cell_m;
        let reach = Vec2::splat(CELL_JITTER * cell_m);
        (cell, centre + (p - centre).clamp(-reach, reach))
    }

    /// Whether lattice cell `cell` of `ring` is a column of the grid around `camera`.
    fn column_exists(g: &RingGrid, ring: u32, cell: IVec2, camera: Vec2) -> bool {
        let n = g.ring_cells as i32;
        let snapped = (camera / g.cell_m(ring) + 0.5).floor().as_ivec2();
        let offset = cell - snapped + n / 2;
        let inside = offset.cmpge(IVec2::ZERO).all() && offset.cmplt(IVec2::splat(n)).all();
        let index = ring as i32 * n * n + offset.y * n + offset.x;
        inside && g.column(index as u32, camera).is_some()
    }
}
