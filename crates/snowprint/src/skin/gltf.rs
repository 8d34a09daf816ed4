//! Reading a [`SkinnedMesh`] from a glTF or GLB file: the same file rules as static meshes
//! (`mesh/gltf_file`: URIs kept under the folder, sizes bounded, node trees checked, accessors read
//! with checked arithmetic), then skins, vertex influences and animations. What snowprint cannot
//! pose is refused with one sentence: a fifth influence (`JOINTS_1`), morph targets, an animation
//! that targets a node given as a matrix.

use std::path::Path;

use glam::{Mat4, Quat, Vec3, Vec4};
use gltf::accessor::{DataType, Dimensions};

use super::{
    Animation, Channel, Influence, Interpolation, Joint, MAX_ANIMATION_KEYS, MAX_SKIN_JOINTS, Node,
    Property, SkinnedMesh, Trs,
};
use crate::error::Result;
use crate::mesh::Mesh;
use crate::mesh::gltf_file::accessors::{read_components, read_indices, read_positions};
use crate::mesh::gltf_file::{
    MAX_GLTF_TRIANGLES, MAX_GLTF_VERTICES, canonical_files, check_node_trees, file_error, open,
    read_within,
};

impl SkinnedMesh {
    /// Load a glTF or GLB file's mesh nodes (skinned, or bound rigidly to their node), skins and
    /// animations. External buffers are read only from the file's own folder and below.
    ///
    /// # Errors
    ///
    /// As [`Mesh::load_gltf`]; also [`crate::SnowError::MeshFile`] for what cannot be posed: more
    /// than four influences a vertex (`JOINTS_1`), morph targets, joints or weights that do not fit
    /// the vertices, animation channels whose times do not increase.
    pub fn load_gltf(path: &Path) -> Result<SkinnedMesh> {
        let folder = match path.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_owned(),
            _ => std::path::PathBuf::from("."),
        };
        Self::load_gltf_within(path, &folder)
    }

    /// As [`SkinnedMesh::load_gltf`], but the file and every file it names must lie under `root`.
    ///
    /// # Errors
    ///
    /// As [`SkinnedMesh::load_gltf`].
    pub fn load_gltf_within(path: &Path, root: &Path) -> Result<SkinnedMesh> {
        let (bytes, folder, root) = read_within(path, root)?;
        parse(&bytes, path, Some((&folder, &root)))
    }

    /// As [`Mesh::from_gltf_slice`], for a skinned mesh.
    ///
    /// # Errors
    ///
    /// As [`SkinnedMesh::load_gltf`].
    pub fn from_gltf_slice(
        bytes: &[u8],
        name: &Path,
        files: Option<(&Path, &Path)>,
    ) -> Result<SkinnedMesh> {
        let files = canonical_files(name, files)?;
        parse(
            bytes,
            name,
            files.as_ref().map(|(f, r)| (f.as_path(), r.as_path())),
        )
    }
}

