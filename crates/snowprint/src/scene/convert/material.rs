//! `[[material]]` tables: materials of the scene's own, each a preset (`like`, default `snow`) with
//! the keys it sets changed (how it moves, its compressibility and its look), named for surfaces'
//! `material` key.

use std::collections::HashMap;

use toml::Spanned;

use super::values::{number, required, unique, vector};
use crate::error::Result;
use crate::material::{Material, MaterialLook};
use crate::scene::diagnose::Source;
use crate::scene::raw::{Num, Nums, RawMaterial, Str};

/// The presets' names, for messages.
pub(super) const PRESETS: &str = "\"snow\", \"packed_snow\", \"powder\", \"sand\", \"mud\"";

/// Every `[[material]]` of the file, by name.
pub(super) fn materials(
    src: &Source<'_>,
    raw: Vec<Spanned<RawMaterial>>,
) -> Result<HashMap<String, Material>> {
    let mut names = HashMap::new();
    let mut out = HashMap::new();
    for m in raw {
        let table = m.span();
        let mut m = m.into_inner();
        let name = required(
            src,
            &table,
            m.name.take(),
            "this [[material]]",
            "name",
            "add name = \"<a name for surfaces' material key>\"",
        )?;
        if Material::named(name.get_ref()).is_some() {
            return Err(src.error(
                &name.span(),
                format!("material name {:?} is a preset's", name.get_ref()),
                format!("pick another name (the presets are {PRESETS}); use like = {:?} to start from it", name.get_ref()),
            ));
        }
        unique(src, &mut names, &name, "material")?;
        let who = format!("material {:?}", name.get_ref());
        let mut material = match &m.like {
            Some(like) => preset(src, like, &who, "like")?,
            None => Material::snow(),
        };
        if let Some(v) = &m.repose_degrees {
            material.repose_degrees = Some(number(
                src,
                v,
                &who,
                "repose_degrees",
                |x| (0.0..=90.0).contains(&x),
                "repose_degrees must be a number of degrees from 0 to 90",
            )?);
            if material.relax_steps == 0 {
                material.relax_steps = Material::sand().relax_steps;
                material.settle_updates = Material::sand().settle_updates;
            }
        }
        if let Some(v) = &m.relax_steps {
            material.relax_steps = count(src, v, &who, "relax_steps", 64)?;
        }
        if let Some(v) = &m.settle_updates {
            material.settle_updates = count(src, v, &who, "settle_updates", 100_000)?;
        }
        if let Some(v) = &m.compressibility {
            material.compressibility = Some(share(src, v, &who, "compressibility")?);
        }
        look(src, &m, &who, &mut material.look)?;
        out.insert(name.into_inner(), material);
    }
    Ok(out)
}

/// A number from 0 to 1.
fn share(src: &Source<'_>, v: &Num, who: &str, key: &str) -> Result<f32> {
    number(
        src,
        v,
        who,
        key,
        |x| (0.0..=1.0).contains(&x),
        &format!("{key} must be a number from 0 to 1"),
    )
}

/// The look's keys the table sets (`MaterialLook`), each checked with its line.
fn look(src: &Source<'_>, m: &RawMaterial, who: &str, look: &mut MaterialLook) -> Result<()> {
    let colour = |v: &Nums, key: &str| {
        vector::<3>(
            src,
            v,
            who,
            key,
            "[red, green, blue] in linear light",
            |x| (0.0..=1.0).contains(&x),
            &format!("{key} must be three numbers from 0 to 1"),
        )
    };
    if let Some(v) = &m.albedo {
        look.albedo = colour(v, "albedo")?;
    }
    if let Some(v) = &m.disturbed_albedo {
        look.disturbed_albedo = colour(v, "disturbed_albedo")?;
    }
    let shares: [(&Option<Num>, &str, &mut f32); 6] = [
        (&m.roughness, "roughness", &mut look.roughness),
        (&m.wet_roughness, "wet_roughness", &mut look.wet_roughness),
        (&m.grain, "grain", &mut look.grain),
        (&m.sparkle, "sparkle", &mut look.sparkle),
        (&m.wetness, "wetness", &mut look.wetness),
        (&m.translucency, "translucency", &mut look.translucency),
    ];
    for (v, key, field) in shares {
        if let Some(v) = v {
            *field = share(src, v, who, key)?;
        }
    }
    if let Some(v) = &m.ground_from {
        look.ground_from = Some(number(
            src,
            v,
            who,
            "ground_from",
            |x| x > 0.0 && x < 1.0,
            "ground_from must be a fraction of the depth above 0 and below 1",
        )?);
    }
    if let Some(v) = &m.water_depth {
        look.water_depth = Some(number(
            src,
            v,
            who,
            "water_depth",
            |x| x > 0.0,
            "water_depth must be a number of metres above 0",
        )?);
    }
    Ok(())
}

/// A whole number from 0 to `max`.
fn count(src: &Source<'_>, v: &Spanned<i64>, who: &str, key: &str, max: u32) -> Result<u32> {
    match u32::try_from(*v.get_ref()) {
        Ok(n) if n <= max => Ok(n),
        _ => Err(src.error(
            &v.span(),
            format!("{who} has {key} {}", src.quote(&v.span())),
            format!("{key} must be a whole number from 0 to {max}"),
        )),
    }
}

/// The preset named by `v`, or one sentence listing them.
fn preset(src: &Source<'_>, v: &Str, who: &str, key: &str) -> Result<Material> {
    Material::named(v.get_ref()).ok_or_else(|| {
        src.error(
            &v.span(),
            format!("{who} has {key} {}", src.quote(&v.span())),
            format!("{key} must be one of {PRESETS}"),
        )
    })
}

/// The material a surface names: one of the file's `[[material]]` tables, else a preset.
pub(super) fn named(
    src: &Source<'_>,
    v: &Str,
    who: &str,
    own: &HashMap<String, Material>,
) -> Result<Material> {
    if let Some(m) = own.get(v.get_ref()) {
        return Ok(*m);
    }
    Material::named(v.get_ref()).ok_or_else(|| {
        let mut mine: Vec<&str> = own.keys().map(String::as_str).collect();
        mine.sort_unstable();
        let listed = if mine.is_empty() {
            String::new()
        } else {
            format!(
                ", or one of the file's [[material]] tables ({})",
                mine.join(", ")
            )
        };
        src.error(
            &v.span(),
            format!("{who} has material {}", src.quote(&v.span())),
            format!("material must be one of {PRESETS}{listed}"),
        )
    })
}
