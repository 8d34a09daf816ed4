//! Parsing a save's bytes without a GPU: the header, the sections and what they hold.

use super::bytes::{Reader, read_mesh, read_string};
use super::config::SavedConfig;
use super::terrain::{check_terrains, read_terrain};
use super::{
    CODEC_LZ4, CODEC_RAW, HEADER, MAGIC, MAX_SECTION_BYTES, MAX_SECTIONS, SECTION_HEADER, SaveFile,
    SavedGround, SavedMeshes, SavedSurface, Section, VERSION,
};
use crate::manager::ManagerConfig;
use crate::manager::planner::PlannerState;
use crate::relax::Settle;
use crate::world::SurfaceSnapshot;

impl SaveFile {
    /// Read and check a save's bytes without a GPU: magic, version, every checksum and length,
    /// the settings and the planner's state. One sentence for the first thing wrong.
    pub fn parse(bytes: &[u8]) -> std::result::Result<Self, String> {
        Self::parse_inner(bytes).map_err(|e| one_line(&e))
    }

    fn parse_inner(bytes: &[u8]) -> std::result::Result<Self, String> {
        let mut r = Reader::new(bytes);
        let head = r.take(HEADER, "the header").map_err(|_| {
            format!(
                "it is {} bytes long, shorter than a save's {HEADER}-byte header; it is not a snowprint save",
                bytes.len()
            )
        })?;
        if head[..8] != MAGIC {
            return Err("it does not start with SNOWSAVE; it is not a snowprint save".into());
        }
        let mut h = Reader::new(&head[8..]);
        let version = h.u32("the header")?;
        let count = h.u32("the header")?;
        let crc = h.u32("the header")?;
        if crc != crc32fast::hash(&head[..16]) {
            return Err("its header checksum does not match; the file is damaged".into());
        }
        if version == 0 || version > VERSION {
            return Err(format!(
                "it is format version {version}, this snowprint reads versions 1 to {VERSION}; use a newer snowprint"
            ));
        }
        if !(3..=MAX_SECTIONS).contains(&count) {
            return Err(format!(
                "it claims {count} sections, a save has 3 to {MAX_SECTIONS}"
            ));
        }
        let mut sections = Vec::new();
        for k in 0..count {
            let what = format!("section {k}");
            let head = r.take(SECTION_HEADER, &what)?;
            let mut h = Reader::new(head);
            let tag: [u8; 4] = h.take(4, &what)?.try_into().unwrap_or_default();
            let codec = h.u32(&what)?;
            let raw = h.u64(&what)?;
            let stored = h.u64(&what)?;
            let crc = h.u32(&what)?;
            // A damaged tag is shown as hex, so the sentence stays one line of text.
            let name = if tag.iter().all(u8::is_ascii_alphanumeric) {
                String::from_utf8_lossy(&tag).into_owned()
            } else {
                format!(
                    "tag {:02x}{:02x}{:02x}{:02x}",
                    tag[0], tag[1], tag[2], tag[3]
                )
            };
            if raw > MAX_SECTION_BYTES {
                return Err(format!(
                    "section {k} ({name}) claims {raw} bytes, more than {MAX_SECTION_BYTES}"
                ));
            }
            let data = r.take(usize::try_from(stored).unwrap_or(usize::MAX), &what)?;
            if crc32fast::hash(data) != crc {
                return Err(format!(
                    "section {k} ({name}) fails its checksum; the file is damaged"
                ));
            }
            let data = match codec {
                CODEC_RAW if raw == stored => data.to_vec(),
                // LZ4 expands at most 255 times: a larger claim is damage, not data.
                CODEC_LZ4 if raw <= stored.saturating_mul(255) + 16 => {
                    lz4_flex::block::decompress(data, raw as usize)
                        .map_err(|e| format!("section {k} ({name}) does not decompress: {e}"))?
                }
                _ => {
                    return Err(format!(
                        "section {k} ({name}) has an unknown codec {codec} or wrong sizes"
                    ));
                }
            };
            if data.len() as u64 != raw {
                return Err(format!(
                    "section {k} ({name}) holds {} bytes, {raw} were written",
                    data.len()
                ));
            }
            sections.push(Section {
                tag,
                codec,
                stored,
                data,
            });
        }
        r.done("the file")?;
        let (heightmaps, ground_end) = section_order(&sections, version)?;
        let saved: SavedConfig = serde_json::from_slice(&sections[0].data)
            .map_err(|e| format!("its settings (CONF) do not read: {e}"))?;
        let config = saved
            .config()
            .map_err(|e| format!("its settings (CONF): {e}"))?;
        let plan: PlannerState = serde_json::from_slice(&sections[1].data)
            .map_err(|e| format!("its planner state (PLAN) does not read: {e}"))?;
        let meshes =
            read_meshes(&sections[2].data).map_err(|e| format!("its meshes (MESH): {e}"))?;
        let mut surfaces = Vec::new();
        for s in &sections[3..heightmaps] {
            surfaces.push(
                read_surface(&s.data, &config, &plan, version)
                    .map_err(|e| format!("a heightmap (SURF): {e}"))?,
            );
        }
        let mut grounds = Vec::new();
        for s in &sections[heightmaps..ground_end] {
            grounds.push(read_ground(&s.data, &plan).map_err(|e| format!("a ground (GRND): {e}"))?);
        }
        let mut terrains = Vec::new();
        for (k, s) in sections.iter().enumerate().skip(ground_end) {
            terrains.push(read_terrain(&s.data, &config, version).map_err(|e| {
                format!("section {k}, a terrain window (TERR): {e}; the save is damaged or was altered: load an earlier one")
            })?);
        }
        check_terrains(&terrains, &config, &plan).map_err(|e| {
            format!("its terrain windows (TERR): {e}; the save is damaged or was altered: load an earlier one")
        })?;
        Ok(Self {
            version,
            config,
            sections,
            plan,
            meshes,
            surfaces,
            grounds,
            terrains,
        })
    }

