//! Capture from below: the ankle-high orthographic frustum of the talk.
//!
//! For every surface updated in a frame, the deformers over it are rendered into a rectangle of a
//! shared depth atlas, looking up from the ground. The frustum runs from the ground (depth 0) to the
//! snow top plus an ankle height (depth 1); the depth test keeps the lowest point of any deformer per
//! texel, the talk's minimum-height field. Surfaces are packed into the atlas so that one render pass
//! captures many of them, each in its own viewport. What is captured is a surface's capture
//! [`region`]: its texels and an apron of one texel beyond each side, which the update's blur
//! reads, so that two surfaces on one texel grid update the line where they meet as one would.
//!
//! Analytic deformers (spheres, capsules, boxes) are drawn as one bounding rectangle each and
//! ray-cast exactly in the fragment shader; a moving sphere is swept into a capsule, other shapes
//! are sub-stepped along their motion. Meshes are rasterized with the override material of the
//! talk: depth only. Both honour depth clamping: a solid that reaches below the ground fills the
//! ground, one entirely below it or above the frustum leaves nothing.
//!
//! CPU reference: [`cpu`].

pub(crate) mod cpu;
mod encode;
mod tiles;

pub use encode::{
    CaptureBuffers, CaptureMesh, CapturePlan, CapturedSurface, append_work_table, encode,
    work_table_bytes,
};
pub use tiles::{tiles_reached, update_tiles_reached};

use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec3};

use crate::deformer::{Deformer, Pose, Shape};
use crate::mesh::MeshId;

/// Which of the talk's two capture paths to use.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum CaptureMode {
    /// The talk's PC path: the lowest point of any deformer per texel, a minimum-height field.
    #[default]
    Depth,
    /// The talk's console path: clear black, deformers white, a fixed imprint depth.
    Mask,
}

/// How surfaces are captured.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CaptureConfig {
    /// Depth or mask capture.
    pub mode: CaptureMode,
    /// Height of the frustum above the snow top, metres (default 0.25).
    pub ankle_height: f32,
    /// In mask mode, the fraction of the snow depth a covered texel is pressed down (default 1).
    pub mask_depth: f32,
}

impl Default for CaptureConfig {
    fn default() -> Self {
        Self {
            mode: CaptureMode::Depth,
            ankle_height: 0.25,
            mask_depth: 1.0,
        }
    }
}

/// WGSL of the capture pass.
pub const SHADER: &str = crate::wgsl::CAPTURE.source;

/// Format of the render target that places each surface's viewport. The capture itself goes to a
/// storage buffer (atomic max of an encoded depth), so this target is never cleared, read or written:
/// the smallest depth format keeps its memory small.
pub const ATLAS_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth16Unorm;

/// Code of depth 1.0, the top of the frustum.
pub const ONE_BITS: u32 = crate::wgsl::consts::ONE_BITS;

/// Encode a depth in [0, 1] as the capture stores it: 0 means nothing was captured, larger values are
/// lower points (so an atomic max keeps the lowest).
pub fn encode_depth(depth: f32) -> u32 {
    ONE_BITS - depth.clamp(0.0, 1.0).to_bits()
}

/// Decode a stored capture value to a depth in [0, 1] (1 = nothing captured).
pub fn decode_depth(code: u32) -> f32 {
    f32::from_bits(ONE_BITS.saturating_sub(code))
}

/// Most sub-steps an analytic deformer is split into along its motion in one update.
pub const MAX_SUBSTEPS: u32 = 32;

/// Texels of apron the capture covers beyond each side of a surface. The update's blur reads one
/// texel around each texel, so a surface's capture is its rectangle grown by a texel on every side:
/// two surfaces on one texel grid then blur the same field along the line where they meet, as one
/// surface over both would, instead of each clamping at its own edge.
pub const APRON: u32 = crate::wgsl::consts::APRON;

