//! Applying a plan to the world, recorded into one encoder: residency changes (page-outs, then
//! evictions and admissions in the plan's order), then the planned updates as catch-up layers.

use super::frame::PageRead;
use super::ground::ManagedGround;
use super::pages::PageStore;
use super::{CatchUp, ManagedId, PlannedUpdate, Planner, ResidencyChange};
use crate::deformer::Deformer;
use crate::error::{Result, SnowError};
use crate::surface::SurfaceId;
use crate::world::{SnowWorld, SurfaceUpdate};

/// What applying a plan's residency changes did.
pub(super) struct Applied {
    /// The page-out of the evicted surfaces, on its way from the GPU.
    pub(super) pages: Option<PageRead>,
    /// Bytes copied out for pages, and written in from pages.
    pub(super) paged_out: u64,
    pub(super) paged_in: u64,
    /// Admissions the world refused (the planner gives their slot back).
    pub(super) failed: Vec<ManagedId>,
}

/// Apply a plan's residency changes, recorded into `enc`: first the copy of every heightmap to
/// evict (one staging buffer, mapped once the encoder is submitted), then, in the plan's order,
/// evictions free their slots and admissions clear theirs or write them from their page, in the
/// encoder's order (after the copies, so a reused slot is read before it is overwritten).
pub(super) fn apply_changes(
    world: &mut SnowWorld,
    pages: &mut PageStore,
    world_ids: &mut [Option<SurfaceId>],
    grounds: &[Option<ManagedGround>],
    planner: &Planner,
    enc: &mut wgpu::CommandEncoder,
) -> Result<Applied> {
    let changes = &planner.last_plan().changes;
    let (mut ids, mut evicting) = (Vec::new(), Vec::new());
    for c in changes {
        if let ResidencyChange::Evict(id) = *c
            && let Some(w) = world_ids[id.0 as usize]
        {
            ids.push(id);
            evicting.push(w);
        }
    }
    let read = if ids.is_empty() {
        None
    } else {
        Some(world.encode_snapshot(enc, &evicting)?)
    };
    let mut applied = Applied {
        pages: None,
        paged_out: 0,
        paged_in: 0,
        failed: Vec::new(),
    };
    for change in changes {
        match *change {
            ResidencyChange::Evict(id) => {
                if let Some(w) = world_ids[id.0 as usize].take() {
                    applied.paged_out += world.payload_bytes_of(w)?;
                    world.remove_surface(w)?;
                }
            }
            ResidencyChange::Admit(id) => {
                let ground = grounds.get(id.0 as usize).and_then(Option::as_ref);
                admit(
                    world,
                    pages,
                    world_ids,
                    (planner, ground),
                    enc,
                    id,
                    &mut applied,
                )?
            }
        }
    }
    applied.pages = read.map(|read| PageRead { read, ids });
    Ok(applied)
}

/// Give surface `id` its slot in the world: from its page when it has one, else untouched; laid on
/// its ground when it has one.
fn admit(
    world: &mut SnowWorld,
    pages: &mut PageStore,
    world_ids: &mut [Option<SurfaceId>],
    (planner, ground): (&Planner, Option<&ManagedGround>),
    enc: &mut wgpu::CommandEncoder,
    id: ManagedId,
    applied: &mut Applied,
) -> Result<()> {
    let at = planner.slot(id).map(|s| s.offset);
    let result = match pages.get(id.0) {
        Some(page) => {
            let snap = page.decompress()?;
            applied.paged_in += snap.words.len() as u64 * 4;
            world.restore_surface_with(&snap, at, Some(enc))
        }
        None => world.add_surface_with(planner.surface(id)?.clone(), Some(enc)),
    };
    match result {
        Ok(w) => {
            if let Some(g) = ground {
                world.set_ground_field(w, Some(g.field.clone()))?;
            }
            pages.take(id.0);
            world_ids[id.0 as usize] = Some(w);
        }
        Err(SnowError::PoolExhausted { name, .. }) => {
            tracing::warn!("the pool refused surface {name:?} that the planner expected to fit");
            applied.failed.push(id);
        }
        Err(e) => return Err(e),
    }
    Ok(())
}

/// The planned updates as catch-up layers. Frame by frame (the default), layer `j` holds the
/// `j`-th queued frame of every surface that has one (the first also catches snowfall up), so a
/// surface that waited goes through the same steps as one updated in every frame; with
/// [`CatchUp::Union`], one layer holds everything queued.
pub(super) fn catch_up_layers<'a>(
    world_ids: &[Option<SurfaceId>],
    updates: &'a [PlannedUpdate],
    catch_up: CatchUp,
) -> Vec<Vec<SurfaceUpdate<'a>>> {
    let mut runs: Vec<(SurfaceId, f32, Vec<&'a [Deformer]>)> = Vec::new();
    for u in updates {
        let Some(w) = world_ids[u.surface.0 as usize] else {
            continue;
        };
        // Runs of imprints of one frame (the queue is in frame order).
        let mut frames: Vec<&'a [Deformer]> = Vec::new();
        let mut start = 0;
        for k in 1..=u.imprints.len() {
            if k == u.imprints.len() || u.frames.get(k) != u.frames.get(start) {
                frames.push(&u.imprints[start..k]);
                start = k;
            }
        }
        if frames.is_empty() || catch_up == CatchUp::Union {
            frames = vec![&u.imprints[..]];
        }
        runs.push((w, u.elapsed, frames));
    }
    let layers = runs.iter().map(|r| r.2.len()).max().unwrap_or(0);
    (0..layers)
        .map(|j| {
            runs.iter()
                .filter_map(|(w, elapsed, frames)| {
                    frames.get(j).map(|d| SurfaceUpdate {
                        surface: *w,
                        elapsed: if j == 0 { *elapsed } else { 0.0 },
                        deformers: d,
                    })
                })
                .collect()
        })
        .collect()
}
