//! Getting GPU results back to the CPU: buffer readbacks for the inspection calls, and the
//! per-pass timestamp queries (slots `2i` and `2i + 1` of [`PASSES`](super::PASSES) entry `i`).

use super::error::{RenderError, RenderResult};
use super::graph::PASSES;

/// Copy `size` bytes of a buffer at `offset` back to the CPU (waits for the GPU).
pub(super) fn read_back(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    buffer: &wgpu::Buffer,
    offset: u64,
    size: u64,
) -> RenderResult<Vec<u8>> {
    let size = size.div_ceil(4) * 4;
    if size == 0 {
        return Ok(Vec::new());
    }
    let staging = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("render readback"),
        size,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut encoder = device.create_command_encoder(&Default::default());
    encoder.copy_buffer_to_buffer(buffer, offset, &staging, 0, size);
    queue.submit([encoder.finish()]);
    map_staging(device, &staging)
}

/// Map a staging buffer whose copy has been submitted, and take its bytes (waits for the GPU).
pub(super) fn map_staging(device: &wgpu::Device, staging: &wgpu::Buffer) -> RenderResult<Vec<u8>> {
    let slice = staging.slice(..);
    let (tx, rx) = std::sync::mpsc::channel();
    slice.map_async(wgpu::MapMode::Read, move |r| {
        let _ = tx.send(r);
    });
    device
        .poll(wgpu::PollType::wait_indefinitely())
        .map_err(|e| RenderError::Readback(e.to_string()))?;
    rx.recv()
        .map_err(|e| RenderError::Readback(e.to_string()))?
        .map_err(|e| RenderError::Readback(e.to_string()))?;
    let data = slice
        .get_mapped_range()
        .map_err(|e| RenderError::Readback(format!("{e:?}")))?
        .to_vec();
    staging.unmap();
    Ok(data)
}

/// A half float's value.
pub(super) fn f16_to_f32(h: u16) -> f32 {
    let sign = if h & 0x8000 != 0 { -1.0 } else { 1.0 };
    let exp = ((h >> 10) & 0x1f) as i32;
    let frac = (h & 0x3ff) as f32;
    sign * match exp {
        0 => frac * 2f32.powi(-24),
        31 => f32::INFINITY,
        _ => (1.0 + frac / 1024.0) * 2f32.powi(exp - 15),
    }
}

/// Timestamp queries of the frame's passes, two per entry of [`PASSES`].
pub(super) struct Timestamps {
    pub set: wgpu::QuerySet,
    pub resolve: wgpu::Buffer,
    pub period_ns: f32,
}

impl Timestamps {
    pub fn new(device: &wgpu::Device, queue: &wgpu::Queue) -> Self {
        let count = 2 * PASSES.len() as u32;
        Self {
            set: device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("render pass timestamps"),
                ty: wgpu::QueryType::Timestamp,
                count,
            }),
            resolve: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("render timestamp resolve"),
                size: count as u64 * 8,
                usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            }),
            period_ns: queue.get_timestamp_period(),
        }
    }
}

/// The timestamp writes of a pass's render passes: `begin` and `end` say whether this render
/// pass opens or closes the pass's span (a pass of several render passes spans them all).
pub(super) fn render_span(
    ts: Option<&Timestamps>,
    slot: usize,
    begin: bool,
    end: bool,
) -> Option<wgpu::RenderPassTimestampWrites<'_>> {
    ts.map(|t| wgpu::RenderPassTimestampWrites {
        query_set: &t.set,
        beginning_of_pass_write_index: begin.then_some(2 * slot as u32),
        end_of_pass_write_index: end.then_some(2 * slot as u32 + 1),
    })
}

/// The timestamp writes of a pass that is one render pass.
pub(super) fn render_writes(
    ts: Option<&Timestamps>,
    slot: usize,
) -> Option<wgpu::RenderPassTimestampWrites<'_>> {
    render_span(ts, slot, true, true)
}

/// The timestamp writes of a pass that is one compute pass.
pub(super) fn compute_writes(
    ts: Option<&Timestamps>,
    slot: usize,
) -> Option<wgpu::ComputePassTimestampWrites<'_>> {
    ts.map(|t| wgpu::ComputePassTimestampWrites {
        query_set: &t.set,
        beginning_of_pass_write_index: Some(2 * slot as u32),
        end_of_pass_write_index: Some(2 * slot as u32 + 1),
    })
}
