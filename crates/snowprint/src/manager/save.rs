//! Saves: the whole snow state of a [`SnowManager`] in one file, read back into a fresh manager on
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
//! replenishment carry). Reading checks everything before anything is built: a corrupt,
//! truncated, foreign or newer file is one [`SnowError::SaveFile`] sentence.

use std::io::Write;
use std::path::Path;

use super::pages::Page;
use super::planner::{Planner, PlannerState};
use super::{CatchUp, ManagedMesh, ManagerConfig, SnowManager, UNLIMITED};
use crate::error::{Result, SnowError};
use crate::gpu::GpuContext;
use crate::mesh::{Mesh, MeshId};
use crate::pool::{PoolFormat, Precision};
use crate::world::{CaptureConfig, CaptureMode, SnowWorld, SurfaceSnapshot};

/// The first eight bytes of every save.
pub const MAGIC: [u8; 8] = *b"SNOWSAVE";
/// The format version this build writes and the newest it reads.
pub const VERSION: u32 = 1;
/// Most sections a save may have (a section per surface, plus three).
pub const MAX_SECTIONS: u32 = 1 << 20;
/// Most bytes a section may expand to (a 512^2 surface at 32 bits with normals is 3 MiB; the
/// JSON sections of a city of 10,000 surfaces with long queues stay far below).
pub const MAX_SECTION_BYTES: u64 = 1 << 30;

const HEADER: usize = 20;
const SECTION_HEADER: usize = 28;
const CODEC_RAW: u32 = 0;
const CODEC_LZ4: u32 = 1;

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
}

/// The meshes of a save: the manager's (handle order) and every world mesh a queue names.
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct SavedMeshes {
    /// `(name, mesh, world index)` by the manager's handle.
    pub(crate) managed: Vec<(String, Mesh, u32)>,
    /// `(world index, mesh)` of earlier posings still named by queues.
    pub(crate) retired: Vec<(u32, Mesh)>,
}

/// The settings as saved (a stable mirror of [`ManagerConfig`]).
#[derive(serde::Serialize, serde::Deserialize)]
struct SavedConfig {
    /// `null` for no budget.
    updates_per_frame: Option<u64>,
    pool_bytes: u64,
    active_distance: f32,
    distance_slack_frames: u32,
    player_slots: u64,
    queue_cap: u64,
    page_bytes: u64,
    replenish_interval: f32,
    capture_mask: bool,
    ankle_height: f32,
    mask_depth: f32,
    atlas_side: u32,
    precision_bits: u32,
    normals: bool,
    /// `false`: frame by frame (the default); `true`: one capture of the union.
    #[serde(default)]
    catch_up_union: bool,
}

impl SavedConfig {
    fn of(c: &ManagerConfig) -> Self {
        Self {
            updates_per_frame: (c.updates_per_frame != UNLIMITED)
                .then_some(c.updates_per_frame as u64),
            pool_bytes: c.pool_bytes,
            active_distance: c.active_distance,
            distance_slack_frames: c.distance_slack_frames,
            player_slots: c.player_slots as u64,
            queue_cap: c.queue_cap as u64,
            page_bytes: c.page_bytes,
            replenish_interval: c.replenish_interval,
            capture_mask: c.capture.mode == CaptureMode::Mask,
            ankle_height: c.capture.ankle_height,
            mask_depth: c.capture.mask_depth,
            atlas_side: c.atlas_side,
            precision_bits: c.format.precision.bits(),
            normals: c.format.normals,
            catch_up_union: c.catch_up == CatchUp::Union,
        }
    }

