//! A coarse grid of conservative extinction bounds (majorants) and the walk of a ray through it:
//! the piecewise-constant majorant that delta and ratio tracking need (Novák et al. 2018, "Monte
//! Carlo Methods for Physically Based Volume Rendering", section 4: a tighter majorant means fewer
//! null collisions, and empty cells are skipped outright).

use crate::geometry::{Aabb, band_intervals};
use crate::medium::{Medium, Shell};
use glam::{IVec3, UVec3, Vec3};
use rayon::prelude::*;
use std::ops::ControlFlow;

/// A stretch of a ray with one majorant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Segment {
    /// Ray parameter where the stretch begins, metres.
    pub start: f32,
    /// Where it ends, metres.
    pub end: f32,
    /// Upper bound of the extinction along the stretch, m^-1.
    pub majorant_per_m: f32,
}

/// Each cell's bound is taken over the cell grown by this fraction of its size on every side, so
/// that points rounded across a cell face are still bounded.
const CELL_PAD_FRACTION: f32 = 1e-3;
/// And by this many metres (`f32` spacing is 0.016 m at 200 km from the origin).
const CELL_PAD_M: f32 = 0.1;
/// Cells are at most this much flatter than wide: layers are thin and vary fast with altitude.
const MIN_CELL_ASPECT: f32 = 0.25;

/// Majorants over a box, plus the medium's shell outside it. Where the medium asks for it
/// ([`Medium::nesting`]), the box holds nested boxes about a focus, each grid twice as wide as the
/// one inside it with as many cells, so that cells are small near the camera (where the particle
/// technique's particles are small) and coarse far away.
#[derive(Clone, Debug)]
pub struct MajorantGrid {
    /// Innermost first; each level's box holds the boxes of the levels before it.
    levels: Vec<Level>,
    shell: Option<Shell>,
}

/// One grid of majorants over a box.
#[derive(Clone, Debug)]
struct Level {
    bounds: Aabb,
    dims: UVec3,
    cell_size: Vec3,
    values: Vec<f32>,
}

impl MajorantGrid {
    /// Bounds `medium` over about `max_cells` cells covering its support box; cells are as wide as
    /// deep and between 1 and 4 times wider than tall, following the box's proportions. With
    /// [`Medium::nesting`], the cells are shared among the nested levels.
    pub fn build(medium: &impl Medium, max_cells: usize) -> MajorantGrid {
        let support = medium.support();
        let boxes = level_boxes(medium, &support.grid_box);
        let cells = (max_cells / boxes.len()).max(1);
        let mut levels: Vec<Level> = Vec::with_capacity(boxes.len());
        for (k, bounds) in boxes.iter().enumerate() {
            // Cells wholly inside the next level in, by a cell's margin, are never read.
            let inner = k.checked_sub(1).map(|i| levels[i].bounds);
            levels.push(Level::build(medium, *bounds, cells, inner));
        }
        MajorantGrid {
            levels,
            shell: support.shell,
        }
    }

    fn outer(&self) -> &Level {
        self.levels.last().expect("at least one level")
    }

    /// Cells along x, y, z of the outermost level.
    pub fn dims(&self) -> UVec3 {
        self.outer().dims
    }

    /// The box the grid covers.
    pub fn bounds(&self) -> Aabb {
        self.outer().bounds
    }

    /// Nested levels (1 without [`Medium::nesting`]).
    pub fn level_count(&self) -> usize {
        self.levels.len()
    }

    /// The majorant that applies at `p`: its cell's inside the box (in the innermost level holding
    /// it), the shell's in the band outside.
    pub fn majorant_at(&self, p: Vec3) -> f32 {
        if let Some(level) = self.levels.iter().find(|l| l.contains(p)) {
            return level.values[level.index(level.cell_of(p))];
        }
        self.shell.map_or(0.0, |s| {
            let h = s.planet.altitude_m(p);
            if (s.bottom_m..=s.top_m).contains(&h) {
                s.majorant_per_m
            } else {
                0.0
            }
        })
    }

    /// Mean majorant over the cells of every level (a measure of how tight the grid is), m^-1.
    pub fn mean_majorant_per_m(&self) -> f32 {
        let (sum, count) = self.levels.iter().fold((0.0, 0), |(s, n), l| {
            (s + l.values.iter().sum::<f32>(), n + l.values.len())
        });
        sum / count as f32
    }

