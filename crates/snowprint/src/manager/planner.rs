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

use std::collections::{HashMap, VecDeque};

use glam::{Mat4, Vec2, Vec3, Vec4};

use super::quadtree::{Aabb, SurfaceIndex};
use super::queue::{self, Imprint};
use super::{CameraView, ManagedDeformer, ManagedId, ManagerConfig, TickStats, ZoneId};
use crate::deformer::{Deformer, Shape};
use crate::error::{Result, SnowError};
use crate::mesh::MeshId;
use crate::pool::{Slot, SlotAllocator};
use crate::surface::SurfaceDesc;

/// Margin, metres, added to every touch test so that the planner's answer is a superset of the
/// world's own culling (float rounding between the two can never hide a touch).
pub const TOUCH_MARGIN: f32 = 1e-3;

/// A candidate for a slot evicts a resident of its own class only when the resident is farther by
/// this factor ...
const HYSTERESIS_FACTOR: f32 = 1.25;
/// ... plus this many metres (so that two surfaces at similar distances do not trade one slot
/// back and forth as the focus moves).
const HYSTERESIS_METRES: f32 = 1.0;

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
    /// after de-duplication (see [`super::queue`]), in frame order.
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

/// Usefulness of a surface for memory: which class, then distance (or, for inactive surfaces that
/// keep their slot, when they were last active).
#[derive(Clone, Copy, Debug)]
struct Rank {
    /// 0 inactive (kept), 1 active, 2 touched or with queued imprints, 3 touched by the player.
    class: u8,
    dist: f32,
    last_active: u64,
    index: u32,
}

impl Rank {
    /// Order from least to most useful: class, then (inactive) least recently active first or
    /// (active) farthest first, then index.
    fn least_useful_first(a: &Rank, b: &Rank) -> std::cmp::Ordering {
        a.class
            .cmp(&b.class)
            .then_with(|| {
                if a.class == 0 {
                    a.last_active.cmp(&b.last_active)
                } else {
                    b.dist.total_cmp(&a.dist)
                }
            })
            .then(b.index.cmp(&a.index))
    }

    /// Whether a candidate for a slot may evict this resident.
    fn evictable_for(&self, candidate: &Rank) -> bool {
        self.class < candidate.class
            || (self.class == candidate.class
                && self.class > 0
                && self.dist > candidate.dist * HYSTERESIS_FACTOR + HYSTERESIS_METRES)
    }
}

/// A [`Rank`] ordered by usefulness (most useful is greatest), for the candidates' heap.
#[derive(Clone, Copy, Debug)]
struct ByUse(Rank);

impl PartialEq for ByUse {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == std::cmp::Ordering::Equal
    }
}

impl Eq for ByUse {}

impl PartialOrd for ByUse {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for ByUse {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        Rank::least_useful_first(&self.0, &other.0)
    }
}

const RESIDENT: u8 = 1;
const REMOVED: u8 = 2;
/// Listed in [`Planner::queued`].
const LISTED: u8 = 4;
/// Snow falls on it (replenish rate above 0).
const SNOWFALL: u8 = 8;
/// Its heightmap is in the page store (it was evicted, or its zone unloaded).
const PAGED: u8 = 16;
/// Resident when its zone was unloaded: paged back in as soon as the zone loads and there is room.
const WANTED: u8 = 32;

/// What the per-tick passes over touched, active and waiting surfaces read and write, in one cache
/// line per surface: a city with hundreds of surfaces waiting for memory is walked several times a
/// tick, and the rest of a surface's state (its description, queue, slot) stays cold.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
struct Status {
    bounds: Aabb,
    /// Tick stamps: last touched, last touched by the player, last active.
    touched: u64,
    player: u64,
    active: u64,
    /// Pool bytes of its slot (at most 4 MiB: 512 x 512 texels at 32 bits with normals).
    bytes: u32,
    zone: u32,
    queue_len: u32,
    flags: u8,
}

impl Status {
    fn has(&self, flag: u8) -> bool {
        self.flags & flag != 0
    }

