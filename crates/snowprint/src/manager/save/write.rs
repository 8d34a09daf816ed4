//! Writing a save: the manager's state as sections.

use std::io::Write;
use std::path::Path;

use super::bytes::{put_mesh, put_settle, put_string, put_u32, put_u64, section};
use super::config::SavedConfig;
use super::{MAGIC, VERSION};
use crate::error::{Result, SnowError};
use crate::manager::SnowManager;
use crate::mesh::Mesh;
use crate::relax::Settle;
use crate::world::SurfaceSnapshot;

impl SnowManager {
    /// The whole snow state as the bytes of a save (see the module docs), terrain windows
    /// included. Pages still on their way from the GPU are waited for, and every terrain's
    /// strips on their way are landed first (as [`SnowManager::flush_terrain`] lands them), so
    /// that the manager saved and one loaded from the save go on alike; refused with
    /// [`SnowError::FramePending`] while a tick is recorded and not submitted.
    pub fn to_save_bytes(&mut self) -> Result<Vec<u8>> {
        self.not_pending()?;
        self.flush_terrains()?;
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
        // Heightmaps: resident ones and the terrains' levels read back in one round trip, paged
        // ones from their pages.
        let resident: Vec<(u32, crate::SurfaceId)> = self
            .world_ids
            .iter()
            .enumerate()
            .filter_map(|(i, w)| w.map(|w| (i as u32, w)))
            .collect();
        let levels: Vec<crate::SurfaceId> = self.level_ids().collect();
        let mut snaps = self.world.snapshot_surfaces(
            &resident
                .iter()
                .map(|r| r.1)
                .chain(levels.iter().copied())
                .collect::<Vec<_>>(),
        )?;
        let level_snaps = snaps.split_off(resident.len());
        let terrains = self.terrain_sections(&levels, &level_snaps)?;
        // A surface paged out (or on its way in) has settled.
        let settled = Settle::default();
        let mut surfaces: Vec<(u32, Option<u64>, SurfaceSnapshot, Settle)> = Vec::new();
        for (&(i, w), s) in resident.iter().zip(snaps) {
            let offset = self
                .planner
                .slot(crate::manager::ManagedId(i))
                .map(|s| s.offset);
            surfaces.push((i, offset, s, self.world.settle_of(w)?));
        }
        for (i, page) in self.pages.iter() {
            surfaces.push((i, None, page.decompress()?, settled));
        }
        for (id, snap) in self.arriving_snapshots()? {
            surfaces.push((id.0, None, snap, settled));
        }
        surfaces.sort_by_key(|s| s.0);
        let mut out = Vec::new();
        out.extend_from_slice(&MAGIC);
        put_u32(&mut out, VERSION);
        let grounds: Vec<(usize, &crate::manager::ground::ManagedGround)> = self
            .grounds
            .iter()
            .enumerate()
            .filter_map(|(i, g)| g.as_ref().map(|g| (i, g)))
            .collect();
        put_u32(
            &mut out,
            (3 + surfaces.len() + grounds.len() + terrains.len()) as u32,
        );
        let crc = crc32fast::hash(&out[..16]);
        put_u32(&mut out, crc);
        section(&mut out, b"CONF", &conf);
        section(&mut out, b"PLAN", &plan);
        section(&mut out, b"MESH", &meshes);
        for (i, offset, s, settle) in &surfaces {
            let mut b = Vec::with_capacity(68 + s.words.len() * 4);
            put_u32(&mut b, *i);
            put_u64(&mut b, offset.unwrap_or(u64::MAX));
            put_u32(&mut b, s.width);
            put_u32(&mut b, s.height);
            b.extend_from_slice(&s.carry.to_bits().to_le_bytes());
            put_u64(&mut b, s.words.len() as u64);
            b.extend_from_slice(bytemuck::cast_slice(&s.words));
            put_settle(&mut b, settle);
            section(&mut out, b"SURF", &b);
        }
        for (i, g) in grounds {
            let mut b = Vec::with_capacity(28 + g.field.ground.len() * 4);
            put_u32(&mut b, i as u32);
            put_u32(&mut b, g.field.width);
            put_u32(&mut b, g.field.height);
            b.extend_from_slice(&g.slope.full_degrees.to_le_bytes());
            b.extend_from_slice(&g.slope.bare_degrees.to_le_bytes());
            put_u64(&mut b, g.field.ground.len() as u64);
            b.extend_from_slice(bytemuck::cast_slice(&g.field.ground));
            section(&mut out, b"GRND", &b);
        }
        for t in &terrains {
            section(&mut out, b"TERR", t);
        }
        Ok(out)
    }

    /// The `TERR` sections of the live terrains, in order of their handles: `levels` are every
    /// level's surface (as [`SnowManager::level_ids`] lists them) and `snaps` their snapshots.
    fn terrain_sections(
        &self,
        levels: &[crate::SurfaceId],
        snaps: &[SurfaceSnapshot],
    ) -> Result<Vec<Vec<u8>>> {
        let mut at = 0;
        let mut out = Vec::new();
        for (index, t) in self.live_terrains() {
            let n = t.surfaces().len();
            let (ids, snaps) = (&levels[at..at + n], &snaps[at..at + n]);
            at += n;
            let mut parts = Vec::with_capacity(n);
            for (&id, s) in ids.iter().zip(snaps) {
                let settle = self.world.settle_of(id)?;
                parts.push((
                    self.world.slot_of(id)?.offset,
                    s.carry,
                    s.words.as_slice(),
                    settle,
                ));
            }
            out.push(super::terrain::put_terrain(index, t, &parts)?);
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
    /// bytes written. Lands the terrains' strips on their way first (see
    /// [`SnowManager::to_save_bytes`]).
    pub fn save(&mut self, path: &Path) -> Result<u64> {
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
        write().map_err(|source| {
            let _ = std::fs::remove_file(&tmp);
            SnowError::WriteFile {
                path: path.to_owned(),
                source,
            }
        })?;
        Ok(bytes.len() as u64)
    }
}

/// JSON for the text sections, with the error as the library's.
pub(super) fn to_json<T: serde::Serialize>(v: &T) -> Result<Vec<u8>> {
    serde_json::to_vec(v).map_err(SnowError::SaveEncode)
}
