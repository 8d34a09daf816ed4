//! The demo's body as a skinned glTF (GLB): one mesh of the fifteen part meshes, each vertex bound
//! with weight 1 to its part's joint, a skin of fifteen joint nodes in the body's tree, and an
//! animation sampled from a [`Motion`] (the pelvis's translation and every joint's rotation, linear
//! keys). Loaded by the library's glTF loader, it is a skinned mesh deformer that presses what the
//! demo's part shapes press, posed on the GPU: the talk's deformer, a character's own skinned mesh.
//!
//! `scenes/Trudger.glb` is [`trudger_glb`]'s output (a test regenerates it and compares the bytes).

use glam::{Mat4, Quat, Vec2, Vec3};
use serde_json::{Value, json};

use crate::anim::{Action, Gait, GaitStyle, Motion, Segment, StepPlan};
use crate::skeleton::{BodyPose, PART_COUNT, Part, Side, dims, joint_offset, part_mesh};

/// Keys a second of the exported animation.
pub const KEYS_PER_SECOND: u32 = 30;

/// The exported walk: a trudge along `+x` from x = -3 to x = 3 on ground at y = 0, 1 m/s, starting
/// at 0.3 s (the figure's file frame: `+x` forward, `+y` up).
pub fn trudger_motion() -> Motion {
    let (t0, speed, from, to) = (0.3_f32, 1.0_f32, -3.0_f32, 3.0_f32);
    let t1 = t0 + (to - from) / speed;
    let path = move |t: f32| (Vec2::new(from + speed * (t.clamp(t0, t1) - t0), 0.0), 0.0);
    let plan = StepPlan {
        start: t0,
        end: t1,
        step_time: 0.6,
        duty: 0.6,
        lateral: 0.14,
        stagger: 0.0,
        min_stride: 0.5,
        first: Side::Right,
        ground: 0.0,
    };
    Motion {
        segments: vec![Segment {
            start: 0.0,
            blend: 0.0,
            action: Action::Gait(Gait::plan(plan, GaitStyle::trudge(), &path)),
        }],
    }
}

/// Seconds the exported walk lasts: the crossing and the feet coming together.
pub const TRUDGER_SECONDS: f32 = 7.0;

/// `scenes/Trudger.glb`: [`trudger_motion`] over [`TRUDGER_SECONDS`], animation `"walk"`.
pub fn trudger_glb() -> Vec<u8> {
    let motion = trudger_motion();
    body_glb(&|t| motion.pose(t), TRUDGER_SECONDS, "walk")
}

/// The bind pose: standing straight, facing `+x`, soles on y = 0.
pub fn bind_pose() -> BodyPose {
    BodyPose::standing(Vec3::new(0.0, dims::PELVIS_HEIGHT, 0.0), 0.0)
}

