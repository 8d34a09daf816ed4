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
        self.add_level_at(desc, layout, None)
    }

    /// [`SnowWorld::add_level`] with its slot at byte `at` of the pool when given (a save's
    /// placement), else first fit.
    fn add_level_at(
        &mut self,
        desc: SurfaceDesc,
        layout: SurfaceLayout,
        at: Option<u64>,
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
        let slot = self.reserve_slot(&desc.name, &layout, at)?;
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

    /// Add a window level holding a saved state (a save's `TERR` section): its slot at byte
    /// `at` of the pool, stored with toroidal offsets `wrap`, its `words` (heights, then normals
    /// when the pool keeps them) given in logical order as a snapshot gives them, and its
    /// replenishment `carry`. Refused, nothing added, when the words or the carry do not fit the
    /// level at this world's format or the slot's range is not free.
    pub(crate) fn restore_level(
        &mut self,
        desc: SurfaceDesc,
        layout: SurfaceLayout,
        (at, wrap): (u64, u32),
        carry: f64,
        words: &[u32],
    ) -> Result<SurfaceId> {
        let bad = |reason: String| SnowError::Snapshot {
            name: desc.name.clone(),
            reason,
        };
        let payload = self.payload_bytes(&layout);
        if words.len() as u64 * 4 != payload {
            return Err(bad(format!(
                "it holds {} words, a {}x{} level needs {}",
                words.len(),
                layout.width,
                layout.height,
                payload / 4
            )));
        }
        if !(carry.is_finite() && (0.0..1.0).contains(&carry)) {
            return Err(bad(format!(
                "its replenishment carry {carry} is not a fraction in [0, 1)"
            )));
        }
        let stored = super::snapshot::stored_words(
            self.config.format,
            (layout.width, layout.height),
            wrap,
            words,
        )
        .ok_or_else(|| bad("its words do not decode at this world's format".into()))?;
        let id = self.add_level_at(desc, layout, Some(at))?;
        let slot = self.state(id)?.slot;
        self.queue
            .write_buffer(&self.pool, slot.offset, bytemuck::cast_slice(&stored));
        if let Some(s) = self.surfaces[id.0 as usize].as_mut() {
            s.carry = carry;
            s.wrap = wrap;
        }
        Ok(id)
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
