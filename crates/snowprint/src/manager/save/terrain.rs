//! The `TERR` section (version 3; version 4 adds each level's settle state): one terrain window of
//! the manager's, written and read back, every value checked before anything is built.
//!
//! ```text
//! index u32 (its ManagedTerrainId)
//! description    bytes u64 | JSON: name, ground height, snow depth, replenish rate, material,
//!                levels, and the ground's columns, rows, origin, size and slope rule
//! ground heights count u64 | f32 each (row after row; 0 of them on flat ground)
//! levels         count u32 | per level: origin x i64, origin z i64, slot offset u64, carry f64,
//!                word count u64, the slot's words in logical order (heights, then normals),
//!                from version 4 its settle state (updates u32, rectangle 4 x u32)
//! statistics     scrolls, texels out, texels in, bytes written, texels paged in, bytes folded,
//!                bytes of the last scroll (7 x u64)
//! pages          count u64 | per page: level u32, chunk column i64, chunk row i64, byte count
//!                u64, the chunk's LZ4 bytes (as the store keeps it), in key order
//! ```

use super::SavedTerrain;
use super::bytes::{Reader, put_settle, put_u32, put_u64};
use crate::ground::{HeightGrid, SlopeRule};
use crate::manager::ManagerConfig;
use crate::manager::planner::PlannerState;
use crate::material::Material;
use crate::pool::SlotAllocator;
use crate::window::saved::{PageState, WindowState};
use crate::window::store::check_page;
use crate::window::{LevelDesc, ScrollStats, Terrain, TerrainDesc, TerrainGround};

/// Most chunks away from the world's origin a saved page may lie (a window is at most 10,000 km
/// from it, chunks at least 64 texels of 1 mm).
const MAX_CHUNK: i64 = 1 << 40;

/// Handles a save holds: a terrain's handle is below this (a loaded manager keeps a place for
/// every handle up to the last, as the saved one did).
pub(super) const MAX_HANDLES: u32 = 1 << 16;

/// One level of a [`SavedTerrain`].
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct SavedLevel {
    pub(crate) origin: [i64; 2],
    pub(crate) offset: u64,
    pub(crate) carry: f64,
    pub(crate) words: Vec<u32>,
    pub(crate) settle: crate::relax::Settle,
}

/// The description as saved (a stable mirror of [`TerrainDesc`] without the ground's heights,
/// which follow it in binary).
#[derive(serde::Serialize, serde::Deserialize)]
struct SavedDesc {
    name: String,
    ground_height: f32,
    snow_depth: f32,
    replenish_rate: f32,
    material: Material,
    levels: Vec<LevelDesc>,
    ground: Option<SavedGroundDesc>,
}

#[derive(serde::Serialize, serde::Deserialize)]
struct SavedGroundDesc {
    columns: u32,
    rows: u32,
    origin: [f32; 2],
    size: [f32; 2],
    full_degrees: f32,
    bare_degrees: f32,
}

/// The bytes of a terrain's `TERR` section: `levels` are its levels' slot offsets, carries and
/// words (from the world's snapshots), finest first.
pub(super) fn put_terrain(
    index: u32,
    terrain: &Terrain,
    levels: &[(u64, f64, &[u32], crate::relax::Settle)],
) -> crate::error::Result<Vec<u8>> {
    if index >= MAX_HANDLES {
        return Err(crate::error::SnowError::SaveContent(format!(
            "terrain {:?}'s handle {index} is past the {MAX_HANDLES} terrains a save holds: nothing was written",
            terrain.desc().name
        )));
    }
    let WindowState {
        origins,
        stats,
        last_written,
        pages,
    } = terrain.saved_state()?;
    let d = terrain.desc();
    let head = SavedDesc {
        name: d.name.clone(),
        ground_height: d.ground_height,
        snow_depth: d.snow_depth,
        replenish_rate: d.replenish_rate,
        material: d.material,
        levels: d.levels.clone(),
        ground: d.ground.as_ref().map(|g| SavedGroundDesc {
            columns: g.grid.columns,
            rows: g.grid.rows,
            origin: g.origin,
            size: g.size,
            full_degrees: g.slope.full_degrees,
            bare_degrees: g.slope.bare_degrees,
        }),
    };
    let json = super::write::to_json(&head)?;
    let mut b = Vec::new();
    put_u32(&mut b, index);
    put_u64(&mut b, json.len() as u64);
    b.extend_from_slice(&json);
    let heights: &[f32] = d.ground.as_ref().map_or(&[], |g| &g.grid.heights);
    put_u64(&mut b, heights.len() as u64);
    b.extend_from_slice(bytemuck::cast_slice(heights));
    put_u32(&mut b, levels.len() as u32);
    for (origin, &(offset, carry, words, settle)) in origins.iter().zip(levels) {
        for v in origin {
            b.extend_from_slice(&v.to_le_bytes());
        }
        put_u64(&mut b, offset);
        b.extend_from_slice(&carry.to_bits().to_le_bytes());
        put_u64(&mut b, words.len() as u64);
        b.extend_from_slice(bytemuck::cast_slice(words));
        put_settle(&mut b, &settle);
    }
    for v in [
        stats.scrolls,
        stats.texels_out,
        stats.texels_in,
        stats.bytes_written,
        stats.texels_paged_in,
        stats.bytes_folded,
        last_written,
    ] {
        put_u64(&mut b, v);
    }
    put_u64(&mut b, pages.len() as u64);
    for ((level, cx, cz), bytes) in &pages {
        put_u32(&mut b, *level as u32);
        b.extend_from_slice(&cx.to_le_bytes());
        b.extend_from_slice(&cz.to_le_bytes());
        put_u64(&mut b, bytes.len() as u64);
        b.extend_from_slice(bytes);
    }
    Ok(b)
}