/// A GLB of the body skinned to its joints, with one animation `name` sampling `pose` from 0 to
/// `seconds` at [`KEYS_PER_SECOND`].
pub fn body_glb(pose: &dyn Fn(f32) -> BodyPose, seconds: f32, name: &str) -> Vec<u8> {
    let mut bin = Bin::default();
    let bind = bind_pose();
    let bind_world = bind.world();
    // The mesh: every part's vertices moved to the bind pose, bound to the part's joint.
    let (mut positions, mut joints, mut indices) = (Vec::new(), Vec::new(), Vec::new());
    for part in Part::ALL {
        let m = part_mesh(part);
        let base = positions.len() as u32;
        let w = bind_world[part.index()];
        positions.extend(m.positions.iter().map(|&p| w.position + w.rotation * p));
        joints.extend(std::iter::repeat_n(part.index() as u8, m.positions.len()));
        indices.extend(m.indices.iter().map(|i| base + i));
    }
    let count = positions.len();
    let (lo, hi) = positions.iter().fold(
        (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)),
        |(lo, hi), &p| (lo.min(p), hi.max(p)),
    );
    let pos = bin.accessor(
        &floats(positions.iter().flat_map(|p| p.to_array())),
        5126,
        count,
        "VEC3",
    );
    let pos = bin.bounds(pos, &lo.to_array(), &hi.to_array());
    let joint_bytes: Vec<u8> = joints.iter().flat_map(|&j| [j, 0, 0, 0]).collect();
    let jnt = bin.accessor(&joint_bytes, 5121, count, "VEC4");
    let wgt = bin.accessor(
        &floats((0..count).flat_map(|_| [1.0, 0.0, 0.0, 0.0])),
        5126,
        count,
        "VEC4",
    );
    let index_bytes: Vec<u8> = indices.iter().flat_map(|i: &u32| i.to_le_bytes()).collect();
    let idx = bin.accessor(&index_bytes, 5125, indices.len(), "SCALAR");
    let ibm = bin.accessor(
        &floats(bind_world.iter().flat_map(|w| {
            Mat4::from_rotation_translation(w.rotation, w.position)
                .inverse()
                .to_cols_array()
        })),
        5126,
        PART_COUNT,
        "MAT4",
    );
    // The animation: one shared time accessor, the pelvis's translation, every joint's rotation.
    let keys = (seconds * KEYS_PER_SECOND as f32).round() as usize + 1;
    let times: Vec<f32> = (0..keys)
        .map(|k| k as f32 / KEYS_PER_SECOND as f32)
        .collect();
    let poses: Vec<BodyPose> = times.iter().map(|&t| pose(t)).collect();
    let time = bin.accessor(&floats(times.iter().copied()), 5126, keys, "SCALAR");
    let time = bin.bounds(time, &[0.0], &[*times.last().unwrap_or(&0.0)]);
    let mut samplers = Vec::new();
    let mut channels = Vec::new();
    let mut channel = |node: usize, path: &str, output: usize| {
        channels.push(json!({"sampler": samplers.len(), "target": {"node": node, "path": path}}));
        samplers.push(json!({"input": time, "output": output, "interpolation": "LINEAR"}));
    };
    let root = floats(poses.iter().flat_map(|p| p.root.to_array()));
    channel(0, "translation", bin.accessor(&root, 5126, keys, "VEC3"));
    for part in Part::ALL {
        let mut previous = Quat::IDENTITY;
        // Consecutive keys on the same hemisphere, so that linear keys never turn the long way.
        let q = floats(poses.iter().flat_map(|p| {
            let q = p.get(part);
            previous = if q.dot(previous) < 0.0 { -q } else { q };
            previous.to_array()
        }));
        channel(
            part.index(),
            "rotation",
            bin.accessor(&q, 5126, keys, "VEC4"),
        );
    }
    // The node tree: the fifteen joints in [`Part::ALL`] order (parents first), then the mesh.
    let mut nodes: Vec<Value> = Part::ALL
        .iter()
        .map(|&part| {
            let t = if part == Part::Pelvis {
                bind.root
            } else {
                joint_offset(part)
            };
            let children: Vec<usize> = Part::ALL
                .iter()
                .filter(|c| c.parent() == Some(part))
                .map(|c| c.index())
                .collect();
            let mut n = json!({
                "name": part.name(),
                "translation": t.to_array(),
                "rotation": bind.get(part).to_array(),
            });
            if !children.is_empty() {
                n["children"] = json!(children);
            }
            n
        })
        .collect();
    nodes.push(json!({"name": "body", "mesh": 0, "skin": 0}));
    let doc = json!({
        "asset": {"version": "2.0", "generator": "snowprint-demo export"},
        "scene": 0,
        "scenes": [{"nodes": [0, PART_COUNT]}],
        "nodes": nodes,
        "meshes": [{"name": "body", "primitives": [{
            "attributes": {"POSITION": pos, "JOINTS_0": jnt, "WEIGHTS_0": wgt},
            "indices": idx,
        }]}],
        "skins": [{"joints": (0..PART_COUNT).collect::<Vec<_>>(), "inverseBindMatrices": ibm, "skeleton": 0}],
        "animations": [{"name": name, "samplers": samplers, "channels": channels}],
        "accessors": bin.accessors,
        "bufferViews": bin.views,
        "buffers": [{"byteLength": bin.bytes.len()}],
    });
    glb(&serde_json::to_vec(&doc).unwrap_or_default(), &bin.bytes)
}

fn floats(v: impl IntoIterator<Item = f32>) -> Vec<u8> {
    v.into_iter().flat_map(f32::to_le_bytes).collect()
}

/// The binary chunk being filled, with its buffer views and accessors (one view each).
#[derive(Default)]
struct Bin {
    bytes: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
}

impl Bin {
    /// Add an accessor of `count` elements over `data`; its index.
    fn accessor(&mut self, data: &[u8], component: u32, count: usize, kind: &str) -> usize {
        while !self.bytes.len().is_multiple_of(4) {
            self.bytes.push(0);
        }
        self.views.push(json!({
            "buffer": 0,
            "byteOffset": self.bytes.len(),
            "byteLength": data.len(),
        }));
        self.bytes.extend_from_slice(data);
        self.accessors.push(json!({
            "bufferView": self.views.len() - 1,
            "componentType": component,
            "count": count,
            "type": kind,
        }));
        self.accessors.len() - 1
    }

    /// Give accessor `index` its bounds (required of positions and animation inputs).
    fn bounds(&mut self, index: usize, min: &[f32], max: &[f32]) -> usize {
        self.accessors[index]["min"] = json!(min);
        self.accessors[index]["max"] = json!(max);
        index
    }
}

/// A GLB container: the JSON chunk padded with spaces, the binary chunk with zeros.
fn glb(json: &[u8], bin: &[u8]) -> Vec<u8> {
    let pad = |n: usize| n.div_ceil(4) * 4;
    let (jl, bl) = (pad(json.len()), pad(bin.len()));
    let total = 12 + 8 + jl + 8 + bl;
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(jl as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(json);
    out.resize(20 + jl, b' ');
    out.extend_from_slice(&(bl as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(bin);
    out.resize(total, 0);
    out
}
