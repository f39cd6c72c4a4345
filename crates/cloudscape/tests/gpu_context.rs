//! GPU set-up, readback and timing on whatever adapter exists (`CLOUDSCAPE_TEST_BACKEND=vulkan|gl`
//! picks one). These tests fail, never skip, when no adapter exists.

use cloudscape::field::voxel::VoxelGrid;
use cloudscape::gpu::{self, GpuContext, GpuError, GpuOptions, PassTimer};
use glam::Vec3;
use wgpu::util::DeviceExt;

/// A texture of `format` filled with `bytes` (rows tightly packed), readable back.
fn texture_with(
    ctx: &GpuContext,
    format: wgpu::TextureFormat,
    size: [u32; 2],
    bytes: &[u8],
) -> wgpu::Texture {
    let texture = ctx.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("test texture"),
        size: wgpu::Extent3d {
            width: size[0],
            height: size[1],
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage: wgpu::TextureUsages::COPY_SRC | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    let bytes_per_texel = format.block_copy_size(None).unwrap();
    ctx.queue.write_texture(
        texture.as_image_copy(),
        bytes,
        wgpu::TexelCopyBufferLayout {
            offset: 0,
            bytes_per_row: Some(size[0] * bytes_per_texel),
            rows_per_image: None,
        },
        texture.size(),
    );
    texture
}

fn buffer_with(ctx: &GpuContext, values: &[u32], usage: wgpu::BufferUsages) -> wgpu::Buffer {
    let buffer = ctx.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("test buffer"),
        size: size_of_val(values) as u64,
        usage: usage | wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    ctx.queue
        .write_buffer(&buffer, 0, bytemuck::cast_slice(values));
    buffer
}

#[test]
fn context_describes_its_adapter() {
    let ctx = GpuContext::for_tests();
    let info = ctx.adapter_info();
    assert!(ctx.summary().starts_with(&info.name));
    assert!(ctx.summary().contains(&format!("{:?}", info.backend)));
    // WebGPU's minimum; the adapter's own limits are requested, so this is at least as large.
    assert!(ctx.max_texture_dimension_2d() >= 2048);
}

#[test]
fn impossible_adapter_filter_explains_itself() {
    let options = GpuOptions {
        backend: None,
        adapter_substring: Some("no-such-gpu-xyz".into()),
    };
    let error = GpuContext::new(&options).unwrap_err();
    assert!(matches!(error, GpuError::NoAdapter { .. }));
    let message = error.to_string();
    assert!(
        message.contains("name does not contain \"no-such-gpu-xyz\""),
        "{message}"
    );
    assert!(
        message.contains("apt-get install mesa-vulkan-drivers libvulkan1"),
        "{message}"
    );
}

#[test]
fn read_texture_strips_row_padding() {
    let ctx = GpuContext::for_tests();
    // 37 texels x 4 bytes = 148 bytes per row: copied with 256-byte rows, returned tight.
    let (width, height) = (37u32, 5u32);
    let bytes: Vec<u8> = (0..width * height * 4)
        .map(|i| (i * 7 % 251) as u8)
        .collect();
    let texture = texture_with(
        &ctx,
        wgpu::TextureFormat::Rgba8Unorm,
        [width, height],
        &bytes,
    );
    assert_eq!(gpu::read_texture(&ctx, &texture), bytes);
}

#[test]
fn read_float_textures_decodes_texels() {
    let ctx = GpuContext::for_tests();
    let texels: Vec<[f32; 4]> = (0..9 * 3)
        .map(|i| [i as f32, -0.5, 0.25 * i as f32, 1.0])
        .collect();
    let texture = texture_with(
        &ctx,
        wgpu::TextureFormat::Rgba32Float,
        [9, 3],
        bytemuck::cast_slice(&texels),
    );
    assert_eq!(gpu::read_texture_rgba32f(&ctx, &texture), texels);
    let halves: Vec<[half::f16; 4]> = texels.iter().map(|t| t.map(half::f16::from_f32)).collect();
    let texture = texture_with(
        &ctx,
        wgpu::TextureFormat::Rgba16Float,
        [9, 3],
        bytemuck::cast_slice(&halves),
    );
    // Every value above is exact in f16.
    assert_eq!(gpu::read_texture_rgba16f(&ctx, &texture), texels);
}

const DOUBLE_SHADER: &str = "
@group(0) @binding(0) var<storage, read_write> values: array<u32>;
@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x < arrayLength(&values) { values[id.x] = 2u * values[id.x]; }
}";

