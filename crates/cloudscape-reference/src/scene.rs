//! Path tracers for a whole scene: the scene's camera, sun, sky, ground, phase function and
//! albedo, just as the GPU techniques get them, around the scene's cloud field
//! ([`PathTracer::for_scene`]) or around a set of the particle technique's particles
//! ([`PathTracer::for_particle_set`]).

use crate::cloud_medium::CloudMedium;
use crate::environment::Environment;
use crate::integrator::PathTracer;
use crate::medium::Medium;
use crate::particle_set_medium::ParticleSetMedium;
use crate::tracking::TrackedMedium;
use cloudscape::field::{CloudField, FieldError, PlanetGeometry};
use cloudscape::frame::{Frame, FrameSettings};
use cloudscape::optics::PhaseLobes;
use cloudscape::particles::density::ReferenceParticle;
use cloudscape::particles::generate::Particle;
use cloudscape::scene::Scene;
use glam::{UVec2, Vec3};
use std::path::Path;

/// Majorant cells for a full render: 4 M cells (16 MiB), built in about a second on two cores in
/// a release build; over a 240 km layer box they are about 400 m wide and 100 m tall.
pub const DEFAULT_MAJORANT_CELLS: usize = 1 << 22;

/// Farthest horizontal distance from the camera that the majorant grid covers, metres; beyond,
/// the layers' single band bound applies.
const MAX_GRID_REACH_M: f32 = 150_000.0;

/// Horizontal half-width of the innermost level of a particle set's nested majorant grid, metres:
/// each level out is twice as wide with as many cells, as each ring of the particle technique's
/// grid has cells twice the size of the one inside it. Camera rays meet the cloud mostly within a
/// few kilometres, where the innermost levels' cells are a few tens of metres wide.
const PARTICLE_GRID_INNER_REACH_M: f32 = 2_000.0;

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
        let planet = field.planet;
        Ok(PathTracer::in_scene(
            scene,
            size,
            planet,
            majorant_cells,
            |frame| {
                let reach_m = frame.far_m.min(MAX_GRID_REACH_M);
                CloudMedium::new(field, frame.time_s, frame.camera_position_m, reach_m)
            },
        ))
    }
}

impl PathTracer<ParticleSetMedium> {
    /// The path tracer of `scene` at `size` pixels with `particles` in place of the scene's cloud
    /// field: the same camera, sun, sky, ground, planet, phase function and albedo as
    /// [`PathTracer::for_scene`], the cloud being the particle technique's own particles, each an
    /// ellipsoid of `reference` of peak extinction `sigma_max_per_m * density` (Yusov 2014; see
    /// [`ParticleSetMedium`]). The scene's reference particle and extinction are those of
    /// `cloudscape::particles::ParticleTableSpec::from_scene`. Builds a majorant grid of about
    /// `majorant_cells` cells over the particles' bounds (see [`DEFAULT_MAJORANT_CELLS`]), in
    /// levels nested about the camera (see [`ParticleSetMedium::nested_about`]).
    ///
    /// Particles wholly farther than the camera's far distance (`camera.far_m`) from the camera
    /// are left out: camera rays see no medium beyond it (here as in [`PathTracer::for_scene`] and
    /// on the GPU), so they would only shadow or light the medium within it along paths that
    /// leave it sideways, which no technique renders either.
    pub fn for_particle_set(
        scene: &Scene,
        size: UVec2,
        particles: &[Particle],
        reference: ReferenceParticle,
        sigma_max_per_m: f32,
        majorant_cells: usize,
    ) -> PathTracer<ParticleSetMedium> {
        let planet = PlanetGeometry::from_scene(&scene.planet);
        PathTracer::in_scene(scene, size, planet, majorant_cells, |frame| {
            let camera = frame.camera_position_m;
            let seen: Vec<Particle> = particles
                .iter()
                .filter(|p| {
                    let radii = Vec3::new(p.radius_m, p.height_m, p.radius_m);
                    let nearest = camera.clamp(p.centre_m - radii, p.centre_m + radii);
                    nearest.distance(camera) <= frame.far_m
                })
                .copied()
                .collect();
            ParticleSetMedium::new(&seen, reference, sigma_max_per_m)
                .nested_about(camera, PARTICLE_GRID_INNER_REACH_M)
        })
    }
}

impl<M: Medium> PathTracer<M> {
    /// The path tracer of `scene` at `size` pixels over `planet` around the medium `medium` makes
    /// for the scene's frame, with a majorant grid of about `majorant_cells` cells.
    fn in_scene(
        scene: &Scene,
        size: UVec2,
        planet: PlanetGeometry,
        majorant_cells: usize,
        medium: impl FnOnce(&Frame) -> M,
    ) -> PathTracer<M> {
        let frame = Frame::from_scene(scene, size);
        let light = cloudscape::environment::Environment::from_scene(scene);
        let ground_albedo = FrameSettings::from_scene(scene).ground_albedo;
        let environment = Environment::new(&frame, &light, ground_albedo, planet);
        let medium = medium(&frame);
        PathTracer {
            volume: TrackedMedium::new(medium, majorant_cells),
            phase: PhaseLobes::from_scene(&scene.phase),
            albedo: scene.lighting.albedo,
            environment,
            frame,
            max_scattering_orders: crate::integrator::MAX_SCATTERING_EVENTS,
        }
    }
}