    fn config(&self) -> std::result::Result<ManagerConfig, String> {
        let precision = Precision::from_bits(self.precision_bits).ok_or_else(|| {
            format!(
                "precision of {} bits is not 8, 16 or 32",
                self.precision_bits
            )
        })?;
        let usize_of = |v: u64, what: &str| {
            usize::try_from(v).map_err(|_| format!("{what} {v} does not fit this machine"))
        };
        let config = ManagerConfig {
            updates_per_frame: match self.updates_per_frame {
                Some(k) => usize_of(k, "updates_per_frame")?,
                None => UNLIMITED,
            },
            pool_bytes: self.pool_bytes,
            active_distance: self.active_distance,
            distance_slack_frames: self.distance_slack_frames,
            player_slots: usize_of(self.player_slots, "player_slots")?,
            queue_cap: usize_of(self.queue_cap, "queue_cap")?,
            page_bytes: self.page_bytes,
            replenish_interval: self.replenish_interval,
            capture: CaptureConfig {
                mode: if self.capture_mask {
                    CaptureMode::Mask
                } else {
                    CaptureMode::Depth
                },
                ankle_height: self.ankle_height,
                mask_depth: self.mask_depth,
            },
            atlas_side: self.atlas_side,
            format: PoolFormat {
                precision,
                normals: self.normals,
            },
            catch_up: if self.catch_up_union {
                CatchUp::Union
            } else {
                CatchUp::FrameByFrame
            },
        };
        config.validate().map_err(|e| e.to_string())?;
        Ok(config)
    }
}

/// A little-endian reader over a byte slice that never reads past its end.
struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl<'a> Reader<'a> {
    fn new(bytes: &'a [u8]) -> Self {
        Self { bytes, at: 0 }
    }

    fn take(&mut self, n: usize, what: &str) -> std::result::Result<&'a [u8], String> {
        let end = self
            .at
            .checked_add(n)
            .filter(|&e| e <= self.bytes.len())
            .ok_or_else(|| {
                format!(
                    "it ends inside {what} (byte {} of {})",
                    self.at,
                    self.bytes.len()
                )
            })?;
        let s = &self.bytes[self.at..end];
        self.at = end;
        Ok(s)
    }

    fn u32(&mut self, what: &str) -> std::result::Result<u32, String> {
        Ok(u32::from_le_bytes(
            self.take(4, what)?.try_into().unwrap_or_default(),
        ))
    }

    fn u64(&mut self, what: &str) -> std::result::Result<u64, String> {
        Ok(u64::from_le_bytes(
            self.take(8, what)?.try_into().unwrap_or_default(),
        ))
    }

    fn f32(&mut self, what: &str) -> std::result::Result<f32, String> {
        Ok(f32::from_bits(self.u32(what)?))
    }

    fn f64(&mut self, what: &str) -> std::result::Result<f64, String> {
        Ok(f64::from_bits(self.u64(what)?))
    }

    /// A count of items of at least `item_bytes` each, checked against the bytes left.
    fn count(&mut self, item_bytes: usize, what: &str) -> std::result::Result<usize, String> {
        let n = self.u64(what)?;
        let left = (self.bytes.len() - self.at) as u64;
        if n.saturating_mul(item_bytes.max(1) as u64) > left {
            return Err(format!("{what} claims {n} items, more than its bytes hold"));
        }
        Ok(n as usize)
    }

    fn done(&self, what: &str) -> std::result::Result<(), String> {
        if self.at == self.bytes.len() {
            Ok(())
        } else {
            Err(format!(
                "{what} has {} bytes past its end",
                self.bytes.len() - self.at
            ))
        }
    }
}

fn put_u32(out: &mut Vec<u8>, v: u32) {
    out.extend_from_slice(&v.to_le_bytes());
}

fn put_u64(out: &mut Vec<u8>, v: u64) {
    out.extend_from_slice(&v.to_le_bytes());
}

fn put_mesh(out: &mut Vec<u8>, mesh: &Mesh) {
    put_u64(out, mesh.positions.len() as u64);
    for p in &mesh.positions {
        for c in p.to_array() {
            put_u32(out, c.to_bits());
        }
    }
    put_u64(out, mesh.indices.len() as u64);
    for &i in &mesh.indices {
        put_u32(out, i);
    }
}

fn read_mesh(r: &mut Reader<'_>) -> std::result::Result<Mesh, String> {
    let n = r.count(12, "a mesh's vertices")?;
    let mut positions = Vec::with_capacity(n);
    for _ in 0..n {
        positions.push(glam::Vec3::new(
            r.f32("a vertex")?,
            r.f32("a vertex")?,
            r.f32("a vertex")?,
        ));
    }
    let n = r.count(4, "a mesh's indices")?;
    let mut indices = Vec::with_capacity(n);
    for _ in 0..n {
        indices.push(r.u32("an index")?);
    }
    Ok(Mesh { positions, indices })
}

