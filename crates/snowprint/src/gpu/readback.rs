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
    let total: u64 = ranges.iter().map(|r| r.1).sum();
    if total == 0 {
        return Ok(Vec::new());
    }
    let staging = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("readback"),
        size: total,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut enc = device.create_command_encoder(&Default::default());
    let mut at = 0;
    for &(offset, size) in ranges {
        enc.copy_buffer_to_buffer(source, offset, &staging, at, size);
        at += size;
    }
    queue.submit([enc.finish()]);
    map_read(device, &staging, 0, total)
}
