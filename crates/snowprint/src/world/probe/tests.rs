//! Probe layouts and decoding, checked by hand.

use super::*;
use crate::surface::SurfaceId;
use glam::{Quat, Vec3};

/// `ProbeQuery` here and in probe.wgsl: same fields, same order, 4 bytes each.
#[test]
fn query_layout_matches_wgsl() {
    let module = naga::front::wgsl::parse_str(crate::wgsl::PROBE.source).unwrap();
    let mut layouter = naga::proc::Layouter::default();
    layouter.update(module.to_ctx()).unwrap();
    let (handle, ty) = module
        .types
        .iter()
        .find(|(_, t)| t.name.as_deref() == Some("ProbeQuery"))
        .unwrap();
    let naga::TypeInner::Struct { members, .. } = &ty.inner else {
        panic!("ProbeQuery is not a struct")
    };
    assert_eq!(
        layouter[handle].size as usize,
        std::mem::size_of::<ProbeQuery>()
    );
    let names: Vec<_> = members.iter().map(|m| m.name.clone().unwrap()).collect();
    let expect = [
        "base",
        "width",
        "height",
        "texel",
        "bits",
        "texel_x",
        "texel_z",
        "snow_depth",
        "wrap",
    ];
    assert_eq!(names, expect);
    for (i, m) in members.iter().enumerate() {
        assert_eq!(m.offset as usize, i * 4, "{:?}", m.name);
    }
}

/// Raw results to samples by hand: channels to metres at the pool's precision, the slope to a
/// normal turned by the surface's yaw, and nothing for a point over no surface.
#[test]
fn decode_by_hand() {
    let info = PointInfo {
        point: Vec3::new(1.0, 2.0, 3.0),
        surface: Some(SurfaceId(0, 0)),
        snow_depth: 0.4,
        rotation: Quat::from_rotation_y(std::f32::consts::FRAC_PI_2),
        channel_max: 255.0,
        bare: 0.0,
        base_slope: glam::Vec2::ZERO,
    };
    // A quarter pressed, a tenth displaced (of 255), rising 1 m per m along local x.
    let raw = [51u32 + 12, 25 + 1, 1f32.to_bits(), 0f32.to_bits()];
    let s = decode(&info, raw);
    assert!((s.depression_m - 0.4 * 63.0 / 255.0).abs() < 1e-6);
    assert!((s.snow_depth_m - (0.4 - s.depression_m)).abs() < 1e-6);
    assert!((s.displaced_m - 0.4 * 26.0 / 255.0).abs() < 1e-6);
    // Local normal (-1, 1, 0) / sqrt 2; a quarter turn about +Y takes local -x to world +z.
    let n = s.normal;
    let h = std::f32::consts::FRAC_1_SQRT_2;
    assert!((n - Vec3::new(0.0, h, h)).length() < 1e-5, "{n}");
    let none = decode(
        &PointInfo {
            surface: None,
            ..info
        },
        raw,
    );
    assert_eq!(none, ProbeSample::outside(info.point));
    // On a slope of the ground holding 0.1 m less (bare), rising 1 m per m along local z under the
    // same snow: the snow left is 0.1 less, and the normal leans on both slopes.
    let on_ground = decode(
        &PointInfo {
            bare: 0.1,
            base_slope: glam::Vec2::new(0.0, 1.0),
            ..info
        },
        raw,
    );
    assert!((on_ground.snow_depth_m - (0.4 - 0.1 - s.depression_m)).abs() < 1e-6);
    let local = Vec3::new(-1.0, 1.0, -1.0).normalize();
    let want = Quat::from_rotation_y(std::f32::consts::FRAC_PI_2) * local;
    assert!(
        (on_ground.normal - want).length() < 1e-5,
        "{}",
        on_ground.normal
    );
}

/// A coarser window level's hole leaves its points to the finer level: a point in the hole is
/// not over the coarse level, one beside it is (with its ground), whichever ground is higher.
#[test]
fn a_point_in_a_levels_hole_is_not_over_it() {
    let coarse = crate::surface::SurfaceDesc::new("coarse", [10.0, 2.0, 0.0], [8.0, 8.0], 0.3);
    // The hole, local: x in [-1, 1), z in [-2, 0).
    let hole = Some([-1.0, -2.0, 1.0, 0.0]);
    let over = |x: f32, z: f32| cpu::over_outside_hole(&coarse, None, hole, Vec3::new(x, 2.5, z));
    assert_eq!(over(10.0, -1.0), None, "in the hole");
    assert_eq!(
        over(9.0, -2.0),
        None,
        "on its first corner (the hole holds its low edges)"
    );
    assert_eq!(over(11.0, -1.0), Some(2.0), "on its high edge: outside");
    assert_eq!(over(12.0, 1.0), Some(2.0), "beside it");
    assert_eq!(
        cpu::over_outside_hole(&coarse, None, None, Vec3::new(10.0, 2.5, -1.0)),
        Some(2.0)
    );
}
