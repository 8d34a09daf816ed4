//! Checking the raw file and turning it into the public [`Scene`] types. Every check reports the
//! line of the offending value (or of the table that lacks a key) and quotes what is written there.

use std::collections::HashMap;
use std::ops::Range;
use std::path::Path;

use toml::Spanned;

use super::diagnose::Source;
use super::raw::{RawBudget, RawScene};
use super::{SCENE_VERSION, Scene, SceneBudget};
use crate::error::Result;
use crate::surface::SurfaceDesc;
use crate::world::CaptureConfig;

mod camera;
mod deformer;
mod ground;
mod material;
mod mesh;
mod surface;
mod terrain;
mod values;

use camera::camera;
use deformer::deformer;
use surface::{capture, surface};
use values::{finite, number, required, unique, vector};

/// Largest surface side accepted, metres (as [`SurfaceDesc::validate`]).
pub(super) const MAX_SIDE: f32 = 100_000.0;

/// Check `raw` and build the scene. `dir` is the scene file's folder, for mesh paths.
pub(super) fn convert(raw: RawScene, src: &Source<'_>, dir: &Path, path: &Path) -> Result<Scene> {
    let Some(version) = raw.version else {
        return Err(src.error_at_line(
            1,
            "the scene file has no version",
            format!("add the line version = {SCENE_VERSION} at the top"),
        ));
    };
    if *version.get_ref() != i64::from(SCENE_VERSION) {
        return Err(src.error(
            &version.span(),
            format!(
                "version is {}, but this snowprint reads only version {SCENE_VERSION}",
                src.quote(&version.span())
            ),
            format!("set version = {SCENE_VERSION} and write the file as docs/SCENES.md describes"),
        ));
    }

    let capture = match raw.capture {
        Some(c) => capture(src, c.into_inner())?,
        None => CaptureConfig::default(),
    };

    let materials = material::materials(src, raw.material)?;
    let mut names = HashMap::new();
    let surface_spans: Vec<Range<usize>> = raw.surface.iter().map(Spanned::span).collect();
    let mut surfaces: Vec<SurfaceDesc> = Vec::new();
    let mut zones = Vec::new();
    let mut grounds = Vec::new();
    for s in raw.surface {
        let table = s.span();
        let (keys, rest) = ground::GroundKeys::take(s.into_inner());
        let (desc, zone) = surface(
            src,
            Spanned::new(table.clone(), rest),
            &mut names,
            &materials,
        )?;
        grounds.push(ground::ground(src, keys, &desc, dir)?);
        surfaces.push(desc);
        zones.push(zone);
    }
    if surfaces.is_empty() && raw.terrain.is_empty() {
        return Err(src.error_at_line(
            1,
            "the scene has no [[surface]] or [[terrain]] table, so there is no snow to press",
            "add at least one [[surface]] with name, center, size and snow_depth",
        ));
    }

    let mut names_of_surfaces = names;
    let mut names = HashMap::new();
    let mut first_player: Option<usize> = None;
    let mut deformers = Vec::new();
    for d in raw.deformer {
        let player = d
            .get_ref()
            .player
            .as_ref()
            .map(|p| (*p.get_ref(), p.span()));
        deformers.push(deformer(src, d, dir, &mut names)?);
        if let Some((true, span)) = player {
            if let Some(first) = first_player {
                return Err(src.error(
                    &span,
                    format!(
                        "deformer {:?} has player = true, but the player is already deformer {:?}",
                        deformers[deformers.len() - 1].name,
                        deformers[first].name
                    ),
                    "mark one deformer only with player = true",
                ));
            }
            first_player = Some(deformers.len() - 1);
        }
    }

    let budget_span = raw.budget.as_ref().map(Spanned::span);
    let pool_span = raw
        .budget
        .as_ref()
        .and_then(|b| b.get_ref().pool_bytes.as_ref().map(Spanned::span));
    let budget = raw
        .budget
        .map(|b| budget(src, b.into_inner()))
        .transpose()?;
    if let (Some(b), Some(table)) = (&budget, budget_span) {
        pool_holds_every_surface(
            src,
            b,
            &surfaces,
            &surface_spans,
            pool_span.unwrap_or(table),
        )?;
    }
    let pool = (
        budget
            .and_then(|b| b.pool_bytes)
            .unwrap_or(crate::WorldConfig::default().pool_bytes),
        crate::pool::PoolFormat::new(budget.and_then(|b| b.precision).unwrap_or_default()),
    );
    let mut terrains = Vec::new();
    let surfaces_bytes: u64 = surfaces
        .iter()
        .map(|s| {
            let l = s.layout();
            pool.1.slot_bytes(l.width, l.height)
        })
        .sum();
    for t in raw.terrain {
        let used: u64 = surfaces_bytes
            + terrains
                .iter()
                .flat_map(|t: &super::SceneTerrain| &t.desc.levels)
                .map(|l| pool.1.slot_bytes(l.texels[0], l.texels[1]))
                .sum::<u64>();
        terrains.push(terrain::terrain(
            src,
            t,
            &mut names_of_surfaces,
            &materials,
            (pool.0.saturating_sub(used), pool.1),
            dir,
        )?);
    }
    let camera = raw
        .camera
        .map(|c| camera(src, c.span(), c.into_inner()))
        .transpose()?;

    Ok(Scene {
        path: path.to_owned(),
        capture,
        surfaces,
        deformers,
        zones,
        budget,
        camera,
        grounds,
        terrains,
    })
}

