//! Types shared by whoever builds a scene to look at (the demo world) and whoever draws it (the
//! renderer).

use glam::{Mat4, Vec3};

/// What lies under the snow of a surface, shown where the snow is pressed down to the ground.
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize,
)]
#[serde(rename_all = "snake_case")]
pub enum GroundMaterial {
    /// Clay roof tiles (rooftops).
    #[default]
    RoofTiles,
    /// Concrete (streets, flat roofs).
    Concrete,
    /// Bare rock (terrain: the cliffs and outcrops too steep to hold snow show it).
    Rock,
}

/// A perspective camera.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Eye position, world metres.
    pub eye: Vec3,
    /// Point looked at.
    pub target: Vec3,
    /// Vertical field of view, degrees.
    pub fov_y_degrees: f32,
}

impl Camera {
    /// World-to-view transform (right-handed, +Y up).
    pub fn view(&self) -> Mat4 {
        glam::camera::rh::view::look_at_mat4(self.eye, self.target, Vec3::Y)
    }

    /// View-to-clip transform for an aspect ratio, with wgpu's 0..1 depth.
    pub fn projection(&self, aspect: f32, near: f32, far: f32) -> Mat4 {
        glam::camera::rh::proj::directx::perspective(
            self.fov_y_degrees.to_radians(),
            aspect,
            near,
            far,
        )
    }
}
