//! The one place that knows every technique: builds the one a scene names.

use crate::gpu::GpuContext;
use crate::particles::render::ParticleRenderer;
use crate::pass::Shared;
use crate::raymarch::RaymarchRenderer;
use crate::scene::Technique as TechniqueName;
use crate::sprites::SpriteRenderer;
use crate::technique::{Draws, Technique};

/// The technique `name` (`render.technique`), built against the shared groups; it draws once
/// [`Technique::configure`] has given it a scene.
pub fn build(ctx: &GpuContext, shared: &Shared, name: TechniqueName) -> Box<dyn Technique> {
    match name {
        TechniqueName::Raymarch => Box::new(RaymarchRenderer::new(ctx, shared)),
        TechniqueName::Particles => Box::new(ParticleRenderer::new(ctx, shared)),
        TechniqueName::Sprites => Box::new(SpriteRenderer::new(ctx, shared)),
    }
}

/// Which clouds the technique `name` draws, without building it.
pub fn draws(name: TechniqueName) -> Draws {
    match name {
        TechniqueName::Raymarch => crate::raymarch::DRAWS,
        TechniqueName::Particles => crate::particles::render::DRAWS,
        TechniqueName::Sprites => crate::sprites::render::DRAWS,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Scene;
    use std::path::Path;

    #[test]
    fn every_technique_is_dispatched_under_its_name() {
        let ctx = GpuContext::for_tests();
        let mut scene = Scene::default();
        let field = crate::field::CloudField::new(&scene, Path::new(".")).unwrap();
        let field_gpu = crate::field::gpu::FieldGpu::new(&ctx, &field);
        let frame = crate::frame::FrameGpu::new(&ctx, "frame");
        let environment =
            crate::environment::EnvironmentGpu::new(&ctx, crate::environment::TableSizes::SMALLEST);
        let shared = Shared {
            field: &field_gpu,
            frame: &frame,
            environment: &environment,
        };
        for name in TechniqueName::ALL {
            let mut built = build(&ctx, &shared, *name);
            assert_eq!(built.name(), name.name());
            assert_eq!(built.draws(), draws(*name));
            built.configure(&ctx, &scene, Path::new(".")).unwrap();
        }
        scene.sprites.model = Some("no-such-model.toml".into());
        let mut sprites = build(&ctx, &shared, TechniqueName::Sprites);
        let error = sprites
            .configure(&ctx, &scene, Path::new("."))
            .expect_err("no file");
        assert_eq!(error.key_path, "sprites.model");
        assert!(
            error.message.contains("no-such-model.toml"),
            "{}",
            error.message
        );
    }
}
