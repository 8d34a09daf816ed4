//! The `[[deformer]]` tables: a name, one shape with only its own fields, and keys.

use std::collections::HashMap;
use std::ops::Range;
use std::path::Path;

use glam::Vec3;
use toml::Spanned;

use crate::deformer::{Deformer, MAX_DEFORMER_SIZE, Shape};
use crate::error::Result;
use crate::scene::diagnose::Source;
use crate::scene::raw::{Num, RawDeformer, RawKey, Str};
use crate::scene::{Key, SceneAnimation, SceneDeformer, SceneShape};
use crate::skin::Playback;

use super::mesh::{mesh, skinned_mesh};
use super::{finite, number, required, unique, vector};

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

pub(super) fn deformer(
    src: &Source<'_>,
    d: Spanned<RawDeformer>,
    dir: &Path,
    names: &mut HashMap<String, usize>,
) -> Result<SceneDeformer> {
    let table = d.span();
    let line = src.line(table.start);
    let mut d = d.into_inner();
    let name = required(
        src,
        &table,
        d.name.take(),
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
        d.shape.as_ref(),
        &who,
        "shape",
        "add shape = \"sphere\", \"capsule\", \"box\" or \"mesh\"",
    )?;
    let kind = shape_kind(src, shape, &who)?;
    refuse_foreign(src, &d, kind, &who)?;
    let shape = scene_shape(src, &table, &d, kind, &who, dir)?;
    let animation = animation(src, &d, &who, dir)?;
    let keys = keys(src, &table, d.keys, &who)?;
    check_analytic(src, &table, &shape, &keys, name.get_ref())?;

    Ok(SceneDeformer {
        name: name.into_inner(),
        shape,
        keys,
        player: d.player.is_some_and(|p| *p.get_ref()),
        animation,
        line,
    })
}

/// The shape named by `shape = "..."`.
fn shape_kind(src: &Source<'_>, shape: &Str, who: &str) -> Result<Kind> {
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
    Ok(kind)
}

/// Refuse a field that belongs to another shape (a radius on a box, a path on a sphere...).
fn refuse_foreign(src: &Source<'_>, d: &RawDeformer, kind: Kind, who: &str) -> Result<()> {
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
        (
            d.animation.as_ref().map(Spanned::span),
            "animation",
            "meshes",
            &[Kind::Mesh][..],
        ),
        (
            d.animation_speed.as_ref().map(Spanned::span),
            "animation_speed",
            "meshes",
            &[Kind::Mesh][..],
        ),
        (
            d.looping.as_ref().map(Spanned::span),
            "loop",
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
    Ok(())
}

/// The shape's own fields, checked, as a [`SceneShape`].
fn scene_shape(
    src: &Source<'_>,
    table: &Range<usize>,
    d: &RawDeformer,
    kind: Kind,
    who: &str,
    dir: &Path,
) -> Result<SceneShape> {
    let what = format!("{who} is {} but", kind.article());
    let radius = |v: Option<&Num>| -> Result<f32> {
        let v = required(src, table, v, &what, "radius", "add radius = <metres>")?;
        number(
            src,
            v,
            who,
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
                table,
                d.half_height.as_ref(),
                &what,
                "half_height",
                "add half_height = <metres>, half the length of the capsule's straight part",
            )?;
            let half_height = number(
                src,
                v,
                who,
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
                table,
                d.half_extents.as_ref(),
                &what,
                "half_extents",
                "add half_extents = [x, y, z], half of each side in metres",
            )?;
            let h: [f32; 3] = vector(
                src,
                v,
                who,
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
                table,
                d.path.as_ref(),
                &what,
                "path",
                "add path = \"file.glb\", a glTF or GLB file relative to the scene file's folder",
            )?;
            mesh(src, v, who, dir)?
        }
    };
    Ok(shape)
}

/// A mesh's `animation`, `animation_speed` and `loop`: the file read again as a skinned mesh,
/// the animation found by name.
fn animation(
    src: &Source<'_>,
    d: &RawDeformer,
    who: &str,
    dir: &Path,
) -> Result<Option<SceneAnimation>> {
    let Some(name) = &d.animation else {
        let lone = [
            (
                "animation_speed",
                d.animation_speed.as_ref().map(Spanned::span),
            ),
            ("loop", d.looping.as_ref().map(Spanned::span)),
        ];
        if let Some((key, Some(span))) = lone.into_iter().find(|(_, s)| s.is_some()) {
            return Err(src.error(
                &span,
                format!("{who} has {key} {} but no animation", src.quote(&span)),
                format!(
                    "add animation = \"NAME\" (an animation of the mesh file), or remove {key}"
                ),
            ));
        }
        return Ok(None);
    };
    // `path` is there: the shape was read first.
    let Some(path) = &d.path else {
        return Ok(None);
    };
    let skinned = skinned_mesh(src, path, who, dir)?;
    let Some(index) = skinned.animation_index(name.get_ref()) else {
        return Err(src.error(
            &name.span(),
            format!(
                "{who} has animation {}, but {} has no animation of that name (it has: {})",
                src.quote(&name.span()),
                path.get_ref(),
                skinned.animation_names()
            ),
            "name one of the file's animations (an unnamed one by its index, as \"0\")",
        ));
    };
    let speed = match &d.animation_speed {
        Some(v) => number(
            src,
            v,
            who,
            "animation_speed",
            |x| x > 0.0 && x <= 1000.0,
            "animation_speed must be a finite number of animation seconds per second, above 0 and at most 1000",
        )?,
        None => 1.0,
    };
    let playback = match d.looping.as_ref().map(|l| *l.get_ref()) {
        Some(false) => Playback::Clamp,
        _ => Playback::Loop,
    };
    Ok(Some(SceneAnimation {
        skinned,
        index,
        name: name.get_ref().clone(),
        speed,
        playback,
    }))
}

/// Backstop: the library's own checks of analytic deformers, at every key.
fn check_analytic(
    src: &Source<'_>,
    table: &Range<usize>,
    shape: &SceneShape,
    keys: &[Key],
    name: &str,
) -> Result<()> {
    let analytic = match *shape {
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
        for k in keys {
            Deformer::new(analytic, k.pose())
                .validate(name)
                .map_err(|e| src.error(table, e, "fix this [[deformer]] table"))?;
        }
    }
    Ok(())
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