fn put_string(out: &mut Vec<u8>, s: &str) {
    put_u64(out, s.len() as u64);
    out.extend_from_slice(s.as_bytes());
}

fn read_string(r: &mut Reader<'_>) -> std::result::Result<String, String> {
    let n = r.count(1, "a name")?;
    String::from_utf8(r.take(n, "a name")?.to_vec()).map_err(|_| "a name is not UTF-8".into())
}

fn section(out: &mut Vec<u8>, tag: &[u8; 4], data: &[u8]) {
    let packed = lz4_flex::block::compress(data);
    let (codec, stored) = if packed.len() < data.len() {
        (CODEC_LZ4, &packed[..])
    } else {
        (CODEC_RAW, data)
    };
    out.extend_from_slice(tag);
    put_u32(out, codec);
    put_u64(out, data.len() as u64);
    put_u64(out, stored.len() as u64);
    put_u32(out, crc32fast::hash(stored));
    out.extend_from_slice(stored);
}

impl SnowManager {
    /// The whole snow state as the bytes of a save (see the module docs).
    pub fn to_save_bytes(&self) -> Result<Vec<u8>> {
        let conf = to_json(&SavedConfig::of(self.planner.config()))?;
        let plan = to_json(&self.planner.state())?;
        // Meshes: the manager's, and the earlier posings that queues still name.
        let mut meshes = Vec::new();
        put_u64(&mut meshes, self.meshes.len() as u64);
        for m in &self.meshes {
            put_string(&mut meshes, &m.name);
            put_u32(&mut meshes, m.world.0);
            put_mesh(&mut meshes, &m.mesh);
        }
        let retired = self.retired_meshes();
        put_u64(&mut meshes, retired.len() as u64);
        for (id, mesh) in &retired {
            put_u32(&mut meshes, *id);
            put_mesh(&mut meshes, mesh);
        }
        // Heightmaps: resident ones read back in one round trip, paged ones from their pages.
        let resident: Vec<(u32, crate::SurfaceId)> = self
            .world_ids
            .iter()
            .enumerate()
            .filter_map(|(i, w)| w.map(|w| (i as u32, w)))
            .collect();
        let snaps = self
            .world
            .snapshot_surfaces(&resident.iter().map(|r| r.1).collect::<Vec<_>>())?;
        let mut surfaces: Vec<(u32, Option<u64>, SurfaceSnapshot)> = resident
            .iter()
            .zip(snaps)
            .map(|(&(i, _), s)| {
                let offset = self.planner.slot(super::ManagedId(i)).map(|s| s.offset);
                (i, offset, s)
            })
            .collect();
        for (i, page) in self.pages.iter() {
            surfaces.push((i, None, page.decompress()?));
        }
        surfaces.sort_by_key(|s| s.0);
        let mut out = Vec::new();
        out.extend_from_slice(&MAGIC);
        put_u32(&mut out, VERSION);
        put_u32(&mut out, 3 + surfaces.len() as u32);
        let crc = crc32fast::hash(&out[..16]);
        put_u32(&mut out, crc);
        section(&mut out, b"CONF", &conf);
        section(&mut out, b"PLAN", &plan);
        section(&mut out, b"MESH", &meshes);
        for (i, offset, s) in &surfaces {
            let mut b = Vec::with_capacity(48 + s.words.len() * 4);
            put_u32(&mut b, *i);
            put_u64(&mut b, offset.unwrap_or(u64::MAX));
            put_u32(&mut b, s.width);
            put_u32(&mut b, s.height);
            b.extend_from_slice(&s.carry.to_bits().to_le_bytes());
            put_u64(&mut b, s.words.len() as u64);
            b.extend_from_slice(bytemuck::cast_slice(&s.words));
            section(&mut out, b"SURF", &b);
        }
        Ok(out)
    }

