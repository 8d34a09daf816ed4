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
//! let map = snow.read_heightmap(roof)?.expect("an active surface holds a heightmap");
//! # Ok(()) }
//! ```
//!
//! See `docs/MANAGER.md` for the priority rule, the starvation bound, the queue bound, the eviction
//! order and the memory accounting.

pub mod city;
pub mod planner;
pub mod plot;
pub mod quadtree;
pub mod queue;

use glam::{Vec3, Vec4};

pub use planner::{Lookup, Plan, PlannedUpdate, Planner, ResidencyChange};
pub use quadtree::{Aabb, SurfaceIndex};

use crate::deformer::Deformer;
use crate::error::{Result, SnowError};
use crate::gpu::GpuContext;
use crate::heightmap::Heightmap;
use crate::mesh::{Mesh, MeshId};
use crate::surface::{SurfaceDesc, SurfaceId};
use crate::view::Camera;
use crate::world::{CaptureConfig, SnowWorld, SurfaceUpdate, WorldConfig};

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

/// Updates per frame that means "no budget".
pub const UNLIMITED: usize = usize::MAX;

/// Settings of a manager.
#[derive(Clone, Debug, PartialEq)]
pub struct ManagerConfig {
    /// Most surface updates per frame, `K` (the talk's 2). [`UNLIMITED`] updates every due surface.
    pub updates_per_frame: usize,
    /// Bytes of the heightmap pool (the talk's 2 MB: default 2 MiB).
    pub pool_bytes: u64,
    /// A visible surface is active only within this distance of the camera's eye, metres
    /// (default 60).
    pub active_distance: f32,
    /// The largest head start, in frames, that a near surface has over a far one (`S`, default 8):
    /// a surface's deadline is the frame it became due plus `S * min(distance / active_distance, 1)`.
    pub distance_slack_frames: u32,
    /// Updates a frame reserved for the player's surfaces, at most `K - 1` (default 1).
    pub player_slots: usize,
    /// Most imprints queued on one surface between two of its updates (default 256); see
    /// [`queue`].
    pub queue_cap: usize,
    /// Keep the heightmaps of surfaces that became inactive until their memory is wanted (least
    /// recently useful first), instead of freeing them at once (default `false`: inactive surfaces
    /// hold no heightmap).
    pub retain_inactive: bool,
    /// Seconds between the updates of a surface that only needs its snowfall refilled (default
    /// 0.25).
    pub replenish_interval: f32,
    /// Capture settings of the world.
    pub capture: CaptureConfig,
    /// Largest side of the world's capture atlas, texels.
    pub atlas_side: u32,
    /// How the world's pool stores heightmaps (bits a channel, normals or not).
    pub format: crate::pool::PoolFormat,
}

impl Default for ManagerConfig {
    fn default() -> Self {
        Self {
            updates_per_frame: 2,
            pool_bytes: 2 << 20,
            active_distance: 60.0,
            distance_slack_frames: 8,
            player_slots: 1,
            queue_cap: 256,
            retain_inactive: false,
            replenish_interval: 0.25,
            capture: CaptureConfig::default(),
            atlas_side: 2048,
            format: crate::pool::PoolFormat::default(),
        }
    }
}

impl ManagerConfig {
    /// Check every field, naming the first one that is wrong.
    pub fn validate(&self) -> Result<()> {
        let bad = |what: &str, value: String, expected: &str| {
            Err(SnowError::Scene(format!(
                "manager setting {what} is {value}, but it must be {expected}"
            )))
        };
        if self.updates_per_frame == 0 {
            return bad("updates_per_frame", "0".into(), "1 or more");
        }
        if !(self.active_distance.is_finite() && self.active_distance >= 0.0) {
            return bad(
                "active_distance",
                self.active_distance.to_string(),
                "a finite number of metres, 0 or more",
            );
        }
        if self.queue_cap == 0 {
            return bad("queue_cap", "0".into(), "1 or more");
        }
        if !(self.replenish_interval.is_finite() && self.replenish_interval >= 0.0) {
            return bad(
                "replenish_interval",
                self.replenish_interval.to_string(),
                "a finite number of seconds, 0 or more",
            );
        }
        let ankle = self.capture.ankle_height;
        if !(ankle.is_finite() && ankle > 0.0) {
            return bad(
                "ankle_height",
                ankle.to_string(),
                "a finite number of metres above 0",
            );
        }
        Ok(())
    }
}

