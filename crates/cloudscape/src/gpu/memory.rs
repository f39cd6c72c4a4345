//! What wgpu reports of a device's memory and live objects: the figures a long-running host
//! watches for leaks (`cloudscape bench --soak`).

/// GPU memory and live wgpu objects at one moment.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct GpuMemoryReport {
    /// Bytes in live allocations (`wgpu::Device::generate_allocator_report`); `None` where the
    /// backend has no sub-allocator to ask (GL, Metal).
    pub allocated_bytes: Option<u64>,
    /// Bytes of the memory blocks those allocations come from.
    pub reserved_bytes: Option<u64>,
    /// Live resources the application holds (buffers, textures, views, samplers, bind groups and
    /// their layouts, shader modules, pipelines, query sets), counted by wgpu-core
    /// (`wgpu::Instance::generate_report`); `None` for a host's device, whose instance is not ours.
    pub live_objects: Option<usize>,
}

impl GpuMemoryReport {
    /// The report of `device`, with the objects of `instance` when given.
    pub(super) fn new(device: &wgpu::Device, instance: Option<&wgpu::Instance>) -> Self {
        let allocator = device.generate_allocator_report();
        GpuMemoryReport {
            allocated_bytes: allocator.as_ref().map(|a| a.total_allocated_bytes),
            reserved_bytes: allocator.as_ref().map(|a| a.total_reserved_bytes),
            live_objects: instance
                .and_then(wgpu::Instance::generate_report)
                .map(|report| live_objects(&report.hub)),
        }
    }
}

/// The resources of `hub` the application still holds.
fn live_objects(hub: &wgpu::wgc::hub::HubReport) -> usize {
    [
        &hub.buffers,
        &hub.textures,
        &hub.texture_views,
        &hub.samplers,
        &hub.bind_groups,
        &hub.bind_group_layouts,
        &hub.pipeline_layouts,
        &hub.shader_modules,
        &hub.render_pipelines,
        &hub.compute_pipelines,
        &hub.query_sets,
    ]
    .iter()
    .map(|registry| registry.num_kept_from_user)
    .sum()
}
