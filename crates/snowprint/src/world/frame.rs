//! The per-frame update: validate, plan ([`FramePlan`]), upload the plan's tables, record the
//! capture and the accumulation, submit, and report.

use std::time::Instant;

use super::plan::{FramePlan, PlanSettings, PlanSurface};
use super::{FrameStats, LastFrame, SnowWorld, StageTimes, SurfaceUpdate};
use crate::accumulate::{self, AccumulateBuffers};
use crate::capture::{self, CaptureBuffers};
use crate::deformer::{Deformer, Shape};
use crate::error::{Result, SnowError};
use crate::gpu::resources::UNIFORM_STRIDE;
use crate::gpu::timestamps::StageQueries;

impl SnowWorld {
    /// Advance every surface by `dt` seconds with the deformers as posed at the end of the frame.
    pub fn step(&mut self, dt: f32, deformers: &[Deformer]) -> Result<FrameStats> {
        if !(dt.is_finite() && dt >= 0.0) {
            return Err(SnowError::InvalidTimeStep { dt });
        }
        for (i, d) in deformers.iter().enumerate() {
            d.validate(&format!("#{i}"))?;
        }
        let updates: Vec<SurfaceUpdate<'_>> = self
            .surfaces()
            .map(|(surface, _)| SurfaceUpdate {
                surface,
                elapsed: dt,
                deformers,
            })
            .collect();
        self.update(&updates)
    }

