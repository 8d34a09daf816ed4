//! The extract step: what a renderer reads of a [`SnowWorld`] to draw a frame, gathered in one
//! call ([`SnowWorld::frame_view`]) instead of per-surface accessor calls scattered through the
//! passes. Built from the world's public accessors only, so another renderer can do the same.

use crate::capture::NO_GROUND;
use crate::error::{Result, SnowError};
use crate::pool::{PoolFormat, Precision};
use crate::surface::{SurfaceDesc, SurfaceId, SurfaceLayout};
use crate::world::SnowWorld;

/// One live surface as a renderer sees it.
#[derive(Clone, Copy, Debug)]
pub struct SurfaceView<'a> {
    /// The surface's handle.
    pub id: SurfaceId,
    /// Where it lies and how deep its snow is.
    pub desc: &'a SurfaceDesc,
    /// Its heightmap's resolution.
    pub layout: SurfaceLayout,
    /// Word offset of its heights in the pool buffer.
    pub heights: u32,
    /// Word offset of its normals in the pool buffer, when the pool keeps them.
    pub normals: Option<u32>,
    /// Precision of its heights in the pool.
    pub precision: Precision,
    /// Its ground: first texel in [`FrameView::ground_buffer`] or [`crate::low_level::ground::NO_GROUND`]
    /// on flat ground.
    pub ground: u32,
    /// Lowest base of its snow columns and highest ground, local metres ((0, 0) on flat ground):
    /// the snow lies between the first and the second plus the snow depth.
    pub ground_range: (f32, f32),
    /// Its toroidal storage offsets (`ox | oy << 16`, 0 for an ordinary surface): logical texel
    /// (x, y) lives at ((x + ox) mod width, (y + oy) mod height) (`pool/texel.wgsl`).
    pub wrap: u32,
    /// A rectangle of its local xz `(x0, z0, x1, z1)` that a finer level of the same terrain
    /// window draws instead (`crate::Terrain`); renderers leave it out. `None` for any other
    /// surface.
    pub hole: Option<[f32; 4]>,
}

/// Everything of a world a frame reads: the pool buffer, its format, every live surface with its
/// layout and offsets in the pool, and the ground fields of the surfaces not on flat ground.
#[derive(Debug)]
pub struct FrameView<'a> {
    /// The pool buffer (`array<u32>` in WGSL).
    pub pool_buffer: &'a wgpu::Buffer,
    /// The pool's format.
    pub pool_format: PoolFormat,
    /// Every live surface, in the world's order (by slot index).
    pub surfaces: Vec<SurfaceView<'a>>,
    /// Every surface's ground field, packed (`array<vec2<f32>>`: `[base, bare]` per texel; read
    /// through `ground_texel` in `ground/texel.wgsl`); surfaces on flat ground have none.
    pub ground_buffer: &'a wgpu::Buffer,
}

#[cfg(test)]
impl<'a> SurfaceView<'a> {
    /// A view of `desc` for the renderer's pure tests: surface `index`, `texels` of 16 bits at
    /// word 0 of the pool, on flat ground, stored plainly, with `hole`.
    pub(crate) fn for_test(
        desc: &'a SurfaceDesc,
        index: u32,
        texels: [u32; 2],
        hole: Option<[f32; 4]>,
    ) -> Self {
        Self {
            id: SurfaceId(index, 0),
            desc,
            layout: crate::surface::SurfaceLayout {
                width: texels[0],
                height: texels[1],
            },
            heights: 0,
            normals: None,
            precision: crate::Precision::Bits16,
            ground: crate::low_level::ground::NO_GROUND,
            ground_range: (0.0, 0.0),
            wrap: 0,
            hole,
        }
    }
}

impl<'a> FrameView<'a> {
    /// A surface of the view, or the error the world gives for a handle it does not hold.
    pub fn surface(&self, id: SurfaceId) -> Result<&SurfaceView<'a>> {
        self.surfaces
            .binary_search_by_key(&id.index(), |s| s.id.index())
            .ok()
            .map(|i| &self.surfaces[i])
            .filter(|s| s.id == id)
            .ok_or(SnowError::StaleHandle {
                what: "surface",
                index: id.index(),
            })
    }
}

impl SnowWorld {
    /// What a renderer reads of the world this frame, in one call: the pool buffer and format,
    /// and each live surface's description, layout and offsets in the pool.
    pub fn frame_view(&self) -> FrameView<'_> {
        let pool_format = self.pool_format();
        let mut surfaces: Vec<SurfaceView<'_>> = self
            .surfaces()
            .filter_map(|(id, desc)| {
                let layout = self.layout(id).ok()?;
                let (heights, normals) = self.gpu_offsets(id).ok()?;
                let placement = self.ground_placement(id).ok()?;
                let (ground, low, high) = placement.unwrap_or((NO_GROUND, 0.0, 0.0));
                Some(SurfaceView {
                    id,
                    desc,
                    layout,
                    heights,
                    normals,
                    precision: pool_format.precision,
                    ground,
                    ground_range: (low, high),
                    wrap: self.wrap(id).ok()?,
                    hole: self.hole(id).ok()?,
                })
            })
            .collect();
        // Sorted by slot for the lookup (the world lists them so already).
        surfaces.sort_by_key(|s| s.id.index());
        FrameView {
            pool_buffer: self.pool_buffer(),
            pool_format,
            surfaces,
            ground_buffer: self.ground_buffer(),
        }
    }
}
