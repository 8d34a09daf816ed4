//! Surface snapshots: a surface's stored state copied to the CPU and back (paging and saves).

use super::{SnowWorld, SurfaceState};
use crate::error::{Result, SnowError};
use crate::gpu::readback;
use crate::gpu::resources::write_in_order;
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
    /// The slot's words: the heights region, then the normals when the format keeps them, in
    /// logical order (a terrain level stored wrapped is unwrapped: `pool::wrapped`).
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

/// Snapshots recorded into an encoder by [`SnowWorld::encode_snapshot`], read once it has run.
#[derive(Debug)]
#[must_use = "call submitted() after submitting the encoder, then try_take() or wait()"]
pub struct SnapshotRead {
    metas: Vec<SurfaceSnapshot>,
    sizes: Vec<u64>,
    /// Each surface's toroidal storage offsets, undone as the words arrive.
    wraps: Vec<u32>,
    read: Option<readback::RangeRead>,
}

impl SnapshotRead {
    /// The encoder was submitted: start mapping the staging buffer.
    pub fn submitted(&self) {
        if let Some(r) = &self.read {
            r.submitted();
        }
    }

    /// Whether the snapshots have arrived (the device must have been polled since submitting).
    pub fn is_ready(&self) -> bool {
        self.read.as_ref().is_none_or(readback::RangeRead::is_ready)
    }

    /// The snapshots, in the order asked, if they have arrived; never waits. Taken once.
    pub fn try_take(&mut self) -> Option<Result<Vec<SurfaceSnapshot>>> {
        match &self.read {
            None => Some(Ok(std::mem::take(&mut self.metas))),
            Some(r) => {
                let bytes = r.try_take()?;
                Some(bytes.map(|b| self.split(&b)))
            }
        }
    }

    /// The snapshots, waiting for the GPU (after the encoder was submitted).
    pub fn wait(mut self, device: &wgpu::Device) -> Result<Vec<SurfaceSnapshot>> {
        match self.read.take() {
            None => Ok(self.metas),
            Some(r) => {
                let bytes = r.wait(device)?;
                Ok(self.split(&bytes))
            }
        }
    }

    /// The snapshots, waiting for the GPU, without taking them (they are still given by
    /// [`SnapshotRead::try_take`] or [`SnapshotRead::wait`]).
    pub fn peek(&self, device: &wgpu::Device) -> Result<Vec<SurfaceSnapshot>> {
        let bytes = match &self.read {
            None => Vec::new(),
            Some(r) => r.peek(device)?,
        };
        Ok(self.split_into(self.metas.clone(), &bytes))
    }

    /// The surfaces' descriptions, in the order asked.
    pub fn surfaces(&self) -> impl Iterator<Item = &SurfaceDesc> {
        self.metas.iter().map(|m| &m.desc)
    }

    fn split(&mut self, bytes: &[u8]) -> Vec<SurfaceSnapshot> {
        let metas = std::mem::take(&mut self.metas);
        self.split_into(metas, bytes)
    }

    fn split_into(&self, metas: Vec<SurfaceSnapshot>, bytes: &[u8]) -> Vec<SurfaceSnapshot> {
        let mut at = 0usize;
        metas
            .into_iter()
            .zip(self.sizes.iter().zip(&self.wraps))
            .map(|(meta, (&size, &wrap))| {
                let words = bytemuck::cast_slice(&bytes[at..at + size as usize]).to_vec();
                at += size as usize;
                let words = logical_words(&meta, wrap, words);
                SurfaceSnapshot { words, ..meta }
            })
            .collect()
    }
}

/// A slot's words as stored with toroidal offsets `wrap`, put in logical order (heights and
/// normals), so that snapshots, pages and saves never depend on where a window stood.
fn logical_words(meta: &SurfaceSnapshot, wrap: u32, words: Vec<u32>) -> Vec<u32> {
    if wrap == 0 {
        return words;
    }
    let (w, h, f) = (meta.width, meta.height, meta.format);
    let n = (f.heights_bytes(w, h) / 4) as usize;
    let Ok((dep, disp)) = f.decode(w, h, &words[..n]) else {
        return words;
    };
    let unwrap = |c: &[u32]| crate::pool::unwrap_channel(wrap, w, h, c);
    let Ok(mut out) = f.encode(w, h, &unwrap(&dep), &unwrap(&disp)) else {
        return words;
    };
    if words.len() > n {
        out.extend(unwrap(&words[n..]));
    }
    out
}

