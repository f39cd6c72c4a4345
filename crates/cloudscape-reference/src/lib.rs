//! Ground truth for cloudscape: a CPU volumetric path tracer that solves the full radiative
//! transfer in the very cloud field the real-time techniques draw (`cloudscape::field`), with the
//! same camera, sun, sky, ground and haze.
//!
//! - [`tracking`]: delta tracking (free flights) and ratio tracking (shadow rays) through a
//!   [`majorant::MajorantGrid`] of conservative bounds;
//! - [`integrator::PathTracer`]: next-event estimation toward the sun disc and the sky, exact
//!   phase sampling, Russian roulette, Lambertian ground;
//! - [`render::ProgressiveRender`]: passes over all cores, deterministic per seed, stoppable;
//! - [`particle_set_medium::ParticleSetMedium`]: the particle technique's own particles as a
//!   medium (Yusov 2014), path traced by [`PathTracer::for_particle_set`];
//! - [`regions`]: which part of the picture each pixel shows (cloud, clear sky, ground, the sun's
//!   neighbourhood), so errors can be told apart by region.
//!
//! ```no_run
//! use cloudscape::scene::SceneDocument;
//! use cloudscape_reference::{DEFAULT_MAJORANT_CELLS, PathTracer, ProgressiveRender};
//! let doc = SceneDocument::load(None, &[]).unwrap();
//! let size = glam::UVec2::new(320, 180);
//! let tracer =
//!     PathTracer::for_scene(&doc.scene, &doc.resolve_path(""), size, DEFAULT_MAJORANT_CELLS)
//!         .unwrap();
//! let mut render = ProgressiveRender::new(&tracer, 1);
//! render.run_pass(16, &|| false, &|_| {});
//! let image = render.image();
//! ```

pub mod cloud_medium;
pub mod environment;
pub mod geometry;
pub mod integrator;
pub mod light_tracer;
pub mod majorant;
pub mod medium;
pub mod particle_medium;
pub mod particle_set_medium;
pub mod regions;
pub mod render;
pub mod rng;
pub mod sampling;
mod scene;
pub mod tracking;

pub use cloud_medium::CloudMedium;
pub use integrator::PathTracer;
pub use particle_set_medium::ParticleSetMedium;
pub use render::{PixelEstimate, ProgressiveRender, RenderStats};
pub use scene::DEFAULT_MAJORANT_CELLS;

/// The revision of what the path tracer converges to: raised by every change that moves its
/// expected image (a fix, a new effect), and only by those, so that references stored with an
/// older revision are traced anew while changes that only lower the noise keep them.
///
/// 2: the air's sunlit in-scattering is shadowed by the clouds, and alpha holds the share of a
/// pixel's paths that met cloud.
pub const TRACER_REVISION: u32 = 2;
