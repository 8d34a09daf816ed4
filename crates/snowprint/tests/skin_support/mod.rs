//! A tiny skinned glTF built by hand for the skinning tests, its GLB form, and the path of the
//! Khronos RiggedFigure sample (CC-BY 4.0, `scenes/RiggedFigure.README.md`).
//!
//! The file: node 0 "hip" (a joint at the origin), its child node 1 "knee" (a joint at (0, 1, 0)),
//! node 2 the mesh, translated by (100, 0, 0) (which a skinned mesh ignores), skinned by skin 0
//! (joints [hip, knee], inverse bind matrices the identity and a translation by (0, -1, 0)).
//! Three vertices: (0, 0.5, 0) on the hip, (0, 1.5, 0) on the knee, (1, 1.5, 0) half on each
//! (weights as normalized unsigned bytes 128 and 128). Animation 0 "bend": the knee's rotation
//! LINEAR from the identity at 0 s to a quarter turn about +Z at 2 s, the hip's translation STEP
//! from (0, 0, 0) at 0 s to (2, 0, 0) at 1 s. Animation 1 "grow": the hip's scale CUBICSPLINE,
//! keys at 0 s and 1 s, values 1 and 3, out-tangent of the first key 1, in-tangent of the second 2
//! (the other tangents 0).

#![allow(dead_code)]

use std::path::PathBuf;

use serde_json::json;

/// Variations of the file, each breaking one rule (the default breaks none).
#[derive(Clone, Debug)]
pub struct TwoJoints {
    /// Add JOINTS_1 and WEIGHTS_1 (a fifth to eighth influence).
    pub joints_1: bool,
    /// Give the primitive a morph target.
    pub morph_target: bool,
    /// The joint of vertex 2's second influence (1 is valid).
    pub joint_index: u8,
    /// Key times of the knee's rotation.
    pub times: [f32; 2],
    /// Give the knee a matrix instead of a translation (the animation then targets a matrix node).
    pub knee_matrix: bool,
    /// Give vertex 0 all-zero weights.
    pub weights_sum_zero: bool,
}

impl Default for TwoJoints {
    fn default() -> Self {
        Self {
            joints_1: false,
            morph_target: false,
            joint_index: 1,
            times: [0.0, 2.0],
            knee_matrix: false,
            weights_sum_zero: false,
        }
    }
}

/// Little-endian bytes with bufferViews recorded as they are appended.
#[derive(Default)]
struct Bin {
    bytes: Vec<u8>,
    views: Vec<serde_json::Value>,
}

impl Bin {
    /// Append bytes (4-aligned) as a new bufferView; its index.
    fn view(&mut self, data: &[u8]) -> usize {
        while !self.bytes.len().is_multiple_of(4) {
            self.bytes.push(0);
        }
        self.views.push(json!({
            "buffer": 0, "byteOffset": self.bytes.len(), "byteLength": data.len()
        }));
        self.bytes.extend_from_slice(data);
        self.views.len() - 1
    }

    fn floats(&mut self, f: &[f32]) -> usize {
        let b: Vec<u8> = f.iter().flat_map(|x| x.to_le_bytes()).collect();
        self.view(&b)
    }
}