fn parse(bytes: &[u8], path: &Path, files: Option<(&Path, &Path)>) -> Result<SkinnedMesh> {
    let err = |reason: String| file_error(path, reason);
    let (doc, buffers) = open(bytes, path, files)?;
    check_node_trees(&doc).map_err(err)?;
    check_skin_indices(doc.as_json()).map_err(err)?;
    let scene = doc
        .default_scene()
        .or_else(|| doc.scenes().next())
        .ok_or_else(|| err("has no scene; add a scene listing the mesh's nodes".into()))?;
    let nodes = read_nodes(&doc);

    let mut out = SkinnedMesh {
        mesh: Mesh::default(),
        influences: Vec::new(),
        joints: Vec::new(),
        nodes,
        animations: Vec::new(),
    };
    // First joint of each skin in `out.joints`, once the skin is met.
    let mut skin_base: Vec<Option<u32>> = vec![None; doc.skins().len()];
    let mut stack: Vec<gltf::Node> = scene.nodes().collect();
    let mut visited = vec![false; doc.nodes().len()];
    while let Some(node) = stack.pop() {
        if std::mem::replace(&mut visited[node.index()], true) {
            return Err(err(format!(
                "scene {} reaches node {} twice (it lists the node, or one of its ancestors, more than once); list each node tree once",
                scene.index(),
                node.index()
            )));
        }
        stack.extend(node.children());
        let Some(gm) = node.mesh() else {
            continue;
        };
        let base = match node.skin() {
            Some(skin) => match skin_base[skin.index()] {
                Some(b) => b,
                None => {
                    let b = add_skin(&mut out.joints, &skin, &buffers)
                        .map_err(|e| err(format!("skin {} {e}", skin.index())))?;
                    skin_base[skin.index()] = Some(b);
                    b
                }
            },
            // A rigid mesh node: one joint, the node itself, with the identity as inverse bind
            // (its vertices are in the node's space).
            None => {
                out.joints.push(Joint {
                    node: node.index(),
                    inverse_bind: Mat4::IDENTITY,
                });
                out.joints.len() as u32 - 1
            }
        };
        if out.joints.len() > MAX_SKIN_JOINTS {
            return Err(err(format!(
                "has more than {MAX_SKIN_JOINTS} joints (over its skins and rigid mesh nodes); simplify the skeleton"
            )));
        }
        let skin_joints = node.skin().map(|s| s.joints().len() as u32);
        for prim in gm.primitives() {
            let what = format!("mesh {} primitive {}", gm.index(), prim.index());
            add_primitive(&mut out, &prim, &buffers, base, skin_joints)
                .map_err(|e| err(format!("{what} {e}")))?;
        }
    }
    if out.mesh.indices.is_empty() {
        return Err(err(
            "holds no triangles; give it a mesh with a triangle primitive".into(),
        ));
    }
    for anim in doc.animations() {
        // The gltf crate unwraps these indices when it follows them: check them first.
        check_indices(doc.as_json(), anim.index())
            .map_err(|e| err(format!("animation {} {e}", anim.index())))?;
        let a = read_animation(&anim, &buffers, &out.nodes)
            .map_err(|e| err(format!("animation {} {e}", anim.index())))?;
        out.animations.push(a);
    }
    out.mesh.validate(&path.display().to_string())?;
    Ok(out)
}

/// Every node's parent and rest transform.
fn read_nodes(doc: &gltf::Document) -> Vec<Node> {
    let mut nodes: Vec<Node> = doc
        .nodes()
        .map(|n| {
            let (matrix, rest) = match n.transform() {
                gltf::scene::Transform::Matrix { matrix } => {
                    (Some(Mat4::from_cols_array_2d(&matrix)), Trs::IDENTITY)
                }
                gltf::scene::Transform::Decomposed {
                    translation,
                    rotation,
                    scale,
                } => (
                    None,
                    Trs {
                        translation: Vec3::from(translation),
                        rotation: Quat::from_array(rotation).normalize(),
                        scale: Vec3::from(scale),
                    },
                ),
            };
            Node {
                name: n.name().map(str::to_owned),
                parent: None,
                rest,
                matrix,
            }
        })
        .collect();
    for n in doc.nodes() {
        for c in n.children() {
            nodes[c.index()].parent = Some(n.index());
        }
    }
    nodes
}

/// Append a skin's joints; the index of its first joint.
fn add_skin(
    joints: &mut Vec<Joint>,
    skin: &gltf::Skin<'_>,
    buffers: &[Vec<u8>],
) -> std::result::Result<u32, String> {
    let count = skin.joints().len();
    if count == 0 || count > MAX_SKIN_JOINTS {
        return Err(format!(
            "has {count} joints; a skin needs 1 to {MAX_SKIN_JOINTS}"
        ));
    }
    let inverse = match skin.inverse_bind_matrices() {
        Some(a) => {
            let m = read_components(
                &a,
                buffers,
                Dimensions::Mat4,
                &[DataType::F32],
                None,
                "MAT4 of FLOAT",
                MAX_SKIN_JOINTS,
            )
            .map_err(|e| format!("has an inverseBindMatrices accessor that {e}"))?;
            if m.len() < count * 16 {
                return Err(format!(
                    "has {} inverse bind matrices for its {count} joints; give one a joint",
                    m.len() / 16
                ));
            }
            m.chunks_exact(16)
                .take(count)
                .map(Mat4::from_cols_slice)
                .collect()
        }
        None => vec![Mat4::IDENTITY; count],
    };
    if let Some(m) = inverse.iter().find(|m| !m.is_finite()) {
        return Err(format!(
            "has an inverse bind matrix that is not finite ({m:?}); export the skin again"
        ));
    }
    let base = joints.len() as u32;
    joints.extend(skin.joints().zip(inverse).map(|(n, inverse_bind)| Joint {
        node: n.index(),
        inverse_bind,
    }));
    Ok(base)
}

