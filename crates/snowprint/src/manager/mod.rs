//! The surface manager: a city of snow surfaces on a fixed memory budget (issue 4).
//!
//! The talk's game has hundreds of rooftops and streets. It looks up which surfaces an actor stands
//! on with a quad tree, updates only 2 surfaces a frame (the player's first, then by distance),
//! gives heightmaps only to active surfaces and reuses the memory of surfaces that are far,
//! invisible or in unstreamed zones, inside 2 MB. [`SnowManager`] does the same for thousands of
//! surfaces, with one difference: **no imprint is lost** because its surface was not updated in the
//! frame it was made. Whatever touches a surface between its updates is queued (as the swept shape
//! of each frame) and captured together when the surface's turn comes.
//!
//! The manager is split in two:
//! - [`Planner`] (pure CPU, property-tested and benchmarked without a GPU) decides, each tick, what
//!   is touched, what is active, which surfaces hold a slot of the pool and which are updated;
//! - [`SnowManager`] applies those plans to a [`SnowWorld`]: admissions and evictions become
//!   [`SnowWorld::add_surface`] and [`SnowWorld::remove_surface`], updates one
//!   [`SnowWorld::update`] call per frame.
//!
//! ```no_run
//! use snowprint::manager::{CameraView, ManagedDeformer, ManagerConfig, SnowManager, ZoneId};
//! use snowprint::{Camera, Deformer, GpuContext, GpuOptions, Pose, Shape, SurfaceDesc};
//! # fn main() -> snowprint::Result<()> {
//! let gpu = GpuContext::new(&GpuOptions::default())?;
//! let mut snow = SnowManager::new(&gpu, ManagerConfig::default())?;
//! let roof = snow.add_surface(SurfaceDesc::new("roof", [0.0, 10.0, 0.0], [6.0, 4.0], 0.3), ZoneId(0))?;
//! let camera = Camera { eye: [0.0, 14.0, 8.0].into(), target: [0.0, 10.0, 0.0].into(), fov_y_degrees: 60.0 };
//! let foot = Deformer::new(Shape::Sphere { radius: 0.12 }, Pose::at([0.0, 10.35, 0.0]));
//! let stats = snow.tick(1.0 / 60.0, Some(&CameraView::new(&camera, 16.0 / 9.0)), &[ManagedDeformer::player(foot)])?;
//! assert_eq!(stats.updated, ["roof"]);
//! let map = snow.read_heightmap(roof)?;
//! assert!(map.depression.iter().any(|&d| d > 0));
//! # Ok(()) }
//! ```
//!
//! See `docs/MANAGER.md` for the priority rule, the starvation bound, the queue bound, the eviction
//! order and the memory accounting.

pub(crate) mod pages;
pub(crate) mod planner;
pub(crate) mod quadtree;
pub(crate) mod queue;
pub(crate) mod save;

mod apply;
mod camera;
mod config;
mod frame;
mod ground;
mod probe;
mod skinned;
mod stats;
mod terrain;

use glam::Vec3;

pub use planner::{Lookup, Plan, PlannedUpdate, Planner, ResidencyChange};
pub use quadtree::{Aabb, SurfaceIndex};

pub use camera::{CameraView, Frustum};
pub use config::{CatchUp, ManagerConfig, UNLIMITED};
pub use frame::PendingTick;
pub use probe::{ManagedProbeStatus, ManagedProbeTicket, ManagedSample};
pub use save::{SaveFile, SavedGround, SavedSurface, Section};
pub use stats::TickStats;
pub use terrain::ManagedTerrainId;

use crate::deformer::Deformer;
use crate::error::{Result, SnowError};
use crate::gpu::GpuContext;
use crate::heightmap::Heightmap;
use crate::mesh::{Mesh, MeshId};
use crate::surface::{SurfaceDesc, SurfaceId};
use crate::world::{SnowWorld, WorldConfig};
use pages::PageStore;

/// Handle of a surface in a [`SnowManager`] (or a [`Planner`]); stable whether or not the surface
/// holds a heightmap.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct ManagedId(pub(crate) u32);

impl ManagedId {
    /// Index of the surface, in order of registration.
    pub fn index(self) -> u32 {
        self.0
    }

