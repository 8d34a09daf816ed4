//! Surfaces on ground that is not flat: [`SnowWorld::set_ground`] builds a surface's
//! [`GroundField`] (a mesh rasterised on the GPU first) and keeps every field in one buffer the
//! capture reads (`capture.wgsl`, binding `ground`).

use super::SnowWorld;
use super::plan::PlanGround;
use crate::capture::encode_depth;
use crate::error::{Result, SnowError};
use crate::ground::raster::GroundRaster;
use crate::ground::{Ground, GroundField, SlopeRule, sample_grid};
use crate::surface::SurfaceId;

/// A surface's ground field and its place in the world's ground buffer.
#[derive(Clone, Debug)]
pub(crate) struct SurfaceGround {
    pub field: GroundField,
    /// First texel in the ground buffer.
    pub offset: u32,
    /// First of its capture codes in the ground codes buffer, one per texel of its capture region
    /// (`capture::region`).
    pub codes: u32,
    /// [`GroundField::range`], kept: the renderer reads it every frame.
    pub range: (f32, f32),
    /// [`GroundField::region_range`], kept: the plan culls against it every frame.
    pub region_range: (f32, f32),
}

impl SurfaceGround {
    /// What the frame plan needs of it.
    pub fn plan(&self) -> PlanGround {
        PlanGround {
            offset: self.offset,
            codes: self.codes,
            range: self.region_range,
        }
    }
}

impl SnowWorld {
    /// Lay a surface on `ground`, bared where it is steeper than `slope` allows (see
    /// [`GroundField`]); [`Ground::Flat`] gives back the flat ground of [`SnowWorld::add_surface`].
    /// The heightmap is kept: what was pressed stays pressed, measured from the new snow top. A mesh
    /// is rasterised on the GPU, waiting for it. Refused with [`SnowError::FramePending`] while an
    /// encoded frame is not submitted, and with [`SnowError::InvalidGround`] for a grid whose size
    /// does not match its heights, a mesh with no triangles or a bad slope rule.
    pub fn set_ground(&mut self, id: SurfaceId, ground: &Ground, slope: SlopeRule) -> Result<()> {
        if self.in_flight.is_some() {
            return Err(SnowError::FramePending);
        }
        let (desc, layout) = {
            let s = self.state(id)?;
            (s.desc.clone(), s.layout)
        };
        let field = self.resolve_ground(&desc, layout, ground, slope)?;
        self.set_ground_field(id, field)
    }

    /// The field of `ground` under a surface of `desc` at `layout` (`None` on flat ground),
    /// checked as [`SnowWorld::set_ground`] checks it; a mesh is rasterised on the GPU, waiting
    /// for it. The manager resolves a surface's ground once with it and lays the field again at
    /// each admission.
    pub(crate) fn resolve_ground(
        &mut self,
        desc: &crate::SurfaceDesc,
        layout: crate::surface::SurfaceLayout,
        ground: &Ground,
        slope: SlopeRule,
    ) -> Result<Option<GroundField>> {
        slope.validate(&desc.name)?;
        let heights = match ground {
            Ground::Flat => None,
            Ground::Grid(grid) => {
                grid.validate(&desc.name)?;
                Some(sample_grid(grid, layout))
            }
            Ground::Mesh(mesh) => {
                let bad = |reason: &str| SnowError::InvalidGround {
                    name: desc.name.clone(),
                    reason: reason.to_owned(),
                };
                if mesh.triangles.is_empty() {
                    return Err(bad(
                        "the ground mesh has no triangles; give it at least one face",
                    ));
                }
                if mesh.triangles.iter().flatten().any(|v| !v.is_finite()) {
                    return Err(bad("the ground mesh has a vertex that is not finite"));
                }
                let raster = self
                    .ground_raster
                    .get_or_insert_with(|| GroundRaster::new(&self.device));
                let texels = raster.rasterise(
                    &self.device,
                    &self.queue,
                    &mesh.triangles,
                    desc.world_to_local(),
                    desc.size,
                    layout,
                )?;
                Some(texels.into_iter().map(|h| h.unwrap_or(0.0)).collect())
            }
        };
        Ok(heights.map(|g| GroundField::build(layout, desc.size, g, desc.snow_depth, slope)))
    }

    /// Lay a surface on a field resolved for its layout (`None`: flat ground). Refused while an
    /// encoded frame is not submitted.
    pub(crate) fn set_ground_field(
        &mut self,
        id: SurfaceId,
        field: Option<GroundField>,
    ) -> Result<()> {
        if self.in_flight.is_some() {
            return Err(SnowError::FramePending);
        }
        let layout = self.state(id)?.layout;
        if let Some(f) = &field
            && (f.width, f.height) != (layout.width, layout.height)
        {
            return Err(SnowError::InvalidGround {
                name: self.state(id)?.desc.name.clone(),
                reason: format!(
                    "the ground field is {} x {} texels and the surface {} x {}",
                    f.width, f.height, layout.width, layout.height
                ),
            });
        }
        self.surfaces[id.0 as usize]
            .as_mut()
            .expect("checked live above")
            .ground = field.map(|field| SurfaceGround {
            range: field.range(),
            region_range: field.region_range(),
            field,
            offset: 0,
            codes: 0,
        });
        self.upload_grounds();
        Ok(())
    }