/// Where the camera is and what it sees: activity is decided against its frustum.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraView {
    /// Eye, world metres.
    pub eye: Vec3,
    /// Point looked at.
    pub target: Vec3,
    /// Vertical field of view, degrees.
    pub fov_y_degrees: f32,
    /// Width over height.
    pub aspect: f32,
    /// Near plane, metres.
    pub near: f32,
    /// Far plane, metres.
    pub far: f32,
}

impl CameraView {
    /// The view of a [`Camera`] with an aspect ratio, near plane 0.1 m and far plane 10 km (the
    /// manager's `active_distance` limits activity anyway).
    pub fn new(camera: &Camera, aspect: f32) -> Self {
        Self {
            eye: camera.eye,
            target: camera.target,
            fov_y_degrees: camera.fov_y_degrees,
            aspect,
            near: 0.1,
            far: 10_000.0,
        }
    }

    /// The six planes of the view, checking every field.
    pub fn frustum(&self) -> Result<Frustum> {
        let bad = |what: &str, value: String, expected: &str| {
            Err(SnowError::Scene(format!(
                "camera {what} is {value}, but it must be {expected}"
            )))
        };
        if !self.eye.is_finite() || !self.target.is_finite() {
            return bad(
                "eye or target",
                format!("{:?} / {:?}", self.eye.to_array(), self.target.to_array()),
                "finite",
            );
        }
        let forward = (self.target - self.eye).normalize_or_zero();
        if forward == Vec3::ZERO {
            return bad(
                "target",
                format!("{:?}", self.target.to_array()),
                "different from the eye",
            );
        }
        if !(self.fov_y_degrees.is_finite()
            && self.fov_y_degrees > 0.0
            && self.fov_y_degrees < 180.0)
        {
            return bad(
                "fov_y_degrees",
                self.fov_y_degrees.to_string(),
                "between 0 and 180",
            );
        }
        if !(self.aspect.is_finite() && self.aspect > 0.0) {
            return bad("aspect", self.aspect.to_string(), "a finite number above 0");
        }
        if !(self.near.is_finite()
            && self.far.is_finite()
            && self.near > 0.0
            && self.far > self.near)
        {
            return bad(
                "near / far",
                format!("{} / {}", self.near, self.far),
                "finite with 0 < near < far",
            );
        }
        // Looking straight up or down: any horizontal axis serves as "up".
        let up = if forward.cross(Vec3::Y).length_squared() < 1e-8 {
            Vec3::Z
        } else {
            Vec3::Y
        };
        let right = forward.cross(up).normalize();
        let up = right.cross(forward);
        let tan_v = (self.fov_y_degrees.to_radians() * 0.5).tan();
        let tan_h = tan_v * self.aspect;
        // Inward normals through the eye for the four sides.
        let side = |n: Vec3| {
            let n = n.normalize();
            n.extend(-n.dot(self.eye))
        };
        Ok(Frustum {
            planes: [
                side(forward * tan_h + right),
                side(forward * tan_h - right),
                side(forward * tan_v + up),
                side(forward * tan_v - up),
                forward.extend(-forward.dot(self.eye) - self.near),
                (-forward).extend(forward.dot(self.eye) + self.far),
            ],
        })
    }
}

/// A view frustum as six inward planes `(n, d)`, `n . p + d >= 0` inside.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frustum {
    /// Left, right, bottom, top, near, far.
    pub planes: [Vec4; 6],
}