    fn set(&mut self, flag: u8, on: bool) {
        if on {
            self.flags |= flag;
        } else {
            self.flags &= !flag;
        }
    }
}

/// The rest of a surface's state.
#[derive(Clone, Debug)]
struct Managed {
    desc: SurfaceDesc,
    slot: Option<Slot>,
    /// Position in [`Planner::resident`] while resident.
    resident_pos: usize,
    queue: VecDeque<Imprint>,
    /// What the last update captured (cleared when the heightmap is lost).
    applied: Vec<Deformer>,
    due_since: Option<u64>,
    last_update_time: f64,
    /// Until when (seconds) snowfall still has something to refill.
    pressed_until: f64,
}

impl Managed {
    fn new(desc: SurfaceDesc) -> Self {
        Self {
            desc,
            slot: None,
            resident_pos: 0,
            queue: VecDeque::new(),
            applied: Vec::new(),
            due_since: None,
            last_update_time: 0.0,
            pressed_until: 0.0,
        }
    }
}

/// What the touch test reads of a surface, in one cache line: a tick tests thousands of candidates
/// and few of them are touched.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
struct TouchVolume {
    /// The first three rows of the world-to-local transform.
    rows: [Vec4; 3],
    half: Vec2,
    /// Snow depth plus ankle height: the capture frustum's height.
    top: f32,
    zone: u32,
}

impl TouchVolume {
    fn new(to_local: Mat4, half: Vec2, top: f32, zone: u32) -> Self {
        let t = to_local.transpose();
        Self {
            rows: [t.x_axis, t.y_axis, t.z_axis],
            half,
            top,
            zone,
        }
    }

    #[inline]
    fn local(&self, p: Vec3) -> Vec3 {
        let p = p.extend(1.0);
        Vec3::new(
            self.rows[0].dot(p),
            self.rows[1].dot(p),
            self.rows[2].dot(p),
        )
    }

    /// The world's culling test, made conservative: a ball of radius `r` swept from `a` to `b`
    /// against the capture volume, in the surface's frame.
    #[inline]
    fn touched_by(&self, a: Vec3, b: Vec3, r: f32) -> bool {
        let (la, lb) = (self.local(a), self.local(b));
        let e = Vec3::splat(r + TOUCH_MARGIN);
        let (lo, hi) = (la.min(lb) - e, la.max(lb) + e);
        hi.x >= -self.half.x
            && lo.x <= self.half.x
            && hi.z >= -self.half.y
            && lo.z <= self.half.y
            && hi.y >= 0.0
            && lo.y < self.top
    }
}

