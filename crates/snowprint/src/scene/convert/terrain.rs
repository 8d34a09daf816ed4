//! The `[[terrain]]` tables: a snow layer whose window follows the player or the camera.

use std::collections::HashMap;

use toml::Spanned;

use crate::error::Result;
use crate::material::Material;
use crate::pool::PoolFormat;
use crate::scene::diagnose::Source;
use crate::scene::raw::RawTerrain;
use crate::scene::{SceneTerrain, TerrainFollow};
use crate::window::{LevelDesc, TerrainDesc, TerrainGround};

use super::{number, required, unique, vector};

/// Largest side of a level, texels: the default capture atlas's side less the capture's apron of
/// a texel on each side (`capture::APRON`), so that the level's capture region fits the atlas.
const MAX_LEVEL_TEXELS: f32 = 2046.0;

pub(super) fn terrain(
    src: &Source<'_>,
    t: Spanned<RawTerrain>,
    names: &mut HashMap<String, usize>,
    materials: &HashMap<String, Material>,
    pool: (u64, PoolFormat),
    dir: &std::path::Path,
) -> Result<SceneTerrain> {
    let table = t.span();
    let mut t = t.into_inner();
    let keys = super::ground::GroundKeys::of_terrain(&mut t);
    let rect = t.ground_rect.take();
    let name = required(
        src,
        &table,
        t.name,
        "this [[terrain]]",
        "name",
        "add name = \"...\" using letters, digits, \"_\", \"-\" and \".\"",
    )?;
    if let Some(problem) = super::surface::file_name_problem(name.get_ref()) {
        return Err(src.error(
            &name.span(),
            format!(
                "terrain name {} cannot be used ({problem})",
                src.quote(&name.span())
            ),
            "use at most 250 letters, digits, \"_\", \"-\" and \".\"",
        ));
    }
    unique(src, names, &name, "surface")?;
    let who = format!("terrain {:?}", name.get_ref());
    let ground_height = match &t.ground_height {
        Some(v) => number(
            src,
            v,
            &who,
            "ground_height",
            |_| true,
            "ground_height must be a finite number of metres",
        )?,
        None => 0.0,
    };
    let depth = required(
        src,
        &table,
        t.snow_depth,
        &who,
        "snow_depth",
        "add snow_depth = <metres of fresh snow>, such as snow_depth = 0.3",
    )?;
    let snow_depth = number(
        src,
        &depth,
        &who,
        "snow_depth",
        |x| x > 0.0,
        "snow_depth must be a finite number of metres above 0",
    )?;
    let replenish_rate = match &t.replenish_rate {
        Some(v) => number(
            src,
            v,
            &who,
            "replenish_rate",
            |x| x >= 0.0,
            "replenish_rate must be a finite fraction of the snow depth per second, 0 or more",
        )?,
        None => 0.0,
    };
    let material = match &t.material {
        Some(m) => super::material::named(src, m, &who, materials)?,
        None => Material::snow(),
    };
    let follow = match &t.follow {
        None => TerrainFollow::Player,
        Some(f) => match f.get_ref().as_str() {
            "player" => TerrainFollow::Player,
            "camera" => TerrainFollow::Camera,
            _ => {
                return Err(src.error(
                    &f.span(),
                    format!("{who} has follow {}", src.quote(&f.span())),
                    "use follow = \"player\" (the deformer with player = true) or follow = \"camera\"",
                ));
            }
        },
    };
    let ground = terrain_ground(src, keys, rect, &who, name.get_ref(), dir)?;
    let (levels_span, out) = levels(src, &table, t.levels, &who)?;
    let (budget, format) = pool;
    let bytes: u64 = out
        .iter()
        .map(|l| format.slot_bytes(l.texels[0], l.texels[1]))
        .sum();
    if bytes > budget {
        return Err(src.error(
            &levels_span,
            format!("{who}'s levels need {bytes} bytes of heightmap pool, and the pool has {budget} left for them"),
            "use fewer or smaller levels, or raise [budget] pool_bytes",
        ));
    }
    Ok(SceneTerrain {
        desc: TerrainDesc {
            name: name.into_inner(),
            ground_height,
            ground,
            snow_depth,
            replenish_rate,
            material,
            levels: out,
        },
        follow,
        line: src.line(table.start),
    })
}

