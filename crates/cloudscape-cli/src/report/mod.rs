//! `cloudscape report`: the canonical scenes rendered by every real-time technique at every
//! quality preset and by the path tracer, compared, timed and written up as `docs/realism.md`,
//! with the images side by side and a chart of error against frame time.
//!
//! The path-traced references are stored in the repository ([`references`]), keyed by what the
//! path tracer reads ([`keys`]), so a run re-traces only what changed.

mod canonical;
mod chart;
mod keys;
mod markdown;
mod measure;
mod noise;
mod particles;
mod references;
mod regions;
mod sprites;

use crate::common::GpuArgs;
use crate::compare::Comparison;
use anyhow::{Context, Result, anyhow};
use canonical::{CANONICAL, Canonical};
use clap::Args;
use cloudscape::gpu::GpuContext;
use cloudscape::image::write_image;
use cloudscape::scene::{SceneDocument, Technique};
use cloudscape_reference::{DEFAULT_MAJORANT_CELLS, PathTracer};
use glam::UVec2;
use measure::{Measurement, Variant};
use noise::ReferenceNoise;
use references::{Budget, Reference, ReferenceStore};
use std::path::{Path, PathBuf};

/// Arguments of `cloudscape report`.
#[derive(Args, Debug)]
pub struct ReportArgs {
    /// Directory of the canonical scene files.
    #[arg(long, default_value = "scenes")]
    scenes: PathBuf,
    /// Directory to write `realism.md` and its images (`realism/`) into.
    #[arg(long, default_value = "docs")]
    out: PathBuf,
    /// Image width in pixels.
    #[arg(long, default_value_t = 160)]
    width: u32,
    /// Image height in pixels.
    #[arg(long, default_value_t = 90)]
    height: u32,
    /// Path-traced samples per pixel wanted (half with each of two seeds, for the noise estimate):
    /// stored references with fewer are extended, continuing their samples. Without it the stored
    /// references are used as they are, and a missing or stale one is traced with 256.
    #[arg(long, value_parser = clap::value_parser!(u32).range(2..))]
    spp: Option<u32>,
    /// Most seconds of path tracing per reference in this run; the samples traced by then are
    /// stored.
    #[arg(long, default_value_t = 1800.0)]
    time_budget: f64,
    /// Seed of the first half of new references (the second half uses the next one).
    #[arg(long, default_value_t = 2)]
    seed: u64,
    /// Where the path-traced references are stored.
    #[arg(long, default_value = "docs/realism/references")]
    references: PathBuf,
    /// Only the scenes whose name contains this text.
    #[arg(long)]
    only: Option<String>,
    #[command(flatten)]
    gpu: GpuArgs,
}

/// One scene's results.
pub struct Row {
    /// The scene.
    canonical: &'static Canonical,
    /// How its reference was traced.
    reference: references::Record,
    /// The reference's noise.
    noise: ReferenceNoise,
    /// Every variant's error and warm frame time, ms.
    variants: Vec<(Variant, Comparison, f64)>,
    /// The ray marcher as the scene renders itself.
    raymarch: Comparison,
    /// The ray marcher's errors by region.
    raymarch_regions: regions::RegionErrors,
    /// The reference's own estimated error by region ([`noise::own_noise_image`]).
    noise_regions: regions::RegionErrors,
    /// The particles' and the sprites' errors by region, where they show the scene's clouds.
    other_regions: [Option<regions::RegionErrors>; 2],
    /// The particle technique's rows; None where the scene makes no particles.
    particles: Option<particles::ParticleRow>,
    /// The sprite technique's row; None where the sprites show none of the scene's clouds.
    sprites: Option<sprites::SpriteRow>,
}

/// Renders, traces and compares every canonical scene, then writes the report and its chart.
pub fn run(args: ReportArgs) -> Result<()> {
    let images = args.out.join("realism");
    std::fs::create_dir_all(&images).with_context(|| images.display().to_string())?;
    let voxel_dir = std::env::temp_dir().join("cloudscape-report");
    let store = ReferenceStore::new(&args.references);
    let mut ctx = None;
    let mut rows = Vec::new();
    for canonical in CANONICAL
        .iter()
        .filter(|c| args.only.as_deref().is_none_or(|o| c.name.contains(o)))
    {
        eprintln!("== {}", canonical.title);
        let doc = canonical::load(canonical, &args, &voxel_dir)?;
        let ctx = match &ctx {
            Some(c) => c,
            None => ctx.insert(args.gpu.open(&doc)?),
        };
        rows.push(scene_row(canonical, &doc, ctx, (&args, &store), &images)?);
    }
    let adapter = ctx.map_or_else(String::new, |c| c.summary());
    let chart_path = images.join("error-vs-cost.png");
    chart::draw(
        &chart_path,
        &markdown::chart_series(&rows),
        &format!(
            "Error against cost, {}x{}, {}",
            args.width,
            args.height,
            short_adapter(&adapter)
        ),
    )?;
    let path = args.out.join("realism.md");
    std::fs::write(&path, markdown::document(&rows, &args, &adapter))
        .with_context(|| path.display().to_string())?;
    eprintln!("wrote {} and {}", path.display(), chart_path.display());
    Ok(())
}

