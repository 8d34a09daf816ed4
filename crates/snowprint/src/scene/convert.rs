//! Checking the raw file and turning it into the public [`Scene`] types. Every check reports the
//! line of the offending value (or of the table that lacks a key) and quotes what is written there.

use std::collections::HashMap;
use std::ops::Range;
use std::path::Path;

use glam::{Vec2, Vec3};
use toml::Spanned;

use crate::deformer::{Deformer, MAX_DEFORMER_SIZE, Shape};
use crate::error::{Result, SnowError};
use crate::mesh::Mesh;
use crate::surface::SurfaceDesc;
use crate::world::{CaptureConfig, CaptureMode};

use super::diagnose::Source;
use super::raw::{
    Num, Nums, RawBudget, RawCamera, RawCapture, RawDeformer, RawKey, RawScene, RawSurface, Str,
};
use super::{Key, SCENE_VERSION, Scene, SceneBudget, SceneCamera, SceneDeformer, SceneShape};

/// Largest surface side accepted, metres (as [`SurfaceDesc::validate`]).
const MAX_SIDE: f32 = 100_000.0;

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

    let mut names = HashMap::new();
    let surface_spans: Vec<Range<usize>> = raw.surface.iter().map(Spanned::span).collect();
    let (surfaces, zones): (Vec<SurfaceDesc>, Vec<u32>) = raw
        .surface
        .into_iter()
        .map(|s| surface(src, s, &mut names))
        .collect::<Result<Vec<_>>>()?
        .into_iter()
        .unzip();
    if surfaces.is_empty() {
        return Err(src.error_at_line(
            1,
            "the scene has no [[surface]] table, so there is no snow to press",
            "add at least one [[surface]] with name, center, size and snow_depth",
        ));
    }

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

fn camera(src: &Source<'_>, table: Range<usize>, c: RawCamera) -> Result<SceneCamera> {
    let target = required(
        src,
        &table,
        c.target.as_ref(),
        "[camera]",
        "target",
        "add target = [x, y, z], the point the camera looks at",
    )?;
    let target = vector::<3>(
        src,
        target,
        "[camera]",
        "target",
        "[x, y, z] in metres",
        |_| true,
        "target must be three finite numbers of metres",
    )?;
    let fov_y_degrees = match &c.fov_y_degrees {
        Some(v) => number(
            src,
            v,
            "[camera]",
            "fov_y_degrees",
            |x| x > 1.0 && x < 179.0,
            "fov_y_degrees must be an angle between 1 and 179 degrees",
        )?,
        None => 50.0,
    };
    let keys = required(
        src,
        &table,
        c.keys,
        "[camera]",
        "keys",
        "add keys = [{ t = 0.0, eye = [x, y, z] }, ...]",
    )?;
    let keys_span = keys.span();
    let mut out: Vec<(f32, Vec3)> = Vec::new();
    for k in keys.into_inner() {
        let span = k.span();
        let k = k.into_inner();
        let t = required(
            src,
            &span,
            k.t.as_ref(),
            "a camera key",
            "t",
            "add t = <seconds>",
        )?;
        let t = number(
            src,
            t,
            "a camera key",
            "t",
            |_| true,
            "t must be a finite number of seconds",
        )?;
        let eye = required(
            src,
            &span,
            k.eye.as_ref(),
            "a camera key",
            "eye",
            "add eye = [x, y, z]",
        )?;
        let eye = vector::<3>(
            src,
            eye,
            "a camera key",
            "eye",
            "[x, y, z] in metres",
            |_| true,
            "eye must be three finite numbers of metres",
        )?;
        if let Some(&(prev, _)) = out.last()
            && t <= prev
        {
            return Err(src.error(
                &span,
                format!("a camera key has t = {t} after a key at t = {prev}"),
                "list the camera keys in strictly increasing time",
            ));
        }
        let eye = Vec3::from(eye);
        let target = Vec3::from(target);
        if (eye - target).length() <= EYE_CLEARANCE {
            return Err(src.error(
                &span,
                format!(
                    "the camera key at t = {t} has its eye at {:?}, on the target {:?}, so it looks nowhere",
                    eye.to_array(),
                    target.to_array()
                ),
                "move the eye away from the target (or the target away from the eye)",
            ));
        }
        if let Some(&(prev_t, prev_eye)) = out.last()
            && segment_distance(prev_eye, eye, target) <= EYE_CLEARANCE
        {
            return Err(src.error(
                &span,
                format!(
                    "the camera's eye passes through its target {:?} between the keys at t = {prev_t} and t = {t}, where it looks nowhere",
                    target.to_array()
                ),
                "add a key that takes the eye around the target, or move the target",
            ));
        }
        out.push((t, eye));
    }
    if out.is_empty() {
        return Err(src.error(
            &keys_span,
            "[camera] has no keys",
            "add at least one key: keys = [{ t = 0.0, eye = [x, y, z] }]",
        ));
    }
    Ok(SceneCamera {
        keys: out,
        target: Vec3::from(target),
        fov_y_degrees,
        line: src.line(table.start),
    })
}

