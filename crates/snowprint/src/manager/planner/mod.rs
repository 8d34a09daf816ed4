//! The pure-CPU half of the manager: which surfaces are active, which hold a heightmap, which are
//! updated this frame and with what. [`Planner::tick`] returns a [`Plan`] that
//! [`crate::manager::SnowManager`] applies to a [`crate::SnowWorld`]; without a GPU the planner can be
//! property-tested and benchmarked on its own.
//!
//! One tick, in order:
//! 1. **Touches.** Each deformer's swept bounds (the ball around its shape, swept from its previous
//!    pose) are looked up in the [`SurfaceIndex`] and checked against each candidate's capture
//!    volume in the surface's own frame. A touch queues the deformer on the surface
//!    ([`super::queue`]); no per-surface actor list is kept from one frame to the next.
//! 2. **Activity.** A surface of a loaded zone is active while it is in the camera's frustum
//!    (the bounding sphere of its box) and within `active_distance` of the eye (its box), while
//!    something touches it, or while imprints wait in its queue. A surface that stops being active
//!    keeps its slot until the memory is wanted.
//! 3. **Residency.** Active surfaces without a slot ask for one, most useful first; when the pool
//!    has no room, less useful residents are evicted (see [`Planner`] for the order): their
//!    heightmaps are paged out, and paged back in when they are admitted again. The planner keeps
//!    its own copy of the world's first-fit allocator, so it knows exactly what fits.
//! 4. **Budget.** Of the resident surfaces due for an update, at most `updates_per_frame` are chosen:
//!    the player's surfaces first (up to `player_slots`), then earliest deadline first, where a
//!    surface's deadline is the frame it became due plus a slack that grows with its distance.
//!
//! The tick and its first two steps are in `tick.rs`, residency in `admit.rs`, the budget in
//! `schedule.rs`; `surface.rs` holds what is kept per surface and `state.rs` the state for saves.

mod admit;
mod schedule;
mod state;
mod surface;
mod tick;

pub(crate) use state::PlannerState;
use surface::{ARRIVING, LISTED, PAGED, REMOVED, RESIDENT, SNOWFALL, WANTED};
use surface::{Managed, Rank, Status, TouchVolume};

use std::collections::{HashMap, VecDeque};

use glam::{Mat4, Vec3};

use super::quadtree::{Aabb, SurfaceIndex};
use super::queue::Imprint;
use super::{ManagedId, ManagerConfig, TickStats, ZoneId};
use crate::deformer::{Deformer, Shape};
use crate::error::{Result, SnowError};
use crate::mesh::MeshId;
use crate::pool::{Slot, SlotAllocator};
use crate::surface::SurfaceDesc;

/// Margin, metres, added to every touch test so that the planner's answer is a superset of the
/// world's own culling (float rounding between the two can never hide a touch).
pub(crate) const TOUCH_MARGIN: f32 = 1e-3;

/// The swept bounds of a deformer: the ball that holds its shape (a mesh's registered bound, from
/// `radii`; an unknown mesh's as large as any world) swept from its previous pose. The world draws
/// a moving mesh at sub-steps along its motion, which this ball holds too.
pub(super) fn sweep_with(radii: &[Option<f32>], d: &Deformer) -> (Vec3, Vec3, f32) {
    let r = match d.shape {
        Shape::Mesh(id) => radii.get(id.0 as usize).copied().flatten().unwrap_or(1e9),
        shape => shape.bounding_radius().unwrap_or(0.0),
    };
    (d.previous.unwrap_or(d.pose).position, d.pose.position, r)
}

/// How the planner finds which surfaces a box overlaps.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Lookup {
    /// The quad tree (the default).
    #[default]
    QuadTree,
    /// Every surface tested against every box: the reference for tests and the benchmark.
    BruteForce,
}

