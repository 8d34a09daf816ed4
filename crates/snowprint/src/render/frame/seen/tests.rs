use glam::{Mat4, Vec3};

use super::*;
use crate::extract::SurfaceView;
use crate::render::heightfield::Beside;
use crate::render::tessellate::SurfaceGeometry;
use crate::surface::SurfaceDesc;
use crate::view::GroundMaterial;

fn view(desc: &SurfaceDesc) -> SurfaceView<'_> {
    SurfaceView::for_test(desc, 0, [64, 64], None)
}

fn surface<'a>(view: &'a SurfaceView<'a>, geometry: &'a SurfaceGeometry) -> FrameSurface<'a> {
    FrameSurface {
        view,
        ground: GroundMaterial::Concrete,
        geometry,
        tessellated: true,
        sides: [None; 4],
        enclosed: false,
        seen: false,
    }
}

/// The camera at (0, 2, 0) looking along -z, 60 degrees high, 16:9.
fn camera() -> Mat4 {
    let camera = crate::Camera {
        eye: Vec3::new(0.0, 2.0, 0.0),
        target: Vec3::new(0.0, 2.0, -1.0),
        fov_y_degrees: 60.0,
    };
    camera.projection(16.0 / 9.0, 0.05, 600.0) * camera.view()
}

/// An orthographic cascade over x, z in [-10, 10] around (0, 0, 30), looking straight down.
fn cascade() -> Mat4 {
    let proj = glam::camera::rh::proj::directx::orthographic(-10.0, 10.0, -10.0, 10.0, 0.0, 100.0);
    let eye = Vec3::new(0.0, 50.0, 30.0);
    proj * glam::camera::rh::view::look_at_mat4(eye, Vec3::new(0.0, 0.0, 30.0), Vec3::NEG_Z)
}

fn seen(center: [f32; 3], size: [f32; 2], shadow: Option<Mat4>, linked: bool) -> bool {
    let desc = SurfaceDesc::new("s", center, size, 0.3);
    let v = view(&desc);
    let g = SurfaceGeometry::default();
    let other_desc = SurfaceDesc::new("o", [0.0, 0.0, -5.0], [2.0, 2.0], 0.3);
    let other = view(&other_desc);
    let mut s = [surface(&v, &g)];
    if linked {
        s[0].sides[1] = Some(Beside {
            view: &other,
            offset: 0,
        });
    }
    mark_seen(&mut s, camera(), shadow);
    s[0].seen
}

/// Surfaces before the camera, around it, behind it, beside the frustum, and under the near
/// cascade only, each placed by hand against the frustum's planes.
#[test]
fn surfaces_are_seen_where_the_view_or_the_near_cascade_reaches_them() {
    // Ahead, on the ground: in view.
    assert!(seen([0.0, 0.0, -10.0], [4.0, 4.0], None, false));
    // Under the camera and around it (corners behind the eye and ahead of it): in view.
    assert!(seen([0.0, 0.0, 0.0], [40.0, 40.0], None, false));
    // Behind the camera (z from 8 to 12): not.
    assert!(!seen([0.0, 0.0, 10.0], [4.0, 4.0], None, false));
    // Far to the left of the frustum: at z = -10 the view reaches |x| < 10 tan(30) 16/9 = 10.3.
    assert!(!seen([-20.0, 0.0, -10.0], [4.0, 4.0], None, false));
    // Behind the camera but under the near cascade (z in [20, 40]): seen when the frame dices.
    assert!(seen([0.0, 0.0, 30.0], [4.0, 4.0], Some(cascade()), false));
    assert!(!seen([0.0, 0.0, 30.0], [4.0, 4.0], None, false));
    // Out of view and out of the cascade, but linked to a surface beside it: seen.
    assert!(seen([0.0, 0.0, 10.0], [4.0, 4.0], None, true));
    // Against the view's bottom plane: the eye at 2 m looking level sees down to 30 degrees
    // below the horizon; the box of snow 0.3 m deep rises to 0.7 m (twice the depth, and the
    // waves' 0.1 m), seen from 1.3 / tan(30) = 2.25 m ahead: a surface reaching z = -2.5 is
    // seen, one reaching z = -2.0 not.
    assert!(seen([0.0, 0.0, -1.5], [2.0, 2.0], None, false));
    assert!(!seen([0.0, 0.0, -1.0], [2.0, 2.0], None, false));
}
