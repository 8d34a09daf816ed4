//! The manager's frame: plan, then record everything the plan asks of the GPU into one encoder
//! (the caller's, with [`SnowManager::encode_tick`]), with nothing that waits for the GPU.
//!
//! In the encoder, in this order:
//! 1. the probes asked of the manager since the last tick (they read the snow the last tick left);
//! 2. the page-out of every surface evicted this tick: its slot copied into a staging buffer
//!    ([`SnowWorld::encode_snapshot`]), mapped once the caller reports the encoder submitted and
//!    compressed into the page store when it has arrived (checked without waiting at every tick);
//! 3. the admissions: slots cleared, or written from their page, in the encoder's order, so that a
//!    slot freed by an eviction is written only after its page-out copied it;
//! 4. the updates: every catch-up layer ([`CatchUp::Frames`]) one after the other, as one world
//!    frame ([`SnowWorld::encode_update`] for several layers).
//!
//! A surface whose page is still on its way is not admitted (it waits a tick, its queue intact).
//! [`SnowManager::tick`] (in `mod.rs`, with the other calls that may wait) is the same into an
//! encoder of its own, submitted at once, and then waits for its pages, so that a tick leaves
//! every heightmap in the pool or the page store. Nothing in this file waits for the GPU.

use super::apply::{apply_changes, catch_up_layers};
use super::pages::Page;
use super::{CameraView, ManagedDeformer, ManagedId, SnowManager, TickStats};
use crate::deformer::Shape;
use crate::error::{Result, SnowError};
use crate::world::{PendingFrame, SnapshotRead, SurfaceUpdate};

/// A tick recorded into a caller's command encoder by [`SnowManager::encode_tick`], waiting for
/// the caller's `queue.submit`. Give it back with [`SnowManager::submitted`] after submitting.
#[must_use = "give it to SnowManager::submitted after submitting the encoder"]
#[derive(Debug)]
pub struct PendingTick {
    manager: u64,
    tick: u64,
    frame: Option<PendingFrame>,
    stats: TickStats,
}

/// Heightmaps paged out in one tick, on their way from the GPU.
#[derive(Debug)]
pub(super) struct PageRead {
    pub(super) read: SnapshotRead,
    pub(super) ids: Vec<ManagedId>,
}

/// The tick in flight: what [`SnowManager::abandon_pending`] must undo or report.
#[derive(Debug)]
pub(super) struct TickInFlight {
    pub(super) tick: u64,
    /// Its page-out, mapped once the tick is submitted.
    pub(super) pages: Option<PageRead>,
}