/// A quick check that a deformer's numbers are usable (finite, sizes above 0); the full check, with
/// its message, runs only when this one fails.
fn plausible(d: &Deformer) -> bool {
    let sizes = match d.shape {
        Shape::Sphere { radius } => radius > 0.0 && radius.is_finite(),
        Shape::Capsule {
            radius,
            half_height,
        } => radius > 0.0 && (radius + half_height).is_finite() && half_height >= 0.0,
        Shape::Box { half_extents } => half_extents.min_element() > 0.0 && half_extents.is_finite(),
        Shape::Mesh(_) => true,
    };
    let prev = d.previous.unwrap_or(d.pose);
    sizes
        && d.pose.position.is_finite()
        && prev.position.is_finite()
        && d.pose.rotation.is_finite()
        && prev.rotation.is_finite()
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
    /// Entries merged by [`queue::bound`] since the planner was made.
    merged_total: u64,
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
        let half = desc.size * 0.5;
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
    /// [`queue::bound`]).
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
    /// budget `K` of 2 or more, `1` for a budget of 1 (the player then gets no reserved slot).
    pub fn non_player_slots(&self) -> usize {
        let k = self.config.updates_per_frame;
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
        match d.shape {
            Shape::Mesh(id) => {
                let r = self
                    .mesh_radius
                    .get(id.0 as usize)
                    .copied()
                    .flatten()
                    .ok_or(SnowError::StaleHandle {
                        what: "mesh",
                        index: id.0,
                    })?;
                // The world draws a moving mesh at sub-steps along its motion: the ball of its
                // bound swept from the previous pose holds them all.
                Ok((d.previous.unwrap_or(d.pose).position, d.pose.position, r))
            }
            shape => {
                let r = shape.bounding_radius().unwrap_or(0.0);
                Ok((d.previous.unwrap_or(d.pose).position, d.pose.position, r))
            }
        }
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

    /// Run one frame: `dt` seconds passed, the camera (if any) looks at the world and the deformers
    /// are posed as at the end of the frame (with `previous` = last frame's pose for a sweep).
    /// Everything is checked before anything changes.
    pub fn tick(
        &mut self,
        dt: f32,
        camera: Option<&CameraView>,
        deformers: &[ManagedDeformer],
    ) -> Result<&Plan> {
        if !(dt.is_finite() && dt >= 0.0) {
            return Err(SnowError::InvalidTimeStep { dt });
        }
        let frustum = camera.map(CameraView::frustum).transpose()?;
        let mut sweeps = std::mem::take(&mut self.sweeps);
        sweeps.clear();
        for (i, d) in deformers.iter().enumerate() {
            if !plausible(&d.deformer)
                && let Err(e) = d.deformer.validate(&format!("#{i}"))
            {
                self.sweeps = sweeps;
                return Err(e);
            }
            match self.sweep_of(&d.deformer) {
                Ok(sweep) => sweeps.push(sweep),
                Err(e) => {
                    self.sweeps = sweeps;
                    return Err(e);
                }
            }
        }
        self.ensure_index();
        self.tick += 1;
        self.time += dt as f64;
        let now = self.tick;
        self.plan.changes.clear();
        self.plan.updates.clear();
        self.plan.stats = TickStats {
            frame: now - 1,
            evicted: std::mem::take(&mut self.evicted_between),
            ..TickStats::default()
        };
        let mut scratch = std::mem::take(&mut self.scratch);

        // 1. Touches.
        self.touched.clear();
        // The deformers themselves are read only where they touch something.
        for (k, &(a, b, r)) in sweeps.iter().enumerate() {
            let m = Vec3::splat(r + TOUCH_MARGIN);
            self.lookup_into(&Aabb::new(a.min(b) - m, a.max(b) + m), &mut scratch);
            for &i in &scratch {
                let v = &self.volumes[i as usize];
                if !v.touched_by(a, b, r) || !self.zone_loaded[v.zone as usize] {
                    continue;
                }
                let d = &deformers[k];
                let st = &mut self.status[i as usize];
                if st.touched != now {
                    st.touched = now;
                    self.touched.push(i);
                }
                if d.player {
                    st.player = now;
                }
                let m = &mut self.surfaces[i as usize];
                let skip_applied = !st.has(SNOWFALL);
                queue::push(&mut m.queue, &m.applied, skip_applied, now, d.deformer);
                st.queue_len = m.queue.len() as u32;
                if st.queue_len > 0 && !st.has(LISTED) {
                    st.set(LISTED, true);
                    self.queued.push(i);
                }
            }
        }
        self.sweeps = sweeps;
        self.plan.stats.touched = self.touched.len();
        let focus = deformers
            .iter()
            .find(|d| d.player)
            .map(|d| d.deformer.pose.position)
            .or(camera.map(|c| c.eye));

        // 2. Activity.
        self.active_next.clear();
        if let (Some(cam), Some(frustum)) = (camera, &frustum) {
            let reach = Vec3::splat(self.config.active_distance);
            self.lookup_into(&Aabb::new(cam.eye - reach, cam.eye + reach), &mut scratch);
            for &i in &scratch {
                let s = &self.status[i as usize];
                // The bounding sphere of the surface's box.
                let (centre, radius) = (
                    (s.bounds.min + s.bounds.max) * 0.5,
                    (s.bounds.max - s.bounds.min).length() * 0.5,
                );
                if self.zone_loaded[s.zone as usize]
                    && s.bounds.distance_to(cam.eye) <= self.config.active_distance
                    && frustum.sees(centre, radius)
                {
                    self.activate(i, now);
                }
            }
        }
        for k in 0..self.touched.len() {
            self.activate(self.touched[k], now);
        }
        let mut k = 0;
        while k < self.queued.len() {
            let i = self.queued[k];
            let s = &mut self.status[i as usize];
            if (s.queue_len == 0 && !s.has(WANTED)) || s.has(REMOVED) {
                s.set(LISTED, false);
                self.queued.swap_remove(k);
                continue;
            }
            if self.zone_loaded[s.zone as usize] {
                self.activate(i, now);
            }
            k += 1;
        }
        let previous = std::mem::take(&mut self.active);
        // In index order, so that the plan does not depend on the order of lookups.
        let mut gone: Vec<u32> = previous
            .iter()
            .copied()
            .filter(|&i| {
                let s = &self.status[i as usize];
                s.active != now && !s.has(REMOVED)
            })
            .collect();
        gone.sort_unstable();
        // An inactive surface keeps its heightmap until the memory is wanted.
        for i in gone {
            self.surfaces[i as usize].due_since = None;
        }
        self.active = std::mem::take(&mut self.active_next);
        self.active_next = previous;
        self.plan.stats.active = self.active.len();

        // 3. Residency.
        self.admit(now, focus);

        // 4. Budget.
        self.schedule(now, focus);

        // 5. The queues of surfaces still waiting are bounded, conservatively.
        self.bound_queues();

        self.scratch = scratch;
        let st = &mut self.plan.stats;
        st.resident = self.resident.len();
        st.pool_bytes_used = self.alloc.used();
        st.pool_bytes_budget = self.alloc.budget();
        let mut waiting_for_memory = 0;
        let mut queued = 0;
        for &i in &self.queued {
            let s = &self.status[i as usize];
            queued += s.queue_len as usize;
            if !s.has(RESIDENT) && s.queue_len > 0 && s.active == now {
                waiting_for_memory += 1;
            }
        }
        st.queued_imprints = queued;
        st.waiting_for_memory = waiting_for_memory;
        Ok(&self.plan)
    }

    /// Bound the queue of every surface left waiting this tick (see [`queue::bound`]).
    fn bound_queues(&mut self) {
        let cap = self.config.queue_cap;
        let mut merged = 0;
        for k in 0..self.queued.len() {
            let i = self.queued[k] as usize;
            if (self.status[i].queue_len as usize) <= cap {
                continue;
            }
            let radii = &self.mesh_radius;
            let radius = |shape: &Shape| match shape {
                Shape::Mesh(id) => radii.get(id.0 as usize).copied().flatten().unwrap_or(0.0),
                s => s.bounding_radius().unwrap_or(0.0),
            };
            let q = &mut self.surfaces[i].queue;
            merged += queue::bound(q, cap, radius) as u64;
            self.status[i].queue_len = q.len() as u32;
        }
        self.plan.stats.imprints_merged = merged;
        self.merged_total += merged;
    }

    fn activate(&mut self, i: u32, now: u64) {
        let s = &mut self.status[i as usize];
        if s.active != now {
            s.active = now;
            self.active_next.push(i);
        }
    }

    /// Give slots to active surfaces without one, most useful first, evicting less useful ones.
    fn admit(&mut self, now: u64, focus: Option<Vec3>) {
        let mut victims: Vec<Rank> = self
            .resident
            .iter()
            .map(|&i| self.rank(i, now, focus))
            .collect();
        victims.sort_unstable_by(Rank::least_useful_first);
        let weakest = victims.first().copied();
        let largest_free = self.alloc.largest_free();
        let mut candidates: Vec<ByUse> = Vec::new();
        let mut best: Option<ByUse> = None;
        for &i in &self.active {
            let s = &self.status[i as usize];
            if s.has(RESIDENT) {
                continue;
            }
            let r = ByUse(self.rank(i, now, focus));
            // Cheap filter: it fits as things are, or it could evict the weakest resident.
            if s.bytes as u64 <= largest_free || weakest.is_some_and(|w| w.evictable_for(&r.0)) {
                best = best.max(Some(r));
                candidates.push(r);
            }
        }
        let Some(best) = best else { return };
        // The largest room any candidate can make: what the most useful one frees by evicting all
        // it may (eviction is monotone in usefulness). Larger candidates cannot get a slot now.
        let mut trial = self.alloc.clone();
        for v in victims.iter().take_while(|v| v.evictable_for(&best.0)) {
            if let Some(slot) = self.surfaces[v.index as usize].slot {
                trial.free(slot);
            }
        }
        let room = trial.largest_free();
        candidates.retain(|c| self.status[c.0.index as usize].bytes as u64 <= room);
        let smallest = candidates
            .iter()
            .map(|c| self.status[c.0.index as usize].bytes as u64)
            .min()
            .unwrap_or(u64::MAX);
        // Most useful first, popped only as far as needed (a heap builds in linear time; a city of
        // walkers can have hundreds of candidates for a handful of slots).
        let mut candidates = std::collections::BinaryHeap::from(candidates);
        let mut evicted = vec![false; victims.len()];
        let mut weakest_alive = 0;
        let mut chosen: Vec<usize> = Vec::new();
        // Evicting can only get less from here on: a candidate at least this large cannot fit.
        let mut hopeless = u64::MAX;
        while let Some(ByUse(cand)) = candidates.pop() {
            while weakest_alive < victims.len() && evicted[weakest_alive] {
                weakest_alive += 1;
            }
            let can_evict = victims
                .get(weakest_alive)
                .is_some_and(|v| v.evictable_for(&cand));
            // Eviction is monotone in usefulness: if this candidate cannot evict the weakest
            // resident, no later (less useful) one can; only free room is left for them.
            let free = self.alloc.largest_free();
            if (!can_evict || smallest >= hopeless) && free < smallest {
                break;
            }
            let bytes = self.status[cand.index as usize].bytes as u64;
            if bytes <= free
                && let Some(slot) = self.alloc.alloc(bytes)
            {
                self.give_slot(cand.index, slot);
                continue;
            }
            if !can_evict || bytes >= hopeless {
                continue;
            }
            // Try evicting the least useful residents, on a copy, until it fits.
            chosen.clear();
            let mut trial: Option<SlotAllocator> = None;
            let mut fits = false;
            // Every eviction pages a heightmap out: the page store must have room for it.
            let mut paged = self.paged_bound;
            for (v, rank) in victims.iter().enumerate().skip(weakest_alive) {
                if evicted[v] {
                    continue;
                }
                if !rank.evictable_for(&cand) {
                    break;
                }
                let Some(slot) = self.surfaces[rank.index as usize].slot else {
                    continue;
                };
                paged += self.status[rank.index as usize].bytes as u64;
                if paged > self.config.page_bytes {
                    break;
                }
                let t = trial.get_or_insert_with(|| self.alloc.clone());
                t.free(slot);
                chosen.push(v);
                if t.largest_free() >= bytes {
                    fits = true;
                    break;
                }
            }
            if !fits {
                // Later candidates can evict at most what this one could.
                hopeless = hopeless.min(bytes);
                continue;
            }
            for &v in &chosen {
                evicted[v] = true;
                self.release(victims[v].index, false, true);
            }
            if let Some(slot) = self.alloc.alloc(bytes) {
                self.give_slot(cand.index, slot);
            }
        }
    }

    fn give_slot(&mut self, index: u32, slot: Slot) {
        let s = &mut self.surfaces[index as usize];
        let st = &mut self.status[index as usize];
        s.slot = Some(slot);
        s.resident_pos = self.resident.len();
        if st.has(PAGED) {
            // Its heightmap comes back as it was: snowfall refills from its last update on.
            st.set(PAGED, false);
            self.paged_bound -= st.bytes as u64;
        } else {
            s.last_update_time = self.time;
            s.pressed_until = 0.0;
        }
        s.applied.clear();
        s.due_since = None;
        st.set(WANTED, false);
        st.set(RESIDENT, true);
        self.resident.push(index);
        self.plan
            .changes
            .push(ResidencyChange::Admit(ManagedId(index)));
    }

    /// Pick at most K due surfaces and hand them their queued imprints.
    fn schedule(&mut self, now: u64, focus: Option<Vec3>) {
        let slack_max = self.config.distance_slack_frames as u64;
        let reach = self.config.active_distance.max(f32::MIN_POSITIVE);
        // (deadline, due since, index, player)
        let mut due: Vec<(u64, u64, u32, bool)> = Vec::new();
        for &i in &self.resident {
            let st = &self.status[i as usize];
            if st.active != now {
                continue;
            }
            let s = &mut self.surfaces[i as usize];
            if s.due_since.is_none() {
                let replenish = st.has(SNOWFALL)
                    && s.pressed_until > s.last_update_time
                    && self.time - s.last_update_time >= self.config.replenish_interval as f64;
                if st.queue_len > 0 || replenish {
                    s.due_since = Some(now);
                }
            }
            let Some(since) = s.due_since else { continue };
            let player = st.player == now;
            let slack = if player {
                0
            } else if st.queue_len == 0 {
                slack_max
            } else {
                let d = focus.map_or(0.0, |f| st.bounds.distance_to(f));
                (slack_max as f32 * (d / reach).min(1.0)).round() as u64
            };
            due.push((since + slack, since, i, player));
        }
        self.plan.stats.due = due.len();
        let k = self.config.updates_per_frame;
        due.sort_unstable();
        let mut pick: Vec<u32> = Vec::with_capacity(k.min(due.len()));
        let mut max_wait = 0;
        if due.len() <= k {
            // Everything due fits: player's first, then by deadline.
            pick.extend(due.iter().filter(|d| d.3).map(|d| d.2));
            pick.extend(due.iter().filter(|d| !d.3).map(|d| d.2));
        } else {
            // The player's surfaces take up to the reserved slots, then earliest deadline first.
            let reserved = k - self.non_player_slots();
            let mut taken = vec![false; due.len()];
            for (n, d) in due.iter().enumerate() {
                if pick.len() >= reserved {
                    break;
                }
                if d.3 {
                    pick.push(d.2);
                    taken[n] = true;
                }
            }
            for (n, d) in due.iter().enumerate() {
                if pick.len() >= k {
                    break;
                }
                if !taken[n] {
                    pick.push(d.2);
                    taken[n] = true;
                }
            }
            for (n, &(_, since, _, _)) in due.iter().enumerate() {
                if !taken[n] {
                    max_wait = max_wait.max(now - since);
                }
            }
        }
        for i in pick {
            let time = self.time;
            let s = &mut self.surfaces[i as usize];
            let since = s.due_since.take().unwrap_or(now);
            let queued = std::mem::take(&mut s.queue);
            let frames: Vec<u64> = queued.iter().map(|e| e.frame).collect();
            let imprints: Vec<Deformer> = queued.into_iter().map(|e| e.deformer).collect();
            self.status[i as usize].queue_len = 0;
            let elapsed = (time - s.last_update_time) as f32;
            s.last_update_time = time;
            if !imprints.is_empty() && s.desc.replenish_rate > 0.0 {
                s.pressed_until = time + 1.0 / s.desc.replenish_rate as f64;
            }
            s.applied.clear();
            s.applied.extend_from_slice(&imprints);
            max_wait = max_wait.max(now - since);
            self.plan.stats.updated.push(s.desc.name.clone());
            self.plan.updates.push(PlannedUpdate {
                surface: ManagedId(i),
                elapsed,
                wait_frames: now - since,
                imprints,
                frames,
            });
        }
        self.plan.stats.max_wait_frames = max_wait;
    }
}

/// One surface of a [`PlannerState`].
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub(crate) struct SurfaceState {
    pub(crate) desc: SurfaceDesc,
    pub(crate) zone: ZoneId,
    pub(crate) removed: bool,
    pub(crate) paged: bool,
    pub(crate) wanted: bool,
    /// Tick stamps: last touched, by the player, last active.
    pub(crate) stamps: [u64; 3],
    /// `(offset, bytes)` of its slot while resident.
    pub(crate) slot: Option<(u64, u64)>,
    pub(crate) queue: Vec<Imprint>,
    pub(crate) applied: Vec<Deformer>,
    pub(crate) due_since: Option<u64>,
    pub(crate) last_update_time: f64,
    pub(crate) pressed_until: f64,
}

/// Everything a [`Planner`] decides from, for saves: a planner rebuilt from it plans exactly as
/// the one it was taken from.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub(crate) struct PlannerState {
    pub(crate) tick: u64,
    pub(crate) time: f64,
    pub(crate) merged_total: u64,
    /// Zones in the order the planner met them, with whether they are loaded.
    pub(crate) zones: Vec<(ZoneId, bool)>,
    /// Bounding radius of each world mesh, by its index.
    pub(crate) mesh_radius: Vec<Option<f32>>,
    pub(crate) surfaces: Vec<SurfaceState>,
    pub(crate) active: Vec<u32>,
    pub(crate) resident: Vec<u32>,
    pub(crate) queued: Vec<u32>,
    pub(crate) evicted_between: Vec<String>,
}

