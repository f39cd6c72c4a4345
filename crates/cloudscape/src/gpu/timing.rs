//! GPU time per compute or render pass, from timestamp queries written at the start and end of each pass.
//!
//! Use per frame: [`PassTimer::reset`], then [`PassTimer::compute_pass_writes`] for each pass to
//! time (pass the result to [`wgpu::ComputePassDescriptor::timestamp_writes`]), then
//! [`PassTimer::resolve`] on the frame's last encoder, submit, and [`PassTimer::read_ms`] (which
//! waits). A real-time host calls [`PassTimer::resolve_late`] instead and reads the newest finished
//! frame's times with [`PassTimer::latest_ms`], which never waits.
//!
//! On adapters without [`wgpu::Features::TIMESTAMP_QUERY`] (e.g. GL) nothing is timed and
//! [`PassTimer::read_ms`] returns an empty list. On software adapters (lavapipe, llvmpipe) the
//! numbers are the CPU time of the emulated GPU work: use them to compare passes with each other,
//! not as a GPU budget, and never in an assertion.

use std::collections::VecDeque;

use super::late_readback::LateReadback;
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
    /// Copies of the ticks read a frame late, and the labels of each frame copied, oldest first.
    late: LateReadback,
    late_labels: VecDeque<(u64, Vec<String>)>,
}

impl PassTimer {
    /// A timer for up to `capacity_passes` passes per frame.
    pub fn new(ctx: &GpuContext, capacity_passes: u32) -> PassTimer {
        let bytes = 2 * u64::from(capacity_passes) * TIMESTAMP_BYTES;
        let queries = (ctx.has_timestamps() && capacity_passes > 0).then(|| Queries {
            set: ctx.device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("pass timer queries"),
                ty: wgpu::QueryType::Timestamp,
                count: 2 * capacity_passes,
            }),
            resolved: ctx.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("pass timer resolved ticks"),
                size: bytes,
                usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            }),
            late: LateReadback::new(ctx, "pass timer ticks", bytes),
            late_labels: VecDeque::new(),
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

    /// Like [`PassTimer::resolve`], and copies the ticks out to be read without waiting by
    /// [`PassTimer::latest_ms`] once the GPU has run the frame.
    pub fn resolve_late(&mut self, encoder: &mut wgpu::CommandEncoder) {
        self.resolve(encoder);
        let Some(queries) = self.queries.as_mut().filter(|_| !self.labels.is_empty()) else {
            return;
        };
        if let Some(frame) = queries.late.copy(encoder, &queries.resolved) {
            let labels = &mut queries.late_labels;
            labels.push_back((frame, self.labels.clone()));
            // The readback holds a few frames in flight; older labels can no longer be read.
            while labels.len() > 8 {
                labels.pop_front();
            }
        }
    }

    /// Milliseconds each pass took in the newest frame resolved by [`PassTimer::resolve_late`]
    /// that the GPU has finished; never waits. None before the first is ready, and without
    /// timestamp queries.
    pub fn latest_ms(&mut self, ctx: &GpuContext) -> Option<Vec<(String, f64)>> {
        let queries = self.queries.as_mut()?;
        let (frame, bytes) = queries.late.latest_numbered(ctx)?;
        let (_, labels) = queries.late_labels.iter().find(|(f, _)| *f == frame)?;
        let ticks: Vec<u64> = bytemuck::pod_collect_to_vec(bytes);
        Some(pass_times(ctx, labels, &ticks))
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
        pass_times(ctx, &self.labels, &ticks)
    }
}

/// Each label with the milliseconds between its pair of `ticks` (start, end).
fn pass_times(ctx: &GpuContext, labels: &[String], ticks: &[u64]) -> Vec<(String, f64)> {
    let ns_per_tick = f64::from(ctx.queue.get_timestamp_period());
    labels
        .iter()
        .zip(ticks.chunks_exact(2))
        .map(|(label, pair)| {
            let elapsed_ticks = pair[1].saturating_sub(pair[0]);
            (label.clone(), elapsed_ticks as f64 * ns_per_tick * 1e-6)
        })
        .collect()
}

/// The writes of query pair `index`: its beginning and end timestamps.
fn pass_writes(set: &wgpu::QuerySet, index: u32) -> wgpu::ComputePassTimestampWrites<'_> {
    wgpu::ComputePassTimestampWrites {
        query_set: set,
        beginning_of_pass_write_index: Some(2 * index),
        end_of_pass_write_index: Some(2 * index + 1),
    }
}
