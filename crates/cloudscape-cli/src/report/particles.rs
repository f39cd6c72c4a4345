//! The particle technique's rows of `cloudscape report`. Two errors are kept apart:
//! - **lighting**: the LUT-shaded particles against the path tracer on the very same particles
//!   (the particle set as a medium, the sum of the particles' densities);
//! - **shape**: that path-traced particle medium against the path-traced cloud field, what turning
//!   the field into particles costs whatever the lighting.
//!
//! The total, the particles against the field's reference, is what a user sees.

use super::keys::particle_key;
use super::measure::Measurement;
use super::noise;
use super::references::{Budget, Reference, ReferenceStore};
use crate::compare::Comparison;
use anyhow::Result;
use cloudscape::image::{HdrImage, write_image};
use cloudscape::particles::ParticleTableSpec;
use cloudscape::particles::density::RadialProfile;
use cloudscape::particles::generate::{self, Generation};
use cloudscape_reference::{DEFAULT_MAJORANT_CELLS, PathTracer};
use glam::UVec2;
use std::fmt::Write as _;
use std::path::Path;

/// The particle technique on one scene.
pub struct ParticleRow {
    /// Particles against the path-traced field.
    pub total: Comparison,
    /// Particles against the path-traced particles.
    pub lighting: Comparison,
    /// Path-traced particles against the path-traced field.
    pub shape: Comparison,
    /// Particles generated (the CPU specification's count).
    pub count: usize,
    /// The path-traced particles' estimated error: their noise ([`noise::own_error`]).
    pub noise: Comparison,
}

/// Where the particle row finds its references: the store, the budget and the field's key.
pub struct Sources<'a> {
    /// The stored references.
    pub store: &'a ReferenceStore,
    /// How much tracing is allowed.
    pub budget: Budget,
    /// The key of the scene's field reference.
    pub field_key: &'a str,
}

/// Compares the particle render `m` with the field's reference `field` and with the path-traced
/// particle set (stored as `NAME-particles`); writes the images beside the ray marcher's. None
/// where the scene makes no particles.
pub fn row(
    name: &str,
    m: &Measurement,
    sources: &Sources,
    (field, images): (&HdrImage, &Path),
) -> Result<Option<ParticleRow>> {
    let scene = &m.scene;
    let spec = ParticleTableSpec::from_scene(scene);
    let generation = Generation::from_scene(scene, RadialProfile::of(&spec.particle).volume_mean());
    let particles = generate::generate(m.renderer.field(), &generation);
    if particles.is_empty() {
        return Ok(None);
    }
    let key = particle_key(
        sources.field_key,
        spec.particle.seed,
        spec.particle.style.gpu_index(),
        &particles,
    );
    let size = (scene.render.width, scene.render.height);
    let reference: Reference = sources.store.obtain(
        &format!("{name}-particles"),
        (&key, size),
        sources.budget,
        || {
            Ok(PathTracer::for_particle_set(
                scene,
                UVec2::new(size.0, size.1),
                &particles,
                spec.particle,
                spec.extinction_per_m,
                DEFAULT_MAJORANT_CELLS,
            ))
        },
    )?;
    let traced = reference.image();
    let path = |kind: &str| images.join(format!("{name}-{kind}.png"));
    m.write_images(field, &path("particles"), &path("particles-flip"))?;
    let (ev, op) = (scene.render.exposure_ev, scene.render.tonemap);
    write_image(
        &path("particle-reference"),
        &traced.clone().opaque(),
        ev,
        op,
    )?;
    let row = ParticleRow {
        total: m.comparison.clone(),
        lighting: Comparison::of(&traced, &m.rendered.hdr, None)?,
        shape: Comparison::of(field, &traced, None)?,
        count: particles.len(),
        noise: noise::own_error(&reference, &traced)?,
    };
    eprintln!(
        "particles: {} made; HDR-FLIP total {:.4}, lighting {:.4}, shape {:.4}",
        row.count, row.total.flip_mean, row.lighting.flip_mean, row.shape.flip_mean
    );
    Ok(Some(row))
}

/// The particle section of the report: one row per scene.
pub fn markdown<'a>(
    s: &mut String,
    rows: impl Iterator<Item = (&'a str, &'a Option<ParticleRow>)>,
) {
    let _ = writeln!(
        s,
        "\n## Particles\n\n\
         The particle technique (`render.technique = \"particles\"`) on the same scenes and \
         references. *Total* compares it with the path-traced cloud field, as the table above \
         does the ray marcher. *Lighting* compares it with the path tracer on its own particles \
         (the particle set as a medium, the sum of the particles' densities): the error of the \
         precomputed tables, the light occlusion and the blending. *Shape* compares the \
         path-traced particles with the path-traced field: the error of turning the field into \
         particles, whatever the lighting. The particle references are stored and extended as the \
         field's are; their noise is estimated as the field's is. The particle \
         technique does not turn voxel grids into particles: the voxel scene makes none.\n\n\
         | scene | particles | total HDR-FLIP | total relMSE | lighting HDR-FLIP | lighting relMSE | shape HDR-FLIP | shape relMSE | reference noise HDR-FLIP |\n\
         |---|---|---|---|---|---|---|---|---|"
    );
    for (title, r) in rows {
        let Some(r) = r else {
            let _ = writeln!(s, "| {title} | 0 | | | | | | | |");
            continue;
        };
        let _ = writeln!(
            s,
            "| {title} | {} | {:.4} | {:.4} | {:.4} | {:.4} | {:.4} | {:.4} | {:.4} |",
            r.count,
            r.total.flip_mean,
            r.total.relative_mse,
            r.lighting.flip_mean,
            r.lighting.relative_mse,
            r.shape.flip_mean,
            r.shape.relative_mse,
            r.noise.flip_mean
        );
    }
}
