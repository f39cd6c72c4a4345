//! cloudscape: physically based, real-time cloud rendering on wgpu.
//!
//! One [`scene::Scene`] describes the sky; [`field::CloudField`] turns it into cloud density (the CPU
//! specification that every GPU technique is tested against). Each technique ([`raymarch`]) turns
//! the field into the cloud-output contract ([`output`]) through the [`technique::Technique`]
//! trait; the shared frame state ([`frame`], [`environment`]) and the shared passes ([`temporal`],
//! [`post`]) serve every technique. [`renderer::CloudRenderer`] hosts them on a game engine's
//! device; [`renderer::SceneRenderer`] renders whole scenes offline.

pub mod animation;
pub mod environment;
pub mod export;
pub mod field;
pub mod frame;
mod fsutil;
pub mod gpu;
pub mod image;
pub mod optics;
pub mod output;
pub mod post;
pub mod probe;
pub mod raymarch;
pub mod renderer;
pub mod scene;
pub mod shader;
pub mod technique;
pub mod temporal;
