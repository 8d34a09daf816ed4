//! Surface snapshots: a surface's stored state copied to the CPU and back (paging and saves).

use super::{SnowWorld, SurfaceState};
use crate::error::{Result, SnowError};
use crate::gpu::readback;
use crate::heightmap::Heightmap;
use crate::pool::PoolFormat;
use crate::surface::{SurfaceDesc, SurfaceId, SurfaceLayout};

/// A surface's stored state on the CPU (see [`SnowWorld::snapshot_surfaces`]): what the manager
/// pages out and what saves hold.
#[derive(Clone, Debug, PartialEq)]
pub struct SurfaceSnapshot {
    /// The surface.
    pub desc: SurfaceDesc,
    /// Heightmap texels along local x.
    pub width: u32,
    /// Heightmap texels along local z.
    pub height: u32,
    /// How `words` are laid out (see [`crate::PoolFormat`]).
    pub format: PoolFormat,
    /// Replenishment not yet applied, units at the format's precision (a fraction in `[0, 1)`).
    pub carry: f64,
    /// The slot's words as stored: the heights region, then the normals when the format keeps
    /// them.
    pub words: Vec<u32>,
}

impl SurfaceSnapshot {
    /// The heightmap in 16-bit units (as [`SnowWorld::read_heightmap`] gives it).
    pub fn heightmap(&self) -> Result<Heightmap> {
        let heights = self.format.heights_bytes(self.width, self.height) as usize / 4;
        let words = self
            .words
            .get(..heights)
            .ok_or_else(|| SnowError::Snapshot {
                name: self.desc.name.clone(),
                reason: format!(
                    "it holds {} words, its heights need {heights}",
                    self.words.len()
                ),
            })?;
        let (depression, displaced) = self.format.decode(self.width, self.height, words)?;
        Ok(Heightmap::from_channels(
            self.width,
            self.height,
            self.format.precision,
            &depression,
            &displaced,
        ))
    }
}

impl SnowWorld {
    /// Copy the stored state of surfaces to the CPU in one GPU round trip: their slots' words
    /// (heights, and normals when the pool keeps them) and the replenishment carried between
    /// updates. What paging and saves keep of a surface; [`SnowWorld::restore_surface`] puts it
    /// back bit for bit.
    pub fn snapshot_surfaces(&self, ids: &[SurfaceId]) -> Result<Vec<SurfaceSnapshot>> {
        let mut spans = Vec::with_capacity(ids.len());
        let mut total = 0u64;
        for &id in ids {
            let s = self.state(id)?;
            let bytes = self.payload_bytes(&s.layout);
            spans.push((s, total, bytes));
            total += bytes;
        }
        if total == 0 {
            return Ok(Vec::new());
        }
        let ranges: Vec<(u64, u64)> = spans
            .iter()
            .map(|&(s, _, bytes)| (s.slot.offset, bytes))
            .collect();
        let data = readback::download_ranges(&self.device, &self.queue, &self.pool, &ranges)?;
        Ok(spans
            .into_iter()
            .map(|(s, at, bytes)| SurfaceSnapshot {
                desc: s.desc.clone(),
                width: s.layout.width,
                height: s.layout.height,
                format: self.config.format,
                carry: s.carry,
                words: bytemuck::cast_slice(&data[at as usize..(at + bytes) as usize]).to_vec(),
            })
            .collect())
    }

    /// Bytes of a slot that hold data (heights, then normals when kept): what a snapshot copies.
    pub(super) fn payload_bytes(&self, layout: &SurfaceLayout) -> u64 {
        let f = &self.config.format;
        f.heights_bytes(layout.width, layout.height)
            + if f.normals { layout.texels() * 4 } else { 0 }
    }

    /// Whether a snapshot fits this world (its description valid, taken at this world's format,
    /// with its description's layout, word count and a carry in `[0, 1)`); returns the layout.
    pub fn check_snapshot(&self, snapshot: &SurfaceSnapshot) -> Result<SurfaceLayout> {
        let desc = &snapshot.desc;
        desc.validate()?;
        let layout = SurfaceLayout::for_size_capped(desc.size, self.config.max_resolution);
        let bad = |reason: String| {
            Err(SnowError::Snapshot {
                name: desc.name.clone(),
                reason,
            })
        };
        if snapshot.format != self.config.format {
            return bad(format!(
                "it was taken at {} bits a channel{}, this world stores {} bits{}",
                snapshot.format.precision.bits(),
                if snapshot.format.normals {
                    " with normals"
                } else {
                    ""
                },
                self.config.format.precision.bits(),
                if self.config.format.normals {
                    " with normals"
                } else {
                    ""
                },
            ));
        }
        if (snapshot.width, snapshot.height) != (layout.width, layout.height) {
            return bad(format!(
                "it holds {}x{} texels, the surface's size gives {}x{}",
                snapshot.width, snapshot.height, layout.width, layout.height
            ));
        }
        let payload = self.payload_bytes(&layout);
        if snapshot.words.len() as u64 * 4 != payload {
            return bad(format!(
                "it holds {} words, a {}x{} surface needs {}",
                snapshot.words.len(),
                layout.width,
                layout.height,
                payload / 4
            ));
        }
        if !(snapshot.carry.is_finite() && (0.0..1.0).contains(&snapshot.carry)) {
            return bad(format!(
                "its replenishment carry {} is not a fraction in [0, 1)",
                snapshot.carry
            ));
        }
        Ok(layout)
    }

    /// Add a surface with the state of a snapshot (its heights, normals and replenishment carry),
    /// at `at` in the pool when given (saves restore the pool's exact placement; `None`: first
    /// fit). Fails with [`SnowError::PoolExhausted`] when there is no room, and with
    /// [`SnowError::Snapshot`] when the snapshot does not fit this world's format or its
    /// description's layout; nothing changes then.
    pub fn restore_surface(
        &mut self,
        snapshot: &SurfaceSnapshot,
        at: Option<u64>,
    ) -> Result<SurfaceId> {
        let layout = self.check_snapshot(snapshot)?;
        let desc = &snapshot.desc;
        let slot = self.reserve_slot(&desc.name, &layout, at)?;
        self.queue.write_buffer(
            &self.pool,
            slot.offset,
            bytemuck::cast_slice(&snapshot.words),
        );
        Ok(self.insert_state(SurfaceState {
            desc: desc.clone(),
            layout,
            slot,
            carry: snapshot.carry,
        }))
    }
}
