//! Reading the coarse field at many points at once: the sprite technique asks for the density at
//! every candidate sprite of the tiles it makes. The CPU specification reads
//! [`CloudField::coarse_extinction_per_m`] point by point; [`crate::probe::GpuCoarseReader`] asks
//! the GPU's twin of it (`field_extinction_coarse`) for all of them in one dispatch.

use glam::Vec3;
use rayon::prelude::*;

use super::CloudField;

/// Points to read at once above which the CPU reader bakes the base noise first (its texels are
/// otherwise computed at every read: 8 per point).
const BAKE_ABOVE_POINTS: usize = 250_000;

/// Reads the coarse field's extinction at many points, at one scene time.
pub trait CoarseFieldReader {
    /// [`CloudField::coarse_extinction_per_m`] at each of `points_m` (world, at the reader's
    /// time), m^-1.
    fn coarse_extinctions_per_m(&self, points_m: &[Vec3]) -> Vec<f32>;
}

/// The CPU specification: the field itself at `time_s`.
#[derive(Clone, Copy)]
pub struct CpuCoarseReader<'a> {
    /// The field read.
    pub field: &'a CloudField,
    /// Scene time, s.
    pub time_s: f32,
}

impl CoarseFieldReader for CpuCoarseReader<'_> {
    fn coarse_extinctions_per_m(&self, points_m: &[Vec3]) -> Vec<f32> {
        if points_m.len() > BAKE_ABOVE_POINTS {
            self.field.bake_coarse_noise();
        }
        points_m
            .par_iter()
            .map(|&p| self.field.coarse_extinction_per_m(p, self.time_s))
            .collect()
    }
}