/// Append a triangle primitive: positions, indices and influences (`base` is the first joint of
/// its skin, `skin_joints` the skin's joint count; a rigid primitive's vertices all follow joint
/// `base`).
fn add_primitive(
    out: &mut SkinnedMesh,
    prim: &gltf::Primitive<'_>,
    buffers: &[Vec<u8>],
    base: u32,
    skin_joints: Option<u32>,
) -> std::result::Result<(), String> {
    if prim.morph_targets().next().is_some() {
        return Err("has morph targets, which snowprint cannot pose; bake them into the mesh or remove them".into());
    }
    if prim.mode() != gltf::mesh::Mode::Triangles {
        return Ok(());
    }
    let Some(positions) = prim.get(&gltf::Semantic::Positions) else {
        return Ok(());
    };
    if prim.get(&gltf::Semantic::Joints(1)).is_some()
        || prim.get(&gltf::Semantic::Weights(1)).is_some()
    {
        return Err("has JOINTS_1 or WEIGHTS_1, more than 4 influences a vertex, which snowprint does not skin; limit the export to 4 influences a vertex".into());
    }
    let pos = read_positions(&positions, buffers)
        .map_err(|e| format!("has a POSITION accessor that {e}"))?;
    let n = pos.len();
    let indices = match prim.indices() {
        Some(a) => {
            read_indices(&a, buffers).map_err(|e| format!("has an index accessor that {e}"))?
        }
        None => (0..n as u32).collect(),
    };
    if let Some(&i) = indices.iter().find(|&&i| i as usize >= n) {
        return Err(format!(
            "has index {i}, out of range for its {n} vertices; fix the indices"
        ));
    }
    let first = out.mesh.positions.len();
    if first + n > MAX_GLTF_VERTICES
        || (out.mesh.indices.len() + indices.len()) / 3 > MAX_GLTF_TRIANGLES
    {
        return Err(format!(
            "brings the mesh to more than {MAX_GLTF_VERTICES} vertices or {MAX_GLTF_TRIANGLES} triangles; simplify the mesh"
        ));
    }
    let influences = if let Some(joint_count) = skin_joints {
        read_influences(prim, buffers, n, joint_count)?
    } else {
        vec![
            Influence {
                joints: [0; 4],
                weights: [1.0, 0.0, 0.0, 0.0]
            };
            n
        ]
    };
    out.mesh.positions.extend(pos);
    out.mesh
        .indices
        .extend(indices.into_iter().map(|i| first as u32 + i));
    out.influences.extend(influences.into_iter().map(|mut inf| {
        for j in &mut inf.joints {
            *j += base;
        }
        inf
    }));
    Ok(())
}

