//! CPU reference of the capture: the same maths as `write.wgsl` (both capture paths), evaluated at every texel centre.
//! Depth 0 is the ground, 1 the top of the frustum; 1 also means "nothing captured" (the clear value).
//! The capture covers a surface's capture region (its texels and the apron around them,
//! [`super::region`]): [`capture_region`] gives it whole, [`capture`] the surface's own texels.

use glam::{Vec2, Vec3, Vec3Swizzles};

use super::{GpuPrimitive, PRIM_CAPSULE};

const BIG: f32 = 1e30;

/// Local `(x, z)` of the centre of texel `(column, row)`.
pub fn texel_center(column: u32, row: u32, width: u32, height: u32, half_size: Vec2) -> Vec2 {
    // Same operations, in the same order, as `texel_center_of` in write.wgsl.
    let cell = Vec2::new(column as f32 + 0.5, row as f32 + 0.5);
    -half_size + cell / Vec2::new(width as f32, height as f32) * 2.0 * half_size
}

/// Local `(x, z)` of the centre of texel `(column, row)` of the capture region of a `width x
/// height` surface ([`super::region`]: the surface's texel `(column - 1, row - 1)`, one texel
/// beyond its sides in the apron).
pub fn region_texel_center(
    column: u32,
    row: u32,
    width: u32,
    height: u32,
    half_size: Vec2,
) -> Vec2 {
    // The region's cell centre less the apron, as `texel_center_of` in write.wgsl (exact in f32).
    let apron = super::APRON as f32;
    let cell = Vec2::new(column as f32 + 0.5 - apron, row as f32 + 0.5 - apron);
    -half_size + cell / Vec2::new(width as f32, height as f32) * 2.0 * half_size
}

/// Same stable form as `sphere_interval` in capture.wgsl: `(c.y -+ r) +- d^2 / (r + s)`.
fn sphere_interval(c: Vec3, r: f32, x: f32, z: f32) -> (f32, f32) {
    let (dx, dz) = (x - c.x, z - c.z);
    let d2 = dx * dx + dz * dz;
    let d = d2.sqrt();
    if d > r {
        return (BIG, -BIG);
    }
    let s = ((r - d) * (r + d)).sqrt();
    let sag = d2 / (r + s);
    ((c.y - r) + sag, (c.y + r) - sag)
}

/// Heights where the vertical line through `(x, z)` is inside the capsule; empty when `lo > hi`.
pub fn capsule_interval(a: Vec3, b: Vec3, r: f32, x: f32, z: f32) -> (f32, f32) {
    let ia = sphere_interval(a, r, x, z);
    let ib = sphere_interval(b, r, x, z);
    let mut iv = (ia.0.min(ib.0), ia.1.max(ib.1));
    let ab = b - a;
    let len = ab.length();
    if len > 1e-6 {
        let u = ab / len;
        let w = Vec3::new(x, 0.0, z) - a;
        let wu = w.dot(u);
        let e_perp = Vec3::Y - u.y * u;
        let w_perp = w - wu * u;
        let qa = e_perp.dot(e_perp);
        if qa > 1e-6 {
            let qb = e_perp.dot(w_perp);
            let qc = w_perp.dot(w_perp) - r * r;
            let disc = qb * qb - qa * qc;
            if disc >= 0.0 {
                // Same stable form as capture.wgsl.
                let sq = disc.sqrt();
                let q = -(qb + if qb >= 0.0 { sq } else { -sq });
                let r0 = q / qa;
                let r1 = if q == 0.0 { r0 } else { qc / q };
                let (mut y0, mut y1) = (r0.min(r1), r0.max(r1));
                if u.y.abs() > 1e-6 {
                    let ya = -wu / u.y;
                    let yb = (len - wu) / u.y;
                    y0 = y0.max(ya.min(yb));
                    y1 = y1.min(ya.max(yb));
                } else if wu < 0.0 || wu > len {
                    (y0, y1) = (BIG, -BIG);
                }
                if y0 <= y1 {
                    iv = (iv.0.min(y0), iv.1.max(y1));
                }
            }
        }
    }
    iv
}

