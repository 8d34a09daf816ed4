//! The tessellated tier ([`Tier::Tessellated`](super::Tier::Tessellated)): real displaced snow
//! geometry, the talk's "DirectX 11 With Tessellation" path done the way current engines do it
//! without hull and domain shaders: a compute pass dices each surface's mesh into vertices and
//! indices, and an indexed indirect draw displaces them in the vertex stage.
//!
//! | pass | WGSL | reads | writes |
//! |---|---|---|---|
//! | `banks` (compute, indirect) | `banks.wgsl` | heightfields (smoothed depression, displaced channel) | per surface: bank heights |
//! | `dice` (compute) | `dice.wgsl` | base meshes, heightfields, banks, surface state, camera | diced vertices, indices, indirect draws |
//! | `snow_shadow` (render) | `tess_surface.wgsl` | diced mesh, heightfields, banks | the moon's shadow map (both cascades) |
//! | `snow` (render, indexed indirect) | `tess_surface.wgsl` | diced mesh, heightfields, banks, shadow map | scene colour, depth |
//!
//! **Crack-free dicing.** Every edge of the base mesh gets a level (number of segments) that is a
//! function of the edge alone: its two endpoints, taken lower vertex id first. A triangle's interior
//! is a uniform lattice of level `N = max(levels, 3)` whose outer ring is replaced by three strips
//! stitched between each edge's own points and the inner lattice. The points of a shared edge are
//! computed by one expression from the same canonical endpoints in both triangles, so they are the
//! same to the bit, and each segment of an edge belongs to one triangle on each side: no cracks
//! and no T-junctions. Displacement is a function of the local (x, z) only, so equal points stay
//! equal after it. Edges of the base mesh that no other triangle shares get **skirts**: a wall from
//! the displaced top down to the base, so open edges never show a gap.
//!
//! **Banks.** A fraction ([`BankSettings::fraction`]) of the snow the captures pushed down (the
//! heightmap's displaced channel) is moved onto the snow around it within the bank width; the rest
//! is compacted. Each texel gives away exactly its share, normalized over where it lands, so the
//! banks' volume is that fraction of the pushed volume (see [`cpu::bank_field`] and the test
//! `tests/render_tessellated.rs`).

pub(in crate::render) mod banks;
pub(crate) mod cpu;
pub(in crate::render) mod dice;
pub(crate) mod gpu;
pub(in crate::render) mod seams;
pub(in crate::render) mod snow_shadow;

use bytemuck::{Pod, Zeroable};
use glam::{Vec2, Vec3};

use super::error::{RenderError, RenderResult};

/// Largest edge level (segments per base-mesh edge). Must match nothing in WGSL: the level is a
/// uniform there.
pub const MAX_LEVEL: u32 = 64;
/// Most triangles in a surface's base mesh (the dicing dispatch is one workgroup per triangle).
pub const MAX_BASE_TRIANGLES: usize = 1 << 20;
/// Words of the dicing counters before the per-surface draw arguments.
pub const ARGS_BASE: u64 = crate::wgsl::consts::ARGS_BASE as u64;
/// Words per surface of draw arguments.
pub const ARGS_STRIDE: u64 = crate::wgsl::consts::ARGS_STRIDE as u64;
/// Counter of vertices appended.
pub const COUNTER_VERTICES: u64 = crate::wgsl::consts::COUNTER_VERTICES as u64;
/// Counter of indices appended.
pub const COUNTER_INDICES: u64 = crate::wgsl::consts::COUNTER_INDICES as u64;
/// Counter of base triangles dropped because the buffers were full.
pub const COUNTER_OVERFLOW: u64 = crate::wgsl::consts::COUNTER_OVERFLOW as u64;
/// Bytes of one diced vertex: local position and kind, skirt normal.
pub const VERTEX_BYTES: u64 = 32;

/// Snow banks (berms) beside trails, from the heightmap's displaced channel.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct BankSettings {
    /// Share of the pushed snow that rises in banks (0 to 1); the rest is compacted.
    pub fraction: f32,
    /// How far from where it was pushed the snow lands, metres (at least a texel, at most 2 m).
    pub width: f32,
}

impl Default for BankSettings {
    /// 25 % of the pushed volume into banks within 30 cm (more buries people lying in the snow).
    fn default() -> Self {
        Self {
            fraction: 0.25,
            width: 0.3,
        }
    }
}

