//! One compute pass that fills one of the environment's tables: the shape every atmosphere table
//! pass and the cloud shadow map share.

use super::{EnvironmentTable, TABLE_FORMAT};
use crate::frame::{Shared, SharedSlots};
use crate::gpu::pipeline::{bind_group, bind_group_layout, compute_pipeline, storage_texture};
use crate::gpu::{GpuContext, PassTimer};
use glam::UVec2;

/// A pipeline writing `table` through its output views (group 3, binding order), with its bind
/// group, remade whenever the environment remakes its tables.
pub struct TablePass {
    label: &'static str,
    table: EnvironmentTable,
    slots: SharedSlots,
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    group: Option<(u64, wgpu::BindGroup)>,
}

impl TablePass {
    /// The pass `label` running `entry` of `program`, writing `table` through storage views of
    /// `outputs` dimensions.
    pub fn new(
        ctx: &GpuContext,
        shared: &Shared,
        (program, entry): (&str, &str),
        (label, table): (&'static str, EnvironmentTable),
        outputs: &[wgpu::TextureViewDimension],
    ) -> TablePass {
        let types: Vec<_> = outputs
            .iter()
            .map(|d| storage_texture(TABLE_FORMAT, *d))
            .collect();
        let layout = bind_group_layout(&ctx.device, label, &types);
        let slots = SharedSlots::of(program);
        let pipeline = compute_pipeline(
            ctx,
            label,
            &crate::shader::program(program),
            entry,
            &shared.layouts(slots, &layout),
        );
        TablePass {
            label,
            table,
            slots,
            pipeline,
            layout,
            group: None,
        }
    }

    /// The label the pass is timed under.
    pub fn label(&self) -> &'static str {
        self.label
    }

    /// Records the pass over `size` invocations (8 x 8 per workgroup).
    pub fn encode(
        &mut self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        shared: &Shared,
        size: UVec2,
        timer: Option<&mut PassTimer>,
    ) {
        let environment = shared.environment;
        let generation = environment.generation();
        if self.group.as_ref().is_none_or(|(g, _)| *g != generation) {
            let views = environment.output_views(self.table);
            let resources: Vec<_> = views
                .iter()
                .map(wgpu::BindingResource::TextureView)
                .collect();
            let group = bind_group(&ctx.device, &self.layout, &resources);
            self.group = Some((generation, group));
        }
        let (_, group) = self.group.as_ref().expect("made above");
        let writing = environment.bind_group_writing(self.table);
        let groups = shared.bind_groups_with(self.slots, writing, group);
        let writes = timer.and_then(|t| t.compute_pass_writes(self.label));
        crate::gpu::pipeline::dispatch_2d(
            encoder,
            self.label,
            &self.pipeline,
            &groups,
            size,
            writes,
        );
    }
}