/// A change of residency, applied in order (the world's allocator must see the same sequence as
/// the planner's copy).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ResidencyChange {
    /// Page the surface's heightmap out (to the manager's page store) and free its slot.
    Evict(ManagedId),
    /// Give the surface a slot: its paged heightmap when it has one
    /// ([`Planner::is_paged`] before the tick), else fresh, untouched snow.
    Admit(ManagedId),
}

/// One surface update of a plan.
#[derive(Clone, Debug, PartialEq)]
pub struct PlannedUpdate {
    /// The surface.
    pub surface: ManagedId,
    /// Seconds since the surface's last update (or since it got its slot): replenishment.
    pub elapsed: f32,
    /// Frames the surface waited since it became due.
    pub wait_frames: u64,
    /// Everything that touched it since its last update: swept shapes, one per frame and deformer
    /// after de-duplication (see [`crate::low_level::queue`]), in frame order.
    pub imprints: Vec<Deformer>,
    /// The frame of each imprint: the update captures each frame's imprints on their own, in
    /// order, as if the surface had been updated in every frame.
    pub frames: Vec<u64>,
}

/// What one tick decided.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Plan {
    /// Evictions and admissions, in the order they must be applied, before the updates.
    pub changes: Vec<ResidencyChange>,
    /// The surfaces to update this frame, at most `updates_per_frame`, player's first.
    pub updates: Vec<PlannedUpdate>,
    /// The tick's statistics.
    pub stats: TickStats,
}

/// The planner. See the module docs for the tick, and `docs/MANAGER.md` for the bounds.
///
/// Eviction order when a surface needs room: residents of a lower class first (inactive ones that
/// kept their slot, least recently active first; then active ones; then touched ones), within a
/// class the farthest from the focus (the player, else the camera) first, and a resident of the
/// candidate's own class only when it is clearly farther (hysteresis). A candidate that would have
/// to evict something at least as useful as itself waits without a slot; its queued imprints wait
/// with it.
#[derive(Clone, Debug)]
pub struct Planner {
    config: ManagerConfig,
    lookup: Lookup,
    /// Per surface, by index: hot state, touch volume, and the rest.
    status: Vec<Status>,
    volumes: Vec<TouchVolume>,
    surfaces: Vec<Managed>,
    index: SurfaceIndex,
    index_dirty: bool,
    alloc: SlotAllocator,
    zones: HashMap<ZoneId, usize>,
    zone_loaded: Vec<bool>,
    zone_members: Vec<Vec<u32>>,
    mesh_radius: Vec<Option<f32>>,
    /// Ticks done; stamps compare with it.
    tick: u64,
    time: f64,
    active: Vec<u32>,
    active_next: Vec<u32>,
    resident: Vec<u32>,
    /// Surfaces that may have queued imprints (pruned lazily).
    queued: Vec<u32>,
    touched: Vec<u32>,
    scratch: Vec<u32>,
    sweeps: Vec<(Vec3, Vec3, f32)>,
    /// Names of surfaces evicted between ticks (zone unloads, removals), reported by the next tick.
    evicted_between: Vec<String>,
    /// Slot bytes of the paged surfaces: a bound on what the page store holds (a page is never
    /// larger than its slot), checked against `ManagerConfig::page_bytes` before evicting.
    paged_bound: u64,
    /// Entries merged by [`super::queue::bound`] since the planner was made.
    merged_total: u64,
    /// Updates a frame left to the manager's terrain window levels (`reserve_updates`).
    reserved_updates: usize,
    plan: Plan,
}