/// The top of a snow surface as a triangle mesh in the surface's local frame: `x` and `z` within
/// the surface's rectangle (where its heightmap is), `y` the height of the base the snow lies on
/// (0 for a flat roof). The snow is displaced along local +y from there.
#[derive(Clone, Debug, PartialEq)]
pub struct SurfaceMesh {
    /// Vertex positions, local frame, metres.
    pub positions: Vec<Vec3>,
    /// Triangles (indices into `positions`), counter-clockwise seen from above.
    pub triangles: Vec<[u32; 3]>,
}

impl SurfaceMesh {
    /// The default mesh: the rectangle `[-half.x, half.x] x [-half.y, half.y]` cut into cells of
    /// about a metre (at most 64 a side), two triangles a cell.
    pub fn rectangle(half: Vec2) -> Self {
        let (xs, zs) = rectangle_lines(half);
        let (nx, nz) = (xs.len() as u32 - 1, zs.len() as u32 - 1);
        let positions = zs
            .iter()
            .flat_map(|&z| xs.iter().map(move |&x| Vec3::new(x, 0.0, z)))
            .collect();
        let id = |c: u32, r: u32| r * (nx + 1) + c;
        let mut triangles = Vec::with_capacity((2 * nx * nz) as usize);
        for r in 0..nz {
            for c in 0..nx {
                // Counter-clockwise seen from above (+y): x right, z towards the viewer.
                triangles.push([id(c, r), id(c, r + 1), id(c + 1, r + 1)]);
                triangles.push([id(c, r), id(c + 1, r + 1), id(c + 1, r)]);
            }
        }
        Self {
            positions,
            triangles,
        }
    }

    /// Check the mesh against a surface of half sides `half`: finite positions within the
    /// rectangle, valid indices, no triangle without area seen from above, no edge shared by more
    /// than two triangles. The error names the first problem.
    pub fn validate(&self, half: Vec2) -> RenderResult<()> {
        let bad = |value: String, expected| {
            Err(RenderError::InvalidFrame {
                what: "surface mesh".into(),
                value,
                expected,
            })
        };
        if self.triangles.is_empty() || self.triangles.len() > MAX_BASE_TRIANGLES {
            return bad(
                format!("{} triangles", self.triangles.len()),
                "between 1 and 1048576 triangles",
            );
        }
        let slack = 1e-3;
        for (i, p) in self.positions.iter().enumerate() {
            if !p.is_finite() || p.x.abs() > half.x + slack || p.z.abs() > half.y + slack {
                return bad(
                    format!("vertex {i} at {:?}", p.to_array()),
                    "finite, with x and z within the surface's rectangle (its heightmap)",
                );
            }
        }
        let n = self.positions.len() as u32;
        let mut edges = std::collections::HashMap::new();
        for (i, t) in self.triangles.iter().enumerate() {
            if t.iter().any(|&v| v >= n) {
                return bad(
                    format!("triangle {i} {t:?} with {n} vertices"),
                    "indices of existing vertices",
                );
            }
            let [a, b, c] = t.map(|v| self.positions[v as usize]);
            let area = (b.x - a.x) * (c.z - a.z) - (b.z - a.z) * (c.x - a.x);
            if area.abs() < 1e-8 || t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
                return bad(
                    format!("triangle {i} {t:?}"),
                    "triangles with an area seen from above",
                );
            }
            for e in 0..3 {
                let key = (t[e].min(t[(e + 1) % 3]), t[e].max(t[(e + 1) % 3]));
                let uses = edges.entry(key).or_insert(0u32);
                *uses += 1;
                if *uses > 2 {
                    return bad(
                        format!("edge {key:?}, shared by three triangles or more"),
                        "edges shared by at most two triangles",
                    );
                }
            }
        }
        Ok(())
    }

    /// The triangles as the dicing pass reads them, with the border edges (used by one triangle)
    /// marked.
    pub fn base_triangles(&self) -> Vec<BaseTriangle> {
        let mut uses = std::collections::HashMap::new();
        for t in &self.triangles {
            for e in 0..3 {
                let key = (t[e].min(t[(e + 1) % 3]), t[e].max(t[(e + 1) % 3]));
                *uses.entry(key).or_insert(0u32) += 1;
            }
        }
        self.triangles
            .iter()
            .map(|t| {
                let mut border = 0u32;
                for e in 0..3 {
                    let key = (t[e].min(t[(e + 1) % 3]), t[e].max(t[(e + 1) % 3]));
                    if uses[&key] == 1 {
                        border |= 1 << e;
                    }
                }
                let p = |v: u32| {
                    let q = self.positions[v as usize];
                    [q.x, q.y, q.z, 0.0]
                };
                BaseTriangle {
                    a: p(t[0]),
                    b: p(t[1]),
                    c: p(t[2]),
                    ids: [t[0], t[1], t[2], border],
                }
            })
            .collect()
    }
}