/// The levels of a terrain, finest first, each checked with its line; and the span of `levels`.
fn levels(
    src: &Source<'_>,
    table: &std::ops::Range<usize>,
    levels: Option<Spanned<Vec<Spanned<crate::scene::raw::RawLevel>>>>,
    who: &str,
) -> Result<(std::ops::Range<usize>, Vec<LevelDesc>)> {
    let levels = required(
        src,
        table,
        levels,
        who,
        "levels",
        "add levels = [{ texels = [1024, 1024], texel_size = 0.05 }, { texels = [512, 512], texel_size = 0.4 }], finest first",
    )?;
    let levels_span = levels.span();
    if levels.get_ref().is_empty() {
        return Err(src.error(&levels_span, format!("{who} has levels {}", src.quote(&levels_span)), "give at least one level, such as levels = [{ texels = [512, 512], texel_size = 0.05 }]"));
    }
    let mut out = Vec::new();
    for (i, l) in levels.into_inner().into_iter().enumerate() {
        let span = l.span();
        let l = l.into_inner();
        let lwho = format!("{who}'s level {i}");
        let texels = required(
            src,
            &span,
            l.texels,
            &lwho,
            "texels",
            "add texels = [columns, rows], such as texels = [1024, 1024]",
        )?;
        let texels: [f32; 2] = vector(
            src,
            &texels,
            &lwho,
            "texels",
            "[columns, rows]",
            |x| (1.0..=MAX_LEVEL_TEXELS).contains(&x) && x.fract() == 0.0,
            "a level's texels must be whole numbers from 1 to 2046 (a level of zero texels holds no snow)",
        )?;
        let size = required(
            src,
            &span,
            l.texel_size,
            &lwho,
            "texel_size",
            "add texel_size = <metres>, such as texel_size = 0.05",
        )?;
        let texel_size = number(
            src,
            &size,
            &lwho,
            "texel_size",
            |x| (crate::MIN_TEXEL_SIZE..=100.0).contains(&x),
            "texel_size must be a number of metres from 0.04 to 100",
        )?;
        out.push(LevelDesc {
            texels: [texels[0] as u32, texels[1] as u32],
            texel_size,
        });
    }
    Ok((levels_span, out))
}

/// A terrain's ground keys: a PNG heightmap or a raw grid (as a surface's, `ground.rs`) laid over
/// the world rectangle `ground_rect`, or `None` (flat) without `ground`.
fn terrain_ground(
    src: &Source<'_>,
    keys: super::ground::GroundKeys,
    rect: Option<crate::scene::raw::Nums>,
    who: &str,
    name: &str,
    dir: &std::path::Path,
) -> Result<Option<TerrainGround>> {
    let Some(g) = super::ground::ground_of(src, keys, who, name, glam::Mat4::IDENTITY, dir)? else {
        if let Some(r) = &rect {
            return Err(src.error(
                &r.span(),
                format!(
                    "{who} has ground_rect {} but no ground",
                    src.quote(&r.span())
                ),
                "add ground = \"<heightmap.png or grid.f32>\" or remove ground_rect",
            ));
        }
        return Ok(None);
    };
    let crate::ground::Ground::Grid(grid) = g.ground else {
        return Err(src.error_at_line(
            g.line,
            format!("{who} has a mesh as its ground"),
            "give a terrain a 16-bit PNG heightmap or a raw f32 grid (a mesh ground is for [[surface]] tables)",
        ));
    };
    let Some(r) = rect else {
        return Err(src.error_at_line(
            g.line,
            format!("{who} has a ground but no ground_rect"),
            "add ground_rect = [x0, z0, x1, z1], the world rectangle the heightmap covers, in metres",
        ));
    };
    let [x0, z0, x1, z1]: [f32; 4] = vector(
        src,
        &r,
        who,
        "ground_rect",
        "[x0, z0, x1, z1] in metres",
        |_| true,
        "ground_rect must be four finite numbers of metres, [x0, z0, x1, z1]",
    )?;
    if !(x1 > x0 && z1 > z0) {
        return Err(src.error(
            &r.span(),
            format!("{who} has ground_rect {}", src.quote(&r.span())),
            "give ground_rect = [x0, z0, x1, z1] with x1 above x0 and z1 above z0",
        ));
    }
    Ok(Some(TerrainGround {
        grid,
        origin: [x0, z0],
        size: [x1 - x0, z1 - z0],
        slope: g.slope,
    }))
}
