//! Skinned, animated meshes as deformers: the talk's characters pressing the snow with their own
//! meshes.
//!
//! A [`SkinnedMesh`] is read from a glTF or GLB file (`gltf.rs`): its triangles in bind pose, up to
//! four joint influences a vertex, the joints' inverse bind matrices, the node hierarchy and the
//! animations. Each frame the skeleton is posed on the CPU at the animation's time (a few matrices a
//! figure: `cpu.rs` samples the channels and walks the hierarchy), and a compute pass (`encode.rs`,
//! `skin.wgsl`) blends the joint matrices into the vertex buffer the capture draws for the mesh, so
//! that no posed vertex crosses the bus. `cpu.rs` is also the reference the pass is tested against.
//!
//! A mesh node without a skin is kept as well, bound rigidly to its node (one influence, identity
//! inverse bind), so animated rigid parts move with their nodes.

pub(crate) mod cpu;
mod encode;
mod gltf;

use glam::{Mat4, Quat, Vec3, Vec4};

use crate::mesh::Mesh;

pub use cpu::{joint_matrices, node_globals, sample_locals, skin_vertices};
pub use encode::{GpuBindVertex, SKIN_WORKGROUP};
pub(crate) use encode::{SkinGpu, SkinPipeline, encode as record};

/// Most joints a skinned mesh may have (over every skin of the file, and one a rigid mesh node).
pub const MAX_SKIN_JOINTS: usize = 4096;
/// Most keyframes an animation channel may have.
pub const MAX_ANIMATION_KEYS: usize = 1 << 20;

/// A skinned mesh with its skeleton and animations, ready to be posed.
#[derive(Clone, Debug, PartialEq)]
pub struct SkinnedMesh {
    /// The triangles, vertices in bind pose (each primitive's own coordinates, before skinning).
    pub mesh: Mesh,
    /// Per vertex of `mesh`: its four influences.
    pub influences: Vec<Influence>,
    /// The joints the influences name.
    pub joints: Vec<Joint>,
    /// Every node of the file, with its parent and rest transform.
    pub nodes: Vec<Node>,
    /// The file's animations, in file order.
    pub animations: Vec<Animation>,
}

/// Up to four joints that move a vertex, with weights that sum to 1 (unused slots have weight 0).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Influence {
    /// Indices into [`SkinnedMesh::joints`].
    pub joints: [u32; 4],
    /// Their weights, each in `0..=1`, summing to 1.
    pub weights: [f32; 4],
}

/// A joint: a node of the hierarchy and the inverse of its bind-pose global transform.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Joint {
    /// Index of the node in [`SkinnedMesh::nodes`].
    pub node: usize,
    /// Mesh space (bind pose) to the joint's space.
    pub inverse_bind: Mat4,
}

/// A node of the hierarchy.
#[derive(Clone, Debug, PartialEq)]
pub struct Node {
    /// Its name in the file, if it has one.
    pub name: Option<String>,
    /// Index of its parent, `None` for a root.
    pub parent: Option<usize>,
    /// Its transform when no animation moves it.
    pub rest: Trs,
    /// A transform given as a matrix (animations may not target such a node): used instead of
    /// `rest` when present.
    pub matrix: Option<Mat4>,
}

/// Translation, rotation and scale: the local transform `T * R * S` of a node.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Trs {
    /// Translation.
    pub translation: Vec3,
    /// Rotation (unit quaternion).
    pub rotation: Quat,
    /// Scale.
    pub scale: Vec3,
}

impl Trs {
    /// The identity.
    pub const IDENTITY: Trs = Trs {
        translation: Vec3::ZERO,
        rotation: Quat::IDENTITY,
        scale: Vec3::ONE,
    };

    /// `T * R * S` as a matrix.
    pub fn matrix(&self) -> Mat4 {
        Mat4::from_scale_rotation_translation(self.scale, self.rotation, self.translation)
    }
}

/// One animation: channels that move nodes' translations, rotations and scales over time.
#[derive(Clone, Debug, PartialEq)]
pub struct Animation {
    /// Its name in the file, if it has one.
    pub name: Option<String>,
    /// Its channels.
    pub channels: Vec<Channel>,
    /// Time of its last key over every channel, seconds (the loop's period).
    pub duration: f32,
}

/// What a channel moves.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Property {
    /// The node's translation (values `[x, y, z, 0]`).
    Translation,
    /// The node's rotation (values quaternions `[x, y, z, w]`).
    Rotation,
    /// The node's scale (values `[x, y, z, 0]`).
    Scale,
}

/// How a channel's values are interpolated between keys (glTF's `interpolation`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Interpolation {
    /// Linear (spherical linear for rotations).
    Linear,
    /// The value of the key at or before the time.
    Step,
    /// Cubic Hermite spline: each key holds an in-tangent, a value and an out-tangent.
    CubicSpline,
}

/// One animated property of one node.
#[derive(Clone, Debug, PartialEq)]
pub struct Channel {
    /// Index of the node in [`SkinnedMesh::nodes`].
    pub node: usize,
    /// What it moves.
    pub property: Property,
    /// How it interpolates.
    pub interpolation: Interpolation,
    /// Key times, seconds, strictly increasing.
    pub times: Vec<f32>,
    /// One value a key (three for [`Interpolation::CubicSpline`]: in-tangent, value, out-tangent).
    pub values: Vec<Vec4>,
}

/// How an animation's time runs past its end.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Playback {
    /// Start again: time modulo the duration.
    Loop,
    /// Hold the last pose.
    Clamp,
}