    /// The handle of the surface registered `index`-th (a handle that names no surface is reported
    /// as [`SnowError::StaleHandle`] where it is used).
    pub fn from_index(index: u32) -> Self {
        Self(index)
    }
}

/// A streaming zone: surfaces are registered in one, and a zone can be unloaded (its surfaces give
/// their memory up) and loaded again. The number is the caller's.
#[derive(
    Clone,
    Copy,
    Debug,
    Default,
    PartialEq,
    Eq,
    Hash,
    PartialOrd,
    Ord,
    serde::Serialize,
    serde::Deserialize,
)]
pub struct ZoneId(pub u32);

/// A deformer of one frame, and whether it belongs to the player (whose surfaces go first).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ManagedDeformer {
    /// The shape, its pose at the end of the frame and its pose at the end of the previous frame.
    pub deformer: Deformer,
    /// Whether it is (part of) the player.
    pub player: bool,
}

impl ManagedDeformer {
    /// A deformer of anyone but the player.
    pub fn new(deformer: Deformer) -> Self {
        Self {
            deformer,
            player: false,
        }
    }

    /// A deformer of the player.
    pub fn player(deformer: Deformer) -> Self {
        Self {
            deformer,
            player: true,
        }
    }
}

/// A [`SnowWorld`] run by a [`Planner`]: see the module docs.
pub struct SnowManager {
    world: SnowWorld,
    planner: Planner,
    /// Per managed surface: its handle in the world while it holds a heightmap.
    world_ids: Vec<Option<SurfaceId>>,
    /// Heightmaps of surfaces without a slot that had one.
    pages: PageStore,
    /// Per managed surface: its ground when it is not flat (`ground.rs`).
    grounds: Vec<Option<ground::ManagedGround>>,
    /// Mesh deformers by the manager's [`MeshId`].
    meshes: Vec<ManagedMesh>,
    /// World meshes of earlier posings that queued imprints may still name, and their vertices
    /// (for saves).
    retired: Vec<MeshId>,
    retired_mesh: std::collections::HashMap<u32, Mesh>,
    /// Skeletons of the skinned meshes.
    skins: skinned::ManagedSkins,
    /// Bytes paged out between ticks (zone unloads), reported by the next tick.
    paged_between: u64,
    stats: TickStats,
    /// Which manager this is, so that a [`PendingTick`] is given back to its own.
    id: u64,
    /// Ticks encoded so far.
    ticks: u64,
    /// The tick recorded and not yet reported submitted.
    in_flight: Option<frame::TickInFlight>,
    /// Page-outs on their way from the GPU.
    arriving: Vec<frame::PageRead>,
    /// Gameplay probes asked of the manager.
    probes: probe::ManagerProbes,
    /// Terrain windows, by [`ManagedTerrainId`] (`None`: removed).
    terrains: Vec<Option<terrain::ManagedTerrain>>,
}

/// Source of [`SnowManager`] ids.
static NEXT_MANAGER: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);

/// A mesh deformer: its current posing and the world mesh that holds it.
#[derive(Clone, Debug)]
pub(crate) struct ManagedMesh {
    pub(crate) name: String,
    pub(crate) mesh: Mesh,
    pub(crate) world: MeshId,
}

impl std::fmt::Debug for SnowManager {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SnowManager")
            .field("surfaces", &self.planner.len())
            .field("resident", &self.stats.resident)
            .field("paged", &self.pages.len())
            .field("pool_used", &self.planner.pool_used())
            .finish()
    }
}

impl SnowManager {
    /// A manager with its own world (pool of `config.pool_bytes`, clamped to the device).
    pub fn new(gpu: &GpuContext, config: ManagerConfig) -> Result<Self> {
        config.validate()?;
        let world = SnowWorld::new(gpu, Self::world_config(&config))?;
        // The planner mirrors the world's allocator: same budget after the world's clamping.
        let planner = Planner::new(&ManagerConfig {
            pool_bytes: world.memory().pool_budget,
            ..config
        })?;
        Ok(Self::with_parts(world, planner))
    }

    fn world_config(config: &ManagerConfig) -> WorldConfig {
        WorldConfig {
            capture: config.capture,
            pool_bytes: config.pool_bytes,
            atlas_side: config.atlas_side,
            // The planner sizes slots by the talk's rule (`SurfaceDesc::layout`, 512 a side).
            max_resolution: crate::surface::MAX_RESOLUTION,
            format: config.format,
            ..WorldConfig::default()
        }
    }

