//! The particle technique's rows of `cloudscape report`. Two errors are kept apart:
//! - **lighting**: the LUT-shaded particles against the path tracer on the very same particles
//!   (the particle set as a medium, the sum of the particles' densities);
//! - **shape**: that path-traced particle medium against the path-traced cloud field, what turning
//!   the field into particles costs whatever the lighting.
//!
//! The total, the particles against the field's reference, is what a user sees.

use super::{ReportArgs, cached_trace, render_with};
use crate::compare::Comparison;
use anyhow::Result;
use cloudscape::gpu::GpuContext;
use cloudscape::image::{HdrImage, write_image};
use cloudscape::particles::ParticleTableSpec;
use cloudscape::particles::density::RadialProfile;
use cloudscape::particles::generate::{self, Generation};
use cloudscape::scene::{SceneDocument, Technique};
use cloudscape_reference::{DEFAULT_MAJORANT_CELLS, PathTracer};
use glam::UVec2;
use std::fmt::Write as _;
use std::hash::{Hash, Hasher};
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
    /// Wall time of the GPU render, ms.
    pub gpu_ms: f64,
}

/// Renders the scene with particles, traces its particle set (cached under the field's `key`
/// and the set itself) and compares both with the field's reference `field`; writes the images
/// beside the ray marcher's. None where the scene makes no particles.
pub fn row(
    name: &str,
    doc: &SceneDocument,
    ctx: &GpuContext,
    (args, key): (&ReportArgs, &str),
    (field, images): (&HdrImage, &Path),
) -> Result<Option<ParticleRow>> {
    let (renderer, scene, gpu, gpu_ms) = render_with(doc, ctx, Technique::Particles)?;
    let spec = ParticleTableSpec::from_scene(&scene);
    let generation =
        Generation::from_scene(&scene, RadialProfile::of(&spec.particle).volume_mean());
    let particles = generate::generate(renderer.field(), &generation);
    if particles.is_empty() {
        return Ok(None);
    }
    let mut hasher = std::collections::hash_map::DefaultHasher::new();
    (key, spec.particle.seed, spec.particle.style.gpu_index()).hash(&mut hasher);
    let mut sorted = particles.clone();
    sorted.sort_by_key(|p| p.id);
    for p in &sorted {
        (p.id, p.centre_m.to_array().map(f32::to_bits)).hash(&mut hasher);
        [p.radius_m, p.height_m, p.density]
            .map(f32::to_bits)
            .hash(&mut hasher);
    }
    let size = UVec2::new(scene.render.width, scene.render.height);
    let reference = cached_trace(&format!("{:016x}", hasher.finish()), size, args, || {
        Ok(PathTracer::for_particle_set(
            &scene,
            size,
            &particles,
            spec.particle,
            spec.extinction_per_m,
            DEFAULT_MAJORANT_CELLS,
        ))
    })?;
    let traced = super::average(&reference.halves);
    let path = |kind: &str| images.join(format!("{name}-{kind}.png"));
    let total = Comparison::of(field, &gpu.hdr, Some(&path("particles-flip")))?;
    gpu.ldr.write_png(&path("particles"))?;
    let (ev, op) = (scene.render.exposure_ev, scene.render.tonemap);
    write_image(&path("particle-reference"), &traced, ev, op)?;
    let row = ParticleRow {
        lighting: Comparison::of(&traced, &gpu.hdr, None)?,
        shape: Comparison::of(field, &traced, None)?,
        total,
        count: particles.len(),
        gpu_ms,
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
         particles, whatever the lighting. The particle references are traced with the same \
         samples and seeds as the field's. The particle technique does not turn voxel grids into \
         particles: the voxel scene makes none.\n\n\
         | scene | particles | total HDR-FLIP | total relMSE | lighting HDR-FLIP | lighting relMSE | shape HDR-FLIP | shape relMSE | GPU ms |\n\
         |---|---|---|---|---|---|---|---|---|"
    );
    for (title, r) in rows {
        let Some(r) = r else {
            let _ = writeln!(s, "| {title} | 0 | | | | | | | |");
            continue;
        };
        let _ = writeln!(
            s,
            "| {title} | {} | {:.4} | {:.4} | {:.4} | {:.4} | {:.4} | {:.4} | {:.0} |",
            r.count,
            r.total.flip_mean,
            r.total.relative_mse,
            r.lighting.flip_mean,
            r.lighting.relative_mse,
            r.shape.flip_mean,
            r.shape.relative_mse,
            r.gpu_ms
        );
    }
}