/// The file as glTF JSON with its buffer as a data URI.
pub fn two_joints(o: &TwoJoints) -> Vec<u8> {
    let mut bin = Bin::default();
    let s = std::f32::consts::FRAC_1_SQRT_2;
    let pos = bin.floats(&[0.0, 0.5, 0.0, 0.0, 1.5, 0.0, 1.0, 1.5, 0.0]);
    let idx = bin.view(&[0, 0, 1, 0, 2, 0]);
    let joints = bin.view(&[0, 0, 0, 0, 1, 0, 0, 0, 0, o.joint_index, 0, 0]);
    let w0 = if o.weights_sum_zero { 0 } else { 255 };
    let weights = bin.view(&[w0, 0, 0, 0, 255, 0, 0, 0, 128, 128, 0, 0]);
    let mut ibm = glam::Mat4::IDENTITY.to_cols_array().to_vec();
    ibm.extend(glam::Mat4::from_translation(glam::Vec3::new(0.0, -1.0, 0.0)).to_cols_array());
    let ibm = bin.floats(&ibm);
    let bend_t = bin.floats(&o.times);
    let bend_r = bin.floats(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, s, s]);
    let step_t = bin.floats(&[0.0, 1.0]);
    let step_v = bin.floats(&[0.0, 0.0, 0.0, 2.0, 0.0, 0.0]);
    let grow_t = bin.floats(&[0.0, 1.0]);
    #[rustfmt::skip]
    let grow_v = bin.floats(&[
        0.0, 0.0, 0.0,  1.0, 1.0, 1.0,  1.0, 1.0, 1.0, // key 0: in, value, out
        2.0, 2.0, 2.0,  3.0, 3.0, 3.0,  0.0, 0.0, 0.0, // key 1: in, value, out
    ]);
    let morph = bin.floats(&[0.0; 9]);
    let acc = |view: usize, ty: u32, count: usize, kind: &str| json!({"bufferView": view, "componentType": ty, "count": count, "type": kind});
    let mut accessors = vec![
        acc(pos, 5126, 3, "VEC3"),
        acc(idx, 5123, 3, "SCALAR"),
        acc(joints, 5121, 3, "VEC4"),
        acc(weights, 5121, 3, "VEC4"),
        acc(ibm, 5126, 2, "MAT4"),
        acc(bend_t, 5126, 2, "SCALAR"),
        acc(bend_r, 5126, 2, "VEC4"),
        acc(step_t, 5126, 2, "SCALAR"),
        acc(step_v, 5126, 2, "VEC3"),
        acc(grow_t, 5126, 2, "SCALAR"),
        acc(grow_v, 5126, 6, "VEC3"),
        acc(morph, 5126, 3, "VEC3"),
    ];
    accessors[0]["min"] = json!([0.0, 0.5, 0.0]);
    accessors[0]["max"] = json!([1.0, 1.5, 0.0]);
    accessors[3]["normalized"] = json!(true);
    accessors[11]["min"] = json!([0.0, 0.0, 0.0]);
    accessors[11]["max"] = json!([0.0, 0.0, 0.0]);
    let mut attributes = json!({"POSITION": 0, "JOINTS_0": 2, "WEIGHTS_0": 3});
    if o.joints_1 {
        attributes["JOINTS_1"] = json!(2);
        attributes["WEIGHTS_1"] = json!(3);
    }
    let mut primitive = json!({"attributes": attributes, "indices": 1});
    if o.morph_target {
        primitive["targets"] = json!([{"POSITION": 11}]);
    }
    let knee = if o.knee_matrix {
        json!({"name": "knee", "matrix": [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,1,0,1]})
    } else {
        json!({"name": "knee", "translation": [0.0, 1.0, 0.0]})
    };
    let doc = json!({
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0, 2]}],
        "nodes": [
            {"name": "hip", "children": [1]},
            knee,
            {"name": "figure", "mesh": 0, "skin": 0, "translation": [100.0, 0.0, 0.0]}
        ],
        "meshes": [{"primitives": [primitive]}],
        "skins": [{"joints": [0, 1], "inverseBindMatrices": 4}],
        "animations": [
            {"name": "bend", "samplers": [
                {"input": 5, "output": 6, "interpolation": "LINEAR"},
                {"input": 7, "output": 8, "interpolation": "STEP"}
            ], "channels": [
                {"sampler": 0, "target": {"node": 1, "path": "rotation"}},
                {"sampler": 1, "target": {"node": 0, "path": "translation"}}
            ]},
            {"name": "grow", "samplers": [
                {"input": 9, "output": 10, "interpolation": "CUBICSPLINE"}
            ], "channels": [
                {"sampler": 0, "target": {"node": 0, "path": "scale"}}
            ]}
        ],
        "accessors": accessors,
        "bufferViews": bin.views,
        "buffers": [{
            "byteLength": bin.bytes.len(),
            "uri": format!("data:application/octet-stream;base64,{}", encode_base64(&bin.bytes))
        }]
    });
    serde_json::to_vec(&doc).unwrap()
}

/// The same file as GLB: the JSON chunk without the buffer's uri, the buffer as the BIN chunk.
pub fn glb(gltf: &[u8]) -> Vec<u8> {
    let mut doc: serde_json::Value = serde_json::from_slice(gltf).unwrap();
    let uri = doc["buffers"][0]["uri"].as_str().unwrap().to_owned();
    let mut bin = decode_data_uri(&uri);
    doc["buffers"][0].as_object_mut().unwrap().remove("uri");
    let mut text = serde_json::to_vec(&doc).unwrap();
    while !text.len().is_multiple_of(4) {
        text.push(b' ');
    }
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let total = 12 + 8 + text.len() + 8 + bin.len();
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(text.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&text);
    out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(&bin);
    out
}

const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

fn encode_base64(data: &[u8]) -> String {
    let mut out = String::new();
    for chunk in data.chunks(3) {
        let b = [
            chunk[0],
            *chunk.get(1).unwrap_or(&0),
            *chunk.get(2).unwrap_or(&0),
        ];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for k in 0..4 {
            if k <= chunk.len() {
                out.push(ALPHABET[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// The bytes of a base64 `data:` URI.
pub fn decode_data_uri(uri: &str) -> Vec<u8> {
    let text = &uri[uri.find(',').unwrap() + 1..];
    let mut out = Vec::new();
    let (mut acc, mut bits) = (0u32, 0);
    for c in text.bytes().filter(|&c| c != b'=') {
        let v = ALPHABET.iter().position(|&a| a == c).unwrap() as u32;
        acc = (acc << 6) | v;
        bits += 6;
        if bits >= 8 {
            bits -= 8;
            out.push((acc >> bits) as u8);
            acc &= (1 << bits) - 1;
        }
    }
    out
}

/// The Khronos RiggedFigure sample, kept in `scenes/` with its attribution
/// (`scenes/RiggedFigure.README.md`).
pub fn rigged_figure() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes/RiggedFigure.gltf")
}
