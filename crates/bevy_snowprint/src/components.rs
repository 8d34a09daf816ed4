//! What a game puts on its entities: snow surfaces and the shapes that press them.

use bevy::prelude::*;
use snowprint::glam as sg;

/// A rectangle of deformable snow on the ground. The entity's `GlobalTransform` places it: its
/// translation is the centre of the rectangle on the ground under the snow, its rotation about
/// world +Y turns it (any tilt is ignored: snowprint's surfaces lie flat). The plugin gives the
/// entity a mesh (the box of snow) and a [`crate::SnowMaterial`] drawn with Bevy's lights.
///
/// The surface is created in the snow world the first frame it is seen and removed with the
/// entity (or the component); changing its fields later has no effect (remove and insert it).
#[derive(Component, Clone, Debug)]
#[require(Transform, Visibility)]
pub struct SnowSurface {
    /// Side lengths along local x and z, metres.
    pub size: Vec2,
    /// Depth of fresh snow over the ground, metres.
    pub snow_depth: f32,
    /// Fraction of the snow depth refilled per second while it snows (0: prints stay).
    pub replenish_rate: f32,
    /// What it is made of, and how it looks: [`snowprint::Material::snow`] by default.
    pub material: snowprint::Material,
}

impl SnowSurface {
    /// A surface of `size` metres with `snow_depth` metres of the talk's snow, no snowfall.
    pub fn new(size: Vec2, snow_depth: f32) -> Self {
        Self {
            size,
            snow_depth,
            replenish_rate: 0.0,
            material: snowprint::Material::snow(),
        }
    }

    /// Its heightmap's resolution (texels along x and z): the library's rule, square texels of
    /// max(4 cm, longest side / 512).
    pub fn resolution(&self) -> UVec2 {
        let layout = snowprint::SurfaceLayout::for_size(sg::Vec2::new(self.size.x, self.size.y));
        UVec2::new(layout.width, layout.height)
    }

    /// The library's description of this surface placed by `transform`, named `name`.
    pub fn desc(&self, name: &str, transform: &GlobalTransform) -> snowprint::SurfaceDesc {
        let (_, rotation, translation) = transform.to_scale_rotation_translation();
        let forward = rotation * Vec3::X;
        // Yaw about +Y that turns local +x to `forward` seen from above (counter-clockwise).
        let yaw = (-forward.z).atan2(forward.x);
        snowprint::SurfaceDesc {
            name: name.to_owned(),
            center: sg::Vec3::from_array(translation.to_array()),
            size: sg::Vec2::new(self.size.x, self.size.y),
            yaw_degrees: yaw.to_degrees(),
            snow_depth: self.snow_depth,
            replenish_rate: self.replenish_rate,
            material: self.material,
        }
    }
}

/// The shape of a [`SnowDeformer`], in the entity's local frame (scale is ignored).
#[derive(Clone, Debug, PartialEq)]
pub enum DeformerShape {
    /// A ball of this radius, metres.
    Sphere {
        /// Radius, metres.
        radius: f32,
    },
    /// A capsule along local +Y: a segment from `-half_height` to `+half_height` swept by a ball.
    Capsule {
        /// Radius, metres.
        radius: f32,
        /// Half the length of the inner segment, metres.
        half_height: f32,
    },
    /// A box of these half sides, metres.
    Box {
        /// Half of each side, metres.
        half_extents: Vec3,
    },
    /// A closed triangle mesh of Bevy's (a triangle list, wound counter-clockwise seen from
    /// outside, as Bevy's primitives are), registered with the snow world the first frame it is
    /// seen. It must keep its data in the main world (`RenderAssetUsages::MAIN_WORLD`, the
    /// default). On an entity with Bevy's `SkinnedMesh` it is skinned as Bevy skins it (each
    /// joint's `GlobalTransform` times its inverse bind pose, the entity's own transform unused)
    /// by snowprint's skinning pass each frame, before the update.
    Mesh(Handle<Mesh>),
}

impl DeformerShape {
    /// The library's shape, for the analytic shapes (`None` for a mesh, which the render world
    /// registers first).
    pub(crate) fn analytic(&self) -> Option<snowprint::Shape> {
        Some(match *self {
            DeformerShape::Sphere { radius } => snowprint::Shape::Sphere { radius },
            DeformerShape::Capsule {
                radius,
                half_height,
            } => snowprint::Shape::Capsule {
                radius,
                half_height,
            },
            DeformerShape::Box { half_extents } => snowprint::Shape::Box {
                half_extents: sg::Vec3::from_array(half_extents.to_array()),
            },
            DeformerShape::Mesh(_) => return None,
        })
    }
}

/// A Bevy mesh as the library's closed triangle list, or why it cannot be one.
pub(crate) fn library_mesh(mesh: &Mesh) -> Result<snowprint::Mesh, String> {
    use bevy::mesh::{PrimitiveTopology, VertexAttributeValues};
    if mesh.primitive_topology() != PrimitiveTopology::TriangleList {
        return Err(format!(
            "is a {:?}; a snow deformer needs a triangle list",
            mesh.primitive_topology()
        ));
    }
    let Some(VertexAttributeValues::Float32x3(positions)) =
        mesh.attribute(Mesh::ATTRIBUTE_POSITION)
    else {
        return Err("has no Float32x3 positions (or they live only in the render world)".into());
    };
    let indices: Vec<u32> = match mesh.indices() {
        Some(indices) => indices.iter().map(|i| i as u32).collect(),
        None => (0..positions.len() as u32).collect(),
    };
    Ok(snowprint::Mesh {
        positions: positions.iter().map(|p| sg::Vec3::from_array(*p)).collect(),
        indices,
    })
}

