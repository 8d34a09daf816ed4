//! Getting GPU results back to the CPU: buffer readbacks for the inspection calls, and the
//! per-pass timestamp queries (slots `2i` and `2i + 1` of [`PASSES`](super::PASSES) entry `i`).

use super::error::{RenderError, RenderResult};
use super::graph::PASSES;
use crate::gpu::{readback, timestamps};

/// Copy `size` bytes of a buffer at `offset` back to the CPU (waits for the GPU), through the
/// library's one readback path (`gpu::readback`), `size` rounded up to whole words.
pub(super) fn read_back(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    buffer: &wgpu::Buffer,
    offset: u64,
    size: u64,
) -> RenderResult<Vec<u8>> {
    readback::download(device, queue, buffer, offset, size.div_ceil(4) * 4).map_err(readback_error)
}

/// Map a staging buffer whose copy has been submitted, and take its bytes (waits for the GPU).
pub(super) fn map_staging(device: &wgpu::Device, staging: &wgpu::Buffer) -> RenderResult<Vec<u8>> {
    readback::map_read(device, staging, 0, staging.size()).map_err(readback_error)
}

fn readback_error(e: crate::SnowError) -> RenderError {
    match e {
        crate::SnowError::Readback(reason) => RenderError::Readback(reason),
        crate::SnowError::Poll(e) => RenderError::Poll(e),
        crate::SnowError::BufferMap(e) => RenderError::BufferMap(e),
        crate::SnowError::MapRange(e) => RenderError::MapRange(e),
        other => RenderError::Readback(other.to_string()),
    }
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

/// Timestamp queries of the frame's passes, two per entry of [`PASSES`] (the library's one query
/// set type, `gpu::timestamps`, with the renderer placing its writes at fixed slots).
pub(super) type Timestamps = timestamps::Timestamps;

/// The renderer's query set: two timestamps per entry of [`PASSES`].
pub(super) fn new_timestamps(device: &wgpu::Device, queue: &wgpu::Queue) -> Timestamps {
    Timestamps::new(
        device,
        queue,
        "render pass timestamps",
        2 * PASSES.len() as u32,
    )
}

/// The timestamp writes of a pass's render passes: `begin` and `end` say whether this render
/// pass opens or closes the pass's span (a pass of several render passes spans them all; one in
/// the middle writes none).
pub(super) fn render_span(
    ts: Option<&Timestamps>,
    slot: usize,
    begin: bool,
    end: bool,
) -> Option<wgpu::RenderPassTimestampWrites<'_>> {
    ts.filter(|_| begin || end)
        .map(|t| wgpu::RenderPassTimestampWrites {
            query_set: t.query_set(),
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

/// Begin pass `slot` of [`PASSES`] as one compute pass, labelled and timed from the table.
pub(super) fn compute_pass<'e>(
    encoder: &'e mut wgpu::CommandEncoder,
    ts: Option<&Timestamps>,
    slot: usize,
) -> wgpu::ComputePass<'e> {
    encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
        label: Some(PASSES[slot].name),
        timestamp_writes: compute_writes(ts, slot),
    })
}

/// The timestamp writes of a pass that is one compute pass.
pub(super) fn compute_writes(
    ts: Option<&Timestamps>,
    slot: usize,
) -> Option<wgpu::ComputePassTimestampWrites<'_>> {
    ts.map(|t| wgpu::ComputePassTimestampWrites {
        query_set: t.query_set(),
        beginning_of_pass_write_index: Some(2 * slot as u32),
        end_of_pass_write_index: Some(2 * slot as u32 + 1),
    })
}