impl Planner {
    /// A planner with no surfaces. Checks the configuration.
    pub fn new(config: &ManagerConfig) -> Result<Self> {
        config.validate()?;
        Ok(Self {
            alloc: SlotAllocator::new(config.pool_bytes),
            config: config.clone(),
            lookup: Lookup::QuadTree,
            status: Vec::new(),
            volumes: Vec::new(),
            surfaces: Vec::new(),
            index: SurfaceIndex::default(),
            index_dirty: false,
            zones: HashMap::new(),
            zone_loaded: Vec::new(),
            zone_members: Vec::new(),
            mesh_radius: Vec::new(),
            tick: 0,
            time: 0.0,
            active: Vec::new(),
            active_next: Vec::new(),
            resident: Vec::new(),
            queued: Vec::new(),
            touched: Vec::new(),
            scratch: Vec::new(),
            sweeps: Vec::new(),
            evicted_between: Vec::new(),
            paged_bound: 0,
            merged_total: 0,
            reserved_updates: 0,
            plan: Plan::default(),
        })
    }

    /// Choose the lookup (the quad tree by default; brute force for reference runs).
    pub fn set_lookup(&mut self, lookup: Lookup) {
        self.lookup = lookup;
    }

    /// The configuration.
    pub fn config(&self) -> &ManagerConfig {
        &self.config
    }

    fn zone_index(&mut self, zone: ZoneId) -> usize {
        *self.zones.entry(zone).or_insert_with(|| {
            self.zone_loaded.push(true);
            self.zone_members.push(Vec::new());
            self.zone_loaded.len() - 1
        })
    }

    /// Register a surface in a zone (zones are loaded until unloaded). It holds no heightmap until
    /// it becomes active.
    ///
    /// Fails with [`SnowError::PoolExhausted`] when the surface is larger than the whole pool (it
    /// could never hold a heightmap).
    pub fn add_surface(&mut self, desc: &SurfaceDesc, zone: ZoneId) -> Result<ManagedId> {
        desc.validate()?;
        let layout = desc.layout();
        let needed = self.config.format.slot_bytes(layout.width, layout.height);
        if needed > self.alloc.budget() {
            return Err(SnowError::PoolExhausted {
                name: desc.name.clone(),
                needed,
                free: self.alloc.budget(),
                budget: self.alloc.budget(),
            });
        }
        let index = u32::try_from(self.surfaces.len()).map_err(|_| SnowError::InvalidSurface {
            name: desc.name.clone(),
            what: "surface count",
            value: self.surfaces.len().to_string(),
            expected: "below 2^32",
        })?;
        let zone = self.zone_index(zone);
        let top = desc.snow_depth + self.config.capture.ankle_height;
        // The surface's capture region, grown by the apron: a deformer that presses only a
        // neighbour's edge column reaches this surface's blur too, and is queued here.
        let half = region_half(desc);
        let rot = desc.rotation();
        let ext = (rot * Vec3::new(half.x, 0.0, half.y))
            .abs()
            .max((rot * Vec3::new(half.x, 0.0, -half.y)).abs());
        let bounds = Aabb::new(
            desc.center - Vec3::new(ext.x, 0.0, ext.z),
            desc.center + Vec3::new(ext.x, top, ext.z),
        );
        let mut status = Status {
            bounds,
            touched: 0,
            player: 0,
            active: 0,
            // A slot is at most 512 x 512 texels x 16 bytes: 4 MiB.
            bytes: u32::try_from(needed).unwrap_or(u32::MAX),
            zone: zone as u32,
            queue_len: 0,
            flags: 0,
        };
        status.set(SNOWFALL, desc.replenish_rate > 0.0);
        self.status.push(status);
        self.volumes.push(TouchVolume::new(
            desc.world_to_local(),
            half,
            top,
            zone as u32,
        ));
        self.surfaces.push(Managed::new(desc.clone()));
        self.zone_members[zone].push(index);
        self.index_dirty = true;
        Ok(ManagedId(index))
    }

