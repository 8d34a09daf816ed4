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
//!
//! # What to reach for
//!
//! | you want | reach for |
//! |---|---|
//! | a GPU device, checked for what the passes need | [`GpuContext`], [`GpuOptions`], [`Capabilities`] |
//! | the engine's own device and command encoder | [`required_features`], [`required_limits`], [`GpuContext::from_device`], [`SnowWorld::encode_update`], [`PendingFrame`], [`render::Renderer::encode_to_view`] |
//! | snow surfaces stepped by deformers | [`SnowWorld`], [`WorldConfig`], [`SurfaceDesc`], [`Deformer`], [`Shape`], [`Pose`], [`Mesh`] |
//! | the heightmaps back, or their place in the pool | [`Heightmap`], [`PoolFormat`], [`Precision`], [`FrameView`], [`SurfaceSnapshot`], [`SnapshotRead`] |
//! | a city of surfaces paged in and out, saves | [`manager`]: [`SnowManager`], [`ManagerConfig`], [`manager::SaveFile`] |
//! | scene files (TOML) | [`scene`]: [`scene::Scene`] |
//! | pictures: the snow material, sky, shadows, falling snow | [`render`]: [`render::Renderer`], [`render::RenderConfig`], [`render::RenderFrame`] |
//! | the CPU references the GPU passes are tested against | [`reference`](mod@reference) |
//! | the passes themselves, to drive from an engine or a tool | [`low_level`] |
//! | the WGSL modules, composed and validated, with their reflected bindings and shared constants | [`wgsl`] |
//! | errors to match on | [`SnowError`], [`render::RenderError`] (both `#[non_exhaustive]`) |
//!
//! The crate re-exports the [`glam`] and [`wgpu`] it is built against, so an engine can name the
//! same versions.

mod accumulate;
mod capture;
mod deformer;
mod error;
mod extract;
mod gpu;
mod ground;
mod heightmap;
pub mod manager;
mod material;
mod mesh;
mod pool;
mod relax;
pub mod render;
pub mod scene;
mod skin;
mod spray;
mod surface;
mod view;
pub mod wgsl;
mod window;
mod world;

pub use glam;
pub use wgpu;

pub use deformer::{Deformer, MAX_DEFORMER_SIZE, Pose, Shape};
pub use error::{Result, SnowError};
pub use extract::{FrameView, SurfaceView};
pub use gpu::{Capabilities, GpuContext, GpuOptions, required_features, required_limits};
pub use ground::{Ground, GroundField, GroundMesh, HeightGrid, SlopeRule};
pub use heightmap::Heightmap;
pub use manager::{
    CameraView, ManagedDeformer, ManagedId, ManagerConfig, SnowManager, TickStats, ZoneId,
};
pub use material::{Material, MaterialLook};
pub use mesh::{
    MAX_GLTF_DEPTH, MAX_GLTF_FILE_BYTES, MAX_GLTF_NODES, MAX_GLTF_TRIANGLES, MAX_GLTF_VERTICES,
    Mesh, MeshId,
};
pub use pool::{PoolFormat, Precision};
pub use render::gpu::SurfaceUniform;
pub use skin::{Playback, SkinnedMesh};
pub use spray::{
    MAX_SPRAY_CAPACITY, Particle, SPRAY_RING_HEADER, SprayConfig, SprayCounters, SprayLook,
};
pub use surface::{MAX_RESOLUTION, MIN_TEXEL_SIZE, SurfaceDesc, SurfaceId, SurfaceLayout};
pub use view::{Camera, GroundMaterial};
pub use window::{LevelDesc, ScrollStats, Terrain, TerrainDesc, TerrainGround};
pub use world::{
    CaptureConfig, CaptureMode, CapturePath, CpuSteps, FrameStats, MemoryReport, MeshAnimation,
    PassMode, PendingFrame, SnapshotRead, SnowWorld, StageTimes, SurfaceSnapshot, SurfaceUpdate,
    WorldConfig,
};

/// What a [`SkinnedMesh`] holds besides its triangles: joints and influences, the node hierarchy,
/// animations and their channels.
pub mod skeleton {
    pub use crate::skin::{
        Animation, Channel, Influence, Interpolation, Joint, MAX_ANIMATION_KEYS, MAX_SKIN_JOINTS,
        Node, Property, Trs,
    };
}
pub use world::{
    Footstep, MAX_PROBE_POINTS, MAX_UNCLAIMED_ANSWERS, PROBE_RING, ProbeSample, ProbeStatus,
    ProbeTicket,
};

