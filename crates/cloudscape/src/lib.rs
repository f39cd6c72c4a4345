//! cloudscape: physically based, real-time cloud rendering on wgpu.
//!
//! One [`scene::Scene`] describes the sky; [`field::CloudField`] turns it into cloud density (the CPU
//! specification that every GPU technique is tested against); each technique module renders it.

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
