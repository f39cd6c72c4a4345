//! The raster-pass helpers: a render pipeline with premultiplied-alpha blending, tested against a
//! read-only depth attachment, timed by the pass timer, as sprite and particle splats use them.

use cloudscape::frame::DepthConvention;
use cloudscape::gpu::pipeline::{
    DepthTest, PREMULTIPLIED_OVER, RasterDescriptor, begin_render_pass, render_pipeline, texture_2d,
};
use cloudscape::gpu::{GpuContext, PassTimer, read_texture_rgba16f};
use glam::UVec2;

/// Instance 0 covers the left half at depth 0.25, instance 1 the right half at 0.75; both write
/// premultiplied (0.5, 0, 0, 0.5).
const SPLAT_WGSL: &str = "
@vertex fn vs(@builtin(vertex_index) v: u32, @builtin(instance_index) i: u32) -> @builtin(position) vec4<f32> {
    let corner = vec2<f32>(f32(v & 1u), f32(v >> 1u));
    let x = mix(-1.0, 0.0, corner.x) + f32(i);
    let y = mix(-1.0, 1.0, corner.y);
    return vec4<f32>(x, y, select(0.25, 0.75, i == 1u), 1.0);
}
@fragment fn fs() -> @location(0) vec4<f32> {
    return vec4<f32>(0.5, 0.0, 0.0, 0.5);
}";

#[test]
fn splats_blend_premultiplied_and_respect_a_read_only_depth_buffer() {
    let ctx = GpuContext::for_tests();
    let size = UVec2::new(16, 8);
    use wgpu::TextureUsages as U;
    let format = wgpu::TextureFormat::Rgba16Float;
    let color = texture_2d(
        &ctx,
        "splat target",
        size,
        format,
        U::RENDER_ATTACHMENT | U::COPY_SRC,
    );
    let depth_format = wgpu::TextureFormat::Depth32Float;
    let depth = texture_2d(&ctx, "host depth", size, depth_format, U::RENDER_ATTACHMENT);
    let (color_view, depth_view) = (
        color.create_view(&Default::default()),
        depth.create_view(&Default::default()),
    );
    let pipeline = render_pipeline(
        &ctx,
        &RasterDescriptor {
            label: "splats",
            entries: ("vs", "fs"),
            targets: &[Some(wgpu::ColorTargetState {
                format,
                blend: Some(PREMULTIPLIED_OVER),
                write_mask: wgpu::ColorWrites::ALL,
            })],
            depth: Some(DepthTest {
                format: depth_format,
                compare: DepthConvention::Standard.compare(),
            }),
            topology: wgpu::PrimitiveTopology::TriangleStrip,
        },
        SPLAT_WGSL,
        &[],
    );
    let mut encoder = ctx.device.create_command_encoder(&Default::default());
    cloudscape::gpu::pipeline::clear_depth(&mut encoder, &depth_view, 0.5);
    let mut timer = PassTimer::new(&ctx, 1);
    {
        let blue = wgpu::LoadOp::Clear(wgpu::Color::BLUE);
        let writes = timer.render_pass_writes("splats");
        let mut pass = begin_render_pass(
            &mut encoder,
            "splats",
            (&color_view, blue),
            Some(&depth_view),
            writes,
        );
        pass.set_pipeline(&pipeline);
        pass.draw(0..4, 0..2);
    }
    timer.resolve(&mut encoder);
    ctx.queue.submit([encoder.finish()]);
    let pixels = read_texture_rgba16f(&ctx, &color);
    let at = |x: u32, y: u32| pixels[(y * size.x + x) as usize];
    assert_eq!(
        at(3, 4),
        [0.5, 0.0, 0.5, 1.0],
        "in front of the depth: blended over blue"
    );
    assert_eq!(
        at(12, 4),
        [0.0, 0.0, 1.0, 1.0],
        "behind the depth: rejected"
    );
    if ctx.has_timestamps() {
        assert_eq!(timer.read_ms(&ctx).len(), 1, "the raster pass is timed");
    }
}