fn budget(src: &Source<'_>, b: RawBudget) -> Result<SceneBudget> {
    let whole = |v: &Spanned<i64>, key: &str, min: i64, max: i64, rule: &str| -> Result<i64> {
        let x = *v.get_ref();
        if (min..=max).contains(&x) {
            Ok(x)
        } else {
            Err(src.error(
                &v.span(),
                format!("[budget] has {key} {}", src.quote(&v.span())),
                rule,
            ))
        }
    };
    Ok(SceneBudget {
        updates_per_frame: b
            .updates_per_frame
            .as_ref()
            .map(|v| {
                whole(
                    v,
                    "updates_per_frame",
                    1,
                    1 << 20,
                    "updates_per_frame must be a whole number of surfaces from 1 to 1048576",
                )
            })
            .transpose()?
            .map(|x| x as u32),
        pool_bytes: b
            .pool_bytes
            .as_ref()
            .map(|v| {
                whole(
                    v,
                    "pool_bytes",
                    256,
                    1 << 40,
                    "pool_bytes must be a whole number of bytes, at least 256 (2 MiB is 2097152)",
                )
            })
            .transpose()?
            .map(|x| x as u64),
        active_distance: b
            .active_distance
            .as_ref()
            .map(|v| {
                number(
                    src,
                    v,
                    "[budget]",
                    "active_distance",
                    |x| x > 0.0,
                    "active_distance must be a finite number of metres above 0",
                )
            })
            .transpose()?,
        precision: b
            .precision_bits
            .as_ref()
            .map(|v| {
                let bits = *v.get_ref();
                u32::try_from(bits)
                    .ok()
                    .and_then(crate::pool::Precision::from_bits)
                    .ok_or_else(|| {
                        src.error(
                            &v.span(),
                            format!("[budget] has precision_bits {}", src.quote(&v.span())),
                            "precision_bits must be 8, 16 or 32 (bits a heightmap channel)",
                        )
                    })
            })
            .transpose()?,
    })
}

/// The surface manager's pool must hold the largest surface on its own, or that surface could
/// never be updated: known from the file alone, so refused here rather than at some frame.
fn pool_holds_every_surface(
    src: &Source<'_>,
    b: &SceneBudget,
    surfaces: &[SurfaceDesc],
    spans: &[Range<usize>],
    at: Range<usize>,
) -> Result<()> {
    let defaults = crate::manager::ManagerConfig::default();
    let mut format = defaults.format;
    if let Some(p) = b.precision {
        format.precision = p;
    }
    let pool = b.pool_bytes.unwrap_or(defaults.pool_bytes);
    let largest = surfaces
        .iter()
        .zip(spans)
        .map(|(s, span)| {
            let l = s.layout();
            (format.slot_bytes(l.width, l.height), s, span)
        })
        .max_by_key(|(bytes, _, _)| *bytes);
    if let Some((needed, s, span)) = largest
        && needed > pool
    {
        let l = s.layout();
        let written = if b.pool_bytes.is_some() {
            format!("pool_bytes = {pool}")
        } else {
            format!("the default pool of {pool} bytes")
        };
        return Err(src.error(
            &at,
            format!(
                "[budget] has {written}, but surface {:?} (line {}, {} x {} texels) needs {needed} bytes of the pool at {} bits",
                s.name,
                src.line(span.start),
                l.width,
                l.height,
                format.precision.bits()
            ),
            format!(
                "set pool_bytes to at least {needed}, use fewer precision_bits, or make the surface smaller"
            ),
        ));
    }
    Ok(())
}
