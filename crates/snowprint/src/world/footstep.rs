//! Footstep events: a deformer whose lowest point passes from above a surface's snow top to below
//! it during an update, over that surface. Computed on the CPU from the shapes the capture draws
//! (sphere, capsule, box, and meshes from a CPU copy of their vertices kept by the world) and their
//! `previous` and current poses; for sound and effects.
//!
//! A mesh posed with [`crate::SnowWorld::pose_mesh`] is judged with its vertices as last posed at
//! both poses (the capture, too, draws meshes at their current pose only).
//!
//! The snow top is the fresh snow top (ground + [`SurfaceDesc::snow_depth`]; on ground that is not
//! flat, the local top of the texel under the lowest point, [`crate::GroundField`]): a foot that
//! comes down into an older print lands when it passes that height, and its depth is measured from
//! it, at most the snow the texel holds.

use glam::{Mat4, Vec2, Vec3};

use crate::deformer::{Deformer, Pose, Shape};
use crate::ground::GroundField;
use crate::mesh::MeshId;
use crate::surface::{SurfaceDesc, SurfaceId};

/// A deformer landing on a surface during one update (see [`crate::SnowWorld::footsteps`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Footstep {
    /// Index of the deformer in the update's list of that surface's deformers (for
    /// [`crate::SnowWorld::step`], its index in the slice given).
    pub deformer: usize,
    /// The surface it landed on; its [`SurfaceDesc`] names the material (`name`).
    pub surface: SurfaceId,
    /// The deformer's lowest point at the end of the update, world metres.
    pub point: Vec3,
    /// How far below the fresh snow top that point reaches, metres, at most the snow depth.
    pub depth_m: f32,
    /// Speed of the lowest point over the update, metres per second (0 when no time elapsed).
    pub speed: f32,
}

/// The lowest point of a shape at `pose` (the middle of the lowest edge or face when one is
/// level); a mesh's from its vertices as `mesh_vertices` gives them (`None` when it gives none).
pub fn lowest_point<'a>(
    shape: &Shape,
    pose: &Pose,
    mesh_vertices: impl Fn(MeshId) -> Option<&'a [Vec3]>,
) -> Option<Vec3> {
    let down = Vec3::NEG_Y;
    match *shape {
        Shape::Sphere { radius } => Some(pose.position + down * radius),
        Shape::Capsule {
            radius,
            half_height,
        } => {
            let axis = pose.rotation * Vec3::Y * half_height;
            let (a, b) = (pose.position + axis, pose.position - axis);
            let tie = 1e-6 * (1.0 + half_height);
            let end = if (a.y - b.y).abs() <= tie {
                (a + b) * 0.5
            } else if a.y < b.y {
                a
            } else {
                b
            };
            Some(end + down * radius)
        }
        Shape::Box { half_extents } => {
            let corners: [Vec3; 8] = std::array::from_fn(|i| {
                let sign = Vec3::new(
                    if i & 1 == 0 { -1.0 } else { 1.0 },
                    if i & 2 == 0 { -1.0 } else { 1.0 },
                    if i & 4 == 0 { -1.0 } else { 1.0 },
                );
                half_extents * sign
            });
            lowest_vertex(&corners, pose)
        }
        Shape::Mesh(id) => lowest_vertex(mesh_vertices(id)?, pose),
    }
}

/// The lowest of `vertices` (in the shape's frame) at `pose`; several within a millionth of the
/// shape's size of the lowest are averaged (a level edge or face). `None` for no vertices.
fn lowest_vertex(vertices: &[Vec3], pose: &Pose) -> Option<Vec3> {
    let placed = vertices.iter().map(|&v| pose.position + pose.rotation * v);
    let low = placed.clone().map(|c| c.y).fold(f32::INFINITY, f32::min);
    let size = vertices.iter().map(|v| v.length()).fold(0.0, f32::max);
    let tie = 1e-6 * (1.0 + size);
    let (sum, n) = placed
        .filter(|c| c.y <= low + tie)
        .fold((Vec3::ZERO, 0.0), |(s, n), c| (s + c, n + 1.0));
    (n > 0.0).then(|| Vec3::new(sum.x / n, low, sum.z / n))
}