/// The lines of [`SurfaceMesh::rectangle`]'s cells along x and along z, first and last
/// included: about a metre apart, at most 64 cells a side.
pub(crate) fn rectangle_lines(half: Vec2) -> (Vec<f32>, Vec<f32>) {
    let lines = |h: f32| {
        let n = ((2.0 * h).ceil() as u32).clamp(1, 64);
        (0..=n)
            .map(|i| -h + 2.0 * h * i as f32 / n as f32)
            .collect()
    };
    (lines(half.x), lines(half.y))
}

/// How a snow surface is drawn in the tessellated tier. Set per surface with
/// [`Renderer::set_surface_geometry`](super::Renderer::set_surface_geometry); surfaces without one
/// get the default (their rectangle, tessellated, default banks, full waves).
#[derive(Clone, Debug, PartialEq)]
pub struct SurfaceGeometry {
    /// The top of the surface; `None` for its rectangle ([`SurfaceMesh::rectangle`]).
    pub mesh: Option<SurfaceMesh>,
    /// Whether to tessellate it. Off, the surface is drawn with the relief tier's material in the
    /// tessellated tier too (the talk's caveat: meshes with geometry just under the snow, which
    /// displaced snow would cut through).
    pub tessellate: bool,
    /// Banks beside trails.
    pub banks: BankSettings,
    /// Height of the macro waves as a multiple of the material's (0 for flat snow, 1 default).
    pub macro_waves: f32,
}

impl Default for SurfaceGeometry {
    fn default() -> Self {
        Self {
            mesh: None,
            tessellate: true,
            banks: BankSettings::default(),
            macro_waves: 1.0,
        }
    }
}

impl SurfaceGeometry {
    /// Check the settings (and the mesh, against the surface's half sides and texel).
    pub fn validate(&self, half: Vec2, texel: f32) -> RenderResult<()> {
        let bad = |what: &str, value: String, expected| {
            Err(RenderError::InvalidFrame {
                what: format!("surface geometry {what}"),
                value,
                expected,
            })
        };
        let b = self.banks;
        if !(b.fraction.is_finite() && (0.0..=1.0).contains(&b.fraction)) {
            return bad("banks.fraction", b.fraction.to_string(), "between 0 and 1");
        }
        if !(b.width.is_finite() && b.width >= texel && b.width <= 2.0) {
            return bad(
                "banks.width",
                b.width.to_string(),
                "at least the heightmap's texel and at most 2 metres",
            );
        }
        if !(self.macro_waves.is_finite() && (0.0..=4.0).contains(&self.macro_waves)) {
            return bad(
                "macro_waves",
                self.macro_waves.to_string(),
                "between 0 and 4",
            );
        }
        if let Some(m) = &self.mesh {
            m.validate(half)?;
        }
        Ok(())
    }
}

/// The dicing pass's settings.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct DiceSettings {
    /// Length of a diced edge on screen, pixels (of the internal, supersampled image).
    pub target_edge_pixels: f32,
    /// Most segments per base-mesh edge (1 to [`MAX_LEVEL`]).
    pub max_level: u32,
    /// Share of the density kept on snow without relief (0 to 1): flat snow is diced this much
    /// coarser than prints and banks.
    pub detail_floor: f32,
    /// Room for diced triangles (all surfaces of a frame); base triangles beyond it are dropped
    /// and counted ([`FrameReport::dice_overflow`](super::FrameReport::dice_overflow)).
    pub max_triangles: u32,
}

impl Default for DiceSettings {
    /// 8-pixel edges, level 48 at most, flat snow at 35 %, room for 2^20 triangles.
    fn default() -> Self {
        Self {
            target_edge_pixels: 8.0,
            max_level: 48,
            detail_floor: 0.35,
            max_triangles: 1 << 20,
        }
    }
}

impl DiceSettings {
    pub(crate) fn validate(&self) -> RenderResult<()> {
        let ok = self.target_edge_pixels.is_finite()
            && self.target_edge_pixels >= 0.5
            && (1..=MAX_LEVEL).contains(&self.max_level)
            && self.detail_floor.is_finite()
            && self.detail_floor > 0.0
            && self.detail_floor <= 1.0
            && (1024..=1 << 26).contains(&self.max_triangles);
        if ok {
            Ok(())
        } else {
            Err(RenderError::InvalidConfig {
                what: "dice",
                value: format!("{self:?}"),
                expected: "target_edge_pixels >= 0.5, 1 <= max_level <= 64, 0 < detail_floor <= 1, 1024 <= max_triangles <= 2^26",
            })
        }
    }
}

