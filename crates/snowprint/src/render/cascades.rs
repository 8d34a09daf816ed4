//! The moon's two shadow cascades: the near one around what the camera looks at, the far one
//! around the snow surfaces and every shadow caster. Pure maths on the frame's inputs.

use glam::{Mat4, Vec2, Vec3};

use super::inputs::RenderFrame;
use super::meshes::GpuMesh;
use crate::surface::SurfaceDesc;

/// Side of the near shadow cascade, metres.
const NEAR_CASCADE: f32 = 12.0;

/// Where the near cascade is centred: this far along the view, as a fraction of its side.
const NEAR_FOCUS: f32 = 0.4;

/// How far the near cascade's focus may move (metres, along either axis of the moon's view)
/// before the cascade follows it: while it holds still, its shadows of still casters come from
/// its cache (`shadow/cache.rs`) instead of being drawn again, for a moving camera too.
const NEAR_HOLD: f32 = 1.0;

/// Where the near cascade stood: its centre in the moon's view (metres), that view, and the
/// map's side it was snapped to.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct NearHold {
    view: Mat4,
    size: u32,
    centre: Vec2,
}

/// Side of a scene pixel (`rows` pixels high) at the near cascade's focus, metres: the shadow
/// texel the view would need there for one texel a pixel.
pub(super) fn view_pixel(frame: &RenderFrame<'_>, rows: u32) -> f32 {
    let distance = NEAR_CASCADE * NEAR_FOCUS;
    2.0 * distance * (frame.camera.fov_y_degrees.to_radians() * 0.5).tan() / rows as f32
}

/// Side of the shadow map, texels, whose near cascade has a texel no larger than a scene pixel at
/// its focus for a camera of `fov_y_degrees` over `rows` pixels: the smallest multiple of 256 that
/// is, from 512 to 8192. A larger map costs texels (fill and memory) that the view cannot show.
pub(super) fn shadow_map_size_for_view(fov_y_degrees: f32, rows: u32) -> u32 {
    let distance = NEAR_CASCADE * NEAR_FOCUS;
    let pixel = 2.0 * distance * (fov_y_degrees.clamp(1.0, 179.0).to_radians() * 0.5).tan()
        / rows.max(1) as f32;
    let texels = (NEAR_CASCADE / pixel).ceil() as u32;
    texels.div_ceil(256).clamp(2, 32) * 256
}

/// The moon's two shadow projections and their texels in metres.
pub(super) struct ShadowCascades {
    pub near: Mat4,
    pub far: Mat4,
    pub near_texel: f32,
    pub far_texel: f32,
    /// Where the near cascade stands, for the next frame.
    pub hold: NearHold,
}

