//! The frame report's readback: each surface's state words, the dicing's counters and the pass
//! timestamps, copied into one buffer after the passes and mapped without stalling the frame.

use std::sync::Arc;
use std::sync::atomic::{AtomicU8, Ordering};

use super::error::{RenderError, RenderResult};
use super::gpu::{STATE_DEEPEST, STATE_DEFORMABLE_DRAW, STATE_WORDS};
use super::graph::PASSES;
use super::readback::Timestamps;
use super::report::{FrameReport, PassTime, SnowMaterialKind, SurfaceShading};
use super::tessellate;
use crate::surface::SurfaceId;

/// Map state of the stats readback buffer.
const MAP_IDLE: u8 = 0;
const MAP_PENDING: u8 = 1;
const MAP_READY: u8 = 2;
const MAP_FAILED: u8 = 3;

pub(super) struct StatsReadback {
    buffer: wgpu::Buffer,
    state: Arc<AtomicU8>,
    /// Surfaces of the frame being read, and whether timestamps were copied.
    surfaces: Vec<SurfaceId>,
    timestamps: bool,
}

/// The GPU buffers a frame's report is read from.
pub(super) struct StatsSources<'a> {
    /// Per-surface state words (the classify pass's output).
    pub state: &'a wgpu::Buffer,
    /// The dicing's counters and draw arguments.
    pub counters: &'a wgpu::Buffer,
    pub timestamps: Option<&'a Timestamps>,
}

impl StatsReadback {
    pub(super) fn new(device: &wgpu::Device) -> Self {
        Self {
            buffer: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("render stats readback"),
                size: 1024,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            state: Arc::new(AtomicU8::new(MAP_IDLE)),
            surfaces: Vec::new(),
            timestamps: false,
        }
    }

    /// Whether no readback is in flight (the buffer can take a new frame's copy).
    pub(super) fn is_idle(&self) -> bool {
        self.state.load(Ordering::Acquire) == MAP_IDLE
    }

    /// Copy the frame's state words, counters and timestamps into the readback buffer.
    pub(super) fn copy(
        &mut self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        from: StatsSources<'_>,
        surfaces: Vec<SurfaceId>,
    ) {
        let state_bytes = surfaces.len() as u64 * STATE_WORDS * 4;
        let dice_bytes = tessellate::gpu::counters_bytes(surfaces.len());
        let ts_bytes = if from.timestamps.is_some() {
            PASSES.len() as u64 * 16
        } else {
            0
        };
        let need = (state_bytes + dice_bytes + ts_bytes).max(16);
        if self.buffer.size() < need {
            self.buffer = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("render stats readback"),
                size: need.next_power_of_two(),
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
        }
        if state_bytes > 0 {
            encoder.copy_buffer_to_buffer(from.state, 0, &self.buffer, 0, state_bytes);
        }
        encoder.copy_buffer_to_buffer(from.counters, 0, &self.buffer, state_bytes, dice_bytes);
        if let Some(ts) = from.timestamps {
            encoder.resolve_query_set(
                ts.query_set(),
                0..2 * PASSES.len() as u32,
                ts.resolve_buffer(),
                0,
            );
            encoder.copy_buffer_to_buffer(
                ts.resolve_buffer(),
                0,
                &self.buffer,
                state_bytes + dice_bytes,
                ts_bytes,
            );
        }
        self.surfaces = surfaces;
        self.timestamps = from.timestamps.is_some();
    }

    /// Start mapping the buffer (after the frame's submission).
    pub(super) fn start_map(&mut self) {
        let state = self.state.clone();
        state.store(MAP_PENDING, Ordering::Release);
        self.buffer
            .slice(..)
            .map_async(wgpu::MapMode::Read, move |r| {
                state.store(
                    if r.is_ok() { MAP_READY } else { MAP_FAILED },
                    Ordering::Release,
                );
            });
    }

    /// The report when the readback has arrived (waiting for it when `wait`); `None` when
    /// nothing was in flight or it has not arrived yet.
    pub(super) fn finish(
        &mut self,
        device: &wgpu::Device,
        timestamps: Option<&Timestamps>,
        wait: bool,
    ) -> RenderResult<Option<FrameReport>> {
        if self.is_idle() {
            return Ok(None);
        }
        let poll = if wait {
            wgpu::PollType::wait_indefinitely()
        } else {
            wgpu::PollType::Poll
        };
        device.poll(poll)?;
        match self.state.load(Ordering::Acquire) {
            MAP_READY => {}
            MAP_FAILED => {
                self.state.store(MAP_IDLE, Ordering::Release);
                return Err(RenderError::Readback(
                    "mapping the frame report failed".into(),
                ));
            }
            _ => return Ok(None),
        }
        let report = {
            let data = self.buffer.slice(..).get_mapped_range()?;
            self.report(&data, timestamps)
        };
        self.buffer.unmap();
        self.state.store(MAP_IDLE, Ordering::Release);
        Ok(Some(report))
    }

    /// The report in the mapped bytes.
    fn report(&self, data: &[u8], timestamps: Option<&Timestamps>) -> FrameReport {
        let n = self.surfaces.len();
        // Read by value: a mapped range promises no alignment.
        let word = |i: usize| {
            u32::from_le_bytes([
                data[4 * i],
                data[4 * i + 1],
                data[4 * i + 2],
                data[4 * i + 3],
            ])
        };
        let surfaces = self
            .surfaces
            .iter()
            .enumerate()
            .map(|(s, &id)| {
                let base = s * STATE_WORDS as usize;
                let args = n * STATE_WORDS as usize
                    + (tessellate::ARGS_BASE + tessellate::ARGS_STRIDE * s as u64) as usize;
                SurfaceShading {
                    surface: id,
                    // The pipeline that draws it: the deformable one's instance count (a surface
                    // on ground that is not flat takes it untouched).
                    material: if word(base + STATE_DEFORMABLE_DRAW as usize + 1) == 0 {
                        SnowMaterialKind::Basic
                    } else {
                        SnowMaterialKind::Deformable
                    },
                    deepest: f32::from_bits(word(base + STATE_DEEPEST as usize)),
                    triangles: word(args) / 3,
                }
            })
            .collect();
        let mut pass_times = Vec::new();
        if let (true, Some(ts)) = (self.timestamps, timestamps) {
            let start = n * STATE_WORDS as usize * 4 + tessellate::gpu::counters_bytes(n) as usize;
            let tick = |i: usize| {
                let o = start + 8 * i;
                let mut b = [0u8; 8];
                b.copy_from_slice(&data[o..o + 8]);
                u64::from_le_bytes(b)
            };
            for (i, p) in PASSES.iter().enumerate() {
                let dt = tick(2 * i + 1).saturating_sub(tick(2 * i));
                pass_times.push(PassTime {
                    name: p.name,
                    gpu_ms: dt as f64 * ts.period_ns() as f64 * 1e-6,
                });
            }
        }
        FrameReport {
            pass_times,
            surfaces,
            dice_overflow: word(n * STATE_WORDS as usize + tessellate::COUNTER_OVERFLOW as usize),
        }
    }
}