/// The capture region of a `width` x `height` surface: its texels and the apron around them,
/// `(width + 2 APRON, height + 2 APRON)`. Region texel `(c, r)` is the surface's logical texel
/// `(c - APRON, r - APRON)`.
pub fn region(width: u32, height: u32) -> (u32, u32) {
    (width + 2 * APRON, height + 2 * APRON)
}

/// Texels of a surface's capture region ([`region`]).
pub fn region_texels(width: u32, height: u32) -> u32 {
    let (w, h) = region(width, height);
    w * h
}

/// The surface's own `width` x `height` texels of a capture `region` laid out as [`region`] says
/// (the apron left out), row-major.
pub fn strip_apron<T: Copy>(width: u32, height: u32, region_values: &[T]) -> Vec<T> {
    let (rw, _) = region(width, height);
    (0..height)
        .flat_map(|y| (0..width).map(move |x| ((y + APRON) * rw + x + APRON) as usize))
        .map(|i| region_values[i])
        .collect()
}

/// `record` of a [`CaptureView`] whose flagged tiles are not listed (the update runs its grid).
pub const NO_LIST: u32 = crate::wgsl::consts::NO_LIST;

/// One surface's capture view: a uniform block in `capture.wgsl`, 256-byte storage blocks in
/// `prims.wgsl`. Must match `CaptureView` in `write.wgsl`. Its sizes are the surface's; what is
/// captured is the surface's [`region`], the apron included.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct CaptureView {
    /// Half the surface's sides, metres.
    pub half_size: [f32; 2],
    /// Snow depth plus ankle height, metres.
    pub frustum_height: f32,
    /// First texel of the surface's capture region ([`region`]) in the capture buffer.
    pub offset: u32,
    /// The region's top-left texel in the atlas.
    pub origin: [f32; 2],
    /// The surface's heightmap width and height, texels.
    pub texels: [f32; 2],
    /// First tile flag of the surface in the tiles buffer.
    pub tiles: u32,
    /// Tiles a row (16x16 texels each).
    pub tiles_x: u32,
    /// The surface's record in the update (listed with each flagged tile), or [`NO_LIST`].
    pub record: u32,
    /// First texel of the surface's ground field in the capture's ground buffer, or [`NO_GROUND`]
    /// on flat ground.
    pub ground: u32,
    /// Compute path: its primitives (first, count); count 0 on the raster path.
    pub prims: [u32; 2],
    /// Compute path: 1 where its region is not cleared and each tile the work list takes is
    /// written whole (`tiles_reached`); else 0.
    pub whole: u32,
    /// Padding to the WGSL struct's 8-byte alignment.
    pub _pad: u32,
}

/// A primitive's footprint on its surface: the corners of its bounding rectangle, local `(x, z)`.
/// Must match `prim_footprint` in `write.wgsl`.
pub fn footprint(p: &GpuPrimitive) -> [f32; 4] {
    if p.kind[0] == PRIM_CAPSULE {
        let r = p.p0[3];
        return [
            p.p0[0].min(p.p1[0]) - r,
            p.p0[2].min(p.p1[2]) - r,
            p.p0[0].max(p.p1[0]) + r,
            p.p0[2].max(p.p1[2]) + r,
        ];
    }
    let e = |k: usize| p.p1[k].abs() * p.p1[3] + p.p2[k].abs() * p.p2[3] + p.p3[k].abs() * p.p3[3];
    let (ex, ez) = (e(0), e(2));
    [p.p0[0] - ex, p.p0[2] - ez, p.p0[0] + ex, p.p0[2] + ez]
}

/// `batch` of a surface record captured by the compute path (no pass over the atlas; anything but
/// `NO_CAPTURE` tells the update that the capture holds its texels).
pub const COMPUTED: u32 = 0xffff_fffe;

/// `batch` of a surface record whose analytic primitives the update ray-casts itself
/// ([`CapturePath::Update`], [`crate::pool::MODE_CAST`]): no capture holds its texels.
pub const CAST: u32 = 0xffff_fffd;