/// `JOINTS_0` and `WEIGHTS_0` of `n` vertices, joints below `joint_count`, weights normalized to
/// sum to 1.
fn read_influences(
    prim: &gltf::Primitive<'_>,
    buffers: &[Vec<u8>],
    n: usize,
    joint_count: u32,
) -> std::result::Result<Vec<Influence>, String> {
    let (Some(ja), Some(wa)) = (
        prim.get(&gltf::Semantic::Joints(0)),
        prim.get(&gltf::Semantic::Weights(0)),
    ) else {
        return Err("belongs to a skinned node but lacks JOINTS_0 or WEIGHTS_0; export the skin weights with the mesh".into());
    };
    let joints = read_components(
        &ja,
        buffers,
        Dimensions::Vec4,
        &[DataType::U8, DataType::U16],
        Some(false),
        "VEC4 of UNSIGNED_BYTE or UNSIGNED_SHORT",
        MAX_GLTF_VERTICES,
    )
    .map_err(|e| format!("has a JOINTS_0 accessor that {e}"))?;
    let weights = read_components(
        &wa,
        buffers,
        Dimensions::Vec4,
        &[DataType::F32, DataType::U8, DataType::U16],
        Some(true),
        "VEC4 of FLOAT or normalized UNSIGNED_BYTE or UNSIGNED_SHORT",
        MAX_GLTF_VERTICES,
    )
    .map_err(|e| format!("has a WEIGHTS_0 accessor that {e}"))?;
    if joints.len() != 4 * n || weights.len() != 4 * n {
        return Err(format!(
            "has {} joints and {} weights entries for its {n} vertices; give JOINTS_0 and WEIGHTS_0 one entry a vertex",
            joints.len() / 4,
            weights.len() / 4
        ));
    }
    let mut out = Vec::with_capacity(n);
    for (v, (j, w)) in joints
        .chunks_exact(4)
        .zip(weights.chunks_exact(4))
        .enumerate()
    {
        if let Some(&bad) = w.iter().find(|x| !(x.is_finite() && **x >= 0.0)) {
            return Err(format!(
                "gives vertex {v} the weight {bad}; weights must be finite and 0 or more"
            ));
        }
        let sum: f32 = w.iter().sum();
        if sum <= 1e-6 {
            return Err(format!(
                "gives vertex {v} weights that sum to {sum}; every skinned vertex needs a positive weight"
            ));
        }
        let mut inf = Influence {
            joints: [0; 4],
            weights: [0.0; 4],
        };
        for k in 0..4 {
            inf.weights[k] = w[k] / sum;
            // A joint with weight 0 may be anything; point it at joint 0.
            if w[k] > 0.0 {
                let joint = j[k] as u32;
                if joint >= joint_count {
                    return Err(format!(
                        "gives vertex {v} joint {joint}, but its skin has {joint_count} joints; fix JOINTS_0"
                    ));
                }
                inf.joints[k] = joint;
            }
        }
        out.push(inf);
    }
    Ok(out)
}

/// Whether every skin names joints, a skeleton and inverse bind matrices that exist (the gltf
/// crate unwraps them when it follows them).
fn check_skin_indices(json: &gltf::json::Root) -> std::result::Result<(), String> {
    let nodes = json.nodes.len();
    for (k, node) in json.nodes.iter().enumerate() {
        if let Some(skin) = node.skin.map(|s| s.value())
            && skin >= json.skins.len()
        {
            return Err(format!(
                "node {k} uses skin {skin}, but the file has {} skins; fix the node's skin",
                json.skins.len()
            ));
        }
    }
    for (k, skin) in json.skins.iter().enumerate() {
        let bad_node = skin
            .joints
            .iter()
            .map(|j| j.value())
            .chain(skin.skeleton.map(|s| s.value()))
            .find(|&j| j >= nodes);
        if let Some(j) = bad_node {
            return Err(format!(
                "skin {k} names node {j}, but the file has {nodes} nodes; fix the skin's joints"
            ));
        }
        if let Some(a) = skin.inverse_bind_matrices.map(|a| a.value())
            && a >= json.accessors.len()
        {
            return Err(format!(
                "skin {k} has inverse bind matrices accessor {a}, but the file has {} accessors; fix the skin",
                json.accessors.len()
            ));
        }
    }
    Ok(())
}

/// Whether every channel of animation `a` names a sampler, node and accessors that exist.
fn check_indices(json: &gltf::json::Root, a: usize) -> std::result::Result<(), String> {
    let anim = &json.animations[a];
    let accessors = json.accessors.len();
    for (k, ch) in anim.channels.iter().enumerate() {
        if !matches!(ch.target.path, gltf::json::validation::Checked::Valid(_)) {
            return Err(format!(
                "channel {k} has a target path that is not translation, rotation, scale or weights; fix the channel"
            ));
        }
        let node = ch.target.node.value();
        if node >= json.nodes.len() {
            return Err(format!(
                "channel {k} targets node {node}, but the file has {} nodes; fix the channel's target",
                json.nodes.len()
            ));
        }
        let s = ch.sampler.value();
        let Some(sampler) = anim.samplers.get(s) else {
            return Err(format!(
                "channel {k} uses sampler {s}, but the animation has {} samplers; fix the channel's sampler",
                anim.samplers.len()
            ));
        };
        for (what, i) in [
            ("input", sampler.input.value()),
            ("output", sampler.output.value()),
        ] {
            if i >= accessors {
                return Err(format!(
                    "sampler {s} has {what} accessor {i}, but the file has {accessors} accessors; fix the sampler"
                ));
            }
        }
    }
    Ok(())
}

