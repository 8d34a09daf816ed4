//! The `[[terrain]]` tables: a snow layer whose window follows the player or the camera.

use std::collections::HashMap;

use toml::Spanned;

use crate::error::Result;
use crate::material::Material;
use crate::pool::PoolFormat;
use crate::scene::diagnose::Source;
use crate::scene::raw::RawTerrain;
use crate::scene::{SceneTerrain, TerrainFollow};
use crate::window::{LevelDesc, TerrainDesc};

use super::{number, required, unique, vector};

/// Largest side of a level, texels (the default capture atlas's side).
const MAX_LEVEL_TEXELS: f32 = 2048.0;

pub(super) fn terrain(
    src: &Source<'_>,
    t: Spanned<RawTerrain>,
    names: &mut HashMap<String, usize>,
    materials: &HashMap<String, Material>,
    pool: (u64, PoolFormat),
) -> Result<SceneTerrain> {
    let table = t.span();
    let t = t.into_inner();
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
            ground: None,
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
            "a level's texels must be whole numbers from 1 to 2048 (a level of zero texels holds no snow)",
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
