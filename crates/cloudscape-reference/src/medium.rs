//! What the path tracer needs of a participating medium: its extinction, conservative bounds of it
//! over boxes (for the majorant grid), and where it can be non-zero.

use crate::geometry::Aabb;
use cloudscape::field::PlanetGeometry;
use glam::Vec3;

/// A heterogeneous medium of extinction coefficient sigma_t (m^-1).
pub trait Medium: Sync {
    /// Extinction sigma_t at `p`, m^-1 (>= 0).
    fn extinction_per_m(&self, p: Vec3) -> f32;

    /// An upper bound of [`Medium::extinction_per_m`] over every point of the closed box `b`. It
    /// must never be exceeded (delta tracking is biased wherever it is): prove it, do not sample it.
    fn max_extinction_in_box(&self, b: &Aabb) -> f32;

    /// [`Medium::max_extinction_in_box`] of each of `cells`, which all share one x-z footprint
    /// (a column of the majorant grid), into `out`. Override it when work can be shared.
    fn max_extinction_in_column(&self, cells: &[Aabb], out: &mut [f32]) {
        for (cell, bound) in cells.iter().zip(out) {
            *bound = self.max_extinction_in_box(cell);
        }
    }

    /// Where the extinction may be non-zero.
    fn support(&self) -> Support;

    /// Whether the majorant grid should nest finer levels about a focus (see
    /// [`crate::majorant::MajorantGrid`]); None (the default) for one uniform grid.
    fn nesting(&self) -> Option<Nesting> {
        None
    }

    /// A box holding every point of `region` where the extinction may be non-zero, or None where
    /// there is none; `region` itself by default. Nested majorant levels are shrunk to it.
    fn bounds_within(&self, region: &Aabb) -> Option<Aabb> {
        Some(*region)
    }
}

/// Nested majorant levels about a point: the innermost reaches `inner_reach_m` horizontally from
/// `focus_m`, each next one twice as far, until one holds the support box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Nesting {
    /// Centre of the levels (the camera), m.
    pub focus_m: Vec3,
    /// Horizontal half-width of the innermost level, m.
    pub inner_reach_m: f32,
}

/// The region outside which a medium's extinction is zero: a box, which the majorant grid covers
/// finely, and an altitude band with one bound, which catches whatever lies outside the box (cloud
/// layers reach to the horizon and beyond).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Support {
    /// The box the majorant grid covers.
    pub grid_box: Aabb,
    /// Where the medium continues outside the box.
    pub shell: Option<Shell>,
}

/// An altitude band over the planet with one extinction bound.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Shell {
    /// The planet the altitudes are measured above.
    pub planet: PlanetGeometry,
    /// Lowest altitude, metres.
    pub bottom_m: f32,
    /// Highest altitude, metres.
    pub top_m: f32,
    /// Upper bound of the extinction anywhere in the band, m^-1.
    pub majorant_per_m: f32,
}

/// A box of constant extinction: the analytic medium of the validation tests (slabs, furnaces).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HomogeneousBox {
    /// Where the medium is.
    pub bounds: Aabb,
    /// Its extinction, m^-1.
    pub extinction_per_m: f32,
}

impl Medium for HomogeneousBox {
    fn extinction_per_m(&self, p: Vec3) -> f32 {
        let inside = p.cmpge(self.bounds.min).all() && p.cmple(self.bounds.max).all();
        if inside { self.extinction_per_m } else { 0.0 }
    }

    fn max_extinction_in_box(&self, b: &Aabb) -> f32 {
        if self.bounds.overlaps(b) {
            self.extinction_per_m
        } else {
            0.0
        }
    }

    fn support(&self) -> Support {
        Support {
            grid_box: self.bounds,
            shell: None,
        }
    }
}
