//! Loading a save into a fresh manager, every part checked before use.

use std::path::Path;

use super::SaveFile;
use super::parse::one_line;
use crate::error::{Result, SnowError};
use crate::gpu::GpuContext;
use crate::ground::GroundField;
use crate::manager::ground::ManagedGround;
use crate::manager::pages::Page;
use crate::manager::planner::Planner;
use crate::manager::{ManagedMesh, SnowManager};
use crate::mesh::MeshId;
use crate::window::Terrain;
use crate::window::saved::LevelState;
use crate::world::SnowWorld;

impl SnowManager {
    /// Read a save into a fresh manager on `gpu` (see [`SaveFile::parse`] for what is checked).
    pub fn load(gpu: &GpuContext, path: &Path) -> Result<Self> {
        let bytes = std::fs::read(path).map_err(|e| SnowError::SaveFile {
            path: path.to_owned(),
            reason: format!("it cannot be read: {e}"),
            source: Some(Box::new(e)),
        })?;
        let file = SaveFile::parse(&bytes).map_err(|reason| SnowError::SaveFile {
            path: path.to_owned(),
            reason,
            source: None,
        })?;
        Self::from_save(gpu, file).map_err(|e| SnowError::SaveFile {
            path: path.to_owned(),
            reason: one_line(&e.to_string()),
            source: Some(Box::new(e)),
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
            return Err(SnowError::SaveContent(format!(
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
                return Err(SnowError::SaveContent(format!(
                    "heightmap section for surface {i} is out of range or repeated"
                )));
            }
            let desc = m.planner.surface(crate::manager::ManagedId(s.index))?;
            if &s.snapshot.desc != desc {
                return Err(SnowError::SaveContent(format!(
                    "heightmap section {i} is not surface {:?}'s",
                    desc.name
                )));
            }
            match s.slot_offset {
                Some(offset) => {
                    let want = m
                        .planner
                        .slot(crate::manager::ManagedId(s.index))
                        .map(|s| s.offset);
                    if want != Some(offset) {
                        return Err(SnowError::SaveContent(format!(
                            "surface {:?}'s heightmap is at {offset}, its slot elsewhere",
                            desc.name
                        )));
                    }
                    let w = m.world.restore_surface(&s.snapshot, Some(offset))?;
                    m.world.set_settle(w, s.settle)?;
                    m.world_ids[i] = Some(w);
                }
                None => {
                    if !paged[i] {
                        return Err(SnowError::SaveContent(format!(
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
                return Err(SnowError::SaveContent(format!(
                    "surface {i} holds a heightmap but the save has none for it"
                )));
            }
        }
        m.restore_grounds(file.grounds)?;
        m.restore_terrains(file.terrains)?;
        Ok(m)
    }

    /// Lay the saved grounds on their surfaces (rebuilt as `GroundField::build` built them).
    fn restore_grounds(&mut self, grounds: Vec<super::SavedGround>) -> Result<()> {
        let m = self;
        m.grounds = vec![None; m.planner.len()];
        for g in grounds {
            let id = crate::manager::ManagedId(g.index);
            let desc = m.planner.surface(id)?.clone();
            if m.grounds[g.index as usize].is_some() {
                return Err(SnowError::SaveContent(format!(
                    "surface {:?} has two grounds",
                    desc.name
                )));
            }
            let field = GroundField::build(
                desc.layout(),
                desc.size,
                g.heights,
                desc.snow_depth,
                g.slope,
            );
            m.lay_ground(
                id,
                Some(ManagedGround {
                    field,
                    slope: g.slope,
                }),
            )?;
        }
        Ok(())
    }

    /// Build the saved terrains again, each under its handle: levels at their slots (pinned in
    /// the planner), windows at their origins, words, carries, grounds, pages and statistics as
    /// they were.
    fn restore_terrains(&mut self, terrains: Vec<super::SavedTerrain>) -> Result<()> {
        for t in terrains {
            let levels: Vec<LevelState<'_>> = t
                .levels
                .iter()
                .map(|l| LevelState {
                    origin: l.origin,
                    offset: l.offset,
                    carry: l.carry,
                    words: &l.words,
                })
                .collect();
            let terrain = Terrain::restore(
                &mut self.world,
                t.desc,
                &levels,
                (t.stats, t.last_written),
                t.pages,
            )?;
            for (id, l) in terrain.surfaces().into_iter().zip(&t.levels) {
                self.world.set_settle(id, l.settle)?;
            }
            self.put_restored_terrain(t.index, terrain)?;
        }
        Ok(())
    }
}
