//! Clouds respect the host's depth buffer in every depth convention: geometry in front of the
//! layer hides them, and the march stops at the geometry's distance. Drives the technique the way a
//! host engine does, through [`CloudRenderer`].

use cloudscape::frame::{DepthConvention, Frame};
use cloudscape::gpu::{GpuContext, read_texture_rgba16f};
use cloudscape::renderer::{CloudRenderer, Reuse};
use cloudscape::scene::{Scene, Technique};
use cloudscape::shadow::LightingReuse;
use glam::UVec2;

/// The default scene (drawn by `technique`), looking up into an overcast layer.
fn overcast(technique: Technique) -> Scene {
    let mut scene = Scene::default();
    scene.camera.pitch_deg = 35.0;
    scene.layers[0].coverage = 0.8;
    scene.render.quality = cloudscape::scene::Quality::Low;
    scene.render.technique = technique;
    scene.particles.table_resolution = cloudscape::scene::TableResolution::Low;
    scene
}

/// The default scene's renderer for `technique`.
fn renderer(ctx: &GpuContext, technique: Technique) -> CloudRenderer {
    CloudRenderer::new(ctx, &overcast(technique), std::path::Path::new(".")).expect("field")
}

/// Begins a frame of `convention` at 64x36 on `clouds`, which draws `technique` with `reuse`.
fn begin(
    ctx: &GpuContext,
    clouds: &mut CloudRenderer,
    convention: DepthConvention,
    (technique, reuse): (Technique, Reuse),
) -> Frame {
    let scene = overcast(technique);
    let frame = Frame::from_scene(&scene, UVec2::new(64, 36)).with_depth(&scene, convention);
    clouds.begin_frame(ctx, &frame, reuse);
    frame
}

/// A depth buffer of `size` cleared to `depth`, recorded into `encoder`.
fn depth_buffer(
    ctx: &GpuContext,
    encoder: &mut wgpu::CommandEncoder,
    size: UVec2,
    depth: f32,
) -> wgpu::TextureView {
    use wgpu::TextureUsages as U;
    let depth_texture = cloudscape::gpu::pipeline::texture_2d(
        ctx,
        "host depth",
        size,
        wgpu::TextureFormat::Depth32Float,
        U::TEXTURE_BINDING | U::RENDER_ATTACHMENT,
    );
    let view = depth_texture.create_view(&Default::default());
    cloudscape::gpu::pipeline::clear_depth(encoder, &view, depth);
    view
}

/// Renders the default scene with `technique` (on `clouds`, its renderer) over a depth buffer of
/// `convention` cleared to the depth of a wall `wall_m` away (None: no geometry); returns the
/// full-resolution output's (rgb radiance sum, mean transmittance), upsampled where the technique
/// renders a coarser grid.
fn clouds_over_depth(
    ctx: &GpuContext,
    clouds: &mut CloudRenderer,
    convention: DepthConvention,
    wall_m: Option<f32>,
    drawn: (Technique, Reuse),
) -> (f32, f32) {
    let frame = begin(ctx, clouds, convention, drawn);
    let depth = wall_m.map_or(convention.far_value(), |d| {
        convention.depth_of_distance(&frame.clip_from_view, d)
    });
    let mut encoder = ctx.device.create_command_encoder(&Default::default());
    let depth_view = depth_buffer(ctx, &mut encoder, frame.size, depth);
    clouds.encode_clouds(ctx, &mut encoder, &depth_view, None, None);
    let color = host_colour(ctx, frame.size);
    let background = cloudscape::post::Background {
        color: &color,
        depth: &depth_view,
    };
    clouds.encode_finish(ctx, &mut encoder, &background, None);
    ctx.queue.submit([encoder.finish()]);
    let pixels = read_texture_rgba16f(ctx, clouds.images().clouds.radiance_texture());
    let radiance: f32 = pixels.iter().map(|p| p[0] + p[1] + p[2]).sum();
    let transmittance = pixels.iter().map(|p| p[3]).sum::<f32>() / pixels.len() as f32;
    (radiance, transmittance)
}

