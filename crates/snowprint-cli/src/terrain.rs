//! A scene's `[[terrain]]` windows in `snowprint simulate`: made centred on their focus at the
//! first frame, moved before each step, and each level dumped as `<terrain>.<level>.png` and
//! `.json` beside the surfaces; in a plain world ([`Windows`]) or run by the surface manager
//! ([`ManagedWindows`]: its pool and budget).

use std::path::Path;

use snowprint::manager::{ManagedTerrainId, SnowManager};
use snowprint::scene::{Scene, SceneTerrain};
use snowprint::{SnowWorld, Terrain};

use crate::output::OutputSet;

/// Bytes of pool the scene's terrains need at `format`.
pub fn pool_bytes(scene: &Scene, format: snowprint::PoolFormat) -> u64 {
    scene
        .terrains
        .iter()
        .flat_map(|t| &t.desc.levels)
        .map(|l| format.slot_bytes(l.texels[0], l.texels[1]))
        .sum()
}

/// The file names a terrain's levels are dumped as, without extension.
fn level_names(t: &SceneTerrain) -> impl Iterator<Item = String> + '_ {
    (0..t.desc.levels.len()).map(|i| format!("{}.{i}", t.desc.name))
}

/// Check that the dump can take every level's files.
pub fn check_names(scene: &Scene, set: &OutputSet) -> Result<(), String> {
    for t in &scene.terrains {
        for name in level_names(t) {
            for ext in ["png", "json"] {
                set.check_name(&format!("{name}.{ext}"))?;
            }
        }
    }
    Ok(())
}

/// The scene's terrains in a world.
pub struct Windows {
    terrains: Vec<Terrain>,
}

impl Windows {
    /// Add every terrain of `scene` to `world`, centred on its focus at time 0.
    pub fn new(world: &mut SnowWorld, scene: &Scene) -> Result<Self, String> {
        let mut terrains = Vec::new();
        for t in &scene.terrains {
            let terrain = Terrain::new(world, t.desc.clone(), t.focus(scene, 0.0))
                .map_err(|e| format!("{}:{}: {e}", scene.path.display(), t.line))?;
            terrains.push(terrain);
        }
        Ok(Self { terrains })
    }

    /// Centre every window on its focus at time `t`.
    pub fn follow(
        &mut self,
        world: &mut SnowWorld,
        scene: &Scene,
        t: f32,
    ) -> snowprint::Result<()> {
        for (terrain, st) in self.terrains.iter_mut().zip(&scene.terrains) {
            terrain.follow(world, st.focus(scene, t))?;
        }
        Ok(())
    }

    /// Write every level's heightmap and description into the dump (after every scroll's
    /// readback has landed).
    pub fn dump(
        &mut self,
        world: &mut SnowWorld,
        scene: &Scene,
        set: &mut OutputSet,
    ) -> Result<(), String> {
        for terrain in &mut self.terrains {
            terrain.flush(world).map_err(|e| e.to_string())?;
        }
        for (terrain, st) in self.terrains.iter().zip(&scene.terrains) {
            write_levels(world, terrain, st, set)?;
        }
        Ok(())
    }
}

/// The scene's terrains run by a surface manager, in its pool and under its budget.
pub struct ManagedWindows {
    ids: Vec<ManagedTerrainId>,
}

impl ManagedWindows {
    /// Add every terrain of `scene` to `snow`, centred on its focus at time `t`; after `--load`
    /// (`loaded`, the save's path), find them in the loaded manager by name instead, where the
    /// save left them: each must be there with the scene's description, and no other.
    pub fn new(
        snow: &mut SnowManager,
        scene: &Scene,
        t: f32,
        loaded: Option<&Path>,
    ) -> Result<Self, String> {
        if let Some(path) = loaded {
            return Self::loaded(snow, scene, path);
        }
        let mut ids = Vec::new();
        for st in &scene.terrains {
            let id = snow
                .add_terrain(st.desc.clone(), st.focus(scene, t))
                .map_err(|e| format!("{}:{}: {e}", scene.path.display(), st.line))?;
            ids.push(id);
        }
        Ok(Self { ids })
    }

    /// The scene's terrains in a manager loaded from the save at `path`, checked against the
    /// scene.
    fn loaded(snow: &SnowManager, scene: &Scene, path: &Path) -> Result<Self, String> {
        let mut ids = Vec::new();
        for st in &scene.terrains {
            let id = snow.terrain_named(&st.desc.name).ok_or_else(|| {
                format!(
                    "--load {}: the save has no terrain {:?} of {}:{}; load it with the scene it was saved from",
                    path.display(),
                    st.desc.name,
                    scene.path.display(),
                    st.line
                )
            })?;
            let saved = snow.terrain(id).map_err(|e| e.to_string())?;
            if saved.desc() != &st.desc {
                return Err(format!(
                    "--load {}: terrain {:?} differs between the save and {}:{}; load it with the scene it was saved from",
                    path.display(),
                    st.desc.name,
                    scene.path.display(),
                    st.line
                ));
            }
            ids.push(id);
        }
        let held = snow.terrain_ids().count();
        if held != ids.len() {
            return Err(format!(
                "--load {}: the save holds {held} terrains, {} has {}; load it with the scene it was saved from",
                path.display(),
                scene.path.display(),
                ids.len()
            ));
        }
        Ok(Self { ids })
    }

    /// Centre every window on its focus at time `t`.
    pub fn follow(&self, snow: &mut SnowManager, scene: &Scene, t: f32) -> snowprint::Result<()> {
        for (&id, st) in self.ids.iter().zip(&scene.terrains) {
            snow.follow_terrain(id, st.focus(scene, t))?;
        }
        Ok(())
    }

    /// Write every level's heightmap and description into the dump.
    pub fn dump(
        &self,
        snow: &mut SnowManager,
        scene: &Scene,
        set: &mut OutputSet,
    ) -> Result<(), String> {
        for (&id, st) in self.ids.iter().zip(&scene.terrains) {
            snow.flush_terrain(id).map_err(|e| e.to_string())?;
            let terrain = snow.terrain(id).map_err(|e| e.to_string())?;
            write_levels(snow.world(), terrain, st, set)?;
        }
        Ok(())
    }
}

/// Write a terrain's levels' heightmaps and descriptions into the dump.
fn write_levels(
    world: &SnowWorld,
    terrain: &Terrain,
    st: &SceneTerrain,
    set: &mut OutputSet,
) -> Result<(), String> {
    for ((i, id), name) in terrain
        .surfaces()
        .into_iter()
        .enumerate()
        .zip(level_names(st))
    {
        let map = world.read_heightmap(id).map_err(|e| e.to_string())?;
        map.save_png(&set.path(&format!("{name}.png")))
            .map_err(|e| e.to_string())?;
        let level = st.desc.levels[i];
        let desc = world.surface(id).map_err(|e| e.to_string())?;
        let meta = serde_json::json!({
            "terrain": st.desc.name,
            "level": i,
            "resolution": level.texels,
            "texel_size": level.texel_size,
            "center": desc.center.to_array(),
            "origin_texel": terrain.origin(i),
            "snow_depth": st.desc.snow_depth,
            "scroll": terrain.stats(),
            "png": "16-bit greyscale depression: 0 = untouched, 65535 = pressed to the ground; column 0 = smallest x, row 0 = smallest z, the window where it stood after the last frame",
        });
        let text = serde_json::to_string_pretty(&meta).map_err(|e| e.to_string())?;
        set.write(&format!("{name}.json"), text + "\n")?;
    }
    Ok(())
}
