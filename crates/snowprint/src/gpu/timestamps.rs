//! GPU timestamp queries at pass boundaries: one query set, resolved and read back after the
//! frame, turned into milliseconds per named stage. Shared by the world's update and usable by the
//! renderer: a frame asks [`StageQueries`] for the writes of each pass it wants measured.

use crate::error::Result;

/// A query set with its resolve and readback buffers.
pub struct Timestamps {
    set: wgpu::QuerySet,
    resolve: wgpu::Buffer,
    readback: wgpu::Buffer,
    period_ns: f32,
    capacity: u32,
}

impl std::fmt::Debug for Timestamps {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Timestamps")
            .field("capacity", &self.capacity)
            .finish()
    }
}

impl Timestamps {
    /// A query set of `capacity` timestamps (two a measured pass), on a device created with
    /// `wgpu::Features::TIMESTAMP_QUERY`.
    pub fn new(device: &wgpu::Device, queue: &wgpu::Queue, label: &str, capacity: u32) -> Self {
        use wgpu::BufferUsages as U;
        let buffer = |usage| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: capacity as u64 * 8,
                usage,
                mapped_at_creation: false,
            })
        };
        Self {
            set: device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some(label),
                ty: wgpu::QueryType::Timestamp,
                count: capacity,
            }),
            resolve: buffer(U::QUERY_RESOLVE | U::COPY_SRC),
            readback: buffer(U::MAP_READ | U::COPY_DST),
            period_ns: queue.get_timestamp_period(),
            capacity,
        }
    }

    /// Timestamps the set holds.
    pub fn capacity(&self) -> u32 {
        self.capacity
    }

    /// The query set (for passes that place their writes themselves, as the renderer's fixed
    /// slots do).
    pub fn query_set(&self) -> &wgpu::QuerySet {
        &self.set
    }

    /// The buffer the queries resolve into (`QUERY_RESOLVE | COPY_SRC`, 8 bytes a query).
    pub fn resolve_buffer(&self) -> &wgpu::Buffer {
        &self.resolve
    }

    /// Nanoseconds a timestamp tick.
    pub fn period_ns(&self) -> f32 {
        self.period_ns
    }
}

/// The passes measured in one frame, in order, each by a pair of timestamps named by its stage.
/// Without [`Timestamps`] (profiling off, or an adapter without queries) it measures nothing and
/// allocates nothing.
#[derive(Debug)]
pub struct StageQueries<'a> {
    timestamps: Option<&'a Timestamps>,
    stages: Vec<&'static str>,
}

impl<'a> StageQueries<'a> {
    /// Measure with `timestamps` when given.
    pub fn new(timestamps: Option<&'a Timestamps>) -> Self {
        Self {
            timestamps,
            stages: Vec::new(),
        }
    }

    /// The next pair of queries, for a pass of `stage`, while the set has room.
    fn next(&mut self, stage: &'static str) -> Option<(&'a wgpu::QuerySet, u32)> {
        let ts = self.timestamps?;
        let q = self.stages.len() as u32 * 2;
        if q + 2 > ts.capacity {
            return None;
        }
        self.stages.push(stage);
        Some((&ts.set, q))
    }

    /// Timestamp writes for a render pass of `stage` (`None`: not measured).
    pub fn render(&mut self, stage: &'static str) -> Option<wgpu::RenderPassTimestampWrites<'a>> {
        self.next(stage)
            .map(|(query_set, q)| wgpu::RenderPassTimestampWrites {
                query_set,
                beginning_of_pass_write_index: Some(q),
                end_of_pass_write_index: Some(q + 1),
            })
    }

    /// Timestamp writes for a compute pass of `stage` (`None`: not measured).
    pub fn compute(&mut self, stage: &'static str) -> Option<wgpu::ComputePassTimestampWrites<'a>> {
        self.next(stage)
            .map(|(query_set, q)| wgpu::ComputePassTimestampWrites {
                query_set,
                beginning_of_pass_write_index: Some(q),
                end_of_pass_write_index: Some(q + 1),
            })
    }

    /// Whether any pass was measured.
    pub fn is_empty(&self) -> bool {
        self.stages.is_empty()
    }

    /// The stages of the measured passes, in order.
    pub fn stages(&self) -> &[&'static str] {
        &self.stages
    }

    /// Record the resolve of the frame's queries and their copy to the readback buffer (last in
    /// the frame's encoder).
    pub fn resolve(&self, enc: &mut wgpu::CommandEncoder) {
        if let Some(ts) = self.timestamps {
            self.resolve_to(enc, &ts.readback);
        }
    }

    /// Record the resolve of the frame's queries and their copy to `readback` (`COPY_DST`, 16
    /// bytes a measured pass), last in the frame's encoder.
    pub fn resolve_to(&self, enc: &mut wgpu::CommandEncoder, readback: &wgpu::Buffer) {
        if let (Some(ts), false) = (self.timestamps, self.stages.is_empty()) {
            let n = self.stages.len() as u32 * 2;
            enc.resolve_query_set(&ts.set, 0..n, &ts.resolve, 0);
            enc.copy_buffer_to_buffer(&ts.resolve, 0, readback, 0, n as u64 * 8);
        }
    }

    /// After the frame was submitted: wait for it and give each measured pass's stage and GPU
    /// time, milliseconds, in the order measured. Empty when nothing was measured.
    pub fn read(&self, device: &wgpu::Device) -> Result<Vec<(&'static str, f64)>> {
        let Some(ts) = self.timestamps.filter(|_| !self.stages.is_empty()) else {
            return Ok(Vec::new());
        };
        let bytes =
            super::readback::map_read(device, &ts.readback, 0, self.stages.len() as u64 * 16)?;
        let ticks: &[u64] = bytemuck::cast_slice(&bytes);
        Ok(self
            .stages
            .iter()
            .enumerate()
            .map(|(i, &stage)| {
                let ms = ticks[2 * i + 1].saturating_sub(ticks[2 * i]) as f64
                    * ts.period_ns as f64
                    * 1e-6;
                (stage, ms)
            })
            .collect())
    }
}
