//! The sprite technique's rows of `cloudscape report`: the sprite clusters against the
//! path-traced cloud field, the same reference the ray marcher is measured against. Sprites have
//! no volumetric twin to trace (a sprite is a picture, not a density), so there is one error: what
//! a user sees.

use super::measure::Measurement;
use crate::compare::Comparison;
use anyhow::Result;
use cloudscape::gpu::GpuContext;
use cloudscape::image::HdrImage;
use std::fmt::Write as _;
use std::path::Path;

/// The sprite technique on one scene.
pub struct SpriteRow {
    /// Sprites against the path-traced field.
    pub total: Comparison,
    /// Sprites drawn (in 3D and into the impostors).
    pub sprites: u32,
    /// Wall time of the first frame, ms: the clouds are made on the CPU in it.
    pub first_frame_ms: f64,
}

/// The sprite render `m` against the field's reference `field`; writes the images beside the ray
/// marcher's.
pub fn row(
    name: &str,
    m: &mut Measurement,
    ctx: &GpuContext,
    (field, images): (&HdrImage, &Path),
) -> Result<SpriteRow> {
    let image = |kind: &str| images.join(format!("{name}-{kind}.png"));
    m.write_images(field, &image("sprites"), &image("sprites-flip"))?;
    let sprites = m
        .renderer
        .stats(ctx)
        .and_then(|s| s.primitives)
        .unwrap_or_default();
    eprintln!(
        "sprites: {sprites} drawn, HDR-FLIP {:.4}",
        m.comparison.flip_mean
    );
    Ok(SpriteRow {
        total: m.comparison.clone(),
        sprites,
        first_frame_ms: m.first_frame_ms,
    })
}

/// The sprite section of the report: one row per scene.
pub fn markdown<'a>(s: &mut String, rows: impl Iterator<Item = (&'a str, &'a Option<SpriteRow>)>) {
    let _ = writeln!(
        s,
        "\n## Sprites\n\n\
         The sprite technique (`render.technique = \"sprites\"`, Wang 2003) on the same scenes, \
         against the same path-traced field. Its clouds are the field's (clusters of soft textured \
         sprites in wind-borne tiles, each as opaque as the matter of its cell, lit from the light \
         volume and the cloud shadow map) and hand-made or model-file clouds (Wang's artist model \
         with physically derived numbers; `docs/sprites.md`). It draws no voxel grids: the voxel \
         scene shows none, and is not measured.\n\n\
         The first frame's wall time includes making the field's sprite clouds (the tiles' drafts on \
         the CPU, the field's density at every candidate read on the GPU) and the light volume's \
         first solve; `cloudscape bench` times the build alone (\"first frame's prepare\").\n\n\
         | scene | sprites drawn | HDR-FLIP | relMSE | luminance ratio | first frame ms |\n\
         |---|---|---|---|---|---|"
    );
    for (title, r) in rows {
        let Some(r) = r else {
            let _ = writeln!(s, "| {title} | 0 | | | | |");
            continue;
        };
        let c = &r.total;
        let _ = writeln!(
            s,
            "| {title} | {} | {:.4} | {:.4} | {:.3} | {:.0} |",
            r.sprites, c.flip_mean, c.relative_mse, c.luminance_ratio, r.first_frame_ms
        );
    }
}
