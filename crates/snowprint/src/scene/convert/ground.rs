//! A surface's ground keys: `ground` (a 16-bit PNG heightmap with `ground_heights`, a raw `f32`
//! grid with `ground_grid`, or a glTF/GLB mesh in the surface's local metres) and the slope rule
//! (`full_slope_degrees`, `bare_slope_degrees`). Files resolve within the scene's folder, as mesh
//! deformers' do; every refusal names the line of the key.

use std::path::Path;

use crate::error::Result;
use crate::ground::{Ground, GroundMesh, HeightGrid, SlopeRule};
use crate::mesh::Mesh;
use crate::scene::SceneGround;
use crate::scene::diagnose::Source;
use crate::scene::raw::{Num, Nums, RawSurface, Str};
use crate::surface::SurfaceDesc;

use super::mesh::{load_error, resolve};
use super::{number, vector};

/// The ground keys of a `[[surface]]`, taken out of it.
pub(super) struct GroundKeys {
    ground: Option<Str>,
    heights: Option<Nums>,
    grid: Option<Nums>,
    full: Option<Num>,
    bare: Option<Num>,
}

impl GroundKeys {
    /// The ground keys of a `[[terrain]]`.
    pub(super) fn of_terrain(t: &mut crate::scene::raw::RawTerrain) -> Self {
        Self {
            ground: t.ground.take(),
            heights: t.ground_heights.take(),
            grid: t.ground_grid.take(),
            full: t.full_slope_degrees.take(),
            bare: t.bare_slope_degrees.take(),
        }
    }

    /// Split the ground keys from the rest of the surface's table.
    pub(super) fn take(mut s: RawSurface) -> (Self, RawSurface) {
        let keys = Self {
            ground: s.ground.take(),
            heights: s.ground_heights.take(),
            grid: s.ground_grid.take(),
            full: s.full_slope_degrees.take(),
            bare: s.bare_slope_degrees.take(),
        };
        (keys, s)
    }
}

/// The surface's ground, or `None` when it has no `ground` key (flat ground).
pub(super) fn ground(
    src: &Source<'_>,
    k: GroundKeys,
    desc: &SurfaceDesc,
    dir: &Path,
) -> Result<Option<SceneGround>> {
    let who = format!("surface {:?}", desc.name);
    ground_of(src, k, &who, &desc.name, desc.local_to_world(), dir)
}