/// Most analytic primitives a surface may have and still be ray-cast by the update itself
/// ([`CapturePath::Update`]): each texel its blur reads tests every one of them that reaches its
/// tile, and a tile keeps them in a mask of one bit each.
pub const CAST_PRIMS_MAX: u32 = crate::wgsl::consts::CAST_PRIMS_MAX;

/// Most analytic primitives a surface may have and still be captured by the compute path (each
/// texel of its reach tests every one of them; past this the raster path, which draws each
/// primitive's rectangle alone, does less work).
pub const COMPUTE_PRIMS_MAX: u32 = 256;

/// Which path captures analytic deformers. All give the same bits (`tests/capture_paths.rs`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum CapturePath {
    /// [`CapturePath::Update`] on a GPU (where it costs the least: `docs/PERFORMANCE.md`, "The
    /// update's own ray cast"), [`CapturePath::Raster`] on a software adapter (where llvmpipe ran
    /// the compute path up to three times slower).
    #[default]
    Auto,
    /// Compute, one dispatch for every surface that only analytic deformers press (up to
    /// `COMPUTE_PRIMS_MAX` primitives): no viewport and no draw per surface, a workgroup per tile
    /// the primitives reach. Surfaces that meshes press are rendered.
    Compute,
    /// Every surface rendered in its viewport of the atlas, primitives as rectangles.
    Raster,
    /// No capture for the surfaces that only analytic deformers press, up to
    /// [`CAST_PRIMS_MAX`] primitives: the fused update ray-casts them itself at each texel its
    /// blur reads, so they need no capture pass, no capture memory and no clear. The others take
    /// [`CapturePath::Compute`], and every surface does in a world with separate passes
    /// ([`crate::PassMode::Separate`]) or kicked-up snow, whose passes read the capture.
    Update,
}

impl CapturePath {
    /// The path `Auto` stands for on an adapter of `device_type`.
    pub fn resolved(self, device_type: wgpu::DeviceType) -> Self {
        match (self, device_type) {
            (Self::Auto, wgpu::DeviceType::Cpu) => Self::Raster,
            (Self::Auto, _) => Self::Update,
            (path, _) => path,
        }
    }
}

/// `ground` of a [`CaptureView`] on flat ground.
pub const NO_GROUND: u32 = crate::wgsl::consts::NO_GROUND;

/// An analytic deformer in surface-local coordinates. Must match `Primitive` in `write.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct GpuPrimitive {
    /// `kind[0]`: [`PRIM_CAPSULE`] or [`PRIM_BOX`].
    pub kind: [u32; 4],
    /// Capsule: segment start and radius. Box: centre.
    pub p0: [f32; 4],
    /// Capsule: segment end. Box: unit x axis and half extent.
    pub p1: [f32; 4],
    /// Box: unit y axis and half extent.
    pub p2: [f32; 4],
    /// Box: unit z axis and half extent.
    pub p3: [f32; 4],
}

/// Primitive kind: capsule (a sphere is a capsule of zero length).
pub const PRIM_CAPSULE: u32 = crate::wgsl::consts::PRIM_CAPSULE;
/// Primitive kind: oriented box.
pub const PRIM_BOX: u32 = crate::wgsl::consts::PRIM_BOX;

/// Per-draw uniform of a mesh deformer. Must match `MeshDraw` in `capture.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct MeshDraw {
    /// Mesh space to surface-local space.
    pub to_local: [[f32; 4]; 4],
}

impl GpuPrimitive {
    /// A capsule from `a` to `b` of radius `r`.
    pub fn capsule(a: Vec3, b: Vec3, r: f32) -> Self {
        Self {
            kind: [PRIM_CAPSULE, 0, 0, 0],
            p0: [a.x, a.y, a.z, r],
            p1: [b.x, b.y, b.z, 0.0],
            ..Default::default()
        }
    }

