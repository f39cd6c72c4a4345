//! What a host needs to render clouds in its own renderer, in one import:
//! `use cloudscape::prelude::*;`.
//!
//! A host opens its device ([`GpuContext::from_wgpu`]), reads a scene ([`SceneDocument`]), builds
//! a [`CloudRenderer`] once, and each frame passes a [`Frame`] (its camera, [`DepthConvention`],
//! [`FrameSun`], clock and exposure) with [`Reuse`], records the clouds against its depth buffer
//! and composes them over its [`Background`]. [`SceneRenderer`] renders whole scenes offline. A
//! host's own shaders reach the sky, the sun and the clouds' shadow through [`Program::host`] over
//! [`ENVIRONMENT_WGSL`], bound at [`ENVIRONMENT_GROUP`]
//! ([`CloudRenderer::environment_group`]).

pub use crate::environment::ENVIRONMENT_WGSL;
pub use crate::field::FieldError;
pub use crate::frame::{DepthConvention, Frame, FrameSun};
pub use crate::gpu::{GpuContext, GpuOptions, read_texture, read_texture_rgba16f};
pub use crate::image::{HdrImage, LdrImage};
pub use crate::post::Background;
pub use crate::renderer::{CloudRenderer, FieldUpdate, FrameImages, Reuse, SceneRenderer};
pub use crate::scene::{Scene, SceneDocument, SceneError, direction_from_angles_deg};
pub use crate::shader::{ENVIRONMENT_GROUP, Program};
pub use crate::temporal::TemporalSettings;
