//! Applying a plan to the world: residency changes, then the planned updates.

use super::pages::{Page, PageStore};
use super::{CatchUp, ManagedId, PlannedUpdate, Planner, ResidencyChange};
use crate::deformer::Deformer;
use crate::error::{Result, SnowError};
use crate::surface::SurfaceId;
use crate::world::{SnowWorld, SurfaceUpdate};

/// Apply a plan's residency changes in order: evictions page out (every heightmap to evict is
/// read back in one round trip, before any slot is reused), admissions page in or start fresh.
/// Returns the bytes paged out and in, and the admissions the world refused.
pub(super) fn apply_changes(
    world: &mut SnowWorld,
    pages: &mut PageStore,
    world_ids: &mut [Option<SurfaceId>],
    planner: &Planner,
) -> Result<(u64, u64, Vec<ManagedId>)> {
    let changes = &planner.last_plan().changes;
    let evicting: Vec<SurfaceId> = changes
        .iter()
        .filter_map(|c| match *c {
            ResidencyChange::Evict(id) => world_ids[id.0 as usize],
            ResidencyChange::Admit(_) => None,
        })
        .collect();
    let mut snaps = world.snapshot_surfaces(&evicting)?.into_iter();
    let (mut paged_out, mut paged_in) = (0, 0);
    let mut failed = Vec::new();
    for change in changes {
        match *change {
            ResidencyChange::Evict(id) => {
                if let Some(w) = world_ids[id.0 as usize].take() {
                    let snap = snaps.next().ok_or_else(|| {
                        SnowError::Readback("a page-out returned fewer surfaces".into())
                    })?;
                    paged_out += snap.words.len() as u64 * 4;
                    pages.put(id.0, Page::compress(snap));
                    world.remove_surface(w)?;
                }
            }
            ResidencyChange::Admit(id) => {
                let at = planner.slot(id).map(|s| s.offset);
                let result = match pages.get(id.0) {
                    Some(page) => {
                        let snap = page.decompress()?;
                        paged_in += snap.words.len() as u64 * 4;
                        world.restore_surface(&snap, at)
                    }
                    None => world.add_surface(planner.surface(id)?.clone()),
                };
                match result {
                    Ok(w) => {
                        pages.take(id.0);
                        world_ids[id.0 as usize] = Some(w);
                    }
                    Err(SnowError::PoolExhausted { name, .. }) => {
                        tracing::warn!(
                            "the pool refused surface {name:?} that the planner expected to fit"
                        );
                        failed.push(id);
                    }
                    Err(e) => return Err(e),
                }
            }
        }
    }
    Ok((paged_out, paged_in, failed))
}

/// Update the planned surfaces with their queued imprints. Frame by frame (the default), update `j`
/// holds the `j`-th queued frame of every surface that has one (the first also catches snowfall
/// up), so a surface that waited goes through the same steps as one updated in every frame; with
/// [`CatchUp::Union`], one update holds everything queued.
pub(super) fn update_planned(
    world: &mut SnowWorld,
    world_ids: &[Option<SurfaceId>],
    updates: &[PlannedUpdate],
    catch_up: CatchUp,
) -> Result<()> {
    let mut runs: Vec<(SurfaceId, f32, Vec<&[Deformer]>)> = Vec::new();
    for u in updates {
        let Some(w) = world_ids[u.surface.0 as usize] else {
            continue;
        };
        // Runs of imprints of one frame (the queue is in frame order).
        let mut frames: Vec<&[Deformer]> = Vec::new();
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
    for j in 0..layers {
        let batch: Vec<SurfaceUpdate<'_>> = runs
            .iter()
            .filter_map(|(w, elapsed, frames)| {
                frames.get(j).map(|d| SurfaceUpdate {
                    surface: *w,
                    elapsed: if j == 0 { *elapsed } else { 0.0 },
                    deformers: d,
                })
            })
            .collect();
        world.update(&batch)?;
    }
    Ok(())
}