/// A `TERR` section read and checked against the save's settings: its description as
/// [`Terrain::new`] checks it, each level's origin, words and carry against the level, every
/// page against the store's chunks and the pool's precision. One clause for the first thing
/// wrong, naming the terrain and the value.
pub(super) fn read_terrain(
    data: &[u8],
    config: &ManagerConfig,
    version: u32,
) -> std::result::Result<SavedTerrain, String> {
    let mut r = Reader::new(data);
    let index = r.u32("its handle")?;
    if index >= MAX_HANDLES {
        return Err(format!(
            "its handle {index} is past the {MAX_HANDLES} terrains a save holds"
        ));
    }
    let n = r.count(1, "its description")?;
    let head: SavedDesc = serde_json::from_slice(r.take(n, "its description")?)
        .map_err(|e| format!("its description does not read: {e}"))?;
    let name = head.name.clone();
    let heights = r.floats("its ground's heights")?;
    let desc = description(head, heights)?;
    let format = config.format;
    crate::window::validate_for(&desc, format, config.atlas_side, config.pool_bytes)
        .map_err(|e| e.to_string())?;
    let count = r.u32("its level count")? as usize;
    if count != desc.levels.len() {
        return Err(format!(
            "terrain {name:?} has {count} levels saved, its description {}",
            desc.levels.len()
        ));
    }
    let mut levels = Vec::with_capacity(count);
    for (i, l) in desc.levels.iter().enumerate() {
        let origin = [r.i64("a level's origin")?, r.i64("a level's origin")?];
        let offset = r.u64("a level's slot")?;
        let carry = r.f64("a level's carry")?;
        let words = r.words("a level's words")?;
        let settle = if version >= 4 {
            super::bytes::read_settle(&mut r)?
        } else {
            crate::relax::Settle::default()
        };
        let [w, h] = l.texels;
        let what = format!("terrain {name:?} level {i}");
        super::parse::check_settle(&settle, &what, desc.material.settle_updates, (w, h), false)?;
        let unit = format.precision.unit_texels() as i64;
        let far = origin
            .iter()
            .any(|&o| (o as f64 * l.texel_size as f64).abs() > 2.0e7);
        if far || origin[0] % unit != 0 {
            return Err(format!(
                "terrain {name:?} level {i}'s window origin {origin:?} is not one a window takes (within 10,000 km, x a multiple of {unit} texels)"
            ));
        }
        let want = format.heights_bytes(w, h) / 4
            + if format.normals {
                w as u64 * h as u64
            } else {
                0
            };
        if words.len() as u64 != want {
            return Err(format!(
                "terrain {name:?} level {i} holds {} words, a {w} x {h} level at {} bits needs {want}",
                words.len(),
                format.precision.bits()
            ));
        }
        if !(carry.is_finite() && (0.0..1.0).contains(&carry)) {
            return Err(format!(
                "terrain {name:?} level {i}'s replenishment carry {carry} is not a fraction in [0, 1)"
            ));
        }
        let (surface, _) = crate::window::level_surface(&desc, i, origin);
        surface.validate().map_err(|e| e.to_string())?;
        levels.push(SavedLevel {
            origin,
            offset,
            carry,
            words,
            settle,
        });
    }
    let mut s = [0u64; 7];
    for v in &mut s {
        *v = r.u64("its statistics")?;
    }
    let stats = ScrollStats {
        scrolls: s[0],
        texels_out: s[1],
        texels_in: s[2],
        bytes_written: s[3],
        texels_paged_in: s[4],
        bytes_folded: s[5],
        ..ScrollStats::default()
    };
    let pages = read_pages(&mut r, &name, count, format.precision.channel_max())?;
    r.done("a terrain")?;
    Ok(SavedTerrain {
        index,
        desc,
        levels,
        stats,
        last_written: s[6],
        pages,
    })
}

