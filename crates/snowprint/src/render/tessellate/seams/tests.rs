use glam::Vec2;

use super::*;
use crate::render::tessellate::SurfaceMesh;
use crate::surface::SurfaceDesc;

/// Edge `e` of a base triangle: its endpoints and its seam mark.
fn edge(t: &BaseTriangle, e: usize) -> (Vec2, Vec2, u32) {
    let p = [t.a, t.b, t.c].map(|p| Vec2::new(p[0], p[2]));
    let mark = (t.ids[3] >> (SEAM_SHIFT + 4 * e as u32)) & 15;
    (p[e], p[(e + 1) % 3], mark)
}

fn area(t: &BaseTriangle) -> f32 {
    let [a, b, c] = [t.a, t.b, t.c].map(|p| Vec2::new(p[0], p[2]));
    0.5 * (b - a).perp_dot(c - a).abs()
}

/// Without a hole: the rectangle's own triangles, each border edge marked with its side.
#[test]
fn a_rectangle_without_a_hole_marks_each_border_edge_with_its_side() {
    let half = Vec2::new(2.5, 1.5);
    let plain = SurfaceMesh::rectangle(half).base_triangles();
    let marked = rectangle_triangles(half, None);
    assert_eq!(plain.len(), marked.len());
    let mut sides = [0.0f32; 4];
    for (p, m) in plain.iter().zip(&marked) {
        assert_eq!((p.a, p.b, p.c), (m.a, m.b, m.c));
        assert_eq!(
            p.ids[3],
            m.ids[3] & 7,
            "the border bits are the plain mesh's"
        );
        for e in 0..3 {
            let (a, b, mark) = edge(m, e);
            if p.ids[3] & (1 << e) == 0 {
                assert_eq!(mark, 0, "an inner edge is no seam");
                continue;
            }
            let side = (mark - SEAM_SIDE) as usize;
            let on = [
                a.x == -half.x && b.x == -half.x,
                (a.x - half.x).abs() < 1e-6 && (b.x - half.x).abs() < 1e-6,
                a.y == -half.y && b.y == -half.y,
                (a.y - half.y).abs() < 1e-6 && (b.y - half.y).abs() < 1e-6,
            ];
            assert!(on[side], "edge {a} {b} marked side {side}");
            sides[side] += a.distance(b);
        }
    }
    // Each side's edges cover it once.
    for (s, want) in sides.iter().zip([3.0, 3.0, 5.0, 5.0]) {
        assert!((s - want).abs() < 1e-5, "{sides:?}");
    }
}

/// With a hole: no triangle inside it, the area less the hole's, and the hole's edges marked,
/// running once around its perimeter (computed by hand: 2 x (1.3 + 0.7) = 4 m).
#[test]
fn a_hole_is_cut_out_and_its_sides_are_marked() {
    let half = Vec2::new(2.5, 1.5);
    let hole = [-0.4, -0.25, 0.9, 0.45];
    let base = rectangle_triangles(half, Some(hole));
    let total: f32 = base.iter().map(area).sum();
    assert!((total - (15.0 - 1.3 * 0.7)).abs() < 1e-4, "area {total}");
    let mut perimeter = 0.0;
    for t in &base {
        let c = [t.a, t.b, t.c]
            .iter()
            .fold(Vec2::ZERO, |s, p| s + Vec2::new(p[0], p[2]))
            / 3.0;
        assert!(
            !(c.x > hole[0] && c.x < hole[2] && c.y > hole[1] && c.y < hole[3]),
            "a triangle at {c} inside the hole"
        );
        for e in 0..3 {
            let (a, b, mark) = edge(t, e);
            if mark == SEAM_HOLE {
                let on_x = [hole[0], hole[2]].iter().any(|&x| a.x == x && b.x == x);
                let on_z = [hole[1], hole[3]].iter().any(|&z| a.y == z && b.y == z);
                assert!(on_x || on_z, "hole edge {a} {b} off the hole's lines");
                perimeter += a.distance(b);
            }
        }
    }
    assert!((perimeter - 4.0).abs() < 1e-5, "perimeter {perimeter}");
    assert_borders_counted(&base);
}