    fn with_parts(world: SnowWorld, planner: Planner) -> Self {
        Self {
            world,
            planner,
            world_ids: Vec::new(),
            pages: PageStore::default(),
            grounds: Vec::new(),
            meshes: Vec::new(),
            retired: Vec::new(),
            retired_mesh: Default::default(),
            skins: Default::default(),
            paged_between: 0,
            stats: TickStats::default(),
            id: NEXT_MANAGER.fetch_add(1, std::sync::atomic::Ordering::Relaxed),
            ticks: 0,
            in_flight: None,
            arriving: Vec::new(),
            probes: probe::ManagerProbes::default(),
            terrains: Vec::new(),
        }
    }

    /// Register a surface in a zone. It holds no heightmap until it becomes active.
    pub fn add_surface(&mut self, desc: SurfaceDesc, zone: ZoneId) -> Result<ManagedId> {
        let id = self.planner.add_surface(&desc, zone)?;
        self.world_ids.push(None);
        self.grounds.push(None);
        Ok(id)
    }

    /// Remove a surface for good (its heightmap, resident or paged, is freed).
    pub fn remove_surface(&mut self, id: ManagedId) -> Result<()> {
        self.planner.remove_surface(id)?;
        self.pages.take(id.0);
        self.grounds[id.0 as usize] = None;
        if let Some(w) = self.world_ids.get_mut(id.0 as usize).and_then(Option::take) {
            self.world.remove_surface(w)?;
        }
        Ok(())
    }

    /// Load a zone: the surfaces that held heightmaps when it unloaded page them back in at the
    /// next ticks (as the pool has room), the others when they become active.
    pub fn load_zone(&mut self, zone: ZoneId) {
        self.planner.load_zone(zone);
    }

    /// Unload a zone: its surfaces give their slots up now, and their heightmaps are copied out
    /// in a submission of their own, kept in the page store once they have arrived (checked
    /// without waiting at each tick); their queued imprints wait for the zone to load. Returns the
    /// surfaces that held a heightmap. Refused with [`SnowError::FramePending`] while a tick is
    /// recorded and not submitted.
    pub fn unload_zone(&mut self, zone: ZoneId) -> Result<Vec<ManagedId>> {
        self.not_pending()?;
        let freed = self.planner.unload_zone(zone);
        self.paged_between += self.page_out(&freed)?;
        Ok(freed)
    }

    /// Copy the world surfaces of `ids` out (one submission, not waited for), free their slots
    /// and keep the copy on its way as their pages. Returns the bytes copied.
    fn page_out(&mut self, ids: &[ManagedId]) -> Result<u64> {
        let mut managed = Vec::new();
        let mut world = Vec::new();
        for &id in ids {
            if let Some(w) = self.world_ids[id.0 as usize] {
                managed.push(id);
                world.push(w);
            }
        }
        if world.is_empty() {
            return Ok(0);
        }
        let mut encoder = self
            .world
            .device()
            .create_command_encoder(&Default::default());
        let read = self.world.encode_snapshot(&mut encoder, &world)?;
        self.world.queue().submit([encoder.finish()]);
        read.submitted();
        let mut bytes = 0;
        for (&id, &w) in managed.iter().zip(&world) {
            bytes += self.world.payload_bytes_of(w)?;
            self.world.remove_surface(w)?;
            self.world_ids[id.0 as usize] = None;
            self.planner.page_arriving(id);
        }
        self.arriving.push(frame::PageRead { read, ids: managed });
        Ok(bytes)
    }

    /// Register a mesh deformer shape (see [`SnowWorld::add_mesh`]). The handle is the manager's:
    /// use it in [`crate::Shape::Mesh`] of the deformers given to [`SnowManager::tick`].
    pub fn add_mesh(&mut self, name: &str, mesh: &Mesh) -> Result<MeshId> {
        let world = self.world.add_mesh(name, mesh)?;
        self.planner
            .set_mesh_radius(world, mesh.bounding_radius())?;
        self.meshes.push(ManagedMesh {
            name: name.to_owned(),
            mesh: mesh.clone(),
            world,
        });
        Ok(MeshId(self.meshes.len() as u32 - 1))
    }