    /// Update chosen surfaces, each with its own deformers and the time since its last update
    /// (snow replenishes by that much). Surfaces not listed keep their heightmap untouched. This is
    /// what a manager with a per-frame budget calls; [`SnowWorld::step`] updates every surface.
    /// Everything is checked before anything changes.
    pub fn update(&mut self, updates: &[SurfaceUpdate<'_>]) -> Result<FrameStats> {
        let start = Instant::now();
        self.validate(updates)?;
        self.probes_before_update();
        let mut plan = std::mem::take(&mut self.scratch_cpu.plan);
        self.plan_into(&mut plan, updates);
        let mut stats = plan.stats();
        let result = if plan.is_empty() {
            // Nothing captured: the debug readbacks of the last step must not show an older one.
            self.last.captured.clear();
            self.commit_carries(&plan);
            stats.cpu_encode_ms = start.elapsed().as_secs_f64() * 1e3;
            Ok(())
        } else {
            self.upload(&plan);
            self.record_and_submit(&plan, start, &mut stats)
        };
        self.scratch_cpu.plan = plan;
        if result.is_ok() {
            self.probes_after_update(updates);
        }
        result.map(|()| stats)
    }

    /// Refuse a bad time step, a stale or repeated surface, a bad deformer or a stale mesh.
    fn validate(&mut self, updates: &[SurfaceUpdate<'_>]) -> Result<()> {
        let mut seen = std::mem::take(&mut self.scratch_cpu.seen);
        seen.clear();
        seen.resize(self.surfaces.len(), false);
        let result = self.validate_with(updates, &mut seen);
        self.scratch_cpu.seen = seen;
        result
    }

    fn validate_with(&self, updates: &[SurfaceUpdate<'_>], seen: &mut [bool]) -> Result<()> {
        for u in updates {
            let dt = u.elapsed;
            if !(dt.is_finite() && dt >= 0.0) {
                return Err(SnowError::InvalidTimeStep { dt });
            }
            self.state(u.surface)?;
            let flag = &mut seen[u.surface.0 as usize];
            if *flag {
                return Err(SnowError::DuplicateUpdate { index: u.surface.0 });
            }
            *flag = true;
            for (i, d) in u.deformers.iter().enumerate() {
                d.validate(&format!("#{i}"))?;
                if let Shape::Mesh(id) = d.shape
                    && self
                        .meshes
                        .get(id.0 as usize)
                        .and_then(Option::as_ref)
                        .is_none()
                {
                    return Err(SnowError::StaleHandle {
                        what: "mesh",
                        index: id.0,
                    });
                }
            }
        }
        Ok(())
    }

    /// The frame's plan, from the surfaces' state and the (validated) updates.
    fn plan_into(&self, plan: &mut FramePlan, updates: &[SurfaceUpdate<'_>]) {
        let format = self.config.format;
        let surfaces = updates.iter().filter_map(|u| {
            let index = u.surface.0 as usize;
            let s = self.surfaces[index].as_ref()?;
            Some(PlanSurface {
                index,
                desc: &s.desc,
                layout: s.layout,
                heights_word: s.slot.heights_word(),
                normals_word: s
                    .slot
                    .normals_word(&format, s.layout.width, s.layout.height),
                carry: s.carry,
                elapsed: u.elapsed,
                deformers: u.deformers,
            })
        });
        let meshes = &self.meshes;
        plan.rebuild(&PlanSettings::of(&self.config), surfaces, |id| {
            meshes.get(id.0 as usize)?.as_ref().map(|m| m.radius)
        });
    }

    /// Keep the replenishment carried by every surface planned.
    fn commit_carries(&mut self, plan: &FramePlan) {
        for &(index, carry) in &plan.carries {
            if let Some(s) = self.surfaces[index].as_mut() {
                s.carry = carry;
            }
        }
    }

    /// Grow the per-frame buffers the plan needs and write its tables.
    fn upload(&mut self, plan: &FramePlan) {
        let (device, queue) = (&self.device, &self.queue);
        let sizes = &plan.sizes;
        self.records.ensure(device, sizes.records);
        queue.write_buffer(
            &self.records.buffer,
            0,
            bytemuck::cast_slice(&plan.accumulate.records),
        );
        let c = &plan.capture;
        let blocks = &mut self.scratch_cpu.blocks;
        uniform_blocks(blocks, &c.views, 1);
        self.views.ensure(device, sizes.views);
        queue.write_buffer(&self.views.buffer, 0, blocks);
        if !c.prims.is_empty() {
            self.prims.ensure(device, sizes.prims);
            queue.write_buffer(&self.prims.buffer, 0, bytemuck::cast_slice(&c.prims));
        }
        if !c.draws.is_empty() {
            uniform_blocks(blocks, &c.draws, 0);
            self.draws.ensure(device, sizes.draws);
            queue.write_buffer(&self.draws.buffer, 0, blocks);
        }
        self.scratch.ensure(device, sizes.scratch);
        self.capture.ensure(device, sizes.capture);
        self.winding.ensure(device, sizes.winding);
        self.tiles.ensure(device, sizes.tiles);
        self.tile_list.ensure(device, sizes.tile_list);
    }

    /// Record the plan's capture and accumulation, submit them, keep the carries and what the
    /// debug readbacks need, and read the stage times back when profiling.
    fn record_and_submit(
        &mut self,
        plan: &FramePlan,
        start: Instant,
        stats: &mut FrameStats,
    ) -> Result<()> {
        let atlas = self.atlas(plan.capture.atlas_side);
        let timestamps = self.timestamps.as_ref().filter(|_| self.profiling);
        let mut queries = StageQueries::new(timestamps);
        let mut enc = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("snow update"),
            });
        let capture_buffers = CaptureBuffers {
            views: &self.views.buffer,
            prims: &self.prims.buffer,
            draws: &self.draws.buffer,
            capture: &self.capture.buffer,
            winding: &self.winding.buffer,
            tiles: &self.tiles.buffer,
            tile_list: &self.tile_list.buffer,
            atlas: &self.atlases[atlas].2,
        };
        capture::encode(
            &self.device,
            &mut enc,
            &self.capture_pipes,
            &plan.capture,
            &capture_buffers,
            &self.meshes,
            &mut queries,
        );
        let accumulate_buffers = AccumulateBuffers {
            records: &self.records.buffer,
            capture: &self.capture.buffer,
            winding: &self.winding.buffer,
            scratch: &self.scratch.buffer,
            pool: &self.pool,
            tiles: &self.tiles.buffer,
            tile_list: &self.tile_list.buffer,
        };
        accumulate::encode(
            &self.device,
            &mut enc,
            &self.acc,
            &plan.accumulate,
            &accumulate_buffers,
            &mut queries,
        );
        queries.resolve(&mut enc);
        self.queue.submit([enc.finish()]);
        stats.cpu_encode_ms = start.elapsed().as_secs_f64() * 1e3;

        let times = queries.read(&self.device);
        drop(queries);
        self.commit_carries(plan);
        remember_captures(&mut self.last, plan);
        let times = times?;
        if !times.is_empty() {
            stats.gpu = Some(stage_times(&times));
        }
        Ok(())
    }
}

/// Write `items` as uniform blocks [`UNIFORM_STRIDE`] apart into `bytes` (at least `min` blocks).
fn uniform_blocks<T: bytemuck::Pod>(bytes: &mut Vec<u8>, items: &[T], min: usize) {
    let stride = UNIFORM_STRIDE as usize;
    bytes.clear();
    bytes.resize(items.len().max(min) * stride, 0);
    for (k, item) in items.iter().enumerate() {
        let item = bytemuck::bytes_of(item);
        bytes[k * stride..k * stride + item.len()].copy_from_slice(item);
    }
}

/// The captured surfaces of a submitted frame, for the debug readbacks.
fn remember_captures(last: &mut LastFrame, plan: &FramePlan) {
    last.captured.clear();
    last.captured.extend(plan.capture.surfaces.iter().map(|s| {
        let j = s.record as usize;
        (plan.surfaces[j].index, plan.accumulate.records[j])
    }));
}

/// Milliseconds of each measured pass summed by stage.
fn stage_times(times: &[(&'static str, f64)]) -> StageTimes {
    let mut t = StageTimes::default();
    for &(stage, ms) in times {
        match stage {
            "capture" => t.capture_ms += ms,
            "blur" => t.blur_ms += ms,
            "merge" => t.merge_ms += ms,
            "normals" => t.normals_ms += ms,
            _ => t.fused_ms += ms,
        }
    }
    t
}
