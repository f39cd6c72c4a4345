//! The one place that knows every technique: builds the one a scene names.

use crate::field::FieldError;
use crate::frame::Shared;
use crate::gpu::GpuContext;
use crate::particles::render::ParticleRenderer;
use crate::raymarch::RaymarchRenderer;
use crate::scene::Technique as TechniqueName;
use crate::technique::Technique;

/// The technique `name` (`render.technique`), built against the shared groups; an error naming
/// the built ones for a technique that is not (scene files never get here: validation rejects
/// them with a located error, but a scene made in code can).
pub fn build(
    ctx: &GpuContext,
    shared: &Shared,
    name: TechniqueName,
) -> Result<Box<dyn Technique>, FieldError> {
    match name {
        TechniqueName::Raymarch => Ok(Box::new(RaymarchRenderer::new(ctx, shared))),
        TechniqueName::Particles => Ok(Box::new(ParticleRenderer::new(ctx, shared))),
        TechniqueName::Sprites => {
            let built: Vec<&str> = TechniqueName::BUILT.iter().map(|t| t.name()).collect();
            Err(FieldError {
                key_path: "render.technique".into(),
                message: format!(
                    "{:?} is not built yet; built: {}",
                    name.name(),
                    built.join(", ")
                ),
            })
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_built_technique_is_dispatched_under_its_name() {
        let ctx = GpuContext::for_tests();
        let scene = crate::scene::Scene::default();
        let field = crate::field::CloudField::new(&scene, std::path::Path::new(".")).unwrap();
        let field_gpu = crate::field::gpu::FieldGpu::new(&ctx, &field);
        let frame = crate::frame::FrameGpu::new(&ctx, "frame");
        let environment = crate::environment::EnvironmentGpu::new(&ctx, "environment");
        let shared = Shared {
            field: &field_gpu,
            frame: &frame,
            environment: &environment,
        };
        for name in TechniqueName::BUILT {
            assert_eq!(build(&ctx, &shared, *name).unwrap().name(), name.name());
        }
        let error = build(&ctx, &shared, TechniqueName::Sprites)
            .err()
            .expect("not built");
        assert!(
            error.message.contains("built: raymarch, particles"),
            "{}",
            error.message
        );
    }
}
