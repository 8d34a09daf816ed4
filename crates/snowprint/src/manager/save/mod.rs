//! Saves: the whole snow state of a [`SnowManager`](super::SnowManager) in one file, read back into a fresh manager on
//! any adapter (`docs/SAVES.md`).
//!
//! ```text
//! header   magic "SNOWSAVE" | version u32 | sections u32 | crc32 of the 16 bytes before it
//! section  tag [u8; 4] | codec u32 (0 raw, 1 LZ4 block) | raw bytes u64 | stored bytes u64 |
//!          crc32 of the stored bytes u32 | the stored bytes
//! ```
//! All numbers little-endian. Sections, in order: `CONF` (the manager's settings, JSON), `PLAN`
//! (the planner's state: every surface's description, zone, queue, clocks and slot; JSON), `MESH`
//! (the manager's meshes and the world meshes queued imprints name; binary), then one `SURF` per
//! surface that holds a heightmap, resident or paged (binary: the slot's words and the
//! replenishment carry, and from version 4 how long and where a slumping material still relaxes),
//! then (from version 2) one `GRND` per surface on ground that is not flat
//! (binary: its ground height at every texel and its slope rule; the field is rebuilt from them
//! as [`crate::GroundField::build`] built it), then (from version 3) one `TERR` per terrain
//! window the manager runs (binary, `terrain.rs`: its description, each level's window origin,
//! slot, carry and words, its scroll statistics and the pages of its store; the terrain is built
//! again from them exactly, under the same [`ManagedTerrainId`](super::ManagedTerrainId)).
//! Version 1 files, which have no `GRND`, version 2 files, which have no `TERR`, and version 3
//! files, whose surfaces count as settled, still read.
//! Reading checks everything before anything is built: a corrupt, truncated, foreign or newer
//! file is one [`SnowError::SaveFile`](crate::SnowError::SaveFile) sentence.

use super::ManagerConfig;
use super::planner::PlannerState;
use crate::mesh::Mesh;
use crate::world::SurfaceSnapshot;

mod bytes;
mod config;
mod load;
mod parse;
mod terrain;
mod write;

/// The first eight bytes of every save.
pub(crate) const MAGIC: [u8; 8] = *b"SNOWSAVE";
/// The format version this build writes and the newest it reads.
pub(crate) const VERSION: u32 = 4;
/// Most sections a save may have (a section per surface and per terrain, plus three).
pub(crate) const MAX_SECTIONS: u32 = 1 << 20;
/// Most bytes a section may expand to (a 512^2 surface at 32 bits with normals is 3 MiB; the
/// JSON sections of a city of 10,000 surfaces with long queues stay far below).
pub(crate) const MAX_SECTION_BYTES: u64 = 1 << 30;

pub(super) const HEADER: usize = 20;
pub(super) const SECTION_HEADER: usize = 28;
pub(super) const CODEC_RAW: u32 = 0;
pub(super) const CODEC_LZ4: u32 = 1;

/// One section of a save as read, checked against its checksum and decompressed.
#[derive(Clone, Debug, PartialEq)]
pub struct Section {
    /// Its four-letter tag.
    pub tag: [u8; 4],
    /// How it was stored: 0 raw, 1 LZ4.
    pub codec: u32,
    /// Bytes in the file.
    pub stored: u64,
    /// Its contents.
    pub data: Vec<u8>,
}

/// A save read and checked, before anything is built from it (what `snowprint inspect` prints).
#[derive(Clone, Debug)]
pub struct SaveFile {
    /// Format version.
    pub version: u32,
    /// The manager's settings.
    pub config: ManagerConfig,
    /// Every section, in file order.
    pub sections: Vec<Section>,
    pub(crate) plan: PlannerState,
    pub(crate) meshes: SavedMeshes,
    /// The heightmaps held, by managed surface index.
    pub surfaces: Vec<SavedSurface>,
    /// The grounds that are not flat, by managed surface index.
    pub grounds: Vec<SavedGround>,
    /// The terrain windows, in order of their handles (version 3).
    pub terrains: Vec<SavedTerrain>,
}

/// One terrain window in a save (a `TERR` section): what rebuilds it exactly.
#[derive(Clone, Debug, PartialEq)]
pub struct SavedTerrain {
    /// Its handle's index ([`ManagedTerrainId::index`](super::ManagedTerrainId::index)): the
    /// loaded manager gives it the same handle.
    pub index: u32,
    /// Its description, as [`SnowManager::add_terrain`](super::SnowManager::add_terrain) took it.
    pub desc: crate::TerrainDesc,
    pub(crate) levels: Vec<terrain::SavedLevel>,
    pub(crate) stats: crate::window::ScrollStats,
    pub(crate) last_written: u64,
    pub(crate) pages: Vec<crate::window::saved::PageState>,
}

impl SavedTerrain {
    /// Each level's window: the world texel of its logical texel (0, 0), finest first.
    pub fn origins(&self) -> Vec<[i64; 2]> {
        self.levels.iter().map(|l| l.origin).collect()
    }

    /// Chunks of 64 x 64 texels its page store holds (what its windows paged out).
    pub fn chunks(&self) -> usize {
        self.pages.len()
    }
}

/// One surface's ground in a save: its height at every texel and the slope rule.
#[derive(Clone, Debug, PartialEq)]
pub struct SavedGround {
    /// Managed surface index.
    pub index: u32,
    /// The ground's height at each texel centre of the surface's heightmap, row after row.
    pub heights: Vec<f32>,
    /// How much snow its slopes hold.
    pub slope: crate::SlopeRule,
}

/// One surface's heightmap in a save.
#[derive(Clone, Debug, PartialEq)]
pub struct SavedSurface {
    /// Managed surface index.
    pub index: u32,
    /// Byte offset of its slot in the pool while resident; `None` when it was paged out.
    pub slot_offset: Option<u64>,
    /// The heightmap and its replenishment carry.
    pub snapshot: SurfaceSnapshot,
    /// How long and where a slumping material still relaxes (from version 4; settled before,
    /// and always for a surface paged out).
    pub(crate) settle: crate::relax::Settle,
}

/// The meshes of a save: the manager's (handle order) and every world mesh a queue names.
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct SavedMeshes {
    /// `(name, mesh, world index)` by the manager's handle.
    pub(crate) managed: Vec<(String, Mesh, u32)>,
    /// `(world index, mesh)` of earlier posings still named by queues.
    pub(crate) retired: Vec<(u32, Mesh)>,
}
