//! Reading GPU buffers back to the CPU: the one copy of "copy to staging, map, wait" that the
//! world's readbacks (and the renderer's) share, with the project's errors.

use crate::error::{Result, SnowError};

/// Map a range of a `MAP_READ` buffer and copy it out, waiting for the GPU; the buffer is unmapped
/// again before this returns.
pub fn map_read(
    device: &wgpu::Device,
    buffer: &wgpu::Buffer,
    offset: u64,
    size: u64,
) -> Result<Vec<u8>> {
    let slice = buffer.slice(offset..offset + size);
    let (tx, rx) = std::sync::mpsc::channel();
    slice.map_async(wgpu::MapMode::Read, move |r| {
        let _ = tx.send(r);
    });
    device.poll(wgpu::PollType::wait_indefinitely())?;
    rx.recv()
        .map_err(|e| SnowError::Readback(e.to_string()))??;
    let data = slice.get_mapped_range()?.to_vec();
    buffer.unmap();
    Ok(data)
}

/// Copy `size` bytes of any `COPY_SRC` buffer from `offset` to the CPU through a staging buffer
/// made for the purpose (readbacks are for tests, tools and paging, not for every frame).
pub fn download(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    source: &wgpu::Buffer,
    offset: u64,
    size: u64,
) -> Result<Vec<u8>> {
    download_ranges(device, queue, source, &[(offset, size)])
}

/// Copy several ranges `(offset, size)` of a buffer to the CPU in one GPU round trip, one after
/// the other in the returned bytes.
pub fn download_ranges(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    source: &wgpu::Buffer,
    ranges: &[(u64, u64)],
) -> Result<Vec<u8>> {
    let mut enc = device.create_command_encoder(&Default::default());
    let Some(read) = RangeRead::record(device, &mut enc, source, ranges) else {
        return Ok(Vec::new());
    };
    queue.submit([enc.finish()]);
    read.submitted();
    read.wait(device)
}

const MAP_PENDING: u8 = 0;
const MAP_DONE: u8 = 1;
const MAP_FAILED: u8 = 2;
const NOT_SUBMITTED: u8 = 3;

/// Ranges of a buffer copied, in a caller's encoder, into a staging buffer of their own: mapped
/// once the encoder is reported submitted, and read when the mapping has completed, checked
/// without waiting ([`RangeRead::try_take`]) or waited for ([`RangeRead::wait`]).
#[derive(Debug)]
pub struct RangeRead {
    staging: wgpu::Buffer,
    total: u64,
    state: std::sync::Arc<std::sync::atomic::AtomicU8>,
}

impl RangeRead {
    /// Record the copy of `ranges` of `source` (`COPY_SRC`) into `enc`; `None` when they hold no
    /// byte.
    pub fn record(
        device: &wgpu::Device,
        enc: &mut wgpu::CommandEncoder,
        source: &wgpu::Buffer,
        ranges: &[(u64, u64)],
    ) -> Option<Self> {
        let total: u64 = ranges.iter().map(|r| r.1).sum();
        if total == 0 {
            return None;
        }
        let staging = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("readback"),
            size: total,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut at = 0;
        for &(offset, size) in ranges {
            enc.copy_buffer_to_buffer(source, offset, &staging, at, size);
            at += size;
        }
        Some(Self {
            staging,
            total,
            state: std::sync::Arc::new(std::sync::atomic::AtomicU8::new(NOT_SUBMITTED)),
        })
    }

    /// The encoder was submitted: start mapping (once).
    pub fn submitted(&self) {
        use std::sync::atomic::Ordering;
        if self
            .state
            .compare_exchange(
                NOT_SUBMITTED,
                MAP_PENDING,
                Ordering::AcqRel,
                Ordering::Acquire,
            )
            .is_err()
        {
            return;
        }
        let flag = self.state.clone();
        self.staging
            .slice(..)
            .map_async(wgpu::MapMode::Read, move |r| {
                flag.store(
                    if r.is_ok() { MAP_DONE } else { MAP_FAILED },
                    Ordering::Release,
                );
            });
    }

    /// Whether the bytes have arrived (or failed to); the device must have been polled since.
    pub fn is_ready(&self) -> bool {
        let s = self.state.load(std::sync::atomic::Ordering::Acquire);
        s == MAP_DONE || s == MAP_FAILED
    }

    /// The bytes, if they have arrived; never waits (poll the device first).
    pub fn try_take(&self) -> Option<Result<Vec<u8>>> {
        if !self.is_ready() {
            return None;
        }
        Some(self.bytes())
    }

    /// The bytes, waiting for the GPU (the encoder must have been submitted).
    pub fn wait(self, device: &wgpu::Device) -> Result<Vec<u8>> {
        self.submitted();
        while !self.is_ready() {
            device.poll(wgpu::PollType::wait_indefinitely())?;
        }
        self.bytes()
    }

    /// The bytes, waiting for the GPU, left mapped so that [`RangeRead::try_take`] or
    /// [`RangeRead::wait`] still give them (for readers that cannot take them).
    pub fn peek(&self, device: &wgpu::Device) -> Result<Vec<u8>> {
        self.submitted();
        while !self.is_ready() {
            device.poll(wgpu::PollType::wait_indefinitely())?;
        }
        if self.state.load(std::sync::atomic::Ordering::Acquire) != MAP_DONE {
            return Err(SnowError::Readback(
                "a readback buffer could not be mapped".into(),
            ));
        }
        Ok(self
            .staging
            .slice(..self.total)
            .get_mapped_range()?
            .to_vec())
    }

    fn bytes(&self) -> Result<Vec<u8>> {
        if self.state.load(std::sync::atomic::Ordering::Acquire) != MAP_DONE {
            return Err(SnowError::Readback(
                "a readback buffer could not be mapped".into(),
            ));
        }
        let slice = self.staging.slice(..self.total);
        let data = slice.get_mapped_range()?.to_vec();
        self.staging.unmap();
        Ok(data)
    }
}
