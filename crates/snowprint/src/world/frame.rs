//! The per-frame update: validate, plan ([`FramePlan`]), upload the plan's tables, record the
//! capture and the accumulation into an encoder (the caller's, or the world's own for
//! [`SnowWorld::step`]), and, once the caller says it was submitted, keep the replenishment and
//! read the GPU times back without waiting.

use std::time::Instant;

use super::nearby::INDEX_FROM;
use super::plan::{
    FramePlan, NoPrims, PlanMeshes, PlanSettings, PlanSurface, PrimsTarget, elapsed_ms,
    plan_threads,
};
use super::staging::RingTarget;
use super::{
    FrameStats, InFlight, KEPT_CARRY, KEPT_SETTLE, SnowWorld, StageTimes, SurfaceState,
    SurfaceUpdate, WorldConfig,
};
use crate::accumulate::{self, AccumulateBuffers};
use crate::capture::{self, CaptureBuffers, CaptureMesh};
use crate::deformer::{Deformer, Shape};
use crate::error::{Result, SnowError};
use crate::gpu::resources::{UNIFORM_STRIDE, write_runs};
use crate::gpu::timestamps::StageQueries;
use crate::mesh::MeshId;
use crate::pool::{SurfaceRecord, TILE_LIST_HEADER};
use crate::relax::{self, RelaxBuffers};
use crate::wgsl::consts::TILE_LIST_GRID_FIRST;

/// A world's [`PlanInputs`], borrowed field by field where it is written, so that the borrows stay
/// apart from the staging's (`RingTarget`).
macro_rules! plan_inputs {
    ($world:expr) => {
        PlanInputs {
            config: &$world.config,
            surfaces: &$world.surfaces,
            meshes: WorldMeshes {
                capture: &$world.meshes,
                vertices: &$world.probes.mesh_vertices,
            },
        }
    };
}

/// A frame recorded into a caller's command encoder by [`SnowWorld::encode_update`] or
/// [`SnowWorld::encode_step`], waiting for the caller's `queue.submit`. Give it back with
/// [`SnowWorld::submitted`] after submitting the encoder: that keeps the frame's replenishment
/// and starts reading its GPU times back.
#[must_use = "give it to SnowWorld::submitted after submitting the encoder"]
#[derive(Debug)]
pub struct PendingFrame {
    world: u64,
    frame: u64,
    stats: FrameStats,
    start: Instant,
}

impl PendingFrame {
    /// The frame's number ([`FrameStats::frame`]).
    pub fn frame(&self) -> u64 {
        self.frame
    }

    /// What the frame does and what its encode cost the CPU, as recorded
    /// ([`SnowWorld::submitted`] returns them with the GPU times of an earlier frame).
    pub fn stats(&self) -> &FrameStats {
        &self.stats
    }
}

impl SnowWorld {
    /// Advance every surface by `dt` seconds with the deformers as posed at the end of the frame:
    /// [`SnowWorld::encode_step`] into an encoder of its own, submitted at once.
    pub fn step(&mut self, dt: f32, deformers: &[Deformer]) -> Result<FrameStats> {
        // Queued probes go first in a submission of their own, so that their answer does not
        // wait for the update's passes.
        self.send_probes();
        let mut encoder = self.encoder();
        let pending = self.encode_step(&mut encoder, dt, deformers)?;
        self.submit_own(encoder, pending)
    }