/// CPU references of the GPU passes: the same maths on the same inputs and layouts, written for
/// clarity, against which the tests compare the GPU's results texel by texel.
pub mod reference {
    /// The capture's ray cast from below: depth of capsules, boxes and triangle meshes per texel,
    /// over a surface's capture region (its texels and the apron around them).
    pub mod capture {
        pub use crate::capture::cpu::*;
        pub use crate::capture::{APRON, region, strip_apron};
    }
    /// The accumulation: blur, merge into the history, normals (also what the fused pass computes).
    pub mod accumulate {
        pub use crate::accumulate::cpu::*;
    }
    /// The snow material: Reoriented Normal Mapping, relief and parallax occlusion search, Sobel
    /// normals, light visibility and horizon ambient occlusion.
    pub mod material {
        pub use crate::render::cpu::*;
    }
    /// The tessellated tier: the bank field raised beside a print and the dicing topology.
    pub mod tessellate {
        pub use crate::render::tessellate::cpu::*;
    }
    /// The relaxation of materials with an angle of repose: one step, and the slope's threshold.
    pub mod relax {
        pub use crate::relax::cpu::*;
    }
    /// Kicked-up snow: which texels spawn, the ring's bookkeeping, a particle's step.
    pub mod spray {
        pub use crate::spray::cpu::*;
    }
    /// Skinning: a skeleton posed at an animation's time, joint matrices, skinned vertices.
    pub mod skin {
        pub use crate::skin::cpu::*;
    }
    /// The ground: a mesh rasterised over a surface's texel centres.
    pub mod ground {
        pub use crate::ground::cpu::*;
    }
}

/// The pieces an engine or a tool may need that are not the everyday API: the world's frame plan,
/// the capture and accumulation pipelines and their `encode`, the pool's allocator and surface
/// records, the render graph's pass table, the manager's imprint queue and pages, GPU readback and
/// timestamps. These follow the internals and change more often than the crate root.
pub mod low_level {
    /// The world's plan of a frame, made on the CPU before anything is encoded.
    pub mod world {
        pub use crate::world::plan::*;
    }
    /// The ground mesh rasterisation pass and its uniform.
    pub mod ground {
        pub use crate::capture::NO_GROUND;
        pub use crate::ground::raster::{GroundRaster, RasterView, decode_height};
        pub use crate::ground::sample_grid;
    }
    /// The capture pass: pipelines, primitives, atlas packing and `encode`.
    pub mod capture {
        pub use crate::capture::{
            APRON, ATLAS_FORMAT, AtlasPlacement, CAST, CAST_PRIMS_MAX, CaptureBuffers, CaptureMesh,
            CapturePipelines, CapturePlan, CaptureView, CaptureVolume, CapturedSurface,
            GpuPrimitive, MAX_MESH_SUBSTEPS, MAX_SUBSTEPS, MESH_STEP, MeshDraw, NO_LIST, ONE_BITS,
            PRIM_BOX, PRIM_CAPSULE, decode_depth, encode, encode_depth, mesh_substeps, pack_atlas,
            pack_atlas_compact, push_mesh_draws, push_primitives, region, region_texels,
            strip_apron, substeps,
        };
    }
    /// The relaxation pass: its records, plan, pipelines and `encode`.
    pub mod relax {
        pub use crate::relax::{RelaxBuffers, RelaxPipelines, RelaxPlan, RelaxRecord, encode};
    }
    /// The accumulation passes: pipelines and `encode`.
    pub mod accumulate {
        pub use crate::accumulate::{
            AccumulateBuffers, AccumulatePipelines, AccumulatePlan, TILE_LIST_HEADER, WORKGROUP,
            encode,
        };
    }
    /// The heightmap pool: slot allocator and the per-surface record the passes read.
    pub mod pool {
        pub use crate::pool::{
            MODE_CAST, MODE_GROUND, MODE_MESHES, MODE_REFILLED, NO_CAPTURE, NO_NORMALS, SLOT_ALIGN,
            Slot, SlotAllocator, SurfaceRecord, TILE_LIST_HEADER, TILE_SIDE,
        };
    }
    /// The render graph: the pass table and its check.
    pub mod graph {
        pub use crate::render::graph::*;
    }
    /// The renderer's GPU-side structs (uniforms, records, vertex layouts), laid out as in WGSL.
    pub mod render {
        pub use crate::render::geometry::*;
        pub use crate::render::gpu::*;
    }
    /// The tessellated tier's GPU records: base triangles, dicing and bank parameters, the
    /// counters and indirect arguments the dicing pass writes.
    pub mod tessellate {
        pub use crate::render::tessellate::{
            ARGS_BASE, ARGS_STRIDE, BankParams, BaseTriangle, COUNTER_INDICES, COUNTER_OVERFLOW,
            COUNTER_VERTICES, DiceParams, MAX_BASE_TRIANGLES, MAX_LEVEL, VERTEX_BYTES,
        };
    }
    /// GPU readback and timestamp queries, and the adapter checks.
    pub mod gpu {
        pub use crate::gpu::readback::*;
        pub use crate::gpu::timestamps::*;
        pub use crate::gpu::{REQUIRED_DOWNLEVEL, check_device, describe, missing_capabilities};
    }
    /// The skinning pass's bind-pose vertex as uploaded, and its workgroup size.
    pub mod skin {
        pub use crate::skin::{GpuBindVertex, SKIN_WORKGROUP};
    }
    /// The manager's per-surface imprint queue (merging, bounding).
    pub mod queue {
        pub use crate::manager::queue::*;
    }
    /// Compressed pages of surfaces paged out of the pool.
    pub mod pages {
        pub use crate::manager::pages::*;
    }
}