impl Frustum {
    /// Whether a sphere is at least partly inside (conservative near the frustum's edges, as the
    /// usual plane test is).
    #[inline]
    pub fn sees(&self, center: Vec3, radius: f32) -> bool {
        self.planes
            .iter()
            .all(|p| p.truncate().dot(center) + p.w >= -radius)
    }
}

/// What one tick did. Serialized as one JSON object per frame by `snowprint simulate --report`.
#[derive(Clone, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct TickStats {
    /// Frame number, from 0.
    pub frame: u64,
    /// Names of the surfaces updated this frame, in update order (player's first).
    pub updated: Vec<String>,
    /// Active surfaces: visible and near, touched, or with imprints waiting.
    pub active: usize,
    /// Surfaces holding a heightmap.
    pub resident: usize,
    /// Names of the surfaces that gave their heightmap up since the last frame.
    pub evicted: Vec<String>,
    /// Pool bytes in heightmap slots (exact, alignment included).
    pub pool_bytes_used: u64,
    /// The pool's budget, bytes.
    pub pool_bytes_budget: u64,
    /// The longest wait, in frames, of a resident surface due for an update (updated this frame or
    /// still waiting).
    pub max_wait_frames: u64,
    /// Surfaces something touched this frame.
    pub touched: usize,
    /// Resident surfaces due for an update this frame (before the budget was applied).
    pub due: usize,
    /// Active surfaces with imprints waiting for a slot of the pool.
    pub waiting_for_memory: usize,
    /// Imprints queued, over all surfaces, after this frame's updates.
    pub queued_imprints: usize,
    /// Imprints merged into their predecessor because a queue was full (trail straightened).
    pub imprints_merged: u64,
    /// Imprints dropped because a queue was full and nothing could be merged.
    pub imprints_dropped: u64,
}

/// A [`SnowWorld`] run by a [`Planner`]: see the module docs.
pub struct SnowManager {
    world: SnowWorld,
    planner: Planner,
    /// Per managed surface: its handle in the world while it holds a heightmap.
    world_ids: Vec<Option<SurfaceId>>,
    stats: TickStats,
}

impl std::fmt::Debug for SnowManager {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SnowManager")
            .field("surfaces", &self.planner.len())
            .field("resident", &self.stats.resident)
            .field("pool_used", &self.planner.pool_used())
            .finish()
    }
}

impl SnowManager {
    /// A manager with its own world (pool of `config.pool_bytes`, clamped to the device).
    pub fn new(gpu: &GpuContext, config: ManagerConfig) -> Result<Self> {
        config.validate()?;
        let world = SnowWorld::new(
            gpu,
            WorldConfig {
                capture: config.capture,
                pool_bytes: config.pool_bytes,
                atlas_side: config.atlas_side,
                // The planner sizes slots by the talk's rule (`SurfaceDesc::layout`, 512 a side).
                max_resolution: crate::surface::MAX_RESOLUTION,
                format: config.format,
                ..WorldConfig::default()
            },
        )?;
        // The planner mirrors the world's allocator: same budget after the world's clamping.
        let planner = Planner::new(&ManagerConfig {
            pool_bytes: world.memory().pool_budget,
            ..config
        })?;
        Ok(Self {
            world,
            planner,
            world_ids: Vec::new(),
            stats: TickStats::default(),
        })
    }

    /// Register a surface in a zone. It holds no heightmap until it becomes active.
    pub fn add_surface(&mut self, desc: SurfaceDesc, zone: ZoneId) -> Result<ManagedId> {
        let id = self.planner.add_surface(&desc, zone)?;
        self.world_ids.push(None);
        Ok(id)
    }

    /// Remove a surface for good (its heightmap, if any, is freed).
    pub fn remove_surface(&mut self, id: ManagedId) -> Result<()> {
        self.planner.remove_surface(id)?;
        self.free_world(id)
    }

    fn free_world(&mut self, id: ManagedId) -> Result<()> {
        if let Some(w) = self.world_ids.get_mut(id.0 as usize).and_then(Option::take) {
            self.world.remove_surface(w)?;
        }
        Ok(())
    }

