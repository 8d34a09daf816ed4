//! Terrain windows run by the manager (`crate::Terrain`, `docs/ARCHITECTURE.md`, "The sliding
//! window"): their levels live in the manager's world, in the same pool and under the same
//! budget as its surfaces.
//!
//! - **Pool.** A level's slot is taken when the terrain is added and kept until it is removed;
//!   the planner's copy of the world's allocator holds it too (`Planner::pin_slot`), so the two
//!   keep agreeing and no surface is evicted for it or admitted into it.
//! - **Budget.** Every level is updated at every tick, with the tick's deformers and time (the
//!   player walks in the window, and the window follows the player): the planner schedules
//!   `updates_per_frame` less the levels (`Planner::budget`), so a tick updates at most
//!   `updates_per_frame` surfaces, levels included (`TickStats::updated` names them last).
//! - **Scrolling.** [`SnowManager::follow_terrain`] moves a window between ticks; its strips and
//!   pages are the terrain's own (`window/store.rs`).

use glam::Vec3;

use super::SnowManager;
use crate::error::{Result, SnowError};
use crate::pool::Slot;
use crate::surface::SurfaceId;
use crate::window::{Terrain, TerrainDesc};
use crate::world::SurfaceUpdate;

/// Handle of a terrain window in a [`SnowManager`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct ManagedTerrainId(u32);

impl ManagedTerrainId {
    /// Index of the terrain, in order of addition.
    pub fn index(self) -> u32 {
        self.0
    }

    /// The handle of the terrain added `index`-th (a handle that names no terrain is reported
    /// as [`SnowError::StaleHandle`] where it is used).
    pub fn from_index(index: u32) -> Self {
        Self(index)
    }
}

/// A terrain of the manager's and the pool slots its levels hold.
pub(super) struct ManagedTerrain {
    terrain: Terrain,
    slots: Vec<Slot>,
}

impl SnowManager {
    /// Add a terrain's sliding window centred on `focus`, in the manager's pool and under its
    /// budget (see the module docs): its levels take their slots now and keep them, and each is
    /// updated at every tick. Refused, in one sentence, and nothing added, for what
    /// [`Terrain::new`] refuses (the levels do not fit the pool's free room among them), while a
    /// tick is pending, or when the levels would leave the other surfaces no update a frame
    /// (`updates_per_frame` must exceed all the terrains' levels).
    pub fn add_terrain(&mut self, desc: TerrainDesc, focus: Vec3) -> Result<ManagedTerrainId> {
        self.not_pending()?;
        let levels = self.terrain_levels() + desc.levels.len();
        let budget = self.planner.config().updates_per_frame;
        if levels >= budget {
            return Err(SnowError::InvalidTerrain {
                name: desc.name.clone(),
                what: "its levels with the manager's other terrains'".into(),
                value: format!("{levels} updates a frame"),
                expected: format!(
                    "fewer than ManagerConfig::updates_per_frame ({budget}), which counts every level at every frame: raise it to at least {}",
                    levels + 1
                ),
            });
        }
        let terrain = Terrain::new(&mut self.world, desc, focus)?;
        let ids = terrain.surfaces();
        let mut slots = Vec::with_capacity(ids.len());
        for &id in &ids {
            let slot = self.world.slot_of(id)?;
            if !self.planner.pin_slot(slot) {
                // The planner's copy of the allocator disagrees with the world's: undo.
                for &s in &slots {
                    self.planner.unpin_slot(s);
                }
                for &id in &ids {
                    self.world.remove_surface(id)?;
                }
                return Err(SnowError::InvalidTerrain {
                    name: terrain.desc().name.clone(),
                    what: "a level's slot".into(),
                    value: format!("{} bytes at byte {}", slot.bytes, slot.offset),
                    expected: "free in the manager's copy of the pool's accounting as in the world's (they disagree: nothing was added)".into(),
                });
            }
            slots.push(slot);
        }
        self.terrains.push(Some(ManagedTerrain { terrain, slots }));
        self.planner.reserve_updates(levels);
        Ok(ManagedTerrainId(self.terrains.len() as u32 - 1))
    }

    /// Move a terrain's window to `focus` (see [`Terrain::follow`]); between ticks (refused with
    /// [`SnowError::FramePending`] while one is pending).
    pub fn follow_terrain(&mut self, id: ManagedTerrainId, focus: Vec3) -> Result<()> {
        self.with_terrain(id, |t, world| t.follow(world, focus))
    }

    /// Land a terrain's strips still on their way (see [`Terrain::flush`]), for reads.
    pub fn flush_terrain(&mut self, id: ManagedTerrainId) -> Result<()> {
        self.with_terrain(id, Terrain::flush)
    }