impl Planner {
    /// The planner's state (see [`PlannerState`]).
    pub(crate) fn state(&self) -> PlannerState {
        let mut zones = vec![(ZoneId(0), true); self.zone_loaded.len()];
        for (&id, &z) in &self.zones {
            zones[z] = (id, self.zone_loaded[z]);
        }
        PlannerState {
            tick: self.tick,
            time: self.time,
            merged_total: self.merged_total,
            zones,
            mesh_radius: self.mesh_radius.clone(),
            surfaces: self
                .surfaces
                .iter()
                .zip(&self.status)
                .map(|(m, st)| SurfaceState {
                    desc: m.desc.clone(),
                    zone: zones_id(&self.zones, st.zone),
                    removed: st.has(REMOVED),
                    paged: st.has(PAGED),
                    wanted: st.has(WANTED),
                    stamps: [st.touched, st.player, st.active],
                    slot: m.slot.map(|s| (s.offset, s.bytes)),
                    queue: m.queue.iter().copied().collect(),
                    applied: m.applied.clone(),
                    due_since: m.due_since,
                    last_update_time: m.last_update_time,
                    pressed_until: m.pressed_until,
                })
                .collect(),
            active: self.active.clone(),
            resident: self.resident.clone(),
            queued: self.queued.clone(),
            evicted_between: self.evicted_between.clone(),
        }
    }

