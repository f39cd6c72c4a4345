//! One compute pass that fills one of the environment's tables: the shape every atmosphere table
//! pass and the cloud shadow map share.

use super::{EnvironmentGpu, EnvironmentTable};
use crate::gpu::{GpuContext, PassTimer};
use crate::pass::{BindGroupCache, ComputePass, Shared};
use crate::shader::WgslModule;
use glam::UVec2;

/// A pipeline writing `table` through its output views (its group's bindings, in binding order),
/// with its bind group, remade whenever the environment remakes its tables.
pub struct TablePass {
    label: &'static str,
    table: EnvironmentTable,
    pass: ComputePass,
    group: BindGroupCache,
}

impl TablePass {
    /// The pass `label` running `entry` of program `root`, writing `table`.
    pub fn new(
        ctx: &GpuContext,
        shared: &Shared,
        (root, entry): (&'static WgslModule, &'static str),
        (label, table): (&'static str, EnvironmentTable),
    ) -> TablePass {
        TablePass {
            label,
            table,
            pass: ComputePass::new(ctx, shared, label, root, &[entry]),
            group: BindGroupCache::default(),
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
        (shared, environment): (&Shared, &EnvironmentGpu),
        size: UVec2,
        timer: Option<&mut PassTimer>,
    ) {
        let views = environment.output_views(self.table);
        let pass = &self.pass;
        let group = self.group.get(&views.iter().collect::<Vec<_>>(), || {
            let resources: Vec<_> = pass
                .group
                .names()
                .zip(views.iter().map(wgpu::BindingResource::TextureView))
                .collect();
            pass.group.bind(ctx, &resources)
        });
        let writing = environment.bind_group_writing(self.table);
        let groups = shared.bind_groups_with(pass.slots, writing, group);
        let writes = timer.and_then(|t| t.compute_pass_writes(self.label));
        crate::gpu::pipeline::dispatch_2d(encoder, self.label, pass.main(), &groups, size, writes);
    }
}