/// Heights where the vertical line through `(x, z)` is inside the box; empty when `lo > hi`.
pub fn box_interval(p: &GpuPrimitive, x: f32, z: f32) -> (f32, f32) {
    let c = Vec3::from_slice(&p.p0[..3]);
    let o = Vec3::new(x, 0.0, z) - c;
    let (mut lo, mut hi) = (-BIG, BIG);
    for axis in [p.p1, p.p2, p.p3] {
        let a = Vec3::from_slice(&axis[..3]);
        let (oi, ei, h) = (o.dot(a), a.y, axis[3]);
        if ei.abs() < 1e-7 {
            if oi.abs() > h {
                return (BIG, -BIG);
            }
        } else {
            let (t1, t2) = ((-h - oi) / ei, (h - oi) / ei);
            lo = lo.max(t1.min(t2));
            hi = hi.min(t1.max(t2));
        }
    }
    (lo, hi)
}

/// Depth one primitive leaves at local `(x, z)`, or `None` where it leaves nothing.
pub fn primitive_depth(p: &GpuPrimitive, x: f32, z: f32, frustum_height: f32) -> Option<f32> {
    let (lo, hi) = if p.kind[0] == PRIM_CAPSULE {
        capsule_interval(
            Vec3::from_slice(&p.p0[..3]),
            Vec3::from_slice(&p.p1[..3]),
            p.p0[3],
            x,
            z,
        )
    } else {
        box_interval(p, x, z)
    };
    if lo > hi || hi < 0.0 || lo >= frustum_height {
        return None;
    }
    Some(lo.max(0.0) / frustum_height)
}

/// A triangle in surface-local coordinates, counter-clockwise seen from outside its solid.
pub type LocalTriangle = [Vec3; 3];

/// What a triangle contributes at local `(x, z)`, as the mesh capture does: `Some((height, enters))`
/// where the vertical line through `(x, z)` crosses it, `enters` when the face is turned down (the
/// line enters the solid there going up).
pub fn triangle_crossing(t: &LocalTriangle, x: f32, z: f32) -> Option<(f32, bool)> {
    let [a, b, c] = *t;
    let p = Vec2::new(x, z);
    let (a2, b2, c2) = (a.xz(), b.xz(), c.xz());
    let area = (b2 - a2).perp_dot(c2 - a2);
    if area.abs() < 1e-12 {
        return None;
    }
    let w0 = (c2 - b2).perp_dot(p - b2) / area;
    let w1 = (a2 - c2).perp_dot(p - c2) / area;
    let w2 = 1.0 - w0 - w1;
    if w0 < 0.0 || w1 < 0.0 || w2 < 0.0 {
        return None;
    }
    let y = w0 * a.y + w1 * b.y + w2 * c.y;
    let normal_y = (b - a).cross(c - a).y;
    Some((y, normal_y < 0.0))
}

/// Depth closed meshes leave at local `(x, z)`: 0 where the ground point is inside a solid (the
/// signed count of crossings below the ground is positive), else the lowest entering crossing in
/// the frustum, or `None`.
pub fn triangles_depth(
    triangles: &[LocalTriangle],
    x: f32,
    z: f32,
    frustum_height: f32,
) -> Option<f32> {
    let mut winding = 0i32;
    let mut lowest: Option<f32> = None;
    for t in triangles {
        let Some((y, enters)) = triangle_crossing(t, x, z) else {
            continue;
        };
        if y < 0.0 {
            winding += if enters { 1 } else { -1 };
        } else if enters && y <= frustum_height {
            lowest = Some(lowest.map_or(y, |l: f32| l.min(y)));
        }
    }
    if winding > 0 {
        return Some(0.0);
    }
    lowest.map(|y| y / frustum_height)
}

