//! Writing cloudscape scenes for other renderers.
//!
//! - [`mitsuba`]: a Mitsuba 3 scene and `.vol` grid for a path-traced ground truth.

mod approximations;
pub(crate) mod mitsuba;
mod xml;

pub use mitsuba::{ExportError, write_mitsuba_scene};
