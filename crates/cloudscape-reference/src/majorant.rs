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

/// Majorants over a box, plus the medium's shell outside it.
#[derive(Clone, Debug)]
pub struct MajorantGrid {
    bounds: Aabb,
    dims: UVec3,
    cell_size: Vec3,
    values: Vec<f32>,
    shell: Option<Shell>,
}

impl MajorantGrid {
    /// Bounds `medium` over about `max_cells` cells covering its support box; cells are as wide as
    /// deep and between 1 and 4 times wider than tall, following the box's proportions.
    pub fn build(medium: &impl Medium, max_cells: usize) -> MajorantGrid {
        let support = medium.support();
        let bounds = support.grid_box;
        let dims = grid_dims(bounds.max - bounds.min, max_cells.max(1));
        let cell_size = (bounds.max - bounds.min) / dims.as_vec3();
        let pad = cell_size * CELL_PAD_FRACTION + CELL_PAD_M;
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
                medium.max_extinction_in_box(&Aabb {
                    min: min - pad,
                    max: min + cell_size + pad,
                })
            })
            .collect();
        MajorantGrid {
            bounds,
            dims,
            cell_size,
            values,
            shell: support.shell,
        }
    }

    /// Cells along x, y, z.
    pub fn dims(&self) -> UVec3 {
        self.dims
    }

    /// The box the grid covers.
    pub fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// The majorant that applies at `p`: its cell's inside the box, the shell's in the band outside.
    pub fn majorant_at(&self, p: Vec3) -> f32 {
        if p.cmpge(self.bounds.min).all() && p.cmple(self.bounds.max).all() {
            return self.values[self.index(self.cell_of(p))];
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

    /// Mean majorant over the cells (a measure of how tight the grid is), m^-1.
    pub fn mean_majorant_per_m(&self) -> f32 {
        self.values.iter().sum::<f32>() / self.values.len() as f32
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
            .bounds
            .ray_interval(origin, dir)
            .and_then(|i| i.clip(0.0, t_max))
        {
            None => self.walk_shell(origin, dir, (0.0, t_max), &mut visit),
            Some(inside) => {
                self.walk_shell(origin, dir, (0.0, inside.start), &mut visit)?;
                self.walk_cells(origin, dir, (inside.start, inside.end), &mut visit)?;
                self.walk_shell(origin, dir, (inside.end, t_max), &mut visit)
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

    /// 3D digital differential analyser through the cells (Amanatides & Woo 1987, "A Fast Voxel
    /// Traversal Algorithm for Ray Tracing"); zero cells are skipped without a visit.
    fn walk_cells<R>(
        &self,
        origin: Vec3,
        dir: Vec3,
        (start, end): (f32, f32),
        visit: &mut impl FnMut(Segment) -> ControlFlow<R>,
    ) -> ControlFlow<R> {
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
