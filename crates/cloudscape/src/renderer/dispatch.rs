//! The one place that knows every technique: builds the one a scene names.

use std::path::Path;

use crate::field::FieldError;
use crate::frame::Shared;
use crate::gpu::GpuContext;
use crate::particles::render::ParticleRenderer;
use crate::raymarch::RaymarchRenderer;
use crate::scene::{Scene, Technique as TechniqueName};
use crate::sprites::SpriteRenderer;
use crate::technique::Technique;

/// The technique `scene` names (`render.technique`), built against the shared groups; files it
/// reads (a sprite model) resolve against `base_dir`, and one that cannot be read is an error at
/// its scene key.
pub fn build(
    ctx: &GpuContext,
    shared: &Shared,
    scene: &Scene,
    base_dir: &Path,
) -> Result<Box<dyn Technique>, FieldError> {
    Ok(match scene.render.technique {
        TechniqueName::Raymarch => Box::new(RaymarchRenderer::new(ctx, shared)),
        TechniqueName::Particles => Box::new(ParticleRenderer::new(ctx, shared)),
        TechniqueName::Sprites => Box::new(SpriteRenderer::new(ctx, shared, scene, base_dir)?),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_technique_is_dispatched_under_its_name() {
        let ctx = GpuContext::for_tests();
        let mut scene = Scene::default();
        let field = crate::field::CloudField::new(&scene, Path::new(".")).unwrap();
        let field_gpu = crate::field::gpu::FieldGpu::new(&ctx, &field);
        let frame = crate::frame::FrameGpu::new(&ctx, "frame");
        let environment = crate::environment::EnvironmentGpu::new(&ctx, 16);
        let shared = Shared {
            field: &field_gpu,
            frame: &frame,
            environment: &environment,
        };
        for name in TechniqueName::ALL {
            scene.render.technique = *name;
            let built = build(&ctx, &shared, &scene, Path::new(".")).unwrap();
            assert_eq!(built.name(), name.name());
        }
        scene.sprites.model = Some("no-such-model.toml".into());
        let error = build(&ctx, &shared, &scene, Path::new("."))
            .err()
            .expect("no file");
        assert_eq!(error.key_path, "sprites.model");
        assert!(
            error.message.contains("no-such-model.toml"),
            "{}",
            error.message
        );
    }
}