/// One animation: its channels, checked against the nodes.
fn read_animation(
    anim: &gltf::Animation<'_>,
    buffers: &[Vec<u8>],
    nodes: &[Node],
) -> std::result::Result<Animation, String> {
    let mut channels = Vec::new();
    let mut duration: f32 = 0.0;
    for ch in anim.channels() {
        let node = ch.target().node().index();
        let what = format!("channel {}", ch.index());
        let property = match ch.target().property() {
            gltf::animation::Property::Translation => Property::Translation,
            gltf::animation::Property::Rotation => Property::Rotation,
            gltf::animation::Property::Scale => Property::Scale,
            gltf::animation::Property::MorphTargetWeights => {
                return Err(format!(
                    "{what} animates morph target weights, which snowprint cannot pose; remove the channel or bake the morphs"
                ));
            }
        };
        if nodes.get(node).is_some_and(|n| n.matrix.is_some()) {
            return Err(format!(
                "{what} animates node {node}, whose transform is a matrix (glTF allows animating only translation, rotation and scale); export the node with translation, rotation and scale"
            ));
        }
        let sampler = ch.sampler();
        let interpolation = match sampler.interpolation() {
            gltf::animation::Interpolation::Linear => Interpolation::Linear,
            gltf::animation::Interpolation::Step => Interpolation::Step,
            gltf::animation::Interpolation::CubicSpline => Interpolation::CubicSpline,
        };
        let times = read_components(
            &sampler.input(),
            buffers,
            Dimensions::Scalar,
            &[DataType::F32],
            None,
            "SCALAR of FLOAT",
            MAX_ANIMATION_KEYS,
        )
        .map_err(|e| format!("{what} has an input accessor that {e}"))?;
        if let Some(t) = times.iter().find(|t| !(t.is_finite() && **t >= 0.0)) {
            return Err(format!(
                "{what} has key time {t}; key times must be finite seconds, 0 or more"
            ));
        }
        // Finite now, so `<=` is the negation of `>`.
        if let Some(w) = times.windows(2).find(|w| w[1] <= w[0]) {
            return Err(format!(
                "{what} has key times {} then {}; key times must increase strictly, so export the animation again",
                w[0], w[1]
            ));
        }
        let (dims, types, norm, expect): (_, &[DataType], _, _) = match property {
            Property::Rotation => (
                Dimensions::Vec4,
                &[
                    DataType::F32,
                    DataType::I8,
                    DataType::U8,
                    DataType::I16,
                    DataType::U16,
                ],
                Some(true),
                "VEC4 of FLOAT or normalized integers",
            ),
            _ => (Dimensions::Vec3, &[DataType::F32], None, "VEC3 of FLOAT"),
        };
        let raw = read_components(
            &sampler.output(),
            buffers,
            dims,
            types,
            norm,
            expect,
            3 * MAX_ANIMATION_KEYS,
        )
        .map_err(|e| format!("{what} has an output accessor that {e}"))?;
        let values: Vec<Vec4> = match dims {
            Dimensions::Vec4 => raw.chunks_exact(4).map(Vec4::from_slice).collect(),
            _ => raw
                .chunks_exact(3)
                .map(|c| Vec3::from_slice(c).extend(0.0))
                .collect(),
        };
        let per_key = if interpolation == Interpolation::CubicSpline {
            3
        } else {
            1
        };
        if values.len() != per_key * times.len() {
            return Err(format!(
                "{what} has {} output values for {} key times; {:?} needs {per_key} a key",
                values.len(),
                times.len(),
                interpolation
            ));
        }
        if let Some(v) = values.iter().find(|v| !v.is_finite()) {
            return Err(format!(
                "{what} has the value {v:?}, which is not finite; fix the animation"
            ));
        }
        duration = duration.max(*times.last().unwrap_or(&0.0));
        channels.push(Channel {
            node,
            property,
            interpolation,
            times,
            values,
        });
    }
    Ok(Animation {
        name: anim.name().map(str::to_owned),
        channels,
        duration,
    })
}