    /// Seconds of snow time the save was taken at.
    pub fn time(&self) -> f64 {
        self.plan.time
    }

    /// Frames (ticks) run before the save.
    pub fn frames(&self) -> u64 {
        self.plan.tick
    }

    /// Surfaces registered (removed ones included).
    pub fn surface_count(&self) -> usize {
        self.plan.surfaces.len()
    }

    /// Per registered surface: name, whether removed, imprints queued, and what holds its
    /// heightmap ("resident", "paged" or "untouched").
    pub fn surface_summary(&self) -> Vec<(String, bool, usize, &'static str)> {
        self.plan
            .surfaces
            .iter()
            .map(|s| {
                let holds = if s.slot.is_some() {
                    "resident"
                } else if s.paged {
                    "paged"
                } else {
                    "untouched"
                };
                (s.desc.name.clone(), s.removed, s.queue.len(), holds)
            })
            .collect()
    }

    /// Meshes registered with the manager.
    pub fn mesh_count(&self) -> usize {
        self.meshes.managed.len()
    }
}

/// Where the heightmaps end and the grounds end among the sections, once their order is checked:
/// `CONF, PLAN, MESH, SURF..., GRND..., TERR...`, `GRND` from version 2, `TERR` from 3.
fn section_order(
    sections: &[Section],
    version: u32,
) -> std::result::Result<(usize, usize), String> {
    let tags: Vec<&[u8; 4]> = sections.iter().map(|s| &s.tag).collect();
    let run =
        |from: usize, tag: &[u8; 4]| from + tags[from..].iter().take_while(|t| **t == tag).count();
    let heightmaps = run(3, b"SURF");
    let ground_end = run(heightmaps, b"GRND");
    if tags[0] != b"CONF"
        || tags[1] != b"PLAN"
        || tags[2] != b"MESH"
        || tags[ground_end..].iter().any(|t| *t != b"TERR")
        || (version < 2 && heightmaps < tags.len())
        || (version < 3 && ground_end < tags.len())
    {
        return Err(
            "its sections are not CONF, PLAN, MESH, SURF, (from version 2) GRND and (from version 3) TERR in that order"
                .into(),
        );
    }
    Ok((heightmaps, ground_end))
}

pub(super) fn read_meshes(data: &[u8]) -> std::result::Result<SavedMeshes, String> {
    let mut r = Reader::new(data);
    let mut m = SavedMeshes::default();
    let n = r.count(8 + 4 + 16, "the mesh list")?;
    for _ in 0..n {
        let name = read_string(&mut r)?;
        let world = r.u32("a mesh's world index")?;
        let mesh = read_mesh(&mut r)?;
        mesh.validate(&name).map_err(|e| e.to_string())?;
        m.managed.push((name, mesh, world));
    }
    let n = r.count(4 + 16, "the earlier posings")?;
    for _ in 0..n {
        let world = r.u32("a posing's world index")?;
        let mesh = read_mesh(&mut r)?;
        mesh.validate("an earlier posing")
            .map_err(|e| e.to_string())?;
        m.retired.push((world, mesh));
    }
    r.done("the meshes")?;
    Ok(m)
}

pub(super) fn read_surface(
    data: &[u8],
    config: &ManagerConfig,
    plan: &PlannerState,
    version: u32,
) -> std::result::Result<SavedSurface, String> {
    let mut r = Reader::new(data);
    let index = r.u32("its surface index")?;
    let offset = r.u64("its slot")?;
    let width = r.u32("its width")?;
    let height = r.u32("its height")?;
    let carry = r.f64("its carry")?;
    let words = r.words("its words")?;
    // From version 4: how long and where a slumping material still relaxes.
    let settle = if version >= 4 {
        super::bytes::read_settle(&mut r)?
    } else {
        Settle::default()
    };
    r.done("a heightmap")?;
    let desc = plan
        .surfaces
        .get(index as usize)
        .ok_or_else(|| {
            format!(
                "it names surface {index}, the save has {}",
                plan.surfaces.len()
            )
        })?
        .desc
        .clone();
    let paged = offset == u64::MAX;
    let max = desc.material.settle_updates;
    check_settle(
        &settle,
        &format!("surface {:?}", desc.name),
        max,
        (width, height),
        paged,
    )?;
    Ok(SavedSurface {
        index,
        slot_offset: (offset != u64::MAX).then_some(offset),
        snapshot: SurfaceSnapshot {
            desc,
            width,
            height,
            format: config.format,
            carry,
            words,
        },
        settle,
    })
}

