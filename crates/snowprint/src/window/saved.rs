//! A terrain as a save keeps it (`manager/save`, the `TERR` section): each level's window origin,
//! the pages of its store and its statistics; the levels' words travel with the world's
//! snapshots. [`Terrain::restore`] builds the terrain again from them, bit for bit: the levels
//! at their slots with their toroidal offsets, their grounds laid at their origins (as a scroll
//! leaves them), the store with the same compressed pages.

use super::store::StripStore;
use super::{Level, ScrollStats, Terrain, TerrainDesc, level_surface, plan, validate};
use crate::error::{Result, SnowError};
use crate::world::SnowWorld;

/// What a terrain keeps besides its levels (a new terrain keeps nothing yet).
#[derive(Default)]
pub(crate) struct Kept {
    pub(crate) store: StripStore,
    pub(crate) stats: ScrollStats,
    pub(crate) last_written: u64,
}

/// One level of a saved terrain, to restore.
pub(crate) struct LevelState<'a> {
    /// World texel of its logical texel (0, 0).
    pub(crate) origin: [i64; 2],
    /// Byte offset of its slot in the pool.
    pub(crate) offset: u64,
    /// Its replenishment carry.
    pub(crate) carry: f64,
    /// Its slot's words in logical order (heights, then normals when kept).
    pub(crate) words: &'a [u32],
}

/// A page of a terrain's store as saved: `(level, chunk column, chunk row)` and its LZ4 bytes.
pub(crate) type PageState = (super::store::PageKey, Vec<u8>);

/// What a save keeps of a terrain besides its description and its levels' words.
pub(crate) struct WindowState {
    /// Each level's window origin, finest first.
    pub(crate) origins: Vec<[i64; 2]>,
    /// The scroll statistics (the store's own counts left out: they come back with the store).
    pub(crate) stats: ScrollStats,
    /// Pool bytes of the last scroll whose readback arrived.
    pub(crate) last_written: u64,
    /// Every page of the store, in key order.
    pub(crate) pages: Vec<PageState>,
}

impl Terrain {
    /// What a save keeps of the terrain besides its levels' words (see [`WindowState`]).
    /// Refused while a scroll or fold is still on its way (call [`Terrain::flush`] first).
    pub(crate) fn saved_state(&self) -> Result<WindowState> {
        if !self.in_flight.is_empty() {
            return Err(SnowError::SaveContent(format!(
                "terrain {:?} has strips on their way from the GPU: flush it before saving",
                self.desc.name
            )));
        }
        Ok(WindowState {
            origins: self.levels.iter().map(|l| l.origin).collect(),
            stats: ScrollStats {
                store_bytes: 0,
                store_chunks: 0,
                ..self.stats
            },
            last_written: self.last_written,
            pages: self
                .store
                .pages()
                .into_iter()
                .map(|(k, b)| (k, b.to_vec()))
                .collect(),
        })
    }

    /// Add a saved terrain's levels to `world` as they were: each at its slot, its window at
    /// its origin (toroidal offsets and rectangle), its words and carry written back, its ground
    /// laid there; the store holds `pages` and the statistics go on from `stats`. Refused, in one
    /// sentence, and nothing left in the world, for what [`Terrain::new`] refuses and when a
    /// level's slot is not free or its words do not fit it.
    pub(crate) fn restore(
        world: &mut SnowWorld,
        desc: TerrainDesc,
        levels: &[LevelState<'_>],
        (stats, last_written): (ScrollStats, u64),
        pages: Vec<PageState>,
    ) -> Result<Self> {
        validate(&desc, world)?;
        if levels.len() != desc.levels.len() {
            return Err(SnowError::SaveContent(format!(
                "terrain {:?} has {} levels saved, its description {}",
                desc.name,
                levels.len(),
                desc.levels.len()
            )));
        }
        let mut added: Vec<Level> = Vec::new();
        for (i, l) in levels.iter().enumerate() {
            let (surface, layout) = level_surface(&desc, i, l.origin);
            let wrap = plan::wrap_for(l.origin, desc.levels[i].texels);
            match world.restore_level(surface, layout, (l.offset, wrap), l.carry, l.words) {
                Ok(id) => added.push(Level {
                    surface: id,
                    desc: desc.levels[i],
                    origin: l.origin,
                }),
                Err(e) => {
                    for l in &added {
                        let _ = world.remove_surface(l.surface);
                    }
                    return Err(e);
                }
            }
        }
        let kept = Kept {
            store: StripStore::from_pages(pages),
            stats,
            last_written,
        };
        Self::finish(world, desc, added, kept)
    }
}
