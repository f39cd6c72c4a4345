//! A uniform struct in a bind group of its own: the shape of the frame and environment groups
//! that every program binds at the same slot.

use super::GpuContext;
use super::pipeline::{UNIFORM, bind_group, bind_group_layout, uniform_buffer};
use bytemuck::Pod;
use std::marker::PhantomData;

/// One uniform buffer holding a `T`, and the bind group (binding 0) that binds it; both made once,
/// the buffer rewritten as often as needed.
pub struct UniformGroup<T> {
    buffer: wgpu::Buffer,
    layout: wgpu::BindGroupLayout,
    bind_group: wgpu::BindGroup,
    uniform: PhantomData<T>,
}

impl<T: Pod> UniformGroup<T> {
    /// Makes the buffer (zeroed) and the bind group.
    pub fn new(ctx: &GpuContext, label: &str) -> UniformGroup<T> {
        let buffer = uniform_buffer(ctx, label, size_of::<T>() as u64);
        let layout = bind_group_layout(&ctx.device, label, &[UNIFORM]);
        let bind_group = bind_group(&ctx.device, &layout, &[buffer.as_entire_binding()]);
        UniformGroup {
            buffer,
            layout,
            bind_group,
            uniform: PhantomData,
        }
    }

    /// Uploads `value` for the next submitted work.
    pub fn write(&self, ctx: &GpuContext, value: &T) {
        ctx.queue
            .write_buffer(&self.buffer, 0, bytemuck::bytes_of(value));
    }

    /// The bind group layout, for pipeline layouts.
    pub fn layout(&self) -> &wgpu::BindGroupLayout {
        &self.layout
    }

    /// The bind group.
    pub fn bind_group(&self) -> &wgpu::BindGroup {
        &self.bind_group
    }
}