    /// A planner with `config` that continues from `state`, every part of it checked (a state
    /// read from a file may be anything): one sentence for the first thing that is wrong.
    pub(crate) fn from_state(config: &ManagerConfig, state: PlannerState) -> Result<Self> {
        let bad = |what: String| Err(SnowError::Scene(format!("saved planner state: {what}")));
        let mut p = Planner::new(config)?;
        if !(state.time.is_finite() && state.time >= 0.0) {
            return bad(format!(
                "time {} is not a finite number of seconds",
                state.time
            ));
        }
        for &(zone, loaded) in &state.zones {
            if p.zones.contains_key(&zone) {
                return bad(format!("zone {} is listed twice", zone.0));
            }
            let z = p.zone_index(zone);
            p.zone_loaded[z] = loaded;
        }
        for (i, r) in state.mesh_radius.iter().enumerate() {
            if let Some(r) = *r {
                p.set_mesh_radius(MeshId(i as u32), r)?;
            }
        }
        let n = state.surfaces.len();
        let index_ok = |list: &[u32], what: &str| -> Result<()> {
            let mut seen = vec![false; n];
            for &i in list {
                if i as usize >= n || std::mem::replace(&mut seen[i as usize], true) {
                    return Err(SnowError::Scene(format!(
                        "saved planner state: {what} names surface {i} of {n}, or twice"
                    )));
                }
            }
            Ok(())
        };
        index_ok(&state.active, "the active list")?;
        index_ok(&state.resident, "the resident list")?;
        index_ok(&state.queued, "the queued list")?;
        for (i, s) in state.surfaces.into_iter().enumerate() {
            let id = p.add_surface(&s.desc, s.zone)?;
            let stamps_ok = s.stamps.iter().all(|&t| t <= state.tick);
            let times_ok = [s.last_update_time, s.pressed_until]
                .iter()
                .all(|t| t.is_finite() && *t >= 0.0);
            if !stamps_ok || !times_ok || s.due_since.is_some_and(|d| d > state.tick) {
                return bad(format!(
                    "surface {:?} has stamps past the clock",
                    s.desc.name
                ));
            }
            if s.queue.iter().any(|e| e.frame > state.tick)
                || s.queue
                    .iter()
                    .zip(s.queue.iter().skip(1))
                    .any(|(a, b)| a.frame > b.frame)
            {
                return bad(format!(
                    "surface {:?}'s queue is out of frame order",
                    s.desc.name
                ));
            }
            for (k, d) in s
                .queue
                .iter()
                .map(|e| &e.deformer)
                .chain(&s.applied)
                .enumerate()
            {
                d.validate(&format!("{} imprint #{k}", s.desc.name))?;
                p.sweep_of(d)?;
            }
            let st = &mut p.status[i];
            st.touched = s.stamps[0];
            st.player = s.stamps[1];
            st.active = s.stamps[2];
            st.set(REMOVED, s.removed);
            st.set(WANTED, s.wanted);
            if s.paged {
                st.set(PAGED, true);
                p.paged_bound += st.bytes as u64;
            }
            st.queue_len = s.queue.len() as u32;
            let m = &mut p.surfaces[id.0 as usize];
            m.queue = s.queue.into();
            m.applied = s.applied;
            m.due_since = s.due_since;
            m.last_update_time = s.last_update_time;
            m.pressed_until = s.pressed_until;
            if let Some((offset, bytes)) = s.slot {
                if bytes != p.status[i].bytes as u64 || s.paged || s.removed {
                    return bad(format!(
                        "surface {:?} holds a slot of {bytes} bytes that does not fit its state",
                        p.surfaces[i].desc.name
                    ));
                }
                let Some(slot) = p.alloc.alloc_at(offset, bytes) else {
                    return bad(format!(
                        "surface {:?}'s slot at {offset} overlaps another or leaves the pool",
                        p.surfaces[i].desc.name
                    ));
                };
                p.surfaces[i].slot = Some(slot);
                p.status[i].set(RESIDENT, true);
            }
        }
        let resident: Vec<u32> = (0..n as u32)
            .filter(|&i| p.status[i as usize].has(RESIDENT))
            .collect();
        if resident.len() != state.resident.len()
            || state
                .resident
                .iter()
                .any(|&i| !p.status[i as usize].has(RESIDENT))
        {
            return bad("the resident list does not match the surfaces' slots".into());
        }
        for (pos, &i) in state.resident.iter().enumerate() {
            p.surfaces[i as usize].resident_pos = pos;
        }
        p.resident = state.resident;
        for &i in &state.queued {
            p.status[i as usize].set(LISTED, true);
        }
        if (0..n).any(|i| {
            let st = &p.status[i];
            st.queue_len > 0 && !st.has(REMOVED) && !st.has(LISTED)
        }) {
            return bad("a surface with queued imprints is missing from the queued list".into());
        }
        p.queued = state.queued;
        p.active = state.active;
        p.tick = state.tick;
        p.time = state.time;
        p.merged_total = state.merged_total;
        p.evicted_between = state.evicted_between;
        Ok(p)
    }
}

/// The caller's id of the zone with index `z`.
fn zones_id(zones: &HashMap<ZoneId, usize>, z: u32) -> ZoneId {
    zones
        .iter()
        .find(|&(_, &i)| i == z as usize)
        .map_or(ZoneId(0), |(&id, _)| id)
}
