//! Clouds respect the host's depth buffer: geometry in front of the layer hides them, and the
//! march stops at the geometry's distance. Drives the pass the way a host engine does.

use cloudscape::field::CloudField;
use cloudscape::field::gpu::FieldGpu;
use cloudscape::frame::Frame;
use cloudscape::gpu::{GpuContext, read_texture_rgba16f};
use cloudscape::raymarch::{
    CLOUD_DEPTH_FORMAT, CLOUD_FORMAT, MarchGrid, MarchSettings, RaymarchRenderer, RaymarchTargets,
};
use cloudscape::scene::Scene;
use glam::{UVec2, Vec4};

/// The depth-buffer value (0 near, 1 far) of a point `distance_m` straight ahead.
fn depth_at(frame: &Frame, distance_m: f32) -> f32 {
    let clip = frame.clip_from_view * Vec4::new(0.0, 0.0, -distance_m, 1.0);
    clip.z / clip.w
}

fn texture(
    ctx: &GpuContext,
    size: UVec2,
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
) -> wgpu::Texture {
    cloudscape::gpu::pipeline::texture_2d(ctx, "host depth test", size, format, usage)
}

/// Marches the default scene over a depth buffer cleared to `depth`; returns (rgb radiance sum,
/// mean transmittance).
fn march_over_depth(depth: f32) -> (f32, f32) {
    let ctx = GpuContext::for_tests();
    let mut scene = Scene::default();
    scene.camera.pitch_deg = 35.0;
    scene.layers[0].coverage = 0.8;
    let size = UVec2::new(64, 36);
    let frame = Frame::from_scene(&scene, size);
    let field = CloudField::new(&scene, std::path::Path::new(".")).expect("field");
    let field_gpu = FieldGpu::new(&ctx, &field);
    let mut pass = RaymarchRenderer::new(&ctx, &field_gpu);
    pass.prepare(
        &ctx,
        &frame,
        &MarchSettings::from_scene(&scene),
        &MarchGrid::FULL,
    );
    use wgpu::TextureUsages as U;
    let depth_texture = texture(
        &ctx,
        size,
        wgpu::TextureFormat::Depth32Float,
        U::TEXTURE_BINDING | U::RENDER_ATTACHMENT,
    );
    let clouds = texture(&ctx, size, CLOUD_FORMAT, U::STORAGE_BINDING | U::COPY_SRC);
    let depth_view = depth_texture.create_view(&Default::default());
    let mut encoder = ctx.device.create_command_encoder(&Default::default());
    encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some("host geometry"),
        color_attachments: &[],
        depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
            view: &depth_view,
            depth_ops: Some(wgpu::Operations {
                load: wgpu::LoadOp::Clear(depth),
                store: wgpu::StoreOp::Store,
            }),
            stencil_ops: None,
        }),
        ..Default::default()
    });
    let targets = RaymarchTargets {
        depth: &depth_view,
        clouds: &clouds.create_view(&Default::default()),
        cloud_depth: &texture(&ctx, size, CLOUD_DEPTH_FORMAT, U::STORAGE_BINDING)
            .create_view(&Default::default()),
    };
    pass.encode(
        &ctx,
        &mut encoder,
        &field_gpu,
        &targets,
        (UVec2::ZERO, size),
        None,
    );
    ctx.queue.submit([encoder.finish()]);
    let pixels = read_texture_rgba16f(&ctx, &clouds);
    let radiance: f32 = pixels.iter().map(|p| p[0] + p[1] + p[2]).sum();
    let transmittance = pixels.iter().map(|p| p[3]).sum::<f32>() / pixels.len() as f32;
    (radiance, transmittance)
}

#[test]
fn geometry_in_front_of_the_layer_hides_the_clouds() {
    let scene = Scene::default();
    let frame = Frame::from_scene(&scene, UVec2::new(64, 36));
    // The layer starts 1500 m up; a wall 500 m away stands in front of all of it.
    let (radiance, transmittance) = march_over_depth(depth_at(&frame, 500.0));
    assert_eq!(radiance, 0.0);
    assert_eq!(transmittance, 1.0);
    let (radiance, transmittance) = march_over_depth(1.0);
    assert!(
        radiance > 0.0 && transmittance < 0.8,
        "an empty depth buffer shows the clouds: T = {transmittance}"
    );
}