    /// The handle of the mesh registered under `name`, if any (the first, if several).
    pub fn mesh_named(&self, name: &str) -> Option<MeshId> {
        self.meshes
            .iter()
            .position(|m| m.name == name)
            .map(|i| MeshId(i as u32))
    }

    pub(super) fn mesh(&self, id: MeshId) -> Result<&ManagedMesh> {
        self.meshes
            .get(id.0 as usize)
            .ok_or(SnowError::StaleHandle {
                what: "mesh",
                index: id.0,
            })
    }

    /// Re-pose a mesh deformer (see [`SnowWorld::pose_mesh`]). Imprints of the mesh still queued
    /// keep the posing they were made with: when any are queued, the new posing goes into a new
    /// world mesh and the old one is freed once no queue names it.
    pub fn pose_mesh(&mut self, id: MeshId, positions: &[Vec3]) -> Result<()> {
        let m = self.mesh(id)?;
        let world = m.world;
        if positions.len() != m.mesh.positions.len() {
            return Err(SnowError::PoseMismatch {
                mesh: id.0,
                got: positions.len(),
                expected: m.mesh.positions.len(),
            });
        }
        let posed = Mesh {
            positions: positions.to_vec(),
            indices: m.mesh.indices.clone(),
        };
        let name = m.name.clone();
        posed.validate(&name)?;
        let r = posed.bounding_radius();
        if self.planner.queues_hold_mesh(world) {
            let new = self.world.add_mesh(&name, &posed)?;
            self.planner.set_mesh_radius(new, r)?;
            self.retired.push(world);
            let old = std::mem::replace(&mut self.meshes[id.0 as usize].mesh, posed.clone());
            self.retired_mesh.insert(world.0, old);
            self.meshes[id.0 as usize].world = new;
        } else {
            self.world.pose_mesh(world, positions)?;
            self.planner.set_mesh_radius(world, r)?;
            // What the last updates pressed with the old posing no longer covers the new one.
            self.planner.forget_applied_mesh(world);
        }
        self.meshes[id.0 as usize].mesh = posed;
        Ok(())
    }