/// Geometry 500 m away hides all of the layer, which starts 1500 m up; an empty depth buffer
/// shows it. One renderer draws every frame, as a host's does when its depth convention changes.
fn geometry_hides_the_clouds(technique: Technique, max_clear_transmittance: f32) {
    let ctx = GpuContext::for_tests();
    let mut clouds = renderer(&ctx, technique);
    // The lighting carried from frame to frame: these frames differ in their depth alone.
    clouds.set_lighting_reuse(Some(LightingReuse::REAL_TIME));
    for convention in DepthConvention::ALL {
        let draw = |clouds: &mut CloudRenderer, wall_m| {
            clouds_over_depth(&ctx, clouds, convention, wall_m, (technique, Reuse::None))
        };
        let (radiance, transmittance) = draw(&mut clouds, Some(500.0));
        assert_eq!(radiance, 0.0, "{technique:?} {convention:?}");
        assert_eq!(transmittance, 1.0, "{technique:?} {convention:?}");
        let (radiance, transmittance) = draw(&mut clouds, None);
        assert!(
            radiance > 0.0 && transmittance < max_clear_transmittance,
            "{technique:?} {convention:?}: an empty depth buffer shows the clouds: T = {transmittance}"
        );
    }
}

#[test]
fn geometry_in_front_of_the_layer_hides_the_clouds_in_every_depth_convention() {
    geometry_hides_the_clouds(Technique::Raymarch, 0.8);
}

/// The particles render at half resolution: the coarse grid takes the farthest depth of each
/// block, and the shared upsampling zeroes the weight of cloud behind a pixel's geometry.
#[test]
fn particles_respect_the_depth_buffer_through_the_upsampling() {
    // The particles' coarser clouds let more light through the same sky.
    geometry_hides_the_clouds(Technique::Particles, 0.95);
}

#[test]
fn statistics_come_back_without_waiting() {
    let ctx = GpuContext::for_tests();
    let mut clouds = renderer(&ctx, Technique::Raymarch);
    let frame = begin(
        &ctx,
        &mut clouds,
        DepthConvention::Standard,
        (Technique::Raymarch, Reuse::None),
    );
    let mut encoder = ctx.device.create_command_encoder(&Default::default());
    let depth = depth_buffer(&ctx, &mut encoder, frame.size, 1.0);
    clouds.encode_clouds(&ctx, &mut encoder, &depth, None, None);
    let color = host_colour(&ctx, frame.size);
    let background = cloudscape::post::Background {
        color: &color,
        depth: &depth,
    };
    clouds.encode_finish(&ctx, &mut encoder, &background, None);
    ctx.queue.submit([encoder.finish()]);
    // Asking does not wait: the answer is this frame's counters or none yet.
    let early = clouds.stats(&ctx);
    ctx.wait_idle();
    let late = clouds.stats(&ctx).expect("the finished frame's counters");
    assert_eq!(late.pixels, frame.size.x * frame.size.y);
    assert!(late.density_samples_per_pixel > 1.0);
    assert!(early.is_none_or(|s| s == late));
}

/// A render scale of 1/2 ([`Reuse::Scaled`]): a quarter of the rays, upsampled to every pixel
/// close to the full march, and geometry in front of the layer still hides the clouds.
#[test]
fn a_scaled_frame_marches_a_quarter_of_the_rays_and_fills_every_pixel() {
    let ctx = GpuContext::for_tests();
    let mut clouds = renderer(&ctx, Technique::Raymarch);
    let convention = DepthConvention::Standard;
    let mut draw = |reuse, wall_m| {
        let drawn = (Technique::Raymarch, reuse);
        let image = clouds_over_depth(&ctx, &mut clouds, convention, wall_m, drawn);
        ctx.wait_idle();
        let rays = clouds.stats(&ctx).expect("the frame's counters").pixels;
        (image, rays)
    };
    let ((full_radiance, full_t), full_rays) = draw(Reuse::None, None);
    let ((radiance, t), rays) = draw(Reuse::Scaled(2), None);
    assert_eq!(4 * rays, full_rays, "rays marched at a render scale of 1/2");
    let relative = (radiance - full_radiance).abs() / full_radiance;
    assert!(
        relative < 0.1 && (t - full_t).abs() < 0.05,
        "the upsampled clouds differ from the full march: radiance {radiance} against \
         {full_radiance} ({relative:.3}), mean transmittance {t} against {full_t}"
    );
    let ((hidden_radiance, hidden_t), _) = draw(Reuse::Scaled(2), Some(500.0));
    assert_eq!((hidden_radiance, hidden_t), (0.0, 1.0), "geometry in front");
}

/// A colour target the compositor may read (never shown: the depth holds no geometry).
fn host_colour(ctx: &GpuContext, size: UVec2) -> wgpu::TextureView {
    use wgpu::TextureUsages as U;
    let format = wgpu::TextureFormat::Rgba16Float;
    cloudscape::gpu::pipeline::texture_2d(ctx, "host colour", size, format, U::TEXTURE_BINDING)
        .create_view(&Default::default())
}
