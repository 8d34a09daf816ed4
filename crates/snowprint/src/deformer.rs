//! Deformers: whatever presses into the snow. Analytic primitives (sphere, capsule, box) for cheap
//! crowds, and triangle meshes (static, or posed each frame) for characters and props.

use glam::{Quat, Vec3};

use crate::error::{Result, SnowError};
use crate::mesh::MeshId;

/// Largest size of a deformer, metres: a radius, a capsule's half height, a box's half extent, or a
/// mesh vertex's distance from the mesh's origin. Up to it the capture places a shape to within
/// 50 um of its exact surface (measured at 1000 m on lavapipe: spheres and boxes within 0.01 um, a
/// capsule's straight part 26 um; `tests/gpu_core.rs`, `huge_shapes_*`); beyond it, the spacing of
/// 32-bit floats near the shape's size would move the imprint, so larger shapes are refused.
pub const MAX_DEFORMER_SIZE: f32 = 1000.0;

/// The geometry of a deformer, in its own frame (centred on its pose's position).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Shape {
    /// A ball.
    Sphere {
        /// Radius, metres.
        radius: f32,
    },
    /// A capsule along its local `Y` axis: a segment from `-half_height` to `+half_height` swept
    /// by a ball of `radius`.
    Capsule {
        /// Radius, metres.
        radius: f32,
        /// Half the length of the inner segment, metres.
        half_height: f32,
    },
    /// A box.
    Box {
        /// Half of each side, metres.
        half_extents: Vec3,
    },
    /// A closed triangle mesh registered with [`crate::SnowWorld::add_mesh`].
    Mesh(MeshId),
}

impl Shape {
    /// Radius of a ball around the shape's origin that holds it (meshes report their bound from
    /// the world, so this is `None` for them).
    pub fn bounding_radius(&self) -> Option<f32> {
        match *self {
            Shape::Sphere { radius } => Some(radius),
            Shape::Capsule {
                radius,
                half_height,
            } => Some(radius + half_height),
            Shape::Box { half_extents } => Some(half_extents.length()),
            Shape::Mesh(_) => None,
        }
    }
}

/// Position and rotation of a deformer in the world.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Pose {
    /// World position of the shape's origin, metres.
    pub position: Vec3,
    /// World rotation.
    pub rotation: Quat,
}

impl Pose {
    /// A pose at a position, not rotated.
    pub fn at(position: [f32; 3]) -> Self {
        Self {
            position: Vec3::from(position),
            rotation: Quat::IDENTITY,
        }
    }

    /// Interpolate between two poses (linear position, spherical rotation).
    pub fn lerp(&self, other: &Pose, t: f32) -> Pose {
        Pose {
            position: self.position.lerp(other.position, t),
            rotation: self.rotation.slerp(other.rotation, t),
        }
    }
}

/// One deformer as seen in one frame.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Deformer {
    /// Its geometry.
    pub shape: Shape,
    /// Where it is at the end of the frame.
    pub pose: Pose,
    /// Where it was at the end of the previous frame. When set, analytic shapes are swept from
    /// there to `pose`, so that a fast foot or a slide leaves a continuous trench rather than a row
    /// of dents. Meshes are captured at `pose` only.
    pub previous: Option<Pose>,
}

impl Deformer {
    /// A deformer at rest.
    pub fn new(shape: Shape, pose: Pose) -> Self {
        Self {
            shape,
            pose,
            previous: None,
        }
    }

    /// A deformer that moved from `previous` to `pose` during the frame.
    pub fn moving(shape: Shape, previous: Pose, pose: Pose) -> Self {
        Self {
            shape,
            pose,
            previous: Some(previous),
        }
    }

    /// Check sizes and poses are finite and positive where they must be.
    pub fn validate(&self, name: &str) -> Result<()> {
        self.validate_named(|| name.to_owned())
    }

    /// [`Self::validate`] naming the deformer only when it is refused (a world checks every
    /// deformer of every frame: formatting each name costs more than the check).
    pub(crate) fn validate_named(&self, name: impl Fn() -> String) -> Result<()> {
        let bad = |what: &'static str, value: String, expected: &'static str| {
            Err(SnowError::InvalidDeformer {
                name: name(),
                what,
                value,
                expected,
            })
        };
        let positive = |v: f32| v.is_finite() && v > 0.0 && v <= MAX_DEFORMER_SIZE;
        match self.shape {
            Shape::Sphere { radius } if !positive(radius) => {
                return bad(
                    "radius",
                    radius.to_string(),
                    "a finite number of metres above 0 and at most MAX_DEFORMER_SIZE (1000)",
                );
            }
            Shape::Capsule {
                radius,
                half_height,
            } => {
                if !positive(radius) {
                    return bad(
                        "radius",
                        radius.to_string(),
                        "a finite number of metres above 0 and at most MAX_DEFORMER_SIZE (1000)",
                    );
                }
                if !(half_height.is_finite() && (0.0..=MAX_DEFORMER_SIZE).contains(&half_height)) {
                    return bad(
                        "half_height",
                        half_height.to_string(),
                        "a finite number of metres, 0 or more and at most MAX_DEFORMER_SIZE (1000)",
                    );
                }
            }
            Shape::Box { half_extents }
                if !(half_extents.is_finite()
                    && half_extents.min_element() > 0.0
                    && half_extents.max_element() <= MAX_DEFORMER_SIZE) =>
            {
                return bad(
                    "half_extents",
                    format!("{:?}", half_extents.to_array()),
                    "three finite numbers of metres above 0 and at most MAX_DEFORMER_SIZE (1000)",
                );
            }
            _ => {}
        }
        for pose in std::iter::once(&self.pose).chain(self.previous.as_ref()) {
            if !pose.position.is_finite() {
                return bad(
                    "position",
                    format!("{:?}", pose.position.to_array()),
                    "finite",
                );
            }
            if !pose.rotation.is_finite() {
                return bad("rotation", format!("{:?}", pose.rotation), "finite");
            }
        }
        Ok(())
    }
}
