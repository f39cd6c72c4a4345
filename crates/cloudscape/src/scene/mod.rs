//! The scene: data model, TOML loading, validation and error locations.

mod model;
pub use model::*;