    /// The world meshes of earlier posings that queues name, with their vertices.
    fn retired_meshes(&self) -> Vec<(u32, Mesh)> {
        self.retired
            .iter()
            .filter_map(|id| self.retired_mesh.get(&id.0).map(|m| (id.0, m.clone())))
            .collect()
    }

    /// Write a save to `path` atomically: a temporary file beside it, flushed to disk, then
    /// renamed over it, so a reader finds the old save or the new one, never a part. Returns the
    /// bytes written.
    pub fn save(&self, path: &Path) -> Result<u64> {
        let bytes = self.to_save_bytes()?;
        let out = |reason: String| SnowError::Output {
            path: path.to_owned(),
            reason,
        };
        let name = path
            .file_name()
            .ok_or_else(|| out("it names no file".into()))?;
        let tmp = path.with_file_name(format!(
            ".{}.partial-{}",
            name.to_string_lossy(),
            std::process::id()
        ));
        let write = || -> std::io::Result<()> {
            let mut f = std::fs::File::create(&tmp)?;
            f.write_all(&bytes)?;
            f.sync_all()?;
            std::fs::rename(&tmp, path)
        };
        write().map_err(|e| {
            let _ = std::fs::remove_file(&tmp);
            out(e.to_string())
        })?;
        Ok(bytes.len() as u64)
    }

    /// Read a save into a fresh manager on `gpu` (see [`SaveFile::parse`] for what is checked).
    pub fn load(gpu: &GpuContext, path: &Path) -> Result<Self> {
        let bytes = std::fs::read(path).map_err(|e| SnowError::SaveFile {
            path: path.to_owned(),
            reason: format!("it cannot be read: {e}"),
        })?;
        let file = SaveFile::parse(&bytes).map_err(|reason| SnowError::SaveFile {
            path: path.to_owned(),
            reason,
        })?;
        Self::from_save(gpu, file).map_err(|e| SnowError::SaveFile {
            path: path.to_owned(),
            reason: one_line(&e.to_string()),
        })
    }