    /// A box with centre `c`, orthonormal axes and half extents.
    pub fn oriented_box(c: Vec3, axes: [Vec3; 3], half: Vec3) -> Self {
        let v = |a: Vec3, h: f32| [a.x, a.y, a.z, h];
        Self {
            kind: [PRIM_BOX, 0, 0, 0],
            p0: [c.x, c.y, c.z, 0.0],
            p1: v(axes[0], half.x),
            p2: v(axes[1], half.y),
            p3: v(axes[2], half.z),
        }
    }

    /// Local-space bounds `(min, max)`.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        let p0 = Vec3::from_slice(&self.p0[..3]);
        if self.kind[0] == PRIM_CAPSULE {
            let p1 = Vec3::from_slice(&self.p1[..3]);
            let r = Vec3::splat(self.p0[3]);
            (p0.min(p1) - r, p0.max(p1) + r)
        } else {
            let e = [self.p1, self.p2, self.p3]
                .iter()
                .map(|a| Vec3::from_slice(&a[..3]).abs() * a[3])
                .fold(Vec3::ZERO, |acc, v| acc + v);
            (p0 - e, p0 + e)
        }
    }
}

/// The capture volume of a surface in its local frame: `|x| <= half.x`, `|z| <= half.z`,
/// `ground.0 <= y <= ground.1 + frustum_height`. The world's plan culls against the surface's
/// capture [`region`]: `half_size` is then half the surface's sides plus a texel
/// ([`CaptureVolume::of_region`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CaptureVolume {
    /// World to surface-local transform.
    pub world_to_local: Mat4,
    /// Half the surface's sides.
    pub half_size: glam::Vec2,
    /// Snow depth plus ankle height.
    pub frustum_height: f32,
    /// The lowest base and the highest base of the surface's ground (local metres; `(0, 0)` on flat
    /// ground): the frustum of each texel rises from its base (see [`crate::GroundField`]).
    pub ground: (f32, f32),
}

impl CaptureVolume {
    /// Half sides of the capture [`region`] of a surface of half sides `half` and `width` x
    /// `height` texels: the surface's rectangle grown by [`APRON`] texels on every side.
    pub fn of_region(half: glam::Vec2, width: u32, height: u32) -> glam::Vec2 {
        let texel = half * 2.0 / glam::Vec2::new(width as f32, height as f32);
        half + texel * APRON as f32
    }

    /// Whether local bounds overlap the volume.
    pub fn overlaps(&self, lo: Vec3, hi: Vec3) -> bool {
        hi.x >= -self.half_size.x
            && lo.x <= self.half_size.x
            && hi.z >= -self.half_size.y
            && lo.z <= self.half_size.y
            && hi.y >= self.ground.0
            && lo.y < self.ground.1 + self.frustum_height
    }

    /// Whether a world-space ball overlaps the volume.
    pub fn overlaps_ball(&self, center: Vec3, radius: f32) -> bool {
        let c = self.world_to_local.transform_point3(center);
        self.overlaps(c - Vec3::splat(radius), c + Vec3::splat(radius))
    }
}

/// A world-space ball holding an analytic deformer at every pose of its motion (the positions
/// move on a straight line from `previous` to `pose`), a little larger than needed so that
/// rounding never leaves out a primitive the exact tests would keep; `None` for a mesh.
pub fn swept_ball(deformer: &Deformer) -> Option<(Vec3, f32)> {
    let reach = match deformer.shape {
        Shape::Sphere { radius } => radius,
        Shape::Capsule {
            radius,
            half_height,
        } => radius + half_height,
        Shape::Box { half_extents } => half_extents.length(),
        Shape::Mesh(_) => return None,
    };
    let (a, b) = (
        deformer.previous.unwrap_or(deformer.pose).position,
        deformer.pose.position,
    );
    let radius = 0.5 * a.distance(b) + reach;
    Some(((a + b) * 0.5, radius * 1.001 + 1e-4))
}