/// How close the eye may come to the target, metres: nearer, the view direction is lost.
const EYE_CLEARANCE: f32 = 1e-3;

/// Distance from `p` to the segment `a`-`b`.
fn segment_distance(a: Vec3, b: Vec3, p: Vec3) -> f32 {
    let ab = b - a;
    let len2 = ab.length_squared();
    let f = if len2 > 0.0 {
        ((p - a).dot(ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (a + ab * f - p).length()
}

/// The value as an `f32`, if it stays finite.
fn finite(v: f64) -> Option<f32> {
    let v = v as f32;
    v.is_finite().then_some(v)
}

/// A scalar that must be finite and pass `ok`; otherwise `<who> has <key> <value>; <rule>`.
fn number(
    src: &Source<'_>,
    v: &Num,
    who: &str,
    key: &str,
    ok: impl Fn(f32) -> bool,
    rule: &str,
) -> Result<f32> {
    match finite(*v.get_ref()) {
        Some(x) if ok(x) => Ok(x),
        _ => Err(src.error(
            &v.span(),
            format!("{who} has {key} {}", src.quote(&v.span())),
            rule,
        )),
    }
}

/// An array of exactly `N` finite numbers that each pass `ok`. `layout` describes the array
/// (such as `[x, y, z] in metres`) for the message about a wrong count.
fn vector<const N: usize>(
    src: &Source<'_>,
    v: &Nums,
    who: &str,
    key: &str,
    layout: &str,
    ok: impl Fn(f32) -> bool,
    rule: &str,
) -> Result<[f32; N]> {
    let what = || format!("{who} has {key} {}", src.quote(&v.span()));
    let values = v.get_ref();
    if values.len() != N {
        let count = ["no", "one", "two", "three"]
            .get(N)
            .copied()
            .unwrap_or("more");
        return Err(src.error(
            &v.span(),
            what(),
            format!("{key} needs exactly {count} numbers, {layout}"),
        ));
    }
    let mut out = [0.0; N];
    for (o, &x) in out.iter_mut().zip(values) {
        match finite(x) {
            Some(x) if ok(x) => *o = x,
            _ => return Err(src.error(&v.span(), what(), rule)),
        }
    }
    Ok(out)
}

/// A key that must be there: otherwise `<who> has no <key>; <todo>` on the table's line.
fn required<T>(
    src: &Source<'_>,
    table: &Range<usize>,
    v: Option<T>,
    who: &str,
    key: &str,
    todo: &str,
) -> Result<T> {
    v.ok_or_else(|| src.error(table, format!("{who} has no {key}"), todo))
}

/// Record a name (with the byte offset where it is written), refusing one that is already used.
fn unique(
    src: &Source<'_>,
    names: &mut HashMap<String, usize>,
    name: &Str,
    kind: &str,
) -> Result<()> {
    if let Some(&first) = names.get(name.get_ref()) {
        return Err(src.error(
            &name.span(),
            format!(
                "{kind} name {:?} is used twice (first at line {})",
                name.get_ref(),
                src.line(first)
            ),
            format!("give every {kind} its own name"),
        ));
    }
    names.insert(name.get_ref().clone(), name.span().start);
    Ok(())
}

fn capture(src: &Source<'_>, c: RawCapture) -> Result<CaptureConfig> {
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
fn file_name_problem(name: &str) -> Option<String> {
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

fn surface(
    src: &Source<'_>,
    s: Spanned<RawSurface>,
    names: &mut HashMap<String, usize>,
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

    let desc = SurfaceDesc {
        name: name.into_inner(),
        center: Vec3::from(center),
        size: Vec2::from(size),
        yaw_degrees,
        snow_depth,
        replenish_rate,
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

/// The shapes, as written in `shape = "..."`.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Kind {
    Sphere,
    Capsule,
    Box,
    Mesh,
}

impl Kind {
    fn article(self) -> &'static str {
        match self {
            Kind::Sphere => "a sphere",
            Kind::Capsule => "a capsule",
            Kind::Box => "a box",
            Kind::Mesh => "a mesh",
        }
    }
}

fn deformer(
    src: &Source<'_>,
    d: Spanned<RawDeformer>,
    dir: &Path,
    names: &mut HashMap<String, usize>,
) -> Result<SceneDeformer> {
    let table = d.span();
    let line = src.line(table.start);
    let d = d.into_inner();
    let name = required(
        src,
        &table,
        d.name,
        "this [[deformer]]",
        "name",
        "add name = \"...\", unique among the deformers",
    )?;
    if name.get_ref().is_empty() {
        return Err(src.error(
            &name.span(),
            "a deformer has the empty name \"\"",
            "give it a name, unique among the deformers",
        ));
    }
    unique(src, names, &name, "deformer")?;
    let who = format!("deformer {:?}", name.get_ref());

    let shape = required(
        src,
        &table,
        d.shape,
        &who,
        "shape",
        "add shape = \"sphere\", \"capsule\", \"box\" or \"mesh\"",
    )?;
    let kind = match shape.get_ref().as_str() {
        "sphere" => Kind::Sphere,
        "capsule" => Kind::Capsule,
        "box" => Kind::Box,
        "mesh" => Kind::Mesh,
        _ => {
            return Err(src.error(
                &shape.span(),
                format!("{who} has shape {}", src.quote(&shape.span())),
                "use shape = \"sphere\", \"capsule\", \"box\" or \"mesh\"",
            ));
        }
    };

    // Fields of another shape.
    let foreign = [
        (
            d.radius.as_ref().map(Spanned::span),
            "radius",
            "spheres and capsules",
            &[Kind::Sphere, Kind::Capsule][..],
        ),
        (
            d.half_height.as_ref().map(Spanned::span),
            "half_height",
            "capsules",
            &[Kind::Capsule][..],
        ),
        (
            d.half_extents.as_ref().map(Spanned::span),
            "half_extents",
            "boxes",
            &[Kind::Box][..],
        ),
        (
            d.path.as_ref().map(Spanned::span),
            "path",
            "meshes",
            &[Kind::Mesh][..],
        ),
    ];
    for (span, key, applies, kinds) in foreign {
        if let Some(span) = span {
            if !kinds.contains(&kind) {
                return Err(src.error(
                    &span,
                    format!(
                        "{who} is {} but has {key} {}",
                        kind.article(),
                        src.quote(&span)
                    ),
                    format!("{key} only applies to {applies}, so remove it (or change the shape)"),
                ));
            }
        }
    }

    let what = format!("{who} is {} but", kind.article());
    let radius = |v: Option<&Num>| -> Result<f32> {
        let v = required(src, &table, v, &what, "radius", "add radius = <metres>")?;
        number(
            src,
            v,
            &who,
            "radius",
            |x| x > 0.0 && x <= MAX_DEFORMER_SIZE,
            &format!(
                "radii must be finite numbers of metres above 0 and at most {MAX_DEFORMER_SIZE} (the largest shape the capture places exactly)"
            ),
        )
    };
    let shape = match kind {
        Kind::Sphere => SceneShape::Sphere {
            radius: radius(d.radius.as_ref())?,
        },
        Kind::Capsule => {
            let radius = radius(d.radius.as_ref())?;
            let v = required(
                src,
                &table,
                d.half_height.as_ref(),
                &what,
                "half_height",
                "add half_height = <metres>, half the length of the capsule's straight part",
            )?;
            let half_height = number(
                src,
                v,
                &who,
                "half_height",
                |x| (0.0..=MAX_DEFORMER_SIZE).contains(&x),
                &format!(
                    "half_height must be a finite number of metres, 0 or more and at most {MAX_DEFORMER_SIZE} (the largest shape the capture places exactly)"
                ),
            )?;
            SceneShape::Capsule {
                radius,
                half_height,
            }
        }
        Kind::Box => {
            let v = required(
                src,
                &table,
                d.half_extents.as_ref(),
                &what,
                "half_extents",
                "add half_extents = [x, y, z], half of each side in metres",
            )?;
            let h: [f32; 3] = vector(
                src,
                v,
                &who,
                "half_extents",
                "[x, y, z] in metres",
                |x| x > 0.0 && x <= MAX_DEFORMER_SIZE,
                &format!(
                    "half_extents must be three finite numbers of metres above 0 and at most {MAX_DEFORMER_SIZE} (the largest shape the capture places exactly)"
                ),
            )?;
            SceneShape::Box {
                half_extents: Vec3::from(h),
            }
        }
        Kind::Mesh => {
            let v = required(
                src,
                &table,
                d.path.as_ref(),
                &what,
                "path",
                "add path = \"file.glb\", a glTF or GLB file relative to the scene file's folder",
            )?;
            mesh(src, v, &who, dir)?
        }
    };

    let keys = keys(src, &table, d.keys, &who)?;

    // Backstop: the library's own checks of analytic deformers.
    let analytic = match shape {
        SceneShape::Sphere { radius } => Some(Shape::Sphere { radius }),
        SceneShape::Capsule {
            radius,
            half_height,
        } => Some(Shape::Capsule {
            radius,
            half_height,
        }),
        SceneShape::Box { half_extents } => Some(Shape::Box { half_extents }),
        SceneShape::Mesh { .. } => None,
    };
    if let Some(analytic) = analytic {
        for k in &keys {
            Deformer::new(analytic, k.pose())
                .validate(name.get_ref())
                .map_err(|e| src.error(&table, e, "fix this [[deformer]] table"))?;
        }
    }

    Ok(SceneDeformer {
        name: name.into_inner(),
        shape,
        keys,
        player: d.player.is_some_and(|p| *p.get_ref()),
        line,
    })
}

/// Resolve and load a mesh deformer's file.
fn mesh(src: &Source<'_>, path: &Str, who: &str, dir: &Path) -> Result<SceneShape> {
    let span = path.span();
    let written = path.get_ref();
    if written.trim().is_empty() {
        return Err(src.error(
            &span,
            format!("{who} has the empty path {}", src.quote(&span)),
            "set path to a glTF or GLB file, relative to the scene file's folder",
        ));
    }
    let resolved = dir.join(written);
    let folder = if dir.as_os_str().is_empty() {
        "the current folder".to_owned()
    } else {
        dir.display().to_string()
    };
    // A scene may come from an untrusted mod: it and its meshes read only under its own folder.
    let root = if dir.as_os_str().is_empty() {
        Path::new(".")
    } else {
        dir
    };
    let outside = || {
        src.error(
            &span,
            format!(
                "{who} has path {}, which leads outside the scene file's folder ({folder})",
                src.quote(&span)
            ),
            "a scene may read only files under its own folder, so copy the mesh there and give a path relative to the scene",
        )
    };
    // First as written, without asking the file system (so the answer for a path out of the
    // folder is the same whether its target exists): the path with its `..` resolved on the
    // folder's canonical form must stay under it.
    // (A folder that does not exist, as for a scene given as text, is taken as written.)
    let canonical_root = root
        .canonicalize()
        .or_else(|_| std::path::absolute(root))
        .unwrap_or_else(|_| root.to_path_buf());
    let mut lexical = canonical_root.clone();
    for c in Path::new(written.as_str()).components() {
        match c {
            std::path::Component::ParentDir => {
                lexical.pop();
            }
            std::path::Component::CurDir => {}
            other => lexical.push(other),
        }
    }
    if !lexical.starts_with(&canonical_root) {
        return Err(outside());
    }
    if !resolved.is_file() {
        let problem = if resolved.exists() {
            "is not a file"
        } else {
            "does not exist"
        };
        return Err(src.error(
            &span,
            format!(
                "{who} has path {}, but {} {problem}",
                src.quote(&span),
                resolved.display()
            ),
            format!(
                "mesh paths are relative to the scene file's folder ({folder}), so put the file there or fix the path"
            ),
        ));
    }
    // Then through the file system: a symbolic link inside the folder may lead out of it.
    let inside = resolved
        .canonicalize()
        .is_ok_and(|file| file.starts_with(&canonical_root));
    if !inside {
        return Err(outside());
    }
    let mesh = Mesh::load_gltf_within(&resolved, root).map_err(|e| {
        if let SnowError::MeshUri {
            what,
            uri,
            problem,
            fix,
            ..
        } = &e
        {
            return src.error(
                &span,
                format!(
                    "{who} has path {}, but in {} {what} has uri {uri:?}, which {problem}",
                    src.quote(&span),
                    resolved.display()
                ),
                fix.replace("the mesh's folder", "the scene's folder"),
            );
        }
        let reason = match e {
            SnowError::MeshFile { reason, .. } | SnowError::InvalidMesh { reason, .. } => reason,
            other => other.to_string(),
        };
        let reason = reason.split_whitespace().collect::<Vec<_>>().join(" ");
        // The loader's reasons end with what to do after "; ": make that the hint.
        let (reason, fix) = match reason.split_once("; ") {
            Some((reason, fix)) => (reason.to_owned(), fix.to_owned()),
            None => (
                reason,
                "give it a valid glTF (.gltf) or GLB (.glb) file holding a closed triangle mesh"
                    .to_owned(),
            ),
        };
        src.error(
            &span,
            format!(
                "{who} has path {}, but {} cannot be used as a mesh ({reason})",
                src.quote(&span),
                resolved.display()
            ),
            fix,
        )
    })?;
    Ok(SceneShape::Mesh {
        path: resolved,
        mesh,
    })
}

/// Check a deformer's keys: at least one, times strictly increasing, finite values.
fn keys(
    src: &Source<'_>,
    table: &Range<usize>,
    keys: Option<Spanned<Vec<Spanned<RawKey>>>>,
    who: &str,
) -> Result<Vec<Key>> {
    let keys = required(
        src,
        table,
        keys,
        who,
        "keys",
        "add keys = [ { t = 0.0, position = [x, y, z] } ] (or [[deformer.keys]] tables)",
    )?;
    let keys_span = keys.span();
    let keys = keys.into_inner();
    if keys.is_empty() {
        return Err(src.error(
            &keys_span,
            format!("{who} has an empty keys list {}", src.quote(&keys_span)),
            "give it at least one key such as { t = 0.0, position = [x, y, z] }",
        ));
    }
    let mut out: Vec<Key> = Vec::with_capacity(keys.len());
    let mut previous: Option<(f32, String)> = None;
    for k in keys {
        let key_span = k.span();
        let k = k.into_inner();
        let t = required(
            src,
            &key_span,
            k.t,
            &format!("a key of {who}"),
            "t",
            "add t = <seconds> to every key",
        )?;
        let t_quote = src.quote(&t.span());
        let Some(t_value) = finite(*t.get_ref()) else {
            return Err(src.error(
                &t.span(),
                format!("{who} has a key at t = {t_quote}"),
                "key times must be finite numbers of seconds",
            ));
        };
        if let Some((before, before_quote)) = &previous {
            if t_value <= *before {
                return Err(src.error(
                    &t.span(),
                    format!("{who} has a key at t = {t_quote} after a key at t = {before_quote}"),
                    "key times must increase strictly, so sort the keys or fix their times",
                ));
            }
        }
        let at = format!("{who} at t = {t_quote}");
        let position = required(
            src,
            &key_span,
            k.position,
            &format!("the key of {at}"),
            "position",
            "add position = [x, y, z] in metres to every key",
        )?;
        let position: [f32; 3] = vector(
            src,
            &position,
            &format!("the key of {at}"),
            "position",
            "[x, y, z] in metres",
            |_| true,
            "positions must be three finite numbers of metres, [x, y, z]",
        )?;
        let rotation: [f32; 3] = match &k.rotation_degrees {
            Some(r) => vector(
                src,
                r,
                &format!("the key of {at}"),
                "rotation_degrees",
                "[x, y, z] in degrees",
                |_| true,
                "rotation_degrees must be three finite numbers of degrees, [x, y, z]",
            )?,
            None => [0.0; 3],
        };
        out.push(Key {
            t: t_value,
            position: Vec3::from(position),
            rotation_degrees: Vec3::from(rotation),
        });
        previous = Some((t_value, t_quote));
    }
    Ok(out)
}