/// One base triangle for the dicing pass. Must match `BaseTriangle` in `dice.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct BaseTriangle {
    /// First corner (local position; w unused).
    pub a: [f32; 4],
    /// Second corner.
    pub b: [f32; 4],
    /// Third corner.
    pub c: [f32; 4],
    /// Vertex ids of a, b, c; bit e of w set when edge e (a-b, b-c, c-a) is on the border.
    pub ids: [u32; 4],
}

/// One surface for the dicing pass. Must match `DiceParams` in `dice.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct DiceParams {
    /// Surface-local to clip.
    pub local_to_clip: [[f32; 4]; 4],
    /// The camera in the surface's local frame; w: pixels per radian.
    pub eye: [f32; 4],
    /// Target edge pixels, max level, shortest segment (metres), detail floor.
    pub settings: [f32; 4],
    /// Snow depth, reach above the snow top, the ground field's lowest base and highest ground.
    pub extent: [f32; 4],
    /// Heightfield width and height, surface slot, base triangles.
    pub grid: [u32; 4],
    /// Vertex capacity, index capacity, first texel of the ground field (or `NO_GROUND`), unused.
    pub capacity: [u32; 4],
    /// Half the surface's sides; zw unused.
    pub half_size: [f32; 4],
    /// Surface-local to the moon's near shadow cascade (clip space).
    pub local_to_shadow: [[f32; 4]; 4],
}

/// One surface for the bank passes. Must match `BankParams` in `banks.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct BankParams {
    /// Heightmap texels along x.
    pub width: u32,
    /// Heightmap texels along z.
    pub height: u32,
    /// Kernel half-width in texels along x.
    pub reach_x: i32,
    /// Kernel half-width in texels along z.
    pub reach_z: i32,
    /// Texel along x, metres.
    pub texel_x: f32,
    /// Texel along z, metres.
    pub texel_z: f32,
    /// Bank width, metres.
    pub radius: f32,
    /// Share of the pushed volume in banks.
    pub fraction: f32,
    /// Snow depth, metres.
    pub snow_depth: f32,
    /// Padding.
    pub _pad: [f32; 3],
    /// The texels the passes run over, `[x0, z0, x1, z1)` of the heightmap's (its first at 0):
    /// the surface and, beyond a side with a surface beside it, the band that the banks reach
    /// across the line and the textures' border.
    pub domain: [i32; 4],
}

impl BankParams {
    /// The parameters of a surface of `width x height` texels with nothing beside it.
    pub fn new(width: u32, height: u32, texel: Vec2, snow_depth: f32, banks: BankSettings) -> Self {
        Self {
            domain: [0, 0, width as i32, height as i32],
            width,
            height,
            reach_x: (banks.width / texel.x).floor() as i32,
            reach_z: (banks.width / texel.y).floor() as i32,
            texel_x: texel.x,
            texel_z: texel.y,
            radius: banks.width,
            fraction: banks.fraction,
            snow_depth,
            _pad: [0.0; 3],
        }
    }
}

/// A diced vertex read back from the GPU ([`Renderer::read_diced_mesh`](super::Renderer::read_diced_mesh)).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DicedVertex {
    /// Local position before displacement (y: the base).
    pub position: Vec3,
    /// What it is.
    pub kind: DicedKind,
}

/// Kinds of diced vertices.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum DicedKind {
    /// On the snow's top.
    Top,
    /// Top of a skirt (displaced like the top).
    SkirtTop,
    /// Bottom of a skirt (stays at the base).
    SkirtBottom,
}

/// A surface's diced mesh of the latest frame, as the GPU wrote it.
#[derive(Clone, Debug, PartialEq)]
pub struct DicedMesh {
    /// Vertices the surface's triangles use (indices below are into this list).
    pub vertices: Vec<DicedVertex>,
    /// Triangles.
    pub triangles: Vec<[u32; 3]>,
}

/// A surface's fields as the tessellated tier read them in the latest frame
/// ([`Renderer::read_surface_fields`](super::Renderer::read_surface_fields)), row-major, row 0 at
/// the smallest z.
#[derive(Clone, Debug, PartialEq)]
pub struct SurfaceFields {
    /// Texels along x.
    pub width: u32,
    /// Texels along z.
    pub height: u32,
    /// Smoothed depression, fraction of the snow depth.
    pub depression: Vec<f32>,
    /// Displaced snow, fraction of the snow depth.
    pub displaced: Vec<f32>,
    /// Bank height, metres.
    pub bank: Vec<f32>,
}