/// Number of sub-steps for a motion of `distance` metres by a shape whose smallest feature is
/// `feature` metres: steps no longer than half the feature, at most [`MAX_SUBSTEPS`].
pub fn substeps(distance: f32, feature: f32) -> u32 {
    if distance <= 0.0 || feature <= 0.0 {
        return 1;
    }
    ((distance / (0.5 * feature)).ceil() as u32).clamp(1, MAX_SUBSTEPS)
}

/// Most sub-steps a mesh deformer is drawn at along its motion in one update.
pub const MAX_MESH_SUBSTEPS: u32 = 8;

/// Longest step between two drawn poses of a moving mesh, metres, at the point of the mesh that
/// moves most: under one 4 cm texel, so that the copies overlap into a continuous sweep.
pub const MESH_STEP: f32 = 0.03;

/// Sub-steps for a rigid mesh of bounding radius `radius` moving from `a` to `b`: how far its
/// farthest point can travel (translation plus rotation angle times radius) over [`MESH_STEP`], at
/// most [`MAX_MESH_SUBSTEPS`]. The pose at the end is always drawn; the start was the previous
/// frame's end.
pub fn mesh_substeps(a: &Pose, b: &Pose, radius: f32) -> u32 {
    let travel = a.position.distance(b.position) + a.rotation.angle_between(b.rotation) * radius;
    if !travel.is_finite() || travel <= MESH_STEP {
        return 1;
    }
    ((travel / MESH_STEP).ceil() as u32).clamp(1, MAX_MESH_SUBSTEPS)
}

/// Append the analytic primitives of one deformer, in the local frame of `volume`, culled against
/// it. Meshes append nothing (they are drawn separately).
pub fn push_primitives(deformer: &Deformer, volume: &CaptureVolume, out: &mut Vec<GpuPrimitive>) {
    // Most deformers of a world are far from most of its surfaces: one ball around the whole
    // motion rules them out before any primitive is built.
    if let Some((center, radius)) = swept_ball(deformer)
        && !volume.overlaps_ball(center, radius)
    {
        return;
    }
    let m = volume.world_to_local;
    let prev = deformer.previous.unwrap_or(deformer.pose);
    let mut push = |p: GpuPrimitive| {
        let (lo, hi) = p.bounds();
        if volume.overlaps(lo, hi) {
            out.push(p);
        }
    };
    match deformer.shape {
        Shape::Sphere { radius } => {
            // A sphere swept along a straight line is exactly a capsule.
            push(GpuPrimitive::capsule(
                m.transform_point3(prev.position),
                m.transform_point3(deformer.pose.position),
                radius,
            ));
        }
        Shape::Capsule {
            radius,
            half_height,
        } => {
            let ends = |p: &Pose| {
                let axis = p.rotation * Vec3::Y * half_height;
                (p.position - axis, p.position + axis)
            };
            let (a0, b0) = ends(&prev);
            let (a1, b1) = ends(&deformer.pose);
            let n = substeps(a0.distance(a1).max(b0.distance(b1)), radius);
            for k in 0..=n {
                let t = k as f32 / n as f32;
                let (a, b) = ends(&prev.lerp(&deformer.pose, t));
                push(GpuPrimitive::capsule(
                    m.transform_point3(a),
                    m.transform_point3(b),
                    radius,
                ));
                if deformer.previous.is_none() {
                    break;
                }
            }
        }
        Shape::Box { half_extents } => {
            let corner_move = prev.position.distance(deformer.pose.position)
                + prev.rotation.angle_between(deformer.pose.rotation) * half_extents.length();
            let n = substeps(corner_move, half_extents.min_element() * 2.0);
            // Only a box needs the frame's rotation (a decomposition of the matrix).
            let (_, local_rot, _) = m.to_scale_rotation_translation();
            for k in 0..=n {
                let t = k as f32 / n as f32;
                let p = prev.lerp(&deformer.pose, t);
                let r = local_rot * p.rotation;
                push(GpuPrimitive::oriented_box(
                    m.transform_point3(p.position),
                    [r * Vec3::X, r * Vec3::Y, r * Vec3::Z],
                    half_extents,
                ));
                if deformer.previous.is_none() {
                    break;
                }
            }
        }
        Shape::Mesh(_) => {}
    }
}