/// Reference capture of a surface: `width * height` depths, row-major, 1 where nothing was seen
/// (its capture region without the apron: [`capture_region`]).
pub fn capture(
    width: u32,
    height: u32,
    half_size: Vec2,
    frustum_height: f32,
    primitives: &[GpuPrimitive],
    triangles: &[LocalTriangle],
) -> Vec<f32> {
    capture_on_ground(
        width,
        height,
        half_size,
        frustum_height,
        primitives,
        triangles,
        None,
    )
}

/// Reference capture of a surface's capture region ([`super::region`]: `(width + 2) x (height +
/// 2)` depths, row-major, the surface's texels and the apron of one texel around them), what the
/// update's blur reads ([`crate::accumulate::cpu::blur`]).
pub fn capture_region(
    width: u32,
    height: u32,
    half_size: Vec2,
    frustum_height: f32,
    primitives: &[GpuPrimitive],
    triangles: &[LocalTriangle],
) -> Vec<f32> {
    capture_on_ground_region(
        width,
        height,
        half_size,
        frustum_height,
        primitives,
        triangles,
        None,
    )
}

/// Depth a column of snow on ground that is not flat takes from a solid occupying heights
/// `(lo, hi)` (local metres) over its texel: the column rises from `base`, its lowest `bare` metres
/// are rock. A solid that reaches into the rock presses the snow to the ground (depth
/// `bare / frustum_height`), one wholly in the rock or above the frustum leaves nothing.
pub fn column_depth(
    (lo, hi): (f32, f32),
    base: f32,
    bare: f32,
    frustum_height: f32,
) -> Option<f32> {
    let ground = base + bare;
    if lo > hi || hi < ground || lo >= base + frustum_height {
        return None;
    }
    Some((lo.max(ground) - base) / frustum_height)
}

/// [`capture`] on a ground field: `columns` holds `[base, bare]` per texel (see
/// [`crate::GroundField`]), `None` for flat ground. Written from the solids' intervals in local
/// metres (not by shifting them as the shader does).
pub fn capture_on_ground(
    width: u32,
    height: u32,
    half_size: Vec2,
    frustum_height: f32,
    primitives: &[GpuPrimitive],
    triangles: &[LocalTriangle],
    columns: Option<&[[f32; 2]]>,
) -> Vec<f32> {
    let region = capture_on_ground_region(
        width,
        height,
        half_size,
        frustum_height,
        primitives,
        triangles,
        columns,
    );
    super::strip_apron(width, height, &region)
}

/// [`capture_region`] on a ground field: `columns` holds `[base, bare]` per texel of the surface
/// (`width * height`; the apron's are extrapolated from them, [`apron_columns`]), `None` for flat
/// ground.
pub fn capture_on_ground_region(
    width: u32,
    height: u32,
    half_size: Vec2,
    frustum_height: f32,
    primitives: &[GpuPrimitive],
    triangles: &[LocalTriangle],
    columns: Option<&[[f32; 2]]>,
) -> Vec<f32> {
    let columns = columns.map(|c| apron_columns(c, width, height));
    let (rw, rh) = super::region(width, height);
    let mut out = vec![1.0f32; (rw * rh) as usize];
    for row in 0..rh {
        for col in 0..rw {
            let i = (row * rw + col) as usize;
            let c = region_texel_center(col, row, width, height, half_size);
            let mut d = 1.0f32;
            let Some(columns) = columns.as_deref() else {
                for p in primitives {
                    if let Some(v) = primitive_depth(p, c.x, c.y, frustum_height) {
                        d = d.min(v);
                    }
                }
                if let Some(v) = triangles_depth(triangles, c.x, c.y, frustum_height) {
                    d = d.min(v);
                }
                out[i] = d;
                continue;
            };
            let [base, bare] = columns[i];
            for p in primitives {
                let iv = if p.kind[0] == PRIM_CAPSULE {
                    let (a, b) = (Vec3::from_slice(&p.p0[..3]), Vec3::from_slice(&p.p1[..3]));
                    capsule_interval(a, b, p.p0[3], c.x, c.y)
                } else {
                    box_interval(p, c.x, c.y)
                };
                if let Some(v) = column_depth(iv, base, bare, frustum_height) {
                    d = d.min(v);
                }
            }
            if let Some(v) = triangles_depth_on(triangles, c.x, c.y, base, bare, frustum_height) {
                d = d.min(v);
            }
            out[i] = d;
        }
    }
    out
}

