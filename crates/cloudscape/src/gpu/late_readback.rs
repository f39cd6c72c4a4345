//! Reading small GPU results back without waiting for the GPU: statistics arrive a frame late.

use super::GpuContext;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

/// Staging buffers in flight: the GPU may still be on one frame while the host records the next.
const SLOTS: usize = 3;

#[derive(Debug)]
struct Slot {
    buffer: wgpu::Buffer,
    /// Set by the map callback once the copy can be read.
    mapped: Arc<AtomicBool>,
    /// Frame number of the copy in this slot; None when the slot is free.
    frame: Option<u64>,
}

/// Copies of one storage buffer, one per frame, mapped when the frame's work is submitted
/// (`map_buffer_on_submit`) and read whenever they are ready: [`LateReadback::latest`] never blocks,
/// and returns the newest finished frame's copy.
#[derive(Debug)]
pub struct LateReadback {
    slots: Vec<Slot>,
    frames: u64,
    /// The newest finished copy (allocated once, at the first).
    latest: Vec<u8>,
    /// The frame number of `latest`; 0 before the first is ready.
    latest_frame: u64,
}

impl LateReadback {
    /// Readback of a buffer of `size` bytes.
    pub fn new(ctx: &GpuContext, label: &str, size: u64) -> LateReadback {
        let slots = (0..SLOTS)
            .map(|_| Slot {
                buffer: ctx.device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some(label),
                    size,
                    usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                }),
                mapped: Arc::new(AtomicBool::new(false)),
                frame: None,
            })
            .collect();
        LateReadback {
            slots,
            frames: 0,
            latest: Vec::new(),
            latest_frame: 0,
        }
    }

    /// Records a copy of `source` into a free slot, to be mapped when `encoder` is submitted, and
    /// returns its frame number (counting from 1, one per call). Skips the frame, returning None,
    /// when every slot is still in flight (the GPU is three frames behind).
    pub fn copy(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        source: &wgpu::Buffer,
    ) -> Option<u64> {
        self.frames += 1;
        let frame = self.frames;
        let slot = self.slots.iter_mut().find(|s| s.frame.is_none())?;
        encoder.copy_buffer_to_buffer(source, 0, &slot.buffer, 0, slot.buffer.size());
        let mapped = slot.mapped.clone();
        encoder.map_buffer_on_submit(&slot.buffer, wgpu::MapMode::Read, .., move |result| {
            mapped.store(result.is_ok(), Ordering::Release);
        });
        slot.frame = Some(frame);
        Some(frame)
    }

    /// The newest copy the GPU has finished, without waiting (None before the first is ready).
    pub fn latest(&mut self, ctx: &GpuContext) -> Option<&[u8]> {
        self.latest_numbered(ctx).map(|(_, bytes)| bytes)
    }

    /// Like [`LateReadback::latest`], with the copy's frame number (as [`LateReadback::copy`]
    /// returned it).
    pub fn latest_numbered(&mut self, ctx: &GpuContext) -> Option<(u64, &[u8])> {
        // Non-blocking: runs the callbacks of work that has finished.
        let _ = ctx.device.poll(wgpu::PollType::Poll);
        let mut newest = self.latest_frame;
        for slot in &mut self.slots {
            let Some(frame) = slot.frame else { continue };
            if !slot.mapped.swap(false, Ordering::Acquire) {
                continue;
            }
            if frame > newest {
                newest = frame;
                if let Ok(view) = slot.buffer.slice(..).get_mapped_range() {
                    self.latest.clear();
                    self.latest.extend_from_slice(&view);
                    self.latest_frame = frame;
                }
            }
            slot.buffer.unmap();
            slot.frame = None;
        }
        (self.latest_frame > 0).then_some((self.latest_frame, self.latest.as_slice()))
    }
}
