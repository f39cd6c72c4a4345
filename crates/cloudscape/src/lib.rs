//! cloudscape: physically based, real-time cloud rendering on wgpu.
//!
//! One [`scene::Scene`] describes the sky; [`field::CloudField`] turns it into cloud density (the CPU
//! specification that every GPU technique is tested against); each technique module renders it.
//!
//! Cargo features, all off by default (without them the crate builds no C or C++ and no image
//! codec): `png` (PNG files of [`image::LdrImage`], weather maps from PNG files), `exr` (OpenEXR
//! files of [`image::HdrImage`]), `gif` (the animated preview `animation::GifPreview`), `flip`
//! (FLIP and HDR-FLIP comparison through NVIDIA's C++ FLIP), and `full` for all of them. Asking a
//! build for a file type it lacks is an error that names the feature.

pub mod animation;
pub mod export;
pub mod field;
pub mod frame;
mod fsutil;
pub mod gpu;
pub mod image;
pub mod optics;
pub mod post;
pub mod raymarch;
pub mod renderer;
pub mod scene;
