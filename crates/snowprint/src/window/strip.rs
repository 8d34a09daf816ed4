//! The strip pass (`strip.wgsl`): a scroll's leaving rectangles gathered from the pool into a
//! buffer read back to the CPU, its entering ones scattered from a buffer into the pool, both
//! through the pool's toroidal mapping; the bytes the scatter writes are counted on the GPU.

use crate::error::Result;
use crate::gpu::readback::RangeRead;
use crate::gpu::resources::{Growable, UNIFORM_STRIDE, bind_group, uniform_block};
use crate::pool::Precision;

/// One rectangle of a dispatch. Must match `StripParams` in `strip.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct StripParams {
    /// Word offset of the level's heights region in the pool.
    pub heights: u32,
    /// The level's texels along x.
    pub width: u32,
    /// The level's texels along z.
    pub height: u32,
    /// Its toroidal offsets while the strip moves, packed.
    pub wrap: u32,
    /// The logical rectangle: first column.
    pub x0: u32,
    /// First row.
    pub y0: u32,
    /// Columns.
    pub columns: u32,
    /// Rows.
    pub rows: u32,
    /// Texel of the strip buffer where the rectangle starts.
    pub first: u32,
    /// Pool bytes a unit's store writes.
    pub unit_bytes: u32,
    /// Padding.
    pub _pad: [u32; 2],
}

/// Which way a dispatch moves texels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Direction {
    /// From the pool into the out strip buffer (a leaving rectangle).
    Out,
    /// From the in strip buffer into the pool (an entering rectangle).
    In,
    /// The in strip buffer folded into the pool by the larger of each channel (a finer level's
    /// leaving strip, summed up at this level's texels).
    Max,
}

/// The pass's pipelines and buffers (one set a terrain).
pub struct StripGpu {
    out: wgpu::ComputePipeline,
    into: wgpu::ComputePipeline,
    max: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    params: Growable,
    strip_out: Growable,
    strip_in: Growable,
    written: wgpu::Buffer,
    precision: Precision,
}

/// A scroll's recorded strips: the leaving texels and the written-bytes counter, read once the
/// encoder has run.
#[derive(Debug)]
pub struct StripRead {
    leaving: Option<RangeRead>,
    written: Option<RangeRead>,
}

impl StripRead {
    /// The encoder was submitted: start mapping.
    pub fn submitted(&self) {
        for r in [&self.leaving, &self.written].into_iter().flatten() {
            r.submitted();
        }
    }

    /// Whether everything has arrived (the device must have been polled since submitting).
    pub fn is_ready(&self) -> bool {
        [&self.leaving, &self.written]
            .into_iter()
            .flatten()
            .all(RangeRead::is_ready)
    }

    /// `(leaving texels as (depression, displaced) word pairs, pool bytes written)`, waiting for
    /// the GPU (after the encoder was submitted).
    pub fn wait(self, device: &wgpu::Device) -> Result<(Vec<u32>, u64)> {
        let leaving = match self.leaving {
            Some(r) => bytemuck::cast_slice(&r.wait(device)?).to_vec(),
            None => Vec::new(),
        };
        let written = match self.written {
            Some(r) => {
                let b = r.wait(device)?;
                u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as u64
            }
            None => 0,
        };
        Ok((leaving, written))
    }
}

