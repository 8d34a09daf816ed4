//! Per-stage GPU times that never wait for the GPU: each measured frame resolves its timestamps
//! into one of a few readback buffers, which is mapped with `map_async` after the frame's
//! submission and read when a later frame finds it mapped (`PollType::Poll`, which does not
//! block). The times of a frame therefore arrive a frame or two after it; while every buffer is
//! still on its way, a frame is not measured.

use std::sync::Arc;
use std::sync::atomic::{AtomicU8, Ordering};

use super::timestamps::{StageQueries, Timestamps};
use crate::error::{Result, SnowError};

/// Readback buffers in the ring: one being recorded, one or two on their way back.
pub(crate) const RING_SLOTS: usize = 3;

const IDLE: u8 = 0;
/// Recorded into an encoder, not yet submitted.
const RECORDED: u8 = 1;
const MAPPING: u8 = 2;
const READY: u8 = 3;
const FAILED: u8 = 4;

struct Slot {
    buffer: wgpu::Buffer,
    state: Arc<AtomicU8>,
    /// The measured passes' stages, in query order.
    stages: Vec<&'static str>,
    /// The world's number of the frame measured.
    frame: u64,
}

/// A measured frame's number, and each measured pass's stage and GPU milliseconds in order.
pub(crate) type MeasuredFrame = (u64, Vec<(&'static str, f64)>);

/// A query set and a ring of readback buffers.
pub(crate) struct TimestampRing {
    timestamps: Timestamps,
    slots: Vec<Slot>,
}

impl TimestampRing {
    /// A ring for frames of up to `capacity` timestamps.
    pub fn new(device: &wgpu::Device, queue: &wgpu::Queue, label: &str, capacity: u32) -> Self {
        let slots = (0..RING_SLOTS)
            .map(|_| Slot {
                buffer: device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some(label),
                    size: capacity as u64 * 8,
                    usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                }),
                state: Arc::new(AtomicU8::new(IDLE)),
                stages: Vec::new(),
                frame: 0,
            })
            .collect();
        Self {
            timestamps: Timestamps::new(device, queue, label, capacity),
            slots,
        }
    }

    /// The query set the frame's passes write.
    pub fn timestamps(&self) -> &Timestamps {
        &self.timestamps
    }

    /// A slot free to measure a frame into, if any.
    pub fn free_slot(&self) -> Option<usize> {
        self.slots
            .iter()
            .position(|s| s.state.load(Ordering::Acquire) == IDLE)
    }

    /// Record the resolve of `queries` into slot `slot`, last in the frame's encoder (nothing
    /// when nothing was measured). [`TimestampRing::arm`] then keeps the frame's stages.
    pub fn resolve(
        &self,
        slot: usize,
        queries: &StageQueries<'_>,
        encoder: &mut wgpu::CommandEncoder,
    ) {
        queries.resolve_to(encoder, &self.slots[slot].buffer);
    }

    /// Slot `slot` holds frame `frame`'s measured `stages` once its encoder is submitted.
    pub fn arm(&mut self, slot: usize, frame: u64, stages: &[&'static str]) {
        let s = &mut self.slots[slot];
        s.stages.clear();
        s.stages.extend_from_slice(stages);
        s.frame = frame;
        s.state.store(RECORDED, Ordering::Release);
    }

    /// The frame recorded into `slot` was submitted: start mapping its buffer.
    pub fn submitted(&mut self, slot: usize) {
        let s = &self.slots[slot];
        if s.state.load(Ordering::Acquire) != RECORDED {
            return;
        }
        s.state.store(MAPPING, Ordering::Release);
        let state = s.state.clone();
        s.buffer
            .slice(..s.stages.len() as u64 * 16)
            .map_async(wgpu::MapMode::Read, move |r| {
                let done = if r.is_ok() { READY } else { FAILED };
                state.store(done, Ordering::Release);
            });
    }

    /// The frame recorded into `slot` will never be submitted: free the slot.
    pub fn abandon(&mut self, slot: usize) {
        let s = &self.slots[slot];
        if s.state.load(Ordering::Acquire) == RECORDED {
            s.state.store(IDLE, Ordering::Release);
        }
    }

    /// The oldest measured frame whose times have arrived: its number and each measured pass's
    /// stage and GPU milliseconds. Checks without waiting (`PollType::Poll`).
    pub fn poll(&mut self, device: &wgpu::Device) -> Result<Option<MeasuredFrame>> {
        let busy = |s: &Slot| matches!(s.state.load(Ordering::Acquire), MAPPING | READY | FAILED);
        if !self.slots.iter().any(busy) {
            return Ok(None);
        }
        device
            .poll(wgpu::PollType::Poll)
            .map_err(|e| SnowError::Readback(e.to_string()))?;
        let arrived = self
            .slots
            .iter()
            .enumerate()
            .filter(|(_, s)| matches!(s.state.load(Ordering::Acquire), READY | FAILED))
            .min_by_key(|(_, s)| s.frame)
            .map(|(i, _)| i);
        let Some(i) = arrived else {
            return Ok(None);
        };
        let s = &self.slots[i];
        if s.state.load(Ordering::Acquire) == FAILED {
            s.state.store(IDLE, Ordering::Release);
            return Err(SnowError::Readback(format!(
                "mapping the GPU times of frame {} failed",
                s.frame
            )));
        }
        let times = {
            let data = s
                .buffer
                .slice(..s.stages.len() as u64 * 16)
                .get_mapped_range()
                .map_err(|e| SnowError::Readback(format!("{e:?}")))?;
            let period = self.timestamps.period_ns() as f64;
            s.stages
                .iter()
                .enumerate()
                .map(|(k, &stage)| {
                    // Read by value: a mapped range promises no alignment.
                    let tick = |q: usize| {
                        let mut b = [0u8; 8];
                        b.copy_from_slice(&data[8 * q..8 * q + 8]);
                        u64::from_le_bytes(b)
                    };
                    let ticks = tick(2 * k + 1).saturating_sub(tick(2 * k));
                    (stage, ticks as f64 * period * 1e-6)
                })
                .collect()
        };
        s.buffer.unmap();
        s.state.store(IDLE, Ordering::Release);
        Ok(Some((s.frame, times)))
    }
}
