//! Sprite-cluster clouds (Wang 2003, "Realistic and Fast Cloud Rendering in Computer Games",
//! Microsoft Flight Simulator 2004): each cloud is a cluster of textured sprites, shaded by an
//! artist-style model whose numbers here come from physics, with an impostor ring for the
//! distance.
//!
//! - [`types`]: the ten cloud types and their recipes;
//! - [`model`]: clouds from boxes, the fill-and-cull generator (the CPU specification);
//! - [`from_field`]: clouds from the cloud field, in wind-borne tiles, kept and remade by
//!   [`field_tiles`];
//! - [`textures`]: the 4 x 4 sheet of puffs, baked from the reference particle;
//! - [`shading`]: colour levels, shading groups, directional and single-scattered light;
//! - [`inside`]: the fog that stands for the sprites the eye has passed, inside a cloud;
//! - [`file`]: sprite model files;
//! - [`cloud_set`], [`views`], [`impostors`], [`render`]: the technique on the GPU.

pub mod cloud_set;
pub(crate) mod field_tiles;
pub mod file;
pub(crate) mod from_field;
pub mod impostors;
pub mod inside;
pub(crate) mod model;
pub(crate) mod render;
pub mod shading;
pub(crate) mod textures;
pub mod types;
pub(crate) mod views;

pub use file::ModelFile;
pub use model::{CloudModel, Sprite, SpriteBox, SpriteCloud};
pub use render::SpriteRenderer;
pub use textures::puff_sheet_preview;