/// Whether a world point lies over a surface's rectangle (its yawed local frame).
fn over_local(desc: &SurfaceDesc, world_to_local: &Mat4, point: Vec3) -> bool {
    let local = world_to_local.transform_point3(point);
    let half = desc.size * 0.5;
    Vec2::new(local.x, local.z).abs().cmple(half).all()
}

/// The footstep of one deformer over one surface on flat ground, if it landed there during
/// `elapsed` seconds.
#[cfg(test)]
pub fn landing<'a>(
    desc: &SurfaceDesc,
    shape: &Shape,
    previous: &Pose,
    pose: &Pose,
    elapsed: f32,
    mesh_vertices: impl Fn(MeshId) -> Option<&'a [Vec3]> + Copy,
) -> Option<(Vec3, f32, f32)> {
    let m = desc.world_to_local();
    landing_on(
        (desc, &m),
        None,
        shape,
        previous,
        pose,
        elapsed,
        mesh_vertices,
    )
}

/// The fresh snow top's world height over `point` and the snow depth it holds there: the flat
/// surface's, or on a ground field the local top of the texel under the point.
fn top_over(
    (desc, world_to_local): (&SurfaceDesc, &Mat4),
    ground: Option<&GroundField>,
    point: Vec3,
) -> (f32, f32) {
    let Some(g) = ground else {
        return (desc.center.y + desc.snow_depth, desc.snow_depth);
    };
    let local = world_to_local.transform_point3(point);
    let cell = |v: f32, side: f32, n: u32| {
        (((v / side + 0.5) * n as f32).floor().max(0.0) as u32).min(n - 1)
    };
    let (c, r) = (
        cell(local.x, desc.size.x, g.width),
        cell(local.z, desc.size.y, g.height),
    );
    let [base, bare] = g.columns[(r * g.width + c) as usize];
    (
        desc.center.y + base + desc.snow_depth,
        desc.snow_depth - bare,
    )
}

/// [`landing`] on a surface (given with its world-to-local transform) that may lie on a ground
/// field.
#[allow(clippy::too_many_arguments)]
pub fn landing_on<'a>(
    (desc, world_to_local): (&SurfaceDesc, &Mat4),
    ground: Option<&GroundField>,
    shape: &Shape,
    previous: &Pose,
    pose: &Pose,
    elapsed: f32,
    mesh_vertices: impl Fn(MeshId) -> Option<&'a [Vec3]> + Copy,
) -> Option<(Vec3, f32, f32)> {
    // The current pose first: a deformer above the snow or beside the surface needs no more.
    let now = lowest_point(shape, pose, mesh_vertices)?;
    if !over_local(desc, world_to_local, now) {
        return None;
    }
    let (top, held) = top_over((desc, world_to_local), ground, now);
    if now.y >= top {
        return None;
    }
    let before = lowest_point(shape, previous, mesh_vertices)?;
    if before.y <= top {
        return None;
    }
    let depth = (top - now.y).min(held);
    let speed = if elapsed > 0.0 {
        (now - before).length() / elapsed
    } else {
        0.0
    };
    Some((now, depth, speed))
}