    /// Visits the stretches of the ray `origin + t dir`, `t` in `[0, t_max]`, that may hold
    /// medium, in order of `t`, each with its majorant; stops early when `visit` breaks.
    pub fn walk<R>(
        &self,
        origin: Vec3,
        dir: Vec3,
        t_max: f32,
        mut visit: impl FnMut(Segment) -> ControlFlow<R>,
    ) -> ControlFlow<R> {
        match self
            .bounds()
            .ray_interval(origin, dir)
            .and_then(|i| i.clip(0.0, t_max))
        {
            None => self.walk_shell(origin, dir, (0.0, t_max), &mut visit),
            Some(inside) => {
                self.walk_shell(origin, dir, (0.0, inside.start), &mut visit)?;
                let outer = self.levels.len() - 1;
                self.walk_level(outer, origin, dir, (inside.start, inside.end), &mut visit)?;
                self.walk_shell(origin, dir, (inside.end, t_max), &mut visit)
            }
        }
    }

    /// Walks the stretch `(start, end)` of the ray, inside level `k`'s box: through its cells
    /// where the ray is outside the next level in, through that level where it is inside.
    fn walk_level<R>(
        &self,
        k: usize,
        origin: Vec3,
        dir: Vec3,
        (start, end): (f32, f32),
        visit: &mut impl FnMut(Segment) -> ControlFlow<R>,
    ) -> ControlFlow<R> {
        let level = &self.levels[k];
        let inner = k.checked_sub(1).and_then(|i| {
            self.levels[i]
                .bounds
                .ray_interval(origin, dir)
                .and_then(|r| r.clip(start, end))
        });
        match inner {
            None => level.walk_cells(origin, dir, (start, end), visit),
            Some(inner) => {
                level.walk_cells(origin, dir, (start, inner.start), visit)?;
                self.walk_level(k - 1, origin, dir, (inner.start, inner.end), visit)?;
                level.walk_cells(origin, dir, (inner.end, end), visit)
            }
        }
    }

    fn walk_shell<R>(
        &self,
        origin: Vec3,
        dir: Vec3,
        (start, end): (f32, f32),
        visit: &mut impl FnMut(Segment) -> ControlFlow<R>,
    ) -> ControlFlow<R> {
        let Some(shell) = self.shell.filter(|_| end > start) else {
            return ControlFlow::Continue(());
        };
        let band = (shell.bottom_m, shell.top_m);
        for interval in band_intervals(&shell.planet, origin, dir, band, (start, end))
            .into_iter()
            .flatten()
        {
            visit(Segment {
                start: interval.start,
                end: interval.end,
                majorant_per_m: shell.majorant_per_m,
            })?;
        }
        ControlFlow::Continue(())
    }
}

/// The boxes of the levels, innermost first, the last `grid_box`: about the medium's focus, boxes
/// of horizontal half-width `inner_reach_m * 2^k` until one holds `grid_box`, each clipped to
/// `grid_box`, shrunk to the medium inside it ([`Medium::bounds_within`]) and to the next one out.
/// Levels with no medium are left out (the next one out covers them).
fn level_boxes(medium: &impl Medium, grid_box: &Aabb) -> Vec<Aabb> {
    let Some(nesting) = medium.nesting() else {
        return vec![*grid_box];
    };
    let mut reaches = Vec::new();
    let mut reach = nesting.inner_reach_m.max(1.0);
    let far = (grid_box.min - nesting.focus_m)
        .abs()
        .max((grid_box.max - nesting.focus_m).abs());
    while reach < far.x.max(far.z) && reaches.len() < MAX_LEVELS - 1 {
        reaches.push(reach);
        reach *= 2.0;
    }
    let mut boxes = vec![*grid_box];
    for &reach in reaches.iter().rev() {
        let outer = *boxes.last().expect("the outermost box");
        let half = Vec3::new(reach, 0.0, reach);
        let square = Aabb {
            min: (nesting.focus_m - half).max(outer.min),
            max: (nesting.focus_m + half).min(outer.max),
        };
        let square = Aabb {
            min: Vec3::new(square.min.x, outer.min.y, square.min.z),
            max: Vec3::new(square.max.x, outer.max.y, square.max.z),
        };
        if square.min.cmpge(square.max).any() {
            break;
        }
        let Some(tight) = medium.bounds_within(&square) else {
            break;
        };
        let tight = Aabb {
            min: tight.min.max(square.min),
            max: tight.max.min(square.max),
        };
        if tight.min.cmpge(tight.max).any() {
            break;
        }
        boxes.push(tight);
    }
    boxes.reverse();
    boxes
}