/// The moon's two shadow cascades: the near one around what the camera looks at (where it stood
/// the frame before, `held`, while the focus stays within [`NEAR_HOLD`] of it under the same
/// moon's view), the far one around the snow surfaces and every shadow caster.
pub(super) fn shadow_cascades<'a>(
    surfaces: impl IntoIterator<Item = &'a SurfaceDesc>,
    frame: &RenderFrame<'_>,
    meshes: &[GpuMesh],
    (shadow_size, held): (u32, Option<NearHold>),
) -> ShadowCascades {
    let mut lo = Vec3::splat(f32::MAX);
    let mut hi = Vec3::splat(f32::MIN);
    for d in surfaces {
        let m = d.local_to_world();
        let h = d.size * 0.5;
        for corner in [
            Vec3::new(-h.x, 0.0, -h.y),
            Vec3::new(h.x, 0.0, -h.y),
            Vec3::new(-h.x, d.snow_depth, h.y),
            Vec3::new(h.x, d.snow_depth, h.y),
        ] {
            let p = m.transform_point3(corner);
            lo = lo.min(p);
            hi = hi.max(p);
        }
    }
    // Receivers beyond the surfaces and the casters (a backdrop, a ground to the horizon) are
    // left out: they would spread the far cascade's texels over what casts no shadow.
    for inst in frame.instances.iter().filter(|i| i.casts_shadow) {
        let r = meshes[inst.mesh.0 as usize].radius;
        let (scale, _, t) = inst.transform.to_scale_rotation_translation();
        let r = r * scale.abs().max_element();
        lo = lo.min(t - Vec3::splat(r));
        hi = hi.max(t + Vec3::splat(r));
    }
    if lo.x > hi.x {
        lo = Vec3::splat(-1.0);
        hi = Vec3::splat(1.0);
    }
    // Snap the box outwards to whole metres so that moving characters do not shift the shadow
    // map every frame (that would make shadow edges crawl).
    lo = lo.floor() - Vec3::ONE;
    hi = hi.ceil() + Vec3::ONE;
    let center = (lo + hi) * 0.5;
    let radius = (hi - lo).length() * 0.5;
    let dir = frame.environment.moon_direction.normalize();
    let up = if dir.y.abs() > 0.99 { Vec3::Z } else { Vec3::Y };
    let view = glam::camera::rh::view::look_at_mat4(center + dir * radius * 2.0, center, up);
    let mut vlo = Vec3::splat(f32::MAX);
    let mut vhi = Vec3::splat(f32::MIN);
    for i in 0..8 {
        let c = Vec3::new(
            if i & 1 == 0 { lo.x } else { hi.x },
            if i & 2 == 0 { lo.y } else { hi.y },
            if i & 4 == 0 { lo.z } else { hi.z },
        );
        let v = view.transform_point3(c);
        vlo = vlo.min(v);
        vhi = vhi.max(v);
    }
    let (near_z, far_z) = (-vhi.z - 1.0, -vlo.z + 1.0);
    let proj =
        glam::camera::rh::proj::directx::orthographic(vlo.x, vhi.x, vlo.y, vhi.y, near_z, far_z);
    let far_texel = (vhi.x - vlo.x).max(vhi.y - vlo.y) / shadow_size as f32;

    // The near cascade: a square of NEAR_CASCADE metres around the point 40% of the way into
    // it along the view, with the far cascade's depth range (every caster still casts). Its
    // centre is snapped to whole texels in the moon's view so that a moving camera does not
    // make its shadow edges crawl.
    let cam = &frame.camera;
    let forward = (cam.target - cam.eye).normalize_or(Vec3::NEG_Z);
    let focus = view.transform_point3(cam.eye + forward * (NEAR_CASCADE * NEAR_FOCUS));
    let near_texel = NEAR_CASCADE / shadow_size as f32;
    let snap = |v: f32| (v / near_texel).round() * near_texel;
    let target = Vec2::new(snap(focus.x), snap(focus.y));
    let hold = match held {
        Some(h) if h.view == view && h.size == shadow_size => h,
        _ => NearHold {
            view,
            size: shadow_size,
            centre: target,
        },
    };
    let centre = if (hold.centre - target).abs().max_element() <= NEAR_HOLD {
        hold.centre
    } else {
        target
    };
    let (cx, cy) = (centre.x, centre.y);
    let half = NEAR_CASCADE * 0.5;
    let near_proj = glam::camera::rh::proj::directx::orthographic(
        cx - half,
        cx + half,
        cy - half,
        cy + half,
        near_z,
        far_z,
    );
    ShadowCascades {
        near: near_proj * view,
        far: proj * view,
        near_texel,
        far_texel,
        hold: NearHold { centre, ..hold },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// By hand: the near cascade's focus is 4.8 m along the view, where a pixel of a camera of
    /// field `f` over `rows` rows is 9.6 tan(f/2) / rows metres; its 12 m then need
    /// 1.25 rows / tan(f/2) texels, rounded up to a multiple of 256.
    #[test]
    fn the_shadow_map_fitted_to_a_view_has_a_texel_a_pixel() {
        // 50 degrees: tan 25 = 0.46631. 1080 rows need 2895.1 texels, 1440 need 3860.1 (over 15 x 256).
        assert_eq!(shadow_map_size_for_view(50.0, 1080), 3072);
        assert_eq!(shadow_map_size_for_view(50.0, 1440), 4096);
        // 55 degrees: tan 27.5 = 0.52057; 720 rows need 1728.9 texels.
        assert_eq!(shadow_map_size_for_view(55.0, 720), 1792);
        // A tiny image or a wide field asks for little: the map keeps 512 texels.
        assert_eq!(shadow_map_size_for_view(90.0, 36), 512);
        // A narrow field over many rows asks for more than is useful: 8192 at most.
        assert_eq!(shadow_map_size_for_view(10.0, 2160), 8192);
        // No field or no rows is no panic.
        assert_eq!(shadow_map_size_for_view(0.0, 0), 512);
    }

    /// The near cascade stays where it stood while the camera's focus moves less than
    /// NEAR_HOLD along the moon's view, and follows it beyond; a first frame (or another moon)
    /// places it as it always did.
    #[test]
    fn the_near_cascade_holds_still_while_the_focus_stays_near() {
        let frame = |x: f32| RenderFrame {
            camera: crate::Camera {
                eye: Vec3::new(x, 3.0, 6.0),
                target: Vec3::new(x, 0.0, 0.0),
                fov_y_degrees: 50.0,
            },
            time: 0.0,
            surfaces: &[],
            instances: &[],
            lights: &[],
            environment: crate::render::Environment::moonlit_night(),
            snowfall: false,
        };
        let place = |x: f32, held| shadow_cascades([], &frame(x), &[], (1024, held));
        let first = place(0.0, None);
        // 0.5 m: held (the far cascade, around nothing, does not move).
        let near = place(0.5, Some(first.hold));
        assert_eq!(near.near, first.near);
        assert_eq!(near.far, first.far);
        assert_ne!(place(0.5, None).near, first.near);
        // 3 m: the cascade follows, where a first frame would put it.
        let far = place(3.0, Some(first.hold));
        assert_eq!(far.near, place(3.0, None).near);
        assert_ne!(far.near, first.near);
        // Another map side: placed afresh.
        let resized = shadow_cascades([], &frame(0.5), &[], (2048, Some(first.hold)));
        assert_eq!(
            resized.near,
            shadow_cascades([], &frame(0.5), &[], (2048, None)).near
        );
    }
}
