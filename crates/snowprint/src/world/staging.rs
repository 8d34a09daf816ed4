//! Staging memory the world maps itself, for a split plan's primitives: each run's primitives are
//! copied into their own view of a mapped buffer by the thread that gathers the run
//! (`world/plan/parallel.rs`), where `queue.write_buffer_with`'s memory takes one thread (its
//! `WriteOnly` is not `Send`; a `BufferViewMut` of a mapped range is). The frame's encoder then
//! copies the buffer into the primitives buffer. The buffers are kept in a small ring: one a frame
//! used is mapped again once the frame is submitted or abandoned, and is free once the GPU is done
//! with it.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use super::plan::{Opened, PrimsTarget};
use crate::gpu::resources::Growable;

/// Buffers the ring keeps at most: with more frames in flight, a frame's primitives are written
/// from the parts on one thread.
const RING_MAX: usize = 3;

/// Fewest bytes of primitives a frame copies through the ring: below it, a view a run and the
/// buffer's unmapping and mapping again cost more than the copy they spread. On the H100's host,
/// 256 surfaces of 10 spheres (0.2 MB of primitives) took 0.21 to 0.29 ms through the ring against
/// 0.20 to 0.26 copied on one thread, 1024 (0.8 MB) 0.51 to 0.70 either way, 4096 (3.3 MB) 1.63 to
/// 2.00 against 1.91 to 2.08 (`docs/PERFORMANCE.md`, "Plan threads kept between frames").
pub(crate) const RING_FROM: usize = 512 << 10;

/// One staging buffer and whether it is mapped and free.
struct Staging {
    buffer: wgpu::Buffer,
    /// Set by the buffer's map callback, cleared while a frame holds it.
    free: Arc<AtomicBool>,
}

/// The world's staging buffers for a split plan's primitives.
#[derive(Default)]
pub(crate) struct StagingRing {
    buffers: Vec<Staging>,
    /// The buffer the frame being encoded fills (`open`), then copies from (`record_copy`).
    held: Option<usize>,
    /// Whether the held buffer was unmapped and its copy recorded.
    copied: bool,
}

impl StagingRing {
    /// A free mapped buffer of at least `bytes`, held for this frame: a free one large enough, else
    /// a new one in place of a free one too small or beside the others while the ring has room.
    /// `None` when none is free and the ring is full (a poll first gives back those the GPU is done
    /// with), or the device cannot make one that large.
    fn hold(&mut self, device: &wgpu::Device, bytes: u64) -> Option<usize> {
        let free = |s: &Staging| s.free.load(Ordering::Acquire);
        let mut fits = self
            .buffers
            .iter()
            .position(|s| free(s) && s.buffer.size() >= bytes);
        if fits.is_none() && !self.buffers.iter().any(free) {
            // Map callbacks run when the device is polled; nothing here waits.
            let _ = device.poll(wgpu::PollType::Poll);
            fits = (self.buffers.iter()).position(|s| free(s) && s.buffer.size() >= bytes);
        }
        let i = match fits {
            Some(i) => i,
            None => {
                let limits = device.limits();
                if bytes > limits.max_buffer_size {
                    return None;
                }
                let staging = Staging {
                    buffer: device.create_buffer(&wgpu::BufferDescriptor {
                        label: Some("primitives staging"),
                        size: bytes.next_power_of_two().min(limits.max_buffer_size),
                        usage: wgpu::BufferUsages::MAP_WRITE | wgpu::BufferUsages::COPY_SRC,
                        mapped_at_creation: true,
                    }),
                    free: Arc::new(AtomicBool::new(true)),
                };
                match self.buffers.iter().position(free) {
                    Some(small) => {
                        self.buffers[small] = staging;
                        small
                    }
                    None if self.buffers.len() < RING_MAX => {
                        self.buffers.push(staging);
                        self.buffers.len() - 1
                    }
                    None => return None,
                }
            }
        };
        self.buffers[i].free.store(false, Ordering::Release);
        self.held = Some(i);
        self.copied = false;
        Some(i)
    }