/// The footstep of deformer `i` of a surface's update (`id`, with its description and
/// world-to-local transform) that may lie on a ground field, if the deformer landed on it during
/// `elapsed` seconds. A deformer without a `previous` pose (at rest) never lands. The world's
/// frame plan runs it over each surface's deformers ([`crate::world::FramePlan::footsteps`]).
pub(crate) fn footstep<'m>(
    i: usize,
    deformer: &Deformer,
    (id, desc, world_to_local): (SurfaceId, &SurfaceDesc, &Mat4),
    ground: Option<&GroundField>,
    elapsed: f32,
    mesh_vertices: impl Fn(MeshId) -> Option<&'m [Vec3]> + Copy,
) -> Option<Footstep> {
    let previous = deformer.previous.as_ref()?;
    let (point, depth_m, speed) = landing_on(
        (desc, world_to_local),
        ground,
        &deformer.shape,
        previous,
        &deformer.pose,
        elapsed,
        mesh_vertices,
    )?;
    Some(Footstep {
        deformer: i,
        surface: id,
        point,
        depth_m,
        speed,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Quat;

    /// No mesh has vertices.
    const NO_MESH: fn(MeshId) -> Option<&'static [Vec3]> = |_| None;

    #[test]
    fn lowest_points_by_hand() {
        let at = Pose::at([1.0, 2.0, 3.0]);
        let sphere = Shape::Sphere { radius: 0.5 };
        assert_eq!(
            lowest_point(&sphere, &at, NO_MESH),
            Some(Vec3::new(1.0, 1.5, 3.0))
        );
        let capsule = Shape::Capsule {
            radius: 0.1,
            half_height: 0.4,
        };
        // Upright: the lower cap's bottom.
        let p = lowest_point(&capsule, &at, NO_MESH).unwrap();
        assert!((p - Vec3::new(1.0, 1.5, 3.0)).length() < 1e-6, "{p}");
        // Tilted 90 degrees about z: lying along x, the lowest point is under the middle.
        let lying = Pose {
            rotation: Quat::from_rotation_z(std::f32::consts::FRAC_PI_2),
            ..at
        };
        let p = lowest_point(&capsule, &lying, NO_MESH).unwrap();
        assert!((p - Vec3::new(1.0, 1.9, 3.0)).length() < 1e-5, "{p}");
        // A box turned 45 degrees about x stands on an edge, 0.2 * sqrt(2) below its centre.
        let block = Shape::Box {
            half_extents: Vec3::splat(0.2),
        };
        let edge = Pose {
            rotation: Quat::from_rotation_x(std::f32::consts::FRAC_PI_4),
            ..at
        };
        let p = lowest_point(&block, &edge, NO_MESH).unwrap();
        assert!(
            (p - Vec3::new(1.0, 2.0 - 0.2 * 2f32.sqrt(), 3.0)).length() < 1e-5,
            "{p}"
        );
        // A mesh: from its vertices, as the box it is; none when the world has none for it.
        let cube = crate::mesh::Mesh::cuboid(Vec3::splat(0.2));
        let vertices = |_| Some(cube.positions.as_slice());
        let mesh = Shape::Mesh(MeshId(0));
        let p = lowest_point(&mesh, &edge, vertices).unwrap();
        assert!((p - lowest_point(&block, &edge, NO_MESH).unwrap()).length() < 1e-6);
        assert_eq!(lowest_point(&mesh, &at, NO_MESH), None);
    }

    #[test]
    fn landing_only_when_crossing_the_top_over_the_surface() {
        let mut desc = SurfaceDesc::new("path", [0.0, 1.0, 0.0], [2.0, 1.0], 0.3);
        let foot = Shape::Sphere { radius: 0.1 };
        // Top at 1.3: from 1.5 (bottom 1.4) to 1.3 (bottom 1.2): lands 0.1 deep at 0.2 m / 0.1 s.
        let (point, depth, speed) = landing(
            &desc,
            &foot,
            &Pose::at([0.5, 1.5, 0.2]),
            &Pose::at([0.5, 1.3, 0.2]),
            0.1,
            NO_MESH,
        )
        .unwrap();
        assert!((point - Vec3::new(0.5, 1.2, 0.2)).length() < 1e-6);
        assert!((depth - 0.1).abs() < 1e-6 && (speed - 2.0).abs() < 1e-5);
        // Through the ground: the depth is clamped to the snow depth.
        let deep = landing(
            &desc,
            &foot,
            &Pose::at([0.0, 1.5, 0.0]),
            &Pose::at([0.0, 0.5, 0.0]),
            0.1,
            NO_MESH,
        );
        assert!((deep.unwrap().1 - 0.3).abs() < 1e-6);
        // Resting, rising, or outside the rectangle: nothing.
        let low = Pose::at([0.0, 1.3, 0.0]);
        assert!(landing(&desc, &foot, &low, &low, 0.1, NO_MESH).is_none());
        assert!(landing(&desc, &foot, &low, &Pose::at([0.0, 1.6, 0.0]), 0.1, NO_MESH).is_none());
        assert!(
            landing(
                &desc,
                &foot,
                &Pose::at([1.5, 1.5, 0.0]),
                &Pose::at([1.5, 1.3, 0.0]),
                0.1,
                NO_MESH
            )
            .is_none()
        );
        // Yawed 90 degrees, the 2 m side runs along world z.
        desc.yaw_degrees = 90.0;
        assert!(over_local(
            &desc,
            &desc.world_to_local(),
            Vec3::new(0.0, 1.0, 0.9)
        ));
        assert!(!over_local(
            &desc,
            &desc.world_to_local(),
            Vec3::new(0.9, 1.0, 0.0)
        ));
    }
}