    /// Lay a surface's touch volume and bounds on its ground: `range` is the lowest and the
    /// highest base of its ground field (local metres, [`crate::GroundField::range`]; `(0, 0)`
    /// flat), so the volume runs from the lowest base to the highest base plus the frustum.
    pub fn set_ground_range(&mut self, id: ManagedId, range: (f32, f32)) -> Result<()> {
        let desc = self.get(id)?.desc.clone();
        let i = id.0 as usize;
        let (lo, hi) = range;
        let top = desc.snow_depth + self.config.capture.ankle_height;
        let zone = self.volumes[i].zone;
        // The volume's test starts at local y = 0: shift the frame down to the lowest base.
        let to_local = Mat4::from_translation(Vec3::new(0.0, -lo, 0.0)) * desc.world_to_local();
        self.volumes[i] = TouchVolume::new(to_local, region_half(&desc), hi - lo + top, zone);
        let b = &mut self.status[i].bounds;
        b.min.y = desc.center.y + lo;
        b.max.y = desc.center.y + hi + top;
        self.index_dirty = true;
        Ok(())
    }

    fn get(&self, id: ManagedId) -> Result<&Managed> {
        let i = id.0 as usize;
        match (self.surfaces.get(i), self.status.get(i)) {
            (Some(m), Some(s)) if !s.has(REMOVED) => Ok(m),
            _ => Err(SnowError::StaleHandle {
                what: "managed surface",
                index: id.0,
            }),
        }
    }

    /// Remove a surface for good. Returns whether it held a slot (the caller frees the world's).
    pub fn remove_surface(&mut self, id: ManagedId) -> Result<bool> {
        self.get(id)?;
        let had = self.release(id.0, true, false);
        let i = id.0 as usize;
        if self.status[i].has(PAGED) {
            self.status[i].set(PAGED, false);
            self.paged_bound -= self.status[i].bytes as u64;
        }
        self.status[i].set(REMOVED, true);
        self.clear_queue(id.0);
        self.surfaces[i].applied = Vec::new();
        self.index_dirty = true;
        Ok(had)
    }

    fn clear_queue(&mut self, index: u32) {
        self.surfaces[index as usize].queue = VecDeque::new();
        self.status[index as usize].queue_len = 0;
    }

    /// Free a surface's slot, if it has one, paging its heightmap out when `page`. `between` =
    /// outside a tick (reported by the next).
    fn release(&mut self, index: u32, between: bool, page: bool) -> bool {
        let s = &mut self.surfaces[index as usize];
        let Some(slot) = s.slot.take() else {
            return false;
        };
        self.alloc.free(slot);
        let st = &mut self.status[index as usize];
        st.set(RESIDENT, false);
        if page && !st.has(PAGED) {
            st.set(PAGED, true);
            self.paged_bound += st.bytes as u64;
        }
        s.due_since = None;
        s.applied.clear();
        let pos = s.resident_pos;
        let name = s.desc.name.clone();
        self.resident.swap_remove(pos);
        if let Some(&moved) = self.resident.get(pos) {
            self.surfaces[moved as usize].resident_pos = pos;
        }
        if between {
            self.evicted_between.push(name);
        } else {
            self.plan
                .changes
                .push(ResidencyChange::Evict(ManagedId(index)));
            self.plan.stats.evicted.push(name);
        }
        true
    }

    /// Mark a zone loaded: the surfaces that held a heightmap when it was unloaded ask for their
    /// slots back at the next tick (their pages come back in as room allows), the others when they
    /// become active; queued imprints land as they do.
    pub fn load_zone(&mut self, zone: ZoneId) {
        let z = self.zone_index(zone);
        if !self.zone_loaded[z] {
            self.zone_loaded[z] = true;
            for &m in &self.zone_members[z] {
                let st = &mut self.status[m as usize];
                if st.has(WANTED) && !st.has(REMOVED) && !st.has(LISTED) {
                    st.set(LISTED, true);
                    self.queued.push(m);
                }
            }
        }
    }

