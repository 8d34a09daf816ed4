//! Culling against the view frustum, a pure plan on the CPU: which of the frame's opaque
//! instances can reach a pixel. Each instance is bounded by a sphere (its mesh's bounding radius
//! about the mesh's origin, times the transform's largest axis scale) and kept unless the sphere
//! lies wholly outside one of the frustum's six planes. Shadow casters are not culled here: a
//! caster outside the view can still shadow what is in it.

use glam::{Mat4, Vec3, Vec4};

/// The six planes of a view frustum, each `(n, d)` with `n . p + d >= 0` inside (unnormalised
/// normals, divided through for distances).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Frustum {
    planes: [Vec4; 6],
}

impl Frustum {
    /// The frustum of a world-to-clip matrix with depth in `[0, 1]` (wgpu's convention), by
    /// Gribb and Hartmann's rows: left, right, bottom, top, near, far.
    pub(crate) fn from_view_proj(m: Mat4) -> Self {
        let (r0, r1, r2, r3) = (m.row(0), m.row(1), m.row(2), m.row(3));
        let planes = [r3 + r0, r3 - r0, r3 + r1, r3 - r1, r2, r3 - r2].map(|p| {
            let len = p.truncate().length();
            if len > 0.0 { p / len } else { p }
        });
        Self { planes }
    }

    /// Whether a sphere reaches inside (or touches) the frustum.
    pub(crate) fn sphere_visible(&self, centre: Vec3, radius: f32) -> bool {
        self.planes
            .iter()
            .all(|p| p.truncate().dot(centre) + p.w >= -radius)
    }
}

/// The bounding sphere of a mesh of bounding radius `radius` (about its origin) placed by
/// `transform`: the origin's image, and the radius times the largest axis scale.
pub(crate) fn bounding_sphere(transform: Mat4, radius: f32) -> (Vec3, f32) {
    let scale = transform
        .x_axis
        .truncate()
        .length()
        .max(transform.y_axis.truncate().length())
        .max(transform.z_axis.truncate().length());
    (transform.w_axis.truncate(), radius * scale)
}

/// Which instances (each bounded by a sphere, [`bounding_sphere`]) the view may see.
pub(crate) fn visible(view_proj: Mat4, spheres: &[(Vec3, f32)]) -> Vec<bool> {
    let frustum = Frustum::from_view_proj(view_proj);
    spheres
        .iter()
        .map(|&(c, r)| frustum.sphere_visible(c, r))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The renderer's camera at the origin looking down -z, 90 degrees vertically, square, near
    /// 1, far 100.
    fn camera() -> Mat4 {
        let c = crate::Camera {
            eye: Vec3::ZERO,
            target: Vec3::NEG_Z,
            fov_y_degrees: 90.0,
        };
        c.projection(1.0, 1.0, 100.0) * c.view()
    }

    fn at(x: f32, y: f32, z: f32) -> Mat4 {
        Mat4::from_translation(Vec3::new(x, y, z))
    }

    /// Cases computed by hand: at 90 degrees the side planes are x = +-z and y = +-z, so at depth
    /// 10 a point is inside for |x| <= 10; a unit sphere reaches in while its centre is within
    /// sqrt(2) of the plane (the plane's distance is |x - 10| / sqrt(2) at z = -10).
    #[test]
    fn spheres_against_a_frustum_computed_by_hand() {
        let f = Frustum::from_view_proj(camera());
        // In front, inside.
        assert!(f.sphere_visible(Vec3::new(0.0, 0.0, -10.0), 1.0));
        // Behind the camera, and beyond the far plane.
        assert!(!f.sphere_visible(Vec3::new(0.0, 0.0, 5.0), 1.0));
        assert!(!f.sphere_visible(Vec3::new(0.0, 0.0, -102.0), 1.0));
        assert!(f.sphere_visible(Vec3::new(0.0, 0.0, -100.5), 1.0));
        // Beside the right plane x = -z: the centre 1.4 (< sqrt 2) from it reaches in, 1.5 not.
        let d = |dist: f32| 10.0 + dist * std::f32::consts::SQRT_2;
        assert!(f.sphere_visible(Vec3::new(d(0.99), 0.0, -10.0), 1.0));
        assert!(!f.sphere_visible(Vec3::new(d(1.01), 0.0, -10.0), 1.0));
        // Above the top plane likewise.
        assert!(!f.sphere_visible(Vec3::new(0.0, d(1.01), -10.0), 1.0));
        // Straddling the near plane (z = -1) from behind the camera.
        assert!(f.sphere_visible(Vec3::new(0.0, 0.0, 0.5), 2.0));
    }

    #[test]
    fn scaled_instances_are_bounded_by_their_largest_axis() {
        let t = Mat4::from_scale_rotation_translation(
            Vec3::new(1.0, 4.0, 2.0),
            glam::Quat::from_rotation_y(0.7),
            Vec3::new(3.0, 2.0, 1.0),
        );
        let (c, r) = bounding_sphere(t, 0.5);
        assert!((c - Vec3::new(3.0, 2.0, 1.0)).length() < 1e-6);
        assert!((r - 2.0).abs() < 1e-5);
        // A unit-radius mesh scaled 4 along y, 12 above the view's top at depth 10 (top plane
        // y = 10 there, distance (y - 10) / sqrt(2)): its sphere of radius 4 reaches in from
        // y = 15 but not from y = 16.
        let tall = |y| {
            Mat4::from_scale_rotation_translation(
                Vec3::new(1.0, 4.0, 1.0),
                glam::Quat::IDENTITY,
                Vec3::new(0.0, y, -10.0),
            )
        };
        let spheres = [tall(15.0), tall(16.0), at(0.0, 0.0, -5.0)].map(|t| bounding_sphere(t, 1.0));
        assert_eq!(visible(camera(), &spheres), vec![true, false, true]);
    }
}