/// The adapter's name without its backend and type.
fn short_adapter(summary: &str) -> &str {
    summary.split(" (").next().unwrap_or(summary)
}

/// The stored (or newly traced) reference of the scene's cloud field.
fn field_reference(
    name: &str,
    doc: &SceneDocument,
    (args, store): (&ReportArgs, &ReferenceStore),
    key: &str,
) -> Result<Reference> {
    let size = (doc.scene.render.width, doc.scene.render.height);
    store.obtain(name, (key, size), budget(args), || {
        PathTracer::for_scene(
            &doc.scene,
            &doc.resolve_path(""),
            UVec2::new(size.0, size.1),
            DEFAULT_MAJORANT_CELLS,
        )
        .map_err(|e| anyhow!(doc.error_at(&e.key_path, e.message)))
    })
}

/// The tracing budget the arguments give.
fn budget(args: &ReportArgs) -> Budget {
    Budget {
        spp: args.spp,
        seconds: args.time_budget,
        seed: args.seed,
    }
}

/// Reference, every variant's render and the comparisons and images of one scene.
fn scene_row(
    canonical: &'static Canonical,
    doc: &SceneDocument,
    ctx: &GpuContext,
    (args, store): (&ReportArgs, &ReferenceStore),
    images: &Path,
) -> Result<Row> {
    let key = keys::field_key(doc)?;
    let reference = field_reference(canonical.name, doc, (args, store), &key)?;
    let full = reference.image();
    let noise = ReferenceNoise::of(&reference, &full)?;
    let pixel_regions = regions::of_scene(doc, &full);
    let noise_regions =
        regions::RegionErrors::of(&full, &noise::own_noise_image(&reference), &pixel_regions)?;
    let name = canonical.name;
    let image_path = |kind: &str| images.join(format!("{name}-{kind}.png"));
    let (ev, op) = (doc.scene.render.exposure_ev, doc.scene.render.tonemap);
    write_image(&image_path("reference"), &full.clone().opaque(), ev, op)?;
    let sources = particles::Sources {
        store,
        budget: budget(args),
        field_key: &key,
    };
    let (mut variants, mut raymarch, mut particle_row, mut sprite_row) =
        (Vec::new(), None, None, None);
    let (mut raymarch_regions, mut other_regions) = (None, [None, None]);
    for variant in Variant::all()
        .into_iter()
        .filter(|v| v.shows_clouds_of(&doc.scene))
    {
        let mut m: Measurement = measure::measure(doc, ctx, variant, &full)?;
        eprintln!(
            "{:<16} HDR-FLIP {:.4} relMSE {:.4} frame {:.0} ms",
            variant.label(),
            m.comparison.flip_mean,
            m.comparison.relative_mse,
            m.frame_ms
        );
        variants.push((variant, m.comparison.clone(), m.frame_ms));
        if !variant.is_scene_default(&doc.scene) {
            continue;
        }
        match variant.technique {
            Technique::Raymarch => {
                m.write_images(&full, &image_path("raymarch"), &image_path("flip"))?;
                raymarch = Some(m.comparison.clone());
                raymarch_regions = Some(regions::RegionErrors::of(
                    &full,
                    &m.rendered.hdr,
                    &pixel_regions,
                )?);
            }
            Technique::Particles => {
                other_regions[0] = Some(regions::RegionErrors::of(
                    &full,
                    &m.rendered.hdr,
                    &pixel_regions,
                )?);
                particle_row = particles::row(name, &m, &sources, (&full, images))?;
            }
            Technique::Sprites => {
                other_regions[1] = Some(regions::RegionErrors::of(
                    &full,
                    &m.rendered.hdr,
                    &pixel_regions,
                )?);
                sprite_row = Some(sprites::row(name, &mut m, ctx, (&full, images))?);
            }
        }
    }
    eprintln!(
        "reference noise HDR-FLIP {:.4} (halves against each other {:.4}, {} spp)",
        noise.own.flip_mean,
        noise.halves.flip_mean,
        reference.record.spp()
    );
    Ok(Row {
        canonical,
        reference: reference.record,
        noise,
        variants,
        raymarch: raymarch.context("the ray marcher at the scene's quality was not measured")?,
        raymarch_regions: raymarch_regions.context("the ray marcher's regions")?,
        noise_regions,
        other_regions,
        particles: particle_row,
        sprites: sprite_row,
    })
}