    /// Update chosen surfaces, each with its own deformers and the time since its last update
    /// (snow replenishes by that much). Surfaces not listed keep their heightmap untouched. This is
    /// what a manager with a per-frame budget calls; [`SnowWorld::step`] updates every surface.
    /// Everything is checked before anything changes. [`SnowWorld::encode_update`] into an
    /// encoder of its own, submitted at once.
    pub fn update(&mut self, updates: &[SurfaceUpdate<'_>]) -> Result<FrameStats> {
        self.send_probes();
        let mut encoder = self.encoder();
        let pending = self.encode_update(&mut encoder, updates)?;
        self.submit_own(encoder, pending)
    }

    fn encoder(&self) -> wgpu::CommandEncoder {
        self.device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("snow update"),
            })
    }

    /// Submit an encoder of the world's own and report it submitted; the CPU time includes the
    /// submission.
    fn submit_own(
        &mut self,
        encoder: wgpu::CommandEncoder,
        mut pending: PendingFrame,
    ) -> Result<FrameStats> {
        self.queue.submit([encoder.finish()]);
        pending.stats.cpu_encode_ms = pending.start.elapsed().as_secs_f64() * 1e3;
        self.submitted(pending)
    }

    /// [`SnowWorld::step`] recorded into the caller's `encoder` (between the engine's own
    /// passes, say): every surface advances by `dt` seconds. See [`SnowWorld::encode_update`].
    pub fn encode_step(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        dt: f32,
        deformers: &[Deformer],
    ) -> Result<PendingFrame> {
        if !(dt.is_finite() && dt >= 0.0) {
            return Err(SnowError::InvalidTimeStep { dt });
        }
        for (i, d) in deformers.iter().enumerate() {
            d.validate_named(|| format!("#{i}"))?;
        }
        let updates: Vec<SurfaceUpdate<'_>> = self
            .surfaces()
            .map(|(surface, _)| SurfaceUpdate {
                surface,
                elapsed: dt,
                deformers,
            })
            .collect();
        self.encode_update(encoder, &updates)
    }

    /// [`SnowWorld::update`] recorded into the caller's `encoder`: the capture and accumulation
    /// passes are appended to it, and the frame's tables are written with `queue.write_buffer`
    /// (so they land with the caller's next submission, before its command buffers). Nothing
    /// waits for the GPU. After submitting the encoder, give the [`PendingFrame`] to
    /// [`SnowWorld::submitted`]; until then the world refuses another encode with
    /// [`SnowError::FramePending`] (one frame's tables at a time).
    pub fn encode_update(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        updates: &[SurfaceUpdate<'_>],
    ) -> Result<PendingFrame> {
        self.encode_layers(encoder, &[updates])
    }

    /// Record several updates one after the other into one encoder, as one frame: layer `j + 1`
    /// starts from the snow layer `j` leaves (the manager's frame-by-frame catch-up). The first
    /// layer's tables are written with `queue.write_buffer`, the later ones through staging
    /// copies in the encoder, so that each layer's passes read its own tables. Replenishment
    /// carries are kept as each layer is planned (and put back by
    /// [`SnowWorld::abandon_pending`]).
    pub(crate) fn encode_layers(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        layers: &[&[SurfaceUpdate<'_>]],
    ) -> Result<PendingFrame> {
        let start = Instant::now();
        if self.in_flight.is_some() {
            return Err(SnowError::FramePending);
        }
        let (mut first, check_ms) = self.check_and_plan_first(layers)?;
        self.probes_before_update(encoder);
        self.frames += 1;
        let mut stats = FrameStats {
            frame: self.frames,
            ..FrameStats::default()
        };
        stats.cpu_steps.check_ms = check_ms;
        self.scratch_cpu.carries.clear();
        self.scratch_cpu.settles.clear();
        let kept = &mut self.scratch_cpu.kept;
        kept.clear();
        kept.resize(self.surfaces.len(), 0);
        // The ring is taken out while the layers borrow its query set.
        let ring = self.timestamps.take();
        // A frame is measured only while a readback slot is free: times are never waited for.
        let measured = ring.as_ref().filter(|_| self.profiling);
        let slot = measured.and_then(|r| r.free_slot());
        let mut queries =
            StageQueries::new(measured.filter(|_| slot.is_some()).map(|r| r.timestamps()));
        self.probes.footsteps.clear();
        for (j, updates) in layers.iter().enumerate() {
            let mut plan = match first.take() {
                Some(plan) => plan,
                None => {
                    let mut plan = std::mem::take(&mut self.scratch_cpu.plan);
                    self.plan_into(&mut plan, updates);
                    plan
                }
            };
            self.probes.footsteps.extend_from_slice(&plan.footsteps);
            stats.add_layer(&plan.stats());
            stats.cpu_steps.add(&plan.laps);
            // The spray's particles move by the layer's longest step (a step passes one dt).
            let dt = updates.iter().map(|u| u.elapsed).fold(0.0, f32::max);
            if !plan.is_empty() {
                let start = Instant::now();
                self.upload(&plan, (j > 0).then_some(&mut *encoder));
                if plan.prims_written {
                    let prims = &self.prims.buffer;
                    self.staging.record_copy(encoder, prims, plan.sizes.prims);
                }
                stats.cpu_steps.upload_ms += elapsed_ms(start);
                let start = Instant::now();
                self.record(encoder, &plan, &mut queries, (j, dt));
                stats.cpu_steps.record_ms += elapsed_ms(start);
                let s = &mut self.scratch_cpu;
                remember_captures((&mut s.captured, &mut s.written), &mut plan);
            } else {
                self.record_spray(encoder, &plan, j, dt, &mut queries);
            }
            self.keep_carries(&plan.carries);
            self.keep_settles(&plan.settles);
            self.scratch_cpu.plan = plan;
        }
        let stages = queries.stages().to_vec();
        let timestamp_slot = match (slot, stages.is_empty()) {
            (Some(slot), false) => {
                let r = ring.as_ref().expect("a slot comes from the ring");
                r.resolve(slot, &queries, encoder);
                Some(slot)
            }
            _ => None,
        };
        drop(queries);
        self.timestamps = ring;
        if let (Some(slot), Some(r)) = (timestamp_slot, self.timestamps.as_mut()) {
            r.arm(slot, self.frames, &stages);
        }
        self.in_flight = Some(InFlight {
            frame: self.frames,
            timestamp_slot,
        });
        self.probes_after_update();
        stats.cpu_encode_ms = start.elapsed().as_secs_f64() * 1e3;
        Ok(PendingFrame {
            world: self.id,
            frame: self.frames,
            stats,
            start,
        })
    }

    /// Check every layer and plan the first, before anything changes. The first layer's short
    /// lists (a surface's own deformers) are checked as its plan walks them, so that the
    /// deformers are read once; if anything is refused, the whole check runs again to name the
    /// first fault, as it always did. The plan, unless the quick check alone refused the layers.
    fn check_and_plan_first(
        &mut self,
        layers: &[&[SurfaceUpdate<'_>]],
    ) -> Result<(Option<FramePlan>, f64)> {
        let start = Instant::now();
        let checked = layers
            .iter()
            .enumerate()
            .try_for_each(|(j, updates)| self.validate(updates, j > 0));
        let check_ms = elapsed_ms(start);
        let mut first = std::mem::take(&mut self.scratch_cpu.plan);
        let planned = checked.is_ok() && !layers.is_empty();
        if planned {
            first.check_short_lists = true;
            // A split plan copies its primitives straight into staging memory: a buffer of the
            // world's that the frame's encoder copies from, or the queue's (`world/staging.rs`).
            let mut staging = RingTarget {
                device: &self.device,
                queue: &self.queue,
                ring: &mut self.staging,
                prims: &mut self.prims,
                view: None,
            };
            let inputs = plan_inputs!(self);
            inputs.plan(&mut first, layers[0], Some(&mut staging));
            first.check_short_lists = false;
        }
        if checked.is_err() || (planned && first.refused) {
            // The plan is not used: nor is the staging it filled.
            self.staging.cancel();
            self.scratch_cpu.plan = first;
            layers
                .iter()
                .try_for_each(|updates| self.validate(updates, true))?;
            // Unreachable: what the quick check or the plan refuses, the whole check refuses.
            return Ok((None, check_ms));
        }
        if let Err(e) = self.check_sizes(&first, layers.get(1..).unwrap_or_default()) {
            self.staging.cancel();
            self.scratch_cpu.plan = first;
            return Err(e);
        }
        Ok((Some(first), check_ms))
    }

    /// Refuse a frame whose per-frame buffers the device could not bind (wgpu would panic
    /// binding them): the first layer by its plan, a later one (planned only as the frame is
    /// recorded) by the capture it would need were every surface in it captured, 4 bytes a texel
    /// of each surface's capture region (its texels and the apron around them).
    fn check_sizes(&self, first: &FramePlan, later: &[&[SurfaceUpdate<'_>]]) -> Result<()> {
        let max = self.device.limits().max_storage_buffer_binding_size;
        if let Some((buffer, bytes)) = first.sizes.first_over(max) {
            return Err(SnowError::FrameTooLarge {
                buffer,
                bytes,
                max,
                surfaces: first.accumulate.records.len(),
            });
        }
        for updates in later {
            let bytes: u64 = updates
                .iter()
                .filter_map(|u| self.state(u.surface).ok())
                .map(|s| 4 * crate::capture::region_texels(s.layout.width, s.layout.height) as u64)
                .sum();
            if bytes > max {
                return Err(SnowError::FrameTooLarge {
                    buffer: "capture",
                    bytes,
                    max,
                    surfaces: updates.len(),
                });
            }
        }
        Ok(())
    }

    /// Keep the settle counters a layer leaves (remembering the first for an abandoned frame).
    fn keep_settles(&mut self, settles: &[(usize, crate::relax::Settle)]) {
        let scratch = &mut self.scratch_cpu;
        for &(index, settle) in settles {
            if let Some(s) = self.surfaces.get_mut(index).and_then(Option::as_mut) {
                if scratch.kept[index] & KEPT_SETTLE == 0 {
                    scratch.kept[index] |= KEPT_SETTLE;
                    scratch.settles.push((index, s.settle));
                }
                s.settle = settle;
            }
        }
    }

    /// Keep the carries a layer leaves, remembering each surface's carry before the frame so
    /// that an abandoned frame puts it back.
    fn keep_carries(&mut self, carries: &[(usize, f64)]) {
        let scratch = &mut self.scratch_cpu;
        for &(index, carry) in carries {
            if let Some(s) = self.surfaces.get_mut(index).and_then(Option::as_mut) {
                if scratch.kept[index] & KEPT_CARRY == 0 {
                    scratch.kept[index] |= KEPT_CARRY;
                    scratch.carries.push((index, s.carry));
                }
                s.carry = carry;
            }
        }
    }

    /// The caller submitted the encoder that `pending` was recorded into: keep the frame's
    /// replenishment, make its captures what the debug readbacks show, and start reading its GPU
    /// times back. Returns the frame's stats, with the GPU times of the oldest earlier frame
    /// whose times have arrived (checked without waiting).
    ///
    /// # Errors
    ///
    /// [`SnowError::StaleHandle`] when `pending` is not this world's frame in flight (nothing
    /// changes); [`SnowError::Readback`] when reading times back failed (the frame is kept).
    pub fn submitted(&mut self, pending: PendingFrame) -> Result<FrameStats> {
        let in_flight = self
            .in_flight
            .filter(|f| pending.world == self.id && f.frame == pending.frame)
            .ok_or(SnowError::StaleHandle {
                what: "pending frame",
                index: pending.frame as u32,
            })?;
        self.in_flight = None;
        self.staging.release();
        self.scratch_cpu.carries.clear();
        self.scratch_cpu.settles.clear();
        self.probes_submitted();
        std::mem::swap(&mut self.last.captured, &mut self.scratch_cpu.captured);
        std::mem::swap(&mut self.last.written, &mut self.scratch_cpu.written);
        self.free_deferred();
        // Probe answers that came back while the frame was being submitted.
        self.poll_probes_only();
        let mut stats = pending.stats;
        if let Some(ring) = self.timestamps.as_mut() {
            if let Some(slot) = in_flight.timestamp_slot {
                ring.submitted(slot);
            }
            if let Some((frame, times)) = ring.poll(&self.device)? {
                stats.gpu = Some(stage_times(&times));
                stats.gpu_frame = Some(frame);
            }
        }
        Ok(stats)
    }

    /// Forget the frame in flight, whose encoder will never be submitted (dropped, or its
    /// [`PendingFrame`] lost): its replenishment is not kept, and the world encodes again.
    pub fn abandon_pending(&mut self) {
        self.probes_abandoned();
        self.staging.release();
        if let Some(f) = self.in_flight.take() {
            for (index, carry) in std::mem::take(&mut self.scratch_cpu.carries) {
                if let Some(s) = self.surfaces.get_mut(index).and_then(Option::as_mut) {
                    s.carry = carry;
                }
            }
            for (index, settle) in std::mem::take(&mut self.scratch_cpu.settles) {
                if let Some(s) = self.surfaces.get_mut(index).and_then(Option::as_mut) {
                    s.settle = settle;
                }
            }
            if let (Some(ring), Some(slot)) = (self.timestamps.as_mut(), f.timestamp_slot) {
                ring.abandon(slot);
            }
            self.free_deferred();
        }
    }

    /// The oldest measured frame whose GPU times have arrived and were not yet reported, with
    /// its number ([`FrameStats::frame`]); checked without waiting. After the last frame (and,
    /// say, [`crate::GpuContext::wait_idle`]) this collects the times still on their way.
    pub fn take_gpu_times(&mut self) -> Result<Option<(u64, StageTimes)>> {
        let Some(ring) = self.timestamps.as_mut() else {
            return Ok(None);
        };
        Ok(ring
            .poll(&self.device)?
            .map(|(frame, times)| (frame, stage_times(&times))))
    }

    /// Give back the slots of surfaces removed while a frame was in flight.
    fn free_deferred(&mut self) {
        for slot in self.deferred_frees.drain(..) {
            self.alloc.free(slot);
        }
    }

    /// Refuse a bad time step, a stale or repeated surface, a bad deformer or a stale mesh; the
    /// deformers of lists shorter than [`INDEX_FROM`] only when `short_lists` (else the plan's
    /// walk checks them).
    fn validate(&mut self, updates: &[SurfaceUpdate<'_>], short_lists: bool) -> Result<()> {
        let mut seen = std::mem::take(&mut self.scratch_cpu.seen);
        seen.clear();
        seen.resize(self.surfaces.len(), false);
        let result = self.validate_with(updates, &mut seen, short_lists);
        self.scratch_cpu.seen = seen;
        result
    }

    fn validate_with(
        &self,
        updates: &[SurfaceUpdate<'_>],
        seen: &mut [bool],
        short_lists: bool,
    ) -> Result<()> {
        // `encode_step` hands every surface the same list: check a list once, not once a surface.
        let mut checked: Option<(*const Deformer, usize)> = None;
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
            let list = (u.deformers.as_ptr(), u.deformers.len());
            if checked == Some(list) || (!short_lists && u.deformers.len() < INDEX_FROM) {
                continue;
            }
            checked = Some(list);
            for (i, d) in u.deformers.iter().enumerate() {
                d.validate_named(|| format!("#{i}"))?;
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
    fn plan_into<'a>(&'a self, plan: &mut FramePlan, updates: &'a [SurfaceUpdate<'a>]) {
        let inputs = plan_inputs!(self);
        inputs.plan(plan, updates, None::<&mut NoPrims>);
    }

    /// Grow the per-frame buffers the plan needs and write its tables: with `queue.write_buffer`
    /// when `enc` is `None` (the frame's first layer), else through staging copies recorded in
    /// `enc` (a later layer of the same encoder, whose tables must not overwrite the first's
    /// before its passes ran).
    fn upload(&mut self, plan: &FramePlan, mut enc: Option<&mut wgpu::CommandEncoder>) {
        let (device, queue) = (&self.device, &self.queue);
        let mut write_at = |buffer: &wgpu::Buffer, at: u64, bytes: &[u8]| match enc.as_deref_mut() {
            None => queue.write_buffer(buffer, at, bytes),
            Some(enc) => crate::gpu::resources::write_in_order(device, enc, buffer, at, bytes),
        };
        let sizes = &plan.sizes;
        self.records.ensure(device, sizes.records);
        write_at(
            &self.records.buffer,
            0,
            bytemuck::cast_slice(&plan.accumulate.records),
        );
        let c = &plan.capture;
        let blocks = &mut self.scratch_cpu.blocks;
        uniform_blocks(blocks, &c.views, 1);
        if !c.work.is_empty() {
            // The compute path's work list and its place, after the blocks (`prims.wgsl`).
            blocks.truncate(c.views.len() * UNIFORM_STRIDE as usize);
            capture::append_work_table(c, blocks);
        }
        self.views.ensure(device, sizes.views);
        write_at(&self.views.buffer, 0, blocks);
        if !c.draws.is_empty() {
            uniform_blocks(blocks, &c.draws, 0);
            self.draws.ensure(device, sizes.draws);
            write_at(&self.draws.buffer, 0, blocks);
        }
        if !plan.relax.is_empty() {
            self.relax.records.ensure(device, sizes.relax_records);
            write_at(
                &self.relax.records.buffer,
                0,
                bytemuck::cast_slice(&plan.relax.records),
            );
            self.relax.scratch.ensure(device, sizes.relax_scratch);
            self.relax.tiles.ensure(device, sizes.relax_tiles);
        }
        self.scratch.ensure(device, sizes.scratch);
        self.capture.ensure(device, sizes.capture);
        self.winding.ensure(device, sizes.winding);
        self.tiles.ensure(device, sizes.tiles);
        self.tile_list.ensure(device, sizes.tile_list);
        if c.uploads_list_header() {
            // The list's header (its count, the dispatch arguments seal.wgsl writes, the grid's
            // first record) and the plan's entries, written where they lie rather than copied
            // together first; the capture appends after them.
            let mut header = [0u32; TILE_LIST_HEADER as usize];
            header[3] = c.listed.len() as u32;
            header[TILE_LIST_GRID_FIRST as usize] = c.grid_first;
            let list = &self.tile_list.buffer;
            write_at(list, 0, bytemuck::cast_slice(&header));
            if !c.listed.is_empty() {
                write_at(list, TILE_LIST_HEADER * 4, bytemuck::cast_slice(&c.listed));
            }
        }
        if sizes.prims > 0 {
            self.prims.ensure(device, sizes.prims);
            if !plan.prims_written {
                // Run by run from where each was planned (a split plan's parts are not
                // appended), in one write.
                let runs = plan.prims().map(bytemuck::cast_slice);
                write_runs((device, queue), enc, &self.prims.buffer, sizes.prims, runs);
            }
        }
    }

    /// Record the plan's capture and accumulation into `enc`, measuring their passes with
    /// `queries`; with spray, its pass for `layer` (index, seconds) between the two.
    fn record(
        &mut self,
        enc: &mut wgpu::CommandEncoder,
        plan: &FramePlan,
        queries: &mut StageQueries<'_>,
        layer: (usize, f32),
    ) {
        let atlas = self.atlas(plan.capture.atlas_side);
        let capture_buffers = CaptureBuffers {
            views: &self.views.buffer,
            prims: &self.prims.buffer,
            draws: &self.draws.buffer,
            capture: &self.capture.buffer,
            winding: &self.winding.buffer,
            tiles: &self.tiles.buffer,
            tile_list: &self.tile_list.buffer,
            ground: &self.grounds.buffer,
            ground_codes: &self.ground_codes.buffer,
            atlas: &self.atlases[atlas].2,
        };
        capture::encode(
            &self.device,
            enc,
            &self.capture_pipes,
            &plan.capture,
            &capture_buffers,
            &self.meshes,
            queries,
        );
        self.record_spray(enc, plan, layer.0, layer.1, queries);
        let accumulate_buffers = AccumulateBuffers {
            records: &self.records.buffer,
            capture: &self.capture.buffer,
            winding: &self.winding.buffer,
            scratch: &self.scratch.buffer,
            pool: &self.pool,
            tiles: &self.tiles.buffer,
            tile_list: &self.tile_list.buffer,
            prims: &self.prims.buffer,
            ground: &self.grounds.buffer,
        };
        accumulate::encode_update(
            &self.device,
            enc,
            &self.acc,
            &plan.accumulate,
            &accumulate_buffers,
            queries,
        );
        let relax_buffers = RelaxBuffers {
            records: &self.relax.records.buffer,
            pool: &self.pool,
            scratch: &self.relax.scratch.buffer,
            tiles: &self.relax.tiles.buffer,
        };
        relax::encode(
            &self.device,
            enc,
            &self.relax.pipes,
            &plan.relax,
            &relax_buffers,
            queries,
        );
        accumulate::encode_normals(
            &self.device,
            enc,
            &self.acc,
            &plan.accumulate,
            &accumulate_buffers,
            queries,
        );
    }
}

/// What a frame's plan reads of the world, borrowed field by field (so that the world's staging
/// ring can be borrowed beside it, [`RingTarget`]).
struct PlanInputs<'a> {
    config: &'a WorldConfig,
    surfaces: &'a [Option<SurfaceState>],
    meshes: WorldMeshes<'a>,
}

impl<'a> PlanInputs<'a> {
    /// Plan `updates` into `plan` (on the world's threads when they are many); a split plan's
    /// primitives go to `prims` when given.
    fn plan(
        self,
        plan: &mut FramePlan,
        updates: &'a [SurfaceUpdate<'a>],
        prims: Option<&mut impl PrimsTarget>,
    ) {
        let format = self.config.format;
        let states = self.surfaces;
        let surface = |u: &'a SurfaceUpdate<'a>| -> Option<PlanSurface<'a>> {
            let index = u.surface.0 as usize;
            let s = states.get(index)?.as_ref()?;
            Some(PlanSurface {
                index,
                id: u.surface,
                desc: &s.desc,
                layout: s.layout,
                heights_word: s.slot.heights_word(),
                wrap: s.wrap,
                normals_word: s
                    .slot
                    .normals_word(&format, s.layout.width, s.layout.height),
                carry: s.carry,
                elapsed: u.elapsed,
                deformers: u.deformers,
                settle: s.settle,
                ground: s.ground.as_ref().map(|g| g.plan()),
                ground_field: s.ground.as_ref().map(|g| &g.field),
            })
        };
        let settings = PlanSettings::of(self.config);
        let threads = plan_threads(self.config.plan_threads);
        plan.rebuild_split(&settings, updates, surface, self.meshes, (threads, prims));
    }
}

/// The world's meshes as its plan sees them: their capture radius and the CPU copy of their
/// vertices the footstep test reads, both by mesh index.
struct WorldMeshes<'a> {
    capture: &'a [Option<CaptureMesh>],
    vertices: &'a [Option<Vec<glam::Vec3>>],
}

impl PlanMeshes for WorldMeshes<'_> {
    fn radius(&self, id: MeshId) -> Option<f32> {
        self.capture.get(id.0 as usize)?.as_ref().map(|m| m.radius)
    }

    fn vertices(&self, id: MeshId) -> Option<&[glam::Vec3]> {
        self.vertices.get(id.0 as usize)?.as_deref()
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

/// The captured surfaces of a frame, for the debug readbacks once it is submitted.
fn remember_captures(
    (captured, written): (&mut Vec<(usize, SurfaceRecord)>, &mut Vec<[u32; 2]>),
    plan: &mut FramePlan,
) {
    // The work list is rebuilt next frame: the two lists trade places, each keeping its memory.
    written.clear();
    std::mem::swap(written, &mut plan.capture.work);
    captured.clear();
    captured.extend(plan.capture.surfaces.iter().map(|s| {
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
            "relax" => t.relax_ms += ms,
            "spray" => t.spray_ms += ms,
            "refill" => t.refill_ms += ms,
            _ => t.fused_ms += ms,
        }
    }
    t
}
