//! CPU references of the snow material's maths, in the same form as `snow.wgsl` and
//! `heightfield.wgsl`, so that each can be tested against the talk's formula or an analytic answer.
//!
//! - [`rnm`]: Reoriented Normal Mapping [Barré-Brisebois & Hill 2012], the talk's normal blend.
//! - [`slab_exit`], [`linear_taps`], [`relief_search`], [`pom_search`]: the ray through the snow
//!   slab of a surface (surface-local metres) and the two searches of the relief-mapped path.
//! - [`sobel_normal`], [`horizon_ao`]: what the heightfield pass derives from a heightmap.
//!
//! The heightfield is given as a function from local `(x, z)` to the snow's height above the
//! ground, in metres. A ray point is *inside* the snow when its height is at most that plus
//! [`INSIDE_EPSILON`].

use glam::{Vec2, Vec3};

/// Slack of the inside test, metres (must match `SNOW_EPSILON` in `snow.wgsl`).
pub const INSIDE_EPSILON: f32 = 1e-4;

/// Reoriented Normal Mapping: the detail normal `detail` re-expressed around the base normal
/// `base`, both unit tangent-space normals with `+z` up (unpacked to `[-1, 1]`). This is the talk's
/// formula: `t = n1 + (0,0,1); u = n2 * (-1,-1,1); r = normalize(t * dot(t,u) / t.z - u)`.
/// It equals rotating `detail` by the rotation that takes `(0,0,1)` to `base`.
/// Must match `snow_rnm` in `snow.wgsl`.
pub fn rnm(base: Vec3, detail: Vec3) -> Vec3 {
    let t = base + Vec3::Z;
    let u = detail * Vec3::new(-1.0, -1.0, 1.0);
    (t * t.dot(u) / t.z - u).normalize()
}

/// The talk's HLSL form of RNM, taking texel values in `[0, 1]` as stored in normal maps:
/// `t = base * (2,2,2) + (-1,-1,0); u = detail * (-2,-2,2) + (1,1,-1); r = t * dot(t,u) / t.z - u`
/// (normalized here).
pub fn rnm_packed(base_texel: Vec3, detail_texel: Vec3) -> Vec3 {
    let t = base_texel * 2.0 + Vec3::new(-1.0, -1.0, 0.0);
    let u = detail_texel * Vec3::new(-2.0, -2.0, 2.0) + Vec3::new(1.0, 1.0, -1.0);
    (t * t.dot(u) / t.z - u).normalize()
}

/// A ray in surface-local metres: `origin + dir * t`, `dir` of unit length.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SlabRay {
    /// Where the ray enters the slab (a point on the box drawn for the surface).
    pub origin: Vec3,
    /// Unit direction, away from the eye.
    pub dir: Vec3,
}

impl SlabRay {
    /// The point at parameter `t`.
    pub fn at(&self, t: f32) -> Vec3 {
        self.origin + self.dir * t
    }
}

/// Where a ray leaves the snow slab `|x| <= half.x, |z| <= half.y, 0 <= y <= depth`:
/// `(t, reaches_ground)`. Must match `snow_slab_exit` in `snow.wgsl`, whose slab top is
/// `snow_top`: the snow depth, plus the room for rims of a material that throws them (pass that
/// sum as `depth`).
pub fn slab_exit(ray: &SlabRay, half: Vec2, depth: f32) -> (f32, bool) {
    let (o, d) = (ray.origin, ray.dir);
    let mut t = f32::MAX;
    let mut ground = false;
    if d.y < 0.0 {
        t = o.y / -d.y;
        ground = true;
    } else if d.y > 0.0 {
        t = (depth - o.y) / d.y;
    }
    for (oc, dc, h) in [(o.x, d.x, half.x), (o.z, d.z, half.y)] {
        if dc != 0.0 {
            let tc = ((if dc > 0.0 { h } else { -h }) - oc) / dc;
            if tc < t {
                t = tc;
                ground = false;
            }
        }
    }
    (t.max(0.0), ground)
}

