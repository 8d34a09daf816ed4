//! The `[capture]` table and the `[[surface]]` tables.

use std::collections::HashMap;

use glam::{Vec2, Vec3};
use toml::Spanned;

use crate::error::Result;
use crate::material::Material;
use crate::scene::diagnose::Source;
use crate::scene::raw::{RawCapture, RawSurface};
use crate::surface::SurfaceDesc;
use crate::world::{CaptureConfig, CaptureMode};

use super::{MAX_SIDE, number, required, unique, vector};

pub(super) fn capture(src: &Source<'_>, c: RawCapture) -> Result<CaptureConfig> {
    let mut out = CaptureConfig::default();
    if let Some(mode) = &c.mode {
        out.mode = match mode.get_ref().as_str() {
            "depth" => CaptureMode::Depth,
            "mask" => CaptureMode::Mask,
            _ => {
                return Err(src.error(
                    &mode.span(),
                    format!("[capture] has mode {}", src.quote(&mode.span())),
                    "use mode = \"depth\" (lowest point per texel) or mode = \"mask\" (fixed imprint depth)",
                ));
            }
        };
    }
    if let Some(v) = &c.ankle_height {
        out.ankle_height = number(
            src,
            v,
            "[capture]",
            "ankle_height",
            |x| x > 0.0,
            "ankle_height must be a finite number of metres above 0",
        )?;
    }
    if let Some(v) = &c.mask_depth {
        out.mask_depth = number(
            src,
            v,
            "[capture]",
            "mask_depth",
            |x| x > 0.0 && x <= 1.0,
            "mask_depth must be a fraction of the snow depth above 0 and at most 1",
        )?;
    }
    Ok(out)
}

/// Longest surface name, bytes: `<name>.json` must fit the 255 bytes of a file name.
const MAX_NAME_BYTES: usize = 250;

/// Why a surface name cannot be a file name, if it cannot.
pub(super) fn file_name_problem(name: &str) -> Option<String> {
    if name.is_empty() {
        return Some("it is empty".into());
    }
    if let Some(c) = name
        .chars()
        .find(|c| !(c.is_ascii_alphanumeric() || matches!(c, '_' | '-' | '.')))
    {
        return Some(format!("it contains {c:?}"));
    }
    if name.chars().all(|c| c == '.') {
        return Some("it is only dots".into());
    }
    // Outputs are `<name>.json` and `<name>.png`, and most file systems stop at 255 bytes.
    if name.len() > MAX_NAME_BYTES {
        return Some(format!(
            "it has {} characters, and a file name of at most 255 leaves {MAX_NAME_BYTES} for it before \".json\"",
            name.len()
        ));
    }
    None
}

pub(super) fn surface(
    src: &Source<'_>,
    s: Spanned<RawSurface>,
    names: &mut HashMap<String, usize>,
    materials: &HashMap<String, Material>,
) -> Result<(SurfaceDesc, u32)> {
    let table = s.span();
    let s = s.into_inner();
    let name = required(
        src,
        &table,
        s.name,
        "this [[surface]]",
        "name",
        "add name = \"...\" using letters, digits, \"_\", \"-\" and \".\"",
    )?;
    if let Some(problem) = file_name_problem(name.get_ref()) {
        return Err(src.error(
            &name.span(),
            format!(
                "surface name {} cannot be used as a file name ({problem})",
                src.quote(&name.span())
            ),
            "use at most 250 letters, digits, \"_\", \"-\" and \".\"",
        ));
    }
    unique(src, names, &name, "surface")?;
    let who = format!("surface {:?}", name.get_ref());

    let center = required(
        src,
        &table,
        s.center,
        &who,
        "center",
        "add center = [x, y, z] in metres, y being the ground under the snow",
    )?;
    let center: [f32; 3] = vector(
        src,
        &center,
        &who,
        "center",
        "[x, y, z] in metres",
        |_| true,
        "center must be three finite numbers of metres, [x, y, z]",
    )?;

    let size = required(
        src,
        &table,
        s.size,
        &who,
        "size",
        "add size = [x, z], the side lengths in metres",
    )?;
    let size: [f32; 2] = vector(
        src,
        &size,
        &who,
        "size",
        "[x, z] in metres",
        |x| x > 0.0 && x <= MAX_SIDE,
        "sizes must be finite numbers of metres above 0 (and at most 100000)",
    )?;

    let yaw_degrees = match &s.yaw_degrees {
        Some(v) => number(
            src,
            v,
            &who,
            "yaw_degrees",
            |_| true,
            "yaw_degrees must be a finite number of degrees",
        )?,
        None => 0.0,
    };

    let depth = required(
        src,
        &table,
        s.snow_depth,
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

    let replenish_rate = match &s.replenish_rate {
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

    let material = match &s.material {
        Some(m) => super::material::named(src, m, &who, materials)?,
        None => Material::snow(),
    };
    let desc = SurfaceDesc {
        name: name.into_inner(),
        center: Vec3::from(center),
        size: Vec2::from(size),
        yaw_degrees,
        snow_depth,
        replenish_rate,
        material,
    };
    desc.validate()
        .map_err(|e| src.error(&table, e, "fix this [[surface]] table"))?;
    let zone = match &s.zone {
        Some(z) if (0..=i64::from(u32::MAX)).contains(z.get_ref()) => *z.get_ref() as u32,
        Some(z) => {
            return Err(src.error(
                &z.span(),
                format!("surface {:?} has zone {}", desc.name, src.quote(&z.span())),
                "zone must be a whole number from 0 to 4294967295",
            ));
        }
        None => 0,
    };
    Ok((desc, zone))
}
