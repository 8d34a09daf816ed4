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
}

impl SurfaceGround {
    /// What the frame plan needs of it.
    pub fn plan(&self) -> PlanGround {
        PlanGround {
            offset: self.offset,
            range: self.field.range(),
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
            .ground = field.map(|field| super::ground::SurfaceGround { field, offset: 0 });
        self.upload_grounds();
        Ok(())
    }

    /// A surface's ground field (`None` on flat ground).
    pub fn ground(&self, id: SurfaceId) -> Result<Option<&GroundField>> {
        Ok(self.state(id)?.ground.as_ref().map(|g| &g.field))
    }

    /// Pack every live surface's field into the ground buffer, one after the other, and write it.
    fn upload_grounds(&mut self) {
        let ankle = self.config.capture.ankle_height;
        let mut columns: Vec<[f32; 2]> = Vec::new();
        let mut codes: Vec<u32> = Vec::new();
        for s in self.surfaces.iter_mut().flatten() {
            if let Some(g) = s.ground.as_mut() {
                g.offset = columns.len() as u32;
                columns.extend_from_slice(&g.field.columns);
                // Where a mesh solid holds the ground point the snow is pressed to the ground:
                // the bare depth above the base, as a capture code (`capture::encode_depth`).
                let frustum = s.desc.snow_depth + ankle;
                codes.extend(g.field.columns.iter().map(|c| encode_depth(c[1] / frustum)));
            }
        }
        if columns.is_empty() {
            return;
        }
        let bytes: &[u8] = bytemuck::cast_slice(&columns);
        self.grounds.ensure(&self.device, bytes.len() as u64);
        self.queue.write_buffer(&self.grounds.buffer, 0, bytes);
        let bytes: &[u8] = bytemuck::cast_slice(&codes);
        self.ground_codes.ensure(&self.device, bytes.len() as u64);
        self.queue.write_buffer(&self.ground_codes.buffer, 0, bytes);
    }
}