/// Nested levels at most.
const MAX_LEVELS: usize = 12;

impl Level {
    /// Bounds `medium` over about `max_cells` cells covering `bounds`; cells well inside `inner`
    /// (which the grid reads instead) are set to 0 without a bound.
    fn build(medium: &impl Medium, bounds: Aabb, max_cells: usize, inner: Option<Aabb>) -> Level {
        let dims = grid_dims(bounds.max - bounds.min, max_cells.max(1));
        let cell_size = (bounds.max - bounds.min) / dims.as_vec3();
        let pad = cell_size * CELL_PAD_FRACTION + CELL_PAD_M;
        let skipped = inner.map(|b| Aabb {
            min: b.min + cell_size,
            max: b.max - cell_size,
        });
        let (nx, ny) = (dims.x as usize, dims.y as usize);
        let values = (0..dims.element_product() as usize)
            .into_par_iter()
            .map(|i| {
                let cell = UVec3::new(
                    (i % nx) as u32,
                    (i / nx % ny) as u32,
                    (i / (nx * ny)) as u32,
                );
                let min = bounds.min + cell.as_vec3() * cell_size;
                let b = Aabb {
                    min: min - pad,
                    max: min + cell_size + pad,
                };
                if skipped.is_some_and(|s| b.min.cmpge(s.min).all() && b.max.cmple(s.max).all()) {
                    return 0.0;
                }
                medium.max_extinction_in_box(&b)
            })
            .collect();
        Level {
            bounds,
            dims,
            cell_size,
            values,
        }
    }

    fn contains(&self, p: Vec3) -> bool {
        p.cmpge(self.bounds.min).all() && p.cmple(self.bounds.max).all()
    }

    fn cell_of(&self, p: Vec3) -> IVec3 {
        ((p - self.bounds.min) / self.cell_size)
            .floor()
            .as_ivec3()
            .clamp(IVec3::ZERO, self.dims.as_ivec3() - 1)
    }

    fn index(&self, cell: IVec3) -> usize {
        let d = self.dims.as_ivec3();
        (cell.x + d.x * (cell.y + d.y * cell.z)) as usize
    }

    /// 3D digital differential analyser through the cells (Amanatides & Woo 1987, "A Fast Voxel
    /// Traversal Algorithm for Ray Tracing"); zero cells are skipped without a visit.
    fn walk_cells<R>(
        &self,
        origin: Vec3,
        dir: Vec3,
        (start, end): (f32, f32),
        visit: &mut impl FnMut(Segment) -> ControlFlow<R>,
    ) -> ControlFlow<R> {
        if end <= start {
            return ControlFlow::Continue(());
        }
        let mut cell = self.cell_of(origin + dir * start);
        let step = IVec3::new(
            dir.x.signum() as i32,
            dir.y.signum() as i32,
            dir.z.signum() as i32,
        );
        let next_face = |cell: IVec3| {
            let face = cell + step.max(IVec3::ZERO);
            (self.bounds.min + face.as_vec3() * self.cell_size - origin) / dir
        };
        let mut t_next = Vec3::select(dir.cmpeq(Vec3::ZERO), Vec3::INFINITY, next_face(cell));
        let t_delta = (self.cell_size / dir.abs()).min(Vec3::INFINITY);
        let mut t = start;
        loop {
            let t_exit = t_next.min_element().min(end);
            let majorant_per_m = self.values[self.index(cell)];
            if t_exit > t && majorant_per_m > 0.0 {
                visit(Segment {
                    start: t,
                    end: t_exit,
                    majorant_per_m,
                })?;
            }
            if t_exit >= end {
                return ControlFlow::Continue(());
            }
            let axis = t_next.min_position();
            cell[axis] += step[axis];
            if cell[axis] < 0 || cell[axis] >= self.dims[axis] as i32 {
                return ControlFlow::Continue(());
            }
            t = t_exit.max(t);
            t_next[axis] += t_delta[axis];
        }
    }
}

