//! The CPU side of skinning, and the reference the GPU pass is tested against: sample an
//! animation's channels at a time, walk the node hierarchy to global transforms, multiply by the
//! inverse bind matrices, and blend each vertex by its four weights (glTF 2.0's skinning, section
//! 3.7.3, and its animation sampling, 3.11 and appendix C for the cubic spline).

use glam::{Mat4, Quat, Vec3, Vec4};

use super::{Animation, Channel, Influence, Interpolation, Joint, Node, Property, Trs};

/// Every node's local transform: its rest transform, with the channels of `animation` (sampled at
/// the given time within it) replacing the properties they move.
pub fn sample_locals(nodes: &[Node], animation: Option<(&Animation, f32)>) -> Vec<Mat4> {
    let mut trs: Vec<Trs> = nodes.iter().map(|n| n.rest).collect();
    if let Some((anim, t)) = animation {
        for c in &anim.channels {
            let Some(node) = trs.get_mut(c.node) else {
                continue;
            };
            let v = sample(c, t);
            match c.property {
                Property::Translation => node.translation = v.truncate(),
                Property::Rotation => node.rotation = Quat::from_vec4(v).normalize(),
                Property::Scale => node.scale = v.truncate(),
            }
        }
    }
    nodes
        .iter()
        .zip(&trs)
        .map(|(n, t)| n.matrix.unwrap_or_else(|| t.matrix()))
        .collect()
}

/// A channel's value at time `t`: the first key's before it, the last key's after it.
pub fn sample(c: &Channel, t: f32) -> Vec4 {
    let n = c.times.len();
    let cubic = c.interpolation == Interpolation::CubicSpline;
    // The key's value: the middle of three for a cubic spline.
    let value = |k: usize| {
        if cubic {
            c.values[3 * k + 1]
        } else {
            c.values[k]
        }
    };
    if n == 0 {
        return Vec4::ZERO;
    }
    if t.is_nan() || t <= c.times[0] {
        return value(0);
    }
    if t >= c.times[n - 1] {
        return value(n - 1);
    }
    // times[k] <= t < times[k + 1].
    let k = c.times.partition_point(|&x| x <= t) - 1;
    let (t0, t1) = (c.times[k], c.times[k + 1]);
    let dt = t1 - t0;
    let s = (t - t0) / dt;
    match c.interpolation {
        Interpolation::Step => value(k),
        Interpolation::Linear if c.property == Property::Rotation => {
            let a = Quat::from_vec4(value(k)).normalize();
            let b = Quat::from_vec4(value(k + 1)).normalize();
            Vec4::from(a.slerp(b, s))
        }
        Interpolation::Linear => value(k).lerp(value(k + 1), s),
        Interpolation::CubicSpline => {
            // p(s) = (2s^3 - 3s^2 + 1) v0 + (s^3 - 2s^2 + s) dt b0 + (-2s^3 + 3s^2) v1
            //        + (s^3 - s^2) dt a1, with b0 key k's out-tangent and a1 key k+1's in-tangent.
            let (s2, s3) = (s * s, s * s * s);
            let v0 = c.values[3 * k + 1];
            let b0 = c.values[3 * k + 2];
            let a1 = c.values[3 * (k + 1)];
            let v1 = c.values[3 * (k + 1) + 1];
            let p = v0 * (2.0 * s3 - 3.0 * s2 + 1.0)
                + b0 * (dt * (s3 - 2.0 * s2 + s))
                + v1 * (-2.0 * s3 + 3.0 * s2)
                + a1 * (dt * (s3 - s2));
            if c.property == Property::Rotation {
                p.normalize_or(Vec4::W)
            } else {
                p
            }
        }
    }
}

/// Global transforms from local ones: each node's parent's global times its local. The nodes form
/// trees (checked when the file is read), so following parents ends.
pub fn node_globals(nodes: &[Node], locals: &[Mat4]) -> Vec<Mat4> {
    let mut globals: Vec<Option<Mat4>> = vec![None; nodes.len()];
    let mut chain = Vec::new();
    for start in 0..nodes.len() {
        // Climb to a node already known (or a root), then come back down.
        let mut at = Some(start);
        while let Some(i) = at {
            if globals[i].is_some() {
                break;
            }
            chain.push(i);
            at = nodes[i].parent;
        }
        let mut above = at.and_then(|i| globals[i]).unwrap_or(Mat4::IDENTITY);
        while let Some(i) = chain.pop() {
            above *= locals[i];
            globals[i] = Some(above);
        }
    }
    globals
        .into_iter()
        .map(|g| g.unwrap_or(Mat4::IDENTITY))
        .collect()
}

/// Each joint's matrix: its node's global transform times its inverse bind matrix.
pub fn joint_matrices(joints: &[Joint], globals: &[Mat4]) -> Vec<Mat4> {
    joints
        .iter()
        .map(|j| globals.get(j.node).copied().unwrap_or(Mat4::IDENTITY) * j.inverse_bind)
        .collect()
}

/// Skinned vertices: each bind-pose vertex moved by the weighted sum of its joints' matrices.
pub fn skin_vertices(bind: &[Vec3], influences: &[Influence], joints: &[Mat4]) -> Vec<Vec3> {
    bind.iter()
        .zip(influences)
        .map(|(&p, inf)| {
            let mut out = Vec3::ZERO;
            for (&j, &w) in inf.joints.iter().zip(&inf.weights) {
                if w != 0.0 {
                    let m = joints.get(j as usize).copied().unwrap_or(Mat4::IDENTITY);
                    out += w * m.transform_point3(p);
                }
            }
            out
        })
        .collect()
}
