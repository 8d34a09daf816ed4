//! The `[camera]` table: a target, an eye clear of it, a field of view.

use std::ops::Range;

use glam::Vec3;

use crate::error::Result;
use crate::scene::SceneCamera;
use crate::scene::diagnose::Source;
use crate::scene::raw::RawCamera;

use super::{number, required, vector};

pub(super) fn camera(src: &Source<'_>, table: Range<usize>, c: RawCamera) -> Result<SceneCamera> {
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
pub(super) fn segment_distance(a: Vec3, b: Vec3, p: Vec3) -> f32 {
    let ab = b - a;
    let len2 = ab.length_squared();
    let f = if len2 > 0.0 {
        ((p - a).dot(ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (a + ab * f - p).length()
}