    /// Run `f` on a terrain and the world, between ticks.
    fn with_terrain(
        &mut self,
        id: ManagedTerrainId,
        f: impl FnOnce(&mut Terrain, &mut crate::SnowWorld) -> Result<()>,
    ) -> Result<()> {
        self.not_pending()?;
        let entry = self
            .terrains
            .get_mut(id.0 as usize)
            .and_then(Option::as_mut)
            .ok_or(stale(id))?;
        f(&mut entry.terrain, &mut self.world)
    }

    /// A terrain of the manager's (its levels are surfaces of [`SnowManager::world`]).
    pub fn terrain(&self, id: ManagedTerrainId) -> Result<&Terrain> {
        self.terrains
            .get(id.0 as usize)
            .and_then(Option::as_ref)
            .map(|t| &t.terrain)
            .ok_or(stale(id))
    }

    /// Remove a terrain: its levels leave the world and give their slots back. Its handle is
    /// stale afterwards.
    pub fn remove_terrain(&mut self, id: ManagedTerrainId) -> Result<()> {
        self.not_pending()?;
        let gone = self
            .terrains
            .get_mut(id.0 as usize)
            .and_then(Option::take)
            .ok_or(stale(id))?;
        for s in gone.terrain.surfaces() {
            self.world.remove_surface(s)?;
        }
        for s in gone.slots {
            self.planner.unpin_slot(s);
        }
        self.planner.reserve_updates(self.terrain_levels());
        Ok(())
    }

    /// Levels of all the manager's terrains.
    pub(super) fn terrain_levels(&self) -> usize {
        self.level_ids().count()
    }

    /// Every terrain level's surface, terrains in order of addition, finest level first.
    pub(super) fn level_ids(&self) -> impl Iterator<Item = SurfaceId> + '_ {
        self.terrains
            .iter()
            .flatten()
            .flat_map(|t| t.terrain.surfaces())
    }

    /// Every terrain the manager runs, in order of addition, with its name: after
    /// [`SnowManager::load`] the same handles as in the manager that was saved (a removed
    /// terrain's handle stays stale).
    pub fn terrain_ids(&self) -> impl Iterator<Item = (ManagedTerrainId, &str)> {
        self.terrains.iter().enumerate().filter_map(|(i, t)| {
            t.as_ref()
                .map(|t| (ManagedTerrainId(i as u32), t.terrain.desc().name.as_str()))
        })
    }

    /// The handle of the terrain named `name`, if any (the first, if several).
    pub fn terrain_named(&self, name: &str) -> Option<ManagedTerrainId> {
        self.terrain_ids().find(|t| t.1 == name).map(|t| t.0)
    }

    /// Land every terrain's strips still on their way (a save needs them in the stores).
    pub(super) fn flush_terrains(&mut self) -> Result<()> {
        for t in self.terrains.iter_mut().flatten() {
            t.terrain.flush(&mut self.world)?;
        }
        Ok(())
    }

    /// The live terrains with their handles' indices, in order.
    pub(super) fn live_terrains(&self) -> impl Iterator<Item = (u32, &Terrain)> {
        self.terrain_ids()
            .filter_map(|(id, _)| self.terrain(id).ok().map(|t| (id.0, t)))
    }

    /// Put a terrain restored from a save under handle `index` (after the terrains of lower
    /// handles): its levels' slots pinned in the planner as `add_terrain` pins them, the levels'
    /// updates reserved. Refused when the planner's copy of the pool does not have the slots
    /// free (the save is checked against that before anything is built).
    pub(super) fn put_restored_terrain(&mut self, index: u32, terrain: Terrain) -> Result<()> {
        let i = index as usize;
        if i < self.terrains.len() {
            return Err(SnowError::SaveContent(format!(
                "terrain {:?}'s handle {index} is taken",
                terrain.desc().name
            )));
        }
        let mut slots = Vec::new();
        for id in terrain.surfaces() {
            let slot = self.world.slot_of(id)?;
            if !self.planner.pin_slot(slot) {
                return Err(SnowError::SaveContent(format!(
                    "terrain {:?}'s level slot at byte {} overlaps a surface's",
                    terrain.desc().name,
                    slot.offset
                )));
            }
            slots.push(slot);
        }
        self.terrains.resize_with(i, || None);
        self.terrains.push(Some(ManagedTerrain { terrain, slots }));
        self.planner.reserve_updates(self.terrain_levels());
        Ok(())
    }
}

/// The error for a terrain handle the manager does not hold.
fn stale(id: ManagedTerrainId) -> SnowError {
    SnowError::StaleHandle {
        what: "terrain",
        index: id.0,
    }
}

/// The updates of every level of `levels` this tick: `dt` of replenishment and every deformer.
pub(super) fn level_updates<'a>(
    levels: &[SurfaceId],
    dt: f32,
    deformers: &'a [crate::deformer::Deformer],
) -> Vec<SurfaceUpdate<'a>> {
    levels
        .iter()
        .map(|&surface| SurfaceUpdate {
            surface,
            elapsed: dt,
            deformers,
        })
        .collect()
}