    /// Move a surface's ground field by `by` texels ([`GroundField::scroll`]: `sample(c, r)` gives
    /// the heights of the texels that enter, at their new logical place) and write that surface's
    /// part of the ground buffers, nothing else. `false`, and nothing changed, on flat ground or
    /// for a move as large as the field: lay it whole then. Refused while an encoded frame is not
    /// submitted.
    pub(crate) fn scroll_ground(
        &mut self,
        id: SurfaceId,
        by: [i64; 2],
        slope: SlopeRule,
        sample: impl FnMut(u32, u32) -> f32,
    ) -> Result<bool> {
        if self.in_flight.is_some() {
            return Err(SnowError::FramePending);
        }
        self.state(id)?;
        let ankle = self.config.capture.ankle_height;
        let s = self.surfaces[id.0 as usize]
            .as_mut()
            .expect("checked live above");
        let Some(g) = s.ground.as_mut() else {
            return Ok(false);
        };
        if !g
            .field
            .scroll(by, s.desc.size, s.desc.snow_depth, slope, sample)
        {
            return Ok(false);
        }
        g.range = g.field.range();
        g.region_range = g.field.region_range();
        let frustum = s.desc.snow_depth + ankle;
        let codes = ground_codes(&g.field, frustum);
        let columns: &[u8] = bytemuck::cast_slice(&g.field.columns);
        let codes: &[u8] = bytemuck::cast_slice(&codes);
        self.queue
            .write_buffer(&self.grounds.buffer, g.offset as u64 * 8, columns);
        self.queue
            .write_buffer(&self.ground_codes.buffer, g.codes as u64 * 4, codes);
        self.ground_bytes_written += (columns.len() + codes.len()) as u64;
        Ok(true)
    }

    /// Bytes written into the ground buffers ([`Self::ground_buffer`] and the ground's capture
    /// codes) since the world was made: every field, packed again, when a surface's ground is
    /// set; only the moved field's part when a terrain's window scrolls.
    pub fn ground_bytes_written(&self) -> u64 {
        self.ground_bytes_written
    }

    /// A surface's ground field (`None` on flat ground).
    pub fn ground(&self, id: SurfaceId) -> Result<Option<&GroundField>> {
        Ok(self.state(id)?.ground.as_ref().map(|g| &g.field))
    }

    /// Where a surface's ground lies for a renderer: `(first texel in [`Self::ground_buffer`],
    /// lowest base, highest ground)`, local metres; `None` on flat ground.
    pub fn ground_placement(&self, id: SurfaceId) -> Result<Option<(u32, f32, f32)>> {
        Ok(self
            .state(id)?
            .ground
            .as_ref()
            .map(|g| (g.offset, g.range.0, g.range.1)))
    }

    /// Every surface's ground field, packed (`array<vec2<f32>>` in WGSL: `[base, bare]` per
    /// texel, row after row from each surface's first texel), for renderers that draw the snow on
    /// its ground. Read it through `ground_texel` (`ground/texel.wgsl`). Rewritten by
    /// [`Self::set_ground`] (every field) and by a terrain's scroll (the moved field's part).
    pub fn ground_buffer(&self) -> &wgpu::Buffer {
        &self.grounds.buffer
    }

    /// Pack every live surface's field into the ground buffer, one after the other, and write it.
    fn upload_grounds(&mut self) {
        let ankle = self.config.capture.ankle_height;
        let mut columns: Vec<[f32; 2]> = Vec::new();
        let mut codes: Vec<u32> = Vec::new();
        for s in self.surfaces.iter_mut().flatten() {
            if let Some(g) = s.ground.as_mut() {
                g.offset = columns.len() as u32;
                g.codes = codes.len() as u32;
                columns.extend_from_slice(&g.field.columns);
                codes.extend(ground_codes(&g.field, s.desc.snow_depth + ankle));
            }
        }
        if columns.is_empty() {
            return;
        }
        let bytes: &[u8] = bytemuck::cast_slice(&columns);
        self.grounds.ensure(&self.device, bytes.len() as u64);
        self.queue.write_buffer(&self.grounds.buffer, 0, bytes);
        self.ground_bytes_written += bytes.len() as u64;
        let bytes: &[u8] = bytemuck::cast_slice(&codes);
        self.ground_codes.ensure(&self.device, bytes.len() as u64);
        self.queue.write_buffer(&self.ground_codes.buffer, 0, bytes);
        self.ground_bytes_written += bytes.len() as u64;
    }
}

/// Where a mesh solid holds the ground point the snow is pressed to the ground: the bare depth
/// above the base, as a capture code (`capture::encode_depth`), at every texel of the surface's
/// capture region (the apron's ground extrapolated, [`GroundField::region_columns`]), laid out as
/// the capture region so that one copy puts them beside the winding counts.
fn ground_codes(field: &GroundField, frustum_height: f32) -> Vec<u32> {
    field
        .region_columns()
        .iter()
        .map(|c| encode_depth(c[1] / frustum_height))
        .collect()
}
