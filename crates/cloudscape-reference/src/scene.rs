//! A path tracer for a whole scene: the scene's cloud field, camera, sun, sky, ground, phase
//! function and albedo, just as the GPU techniques get them.

use crate::cloud_medium::CloudMedium;
use crate::environment::Environment;
use crate::integrator::PathTracer;
use crate::tracking::TrackedMedium;
use cloudscape::field::{CloudField, FieldError};
use cloudscape::frame::Frame;
use cloudscape::optics::PhaseLobes;
use cloudscape::scene::Scene;
use glam::UVec2;
use std::path::Path;

/// Majorant cells for a full render: 4 M cells (16 MiB), built in about a second on two cores in
/// a release build; over a 240 km layer box they are about 400 m wide and 100 m tall.
pub const DEFAULT_MAJORANT_CELLS: usize = 1 << 22;

/// Farthest horizontal distance from the camera that the majorant grid covers, metres; beyond,
/// the layers' single band bound applies.
const MAX_GRID_REACH_M: f32 = 150_000.0;

impl PathTracer<CloudMedium> {
    /// The path tracer of `scene` at `size` pixels; files resolve against `base_dir`. Bakes the
    /// noise (when there are layers) and builds a majorant grid of about `majorant_cells` cells (see
    /// [`DEFAULT_MAJORANT_CELLS`]).
    pub fn for_scene(
        scene: &Scene,
        base_dir: &Path,
        size: UVec2,
        majorant_cells: usize,
    ) -> Result<PathTracer<CloudMedium>, FieldError> {
        let field = CloudField::new(scene, base_dir)?;
        if !field.layers.is_empty() {
            field.bake_noise();
        }
        let frame = Frame::from_scene(scene, size);
        let light = cloudscape::environment::Environment::from_scene(scene);
        let environment = Environment::new(&frame, &light, field.planet);
        let reach_m = frame.far_m.min(MAX_GRID_REACH_M);
        let medium = CloudMedium::new(field, frame.time_s, frame.camera_position_m, reach_m);
        Ok(PathTracer {
            volume: TrackedMedium::new(medium, majorant_cells),
            phase: PhaseLobes::from_scene(&scene.phase),
            albedo: scene.lighting.albedo,
            environment,
            frame,
            max_scattering_orders: crate::integrator::MAX_SCATTERING_EVENTS,
        })
    }
}
