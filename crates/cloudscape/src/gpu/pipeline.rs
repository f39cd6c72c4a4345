//! Small builders for compute and raster pipelines, bind group layouts and bind groups, so each
//! pass states only what it binds.

use super::GpuContext;

/// A 2D texture of `size` pixels, one mip level, one sample.
pub fn texture_2d(
    ctx: &GpuContext,
    label: &str,
    size: glam::UVec2,
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
) -> wgpu::Texture {
    ctx.device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d {
            width: size.x,
            height: size.y,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage,
        view_formats: &[],
    })
}

/// Usage of a compute pass's output that later passes read and the CPU may read back.
pub const STORAGE_OUTPUT: wgpu::TextureUsages = wgpu::TextureUsages::STORAGE_BINDING
    .union(wgpu::TextureUsages::TEXTURE_BINDING)
    .union(wgpu::TextureUsages::COPY_SRC);

/// A uniform buffer of `size` bytes that the queue rewrites each frame.
pub fn uniform_buffer(ctx: &GpuContext, label: &str, size: u64) -> wgpu::Buffer {
    ctx.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size,
        usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

/// A storage buffer of `size` bytes, zeroed, that passes read and write and that can be copied
/// to and from.
pub fn storage_buffer(ctx: &GpuContext, label: &str, size: u64) -> wgpu::Buffer {
    ctx.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size,
        usage: wgpu::BufferUsages::STORAGE
            | wgpu::BufferUsages::COPY_DST
            | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    })
}

/// A storage buffer binding, read-only or read-write.
pub const fn storage_binding(read_only: bool) -> wgpu::BindingType {
    wgpu::BindingType::Buffer {
        ty: wgpu::BufferBindingType::Storage { read_only },
        has_dynamic_offset: false,
        min_binding_size: None,
    }
}

/// A uniform buffer binding.
pub const UNIFORM: wgpu::BindingType = wgpu::BindingType::Buffer {
    ty: wgpu::BufferBindingType::Uniform,
    has_dynamic_offset: false,
    min_binding_size: None,
};

/// An unfilterable 2D float texture binding: depth buffers read as values (GLSL cannot load from
/// depth samplers) and R32Float, which GL cannot filter.
pub const UNFILTERABLE_TEXTURE_2D: wgpu::BindingType = wgpu::BindingType::Texture {
    sample_type: wgpu::TextureSampleType::Float { filterable: false },
    view_dimension: wgpu::TextureViewDimension::D2,
    multisampled: false,
};

/// A filterable float texture binding of the given dimension.
pub fn float_texture(dimension: wgpu::TextureViewDimension) -> wgpu::BindingType {
    wgpu::BindingType::Texture {
        sample_type: wgpu::TextureSampleType::Float { filterable: true },
        view_dimension: dimension,
        multisampled: false,
    }
}

/// A write-only 2D storage texture binding.
pub fn storage_texture_2d(format: wgpu::TextureFormat) -> wgpu::BindingType {
    storage_texture(format, wgpu::TextureViewDimension::D2)
}

/// A write-only storage texture binding of the given dimension.
pub fn storage_texture(
    format: wgpu::TextureFormat,
    view_dimension: wgpu::TextureViewDimension,
) -> wgpu::BindingType {
    wgpu::BindingType::StorageTexture {
        access: wgpu::StorageTextureAccess::WriteOnly,
        format,
        view_dimension,
    }
}

/// A bind group layout whose binding `i` has type `types[i]`: read-only bindings are visible to
/// compute, vertex and fragment stages, writable storage to compute (vertex stages cannot write
/// storage without a native feature).
pub fn bind_group_layout(
    device: &wgpu::Device,
    label: &str,
    types: &[wgpu::BindingType],
) -> wgpu::BindGroupLayout {
    let entries: Vec<_> = types
        .iter()
        .enumerate()
        .map(|(i, ty)| wgpu::BindGroupLayoutEntry {
            binding: i as u32,
            visibility: visibility(ty),
            ty: *ty,
            count: None,
        })
        .collect();
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some(label),
        entries: &entries,
    })
}