    /// Load a zone: its surfaces may become active again (with fresh heightmaps).
    pub fn load_zone(&mut self, zone: ZoneId) {
        self.planner.load_zone(zone);
    }

    /// Unload a zone: its surfaces free their heightmaps now and their queued imprints are dropped.
    /// Returns the surfaces that held a heightmap.
    pub fn unload_zone(&mut self, zone: ZoneId) -> Result<Vec<ManagedId>> {
        let freed = self.planner.unload_zone(zone);
        for &id in &freed {
            self.free_world(id)?;
        }
        Ok(freed)
    }

    /// Register a mesh deformer shape (see [`SnowWorld::add_mesh`]).
    pub fn add_mesh(&mut self, name: &str, mesh: &Mesh) -> Result<MeshId> {
        let id = self.world.add_mesh(name, mesh)?;
        self.planner.set_mesh_radius(id, mesh.bounding_radius())?;
        Ok(id)
    }

    /// Re-pose a mesh deformer (see [`SnowWorld::pose_mesh`]). Imprints of the mesh still queued
    /// are captured with the newest posing.
    pub fn pose_mesh(&mut self, id: MeshId, positions: &[Vec3]) -> Result<()> {
        self.world.pose_mesh(id, positions)?;
        let r = positions.iter().map(|p| p.length()).fold(0.0, f32::max);
        self.planner.set_mesh_radius(id, r)
    }

    /// Run one frame: decide (see [`Planner::tick`]), free and give heightmaps, then update at most
    /// `updates_per_frame` surfaces on the GPU with everything that touched them since their last
    /// update. Bad input is an error before anything changes.
    pub fn tick(
        &mut self,
        dt: f32,
        camera: Option<&CameraView>,
        deformers: &[ManagedDeformer],
    ) -> Result<TickStats> {
        self.planner.tick(dt, camera, deformers)?;
        let plan = self.planner.last_plan();
        let mut failed = Vec::new();
        for change in &plan.changes {
            match *change {
                ResidencyChange::Evict(id) => {
                    if let Some(w) = self.world_ids[id.0 as usize].take() {
                        self.world.remove_surface(w)?;
                    }
                }
                ResidencyChange::Admit(id) => {
                    let desc = self.planner.surface(id)?.clone();
                    match self.world.add_surface(desc) {
                        Ok(w) => self.world_ids[id.0 as usize] = Some(w),
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
        let updates: Vec<SurfaceUpdate<'_>> = plan
            .updates
            .iter()
            .filter_map(|u| {
                self.world_ids[u.surface.0 as usize].map(|w| SurfaceUpdate {
                    surface: w,
                    elapsed: u.elapsed,
                    deformers: &u.imprints,
                })
            })
            .collect();
        if !updates.is_empty() {
            self.world.update(&updates)?;
        }
        let mut stats = plan.stats.clone();
        for id in failed {
            self.planner.admission_failed(id);
        }
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
        self.stats = stats.clone();
        Ok(stats)
    }

    /// The statistics of the last tick.
    pub fn stats(&self) -> &TickStats {
        &self.stats
    }

    /// A surface's heightmap, read back from the GPU, or `None` when it holds none (inactive, or
    /// waiting for memory). Imprints still queued are not in it yet.
    pub fn read_heightmap(&self, id: ManagedId) -> Result<Option<Heightmap>> {
        self.planner.surface(id)?;
        match self.world_ids.get(id.0 as usize).copied().flatten() {
            Some(w) => Ok(Some(self.world.read_heightmap(w)?)),
            None => Ok(None),
        }
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

    /// Measure GPU stages with timestamp queries (see [`SnowWorld::set_profiling`]).
    pub fn set_profiling(&mut self, on: bool) {
        self.world.set_profiling(on);
    }

    /// The planner (residency, queues, bounds).
    pub fn planner(&self) -> &Planner {
        &self.planner
    }
}