/// Append the draws of one mesh deformer (`mesh`, of bounding radius `radius`), mesh space to the
/// local frame of `volume`, culled against it. A moving mesh is drawn at sub-steps along its
/// motion ([`mesh_substeps`]), so that a fast hand or foot leaves a continuous sweep rather than a
/// comb of copies; the pose at the end is always among them.
pub fn push_mesh_draws(
    deformer: &Deformer,
    mesh: MeshId,
    radius: f32,
    volume: &CaptureVolume,
    draws: &mut Vec<MeshDraw>,
    meshes: &mut Vec<MeshId>,
) {
    let prev = deformer.previous.unwrap_or(deformer.pose);
    let n = mesh_substeps(&prev, &deformer.pose, radius);
    for k in 1..=n {
        let p = prev.lerp(&deformer.pose, k as f32 / n as f32);
        if volume.overlaps_ball(p.position, radius) {
            let model = Mat4::from_rotation_translation(p.rotation, p.position);
            draws.push(MeshDraw {
                to_local: (volume.world_to_local * model).to_cols_array_2d(),
            });
            meshes.push(mesh);
        }
    }
}

/// The render pipelines of the capture and their bind group layouts.
pub struct CapturePipelines {
    /// Analytic deformers: bounding rectangles, ray-cast per texel.
    pub primitives: wgpu::RenderPipeline,
    /// Mesh deformers.
    pub meshes: wgpu::RenderPipeline,
    /// Group 0: view (dynamic uniform), primitives (storage), capture and winding (storage).
    pub view_layout: wgpu::BindGroupLayout,
    /// Group 1: mesh draw (dynamic uniform).
    pub draw_layout: wgpu::BindGroupLayout,
    /// The compute path for analytic deformers (`prims.wgsl`).
    pub compute: wgpu::ComputePipeline,
    /// Its group 0: views, primitives and ground (storage, read), capture, tiles and tile list.
    pub compute_layout: wgpu::BindGroupLayout,
}