/// The ground of `who` (named `name`; a mesh's vertices taken to the world by `to_world`), or
/// `None` when it has no `ground` key.
pub(super) fn ground_of(
    src: &Source<'_>,
    k: GroundKeys,
    who: &str,
    name: &str,
    to_world: glam::Mat4,
    dir: &Path,
) -> Result<Option<SceneGround>> {
    let who = who.to_owned();
    let slope = slope_rule(src, &k, &who)?;
    let Some(path) = &k.ground else {
        if let Some(v) = k.heights.as_ref().or(k.grid.as_ref()) {
            return Err(src.error(
                &v.span(),
                format!("{who} has {} but no ground", src.quote(&v.span())),
                "add ground = \"<heightmap.png, grid.f32 or mesh.gltf>\" or remove this key",
            ));
        }
        return Ok(None);
    };
    let span = path.span();
    // The mesh loader's messages name the key as "path".
    let whose = format!("the ground of {who}");
    let (resolved, root) = resolve(src, path, &whose, dir)?;
    let lower = resolved.to_string_lossy().to_ascii_lowercase();
    let bad = |reason: String, todo: &str| {
        src.error(
            &span,
            format!("{who} has ground {} which {reason}", src.quote(&span)),
            todo,
        )
    };
    let ground = if lower.ends_with(".gltf") || lower.ends_with(".glb") {
        let mesh = Mesh::load_gltf_within(&resolved, &root)
            .map_err(|e| load_error(src, path, &whose, &resolved, e))?;
        if mesh.indices.len() < 3 {
            return Err(bad(
                "has no triangles".into(),
                "export the terrain or roof with at least one face",
            ));
        }
        let v = |i: u32| to_world.transform_point3(mesh.positions[i as usize]);
        Ground::Mesh(GroundMesh {
            triangles: mesh
                .indices
                .chunks_exact(3)
                .map(|t| [v(t[0]), v(t[1]), v(t[2])])
                .collect(),
        })
    } else {
        let bytes = std::fs::read(&resolved)
            .map_err(|e| bad(format!("cannot be read ({e})"), "check the path"))?;
        let grid = if lower.ends_with(".png") {
            let Some(h) = &k.heights else {
                return Err(bad(
                    "is a PNG heightmap without ground_heights".into(),
                    "add ground_heights = [low, high]: the metres of black and of white",
                ));
            };
            let [low, high]: [f32; 2] = vector(
                src,
                h,
                &who,
                "ground_heights",
                "[low, high] in metres",
                |_| true,
                "ground_heights must be two finite numbers of metres, [low, high]",
            )?;
            let grid = HeightGrid::from_png16(&bytes, low, high)
                .map_err(|r| bad(r, "save the heightmap as a 16-bit greyscale PNG"))?;
            if let Some(g) = &k.grid {
                let [c, r] = grid_size(src, g, &who)?;
                if (c, r) != (grid.columns, grid.rows) {
                    return Err(src.error(
                        &g.span(),
                        format!(
                            "{who} has ground_grid {} but its heightmap is {} x {} pixels",
                            src.quote(&g.span()),
                            grid.columns,
                            grid.rows
                        ),
                        "make the heightmap the size ground_grid says, or fix ground_grid",
                    ));
                }
            }
            grid
        } else {
            let Some(g) = &k.grid else {
                return Err(bad(
                    "is a raw grid without ground_grid".into(),
                    "add ground_grid = [columns, rows], the samples along x and z",
                ));
            };
            let [c, r] = grid_size(src, g, &who)?;
            HeightGrid::from_raw_f32(&bytes, c, r).map_err(|r| {
                bad(
                    r,
                    "write columns x rows little-endian f32 heights, or fix ground_grid",
                )
            })?
        };
        grid.validate(name)
            .map_err(|e| bad(e.to_string(), "fix the heightmap"))?;
        Ground::Grid(grid)
    };
    Ok(Some(SceneGround {
        ground,
        slope,
        line: src.line(span.start),
    }))
}

fn grid_size(src: &Source<'_>, g: &Nums, who: &str) -> Result<[u32; 2]> {
    let v: [f32; 2] = vector(
        src,
        g,
        who,
        "ground_grid",
        "[columns, rows]",
        |x| (2.0..=65536.0).contains(&x) && x.fract() == 0.0,
        "ground_grid must be two whole numbers of samples from 2 to 65536, [columns, rows]",
    )?;
    Ok([v[0] as u32, v[1] as u32])
}

fn slope_rule(src: &Source<'_>, k: &GroundKeys, who: &str) -> Result<SlopeRule> {
    let mut rule = SlopeRule::default();
    let angle = |v: &Num, key: &str| {
        number(
            src,
            v,
            who,
            key,
            |x| (0.0..=90.0).contains(&x),
            "slope angles must be degrees from 0 to 90",
        )
    };
    if let Some(v) = &k.full {
        rule.full_degrees = angle(v, "full_slope_degrees")?;
    }
    if let Some(v) = &k.bare {
        rule.bare_degrees = angle(v, "bare_slope_degrees")?;
    }
    if rule.bare_degrees <= rule.full_degrees {
        let span = k
            .bare
            .as_ref()
            .or(k.full.as_ref())
            .map(|v| v.span())
            .unwrap_or(0..0);
        return Err(src.error(
            &span,
            format!(
                "{who} holds full snow to {} degrees and none from {} degrees",
                rule.full_degrees, rule.bare_degrees
            ),
            "make bare_slope_degrees larger than full_slope_degrees",
        ));
    }
    Ok(rule)
}