    /// Build a manager from a parsed save.
    pub fn from_save(gpu: &GpuContext, file: SaveFile) -> Result<Self> {
        // A save continues exactly only with the pool it was made with: one this device cannot
        // hold is refused before anything is allocated.
        let max_pool = gpu
            .caps
            .max_storage_binding
            .min(gpu.device.limits().max_buffer_size)
            / 256
            * 256;
        if file.config.pool_bytes / 256 * 256 > max_pool {
            return Err(SnowError::Scene(format!(
                "the save's pool of {} bytes is larger than this device allows ({max_pool} bytes)",
                file.config.pool_bytes
            )));
        }
        let world = SnowWorld::new(gpu, Self::world_config(&file.config))?;
        let mut m = SnowManager::with_parts(world, Planner::new(&file.config)?);
        // World meshes are numbered anew: map the saved numbers to the new ones.
        let mut map: std::collections::HashMap<u32, MeshId> = Default::default();
        for (name, mesh, old) in &file.meshes.managed {
            let new = m.world.add_mesh(name, mesh)?;
            map.insert(*old, new);
            m.meshes.push(ManagedMesh {
                name: name.clone(),
                mesh: mesh.clone(),
                world: new,
            });
        }
        for (old, mesh) in &file.meshes.retired {
            let new = m.world.add_mesh("retired posing", mesh)?;
            map.insert(*old, new);
            m.retired.push(new);
            m.retired_mesh.insert(new.0, mesh.clone());
        }
        let mut plan = file.plan;
        let remap = |d: &mut crate::Deformer| -> Result<()> {
            if let crate::Shape::Mesh(id) = &mut d.shape {
                *id = *map.get(&id.0).ok_or(SnowError::StaleHandle {
                    what: "saved mesh",
                    index: id.0,
                })?;
            }
            Ok(())
        };
        for s in &mut plan.surfaces {
            for d in s
                .queue
                .iter_mut()
                .map(|e| &mut e.deformer)
                .chain(s.applied.iter_mut())
            {
                remap(d)?;
            }
        }
        let mut radius = Vec::new();
        for (old, r) in plan.mesh_radius.iter().enumerate() {
            if let (Some(r), Some(new)) = (r, map.get(&(old as u32))) {
                let i = new.0 as usize;
                if radius.len() <= i {
                    radius.resize(i + 1, None);
                }
                radius[i] = Some(*r);
            }
        }
        plan.mesh_radius = radius;
        let paged: Vec<bool> = plan.surfaces.iter().map(|s| s.paged).collect();
        let resident: Vec<bool> = plan.surfaces.iter().map(|s| s.slot.is_some()).collect();
        m.planner = Planner::from_state(&file.config, plan)?;
        m.world_ids = vec![None; m.planner.len()];
        let mut held = vec![false; m.planner.len()];
        for s in file.surfaces {
            let i = s.index as usize;
            if i >= held.len() || std::mem::replace(&mut held[i], true) {
                return Err(SnowError::Scene(format!(
                    "heightmap section for surface {i} is out of range or repeated"
                )));
            }
            let desc = m.planner.surface(super::ManagedId(s.index))?;
            if &s.snapshot.desc != desc {
                return Err(SnowError::Scene(format!(
                    "heightmap section {i} is not surface {:?}'s",
                    desc.name
                )));
            }
            match s.slot_offset {
                Some(offset) => {
                    let want = m.planner.slot(super::ManagedId(s.index)).map(|s| s.offset);
                    if want != Some(offset) {
                        return Err(SnowError::Scene(format!(
                            "surface {:?}'s heightmap is at {offset}, its slot elsewhere",
                            desc.name
                        )));
                    }
                    let w = m.world.restore_surface(&s.snapshot, Some(offset))?;
                    m.world_ids[i] = Some(w);
                }
                None => {
                    if !paged[i] {
                        return Err(SnowError::Scene(format!(
                            "surface {:?} has a page but is not paged out",
                            desc.name
                        )));
                    }
                    // Checked as a restore would check it, then kept compressed.
                    m.world.check_snapshot(&s.snapshot)?;
                    m.pages.put(s.index, Page::compress(s.snapshot));
                }
            }
        }
        for i in 0..held.len() {
            if (paged[i] || resident[i]) && !held[i] {
                return Err(SnowError::Scene(format!(
                    "surface {i} holds a heightmap but the save has none for it"
                )));
            }
        }
        Ok(m)
    }
}

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
        let tags: Vec<&[u8; 4]> = sections.iter().map(|s| &s.tag).collect();
        if tags[0] != b"CONF"
            || tags[1] != b"PLAN"
            || tags[2] != b"MESH"
            || tags[3..].iter().any(|t| *t != b"SURF")
        {
            return Err("its sections are not CONF, PLAN, MESH and SURF in that order".into());
        }
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
        for s in &sections[3..] {
            surfaces.push(
                read_surface(&s.data, &config, &plan)
                    .map_err(|e| format!("a heightmap (SURF): {e}"))?,
            );
        }
        Ok(Self {
            version,
            config,
            sections,
            plan,
            meshes,
            surfaces,
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

fn read_meshes(data: &[u8]) -> std::result::Result<SavedMeshes, String> {
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

fn read_surface(
    data: &[u8],
    config: &ManagerConfig,
    plan: &PlannerState,
) -> std::result::Result<SavedSurface, String> {
    let mut r = Reader::new(data);
    let index = r.u32("its surface index")?;
    let offset = r.u64("its slot")?;
    let width = r.u32("its width")?;
    let height = r.u32("its height")?;
    let carry = r.f64("its carry")?;
    let n = r.count(4, "its words")?;
    let words: Vec<u32> = r
        .take(n * 4, "its words")?
        .chunks_exact(4)
        .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect();
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
    })
}

/// A message as one line of text: control characters (from damaged names or tags) escaped.
fn one_line(s: &str) -> String {
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

/// JSON for the text sections, with the error as the library's.
fn to_json<T: serde::Serialize>(v: &T) -> Result<Vec<u8>> {
    serde_json::to_vec(v).map_err(|e| SnowError::Scene(format!("save: {e}")))
}