impl StripGpu {
    /// Compile the pass for a pool of `precision`.
    pub fn new(device: &wgpu::Device, precision: Precision) -> Self {
        let shader = &crate::wgsl::WINDOW_STRIP;
        let layout = shader.bind_group_layout(device, "window strip", 0);
        let constants = [("PRECISION", precision.bits() as f64)];
        let [out, into, max] = shader.compute_pipelines(
            device,
            ["strip_out", "strip_in", "strip_max"],
            &layout,
            &constants,
        );
        use wgpu::BufferUsages as U;
        Self {
            out,
            into,
            max,
            layout,
            params: Growable::new(
                device,
                "strip params",
                U::UNIFORM | U::COPY_DST,
                UNIFORM_STRIDE * 8,
            ),
            strip_out: Growable::new(device, "strip out", U::STORAGE | U::COPY_SRC, 4096),
            strip_in: Growable::new(device, "strip in", U::STORAGE | U::COPY_DST, 4096),
            written: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("strip bytes written"),
                size: 16,
                usage: U::STORAGE | U::COPY_SRC | U::COPY_DST,
                mapped_at_creation: false,
            }),
            precision,
        }
    }

    /// Pool bytes one store of the scatter writes: a word at 8 bits (two texels) and 16, two
    /// words (one in each plane) at 32.
    pub fn unit_bytes(&self) -> u32 {
        match self.precision {
            Precision::Bits32 => 8,
            _ => 4,
        }
    }

    /// Record `dispatches` in order (each a rectangle and its direction; `params[i].first` set by
    /// the caller), the entering texels `incoming` (word pairs, in the order of the `In` and `Max`
    /// rectangles) uploaded first, and the readback of the leaving texels and of the counter.
    pub fn encode(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        enc: &mut wgpu::CommandEncoder,
        pool: &wgpu::Buffer,
        dispatches: &[(Direction, StripParams)],
        incoming: &[u32],
    ) -> StripRead {
        let texels = |d: Direction| -> u64 {
            dispatches
                .iter()
                .filter(|x| x.0 == d)
                .map(|x| x.1.columns as u64 * x.1.rows as u64)
                .sum()
        };
        let (out_texels, in_texels) = (
            texels(Direction::Out),
            texels(Direction::In) + texels(Direction::Max),
        );
        self.params
            .ensure(device, dispatches.len().max(1) as u64 * UNIFORM_STRIDE);
        self.strip_out.ensure(device, out_texels.max(1) * 8);
        self.strip_in.ensure(device, in_texels.max(1) * 8);
        let mut blocks = vec![0u8; dispatches.len() * UNIFORM_STRIDE as usize];
        for (i, (_, p)) in dispatches.iter().enumerate() {
            let at = i * UNIFORM_STRIDE as usize;
            blocks[at..at + std::mem::size_of::<StripParams>()]
                .copy_from_slice(bytemuck::bytes_of(p));
        }
        if !blocks.is_empty() {
            queue.write_buffer(&self.params.buffer, 0, &blocks);
        }
        if !incoming.is_empty() {
            queue.write_buffer(&self.strip_in.buffer, 0, bytemuck::cast_slice(incoming));
        }
        enc.clear_buffer(&self.written, 0, None);
        let unit = self.precision.unit_texels();
        for (i, (dir, p)) in dispatches.iter().enumerate() {
            let strip = match dir {
                Direction::Out => &self.strip_out.buffer,
                Direction::In | Direction::Max => &self.strip_in.buffer,
            };
            let bg = bind_group(
                device,
                "window strip",
                &self.layout,
                &[
                    pool.as_entire_binding(),
                    uniform_block(&self.params.buffer, i, std::mem::size_of::<StripParams>()),
                    strip.as_entire_binding(),
                    self.written.as_entire_binding(),
                ],
            );
            // A pass a rectangle: a scroll's leaving and entering strips are the same storage,
            // so each dispatch must see the last one's writes.
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("window strip"),
                timestamp_writes: None,
            });
            pass.set_pipeline(match dir {
                Direction::Out => &self.out,
                Direction::In => &self.into,
                Direction::Max => &self.max,
            });
            pass.set_bind_group(0, &bg, &[]);
            let g = crate::wgsl::consts::WORKGROUP;
            pass.dispatch_workgroups(p.columns.div_ceil(unit).div_ceil(g), p.rows.div_ceil(g), 1);
        }
        StripRead {
            leaving: RangeRead::record(device, enc, &self.strip_out.buffer, &[(0, out_texels * 8)]),
            written: RangeRead::record(device, enc, &self.written, &[(0, 4)]),
        }
    }
}