    /// Run one frame: [`SnowManager::encode_tick`] into an encoder of the manager's own,
    /// submitted at once; then wait for the heightmaps paged out in it (so that, as it returns,
    /// every heightmap is in the pool or the page store).
    pub fn tick(
        &mut self,
        dt: f32,
        camera: Option<&CameraView>,
        deformers: &[ManagedDeformer],
    ) -> Result<TickStats> {
        let device = self.world.device().clone();
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("snow manager tick"),
        });
        let pending = self.encode_tick(&mut encoder, dt, camera, deformers)?;
        self.world.queue().submit([encoder.finish()]);
        let mut stats = self.submitted(pending)?;
        self.wait_pages()?;
        stats.page_store_bytes = self.pages.bytes();
        stats.paged_surfaces = self.pages.len();
        self.stats = stats.clone();
        Ok(stats)
    }

    /// Wait for every page-out on its way (reads, saves and [`SnowManager::tick`] need them).
    pub(super) fn wait_pages(&mut self) -> Result<()> {
        let device = self.world.device().clone();
        for p in std::mem::take(&mut self.arriving) {
            let snaps = p.read.wait(&device)?;
            self.keep_pages(p.ids, snaps);
        }
        Ok(())
    }

    /// Free the world meshes of earlier posings that no queue names any more.
    pub(super) fn free_retired_meshes(&mut self) -> Result<()> {
        let mut k = 0;
        while k < self.retired.len() {
            let m = self.retired[k];
            if self.planner.queues_hold_mesh(m) {
                k += 1;
            } else {
                self.world.remove_mesh(m)?;
                self.retired_mesh.remove(&m.0);
                self.retired.swap_remove(k);
            }
        }
        Ok(())
    }

    /// Land every queued imprint now, whatever the budget: ticks of `dt = 0` with no camera and
    /// no deformers and no budget, paging surfaces in and out as the pool allows, until no queue
    /// holds anything (imprints over unloaded zones wait for their zone). Returns the ticks run.
    /// A game calls it before it reads every surface (a save needs no flush: it keeps the queues).
    pub fn flush(&mut self) -> Result<u32> {
        let budget = self.planner.config().updates_per_frame;
        self.planner.set_updates_per_frame(UNLIMITED);
        let mut ticks = 0;
        let mut last = usize::MAX;
        let result = loop {
            let pending = self.planner.pending_loaded_surfaces();
            // Each round updates every resident surface with a queue and admits more; a round
            // that changes nothing means only unloaded zones still wait.
            if pending == 0 || (pending >= last && ticks > self.planner.len() as u32 + 2) {
                break Ok(ticks);
            }
            last = pending;
            if let Err(e) = self.tick(0.0, None, &[]) {
                break Err(e);
            }
            ticks += 1;
        };
        self.planner.set_updates_per_frame(budget);
        result
    }

    /// The statistics of the last tick.
    pub fn stats(&self) -> &TickStats {
        &self.stats
    }

    /// A surface's heightmap: read back from the GPU while it holds a slot, from its page when it
    /// is paged out (waiting for the page when it is still on its way from the GPU), and
    /// untouched snow when it never held one. Imprints still queued are not in it yet (see
    /// [`SnowManager::flush`]). Refused with [`SnowError::FramePending`] while a tick is recorded
    /// and not submitted.
    pub fn read_heightmap(&self, id: ManagedId) -> Result<Heightmap> {
        self.not_pending()?;
        let desc = self.planner.surface(id)?;
        if let Some(w) = self.world_ids.get(id.0 as usize).copied().flatten() {
            return self.world.read_heightmap(w);
        }
        if let Some(page) = self.pages.get(id.0) {
            return page.decompress()?.heightmap();
        }
        if let Some(snap) = self.arriving_snapshot(id)? {
            return snap.heightmap();
        }
        let l = desc.layout();
        Ok(Heightmap::from_packed(
            l.width,
            l.height,
            &vec![0; l.texels() as usize],
        ))
    }

    /// The snapshot of a surface whose page is on its way, waiting for it (left on its way).
    pub(crate) fn arriving_snapshot(
        &self,
        id: ManagedId,
    ) -> Result<Option<crate::world::SurfaceSnapshot>> {
        for p in &self.arriving {
            if let Some(k) = p.ids.iter().position(|&i| i == id) {
                let mut snaps = p.read.peek(self.world.device())?;
                return Ok(Some(snaps.swap_remove(k)));
            }
        }
        Ok(None)
    }

    /// Every surface whose page is on its way, with its snapshot (waiting for them).
    pub(crate) fn arriving_snapshots(
        &self,
    ) -> Result<Vec<(ManagedId, crate::world::SurfaceSnapshot)>> {
        let mut out = Vec::new();
        for p in &self.arriving {
            let snaps = p.read.peek(self.world.device())?;
            out.extend(p.ids.iter().copied().zip(snaps));
        }
        Ok(out)
    }

    /// The world handle of a surface while it holds a heightmap (for renderers).
    pub fn world_id(&self, id: ManagedId) -> Option<SurfaceId> {
        self.world_ids.get(id.0 as usize).copied().flatten()
    }

    /// A surface's description.
    pub fn surface(&self, id: ManagedId) -> Result<&SurfaceDesc> {
        self.planner.surface(id)
    }

    /// Every registered surface (removed ones left out) with its name.
    pub fn surface_names(&self) -> impl Iterator<Item = (ManagedId, &str)> {
        (0..self.planner.len() as u32).filter_map(|i| {
            let id = ManagedId(i);
            self.planner.surface(id).ok().map(|d| (id, d.name.as_str()))
        })
    }

    /// The world (heightmaps on the GPU, memory report).
    pub fn world(&self) -> &SnowWorld {
        &self.world
    }

    /// The page store (heightmaps of surfaces without a slot).
    pub fn pages(&self) -> &PageStore {
        &self.pages
    }

    /// Measure GPU stages with timestamp queries (see [`SnowWorld::set_profiling`]).
    pub fn set_profiling(&mut self, on: bool) {
        self.world.set_profiling(on);
    }

    /// The planner (residency, queues, bounds).
    pub fn planner(&self) -> &Planner {
        &self.planner
    }
}