#[test]
fn timed_compute_pass_runs_and_reads_back() {
    let ctx = GpuContext::for_tests();
    let input: Vec<u32> = (0..100).collect();
    let buffer = buffer_with(&ctx, &input, wgpu::BufferUsages::STORAGE);
    let module = ctx
        .device
        .create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("double"),
            source: wgpu::ShaderSource::Wgsl(DOUBLE_SHADER.into()),
        });
    let pipeline = ctx
        .device
        .create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("double"),
            layout: None,
            module: &module,
            entry_point: Some("main"),
            compilation_options: Default::default(),
            cache: None,
        });
    let bind_group = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("double"),
        layout: &pipeline.get_bind_group_layout(0),
        entries: &[wgpu::BindGroupEntry {
            binding: 0,
            resource: buffer.as_entire_binding(),
        }],
    });
    let mut timer = PassTimer::new(&ctx, 2);
    for _frame in 0..2 {
        timer.reset();
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("double"),
                timestamp_writes: timer.compute_pass_writes("double"),
            });
            pass.set_pipeline(&pipeline);
            pass.set_bind_group(0, &bind_group, &[]);
            pass.dispatch_workgroups(2, 1, 1);
        }
        timer.resolve(&mut encoder);
        ctx.queue.submit([encoder.finish()]);
        let times = timer.read_ms(&ctx);
        if ctx.has_timestamps() {
            assert_eq!(times.len(), 1, "one timed pass per frame after reset");
            assert_eq!(times[0].0, "double");
            assert!(times[0].1.is_finite() && times[0].1 >= 0.0);
        } else {
            assert!(times.is_empty());
        }
    }
    let expected: Vec<u32> = input.iter().map(|v| 4 * v).collect();
    assert_eq!(gpu::read_buffer::<u32>(&ctx, &buffer), expected);
}

#[test]
fn timer_beyond_capacity_leaves_passes_untimed() {
    let ctx = GpuContext::for_tests();
    let mut timer = PassTimer::new(&ctx, 1);
    let first = timer.compute_pass_writes("first").is_some();
    assert_eq!(first, ctx.has_timestamps());
    assert!(timer.compute_pass_writes("second").is_none());
}

const SAMPLE_SHADER: &str = "
@group(0) @binding(0) var grid: texture_3d<f32>;
@group(0) @binding(1) var linear_clamp: sampler;
@group(0) @binding(2) var<storage, read> points: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read_write> samples: array<f32>;
@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x < arrayLength(&points) {
        samples[id.x] = textureSampleLevel(grid, linear_clamp, points[id.x].xyz, 0.0).r;
    }
}";