/// Cells per axis for a box of `extent`: square in x-z, `aspect` times as tall, `aspect` the box's
/// height over its width clamped to [`MIN_CELL_ASPECT`], 1, about `max_cells` in all.
fn grid_dims(extent: Vec3, max_cells: usize) -> UVec3 {
    let width = extent.x.max(extent.z);
    let aspect = (extent.y / width).clamp(MIN_CELL_ASPECT, 1.0);
    let volume = extent.x * extent.y * extent.z;
    let side = (volume / (aspect * max_cells as f32)).cbrt();
    let size = Vec3::new(side, side * aspect, side);
    (extent / size).ceil().max(Vec3::ONE).as_uvec3()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::medium::HomogeneousBox;

    fn boxed(min: Vec3, max: Vec3, sigma: f32) -> HomogeneousBox {
        HomogeneousBox {
            bounds: Aabb { min, max },
            extinction_per_m: sigma,
        }
    }

    /// A medium made of two boxes inside a larger support: cells outside both must be zero.
    struct TwoBoxes([HomogeneousBox; 2]);

    impl Medium for TwoBoxes {
        fn extinction_per_m(&self, p: Vec3) -> f32 {
            self.0.iter().map(|b| b.extinction_per_m(p)).sum()
        }
        fn max_extinction_in_box(&self, b: &Aabb) -> f32 {
            self.0.iter().map(|m| m.max_extinction_in_box(b)).sum()
        }
        fn support(&self) -> crate::medium::Support {
            crate::medium::Support {
                grid_box: Aabb {
                    min: Vec3::ZERO,
                    max: Vec3::splat(100.0),
                },
                shell: None,
            }
        }
    }

    fn two_boxes() -> TwoBoxes {
        TwoBoxes([
            boxed(Vec3::splat(1.0), Vec3::splat(9.0), 0.5),
            boxed(Vec3::splat(91.0), Vec3::splat(99.0), 2.0),
        ])
    }

    #[test]
    fn walk_covers_the_ray_in_order_and_skips_empty_cells() {
        let grid = MajorantGrid::build(&two_boxes(), 1000);
        assert_eq!(grid.dims(), UVec3::splat(10));
        let dir = Vec3::ONE.normalize();
        let mut segments = Vec::new();
        let flow: ControlFlow<()> = grid.walk(Vec3::splat(-5.0), dir, 1e3, |s| {
            segments.push(s);
            ControlFlow::Continue(())
        });
        assert!(flow.is_continue());
        assert!(segments.windows(2).all(|w| w[0].end <= w[1].start));
        // Along the diagonal: through the first box's cell and the last box's cell only, each a
        // 10 m cube.
        let length = |sigma: f32| -> f32 {
            segments
                .iter()
                .filter(|s| s.majorant_per_m == sigma)
                .map(|s| s.end - s.start)
                .sum()
        };
        let diagonal = 10.0 * 3f32.sqrt();
        assert!((length(0.5) - diagonal).abs() < 1e-3, "{segments:?}");
        assert!((length(2.0) - diagonal).abs() < 1e-3, "{segments:?}");
        assert_eq!(segments.len(), 2, "{segments:?}");
    }

    #[test]
    fn walk_stops_when_told() {
        let grid = MajorantGrid::build(&two_boxes(), 1000);
        let flow = grid.walk(Vec3::splat(-5.0), Vec3::ONE.normalize(), 1e3, |s| {
            ControlFlow::Break(s.start)
        });
        assert!(matches!(flow, ControlFlow::Break(t) if (t - 5.0 * 3f32.sqrt()).abs() < 1e-3));
    }

    #[test]
    fn axis_parallel_rays_and_rays_from_inside_work() {
        let grid = MajorantGrid::build(&two_boxes(), 1000);
        let mut total = 0.0;
        let _: ControlFlow<()> = grid.walk(Vec3::new(5.0, 5.0, 5.0), Vec3::X, 1e3, |s| {
            total += (s.end - s.start) * s.majorant_per_m;
            ControlFlow::Continue(())
        });
        assert!((total - 2.5).abs() < 1e-4, "{total}");
        assert_eq!(grid.majorant_at(Vec3::splat(95.0)), 2.0);
        assert_eq!(grid.majorant_at(Vec3::splat(50.0)), 0.0);
        assert_eq!(grid.majorant_at(Vec3::splat(-50.0)), 0.0);
    }
}
