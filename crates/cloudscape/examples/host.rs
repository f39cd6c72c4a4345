//! A host renderer that owns its device, draws its own geometry (a ground and a few towers) into
//! its own reversed-Z depth buffer, and has cloudscape render the clouds over it: the way a game
//! engine uses the library. Writes `host.png` (or the path given) and checks that the towers hide
//! the clouds behind them.
//!
//! `cargo run -p cloudscape --example host -- [OUT.png]`

use cloudscape::prelude::*;
use glam::{UVec2, Vec3};
use wgpu::util::DeviceExt;

const SIZE: UVec2 = UVec2::new(320, 180);
const COLOR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// The host's own shader: Lambert-shaded geometry in scene radiance units.
const HOST_WGSL: &str = "
struct View { clip_from_world: mat4x4<f32>, sun: vec4<f32> }
@group(0) @binding(0) var<uniform> view: View;
struct Out { @builtin(position) clip: vec4<f32>, @location(0) normal: vec3<f32> }
@vertex fn vs(@location(0) p: vec3<f32>, @location(1) n: vec3<f32>) -> Out {
    return Out(view.clip_from_world * vec4<f32>(p, 1.0), n);
}
@fragment fn fs(v: Out) -> @location(0) vec4<f32> {
    let lit = max(dot(normalize(v.normal), view.sun.xyz), 0.0) * view.sun.w + 0.15;
    return vec4<f32>(vec3<f32>(0.18, 0.16, 0.14) * lit, 1.0);
}";

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out = std::env::args().nth(1).unwrap_or_else(|| "host.png".into());
    // The host's device: any adapter, opened by the host, handed to the library.
    let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle());
    let adapter = pollster::block_on(instance.request_adapter(&Default::default()))?;
    let (device, queue) = pollster::block_on(adapter.request_device(&Default::default()))?;
    let gpu = GpuContext::from_wgpu(adapter, device, queue);

    // The clouds' settings: the sky and its layers, read once.
    let doc = SceneDocument::parse(
        "",
        "host scene",
        ".".as_ref(),
        &["layers.0.coverage=0.75".into()],
    )?;
    let mut clouds = CloudRenderer::new(&gpu, &doc.scene, ".".as_ref())?;

    // Each frame, the host's own camera (reversed-Z infinite projection, Bevy's convention), sun
    // and clock.
    let eye = Vec3::new(0.0, 30.0, 0.0);
    let forward = Vec3::new(-0.34, 0.25, 0.94).normalize();
    let depth = DepthConvention::ReversedInfinite;
    let frame = Frame {
        size: SIZE,
        camera_position_m: eye,
        view_from_world: glam::camera::rh::view::look_to_mat4(eye, forward, Vec3::Y),
        clip_from_view: depth.perspective(
            65f32.to_radians(),
            SIZE.x as f32 / SIZE.y as f32,
            0.5,
            1.0e5,
        ),
        depth,
        far_m: 1.2e5,
        sun: FrameSun {
            direction: direction_from_angles_deg(30.0, 215.0),
            irradiance: Vec3::splat(8.0),
            angular_radius_rad: 0.2679f32.to_radians(),
        },
        time_s: 0.0,
        exposure_ev: 0.0,
        frame_index: 0,
    };

    // The host draws its geometry into its own colour and depth targets.
    let targets = HostTargets::new(&gpu);
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    draw_geometry(&gpu, &mut encoder, &targets, &frame);

    // Clouds over it: the library reads the host's depth and colour and composes.
    clouds.begin_frame(&gpu, &frame, Reuse::None);
    clouds.encode_clouds(&gpu, &mut encoder, &targets.depth, None, None);
    let background = Background {
        color: &targets.color,
        depth: &targets.depth,
    };
    clouds.encode_finish(&gpu, &mut encoder, &background, None);
    gpu.queue.submit([encoder.finish()]);

    let images = clouds.images();
    let ldr = LdrImage {
        width: SIZE.x,
        height: SIZE.y,
        pixels: bytemuck::cast_slice(&read_texture(&gpu, images.ldr)).to_vec(),
    };
    ldr.write_png(out.as_ref())?;
    check_towers_hide_the_clouds(&gpu, &clouds, &targets)?;
    println!("wrote {out} on {}", gpu.summary());
    Ok(())
}

/// The host's colour target and its reversed-Z depth buffer.
struct HostTargets {
    color: wgpu::TextureView,
    depth: wgpu::TextureView,
    mask: wgpu::Texture,
}

impl HostTargets {
    fn new(gpu: &GpuContext) -> HostTargets {
        use wgpu::TextureUsages as U;
        let texture = |label, format, usage| {
            gpu.device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size: wgpu::Extent3d {
                    width: SIZE.x,
                    height: SIZE.y,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage,
                view_formats: &[],
            })
        };
        let color = texture(
            "host colour",
            COLOR_FORMAT,
            U::RENDER_ATTACHMENT | U::TEXTURE_BINDING | U::COPY_SRC,
        );
        HostTargets {
            color: color.create_view(&Default::default()),
            depth: texture(
                "host depth",
                DEPTH_FORMAT,
                U::RENDER_ATTACHMENT | U::TEXTURE_BINDING,
            )
            .create_view(&Default::default()),
            mask: color,
        }
    }
}