    /// Unload a zone: its surfaces page their heightmaps out and give their slots up at once;
    /// their queued imprints wait until the zone is loaded again (deformers over an unloaded zone
    /// are ignored). Returns the surfaces that held a slot, whose world heightmaps the caller must
    /// page out and free. A zone never seen before is created unloaded.
    pub fn unload_zone(&mut self, zone: ZoneId) -> Vec<ManagedId> {
        let z = self.zone_index(zone);
        self.zone_loaded[z] = false;
        let members = std::mem::take(&mut self.zone_members[z]);
        let mut freed = Vec::new();
        for &m in &members {
            if self.release(m, true, true) {
                freed.push(ManagedId(m));
                self.status[m as usize].set(WANTED, true);
            }
            self.status[m as usize].active = 0;
        }
        self.zone_members[z] = members;
        freed
    }

    /// Whether a zone is loaded (unknown zones are).
    pub fn zone_loaded(&self, zone: ZoneId) -> bool {
        self.zones.get(&zone).is_none_or(|&z| self.zone_loaded[z])
    }

    /// Tell the planner the bounding radius of a mesh deformer (after [`crate::SnowWorld::add_mesh`]
    /// or a re-pose).
    pub fn set_mesh_radius(&mut self, mesh: MeshId, radius: f32) -> Result<()> {
        if !(radius.is_finite() && radius >= 0.0) {
            return Err(SnowError::InvalidMesh {
                name: format!("mesh {}", mesh.0),
                reason: format!(
                    "bounding radius {radius} is not a finite number of metres, 0 or more"
                ),
            });
        }
        let i = mesh.0 as usize;
        if self.mesh_radius.len() <= i {
            self.mesh_radius.resize(i + 1, None);
        }
        self.mesh_radius[i] = Some(radius);
        Ok(())
    }

    /// Undo an admission the world could not carry out (it should never happen: the planner's
    /// allocator mirrors the world's). The surface goes back to waiting for a slot.
    pub fn admission_failed(&mut self, id: ManagedId) {
        if self
            .surfaces
            .get(id.0 as usize)
            .is_some_and(|s| s.slot.is_some())
        {
            self.release(id.0, true, false);
            self.evicted_between.pop();
        }
    }

    /// Surface `id`'s page is on its way from the GPU: it is not admitted until
    /// [`Planner::page_arrived`].
    pub(crate) fn page_arriving(&mut self, id: ManagedId) {
        if let Some(st) = self.status.get_mut(id.0 as usize) {
            st.set(ARRIVING, true);
        }
    }

    /// Surface `id`'s page has arrived in the page store.
    pub(crate) fn page_arrived(&mut self, id: ManagedId) {
        if let Some(st) = self.status.get_mut(id.0 as usize) {
            st.set(ARRIVING, false);
        }
    }

    /// Surface `id`'s page will never arrive (its tick was abandoned): it holds untouched snow
    /// from now on.
    pub(crate) fn page_lost(&mut self, id: ManagedId) {
        if let Some(st) = self.status.get_mut(id.0 as usize) {
            st.set(ARRIVING, false);
            if st.has(PAGED) {
                st.set(PAGED, false);
                self.paged_bound -= st.bytes as u64;
            }
        }
    }

    /// The plan of the last tick.
    pub fn last_plan(&self) -> &Plan {
        &self.plan
    }

    /// Registered surfaces, removed ones included (ids are never reused).
    pub fn len(&self) -> usize {
        self.surfaces.len()
    }

    /// Whether no surface was ever registered.
    pub fn is_empty(&self) -> bool {
        self.surfaces.is_empty()
    }

    /// A surface's description.
    pub fn surface(&self, id: ManagedId) -> Result<&SurfaceDesc> {
        Ok(&self.get(id)?.desc)
    }

    /// A surface's world-space bounds (capture volume).
    pub fn bounds(&self, id: ManagedId) -> Result<Aabb> {
        self.get(id)?;
        Ok(self.status[id.0 as usize].bounds)
    }

    /// Whether a surface was active in the last tick.
    pub fn is_active(&self, id: ManagedId) -> bool {
        self.get(id).is_ok() && self.tick > 0 && self.status[id.0 as usize].active == self.tick
    }