impl CapturePipelines {
    /// Build both pipelines.
    pub fn new(device: &wgpu::Device) -> Self {
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("capture.wgsl"),
            source: wgpu::ShaderSource::Wgsl(SHADER.into()),
        });
        let view_layout = crate::wgsl::CAPTURE.bind_group_layout(device, "capture view", 0);
        let draw_layout = crate::wgsl::CAPTURE.bind_group_layout(device, "capture mesh draw", 1);
        let prim_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("capture primitives"),
            bind_group_layouts: &[Some(&view_layout)],
            immediate_size: 0,
        });
        let mesh_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("capture meshes"),
            bind_group_layouts: &[Some(&view_layout), Some(&draw_layout)],
            immediate_size: 0,
        });
        let depth = Some(wgpu::DepthStencilState {
            format: ATLAS_FORMAT,
            depth_write_enabled: Some(false),
            depth_compare: Some(wgpu::CompareFunction::Always),
            stencil: wgpu::StencilState::default(),
            bias: wgpu::DepthBiasState::default(),
        });
        let primitives = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("capture primitives"),
            layout: Some(&prim_layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_prim"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: wgpu::PrimitiveState::default(),
            depth_stencil: depth.clone(),
            multisample: wgpu::MultisampleState::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_prim"),
                compilation_options: Default::default(),
                targets: &[],
            }),
            multiview_mask: None,
            cache: None,
        });
        let meshes = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("capture meshes"),
            layout: Some(&mesh_layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_mesh"),
                compilation_options: Default::default(),
                buffers: &[Some(wgpu::VertexBufferLayout {
                    array_stride: 12,
                    step_mode: wgpu::VertexStepMode::Vertex,
                    attributes: &wgpu::vertex_attr_array![0 => Float32x3],
                })],
            },
            primitive: wgpu::PrimitiveState {
                // Seen from below through this projection, a face whose outward normal points down
                // (towards the camera) is wound clockwise; that is the front face.
                front_face: wgpu::FrontFace::Cw,
                cull_mode: None,
                // Depth is not tested; clip z is constant so nothing is clipped (see vs_mesh).
                ..Default::default()
            },
            depth_stencil: depth,
            multisample: wgpu::MultisampleState::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_mesh"),
                compilation_options: Default::default(),
                targets: &[],
            }),
            multiview_mask: None,
            cache: None,
        });
        let compute_layout =
            crate::wgsl::CAPTURE_PRIMS.bind_group_layout(device, "capture compute", 0);
        let compute_module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("prims.wgsl"),
            source: wgpu::ShaderSource::Wgsl(crate::wgsl::CAPTURE_PRIMS.source.into()),
        });
        let compute_pl = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("capture compute"),
            bind_group_layouts: &[Some(&compute_layout)],
            immediate_size: 0,
        });
        let compute = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("capture compute"),
            layout: Some(&compute_pl),
            module: &compute_module,
            entry_point: Some("capture_prims"),
            compilation_options: Default::default(),
            cache: None,
        });
        Self {
            primitives,
            meshes,
            view_layout,
            draw_layout,
            compute,
            compute_layout,
        }
    }
}

/// Where a surface's capture lies in the atlas.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct AtlasPlacement {
    /// Which pass over the atlas (when the surfaces of a frame do not fit in one).
    pub batch: u32,
    /// Left texel.
    pub x: u32,
    /// Top texel.
    pub y: u32,
}

/// Shelf-pack rectangles `(width, height)` into an atlas of `side` x `side`, opening a new batch
/// when one is full. Rectangles are placed tallest first; the result is in input order.
pub fn pack_atlas(rects: &[(u32, u32)], side: u32) -> Vec<AtlasPlacement> {
    let mut order: Vec<usize> = (0..rects.len()).collect();
    order.sort_by_key(|&i| std::cmp::Reverse((rects[i].1, rects[i].0)));
    let mut out = vec![
        AtlasPlacement {
            batch: 0,
            x: 0,
            y: 0
        };
        rects.len()
    ];
    let (mut batch, mut x, mut y, mut shelf) = (0u32, 0u32, 0u32, 0u32);
    for i in order {
        let (w, h) = rects[i];
        if x + w > side {
            x = 0;
            y += shelf;
            shelf = 0;
        }
        if y + h > side {
            batch += 1;
            x = 0;
            y = 0;
            shelf = 0;
        }
        out[i] = AtlasPlacement { batch, x, y };
        x += w;
        shelf = shelf.max(h);
    }
    out
}

/// Pack into the smallest power-of-two square (at least 64, at most `max_side`) that holds every
/// rectangle in one batch; at `max_side`, several batches. Returns the placements and the side.
pub fn pack_atlas_compact(rects: &[(u32, u32)], max_side: u32) -> (Vec<AtlasPlacement>, u32) {
    let area: u64 = rects.iter().map(|r| r.0 as u64 * r.1 as u64).sum();
    let widest = rects.iter().map(|r| r.0.max(r.1)).max().unwrap_or(1);
    let mut side = ((area as f64).sqrt().ceil() as u32)
        .max(widest)
        .next_power_of_two()
        .clamp(64, max_side.max(64));
    loop {
        let placements = pack_atlas(rects, side);
        if side >= max_side || placements.iter().all(|p| p.batch == 0) {
            return (placements, side);
        }
        side *= 2;
    }
}

#[cfg(test)]
mod tests;