/// A slot's words in logical order (as [`logical_words`] gives them) put where a slot stored
/// with toroidal offsets `wrap` keeps them; `None` when they do not decode at `format`.
pub(super) fn stored_words(
    format: PoolFormat,
    (w, h): (u32, u32),
    wrap: u32,
    words: &[u32],
) -> Option<Vec<u32>> {
    if wrap == 0 {
        return Some(words.to_vec());
    }
    let n = (format.heights_bytes(w, h) / 4) as usize;
    let (dep, disp) = format.decode(w, h, words.get(..n)?).ok()?;
    let wrap_c = |c: &[u32]| crate::pool::wrap_channel(wrap, w, h, c);
    let mut out = format.encode(w, h, &wrap_c(&dep), &wrap_c(&disp)).ok()?;
    if words.len() > n {
        out.extend(wrap_c(&words[n..]));
    }
    Some(out)
}

impl SnowWorld {
    /// Copy the stored state of surfaces to the CPU in one GPU round trip: their slots' words
    /// (heights, and normals when the pool keeps them) and the replenishment carried between
    /// updates. What paging and saves keep of a surface; [`SnowWorld::restore_surface`] puts it
    /// back bit for bit. Waits for the GPU: [`SnowWorld::encode_snapshot`] does not.
    pub fn snapshot_surfaces(&self, ids: &[SurfaceId]) -> Result<Vec<SurfaceSnapshot>> {
        let mut enc = self.device.create_command_encoder(&Default::default());
        let read = self.encode_snapshot(&mut enc, ids)?;
        self.queue.submit([enc.finish()]);
        read.wait(&self.device)
    }

    /// [`SnowWorld::snapshot_surfaces`] recorded into the caller's `encoder`: the slots are
    /// copied where the encoder stands (after what it recorded before), into a staging buffer
    /// that is mapped once [`SnapshotRead::submitted`] is called, and read without waiting by
    /// [`SnapshotRead::try_take`]. The description and carry are taken now.
    pub fn encode_snapshot(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        ids: &[SurfaceId],
    ) -> Result<SnapshotRead> {
        let mut metas = Vec::with_capacity(ids.len());
        let mut ranges = Vec::with_capacity(ids.len());
        let mut wraps = Vec::with_capacity(ids.len());
        for &id in ids {
            let s = self.state(id)?;
            wraps.push(s.wrap);
            let bytes = self.payload_bytes(&s.layout);
            ranges.push((s.slot.offset, bytes));
            metas.push(SurfaceSnapshot {
                desc: s.desc.clone(),
                width: s.layout.width,
                height: s.layout.height,
                format: self.config.format,
                carry: s.carry,
                words: Vec::new(),
            });
        }
        let read = readback::RangeRead::record(&self.device, encoder, &self.pool, &ranges);
        Ok(SnapshotRead {
            metas,
            sizes: ranges.iter().map(|r| r.1).collect(),
            wraps,
            read,
        })
    }

    /// Bytes a snapshot of surface `id` copies.
    pub(crate) fn payload_bytes_of(&self, id: SurfaceId) -> Result<u64> {
        Ok(self.payload_bytes(&self.state(id)?.layout))
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
        self.restore_surface_with(snapshot, at, None)
    }

    /// [`SnowWorld::restore_surface`], its words written in `enc`'s order when given (after what
    /// the encoder recorded before), else with the next submission.
    pub(crate) fn restore_surface_with(
        &mut self,
        snapshot: &SurfaceSnapshot,
        at: Option<u64>,
        enc: Option<&mut wgpu::CommandEncoder>,
    ) -> Result<SurfaceId> {
        let layout = self.check_snapshot(snapshot)?;
        let desc = &snapshot.desc;
        let slot = self.reserve_slot(&desc.name, &layout, at)?;
        let words: &[u8] = bytemuck::cast_slice(&snapshot.words);
        let rest = slot.bytes.saturating_sub(words.len() as u64);
        match enc {
            Some(enc) => {
                write_in_order(&self.device, enc, &self.pool, slot.offset, words);
                if rest > 0 {
                    enc.clear_buffer(&self.pool, slot.offset + words.len() as u64, Some(rest));
                }
            }
            None => {
                self.queue.write_buffer(&self.pool, slot.offset, words);
                if rest > 0 {
                    let zeros = vec![0u8; rest as usize];
                    self.queue
                        .write_buffer(&self.pool, slot.offset + words.len() as u64, &zeros);
                }
            }
        }
        Ok(self.insert_state(SurfaceState {
            desc: desc.clone(),
            layout,
            slot,
            carry: snapshot.carry,
            settle: Default::default(),
            ground: None,
            wrap: 0,
            hole: None,
        }))
    }
}