    /// Whether a surface holds a heightmap.
    pub fn is_resident(&self, id: ManagedId) -> bool {
        self.get(id).is_ok_and(|s| s.slot.is_some())
    }

    /// Whether a surface's heightmap is paged out (evicted, or its zone unloaded).
    pub fn is_paged(&self, id: ManagedId) -> bool {
        self.get(id).is_ok() && self.status[id.0 as usize].has(PAGED)
    }

    /// Queue entries merged into covering sweeps since the planner was made (see
    /// [`super::queue::bound`]).
    pub fn imprints_merged(&self) -> u64 {
        self.merged_total
    }

    /// Whether any queue holds an imprint of this (world) mesh.
    pub fn queues_hold_mesh(&self, mesh: MeshId) -> bool {
        let shape = Shape::Mesh(mesh);
        self.queued.iter().any(|&i| {
            self.status[i as usize].queue_len > 0
                && self.surfaces[i as usize]
                    .queue
                    .iter()
                    .any(|d| d.deformer.shape == shape)
        })
    }

    /// Forget what the last updates pressed with a mesh (it was re-posed in place: the same pose
    /// no longer presses the same shape).
    pub fn forget_applied_mesh(&mut self, mesh: MeshId) {
        let shape = Shape::Mesh(mesh);
        for &i in &self.resident {
            self.surfaces[i as usize]
                .applied
                .retain(|d| d.shape != shape);
        }
    }

    /// Change the budget of updates a frame (a flush runs with [`super::UNLIMITED`]).
    pub fn set_updates_per_frame(&mut self, k: usize) {
        self.config.updates_per_frame = k.max(1);
    }

    /// Leave `n` updates a frame to the manager's terrain window levels, which are updated every
    /// frame: the planner schedules `updates_per_frame - n` surfaces ([`Planner::budget`]).
    pub(crate) fn reserve_updates(&mut self, n: usize) {
        self.reserved_updates = n;
    }

    /// Updates a frame the planner schedules: `updates_per_frame` less those left to terrain
    /// window levels, at least 1.
    pub fn budget(&self) -> usize {
        self.config
            .updates_per_frame
            .saturating_sub(self.reserved_updates)
            .max(1)
    }

    /// Keep `slot` (a terrain window level's, placed by the world) out of the planner's hands:
    /// its copy of the world's allocator holds it, and no surface of the planner's is evicted for
    /// it. False when the copy does not have that range free (the two disagree).
    pub(crate) fn pin_slot(&mut self, slot: Slot) -> bool {
        self.alloc.alloc_at(slot.offset, slot.bytes).is_some()
    }

    /// Give a pinned slot back to the planner's copy of the allocator.
    pub(crate) fn unpin_slot(&mut self, slot: Slot) {
        self.alloc.free(slot);
    }

    /// Surfaces of loaded zones with imprints waiting (resident or not).
    pub fn pending_loaded_surfaces(&self) -> usize {
        self.queued
            .iter()
            .filter(|&&s| {
                let st = &self.status[s as usize];
                st.queue_len > 0 && !st.has(REMOVED) && self.zone_loaded[st.zone as usize]
            })
            .count()
    }

    /// The imprints queued on a surface, oldest first.
    pub fn queue(&self, id: ManagedId) -> Result<impl Iterator<Item = &Imprint>> {
        Ok(self.get(id)?.queue.iter())
    }

    /// The pool placement the planner expects the world to give this surface.
    pub fn slot(&self, id: ManagedId) -> Option<Slot> {
        self.get(id).ok().and_then(|s| s.slot)
    }

    /// The frame since which a resident surface waits for an update, if it does.
    pub fn due_since(&self, id: ManagedId) -> Option<u64> {
        self.get(id).ok().and_then(|s| s.due_since.map(|f| f - 1))
    }

    /// Imprints queued on a surface.
    pub fn queued_imprints(&self, id: ManagedId) -> usize {
        self.get(id).map_or(0, |s| s.queue.len())
    }

