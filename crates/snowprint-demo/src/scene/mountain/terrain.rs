//! The mountain's valley: its ground as a function of position, the frozen lake, the rock outcrop
//! steep enough to stand bare, and the meshes drawn from it (the valley floor beyond the snow,
//! trees, rocks and the cabin with its pitched roof).

use glam::{Vec2, Vec3};
use snowprint::{GroundMesh, HeightGrid, Mesh, SurfaceDesc};

/// The frozen lake: centre (x, z), radius, and its ice level, metres.
pub const LAKE: (Vec2, f32) = (Vec2::new(-14.0, 12.0), 11.0);
/// The rock outcrop: centre (x, z); its sides pass 60 degrees, so they hold no snow.
pub const OUTCROP: Vec2 = Vec2::new(22.0, -18.0);
/// The cabin: centre of its floor (x, z), half its sides (x, z), wall height, ridge height above
/// the walls. Its ridge runs along x.
pub const CABIN: (Vec2, Vec2, f32, f32) = (Vec2::new(6.0, 20.0), Vec2::new(3.0, 2.2), 2.6, 1.5);

fn smoothstep(e0: f32, e1: f32, x: f32) -> f32 {
    let t = ((x - e0) / (e1 - e0)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// The valley before the lake and the cabin's pad are cut into it: a bowl rising to the ridges,
/// rolling hills and the outcrop.
fn raw_height(p: Vec2) -> f32 {
    let r2 = p.length_squared();
    let bowl = 9.0 * (1.0 - (-r2 / (2.0 * 55.0 * 55.0)).exp());
    let hills = 1.1 * (0.11 * p.x + 0.5).sin() * (0.09 * p.y).cos()
        + 0.45 * (0.23 * p.x - 0.31 * p.y + 1.3).sin();
    let d2 = (p - OUTCROP).length_squared();
    let outcrop = 6.0 * (-d2 / 6.0).exp();
    bowl + hills + outcrop
}

/// The ice's level: the raw ground at the lake's rim, less half a metre.
pub fn lake_level() -> f32 {
    raw_height(LAKE.0 + Vec2::new(LAKE.1, 0.0)) - 0.5
}

/// Ground height at world `(x, z)`, metres: the valley, flattened to the ice inside the lake and to
/// a level pad under the cabin.
pub fn height(p: Vec2) -> f32 {
    let mut h = raw_height(p);
    let lake = smoothstep(LAKE.1 - 2.0, LAKE.1 + 2.0, (p - LAKE.0).length());
    h = lake_level() + (h - lake_level()) * lake;
    let (c, half, _, _) = CABIN;
    let d = ((p - c).abs() - half - Vec2::splat(1.0))
        .max(Vec2::ZERO)
        .length();
    let pad = smoothstep(0.0, 3.0, d);
    let level = raw_height(c);
    level + (h - level) * pad
}

/// Whether world `(x, z)` lies on the lake's ice.
pub fn on_lake(p: Vec2) -> bool {
    (p - LAKE.0).length() < LAKE.1 - 2.0
}

/// The ground under a surface as a grid of one sample per texel (exact at the texel centres), in
/// the surface's local metres (relative to its centre's height; surfaces here are not yawed).
pub fn grid_under(desc: &SurfaceDesc) -> HeightGrid {
    let l = desc.layout();
    let texel = desc.size / Vec2::new(l.width as f32, l.height as f32);
    let origin = Vec2::new(desc.center.x, desc.center.z) - desc.size * 0.5;
    let mut heights = Vec::with_capacity((l.width * l.height) as usize);
    for r in 0..l.height {
        for c in 0..l.width {
            let p = origin + (Vec2::new(c as f32, r as f32) + 0.5) * texel;
            heights.push(height(p) - desc.center.y);
        }
    }
    HeightGrid {
        columns: l.width,
        rows: l.height,
        heights,
    }
}

/// The valley floor as a mesh over `half` metres around the origin, `step` metres a quad, lowered
/// by `drop` (so that it lies under the snow where snow is drawn).
pub fn floor_mesh(half: f32, step: f32, drop: f32) -> Mesh {
    let n = (2.0 * half / step).round() as u32;
    let mut positions = Vec::with_capacity(((n + 1) * (n + 1)) as usize);
    for r in 0..=n {
        for c in 0..=n {
            let p = Vec2::new(-half + c as f32 * step, -half + r as f32 * step);
            positions.push(Vec3::new(p.x, height(p) - drop, p.y));
        }
    }
    let mut indices = Vec::with_capacity((n * n * 6) as usize);
    for r in 0..n {
        for c in 0..n {
            let i = r * (n + 1) + c;
            let (a, b, d, e) = (i, i + 1, i + n + 1, i + n + 2);
            // Counter-clockwise seen from above (+y).
            indices.extend_from_slice(&[a, d, b, b, d, e]);
        }
    }
    Mesh { positions, indices }
}

/// The cabin's roof: two planes from the eaves (a little past the walls) to the ridge along x, as
/// triangles in world metres (the roof's snow lies on them), and the roof's highest point.
pub fn roof_triangles() -> (GroundMesh, f32) {
    let (c, half, wall, rise) = CABIN;
    let base = raw_height(c) + wall;
    let over = 0.4;
    let (x0, x1) = (c.x - half.x - over, c.x + half.x + over);
    let (z0, z1) = (c.y - half.y - over, c.y + half.y + over);
    // The planes rise `rise` over the walls' half depth; the eaves overhang by `over`.
    let slope = rise / half.y;
    let eave = base - over * slope;
    let ridge = base + rise;
    let v = |x: f32, y: f32, z: f32| Vec3::new(x, y, z);
    let (a0, a1) = (v(x0, eave, z0), v(x1, eave, z0));
    let (r0, r1) = (v(x0, ridge, c.y), v(x1, ridge, c.y));
    let (b0, b1) = (v(x0, eave, z1), v(x1, eave, z1));
    let triangles = vec![[a0, r0, a1], [a1, r0, r1], [r0, b0, r1], [r1, b0, b1]];
    (GroundMesh { triangles }, ridge)
}

/// A small deterministic hash of an integer to [0, 1).
pub fn hash(i: u32) -> f32 {
    let mut x = i.wrapping_mul(0x9E37_79B9) ^ 0x85EB_CA6B;
    x ^= x >> 16;
    x = x.wrapping_mul(0x7FEB_352D);
    x ^= x >> 15;
    (x >> 8) as f32 / (1u32 << 24) as f32
}

/// Where trees stand: a stand on the slope north of the lake and a scatter up the valley's sides,
/// off the lake, the cabin, the outcrop and the hiker's loop (`clear`).
pub fn tree_spots(clear: impl Fn(Vec2) -> bool) -> Vec<(Vec2, f32)> {
    let mut spots = Vec::new();
    let mut k = 0u32;
    while spots.len() < 60 && k < 2000 {
        let (u, v, s) = (hash(3 * k), hash(3 * k + 1), hash(3 * k + 2));
        k += 1;
        let p = if spots.len() < 24 {
            // The stand: a patch around (-30, 30).
            Vec2::new(-30.0, 32.0) + Vec2::new(u - 0.5, v - 0.5) * 22.0
        } else {
            let a = u * std::f32::consts::TAU;
            let r = 42.0 + 20.0 * v;
            Vec2::new(a.cos(), a.sin()) * r
        };
        let near = |q: Vec2, d: f32| (p - q).length() < d;
        if near(LAKE.0, LAKE.1 + 2.0) || near(CABIN.0, 6.0) || near(OUTCROP, 5.0) || !clear(p) {
            continue;
        }
        if spots
            .iter()
            .any(|&(q, _): &(Vec2, f32)| (q - p).length() < 2.5)
        {
            continue;
        }
        spots.push((p, 0.75 + 0.5 * s));
    }
    spots
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_lake_is_flat_ice_and_the_outcrop_steep() {
        let l = lake_level();
        for p in [LAKE.0, LAKE.0 + Vec2::new(5.0, -3.0)] {
            assert!((height(p) - l).abs() < 1e-4);
        }
        // Half a metre below its rim: the ice lies in a hollow.
        assert!(height(LAKE.0 + Vec2::new(LAKE.1 + 2.5, 0.0)) > l + 0.3);
        // The outcrop's flank at 2 m from its top rises more than 60 degrees.
        let e = 0.01;
        let p = OUTCROP + Vec2::new(2.0, 0.0);
        let slope = (height(p + Vec2::X * e) - height(p - Vec2::X * e)) / (2.0 * e);
        assert!(slope.abs().atan().to_degrees() > 60.0, "{slope}");
        // The cabin's pad is level.
        let (c, half, _, _) = CABIN;
        assert!((height(c + half) - height(c - half)).abs() < 1e-4);
    }

    #[test]
    fn the_roof_rises_to_its_ridge() {
        let (roof, ridge) = roof_triangles();
        assert_eq!(roof.triangles.len(), 4);
        let top = roof
            .triangles
            .iter()
            .flatten()
            .map(|v| v.y)
            .fold(f32::MIN, f32::max);
        assert!((top - ridge).abs() < 1e-5);
        // 1.5 m over 2.2 m: 34 degrees, under the 35 that keep the whole snow.
        let (_, half, _, rise) = CABIN;
        assert!((rise / half.y).atan().to_degrees() < 35.0);
    }
}