/// `VoxelGrid::sample` claims to be what a `ClampToEdge` + `Linear` sampler returns: check it.
#[test]
fn voxel_sample_matches_the_gpu_sampler() {
    let ctx = GpuContext::for_tests();
    let (min, max) = (Vec3::ZERO, Vec3::new(5.0, 4.0, 3.0));
    // Values exact in f16, so the R16Float texture holds exactly the grid.
    let quantize = |v: f32| half::f16::from_f32(v).to_f32();
    let grid = VoxelGrid::from_fn([5, 4, 3], min, max, |p| {
        quantize((p.x * 0.7 + p.y * p.z * 0.3).sin())
    });
    let texture = ctx.device.create_texture_with_data(
        &ctx.queue,
        &wgpu::TextureDescriptor {
            label: Some("voxel grid"),
            size: wgpu::Extent3d {
                width: 5,
                height: 4,
                depth_or_array_layers: 3,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D3,
            format: wgpu::TextureFormat::R16Float,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        },
        wgpu::util::TextureDataOrder::LayerMajor,
        bytemuck::cast_slice(
            &grid
                .values
                .iter()
                .map(|&v| half::f16::from_f32(v))
                .collect::<Vec<_>>(),
        ),
    );
    let points: Vec<[f32; 4]> = (0..200)
        .map(|i| {
            let t = i as f32;
            [
                (t * 0.618).fract() * 1.4 - 0.2,
                (t * 0.414).fract() * 1.4 - 0.2,
                (t * 0.732).fract() * 1.4 - 0.2,
                0.0,
            ]
        })
        .collect();
    let samples = run_sample_shader(&ctx, &texture, &points);
    for (point, gpu_value) in points.iter().zip(samples) {
        let cpu_value = grid.sample(Vec3::new(point[0], point[1], point[2]));
        // Vulkan guarantees only 4 bits of sub-texel precision, an error of up to 1/32 of a
        // neighbour step (< 0.05 here); sampling half a texel off would err by about 0.3.
        assert!(
            (cpu_value - gpu_value).abs() < 0.07,
            "{point:?}: CPU {cpu_value}, GPU {gpu_value}"
        );
    }
}

fn run_sample_shader(ctx: &GpuContext, texture: &wgpu::Texture, points: &[[f32; 4]]) -> Vec<f32> {
    let module = ctx
        .device
        .create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("sample grid"),
            source: wgpu::ShaderSource::Wgsl(SAMPLE_SHADER.into()),
        });
    let pipeline = ctx
        .device
        .create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("sample grid"),
            layout: None,
            module: &module,
            entry_point: Some("main"),
            compilation_options: Default::default(),
            cache: None,
        });
    let sampler = ctx.device.create_sampler(&wgpu::SamplerDescriptor {
        mag_filter: wgpu::FilterMode::Linear,
        min_filter: wgpu::FilterMode::Linear,
        ..Default::default()
    });
    let point_buffer = ctx
        .device
        .create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("points"),
            contents: bytemuck::cast_slice(points),
            usage: wgpu::BufferUsages::STORAGE,
        });
    let sample_buffer = buffer_with(ctx, &vec![0; points.len()], wgpu::BufferUsages::STORAGE);
    let view = texture.create_view(&Default::default());
    let bind_group = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("sample grid"),
        layout: &pipeline.get_bind_group_layout(0),
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::TextureView(&view),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: wgpu::BindingResource::Sampler(&sampler),
            },
            wgpu::BindGroupEntry {
                binding: 2,
                resource: point_buffer.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 3,
                resource: sample_buffer.as_entire_binding(),
            },
        ],
    });
    let mut encoder = ctx.device.create_command_encoder(&Default::default());
    {
        let mut pass = encoder.begin_compute_pass(&Default::default());
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &bind_group, &[]);
        pass.dispatch_workgroups(points.len().div_ceil(64) as u32, 1, 1);
    }
    ctx.queue.submit([encoder.finish()]);
    gpu::read_buffer::<f32>(ctx, &sample_buffer)
}

#[test]
fn a_shared_texture_is_made_once_per_key() {
    let ctx = GpuContext::for_tests();
    let made = std::cell::Cell::new(0);
    let make = || {
        made.set(made.get() + 1);
        texture_with(&ctx, wgpu::TextureFormat::R8Unorm, [1, 1], &[7])
    };
    let first = ctx.shared_texture(("shared texture test", 1), make);
    let again = ctx.shared_texture(("shared texture test", 1), make);
    let other = ctx.shared_texture(("shared texture test", 2), make);
    assert_eq!(made.get(), 2, "one texture per key");
    assert!(first == again, "the same key gives the texture made before");
    assert!(first != other, "another key gives another texture");
}
