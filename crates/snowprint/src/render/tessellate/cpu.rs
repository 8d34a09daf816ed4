//! CPU references of the tessellated tier's passes: the bank field of `banks.wgsl` and the topology
//! of `dice.wgsl` (which points and triangles a base triangle is cut into for given edge levels).

use glam::Vec2;

use super::BankSettings;

/// Floor of the receptivity: the bottom of a trail still takes banks when nothing else is within
/// reach, so that no pushed snow is lost.
pub const RECEPTIVITY_FLOOR: f32 = crate::wgsl::consts::RECEPTIVITY_FLOOR;

/// How much bank snow a texel takes, by its (smoothed) depression: 1 on untouched snow, the floor
/// at the bottom of trails. Must match `receptivity` in `banks.wgsl`.
pub fn receptivity(depression: f32) -> f32 {
    let t = ((depression - 0.05) / (0.35 - 0.05)).clamp(0.0, 1.0);
    (1.0 - t * t * (3.0 - 2.0 * t)).max(RECEPTIVITY_FLOOR)
}

/// The bank kernel at an offset of `(dc, dr)` texels: `(1 - q)^2` with `q` the squared distance
/// over the squared bank width, 0 beyond. Must match `kernel` in `banks.wgsl`.
pub fn bank_kernel(dc: i32, dr: i32, texel: Vec2, radius: f32) -> f32 {
    let d = Vec2::new(dc as f32 * texel.x, dr as f32 * texel.y);
    let q = d.dot(d) / (radius * radius);
    if q >= 1.0 { 0.0 } else { (1.0 - q) * (1.0 - q) }
}

/// The bank heights (metres) of a `width x height` surface from its smoothed depression and its
/// displaced channel (fractions of the snow depth, row-major): every texel `y` gives
/// `fraction * displaced(y) * depth` away, spread over the texels `x` within the bank width in
/// proportion to `K(x - y) * receptivity(x)`. The sum of the result times the texel area is
/// therefore `fraction` times the pushed volume (`sum of displaced * depth * texel area`), up to
/// rounding. Must match `bank_norm` and `bank_gather` in `banks.wgsl`.
pub fn bank_field(
    width: u32,
    height: u32,
    depression: &[f32],
    displaced: &[f32],
    texel: Vec2,
    snow_depth: f32,
    banks: BankSettings,
) -> Vec<f32> {
    let (w, h) = (width as i32, height as i32);
    let reach_x = (banks.width / texel.x).floor() as i32;
    let reach_z = (banks.width / texel.y).floor() as i32;
    let at = |c: i32, r: i32| (r * w + c) as usize;
    let m: Vec<f32> = depression.iter().map(|&d| receptivity(d)).collect();
    let mut norm = vec![0.0f32; (w * h) as usize];
    for r in 0..h {
        for c in 0..w {
            let mut n = 0.0;
            for dr in -reach_z..=reach_z {
                for dc in -reach_x..=reach_x {
                    let (x, y) = (c + dc, r + dr);
                    if x >= 0 && y >= 0 && x < w && y < h {
                        n += bank_kernel(dc, dr, texel, banks.width) * m[at(x, y)];
                    }
                }
            }
            norm[at(c, r)] = n;
        }
    }
    let mut out = vec![0.0f32; (w * h) as usize];
    for r in 0..h {
        for c in 0..w {
            let mut sum = 0.0;
            for dr in -reach_z..=reach_z {
                for dc in -reach_x..=reach_x {
                    let (x, y) = (c + dc, r + dr);
                    if x >= 0 && y >= 0 && x < w && y < h {
                        let d = displaced[at(x, y)];
                        let k = bank_kernel(dc, dr, texel, banks.width);
                        if k > 0.0 && d > 0.0 {
                            sum += d * k / norm[at(x, y)].max(1e-6);
                        }
                    }
                }
            }
            out[at(c, r)] = banks.fraction * snow_depth * m[at(c, r)] * sum;
        }
    }
    out
}