/// Linear taps of a search over `t_max` metres of ray: `density` taps per heightmap texel crossed
/// horizontally, clamped to `[min, max]`. This is how the talk's "relief mapping parameters scaled
/// with the heightmap resolution" is done here: a ray looking straight down crosses no texel and
/// takes `min` taps, a grazing one takes more. Must match `snow_linear_taps` in `snow.wgsl`.
pub fn linear_taps(dir: Vec3, t_max: f32, texel: f32, density: f32, min: f32, max: f32) -> u32 {
    let travel = Vec2::new(dir.x, dir.z).length() * t_max / texel;
    (travel * density).ceil().clamp(min, max) as u32
}

/// The most linear taps on a surface whose box spans `terrain` (lowest base, highest untouched top;
/// `None` on flat ground) under snow `snow_depth` deep: the tier's `max`, times the times the box
/// is taller than the snow, at most [`TERRAIN_TAPS`]. Must match `snow_max_taps` in `snow.wgsl`.
pub fn max_taps(max: f32, terrain: Option<(f32, f32)>, snow_depth: f32) -> f32 {
    let Some((low, top)) = terrain else {
        return max;
    };
    let tall = ((top - low) / snow_depth).max(1.0);
    (max * tall).ceil().min(TERRAIN_TAPS.max(max))
}

/// The most linear taps a ray over ground that is not flat takes (`SNOW_TERRAIN_TAPS`).
pub const TERRAIN_TAPS: f32 = 192.0;

fn inside(height: &impl Fn(Vec2) -> f32, ray: &SlabRay, t: f32) -> bool {
    let p = ray.at(t);
    p.y <= height(Vec2::new(p.x, p.z)) + INSIDE_EPSILON
}