/// A ground square and three towers in front of the camera, as triangles of (position, normal).
fn geometry() -> Vec<[f32; 6]> {
    let mut v = Vec::new();
    let mut quad = |corners: [Vec3; 4], n: Vec3| {
        for i in [0, 1, 2, 0, 2, 3] {
            let p = corners[i];
            v.push([p.x, p.y, p.z, n.x, n.y, n.z]);
        }
    };
    let g = 20_000.0;
    quad(
        [
            Vec3::new(-g, 0.0, -g),
            Vec3::new(-g, 0.0, g),
            Vec3::new(g, 0.0, g),
            Vec3::new(g, 0.0, -g),
        ],
        Vec3::Y,
    );
    for (x, z, half, height) in [
        (-300.0, 700.0, 60.0, 420.0),
        (20.0, 900.0, 90.0, 650.0),
        (260.0, 650.0, 50.0, 300.0),
    ] {
        let (lo, hi) = (
            Vec3::new(x - half, 0.0, z - half),
            Vec3::new(x + half, height, z + half),
        );
        let c = |i: u32| {
            Vec3::new(
                if i & 1 == 0 { lo.x } else { hi.x },
                if i & 2 == 0 { lo.y } else { hi.y },
                if i & 4 == 0 { lo.z } else { hi.z },
            )
        };
        for (ids, n) in [
            ([0, 2, 6, 4], Vec3::NEG_X),
            ([1, 5, 7, 3], Vec3::X),
            ([0, 4, 5, 1], Vec3::NEG_Y),
            ([2, 3, 7, 6], Vec3::Y),
            ([0, 1, 3, 2], Vec3::NEG_Z),
            ([4, 6, 7, 5], Vec3::Z),
        ] {
            quad(ids.map(c), n);
        }
    }
    v
}

/// Draws the geometry with the host's own pipeline, depth test keeping nearer (greater) depths.
fn draw_geometry(
    gpu: &GpuContext,
    encoder: &mut wgpu::CommandEncoder,
    targets: &HostTargets,
    frame: &Frame,
) {
    let device = &gpu.device;
    let sun = frame.sun;
    let mut view = frame.clip_from_world().to_cols_array().to_vec();
    view.extend(
        sun.direction
            .extend(sun.irradiance.x / std::f32::consts::PI)
            .to_array(),
    );
    let uniform = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("host view"),
        contents: bytemuck::cast_slice(&view),
        usage: wgpu::BufferUsages::UNIFORM,
    });
    let vertices = geometry();
    let buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("host geometry"),
        contents: bytemuck::cast_slice(&vertices),
        usage: wgpu::BufferUsages::VERTEX,
    });
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("host"),
        source: wgpu::ShaderSource::Wgsl(HOST_WGSL.into()),
    });
    let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("host geometry"),
        layout: None,
        vertex: wgpu::VertexState {
            module: &module,
            entry_point: Some("vs"),
            compilation_options: Default::default(),
            buffers: &[Some(wgpu::VertexBufferLayout {
                array_stride: 24,
                step_mode: wgpu::VertexStepMode::Vertex,
                attributes: &wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3],
            })],
        },
        primitive: Default::default(),
        depth_stencil: Some(wgpu::DepthStencilState {
            format: DEPTH_FORMAT,
            depth_write_enabled: Some(true),
            depth_compare: Some(frame.depth.compare()),
            stencil: Default::default(),
            bias: Default::default(),
        }),
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module: &module,
            entry_point: Some("fs"),
            compilation_options: Default::default(),
            targets: &[Some(COLOR_FORMAT.into())],
        }),
        multiview_mask: None,
        cache: None,
    });
    let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout: &pipeline.get_bind_group_layout(0),
        entries: &[wgpu::BindGroupEntry {
            binding: 0,
            resource: uniform.as_entire_binding(),
        }],
    });
    let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some("host geometry"),
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view: &targets.color,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations {
                load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                store: wgpu::StoreOp::Store,
            },
        })],
        depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
            view: &targets.depth,
            depth_ops: Some(wgpu::Operations {
                load: wgpu::LoadOp::Clear(frame.depth.far_value()),
                store: wgpu::StoreOp::Store,
            }),
            stencil_ops: None,
        }),
        ..Default::default()
    });
    pass.set_pipeline(&pipeline);
    pass.set_bind_group(0, &group, &[]);
    pass.set_vertex_buffer(0, buffer.slice(..));
    pass.draw(0..vertices.len() as u32, 0..1);
}

/// Where the host drew a tower (alpha 1 in its colour target, above the horizon), the cloud output
/// must be clear (transmittance 1, no radiance); the open sky must show clouds.
fn check_towers_hide_the_clouds(
    gpu: &GpuContext,
    clouds: &CloudRenderer,
    targets: &HostTargets,
) -> Result<(), String> {
    let host = read_texture_rgba16f(gpu, &targets.mask);
    let cloud = read_texture_rgba16f(gpu, clouds.images().clouds.radiance_texture());
    let (mut tower, mut sky_with_cloud) = (0, 0);
    for (h, c) in host.iter().zip(&cloud) {
        if h[3] > 0.5 {
            if c[3] < 1.0 {
                tower += 1;
            }
        } else if c[3] < 0.9 {
            sky_with_cloud += 1;
        }
    }
    if tower > 0 {
        return Err(format!(
            "{tower} geometry pixels show clouds in front of them"
        ));
    }
    if sky_with_cloud < 100 {
        return Err(format!("only {sky_with_cloud} sky pixels show clouds"));
    }
    Ok(())
}