/// A point of a diced base triangle, by how `dice.wgsl` places it: on an edge (the canonical edge
/// from the lower vertex id to the higher, and the step along it out of the edge's level), at a
/// corner, or inside (lattice coordinates of the triangle's inner level).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum DicedPoint {
    /// A corner of the base mesh (its vertex id).
    Corner(u32),
    /// Step `k` of `level` along the edge from vertex `from` to vertex `to` (`from < to`).
    Edge {
        /// Lower vertex id.
        from: u32,
        /// Higher vertex id.
        to: u32,
        /// Step from `from`.
        k: u32,
        /// The edge's level.
        level: u32,
    },
    /// Inner lattice point `(i, j)` of base triangle `triangle`.
    Inner {
        /// Which base triangle.
        triangle: u32,
        /// Steps towards the second corner.
        i: u32,
        /// Steps towards the third corner.
        j: u32,
    },
}

/// The top triangles `dice.wgsl` cuts one base triangle (vertex ids `ids`, index `triangle`) into
/// for edge levels `levels` (edges a-b, b-c, c-a), as points identified by how they are placed
/// (no skirts). Mirrors the shader's rings, lattice and stitched strips.
pub fn dice_triangle(triangle: u32, ids: [u32; 3], levels: [u32; 3]) -> Vec<[DicedPoint; 3]> {
    let most = levels.iter().copied().max().unwrap_or(1);
    if most == 1 {
        return vec![ids.map(DicedPoint::Corner)];
    }
    let n = most.max(3);
    let outer = |e: usize, k: u32| -> DicedPoint {
        let (s, u) = (ids[e], ids[(e + 1) % 3]);
        let l = levels[e];
        if k == 0 {
            DicedPoint::Corner(s)
        } else if k == l {
            DicedPoint::Corner(u)
        } else if s < u {
            DicedPoint::Edge {
                from: s,
                to: u,
                k,
                level: l,
            }
        } else {
            DicedPoint::Edge {
                from: u,
                to: s,
                k: l - k,
                level: l,
            }
        }
    };
    let inner = |i: u32, j: u32| DicedPoint::Inner { triangle, i, j };
    let side = |e: usize, m: u32| match e {
        0 => (1 + m, 1),
        1 => (n - 2 - m, 1 + m),
        _ => (1, n - 2 - m),
    };
    let mut out = Vec::new();
    for j in 1..=n.saturating_sub(3) {
        let ups = n - 2 - j;
        for i in 1..=ups {
            out.push([inner(i, j), inner(i + 1, j), inner(i, j + 1)]);
        }
        for i in 1..ups {
            out.push([inner(i + 1, j), inner(i + 1, j + 1), inner(i, j + 1)]);
        }
    }
    for (e, &l) in levels.iter().enumerate() {
        let m_count = n - 2;
        let (mut o, mut m) = (0u32, 0u32);
        while !(o == l && m + 1 == m_count) {
            let im = side(e, m);
            let advance_outer = m + 1 == m_count || (o < l && (o + 1) * 2 * n <= (2 * m + 5) * l);
            if advance_outer {
                out.push([outer(e, o), outer(e, o + 1), inner(im.0, im.1)]);
                o += 1;
            } else {
                let im1 = side(e, m + 1);
                out.push([outer(e, o), inner(im1.0, im1.1), inner(im.0, im.1)]);
                m += 1;
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::tessellate::SurfaceMesh;
    use std::collections::HashMap;

    /// Every combination of edge levels on a mesh of 8 triangles: each edge of the diced mesh is
    /// used twice, except on the border of the base mesh; the diced triangles' areas sum to the
    /// base mesh's; the counts are the shader's.
    #[test]
    fn diced_topology_is_conforming_for_any_levels() {
        let mesh = SurfaceMesh::rectangle(Vec2::new(1.0, 1.0));
        assert_eq!(mesh.triangles.len(), 8);
        let mut seed = 7u32;
        let mut rand = || {
            seed = seed.wrapping_mul(1664525).wrapping_add(1013904223);
            1 + (seed >> 8) % 13
        };
        for case in 0..60 {
            // A level per base edge, shared by both triangles.
            let mut level_of: HashMap<(u32, u32), u32> = HashMap::new();
            let mut diced = Vec::new();
            let mut inner_levels = Vec::new();
            for (ti, t) in mesh.triangles.iter().enumerate() {
                let levels = [0, 1, 2].map(|e| {
                    let key = (t[e].min(t[(e + 1) % 3]), t[e].max(t[(e + 1) % 3]));
                    *level_of
                        .entry(key)
                        .or_insert_with(|| if case == 0 { 1 } else { rand() })
                });
                let most = levels.iter().copied().max().unwrap();
                inner_levels.push(if most == 1 { 1 } else { most.max(3) });
                let tris = dice_triangle(ti as u32, *t, levels);
                let n = inner_levels[ti];
                let expected = if n == 1 {
                    1
                } else {
                    (n - 3) * (n - 3) + levels.iter().map(|l| l + n - 3).sum::<u32>()
                };
                assert_eq!(tris.len() as u32, expected, "case {case} triangle {ti}");
                diced.extend(tris);
            }
            let place = |p: DicedPoint| -> glam::DVec2 {
                let v = |id: u32| {
                    let q = mesh.positions[id as usize];
                    glam::DVec2::new(q.x as f64, q.z as f64)
                };
                match p {
                    DicedPoint::Corner(id) => v(id),
                    DicedPoint::Edge { from, to, k, level } => {
                        v(from).lerp(v(to), k as f64 / level as f64)
                    }
                    DicedPoint::Inner { triangle, i, j } => {
                        let t = mesh.triangles[triangle as usize];
                        let n = inner_levels[triangle as usize] as f64;
                        v(t[0]) * (1.0 - i as f64 / n - j as f64 / n)
                            + v(t[1]) * (i as f64 / n)
                            + v(t[2]) * (j as f64 / n)
                    }
                }
            };
            let mut edges: HashMap<(DicedPoint, DicedPoint), u32> = HashMap::new();
            let mut area = 0.0;
            for t in &diced {
                let [a, b, c] = t.map(place);
                // Counter-clockwise about +y, as the base triangles: negative in (x, z) axes.
                let signed = -(b - a).perp_dot(c - a);
                assert!(
                    signed > 1e-12,
                    "case {case}: a flipped or empty triangle {t:?}"
                );
                area += signed * 0.5;
                for e in 0..3 {
                    let (p, q) = (t[e], t[(e + 1) % 3]);
                    // Undirected, by a stable order of the placements.
                    let key = if format!("{p:?}") < format!("{q:?}") {
                        (p, q)
                    } else {
                        (q, p)
                    };
                    *edges.entry(key).or_insert(0) += 1;
                }
            }
            assert!((area - 4.0).abs() < 1e-9, "case {case}: area {area}");
            for ((p, q), uses) in edges {
                let (a, b) = (place(p), place(q));
                let on_border =
                    (a.x.abs() == 1.0 && b.x == a.x) || (a.y.abs() == 1.0 && b.y == a.y);
                assert_eq!(
                    uses,
                    if on_border { 1 } else { 2 },
                    "case {case}: edge {p:?}-{q:?}"
                );
            }
        }
    }

    #[test]
    fn banks_conserve_the_pushed_volume() {
        let (w, h) = (40u32, 30u32);
        let texel = Vec2::new(0.04, 0.05);
        let mut depression = vec![0.0; (w * h) as usize];
        let mut displaced = vec![0.0; (w * h) as usize];
        // A trench along x, to the ground, running off the surface's edge.
        for r in 12..17 {
            for c in 0..30 {
                depression[(r * w + c) as usize] = 1.0;
                displaced[(r * w + c) as usize] = 1.0;
            }
        }
        let banks = BankSettings {
            fraction: 0.4,
            width: 0.2,
        };
        let field = bank_field(w, h, &depression, &displaced, texel, 0.15, banks);
        let pushed: f32 = displaced.iter().sum::<f32>() * 0.15;
        let bank: f32 = field.iter().sum();
        assert!(
            (bank - 0.4 * pushed).abs() < 1e-4 * pushed,
            "{bank} vs {}",
            0.4 * pushed
        );
        // The banks stand beside the trench, not in it.
        let beside = field[(18 * w + 10) as usize];
        let inside = field[(14 * w + 10) as usize];
        assert!(beside > 0.02 && inside < 0.05 * beside, "{beside} {inside}");
    }
}