/// The border bits, found from the grid, are those of counting each edge's uses
/// (`SurfaceMesh::base_triangles` on the same triangles).
fn assert_borders_counted(base: &[BaseTriangle]) {
    let n = base
        .iter()
        .flat_map(|t| &t.ids[..3])
        .max()
        .map_or(0, |&m| m + 1) as usize;
    let mut positions = vec![glam::Vec3::ZERO; n];
    for t in base {
        for (&id, p) in t.ids[..3].iter().zip([t.a, t.b, t.c]) {
            positions[id as usize] = glam::Vec3::new(p[0], p[1], p[2]);
        }
    }
    let mesh = SurfaceMesh {
        positions,
        triangles: base
            .iter()
            .map(|t| [t.ids[0], t.ids[1], t.ids[2]])
            .collect(),
    };
    for (ours, counted) in base.iter().zip(mesh.base_triangles()) {
        assert_eq!(ours.ids[3] & 7, counted.ids[3], "{ours:?}");
    }
}

/// A hole line within a millimetre of a cell line takes its place (no sliver cells); a hole past
/// the rectangle is clipped to it, and the clipped side is the rectangle's, not the hole's.
#[test]
fn hole_lines_near_cell_lines_replace_them_and_holes_are_clipped() {
    let half = Vec2::new(2.0, 2.0);
    // Cells of 1 m: lines at -2, -1, 0, 1, 2. The hole's x0 is 0.4 mm from -1.
    let base = rectangle_triangles(half, Some([-1.0004, -0.5, 3.0, 0.5]));
    let mut on_right = 0.0;
    for t in &base {
        assert!(area(t) > 1e-4, "a sliver {t:?}");
        for e in 0..3 {
            let (a, b, mark) = edge(t, e);
            if mark == SEAM_SIDE + 1 {
                on_right += a.distance(b);
            }
            if mark == SEAM_HOLE {
                assert!(
                    a.x < 1.9 || b.x < 1.9,
                    "the clipped side is marked the hole's"
                );
            }
        }
    }
    // The +x side is cut by the clipped hole: 4 m less its 1 m.
    assert!((on_right - 3.0).abs() < 1e-5, "{on_right}");
    assert_borders_counted(&base);
    let total: f32 = base.iter().map(area).sum();
    assert!((total - (16.0 - 3.0004)).abs() < 1e-3, "area {total}");
}

fn view(desc: &SurfaceDesc, id: u32, texels: u32, hole: Option<[f32; 4]>) -> SurfaceView<'_> {
    SurfaceView::for_test(desc, id, [texels; 2], hole)
}

/// A fine level is enclosed by the coarse level whose hole is its rectangle (inset by a quarter
/// texel, as the window sets it), not by one whose hole is elsewhere or turned.
#[test]
fn a_level_in_a_coarser_levels_hole_is_enclosed() {
    // Fine: 64 texels of 5 cm centred at (10, 20): x in [8.4, 11.6], z in [18.4, 21.6].
    let fine = SurfaceDesc::new("fine", [10.0, 0.0, 20.0], [3.2, 3.2], 0.2);
    // Coarse: centred at (9, 21); the fine rectangle in its frame is x in [-0.6, 2.6],
    // z in [-2.6, 0.6].
    let coarse = SurfaceDesc::new("coarse", [9.0, 0.0, 21.0], [12.8, 12.8], 0.2);
    let q = 0.25 * 0.05;
    let hole = [-0.6 + q, -2.6 + q, 2.6 - q, 0.6 - q];
    let f = view(&fine, 0, 64, None);
    let c = view(&coarse, 1, 64, Some(hole));
    assert!(enclosed(&f, &[&f, &c]));
    assert!(!enclosed(&c, &[&f, &c]), "the coarse level is in no hole");
    let elsewhere = view(&coarse, 1, 64, Some([0.0, 0.0, 3.2, 3.2]));
    assert!(!enclosed(&f, &[&elsewhere]));
    let turned = SurfaceDesc {
        yaw_degrees: 90.0,
        ..coarse.clone()
    };
    assert!(!enclosed(&f, &[&view(&turned, 1, 64, Some(hole))]));
    assert_eq!(seam_sides(true, [false; 4]), 0b1111);
    assert_eq!(seam_sides(false, [false, true, true, false]), 0b0110);
}
