//! The cloud field: everything that says how much cloud is where.
//!
//! - [`voxel`]: density grids on a regular lattice, in Mitsuba 3's `.vol` format.

pub mod voxel;
