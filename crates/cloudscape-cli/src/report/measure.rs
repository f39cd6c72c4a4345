//! Error against cost: every real-time technique at every quality preset it has, rendered on a
//! canonical scene, compared with the path-traced reference and timed.

use crate::compare::Comparison;
use anyhow::{Result, anyhow};
use cloudscape::frame::Frame;
use cloudscape::gpu::{GpuContext, PassTimer};
use cloudscape::image::HdrImage;
use cloudscape::renderer::{PASS_COUNT, Rendered, Reuse, SceneRenderer};
use cloudscape::scene::{LightingModel, Quality, Scene, SceneDocument, Technique};
use glam::UVec2;
use std::path::Path;

/// A technique at one setting: the ray marcher at a quality preset or with a lighting model, or a
/// technique whose cost no preset changes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Variant {
    /// The technique.
    pub technique: Technique,
    /// Its quality preset, where it has them; None is the scene's.
    pub quality: Option<Quality>,
    /// The ray marcher's model of multiple scattering; None is the scene's.
    pub lighting: Option<LightingModel>,
}

/// Samples per pixel of the rasterising techniques' compared images: each draws the whole frame
/// through its own point of the pixel ([`SceneRenderer::render`]), so they integrate the pixel's
/// footprint as the path tracer does (the ray marcher does so within its march).
const RASTER_FOOTPRINT_SAMPLES: u32 = 8;

/// The ray marcher's model of multiple scattering the report sets beside the scenes' own: the
/// δ-Eddington slab along the sun, which the light volume replaced.
pub const COMPARED_MODEL: LightingModel = LightingModel::Slab;

/// The quality presets from fast to converged.
const PRESETS: [Quality; 4] = [Quality::Low, Quality::Medium, Quality::High, Quality::Ultra];

impl Variant {
    /// Every variant the report measures: the ray marcher at each preset, the ray marcher with
    /// [`COMPARED_MODEL`] at the scene's preset (the model the light volume replaced), then the
    /// particles and the sprites (only the ray marcher reads `render.quality` and
    /// `lighting.model`).
    pub fn all() -> Vec<Variant> {
        let technique = |technique| Variant {
            technique,
            quality: None,
            lighting: None,
        };
        let presets = PRESETS.map(|q| Variant {
            quality: Some(q),
            ..technique(Technique::Raymarch)
        });
        let compared = Variant {
            lighting: Some(COMPARED_MODEL),
            ..technique(Technique::Raymarch)
        };
        let others = [Technique::Particles, Technique::Sprites].map(technique);
        presets
            .into_iter()
            .chain([compared])
            .chain(others)
            .collect()
    }

    /// "raymarch high", "raymarch slab", "particles".
    pub fn label(&self) -> String {
        let mut label = self.technique.name().to_string();
        if let Some(q) = self.quality {
            label += &format!(" {}", quality_name(q));
        }
        if self.lighting == Some(COMPARED_MODEL) {
            label += " slab";
        }
        label
    }

    /// Whether the technique shows any of `scene`'s clouds ([`cloudscape::renderer::draws`]): a
    /// scene of voxel grids alone has nothing for the particles or the sprites to be measured on.
    pub fn shows_clouds_of(&self, scene: &Scene) -> bool {
        cloudscape::renderer::draws(self.technique).any_of(scene)
    }

    /// Whether this is how `scene` renders itself with `technique`.
    pub fn is_scene_default(&self, scene: &Scene) -> bool {
        self.quality.is_none_or(|q| q == scene.render.quality)
            && self.lighting.is_none_or(|l| l == scene.lighting.model)
    }

    /// `scene` set to render this variant.
    fn apply(&self, scene: &Scene) -> Scene {
        let mut scene = scene.clone();
        scene.render.technique = self.technique;
        if let Some(q) = self.quality {
            scene.render.quality = q;
        }
        if let Some(l) = self.lighting {
            scene.lighting.model = l;
        }
        if self.technique != Technique::Raymarch {
            scene.render.samples_per_pixel = Some(RASTER_FOOTPRINT_SAMPLES);
        }
        scene
    }
}

/// The preset's name as scene files spell it.
fn quality_name(q: Quality) -> &'static str {
    match q {
        Quality::Low => "low",
        Quality::Medium => "medium",
        Quality::High => "high",
        Quality::Ultra => "ultra",
    }
}

/// One variant on one scene.
pub struct Measurement {
    /// Its images.
    pub rendered: Rendered,
    /// Against the scene's reference.
    pub comparison: Comparison,
    /// Wall time of a whole frame once the renderer is warm, ms (one submission, waited for).
    pub frame_ms: f64,
    /// Wall time of the first frame, ms: everything the technique builds for a scene is in it.
    pub first_frame_ms: f64,
    /// The renderer, for what the technique's own rows ask of it.
    pub renderer: SceneRenderer,
    /// The scene as rendered.
    pub scene: Scene,
}

/// Renders `variant` of `doc` twice, each frame one submission waited for: the first builds
/// everything the technique keeps between frames, the second is timed as the frame time and its
/// image compared with `reference`.
pub fn measure(
    doc: &SceneDocument,
    ctx: &GpuContext,
    variant: Variant,
    reference: &HdrImage,
) -> Result<Measurement> {
    let scene = variant.apply(&doc.scene);
    let start = std::time::Instant::now();
    let mut renderer = SceneRenderer::new(ctx, &scene, &doc.resolve_path(""))
        .map_err(|e| anyhow!(doc.error_at(&e.key_path, e.message)))?;
    let frame = Frame::from_scene(&scene, UVec2::new(scene.render.width, scene.render.height));
    let mut timer = PassTimer::new(ctx, PASS_COUNT);
    renderer.render_frame(ctx, &frame, Reuse::None, &mut timer);
    let first_frame_ms = start.elapsed().as_secs_f64() * 1e3;
    let frame_ms = renderer
        .render_frame(ctx, &frame, Reuse::None, &mut timer)
        .as_secs_f64()
        * 1e3;
    let rendered = match scene.render.technique {
        Technique::Raymarch => renderer.images(ctx),
        Technique::Particles | Technique::Sprites => renderer.render(ctx, |_| {}),
    };
    let comparison = Comparison::of(reference, &rendered.hdr, None)?;
    Ok(Measurement {
        rendered,
        comparison,
        frame_ms,
        first_frame_ms,
        renderer,
        scene,
    })
}

impl Measurement {
    /// Writes the tone-mapped image to `image`, the HDR radiance beside it as EXR, and the
    /// HDR-FLIP map against `reference` to `flip`.
    pub fn write_images(&self, reference: &HdrImage, image: &Path, flip: &Path) -> Result<()> {
        self.rendered.ldr.write_png(image)?;
        self.rendered.hdr.write_exr(&image.with_extension("exr"))?;
        Comparison::of(reference, &self.rendered.hdr, Some(flip))?;
        Ok(())
    }
}