fn visibility(ty: &wgpu::BindingType) -> wgpu::ShaderStages {
    let writable = match ty {
        wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only },
            ..
        } => !read_only,
        wgpu::BindingType::StorageTexture { .. } => true,
        _ => false,
    };
    if writable {
        wgpu::ShaderStages::COMPUTE
    } else {
        wgpu::ShaderStages::COMPUTE | wgpu::ShaderStages::VERTEX | wgpu::ShaderStages::FRAGMENT
    }
}

/// A bind group whose binding `i` is `resources[i]`.
pub fn bind_group(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    resources: &[wgpu::BindingResource],
) -> wgpu::BindGroup {
    let entries: Vec<_> = resources
        .iter()
        .enumerate()
        .map(|(i, r)| wgpu::BindGroupEntry {
            binding: i as u32,
            resource: r.clone(),
        })
        .collect();
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout,
        entries: &entries,
    })
}

/// Bind group layouts of a pipeline by slot (group `i` = `layouts[i]`); None for a slot the
/// program binds nothing at.
pub type GroupLayouts<'a> = [Option<&'a wgpu::BindGroupLayout>];

/// The shader module of a whole WGSL program ([`crate::shader::Program`]).
pub fn shader_module(ctx: &GpuContext, label: &str, source: &str) -> wgpu::ShaderModule {
    ctx.device
        .create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some(label),
            source: wgpu::ShaderSource::Wgsl(source.into()),
        })
}

fn pipeline_layout(ctx: &GpuContext, label: &str, layouts: &GroupLayouts) -> wgpu::PipelineLayout {
    ctx.device
        .create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some(label),
            bind_group_layouts: layouts,
            immediate_size: 0,
        })
}

/// A compute pipeline from WGSL source with explicit bind group layouts.
pub fn compute_pipeline(
    ctx: &GpuContext,
    label: &str,
    source: &str,
    entry: &str,
    layouts: &GroupLayouts,
) -> wgpu::ComputePipeline {
    let module = shader_module(ctx, label, source);
    ctx.device
        .create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some(label),
            layout: Some(&pipeline_layout(ctx, label, layouts)),
            module: &module,
            entry_point: Some(entry),
            compilation_options: Default::default(),
            cache: None,
        })
}

/// A depth test against a host's depth buffer that never writes it (the attachment is read-only,
/// so the same buffer can be bound as a texture elsewhere in the frame).
#[derive(Clone, Copy, Debug)]
pub struct DepthTest {
    /// Format of the depth attachment.
    pub format: wgpu::TextureFormat,
    /// Which fragments pass: [`crate::frame::DepthConvention::compare`] keeps nearer ones.
    pub compare: wgpu::CompareFunction,
}

/// What a raster pipeline draws: entry points, colour targets (format and blending) and an optional
/// read-only depth test. Vertices come from the vertex shader (storage buffers, vertex index): no
/// vertex buffers.
pub struct RasterDescriptor<'a> {
    /// Pipeline label.
    pub label: &'a str,
    /// Vertex and fragment entry points.
    pub entries: (&'a str, &'a str),
    /// Colour targets, e.g. premultiplied-alpha blending into a cloud output.
    pub targets: &'a [Option<wgpu::ColorTargetState>],
    /// Depth test, or None to draw everything.
    pub depth: Option<DepthTest>,
    /// Primitive topology.
    pub topology: wgpu::PrimitiveTopology,
}