/// Relief mapping [Policarpo & Oliveira 2006]: `taps` equal linear steps from the entry to `t_max`
/// find the first tap inside the snow; `refine` binary steps then halve the bracket. Returns the
/// hit's `t` (the bracket's middle), or `None` when the ray leaves the slab without entering the
/// snow. With one crossing in the bracket the error is at most `t_max / taps / 2^(refine + 1)`.
/// Must match `snow_relief_search` in `snow.wgsl`.
pub fn relief_search(
    height: impl Fn(Vec2) -> f32,
    ray: &SlabRay,
    t_max: f32,
    taps: u32,
    refine: u32,
) -> Option<f32> {
    if inside(&height, ray, 0.0) {
        return Some(0.0);
    }
    let dt = t_max / taps as f32;
    let mut lo = 0.0;
    let mut hi = -1.0;
    for i in 1..=taps {
        let t = dt * i as f32;
        if inside(&height, ray, t) {
            hi = t;
            break;
        }
        lo = t;
    }
    if hi < 0.0 {
        return None;
    }
    for _ in 0..refine {
        let mid = 0.5 * (lo + hi);
        if inside(&height, ray, mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    Some(0.5 * (lo + hi))
}

/// Parallax occlusion mapping: the same linear taps, then the crossing of the straight line through
/// the last tap above the snow and the first below it, repeated `refine` times on the bracket that
/// keeps the crossing (false position): exact for a planar heightfield, always within the bracket
/// `t_max / taps`, and converging fast on a smooth one (without it, the layers of the linear taps
/// show as bands on the walls of prints). Must match `snow_pom_search` in `snow.wgsl`.
pub fn pom_search(
    height: impl Fn(Vec2) -> f32,
    ray: &SlabRay,
    t_max: f32,
    taps: u32,
    refine: u32,
) -> Option<f32> {
    // Signed height of the ray over the snow, minus the slack: <= 0 means inside.
    let above = |t: f32| {
        let p = ray.at(t);
        p.y - height(Vec2::new(p.x, p.z)) - INSIDE_EPSILON
    };
    let f0 = above(0.0);
    if f0 <= 0.0 {
        return Some(0.0);
    }
    let dt = t_max / taps as f32;
    let (mut lo, mut f_lo) = (0.0, f0);
    for i in 1..=taps {
        let t = dt * i as f32;
        let f = above(t);
        if f <= 0.0 {
            let (mut hi, mut f_hi) = (t, f);
            let mut x = lo + (hi - lo) * f_lo / (f_lo - f_hi);
            for _ in 0..refine {
                let fx = above(x);
                if fx <= 0.0 {
                    hi = x;
                    f_hi = fx;
                } else {
                    lo = x;
                    f_lo = fx;
                }
                x = lo + (hi - lo) * f_lo / (f_lo - f_hi);
            }
            return Some(x);
        }
        lo = t;
        f_lo = f;
    }
    None
}

/// The depression at a texel smoothed by a 3x3 binomial filter (`[1 2 1] x [1 2 1] / 16`), as the
/// heightfield pass stores it: the capture's binary coverage leaves texel staircases on the rims of
/// pits pressed to the ground, which this keeps out of the picture. Must match
/// `smoothed_depression` in `heightfield.wgsl`.
pub fn smoothed_depression(depression: impl Fn(i32, i32) -> f32, col: i32, row: i32) -> f32 {
    let mut sum = 0.0;
    for dy in -1..=1i32 {
        for dx in -1..=1i32 {
            sum += ((2 - dx.abs()) * (2 - dy.abs())) as f32 * depression(col + dx, row + dy);
        }
    }
    sum / 16.0
}

/// The displaced-snow channel of a pool texel (what the captures pushed deeper, accumulated; in
/// units of `1 / channel_max` at the pool's precision) as a fraction of the snow depth, as the
/// heightfield pass writes it into the light texture's `.g`. Must match `displaced` in
/// `heightfield.wgsl`.
pub fn displaced_fraction(units: u32, precision: crate::pool::Precision) -> f32 {
    units as f32 / precision.channel_max() as f32
}

/// Normal of the snow top from the depressions around a texel, by a 3x3 Sobel filter (smoother
/// than central differences, which matters at 4 cm texels). `depression(col, row)` is the fraction
/// of the snow depth pressed down (clamped at the edges by the caller). Returns a unit local normal.
/// Must match `sobel_normal` in `heightfield.wgsl`.
pub fn sobel_normal(
    depression: impl Fn(i32, i32) -> f32,
    col: i32,
    row: i32,
    snow_depth: f32,
    texel: Vec2,
) -> Vec3 {
    let h = |dx: i32, dy: i32| -depression(col + dx, row + dy) * snow_depth;
    let gx = (h(1, -1) + 2.0 * h(1, 0) + h(1, 1)) - (h(-1, -1) + 2.0 * h(-1, 0) + h(-1, 1));
    let gz = (h(-1, 1) + 2.0 * h(0, 1) + h(1, 1)) - (h(-1, -1) + 2.0 * h(0, -1) + h(1, -1));
    let dhdx = gx / (8.0 * texel.x);
    let dhdz = gz / (8.0 * texel.y);
    Vec3::new(-dhdx, 1.0, -dhdz).normalize()
}

/// Width of the soft shadow's penumbra per metre travelled towards the light, and at the start.
/// Penumbra width per metre from the occluder.
pub const PENUMBRA_SLOPE: f32 = crate::wgsl::consts::PENUMBRA_SLOPE;
/// See [`PENUMBRA_SLOPE`].
pub const PENUMBRA_BASE: f32 = crate::wgsl::consts::PENUMBRA_BASE;
/// Most taps of [`light_visibility`].
pub const LIGHT_TAPS: u32 = crate::wgsl::consts::LIGHT_TAPS;

/// How much of a light in local direction `light` (unit, pointing to the light) reaches the snow
/// at local `(x, z)`: march from the snow there up to the top of the slab, a tap per texel crossed
/// (at most [`LIGHT_TAPS`]); each tap compares the ray's height with the snow's, over a penumbra
/// that widens with the distance travelled (`0.5 + (ray - snow) / (2 * width)`, clamped), and the
/// darkest tap wins. 1 in the open, 0 at the bottom of a print the light cannot see into.
/// `height(x, z)` is the snow's height above the ground in metres. Must match `light_visibility`
/// in `heightfield.wgsl`.
pub fn light_visibility(
    height: impl Fn(f32, f32) -> f32,
    x: f32,
    z: f32,
    light: Vec3,
    snow_depth: f32,
    texel: f32,
) -> f32 {
    if light.y <= 0.02 {
        return 0.0;
    }
    let h0 = height(x, z);
    let t_top = (snow_depth - h0) / light.y;
    if t_top <= 0.0 {
        return 1.0;
    }
    let across = Vec2::new(light.x, light.z).length() * t_top / texel;
    let taps = across.ceil().clamp(1.0, LIGHT_TAPS as f32) as u32;
    let mut visible = 1.0f32;
    for i in 1..=taps {
        let t = t_top * i as f32 / taps as f32;
        let p = Vec3::new(x, h0, z) + light * t;
        let width = PENUMBRA_BASE + PENUMBRA_SLOPE * t;
        let v = (0.5 + (p.y - height(p.x, p.z)) / (2.0 * width)).clamp(0.0, 1.0);
        visible = visible.min(v);
    }
    visible
}

/// Directions of the horizon search of [`horizon_ao`].
pub const AO_DIRECTIONS: usize = crate::wgsl::consts::AO_DIRECTIONS as usize;
/// Radii of the horizon search, metres (must match `AO_RADII` in `heightfield.wgsl`): prints are
/// 10-30 cm across, so the occluders that matter lie within 30 cm.
pub const AO_RADII: [f32; 4] = [0.04, 0.09, 0.16, 0.28];

/// Ambient occlusion derived from the heightmap (the talk's open question, answered the way
/// horizon-based AO does it): in each of 8 directions, the sine of the highest elevation angle of
/// the snow around the texel; the visible sky is one minus their mean. Untouched snow gets 1, the
/// bottom of a narrow trench much less. `height(x, z)` is the snow height in metres at a local
/// offset from the texel. Must match `horizon_ao` in `heightfield.wgsl`.
pub fn horizon_ao(height: impl Fn(f32, f32) -> f32) -> f32 {
    let h0 = height(0.0, 0.0);
    let mut sum = 0.0;
    for k in 0..AO_DIRECTIONS {
        let a = std::f32::consts::TAU * k as f32 / AO_DIRECTIONS as f32;
        let (sx, sz) = (a.cos(), a.sin());
        let mut best = 0.0f32;
        for r in AO_RADII {
            let dh = height(sx * r, sz * r) - h0;
            best = best.max(dh / (dh * dh + r * r).sqrt());
        }
        sum += best;
    }
    1.0 - sum / AO_DIRECTIONS as f32
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Quat;

    fn close(a: Vec3, b: Vec3, tol: f32) -> bool {
        (a - b).abs().max_element() <= tol
    }

    /// Unit normals spread over the upper hemisphere (no grazing ones: normal maps have z > 0).
    fn normals() -> Vec<Vec3> {
        let mut v = Vec::new();
        for i in 0..12 {
            for j in 0..6 {
                let phi = std::f32::consts::TAU * i as f32 / 12.0;
                let theta = 1.3 * j as f32 / 6.0;
                v.push(Vec3::new(
                    theta.sin() * phi.cos(),
                    theta.sin() * phi.sin(),
                    theta.cos(),
                ));
            }
        }
        v
    }

    #[test]
    fn rnm_flat_detail_returns_the_base() {
        for n in normals() {
            assert!(close(rnm(n, Vec3::Z), n, 1e-5), "{n}");
        }
    }

    #[test]
    fn rnm_flat_base_returns_the_detail() {
        for n in normals() {
            assert!(close(rnm(Vec3::Z, n), n, 1e-5), "{n}");
        }
    }

    #[test]
    fn rnm_is_the_rotation_of_the_detail_onto_the_base() {
        for base in normals() {
            let q = Quat::from_rotation_arc(Vec3::Z, base);
            for detail in normals() {
                let r = rnm(base, detail);
                assert!(
                    close(r, q * detail, 2e-5),
                    "base {base} detail {detail}: {r} vs {}",
                    q * detail
                );
            }
        }
    }

    #[test]
    fn rnm_packed_form_of_the_talk_matches() {
        let pack = |n: Vec3| n * 0.5 + Vec3::splat(0.5);
        for base in normals() {
            for detail in normals().into_iter().step_by(5) {
                assert!(close(
                    rnm_packed(pack(base), pack(detail)),
                    rnm(base, detail),
                    1e-5
                ));
            }
        }
    }

    #[test]
    fn rnm_keeps_detail_that_linear_blending_flattens() {
        // Two equal tilts: RNM tilts twice as far; a lerp stays at the single tilt.
        let n = Vec3::new(0.5f32.sin(), 0.0, 0.5f32.cos());
        let r = rnm(n, n);
        assert!((r.x.asin() - 1.0).abs() < 1e-4, "{r}");
        let lerp = (n + n).normalize();
        assert!((lerp.x.asin() - 0.5).abs() < 1e-4);
    }

    const HALF: Vec2 = Vec2::new(2.0, 1.5);
    const DEPTH: f32 = 0.3;

    fn ray(origin: Vec3, dir: Vec3) -> SlabRay {
        SlabRay {
            origin,
            dir: dir.normalize(),
        }
    }

    #[test]
    fn slab_exit_finds_ground_and_sides() {
        let r = ray(Vec3::new(0.0, DEPTH, 0.0), Vec3::new(0.0, -1.0, 0.0));
        let (t, g) = slab_exit(&r, HALF, DEPTH);
        assert!((t - DEPTH).abs() < 1e-6 && g);
        let r = ray(Vec3::new(1.9, DEPTH, 0.0), Vec3::new(1.0, -0.1, 0.0));
        let (t, g) = slab_exit(&r, HALF, DEPTH);
        assert!(!g && (r.at(t).x - 2.0).abs() < 1e-5);
    }

    /// A tilted plane of snow: height = a + b x. The ray meets it where
    /// o.y + t d.y = a + b (o.x + t d.x).
    fn plane_case(dir: Vec3) -> (impl Fn(Vec2) -> f32, SlabRay, f32) {
        let (a, b) = (0.15, 0.04);
        let h = move |p: Vec2| a + b * p.x;
        let r = ray(Vec3::new(-1.0, DEPTH, 0.2), dir);
        let exact = (a + b * r.origin.x - r.origin.y) / (r.dir.y - b * r.dir.x);
        (h, r, exact)
    }

    #[test]
    fn relief_search_meets_an_analytic_plane_within_its_bound() {
        for dir in [
            Vec3::new(1.0, -0.3, 0.2),
            Vec3::new(0.3, -1.0, -0.1),
            Vec3::new(2.0, -0.25, 1.0),
        ] {
            let (h, r, exact) = plane_case(dir);
            let (t_max, _) = slab_exit(&r, HALF, DEPTH);
            for (taps, refine) in [(4, 5), (8, 5), (16, 3), (12, 6)] {
                let t = relief_search(&h, &r, t_max, taps, refine)
                    .expect("the plane is inside the slab");
                // One crossing in the bracket: at most half the last bracket, plus the slack of the
                // inside test measured along the ray.
                let bound = t_max / taps as f32 / 2f32.powi(refine as i32 + 1)
                    + INSIDE_EPSILON / (r.dir.y - 0.04 * r.dir.x).abs();
                assert!(
                    (t - exact).abs() <= bound * 1.001,
                    "{dir} {taps}/{refine}: {t} vs {exact}, bound {bound}"
                );
            }
        }
    }

    #[test]
    fn pom_search_is_exact_on_a_plane() {
        for dir in [
            Vec3::new(1.0, -0.3, 0.2),
            Vec3::new(0.3, -1.0, -0.1),
            Vec3::new(2.0, -0.25, 1.0),
        ] {
            let (h, r, exact) = plane_case(dir);
            let (t_max, _) = slab_exit(&r, HALF, DEPTH);
            let t = pom_search(&h, &r, t_max, 8, 0).expect("hit");
            // The secant of a linear function is exact; the slack shifts it by eps / |d(above)/dt|.
            let bound = INSIDE_EPSILON / (r.dir.y - 0.04 * r.dir.x).abs() + 1e-5;
            assert!((t - exact).abs() <= bound, "{dir}: {t} vs {exact}");
        }
    }

    /// A ball of radius R pressed k into the snow leaves a spherical dent; a ray entering the top
    /// inside the dent's rim leaves the ball (and meets the snow) at the larger root of
    /// |o + t d - c|^2 = R^2.
    fn dent_case(dir: Vec3) -> (impl Fn(Vec2) -> f32, SlabRay, f32) {
        let (radius, k) = (0.25f32, 0.2f32);
        let c = Vec3::new(0.3, DEPTH + radius - k, -0.2);
        let h = move |p: Vec2| {
            let r2 = (p - Vec2::new(c.x, c.z)).length_squared();
            if r2 >= radius * radius {
                DEPTH
            } else {
                DEPTH.min(c.y - (radius * radius - r2).sqrt())
            }
        };
        let r = ray(Vec3::new(0.25, DEPTH, -0.15), dir);
        let oc = r.origin - c;
        let b = oc.dot(r.dir);
        let disc = b * b - (oc.length_squared() - radius * radius);
        let exact = -b + disc.sqrt();
        (h, r, exact)
    }

    #[test]
    fn relief_and_pom_meet_an_analytic_sphere_dent() {
        for dir in [
            Vec3::new(0.4, -1.0, 0.1),
            Vec3::new(1.0, -0.7, -0.3),
            Vec3::new(-0.3, -1.0, 0.6),
        ] {
            let (h, r, exact) = dent_case(dir);
            let p = r.at(exact);
            assert!(
                p.y > 0.0 && p.y < DEPTH,
                "the case must hit the dent floor: {p}"
            );
            let (t_max, _) = slab_exit(&r, HALF, DEPTH);
            // Near the hit the ray crosses the dent floor at an angle: the inside slack moves the
            // hit by at most eps / |d(above)/dt|, bounded here by eps / 0.1.
            let slack = INSIDE_EPSILON / 0.1;
            for taps in [6u32, 12, 24] {
                let t = relief_search(&h, &r, t_max, taps, 5).expect("hit");
                let bound = t_max / taps as f32 / 64.0 + slack;
                assert!(
                    (t - exact).abs() <= bound,
                    "relief {dir} {taps}: {t} vs {exact} (bound {bound})"
                );
                let t = pom_search(&h, &r, t_max, taps, 0).expect("hit");
                // The secant lies inside the bracket of one tap.
                let bound = t_max / taps as f32 + slack;
                assert!(
                    (t - exact).abs() <= bound,
                    "pom {dir} {taps}: {t} vs {exact} (bound {bound})"
                );
                // False position keeps the crossing bracketed and closes in on it: three steps
                // land within a hundredth of a tap here (the dent is smooth at the crossing).
                let refined = pom_search(&h, &r, t_max, taps, 3).expect("hit");
                let bound = t_max / taps as f32 * 0.01 + slack;
                assert!(
                    (refined - exact).abs() <= bound,
                    "pom+3 {dir} {taps}: {refined} vs {exact} (bound {bound})"
                );
            }
        }
    }

    #[test]
    fn untouched_snow_is_hit_at_the_entry_and_an_open_edge_is_missed() {
        let flat = |_: Vec2| DEPTH;
        let r = ray(Vec3::new(0.0, DEPTH, 0.0), Vec3::new(1.0, -0.5, 0.0));
        assert_eq!(relief_search(flat, &r, 1.0, 8, 5), Some(0.0));
        assert_eq!(pom_search(flat, &r, 1.0, 8, 3), Some(0.0));
        // A trench open at the +x edge: the ray leaves through the side without meeting snow.
        let trench = |p: Vec2| if p.x > 1.0 { 0.0 } else { DEPTH };
        let r = ray(Vec3::new(1.5, DEPTH, 0.0), Vec3::new(1.0, -0.2, 0.0));
        let (t_max, ground) = slab_exit(&r, HALF, DEPTH);
        assert!(!ground);
        assert_eq!(relief_search(trench, &r, t_max, 8, 5), None);
        assert_eq!(pom_search(trench, &r, t_max, 8, 3), None);
    }

    #[test]
    fn taps_scale_with_texels_crossed() {
        let down = Vec3::new(0.0, -1.0, 0.0);
        assert_eq!(linear_taps(down, 0.3, 0.04, 0.5, 4.0, 16.0), 4);
        let grazing = Vec3::new(1.0, -0.2, 0.0).normalize();
        // 0.3 m of snow at this angle: 1.5 m across, 37.5 texels of 4 cm, a tap every 2 texels.
        assert_eq!(
            linear_taps(grazing, 0.3 / 0.2f32.atan().sin(), 0.04, 0.5, 4.0, 32.0),
            19
        );
        assert_eq!(linear_taps(grazing, 10.0, 0.04, 0.5, 4.0, 16.0), 16);
        // On ground: a box 6.3 m tall over 0.3 m of snow is 21 times the snow, so the relief
        // tier's 12 taps become 252, held to 192; a box no taller than the snow keeps 12.
        assert_eq!(max_taps(12.0, None, 0.3), 12.0);
        assert_eq!(max_taps(12.0, Some((-1.0, 5.3)), 0.3), 192.0);
        assert_eq!(max_taps(12.0, Some((0.0, 0.9)), 0.3), 36.0);
        assert_eq!(max_taps(12.0, Some((0.1, 0.3)), 0.3), 12.0);
    }

    #[test]
    fn smoothing_keeps_flat_snow_and_ramps_and_rounds_a_step() {
        assert!((smoothed_depression(|_, _| 0.4, 3, 3) - 0.4).abs() < 1e-6);
        let ramp = |c: i32, _r: i32| 0.1 * c as f32;
        assert!((smoothed_depression(ramp, 5, 2) - 0.5).abs() < 1e-6);
        // A staircase corner: a quarter of the plane pressed to the ground.
        let corner = |c: i32, r: i32| if c >= 0 && r >= 0 { 1.0 } else { 0.0 };
        assert_eq!(smoothed_depression(corner, 0, 0), 9.0 / 16.0);
        assert_eq!(smoothed_depression(corner, -1, -1), 1.0 / 16.0);
    }

    #[test]
    fn sobel_normal_of_a_ramp() {
        // Depression rising 0.1 per column: the snow falls 0.03 m per 4 cm texel.
        let dep = |c: i32, _r: i32| 0.1 * c as f32;
        let n = sobel_normal(dep, 5, 5, 0.3, Vec2::splat(0.04));
        let slope = 0.03 / 0.04;
        assert!(
            close(n, Vec3::new(slope, 1.0, 0.0).normalize(), 1e-5),
            "{n}"
        );
    }

    #[test]
    fn light_reaches_flat_snow_and_not_the_bottom_of_a_trench() {
        let light = Vec3::new(0.8, 0.45, 0.0).normalize();
        assert_eq!(
            light_visibility(|_, _| 0.2, 0.0, 0.0, light, 0.2, 0.04),
            1.0
        );
        // A trench 0.4 m wide and 0.18 m deep along z: its floor near the wall towards the light
        // sees the wall (dark); the wall facing the light and the far floor are lit.
        let trench = |x: f32, _z: f32| if x.abs() < 0.2 { 0.02 } else { 0.2 };
        let near_wall = light_visibility(trench, 0.12, 0.0, light, 0.2, 0.04);
        assert!(near_wall < 0.05, "{near_wall}");
        // Far from the wall that casts the shadow: the ray rises 0.18 m within 0.32 m, clear.
        let open = light_visibility(trench, -0.19, 0.0, light, 0.2, 0.04);
        assert!(open > near_wall, "{open}");
        // The moon below the horizon lights nothing.
        assert_eq!(
            light_visibility(|_, _| 0.2, 0.0, 0.0, Vec3::new(1.0, -0.1, 0.0), 0.2, 0.04),
            0.0
        );
    }

    #[test]
    fn horizon_ao_of_flat_snow_and_a_trench() {
        assert_eq!(horizon_ao(|_, _| 0.3), 1.0);
        // The bottom of a 10 cm wide, 25 cm deep trench along z: half the directions see walls.
        let ao = horizon_ao(|x, _| if x.abs() < 0.05 { 0.05 } else { 0.3 });
        assert!(ao < 0.5 && ao > 0.2, "{ao}");
        // A shallow, wide dent darkens less.
        let shallow = horizon_ao(|x, _| if x.abs() < 0.2 { 0.27 } else { 0.3 });
        assert!(shallow > ao && shallow < 1.0, "{shallow}");
    }
}