/// The `[base, bare]` columns of a surface's capture region from its own `width * height`: the
/// apron's ground one texel beyond each side, extrapolated linearly from the two texels at that
/// side (`2 a - b`, along x first, then along z, from the x-extended rows), the bare depth kept at
/// 0 or more; a side of one texel repeats it. Written on its own from `ground_of` in `write.wgsl`
/// (and `GroundField::region_columns`, which lays the ground's capture codes out the same way).
pub fn apron_columns(columns: &[[f32; 2]], width: u32, height: u32) -> Vec<[f32; 2]> {
    let (w, h) = (width as usize, height as usize);
    let beyond = |p: f32, q: f32| 2.0 * p - q;
    // One line of a field extended by a texel at both ends.
    let extend = |line: &[[f32; 2]]| -> Vec<[f32; 2]> {
        let n = line.len();
        let (first, last) = if n > 1 {
            (
                [
                    beyond(line[0][0], line[1][0]),
                    beyond(line[0][1], line[1][1]),
                ],
                [
                    beyond(line[n - 1][0], line[n - 2][0]),
                    beyond(line[n - 1][1], line[n - 2][1]),
                ],
            )
        } else {
            (line[0], line[0])
        };
        std::iter::once(first)
            .chain(line.iter().copied())
            .chain(std::iter::once(last))
            .collect()
    };
    let rows: Vec<Vec<[f32; 2]>> = columns.chunks(w).take(h).map(extend).collect();
    let mut out = vec![[0.0f32; 2]; (w + 2) * (h + 2)];
    for x in 0..w + 2 {
        let column: Vec<[f32; 2]> = rows.iter().map(|r| r[x]).collect();
        for (y, c) in extend(&column).into_iter().enumerate() {
            out[y * (w + 2) + x] = [c[0], c[1].max(0.0)];
        }
    }
    out
}