/// A render pipeline beside [`compute_pipeline`]: the same bind group slots, no vertex buffers.
pub fn render_pipeline(
    ctx: &GpuContext,
    raster: &RasterDescriptor,
    source: &str,
    layouts: &GroupLayouts,
) -> wgpu::RenderPipeline {
    let module = shader_module(ctx, raster.label, source);
    let depth_stencil = raster.depth.map(|d| wgpu::DepthStencilState {
        format: d.format,
        depth_write_enabled: Some(false),
        depth_compare: Some(d.compare),
        stencil: Default::default(),
        bias: Default::default(),
    });
    ctx.device
        .create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some(raster.label),
            layout: Some(&pipeline_layout(ctx, raster.label, layouts)),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some(raster.entries.0),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: wgpu::PrimitiveState {
                topology: raster.topology,
                ..Default::default()
            },
            depth_stencil,
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some(raster.entries.1),
                compilation_options: Default::default(),
                targets: raster.targets,
            }),
            multiview_mask: None,
            cache: None,
        })
}

/// Premultiplied-alpha "over" blending of colour and alpha: `dst = src + (1 - src.a) dst`.
pub const PREMULTIPLIED_OVER: wgpu::BlendState = wgpu::BlendState::PREMULTIPLIED_ALPHA_BLENDING;

/// A render pass into `color` (loaded or cleared), testing against `depth` read-only.
pub fn begin_render_pass<'e>(
    encoder: &'e mut wgpu::CommandEncoder,
    label: &str,
    (color, load): (&wgpu::TextureView, wgpu::LoadOp<wgpu::Color>),
    depth: Option<&wgpu::TextureView>,
    timestamps: Option<wgpu::RenderPassTimestampWrites>,
) -> wgpu::RenderPass<'e> {
    encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some(label),
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view: color,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations {
                load,
                store: wgpu::StoreOp::Store,
            },
        })],
        depth_stencil_attachment: depth.map(|view| wgpu::RenderPassDepthStencilAttachment {
            view,
            depth_ops: None,
            stencil_ops: None,
        }),
        timestamp_writes: timestamps,
        ..Default::default()
    })
}

/// Records the clearing of depth buffer `view` to `depth` (a host's empty depth: the convention's
/// far value).
pub fn clear_depth(encoder: &mut wgpu::CommandEncoder, view: &wgpu::TextureView, depth: f32) {
    encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some("clear depth"),
        color_attachments: &[],
        depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
            view,
            depth_ops: Some(wgpu::Operations {
                load: wgpu::LoadOp::Clear(depth),
                store: wgpu::StoreOp::Store,
            }),
            stencil_ops: None,
        }),
        ..Default::default()
    });
}

/// Records one compute pass over `size` pixels in 8x8 workgroups.
pub fn dispatch_2d(
    encoder: &mut wgpu::CommandEncoder,
    label: &str,
    pipeline: &wgpu::ComputePipeline,
    groups: &[Option<&wgpu::BindGroup>],
    size: glam::UVec2,
    timestamps: Option<wgpu::ComputePassTimestampWrites>,
) {
    dispatch_2d_repeated(encoder, label, pipeline, groups, (size, 1), timestamps);
}

/// [`dispatch_2d`] `times` times in one pass; each dispatch sees the storage writes of the one
/// before (wgpu orders dispatches that share a read-write resource).
pub fn dispatch_2d_repeated(
    encoder: &mut wgpu::CommandEncoder,
    label: &str,
    pipeline: &wgpu::ComputePipeline,
    groups: &[Option<&wgpu::BindGroup>],
    (size, times): (glam::UVec2, u32),
    timestamps: Option<wgpu::ComputePassTimestampWrites>,
) {
    let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
        label: Some(label),
        timestamp_writes: timestamps,
    });
    pass.set_pipeline(pipeline);
    for (i, g) in groups.iter().enumerate() {
        if let Some(g) = g {
            pass.set_bind_group(i as u32, *g, &[]);
        }
    }
    for _ in 0..times {
        pass.dispatch_workgroups(size.x.div_ceil(8), size.y.div_ceil(8), 1);
    }
}
