//! A terrain window's levels as the world holds them (`crate::window`): surfaces of a fixed
//! layout whose slot is stored toroidally and whose rectangle moves with the window.

use glam::Vec3;

use super::{SnowWorld, SurfaceState};
use crate::error::{Result, SnowError};
use crate::surface::{SurfaceDesc, SurfaceId, SurfaceLayout};

impl SnowWorld {
    /// Add a window level: a surface of exactly `layout` (not derived from its size by the
    /// talk's rule), its slot cleared with the next submission. Refused, in one sentence, when
    /// the layout is larger than the capture atlas or than the pool.
    pub(crate) fn add_level(
        &mut self,
        desc: SurfaceDesc,
        layout: SurfaceLayout,
    ) -> Result<SurfaceId> {
        desc.validate()?;
        // The level's capture region (its texels and the apron) must fit the atlas.
        let side = self.config.atlas_side - 2 * crate::capture::APRON;
        if layout.width > side || layout.height > side || layout.texels() == 0 {
            return Err(SnowError::InvalidTerrain {
                name: desc.name.clone(),
                what: "a level's texels".into(),
                value: format!("{} x {}", layout.width, layout.height),
                expected: format!(
                    "between 1 and {side} a side (the capture atlas's side, WorldConfig.atlas_side, less the capture's apron of a texel on each side)"
                ),
            });
        }
        let slot = self.reserve_slot(&desc.name, &layout, None)?;
        self.queue
            .write_buffer(&self.pool, slot.offset, &vec![0u8; slot.bytes as usize]);
        Ok(self.insert_state(SurfaceState {
            desc,
            layout,
            slot,
            carry: 0.0,
            settle: Default::default(),
            ground: None,
            wrap: 0,
            hole: None,
        }))
    }

    /// Move a window level: its rectangle's centre and its storage's toroidal offsets
    /// (`ox | oy << 16`, [`crate::pool::wrapped`]). Nothing in the pool moves: the caller has
    /// rewritten the strips that entered. Refused while a frame is in flight.
    pub(crate) fn move_level(&mut self, id: SurfaceId, center: Vec3, wrap: u32) -> Result<()> {
        if self.in_flight.is_some() {
            return Err(SnowError::WindowBusy {
                name: self.state(id)?.desc.name.clone(),
            });
        }
        self.state(id)?;
        let s = self.surfaces[id.0 as usize]
            .as_mut()
            .expect("checked live above");
        s.desc.center = center;
        s.wrap = wrap;
        // The settling rectangle was in the old logical coordinates.
        s.settle = Default::default();
        Ok(())
    }

    /// Whether a frame is encoded and not yet reported submitted (window levels cannot move).
    pub(crate) fn frame_pending(&self) -> bool {
        self.in_flight.is_some()
    }

    /// Leave `hole` (local xz, `(x0, z0, x1, z1)`) of a window level undrawn: a finer level
    /// draws it.
    pub(crate) fn set_level_hole(&mut self, id: SurfaceId, hole: Option<[f32; 4]>) -> Result<()> {
        self.state(id)?;
        if let Some(s) = self.surfaces[id.0 as usize].as_mut() {
            s.hole = hole;
        }
        Ok(())
    }

    /// A surface's slot in the pool (the manager keeps a terrain level's out of its planner's).
    pub(crate) fn slot_of(&self, id: SurfaceId) -> Result<crate::pool::Slot> {
        Ok(self.state(id)?.slot)
    }

    /// The word offset of a surface's heights region and its layout (for the window's strips).
    pub(crate) fn level_slot(&self, id: SurfaceId) -> Result<(u32, SurfaceLayout, u32)> {
        let s = self.state(id)?;
        Ok((s.slot.heights_word(), s.layout, s.wrap))
    }
}