/// The description from its JSON mirror and the ground's heights.
fn description(head: SavedDesc, heights: Vec<f32>) -> std::result::Result<TerrainDesc, String> {
    let ground = match head.ground {
        None if heights.is_empty() => None,
        None => {
            return Err(format!(
                "terrain {:?} is on flat ground but holds {} ground heights",
                head.name,
                heights.len()
            ));
        }
        Some(g) => {
            let ground = TerrainGround {
                grid: HeightGrid {
                    columns: g.columns,
                    rows: g.rows,
                    heights,
                },
                origin: g.origin,
                size: g.size,
                slope: SlopeRule {
                    full_degrees: g.full_degrees,
                    bare_degrees: g.bare_degrees,
                },
            };
            Some(ground)
        }
    };
    Ok(TerrainDesc {
        name: head.name,
        ground_height: head.ground_height,
        ground,
        snow_depth: head.snow_depth,
        replenish_rate: head.replenish_rate,
        material: head.material,
        levels: head.levels,
    })
}

/// The pages of a terrain of `levels` levels: keys in order, none twice, each a chunk the store
/// could have written at a precision whose channels reach `max`.
fn read_pages(
    r: &mut Reader<'_>,
    name: &str,
    levels: usize,
    max: u32,
) -> std::result::Result<Vec<PageState>, String> {
    let n = r.count(28, "its pages")?;
    let mut pages: Vec<PageState> = Vec::with_capacity(n);
    for _ in 0..n {
        let level = r.u32("a page's level")? as usize;
        let chunk = [r.i64("a page's chunk")?, r.i64("a page's chunk")?];
        let len = r.count(1, "a page's bytes")?;
        let bytes = r.take(len, "a page's bytes")?.to_vec();
        let key = (level, chunk[0], chunk[1]);
        if level >= levels || chunk.iter().any(|c| c.abs() > MAX_CHUNK) {
            return Err(format!(
                "terrain {name:?} has a page of level {level} at chunk {chunk:?}, past its {levels} levels or the world"
            ));
        }
        if pages.last().is_some_and(|p| p.0 >= key) {
            return Err(format!(
                "terrain {name:?}'s pages are not in order (level {level}, chunk {chunk:?})"
            ));
        }
        check_page(&bytes, max).map_err(|e| {
            format!("terrain {name:?}'s page of level {level} at chunk {chunk:?} {e}")
        })?;
        pages.push((key, bytes));
    }
    Ok(pages)
}

/// The save's terrains checked together against its settings and planner: handles in order and
/// none twice, fewer levels than `updates_per_frame` (as `add_terrain` requires), and every
/// level's slot inside the pool, beside the surfaces' slots and the other levels'.
pub(super) fn check_terrains(
    terrains: &[SavedTerrain],
    config: &ManagerConfig,
    plan: &PlannerState,
) -> std::result::Result<(), String> {
    for pair in terrains.windows(2) {
        if pair[0].index >= pair[1].index {
            return Err(format!(
                "terrain {:?}'s handle {} does not follow the one before ({})",
                pair[1].desc.name, pair[1].index, pair[0].index
            ));
        }
    }
    let levels: usize = terrains.iter().map(|t| t.levels.len()).sum();
    if levels > 0 && levels >= config.updates_per_frame {
        return Err(format!(
            "its terrains have {levels} levels, which leave no update a frame to its surfaces (updates_per_frame is {})",
            config.updates_per_frame
        ));
    }
    let mut alloc = SlotAllocator::new(config.pool_bytes);
    // The surfaces' slots are checked with the planner; here they only take their room.
    for s in &plan.surfaces {
        if let Some((offset, bytes)) = s.slot {
            let _ = alloc.alloc_at(offset, bytes);
        }
    }
    for t in terrains {
        for (i, (l, d)) in t.levels.iter().zip(&t.desc.levels).enumerate() {
            let bytes = config.format.slot_bytes(d.texels[0], d.texels[1]);
            if alloc.alloc_at(l.offset, bytes).is_none() {
                return Err(format!(
                    "terrain {:?} level {i}'s slot of {bytes} bytes at byte {} leaves the pool of {} bytes or overlaps a surface's or another level's",
                    t.desc.name, l.offset, config.pool_bytes
                ));
            }
        }
    }
    Ok(())
}
