//! # snowprint
//!
//! Real-time deformable snow after the GDC 2014 talk on Batman: Arkham Origins. Every snow surface
//! owns a heightmap that is captured each frame by rendering whatever touches the snow from *below*
//! with an ankle-high orthographic frustum, blurred, merged into the history and slowly replenished
//! while it snows. The library is engine-neutral: it takes surfaces and deformer poses and gives back
//! heightmaps (on the GPU for shading, or read back to the CPU).
//!
//! ```no_run
//! use snowprint::{GpuContext, GpuOptions, SnowWorld, WorldConfig, SurfaceDesc, Deformer, Shape, Pose};
//! # fn main() -> snowprint::Result<()> {
//! let gpu = GpuContext::new(&GpuOptions::default())?;
//! let mut world = SnowWorld::new(&gpu, WorldConfig::default())?;
//! let roof = world.add_surface(SurfaceDesc::new("roof", [0.0, 10.0, 0.0], [8.0, 6.0], 0.3))?;
//! let foot = Deformer::new(Shape::Sphere { radius: 0.12 }, Pose::at([0.0, 10.2, 0.0]));
//! world.step(1.0 / 60.0, &[foot])?;
//! let map = world.read_heightmap(roof)?;
//! assert_eq!((map.width, map.height), (200, 150));
//! # Ok(()) }
//! ```
//!
//! See `docs/ARCHITECTURE.md` for the data flow from deformers to heightmaps.

pub mod accumulate;
pub mod capture;
pub mod deformer;
pub mod error;
mod extract;
pub mod gpu;
pub mod heightmap;
pub mod manager;
pub mod mesh;
pub mod pool;
pub mod render;
pub mod scene;
pub mod surface;
pub mod view;
pub mod wgsl;
pub mod world;

pub use deformer::{Deformer, MAX_DEFORMER_SIZE, Pose, Shape};
pub use error::{Result, SnowError};
pub use extract::{FrameView, SurfaceView};
pub use gpu::{Capabilities, GpuContext, GpuOptions, required_features, required_limits};
pub use heightmap::Heightmap;
pub use manager::{
    CameraView, ManagedDeformer, ManagedId, ManagerConfig, SnowManager, TickStats, ZoneId,
};
pub use mesh::{Mesh, MeshId};
pub use pool::{PoolFormat, Precision};
pub use surface::{SurfaceDesc, SurfaceId, SurfaceLayout};
pub use view::{Camera, GroundMaterial};
pub use world::{
    CaptureConfig, CaptureMode, FrameStats, MemoryReport, PassMode, PendingFrame, SnowWorld,
    StageTimes, SurfaceSnapshot, SurfaceUpdate, WorldConfig,
};
