//! The sprite technique's rows of `cloudscape report`: the sprite clusters against the
//! path-traced cloud field, the same reference the ray marcher is measured against. Sprites have
//! no volumetric twin to trace (a sprite is a picture, not a density), so there is one error: what
//! a user sees.

use super::render_with;
use crate::compare::Comparison;
use anyhow::Result;
use cloudscape::gpu::GpuContext;
use cloudscape::image::HdrImage;
use cloudscape::scene::{SceneDocument, Technique};
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

/// Renders the scene with sprites and compares it with the field's reference `field`; writes the
/// images beside the ray marcher's.
pub fn row(
    name: &str,
    doc: &SceneDocument,
    ctx: &GpuContext,
    (field, images): (&HdrImage, &Path),
) -> Result<SpriteRow> {
    let (mut renderer, _, gpu, first_frame_ms) = render_with(doc, ctx, Technique::Sprites)?;
    let image = |kind: &str| images.join(format!("{name}-{kind}.png"));
    let total = Comparison::of(field, &gpu.hdr, Some(&image("sprites-flip")))?;
    gpu.ldr.write_png(&image("sprites"))?;
    let sprites = renderer
        .stats(ctx)
        .and_then(|s| s.primitives)
        .unwrap_or_default();
    eprintln!("sprites: {sprites} drawn, HDR-FLIP {:.4}", total.flip_mean);
    Ok(SpriteRow {
        total,
        sprites,
        first_frame_ms,
    })
}

/// The sprite section of the report: one row per scene.
pub fn markdown<'a>(s: &mut String, rows: impl Iterator<Item = (&'a str, &'a SpriteRow)>) {
    let _ = writeln!(
        s,
        "\n## Sprites\n\n\
         The sprite technique (`render.technique = \"sprites\"`, Wang 2003) on the same scenes, \
         against the same path-traced field. Its clouds are the field's (clusters of textured \
         sprites in wind-borne tiles, opacity ramping with the field's density) and hand-made or \
         model-file clouds; its shading is Wang's artist model with physically derived numbers \
         (`docs/sprites.md`). It draws no voxel grids: the voxel scene shows none.\n\n\
         The first frame's wall time includes making the field's sprite clouds on the CPU.\n\n\
         | scene | sprites drawn | HDR-FLIP | relMSE | luminance ratio | first frame ms |\n\
         |---|---|---|---|---|---|"
    );
    for (title, r) in rows {
        let c = &r.total;
        let _ = writeln!(
            s,
            "| {title} | {} | {:.4} | {:.4} | {:.3} | {:.0} |",
            r.sprites, c.flip_mean, c.relative_mse, c.luminance_ratio, r.first_frame_ms
        );
    }
}