impl Animation {
    /// The time within the animation for a time since it started: wrapped for
    /// [`Playback::Loop`], held at the ends for [`Playback::Clamp`] (before 0 is 0).
    pub fn local_time(&self, t: f32, playback: Playback) -> f32 {
        if !t.is_finite() || t <= 0.0 || self.duration <= 0.0 {
            return 0.0;
        }
        match playback {
            Playback::Loop => t.rem_euclid(self.duration),
            Playback::Clamp => t.min(self.duration),
        }
    }
}

impl SkinnedMesh {
    /// The index of the animation called `name`; an unnamed animation is also found by its index
    /// written in decimal (`"0"`).
    pub fn animation_index(&self, name: &str) -> Option<usize> {
        self.animations
            .iter()
            .position(|a| a.name.as_deref() == Some(name))
            .or_else(|| {
                name.parse::<usize>()
                    .ok()
                    .filter(|&i| i < self.animations.len())
            })
    }

    /// The animations' names as a user would write them, for messages: quoted names, and the
    /// index of each unnamed one.
    pub fn animation_names(&self) -> String {
        if self.animations.is_empty() {
            return "none".to_owned();
        }
        self.animations
            .iter()
            .enumerate()
            .map(|(i, a)| match &a.name {
                Some(n) => format!("{n:?}"),
                None => format!("\"{i}\" (unnamed)"),
            })
            .collect::<Vec<_>>()
            .join(", ")
    }

    /// The mesh in its rest pose (the nodes' rest transforms), after checking that every vertex
    /// has influences naming joints the skin has and that the posed mesh is usable as a deformer.
    ///
    /// # Errors
    ///
    /// [`crate::SnowError::InvalidMesh`] naming mesh `name` and what is wrong.
    pub fn rest_mesh(&self, name: &str) -> crate::Result<Mesh> {
        self.mesh.validate(name)?;
        let invalid = |reason: String| crate::SnowError::InvalidMesh {
            name: name.to_owned(),
            reason,
        };
        if self.influences.len() != self.mesh.positions.len() {
            return Err(invalid(format!(
                "has {} influences for {} vertices; give every vertex its influences",
                self.influences.len(),
                self.mesh.positions.len()
            )));
        }
        let joints = self.joints.len() as u32;
        if let Some(bad) = self
            .influences
            .iter()
            .find(|i| i.joints.iter().any(|&j| j >= joints))
        {
            return Err(invalid(format!(
                "names joint {:?} but has {joints} joints",
                bad.joints
            )));
        }
        let rest = self.pose(None, 0.0, Playback::Clamp);
        let rest_mesh = Mesh {
            positions: skin_vertices(&self.mesh.positions, &self.influences, &rest),
            indices: self.mesh.indices.clone(),
        };
        rest_mesh.validate(name)?;
        Ok(rest_mesh)
    }

    /// The joint matrices (`global * inverse bind`) of `animation` at time `t` (seconds since it
    /// started, run past its end by `playback`); `None` poses the rest transforms.
    pub fn pose(&self, animation: Option<usize>, t: f32, playback: Playback) -> Vec<Mat4> {
        let sampled = animation
            .and_then(|a| self.animations.get(a))
            .map(|a| (a, a.local_time(t, playback)));
        let locals = sample_locals(&self.nodes, sampled);
        let globals = node_globals(&self.nodes, &locals);
        joint_matrices(&self.joints, &globals)
    }

    /// Bounds of the vertices each joint moves, for [`SkinnedMesh::posed_radius`].
    pub fn joint_bounds(&self) -> Vec<(Vec3, f32)> {
        let mut lo = vec![Vec3::splat(f32::INFINITY); self.joints.len()];
        let mut hi = vec![Vec3::splat(f32::NEG_INFINITY); self.joints.len()];
        for (p, inf) in self.mesh.positions.iter().zip(&self.influences) {
            for (&j, &w) in inf.joints.iter().zip(&inf.weights) {
                if w > 0.0 && (j as usize) < lo.len() {
                    lo[j as usize] = lo[j as usize].min(*p);
                    hi[j as usize] = hi[j as usize].max(*p);
                }
            }
        }
        let mut bounds: Vec<(Vec3, f32)> = lo
            .iter()
            .zip(&hi)
            .map(|(&l, &h)| {
                if l.x > h.x {
                    return (Vec3::ZERO, -1.0);
                }
                let c = (l + h) * 0.5;
                (c, 0.0)
            })
            .collect();
        for (p, inf) in self.mesh.positions.iter().zip(&self.influences) {
            for (&j, &w) in inf.joints.iter().zip(&inf.weights) {
                if let Some(b) = bounds.get_mut(j as usize).filter(|_| w > 0.0) {
                    b.1 = b.1.max(p.distance(b.0));
                }
            }
        }
        bounds
    }

    /// A radius that holds every skinned vertex for these joint matrices: a skinned vertex is a
    /// weighted mean (weights of at least 0 that sum to 1) of its joints' images of it, so it lies
    /// within the farthest of the joints' images of their vertices' bounding balls (a ball of
    /// radius `r` maps into one of radius `r` times the matrix's Frobenius norm, which bounds its
    /// largest stretch).
    pub fn posed_radius(bounds: &[(Vec3, f32)], joints: &[Mat4]) -> f32 {
        bounds
            .iter()
            .zip(joints)
            .filter(|(b, _)| b.1 >= 0.0)
            .map(|(&(c, r), m)| {
                let a = glam::Mat3::from_mat4(*m);
                let stretch = (a.x_axis.length_squared()
                    + a.y_axis.length_squared()
                    + a.z_axis.length_squared())
                .sqrt();
                m.transform_point3(c).length() + stretch * r
            })
            .fold(0.0, f32::max)
    }
}
