//! The coarse field read at many points on the GPU (`field_read.wgsl`): the twin of
//! [`super::CpuCoarseReader`], one dispatch for all the points, waited for.

use glam::{Vec3, Vec4};
use wgpu::util::DeviceExt;

use super::CoarseFieldReader;
use crate::gpu::pipeline::storage_buffer;
use crate::gpu::{GpuContext, readback};
use crate::pass::{ComputePass, Shared};

/// Points one dispatch reads at most (16 bytes each in, 4 out).
const READ_CHUNK: usize = 1 << 22;
/// Invocations per workgroup of `read_coarse_extinction`.
const WORKGROUP: u32 = 64;
/// Workgroups along x at most (the device limit every adapter has).
const MAX_GROUPS_X: u32 = 65_535;

/// The pass that reads the coarse field, built against the shared groups' layouts.
pub struct FieldReadPass {
    pass: ComputePass,
}

impl FieldReadPass {
    /// Builds the pipeline.
    pub fn new(ctx: &GpuContext, shared: &Shared) -> FieldReadPass {
        FieldReadPass {
            pass: ComputePass::new(
                ctx,
                shared,
                "field read",
                &FIELD_READ_WGSL,
                &["read_coarse_extinction"],
            ),
        }
    }

    /// The reader of the field in `shared` (at the time its group was last set to).
    pub fn reader<'a>(&'a self, ctx: &'a GpuContext, shared: Shared<'a>) -> GpuCoarseReader<'a> {
        GpuCoarseReader {
            ctx,
            pass: self,
            shared,
        }
    }

    /// `field_extinction_coarse` at each of `points_m` (at most [`READ_CHUNK`]).
    fn read(&self, ctx: &GpuContext, shared: &Shared, points_m: &[Vec3]) -> Vec<f32> {
        let padded: Vec<Vec4> = points_m.iter().map(|p| p.extend(0.0)).collect();
        let points = ctx
            .device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("field read points"),
                contents: bytemuck::cast_slice(&padded),
                usage: wgpu::BufferUsages::STORAGE,
            });
        let extinctions = storage_buffer(ctx, "field read extinctions", 4 * padded.len() as u64);
        let group = self.pass.group.bind(
            ctx,
            &[
                ("read_points", points.as_entire_binding()),
                ("read_extinctions", extinctions.as_entire_binding()),
            ],
        );
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            pass.set_pipeline(self.pass.main());
            let groups = shared.bind_groups(self.pass.slots, &group);
            for (slot, g) in groups.iter().enumerate() {
                if let Some(g) = g {
                    pass.set_bind_group(slot as u32, *g, &[]);
                }
            }
            let workgroups = (padded.len() as u32).div_ceil(WORKGROUP);
            let x = workgroups.min(MAX_GROUPS_X);
            pass.dispatch_workgroups(x, workgroups.div_ceil(x), 1);
        }
        ctx.queue.submit([encoder.finish()]);
        readback::read_buffer::<f32>(ctx, &extinctions)
    }
}

/// The GPU's coarse field read through [`FieldReadPass`], at the time the shared field group was
/// last set to (the frame's).
#[derive(Clone, Copy)]
pub struct GpuCoarseReader<'a> {
    ctx: &'a GpuContext,
    pass: &'a FieldReadPass,
    shared: Shared<'a>,
}

impl CoarseFieldReader for GpuCoarseReader<'_> {
    fn coarse_extinctions_per_m(&self, points_m: &[Vec3]) -> Vec<f32> {
        if points_m.is_empty() {
            return Vec::new();
        }
        points_m
            .chunks(READ_CHUNK)
            .flat_map(|chunk| self.pass.read(self.ctx, &self.shared, chunk))
            .collect()
    }
}

/// The field-read pass (`field_read.wgsl`).
pub static FIELD_READ_WGSL: crate::shader::WgslModule =
    crate::shader::wgsl_module!("field_read", "field_read.wgsl", [&super::gpu::FIELD_WGSL]);
