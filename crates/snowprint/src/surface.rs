//! Snow surfaces: horizontal rectangles of snow over snow-free ground, and the layout of their
//! heightmaps.
//!
//! A surface's local frame has its origin at the centre of the rectangle *on the ground*, `x` along
//! the rectangle's first side, `z` along its second, and `y` the height above the ground (world `+Y`).
//! The yaw turns the local frame about world `+Y`. Heightmap texel `(column, row)` covers local
//! `x` from `-size_x/2 + column * texel_x`, `z` from `-size_z/2 + row * texel_z`: column 0 is the
//! smallest `x`, row 0 the smallest `z`, and UVs run 0..1 across the capture frustum.

use glam::{Mat4, Quat, Vec2, Vec3};

use crate::error::{Result, SnowError};
use crate::material::Material;

/// Smallest texel side, metres (the talk's "1/4 x surface size in cm").
pub const MIN_TEXEL_SIZE: f32 = 0.04;
/// Largest heightmap side, texels (the talk's 512).
pub const MAX_RESOLUTION: u32 = 512;

/// Description of one snow surface.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SurfaceDesc {
    /// Unique name, used for output files.
    pub name: String,
    /// Centre of the rectangle on the ground under the snow (world metres; `y` is the ground).
    pub center: Vec3,
    /// Side lengths along local `x` and `z`, metres.
    pub size: Vec2,
    /// Rotation of the rectangle about world `+Y`, degrees.
    pub yaw_degrees: f32,
    /// Depth of fresh snow over the ground, metres.
    pub snow_depth: f32,
    /// Fraction of the snow depth refilled per second while it snows (0 = no snowfall).
    pub replenish_rate: f32,
    /// What it is made of: how prints move after they are made ([`Material::snow`] by default:
    /// they keep their walls).
    #[serde(default)]
    pub material: Material,
}

impl SurfaceDesc {
    /// A surface with no yaw and no replenishment.
    pub fn new(name: &str, center: [f32; 3], size: [f32; 2], snow_depth: f32) -> Self {
        Self {
            name: name.to_owned(),
            center: Vec3::from(center),
            size: Vec2::from(size),
            yaw_degrees: 0.0,
            snow_depth,
            replenish_rate: 0.0,
            material: Material::snow(),
        }
    }

    /// Check every field, naming the first one that is wrong.
    pub fn validate(&self) -> Result<()> {
        let bad = |what: &'static str, value: String, expected: &'static str| {
            Err(SnowError::InvalidSurface {
                name: self.name.clone(),
                what,
                value,
                expected,
            })
        };
        if !self.center.is_finite() {
            return bad("center", format!("{:?}", self.center.to_array()), "finite");
        }
        for (what, v) in [("size x", self.size.x), ("size z", self.size.y)] {
            if !(v.is_finite() && v > 0.0) {
                return bad(what, v.to_string(), "a finite number of metres above 0");
            }
            if v > 100_000.0 {
                return bad(what, v.to_string(), "at most 100000 metres");
            }
        }
        if !(self.snow_depth.is_finite() && self.snow_depth > 0.0) {
            return bad(
                "snow_depth",
                self.snow_depth.to_string(),
                "a finite number of metres above 0",
            );
        }
        if !(self.replenish_rate.is_finite() && self.replenish_rate >= 0.0) {
            return bad(
                "replenish_rate",
                self.replenish_rate.to_string(),
                "a finite fraction per second, 0 or more",
            );
        }
        if !self.yaw_degrees.is_finite() {
            return bad("yaw_degrees", self.yaw_degrees.to_string(), "finite");
        }
        self.material.validate(&self.name)
    }

    /// Heightmap layout of this surface (resolution and texel size).
    pub fn layout(&self) -> SurfaceLayout {
        SurfaceLayout::for_size(self.size)
    }

    /// Rotation of the local frame in the world.
    pub fn rotation(&self) -> Quat {
        Quat::from_rotation_y(self.yaw_degrees.to_radians())
    }