/// Something that presses the snow: a shape following the entity's `GlobalTransform`. Between
/// two frames it is swept from its last pose to the new one, so a fast foot leaves a trench
/// rather than a row of dents (meshes are pressed where they are, as the library does).
#[derive(Component, Clone, Debug, PartialEq)]
#[require(Transform)]
pub struct SnowDeformer {
    /// Its geometry, in the entity's frame.
    pub shape: DeformerShape,
}

impl SnowDeformer {
    /// A ball of `radius` metres.
    pub fn sphere(radius: f32) -> Self {
        Self {
            shape: DeformerShape::Sphere { radius },
        }
    }

    /// A capsule along local +Y.
    pub fn capsule(radius: f32, half_height: f32) -> Self {
        Self {
            shape: DeformerShape::Capsule {
                radius,
                half_height,
            },
        }
    }

    /// A box of half sides `half_extents`.
    pub fn cuboid(half_extents: Vec3) -> Self {
        Self {
            shape: DeformerShape::Box { half_extents },
        }
    }

    /// A closed triangle mesh of Bevy's (see [`DeformerShape::Mesh`]).
    pub fn mesh(mesh: Handle<Mesh>) -> Self {
        Self {
            shape: DeformerShape::Mesh(mesh),
        }
    }
}

/// A pose of the library's from a Bevy transform (its scale dropped).
pub(crate) fn pose_of(transform: &GlobalTransform) -> snowprint::Pose {
    let (_, rotation, translation) = transform.to_scale_rotation_translation();
    snowprint::Pose {
        position: sg::Vec3::from_array(translation.to_array()),
        rotation: sg::Quat::from_array(rotation.to_array()),
    }
}

/// A Bevy skinned mesh (joint indices and weights, one inverse bind pose a joint) as the
/// library's skinned mesh: one flat node a joint, its matrices given each frame by the caller
/// (`joint global * inverse bind`, Bevy's own skinning), so no animation of the library's.
pub(crate) fn library_skinned_mesh(
    mesh: &Mesh,
    inverse_bindposes: &[Mat4],
) -> Result<snowprint::SkinnedMesh, String> {
    use bevy::mesh::VertexAttributeValues;
    use snowprint::skeleton::{Influence, Joint, Node, Trs};
    let triangles = library_mesh(mesh)?;
    let Some(VertexAttributeValues::Uint16x4(joints)) = mesh.attribute(Mesh::ATTRIBUTE_JOINT_INDEX)
    else {
        return Err("has no Uint16x4 joint indices".into());
    };
    let Some(VertexAttributeValues::Float32x4(weights)) =
        mesh.attribute(Mesh::ATTRIBUTE_JOINT_WEIGHT)
    else {
        return Err("has no Float32x4 joint weights".into());
    };
    let influences = joints
        .iter()
        .zip(weights)
        .map(|(j, w)| Influence {
            joints: j.map(u32::from),
            weights: *w,
        })
        .collect();
    Ok(snowprint::SkinnedMesh {
        mesh: triangles,
        influences,
        joints: inverse_bindposes
            .iter()
            .enumerate()
            .map(|(node, m)| Joint {
                node,
                inverse_bind: sg::Mat4::from_cols_array(&m.to_cols_array()),
            })
            .collect(),
        nodes: (0..inverse_bindposes.len())
            .map(|_| Node {
                name: None,
                parent: None,
                rest: Trs::IDENTITY,
                matrix: None,
            })
            .collect(),
        animations: Vec::new(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A surface turned a quarter turn counter-clockwise seen from above has a yaw of +90
    /// degrees, the library's convention (`Quat::from_rotation_y`).
    #[test]
    fn yaw_follows_the_rotation_about_y() {
        let surface = SnowSurface::new(Vec2::new(4.0, 2.0), 0.3);
        for degrees in [0.0_f32, 30.0, 90.0, -120.0] {
            let t = GlobalTransform::from(
                Transform::from_xyz(1.0, 2.0, 3.0)
                    .with_rotation(Quat::from_rotation_y(degrees.to_radians())),
            );
            let desc = surface.desc("s", &t);
            assert!(
                (desc.yaw_degrees - degrees).abs() < 1e-3,
                "{degrees}: {}",
                desc.yaw_degrees
            );
            assert_eq!(desc.center.to_array(), [1.0, 2.0, 3.0]);
        }
    }

    /// The resolution is the library's: 4 cm texels on an 8 m x 6 m surface.
    #[test]
    fn resolution_is_the_librarys() {
        assert_eq!(
            SnowSurface::new(Vec2::new(8.0, 6.0), 0.3).resolution(),
            UVec2::new(200, 150)
        );
    }
}
