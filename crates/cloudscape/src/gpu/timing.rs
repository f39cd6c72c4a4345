//! GPU time per compute or render pass, from timestamp queries written at the start and end of each pass.
//!
//! Use per frame: [`PassTimer::reset`], then [`PassTimer::compute_pass_writes`] for each pass to
//! time (pass the result to [`wgpu::ComputePassDescriptor::timestamp_writes`]), then
//! [`PassTimer::resolve`] on the frame's last encoder, submit, and [`PassTimer::read_ms`].
//!
//! On adapters without [`wgpu::Features::TIMESTAMP_QUERY`] (e.g. GL) nothing is timed and
//! [`PassTimer::read_ms`] returns an empty list. On software adapters (lavapipe, llvmpipe) the
//! numbers are the CPU time of the emulated GPU work: use them to compare passes with each other,
//! not as a GPU budget, and never in an assertion.

use super::{GpuContext, readback};

/// Bytes of one resolved timestamp.
const TIMESTAMP_BYTES: u64 = size_of::<u64>() as u64;

/// Start and end timestamps for up to `capacity` labelled passes per frame.
#[derive(Debug)]
pub struct PassTimer {
    /// `None` when the device cannot write timestamps.
    queries: Option<Queries>,
    labels: Vec<String>,
    capacity: u32,
}

#[derive(Debug)]
struct Queries {
    set: wgpu::QuerySet,
    /// Where [`PassTimer::resolve`] writes the raw ticks; read back with [`readback::read_buffer`].
    resolved: wgpu::Buffer,
}

impl PassTimer {
    /// A timer for up to `capacity_passes` passes per frame.
    pub fn new(ctx: &GpuContext, capacity_passes: u32) -> PassTimer {
        let queries = (ctx.has_timestamps() && capacity_passes > 0).then(|| Queries {
            set: ctx.device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("pass timer queries"),
                ty: wgpu::QueryType::Timestamp,
                count: 2 * capacity_passes,
            }),
            resolved: ctx.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("pass timer resolved ticks"),
                size: 2 * u64::from(capacity_passes) * TIMESTAMP_BYTES,
                usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            }),
        });
        PassTimer {
            queries,
            labels: Vec::new(),
            capacity: capacity_passes,
        }
    }

    /// Forgets the passes of the previous frame; call at the start of every frame.
    pub fn reset(&mut self) {
        self.labels.clear();
    }

    /// Timestamp writes for the next compute pass, recorded under `label`; None when the adapter
    /// lacks timestamps or the timer is full.
    pub fn compute_pass_writes(
        &mut self,
        label: &str,
    ) -> Option<wgpu::ComputePassTimestampWrites<'_>> {
        let index = self.reserve(label)?;
        self.queries.as_ref().map(|q| pass_writes(&q.set, index))
    }

    /// Timestamp writes for the next render pass, recorded under `label`: raster passes (sprites,
    /// particle splats) are timed like compute passes.
    pub fn render_pass_writes(
        &mut self,
        label: &str,
    ) -> Option<wgpu::RenderPassTimestampWrites<'_>> {
        let index = self.reserve(label)?;
        self.queries.as_ref().map(|q| {
            let c = pass_writes(&q.set, index);
            wgpu::RenderPassTimestampWrites {
                query_set: c.query_set,
                beginning_of_pass_write_index: c.beginning_of_pass_write_index,
                end_of_pass_write_index: c.end_of_pass_write_index,
            }
        })
    }

    /// Claims the next pair of query slots for `label`.
    fn reserve(&mut self, label: &str) -> Option<u32> {
        self.queries.as_ref()?;
        let index = u32::try_from(self.labels.len())
            .ok()
            .filter(|&i| i < self.capacity)?;
        self.labels.push(label.to_string());
        Some(index)
    }

    /// Copies this frame's timestamps into the readback buffer; encode after the last timed pass.
    pub fn resolve(&self, encoder: &mut wgpu::CommandEncoder) {
        let Some(queries) = &self.queries else {
            return;
        };
        if !self.labels.is_empty() {
            let count = 2 * self.labels.len() as u32;
            encoder.resolve_query_set(&queries.set, 0..count, &queries.resolved, 0);
        }
    }

    /// Milliseconds each pass of this frame took, in the order the passes were added.
    ///
    /// Call after the encoder holding [`PassTimer::resolve`] was submitted; blocks until it ran.
    /// Ticks become nanoseconds through [`wgpu::Queue::get_timestamp_period`].
    pub fn read_ms(&self, ctx: &GpuContext) -> Vec<(String, f64)> {
        let Some(queries) = &self.queries else {
            return Vec::new();
        };
        if self.labels.is_empty() {
            return Vec::new();
        }
        let ticks: Vec<u64> = readback::read_buffer(ctx, &queries.resolved);
        let ns_per_tick = f64::from(ctx.queue.get_timestamp_period());
        self.labels
            .iter()
            .zip(ticks.chunks_exact(2))
            .map(|(label, pair)| {
                let elapsed_ticks = pair[1].saturating_sub(pair[0]);
                (label.clone(), elapsed_ticks as f64 * ns_per_tick * 1e-6)
            })
            .collect()
    }
}

/// The writes of query pair `index`: its beginning and end timestamps.
fn pass_writes(set: &wgpu::QuerySet, index: u32) -> wgpu::ComputePassTimestampWrites<'_> {
    wgpu::ComputePassTimestampWrites {
        query_set: set,
        beginning_of_pass_write_index: Some(2 * index),
        end_of_pass_write_index: Some(2 * index + 1),
    }
}