    /// Surfaces with imprints waiting (resident or not).
    pub fn pending_surfaces(&self) -> usize {
        self.queued
            .iter()
            .filter(|&&s| self.status[s as usize].queue_len > 0)
            .count()
    }

    /// Pool bytes in slots now (the planner's exact copy of the world's accounting).
    pub fn pool_used(&self) -> u64 {
        self.alloc.used()
    }

    /// The pool's budget, bytes.
    pub fn pool_budget(&self) -> u64 {
        self.alloc.budget()
    }

    /// Resident surfaces now.
    pub fn resident(&self) -> impl Iterator<Item = ManagedId> + '_ {
        self.resident.iter().map(|&i| ManagedId(i))
    }

    /// The frame number the next tick will have (0 before the first).
    pub fn next_frame(&self) -> u64 {
        self.tick
    }

    /// Updates guaranteed to non-player surfaces each frame: `K - min(K - 1, player_slots)` for a
    /// budget `K` ([`Planner::budget`]) of 2 or more, `1` for a budget of 1 (the player then gets no reserved slot).
    pub fn non_player_slots(&self) -> usize {
        let k = self.budget();
        let reserved = if k >= 2 {
            (k - 1).min(self.config.player_slots)
        } else {
            0
        };
        k - reserved
    }

    /// The starvation bound: a surface that holds a slot and becomes due is updated within
    /// `distance_slack_frames + floor((n - 1) / non_player_slots)` frames, where `n` is the largest
    /// number of due surfaces during its wait (see `docs/MANAGER.md` for the proof).
    pub fn wait_bound(&self, n: usize) -> u64 {
        self.config.distance_slack_frames as u64
            + (n.saturating_sub(1) / self.non_player_slots()) as u64
    }

    fn ensure_index(&mut self) {
        if self.index_dirty {
            let bounds: Vec<Option<Aabb>> = self
                .status
                .iter()
                .map(|s| (!s.has(REMOVED)).then_some(s.bounds))
                .collect();
            self.index = SurfaceIndex::build(&bounds);
            self.index_dirty = false;
        }
    }

    /// Fill `out` with the surfaces whose bounds overlap `q`.
    fn lookup_into(&mut self, q: &Aabb, out: &mut Vec<u32>) {
        out.clear();
        match self.lookup {
            Lookup::QuadTree => self.index.query(q, out),
            Lookup::BruteForce => {
                for (i, s) in self.status.iter().enumerate() {
                    if !s.has(REMOVED) && s.bounds.overlaps(q) {
                        out.push(i as u32);
                    }
                }
            }
        }
    }

    /// Swept bounds of a deformer: the sweep's two ends and a radius holding the shape.
    fn sweep_of(&self, d: &Deformer) -> Result<(Vec3, Vec3, f32)> {
        if let Shape::Mesh(id) = d.shape
            && self
                .mesh_radius
                .get(id.0 as usize)
                .copied()
                .flatten()
                .is_none()
        {
            return Err(SnowError::StaleHandle {
                what: "mesh",
                index: id.0,
            });
        }
        Ok(sweep_with(&self.mesh_radius, d))
    }

    fn rank(&self, index: u32, now: u64, focus: Option<Vec3>) -> Rank {
        let s = &self.status[index as usize];
        let class = if s.active != now {
            0
        } else if s.player == now {
            3
        } else if s.touched == now || s.queue_len > 0 {
            2
        } else {
            1
        };
        Rank {
            class,
            dist: focus.map_or(0.0, |f| s.bounds.distance_to(f)),
            last_active: s.active,
            index,
        }
    }
}

/// Half the sides of a surface's capture region: its rectangle grown by the capture's apron
/// (`capture::region`), what the world's plan culls against.
fn region_half(desc: &crate::SurfaceDesc) -> glam::Vec2 {
    let layout = desc.layout();
    crate::capture::CaptureVolume::of_region(desc.size * 0.5, layout.width, layout.height)
}
