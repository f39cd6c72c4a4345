//! cloudscape: physically based, real-time cloud rendering on wgpu.
//!
//! One [`scene::Scene`] describes the sky; [`field::CloudField`] turns it into cloud density (the CPU
//! specification that every GPU technique is tested against). Each technique ([`raymarch`]) turns
//! the field into the cloud-output contract ([`output`]) through the [`technique::Technique`]
//! trait; the shared frame state ([`frame`], [`environment`]) and the shared passes ([`temporal`],
//! [`post`]) serve every technique. [`renderer::CloudRenderer`] hosts them on a game engine's
//! device; [`renderer::SceneRenderer`] renders whole scenes offline. A host needs only
//! [`prelude`].
//!
//! The top-level modules form a DAG (`tests/module_graph.rs` holds them to it), from the leaves up:
//! the WGSL registry ([`shader`]), GPU helpers ([`gpu`]), images and optics; the scene document
//! ([`scene`]); the field ([`field`]), the frame ([`frame`]), the atmosphere and the environment
//! ([`environment`]); the pass builder and shared groups (`pass`, internal); the techniques
//! ([`raymarch`], [`particles`], [`sprites`]) behind [`technique`]; temporal reuse, composition and
//! the hosts ([`renderer`]).
//!
//! Cargo features, all off by default (without them the crate builds no C or C++ and no image
//! codec): `png` (PNG files of [`image::LdrImage`], weather maps from PNG files), `exr` (OpenEXR
//! files of [`image::HdrImage`]), `gif` (the animated preview `animation::GifPreview`), `flip`
//! (FLIP and HDR-FLIP comparison through NVIDIA's C++ FLIP), and `full` for all of them. Asking a
//! build for a file type it lacks is an error that names the feature.

pub mod animation;
pub(crate) mod atmosphere;
pub mod environment;
pub mod export;
pub mod field;
pub mod frame;
pub mod fsutil;
pub mod gpu;
pub mod image;
pub mod optics;
pub mod output;
pub mod particles;
pub(crate) mod pass;
pub mod post;
pub mod prelude;
pub mod probe;
pub mod raymarch;
pub mod renderer;
pub mod scene;
pub mod shader;
pub mod shadow;
pub mod sprites;
pub mod stable_hash;
pub mod technique;
pub mod temporal;