/// A saved settle state (of `what`: a surface or a terrain's level, named) fits: a rectangle within
/// its texels, no more updates than its material settles for (`max`), and none on a surface paged
/// out (which has settled).
pub(super) fn check_settle(
    s: &Settle,
    what: &str,
    max: u32,
    (width, height): (u32, u32),
    paged: bool,
) -> std::result::Result<(), String> {
    let r = s.rect;
    if s.updates > max || (paged && s.updates > 0) {
        return Err(format!(
            "{what} still settles for {} updates, its material for at most {}{}",
            s.updates,
            if paged { 0 } else { max },
            if paged { " once paged out" } else { "" }
        ));
    }
    if r.x0 > r.x1 || r.y0 > r.y1 || r.x1 > width || r.y1 > height {
        return Err(format!(
            "{what}'s settling rectangle ({}, {}) to ({}, {}) is not within its {width} x {height} texels",
            r.x0, r.y0, r.x1, r.y1
        ));
    }
    Ok(())
}

/// A `GRND` section: checked against its surface's heightmap size, its heights finite, its rule
/// valid.
pub(super) fn read_ground(
    data: &[u8],
    plan: &PlannerState,
) -> std::result::Result<SavedGround, String> {
    let mut r = Reader::new(data);
    let index = r.u32("its surface index")?;
    let width = r.u32("its width")?;
    let height = r.u32("its height")?;
    let slope = crate::SlopeRule {
        full_degrees: r.f32("its slope rule")?,
        bare_degrees: r.f32("its slope rule")?,
    };
    let heights = r.floats("its heights")?;
    r.done("a ground")?;
    let desc = &plan
        .surfaces
        .get(index as usize)
        .ok_or_else(|| {
            format!(
                "it names surface {index}, the save has {}",
                plan.surfaces.len()
            )
        })?
        .desc;
    let layout = desc.layout();
    if (width, height) != (layout.width, layout.height)
        || heights.len() as u64 != width as u64 * height as u64
    {
        return Err(format!(
            "surface {:?}'s ground is {width} x {height} texels with {} heights, its heightmap {} x {}",
            desc.name,
            heights.len(),
            layout.width,
            layout.height
        ));
    }
    if heights.iter().any(|h| !h.is_finite()) {
        return Err(format!(
            "surface {:?}'s ground has a height that is not finite",
            desc.name
        ));
    }
    slope.validate(&desc.name).map_err(|e| e.to_string())?;
    Ok(SavedGround {
        index,
        heights,
        slope,
    })
}

/// A message as one line of text: control characters (from damaged names or tags) escaped.
pub(super) fn one_line(s: &str) -> String {
    s.chars()
        .flat_map(|c| {
            if c.is_control() {
                c.escape_default().collect::<Vec<_>>()
            } else {
                vec![c]
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::relax::Rect;

    /// A settle state that does not fit its surface is refused in one sentence naming it: a
    /// rectangle past its texels or turned inside out, more updates than its material settles for,
    /// a paged-out surface still settling; one that fits reads.
    #[test]
    fn a_settle_state_must_fit_its_surface() {
        let mut desc = crate::SurfaceDesc::new("dune", [0.0; 3], [2.0, 2.0], 0.2);
        desc.material = crate::Material::sand();
        let settle = |updates, [x0, y0, x1, y1]: [u32; 4]| Settle {
            updates,
            rect: Rect { x0, y0, x1, y1 },
        };
        let size = (50, 40);
        let what = format!("surface {:?}", desc.name);
        let max = desc.material.settle_updates;
        assert!(check_settle(&settle(120, [0, 0, 50, 40]), &what, max, size, false).is_ok());
        assert!(check_settle(&Settle::default(), &what, max, size, true).is_ok());
        for (s, paged, says) in [
            (settle(3, [0, 0, 51, 40]), false, "settling rectangle"),
            (settle(3, [10, 0, 5, 40]), false, "settling rectangle"),
            (settle(121, [0, 0, 1, 1]), false, "at most 120"),
            (settle(1, [0, 0, 1, 1]), true, "once paged out"),
        ] {
            let e = check_settle(&s, &what, max, size, paged).unwrap_err();
            assert!(e.contains(says) && e.contains("\"dune\""), "{e}");
        }
    }
}