/// [`triangles_depth`] over a column rising from `base` with `bare` metres of rock.
fn triangles_depth_on(
    triangles: &[LocalTriangle],
    x: f32,
    z: f32,
    base: f32,
    bare: f32,
    frustum_height: f32,
) -> Option<f32> {
    let mut winding = 0i32;
    let mut lowest: Option<f32> = None;
    for t in triangles {
        let Some((y, enters)) = triangle_crossing(t, x, z) else {
            continue;
        };
        if y < base + bare {
            winding += if enters { 1 } else { -1 };
        } else if enters && y <= base + frustum_height {
            lowest = Some(lowest.map_or(y, |l: f32| l.min(y)));
        }
    }
    if winding > 0 {
        // A contained ground point is pressed to the ground, the bare depth above the base.
        return Some(bare / frustum_height);
    }
    lowest.map(|y| (y - base) / frustum_height)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn capsule_matches_sphere_when_degenerate() {
        let c = Vec3::new(0.0, 1.0, 0.0);
        let (lo, hi) = capsule_interval(c, c, 0.5, 0.3, 0.0);
        let s = (0.25f32 - 0.09).sqrt();
        assert!((lo - (1.0 - s)).abs() < 1e-6 && (hi - (1.0 + s)).abs() < 1e-6);
    }

    #[test]
    fn horizontal_capsule_bottom_is_analytic() {
        // Capsule along x from -1 to 1 at height 0.4, radius 0.3: at x = 0.5, z = 0.1 the lowest
        // point is 0.4 - sqrt(0.09 - 0.01).
        let (lo, _) = capsule_interval(
            Vec3::new(-1.0, 0.4, 0.0),
            Vec3::new(1.0, 0.4, 0.0),
            0.3,
            0.5,
            0.1,
        );
        assert!((lo - (0.4 - 0.08f32.sqrt())).abs() < 1e-6, "{lo}");
        // Slanted capsule, vertical line through its middle: the cylinder part.
        let (lo, hi) = capsule_interval(
            Vec3::new(-1.0, 0.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            0.2,
            0.0,
            0.0,
        );
        // Distance from (0, y, 0) to the axis line through (0, 0.5, 0) with direction (2, 1)/sqrt5
        // is |y - 0.5| * 2 / sqrt5, equal to 0.2 at |y - 0.5| = 0.1 * sqrt5.
        let d = 0.1 * 5f32.sqrt();
        assert!(
            (lo - (0.5 - d)).abs() < 1e-5 && (hi - (0.5 + d)).abs() < 1e-5,
            "{lo} {hi}"
        );
    }

    #[test]
    fn rotated_box_interval() {
        // A cube of half side 0.5 turned 45 degrees about z: a vertical line through x = 0 meets it
        // from -sqrt(0.5) to +sqrt(0.5) around the centre height.
        let r = glam::Quat::from_rotation_z(std::f32::consts::FRAC_PI_4);
        let p = GpuPrimitive::oriented_box(
            Vec3::new(0.0, 1.0, 0.0),
            [r * Vec3::X, r * Vec3::Y, r * Vec3::Z],
            Vec3::splat(0.5),
        );
        let (lo, hi) = box_interval(&p, 0.0, 0.2);
        let s = 0.5f32.sqrt();
        assert!(
            (lo - (1.0 - s)).abs() < 1e-5 && (hi - (1.0 + s)).abs() < 1e-5,
            "{lo} {hi}"
        );
    }

    /// The apron's ground on a plane is the plane one texel beyond (to rounding), the bare depth
    /// held; the production layout of the ground's codes (`GroundField::region_columns`) extends
    /// a field as this reference does, bit for bit, on a plane and on a bumpy field.
    #[test]
    fn the_apron_extends_a_plane_and_matches_the_ground_codes_layout() {
        let (w, h) = (5u32, 4u32);
        let plane = |x: f32, y: f32| [0.3 * x - 0.2 * y, 0.05];
        let bumpy = |x: f32, y: f32| {
            [
                (x * 1.3).sin() + (y * 0.7).cos(),
                0.04 * (x + y).sin().abs(),
            ]
        };
        for f in [plane, bumpy] {
            let columns: Vec<[f32; 2]> = (0..h)
                .flat_map(|y| (0..w).map(move |x| f(x as f32, y as f32)))
                .collect();
            let ours = apron_columns(&columns, w, h);
            let field = crate::GroundField {
                width: w,
                height: h,
                ground: vec![0.0; (w * h) as usize],
                columns: columns.clone(),
            };
            let bits = |v: &[[f32; 2]]| v.iter().flatten().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&ours), bits(&field.region_columns()));
            assert_eq!(crate::capture::strip_apron(w, h, &ours), columns);
        }
        let columns: Vec<[f32; 2]> = (0..h)
            .flat_map(|y| (0..w).map(move |x| plane(x as f32, y as f32)))
            .collect();
        let ours = apron_columns(&columns, w, h);
        for y in 0..h + 2 {
            for x in 0..w + 2 {
                let want = plane(x as f32 - 1.0, y as f32 - 1.0);
                let got = ours[(y * (w + 2) + x) as usize];
                assert!(
                    (got[0] - want[0]).abs() < 1e-6 && (got[1] - want[1]).abs() < 1e-6,
                    "({x}, {y}): {got:?} against {want:?}"
                );
            }
        }
    }

    #[test]
    fn sunk_sphere_clamps_to_its_ground_cross_section() {
        // Centre 0.3 below the ground, radius 0.5: cross-section at the ground has radius 0.4.
        let p = GpuPrimitive::capsule(Vec3::new(0.0, -0.3, 0.0), Vec3::new(0.0, -0.3, 0.0), 0.5);
        assert_eq!(primitive_depth(&p, 0.39, 0.0, 0.5), Some(0.0));
        assert_eq!(primitive_depth(&p, 0.41, 0.0, 0.5), None);
    }
}