impl SnowManager {
    /// Run one frame into the caller's `encoder`: decide (see [`super::Planner::tick`]), then
    /// record the probes, page-outs, page-ins and at most `updates_per_frame` surface updates (see
    /// the module docs). Nothing waits for the GPU. After submitting the encoder, give the
    /// [`PendingTick`] to [`SnowManager::submitted`]; until then the manager refuses another tick,
    /// a zone unload, a read or a save with [`SnowError::FramePending`]. Bad input is an error
    /// before anything changes.
    pub fn encode_tick(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        dt: f32,
        camera: Option<&CameraView>,
        deformers: &[ManagedDeformer],
    ) -> Result<PendingTick> {
        if self.in_flight.is_some() {
            return Err(SnowError::FramePending);
        }
        let deformers = self.world_deformers(deformers)?;
        self.harvest_pages()?;
        self.planner.tick(dt, camera, &deformers)?;
        self.send_probes(encoder)?;
        let paged_between = std::mem::take(&mut self.paged_between);
        let applied = apply_changes(
            &mut self.world,
            &mut self.pages,
            &mut self.world_ids,
            &self.grounds,
            &self.planner,
            encoder,
        )?;
        for &id in &applied.failed {
            self.planner.admission_failed(id);
        }
        if let Some(p) = &applied.pages {
            for &id in &p.ids {
                self.planner.page_arriving(id);
            }
        }
        let (pages, paged_out, paged_in) = (applied.pages, applied.paged_out, applied.paged_in);
        let plan = self.planner.last_plan();
        let runs = catch_up_layers(
            &self.world_ids,
            &plan.updates,
            self.planner.config().catch_up,
        );
        // The terrains' levels, every tick, in the first layer (they never queue).
        let levels: Vec<_> = self.level_ids().collect();
        let level_deformers: Vec<_> = deformers.iter().map(|d| d.deformer).collect();
        let mut runs = runs;
        if !levels.is_empty() {
            if runs.is_empty() {
                runs.push(Vec::new());
            }
            runs[0].extend(super::terrain::level_updates(&levels, dt, &level_deformers));
        }
        let layers: Vec<&[SurfaceUpdate<'_>]> = runs.iter().map(Vec::as_slice).collect();
        let frame = if layers.is_empty() {
            None
        } else {
            Some(self.world.encode_layers(encoder, &layers)?)
        };
        let mut stats = plan.stats.clone();
        drop(runs);
        for &l in &levels {
            stats.updated.push(self.world.surface(l)?.name.clone());
        }
        self.free_retired_meshes()?;
        let memory = self.world.memory();
        if memory.pool_used != self.planner.pool_used() {
            tracing::warn!(
                "pool accounting differs: world {} bytes, planner {} bytes",
                memory.pool_used,
                self.planner.pool_used()
            );
        }
        stats.pool_bytes_used = memory.pool_used;
        stats.pool_bytes_budget = memory.pool_budget;
        stats.paged_out_bytes = paged_out + paged_between;
        stats.paged_in_bytes = paged_in;
        self.ticks += 1;
        self.in_flight = Some(super::frame::TickInFlight {
            tick: self.ticks,
            pages,
        });
        Ok(PendingTick {
            manager: self.id,
            tick: self.ticks,
            frame,
            stats,
        })
    }

    /// The caller submitted the encoder that `pending` was recorded into: the world keeps the
    /// frame, the page-outs start mapping, and the probes' GPU half starts reading back. Returns
    /// the tick's statistics (with the pages that have arrived by now, checked without waiting).
    ///
    /// # Errors
    ///
    /// [`SnowError::StaleHandle`] when `pending` is not this manager's tick in flight (nothing
    /// changes).
    pub fn submitted(&mut self, pending: PendingTick) -> Result<TickStats> {
        let in_flight = self
            .in_flight
            .take_if(|t| pending.manager == self.id && t.tick == pending.tick)
            .ok_or(SnowError::StaleHandle {
                what: "pending tick",
                index: pending.tick as u32,
            })?;
        if let Some(pages) = in_flight.pages {
            pages.read.submitted();
            self.arriving.push(pages);
        }
        let mut stats = pending.stats;
        match pending.frame {
            Some(frame) => {
                self.world.submitted(frame)?;
            }
            None => self.world.probes_sent(),
        }
        self.harvest_pages()?;
        stats.page_store_bytes = self.pages.bytes();
        stats.paged_surfaces = self.pages.len();
        stats.pages_arriving = self.arriving.iter().map(|p| p.ids.len()).sum();
        self.stats = stats.clone();
        Ok(stats)
    }

    /// Forget the tick in flight, whose encoder will never be submitted. What it decided stays
    /// decided, except what the GPU would have done: the world's frame is abandoned (its
    /// replenishment not kept; the imprints it carried are lost), and the heightmaps it paged out
    /// never reach the page store. Returns the surfaces that lost their heightmap that way (they
    /// come back as untouched snow); empty when no tick was in flight or it paged nothing out.
    pub fn abandon_pending(&mut self) -> Vec<ManagedId> {
        self.world.abandon_pending();
        let Some(t) = self.in_flight.take() else {
            return Vec::new();
        };
        let lost = t.pages.map(|p| p.ids).unwrap_or_default();
        for &id in &lost {
            self.planner.page_lost(id);
        }
        lost
    }

    /// Mesh handles are the manager's; the planner and the world see the current world mesh.
    fn world_deformers(&self, deformers: &[ManagedDeformer]) -> Result<Vec<ManagedDeformer>> {
        deformers
            .iter()
            .map(|d| {
                let mut d = *d;
                if let Shape::Mesh(id) = d.deformer.shape {
                    d.deformer.shape = Shape::Mesh(self.mesh(id)?.world);
                }
                Ok(d)
            })
            .collect()
    }

    /// Keep every page-out that has arrived (polling the device without waiting).
    pub(super) fn harvest_pages(&mut self) -> Result<()> {
        if self.arriving.is_empty() {
            return Ok(());
        }
        let _ = self.world.device().poll(wgpu::PollType::Poll);
        let mut k = 0;
        while k < self.arriving.len() {
            let Some(snaps) = self.arriving[k].read.try_take() else {
                k += 1;
                continue;
            };
            let p = self.arriving.swap_remove(k);
            self.keep_pages(p.ids, snaps?);
        }
        Ok(())
    }

    pub(super) fn keep_pages(
        &mut self,
        ids: Vec<ManagedId>,
        snaps: Vec<crate::world::SurfaceSnapshot>,
    ) {
        for (id, snap) in ids.into_iter().zip(snaps) {
            self.planner.page_arrived(id);
            self.pages.put(id.0, Page::compress(snap));
        }
    }

    /// Refuse what needs the GPU's state while a tick is recorded and not submitted.
    pub(super) fn not_pending(&self) -> Result<()> {
        match self.in_flight {
            Some(_) => Err(SnowError::FramePending),
            None => Ok(()),
        }
    }
}
