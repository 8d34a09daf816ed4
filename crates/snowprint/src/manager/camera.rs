//! Where the camera is and what it sees: activity is decided against its frustum.

use glam::{Vec3, Vec4};

use crate::error::{Result, SnowError};
use crate::view::Camera;

/// Where the camera is and what it sees: activity is decided against its frustum.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraView {
    /// Eye, world metres.
    pub eye: Vec3,
    /// Point looked at.
    pub target: Vec3,
    /// Vertical field of view, degrees.
    pub fov_y_degrees: f32,
    /// Width over height.
    pub aspect: f32,
    /// Near plane, metres.
    pub near: f32,
    /// Far plane, metres.
    pub far: f32,
}

impl CameraView {
    /// The view of a [`Camera`] with an aspect ratio, near plane 0.1 m and far plane 10 km (the
    /// manager's `active_distance` limits activity anyway).
    pub fn new(camera: &Camera, aspect: f32) -> Self {
        Self {
            eye: camera.eye,
            target: camera.target,
            fov_y_degrees: camera.fov_y_degrees,
            aspect,
            near: 0.1,
            far: 10_000.0,
        }
    }

    /// The six planes of the view, checking every field.
    pub fn frustum(&self) -> Result<Frustum> {
        let bad = |what: &'static str, value: String, expected: &'static str| {
            Err(SnowError::Config {
                config: "camera",
                what,
                value,
                expected,
            })
        };
        if !self.eye.is_finite() || !self.target.is_finite() {
            return bad(
                "eye or target",
                format!("{:?} / {:?}", self.eye.to_array(), self.target.to_array()),
                "finite",
            );
        }
        let forward = (self.target - self.eye).normalize_or_zero();
        if forward == Vec3::ZERO {
            return bad(
                "target",
                format!("{:?}", self.target.to_array()),
                "different from the eye",
            );
        }
        if !(self.fov_y_degrees.is_finite()
            && self.fov_y_degrees > 0.0
            && self.fov_y_degrees < 180.0)
        {
            return bad(
                "fov_y_degrees",
                self.fov_y_degrees.to_string(),
                "between 0 and 180",
            );
        }
        if !(self.aspect.is_finite() && self.aspect > 0.0) {
            return bad("aspect", self.aspect.to_string(), "a finite number above 0");
        }
        if !(self.near.is_finite()
            && self.far.is_finite()
            && self.near > 0.0
            && self.far > self.near)
        {
            return bad(
                "near / far",
                format!("{} / {}", self.near, self.far),
                "finite with 0 < near < far",
            );
        }
        // Looking straight up or down: any horizontal axis serves as "up".
        let up = if forward.cross(Vec3::Y).length_squared() < 1e-8 {
            Vec3::Z
        } else {
            Vec3::Y
        };
        let right = forward.cross(up).normalize();
        let up = right.cross(forward);
        let tan_v = (self.fov_y_degrees.to_radians() * 0.5).tan();
        let tan_h = tan_v * self.aspect;
        // Inward normals through the eye for the four sides.
        let side = |n: Vec3| {
            let n = n.normalize();
            n.extend(-n.dot(self.eye))
        };
        Ok(Frustum {
            planes: [
                side(forward * tan_h + right),
                side(forward * tan_h - right),
                side(forward * tan_v + up),
                side(forward * tan_v - up),
                forward.extend(-forward.dot(self.eye) - self.near),
                (-forward).extend(forward.dot(self.eye) + self.far),
            ],
        })
    }
}

/// A view frustum as six inward planes `(n, d)`, `n . p + d >= 0` inside.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frustum {
    /// Left, right, bottom, top, near, far.
    pub planes: [Vec4; 6],
}

impl Frustum {
    /// Whether a sphere is at least partly inside (conservative near the frustum's edges, as the
    /// usual plane test is).
    #[inline]
    pub fn sees(&self, center: Vec3, radius: f32) -> bool {
        self.planes
            .iter()
            .all(|p| p.truncate().dot(center) + p.w >= -radius)
    }
}