    /// Transform from surface-local coordinates (origin at the centre on the ground) to world.
    pub fn local_to_world(&self) -> Mat4 {
        Mat4::from_rotation_translation(self.rotation(), self.center)
    }

    /// Transform from world to surface-local coordinates.
    pub fn world_to_local(&self) -> Mat4 {
        self.local_to_world().inverse()
    }
}

/// Resolution of a surface's heightmap.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SurfaceLayout {
    /// Texels along local `x`.
    pub width: u32,
    /// Texels along local `z`.
    pub height: u32,
}

impl SurfaceLayout {
    /// The talk's rule, texels kept square: texel size = max(4 cm, longest side / 512), texels per
    /// axis = ceil(side / texel size). An 8 m x 6 m roof gets 200 x 150, a 30 m x 10 m street
    /// 512 x 171.
    pub fn for_size(size: Vec2) -> Self {
        Self::for_size_capped(size, MAX_RESOLUTION)
    }

    /// The same rule with another cap than 512 texels a side (benchmarks sweep up to 1024).
    pub fn for_size_capped(size: Vec2, max_resolution: u32) -> Self {
        let max_resolution = max_resolution.max(1);
        let texel = (size.x.max(size.y) / max_resolution as f32).max(MIN_TEXEL_SIZE);
        // A tiny relative slack keeps exact multiples (8 m / 4 cm) from rounding up to 201.
        let count = |side: f32| (((side / texel) - 1e-4).ceil() as u32).clamp(1, max_resolution);
        Self {
            width: count(size.x),
            height: count(size.y),
        }
    }

    /// The nominal texel side, metres: max(4 cm, longest side / 512).
    pub fn nominal_texel_size(size: Vec2) -> f32 {
        (size.x.max(size.y) / MAX_RESOLUTION as f32).max(MIN_TEXEL_SIZE)
    }

    /// Number of texels.
    pub fn texels(&self) -> u64 {
        self.width as u64 * self.height as u64
    }
}

/// Handle of a surface in a [`crate::SnowWorld`]: a slot index and the generation of that slot.
///
/// A removed surface's index is reused by a later [`crate::SnowWorld::add_surface`], but with the
/// next generation, so a handle kept past its surface's removal never names the new surface: every
/// call with it answers [`crate::SnowError::StaleHandle`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct SurfaceId(pub(crate) u32, pub(crate) u32);

impl SurfaceId {
    /// Index of the surface's slot in its world; two live surfaces never share one, but a removed
    /// surface's index is given to a later one (compare whole handles to tell them apart).
    pub fn index(self) -> u32 {
        self.0
    }

    /// Generation of the slot: how many surfaces held this index before this one.
    pub fn generation(self) -> u32 {
        self.1
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn talk_resolution_rule() {
        assert_eq!(
            SurfaceLayout::for_size(Vec2::new(8.0, 6.0)),
            SurfaceLayout {
                width: 200,
                height: 150
            }
        );
        assert_eq!(
            SurfaceLayout::for_size(Vec2::new(30.0, 10.0)),
            SurfaceLayout {
                width: 512,
                height: 171
            }
        );
        // Small: 4 cm texels.
        assert_eq!(
            SurfaceLayout::for_size(Vec2::new(1.0, 0.5)),
            SurfaceLayout {
                width: 25,
                height: 13
            }
        );
        // Very long: capped at 512, texels stay square.
        let l = SurfaceLayout::for_size(Vec2::new(100.0, 3.0));
        assert_eq!((l.width, l.height), (512, 16));
    }

    #[test]
    fn validation_names_the_field() {
        let mut s = SurfaceDesc::new("roof", [0.0; 3], [8.0, 6.0], 0.3);
        assert!(s.validate().is_ok());
        s.size.x = -1.0;
        let e = s.validate().unwrap_err().to_string();
        assert!(e.contains("size x") && e.contains("-1"), "{e}");
        s.size.x = 1.0;
        s.snow_depth = f32::NAN;
        let e = s.validate().unwrap_err().to_string();
        assert!(e.contains("snow_depth") && e.contains("NaN"), "{e}");
    }
}