    /// Views of a held buffer for runs of `lens` bytes laid end to end (`None` for an empty run).
    /// `None`, the buffer given back, when a view cannot be made.
    fn views(&mut self, i: usize, lens: &[usize]) -> Option<Vec<Option<wgpu::BufferViewMut>>> {
        let buffer = &self.buffers[i].buffer;
        let mut at = 0u64;
        let mut views = Vec::with_capacity(lens.len());
        for &len in lens {
            let end = at + len as u64;
            views.push(match len {
                0 => None,
                _ => match buffer.get_mapped_range_mut(at..end) {
                    Ok(view) => Some(view),
                    Err(_) => {
                        drop(views);
                        self.cancel();
                        return None;
                    }
                },
            });
            at = end;
        }
        Some(views)
    }

    /// The held buffer was not used after all (the frame was refused once planned): it is still
    /// mapped, and free again.
    pub(crate) fn cancel(&mut self) {
        if let Some(i) = self.held.take()
            && !self.copied
        {
            self.buffers[i].free.store(true, Ordering::Release);
        }
    }

    /// Unmap the held buffer (every view of it dropped: the plan is built) and record the copy of
    /// its first `bytes` into `target` in `enc`.
    pub(crate) fn record_copy(
        &mut self,
        enc: &mut wgpu::CommandEncoder,
        target: &wgpu::Buffer,
        bytes: u64,
    ) {
        if let Some(i) = self.held.filter(|_| !self.copied) {
            let buffer = &self.buffers[i].buffer;
            buffer.unmap();
            enc.copy_buffer_to_buffer(buffer, 0, target, 0, bytes);
            self.copied = true;
        }
    }

    /// The frame that held a buffer was submitted or abandoned: map it again, free once the GPU is
    /// done with it (its map callback).
    pub(crate) fn release(&mut self) {
        match self.held.take() {
            Some(i) if self.copied => {
                let free = self.buffers[i].free.clone();
                let slice = self.buffers[i].buffer.slice(..);
                slice.map_async(wgpu::MapMode::Write, move |r| {
                    free.store(r.is_ok(), Ordering::Release)
                });
                self.copied = false;
            }
            Some(i) => self.buffers[i].free.store(true, Ordering::Release),
            None => {}
        }
    }
}

/// Where a split plan's primitives go (its [`PrimsTarget`]): a frame of [`RING_FROM`] bytes of
/// them or more into a buffer of the ring, a view a run; a smaller one into the staging memory of
/// one `queue.write_buffer_with` into the primitives buffer, grown to them, which the calling
/// thread fills (it lands at the next submission, as `queue.write_buffer`'s would).
pub(crate) struct RingTarget<'w> {
    pub device: &'w wgpu::Device,
    pub queue: &'w wgpu::Queue,
    pub ring: &'w mut StagingRing,
    pub prims: &'w mut Growable,
    /// The queue's staging memory, while the plan fills it.
    pub view: Option<wgpu::QueueWriteBufferView>,
}

impl PrimsTarget for RingTarget<'_> {
    type Piece = wgpu::BufferViewMut;

    fn open(&mut self, lens: &[usize]) -> Option<Opened<'_, Self::Piece>> {
        let bytes = lens.iter().sum::<usize>() as u64;
        let size = wgpu::BufferSize::new(bytes)?;
        // More than the device binds: the world refuses the frame once it is planned
        // (`check_sizes`), and nothing is written.
        let limits = self.device.limits();
        if bytes
            > limits
                .max_storage_buffer_binding_size
                .min(limits.max_buffer_size)
        {
            return None;
        }
        if bytes >= RING_FROM as u64 {
            let i = self.ring.hold(self.device, bytes)?;
            return self.ring.views(i, lens).map(Opened::Pieces);
        }
        self.prims.ensure(self.device, bytes);
        self.view = self.queue.write_buffer_with(&self.prims.buffer, 0, size);
        self.view.as_mut().map(|v| Opened::Whole(v.slice(..)))
    }
}
