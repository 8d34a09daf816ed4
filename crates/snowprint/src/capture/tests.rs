use super::*;
use proptest::prelude::*;

fn shape_of(kind: u8, a: f32, b: f32, c: f32) -> Shape {
    match kind {
        0 => Shape::Sphere { radius: a },
        1 => Shape::Capsule {
            radius: a,
            half_height: b,
        },
        _ => Shape::Box {
            half_extents: Vec3::new(a, b, c),
        },
    }
}

proptest! {
    /// The ball that rules a deformer out holds every primitive of its motion (their bounds,
    /// which the exact test reads): culling by it never leaves out what would be captured.
    #[test]
    fn the_swept_ball_holds_every_primitive(
        kind in 0u8..3,
        (a, b, c) in (0.01f32..2.0, 0.01f32..2.0, 0.01f32..2.0),
        from in prop::array::uniform3(-50.0f32..50.0),
        step in prop::array::uniform3(-3.0f32..3.0),
        (q0, q1) in (prop::array::uniform4(-1.0f32..1.0), prop::array::uniform4(-1.0f32..1.0)),
    ) {
        let rot = |q: [f32; 4]| {
            let q = glam::Quat::from_array(q);
            if q.length() < 1e-3 { glam::Quat::IDENTITY } else { q.normalize() }
        };
        let p0 = Pose { position: Vec3::from(from), rotation: rot(q0) };
        let p1 = Pose { position: Vec3::from(from) + Vec3::from(step), rotation: rot(q1) };
        let d = Deformer::moving(shape_of(kind, a, b, c), p0, p1);
        let everywhere = CaptureVolume {
            world_to_local: Mat4::IDENTITY,
            half_size: glam::Vec2::splat(1e4),
            frustum_height: 2e4,
            ground: (-1e4, 0.0),
        };
        let mut prims = Vec::new();
        push_primitives(&d, &everywhere, &mut prims);
        prop_assert!(!prims.is_empty());
        let (centre, radius) = swept_ball(&d).unwrap();
        for p in &prims {
            let (lo, hi) = p.bounds();
            prop_assert!(lo.cmpge(centre - radius).all() && hi.cmple(centre + radius).all(),
                "{lo} {hi} outside {centre} +- {radius}");
        }
    }
}

proptest! {
    /// The tiles listed are those of the capture region (the surface and its apron) whose cells
    /// the footprints (a texel wider) reach, cells taken with `floor` as the compute shader's
    /// texels are: every tile once, in the order the footprints reach them; then, when they are
    /// fewer than a ninth of the region's tiles, every tile beside one of those (its eight
    /// neighbours), once, in the reached tiles' order, and the region is not to be cleared.
    #[test]
    fn tiles_reached_are_the_tiles_the_footprints_cover(
        caps in prop::collection::vec(
            (prop::array::uniform3(-6.0f32..6.0), prop::array::uniform3(-6.0f32..6.0), 0.01f32..2.0),
            1..12,
        ),
        (w, h) in (1u32..300, 1u32..300),
        (hx, hz) in (0.5f32..5.0, 0.5f32..5.0),
    ) {
        let prims: Vec<GpuPrimitive> = caps
            .iter()
            .map(|&(a, b, r)| GpuPrimitive::capsule(Vec3::from(a), Vec3::from(b), r))
            .collect();
        let half = glam::Vec2::new(hx, hz);
        let (mut seen, mut work) = (Vec::new(), Vec::new());
        let sparse = tiles_reached(&prims, (w, h), half, 7, &mut seen, &mut work);
        let tile = crate::pool::TILE_SIDE;
        let texel = half * 2.0 / glam::Vec2::new(w as f32, h as f32);
        // Region cells: the surface's cell plus one, from column -1 (region 0) to w (region w + 1).
        let cell = |v: f32, h: f32, t: f32, n: u32| {
            (((v + h) / t).floor() as i64 + 1).clamp(0, n as i64 + 1) as u32
        };
        let reach = half + texel;
        let mut expected: Vec<[u32; 2]> = Vec::new();
        for p in &prims {
            let [x0, z0, x1, z1] = footprint(p);
            if x1 < -reach.x || z1 < -reach.y || x0 > reach.x || z0 > reach.y {
                continue;
            }
            let (c0, c1) = (cell(x0 - texel.x, half.x, texel.x, w), cell(x1 + texel.x, half.x, texel.x, w));
            let (r0, r1) = (cell(z0 - texel.y, half.y, texel.y, h), cell(z1 + texel.y, half.y, texel.y, h));
            for r in r0 / tile..=r1 / tile {
                for c in c0 / tile..=c1 / tile {
                    if !expected.contains(&[7, r << 16 | c]) {
                        expected.push([7, r << 16 | c]);
                    }
                }
            }
        }
        let (tiles_x, tiles_y) = ((w + 2).div_ceil(tile) as i64, (h + 2).div_ceil(tile) as i64);
        let reached = expected.len();
        for k in 0..reached {
            let (c, r) = ((expected[k][1] & 0xffff) as i64, (expected[k][1] >> 16) as i64);
            for (dr, dc) in (-1..=1).flat_map(|dr| (-1..=1).map(move |dc| (dr, dc))) {
                let (nr, nc) = (r + dr, c + dc);
                let entry = [7, (nr as u32) << 16 | nc as u32];
                if (0..tiles_y).contains(&nr) && (0..tiles_x).contains(&nc) && !expected.contains(&entry) {
                    expected.push(entry);
                }
            }
        }
        let beside = (expected.len() - reached) as i64;
        prop_assert_eq!(sparse, beside * 9 < tiles_x * tiles_y);
        if !sparse {
            expected.truncate(reached);
        }
        prop_assert_eq!(work, expected);
    }
}

/// The view and the primitive have the Rust side's sizes (`prims.wgsl` reads the view word by
/// word, in its fields' order; `tests/capture_paths.rs` holds it to the raster path).
#[test]
fn layouts_match_wgsl() {
    let module = naga::front::wgsl::parse_str(crate::wgsl::CAPTURE_PRIMS.source).unwrap();
    let mut layouter = naga::proc::Layouter::default();
    layouter.update(module.to_ctx()).unwrap();
    for (name, size) in [
        ("CaptureView", std::mem::size_of::<CaptureView>()),
        ("Primitive", std::mem::size_of::<GpuPrimitive>()),
    ] {
        let (handle, _) = module
            .types
            .iter()
            .find(|(_, t)| t.name.as_deref() == Some(name))
            .unwrap_or_else(|| panic!("{name} not in prims.wgsl"));
        assert_eq!(layouter[handle].size as usize, size, "{name}");
    }
}

#[test]
fn compact_packing_stays_near_the_area() {
    // 64 squares of 128: 1024 x 1024 holds them exactly.
    let rects = vec![(128, 128); 64];
    let (p, side) = pack_atlas_compact(&rects, 8192);
    assert_eq!(side, 1024);
    assert!(p.iter().all(|p| p.batch == 0));
    // Too many for the limit: several batches at the limit.
    let (p, side) = pack_atlas_compact(&[(512, 512); 20], 1024);
    assert_eq!(side, 1024);
    assert_eq!(p.iter().map(|p| p.batch).max(), Some(4));
}

#[test]
fn atlas_packing_never_overlaps() {
    let rects: Vec<(u32, u32)> = (0..300)
        .map(|i| (17 + (i * 37) % 500, 9 + (i * 53) % 400))
        .collect();
    let side = 1024;
    let p = pack_atlas(&rects, side);
    for (i, a) in p.iter().enumerate() {
        assert!(a.x + rects[i].0 <= side && a.y + rects[i].1 <= side);
        for (j, b) in p.iter().enumerate().skip(i + 1) {
            if a.batch != b.batch {
                continue;
            }
            let sep = a.x + rects[i].0 <= b.x
                || b.x + rects[j].0 <= a.x
                || a.y + rects[i].1 <= b.y
                || b.y + rects[j].1 <= a.y;
            assert!(sep, "{i} and {j} overlap");
        }
    }
}

#[test]
fn sweeping_sphere_is_one_capsule() {
    let vol = CaptureVolume {
        world_to_local: Mat4::IDENTITY,
        half_size: glam::Vec2::new(5.0, 5.0),
        frustum_height: 0.5,
        ground: (0.0, 0.0),
    };
    let d = Deformer::moving(
        Shape::Sphere { radius: 0.2 },
        Pose::at([-1.0, 0.1, 0.0]),
        Pose::at([1.0, 0.1, 0.0]),
    );
    let mut out = vec![];
    push_primitives(&d, &vol, &mut out);
    assert_eq!(
        out,
        vec![GpuPrimitive::capsule(
            Vec3::new(-1.0, 0.1, 0.0),
            Vec3::new(1.0, 0.1, 0.0),
            0.2
        )]
    );
    // Above the frustum: culled.
    let high = Deformer::new(Shape::Sphere { radius: 0.2 }, Pose::at([0.0, 0.71, 0.0]));
    out.clear();
    push_primitives(&high, &vol, &mut out);
    assert!(out.is_empty());
}

/// The update's tiles of a 64 x 64 surface of 1 m texels, worked by hand: a ball over texel (20,
/// 20)'s centre alone reaches tile (1, 1) only; one over texel (31, 20) reaches tiles (1, 1) and
/// (2, 1), whose blur reads texel 31 as its apron; one over the apron column 64 alone reaches tile
/// (3, 1); one beyond the apron reaches none. Each tile is listed once, where it is first reached.
#[test]
fn update_tiles_are_those_whose_blur_reads_a_reached_centre() {
    let at = |x: f32, z: f32| {
        let c = Vec3::new(-32.0 + x + 0.5, 0.0, -32.0 + z + 0.5);
        GpuPrimitive::capsule(c, c, 0.3)
    };
    let prims = [
        at(20.0, 20.0),
        at(31.0, 20.0),
        at(64.0, 20.0),
        at(66.0, 20.0),
    ];
    let half = glam::Vec2::splat(32.0);
    let (mut seen, mut list) = (Vec::new(), Vec::new());
    update_tiles_reached(&prims, (64, 64), half, 5, &mut seen, &mut list);
    let tile = |x: u32, y: u32| (y << 16) | x;
    assert_eq!(list, [[5, tile(1, 1)], [5, tile(2, 1)], [5, tile(3, 1)]]);
}

proptest! {
    /// Against every texel centre a tile's blur reads, tested one by one: the update lists every
    /// tile that reads a centre a footprint holds (the tile's texels and one around, the apron's
    /// included), and none that reads no centre of a footprint grown by two slivers; each once.
    #[test]
    fn update_tiles_are_those_that_read_a_centre_a_footprint_holds(
        caps in prop::collection::vec(
            (prop::array::uniform3(-4.0f32..4.0), prop::array::uniform3(-4.0f32..4.0), 0.01f32..1.0),
            1..8,
        ),
        (w, h) in (1u32..80, 1u32..80),
        (hx, hz) in (0.5f32..3.0, 0.5f32..3.0),
    ) {
        let prims: Vec<GpuPrimitive> = caps
            .iter()
            .map(|&(a, b, r)| GpuPrimitive::capsule(Vec3::from(a), Vec3::from(b), r))
            .collect();
        let half = glam::Vec2::new(hx, hz);
        let (mut seen, mut list) = (Vec::new(), Vec::new());
        update_tiles_reached(&prims, (w, h), half, 3, &mut seen, &mut list);
        let t = crate::pool::TILE_SIDE as i64;
        let (tx, ty) = ((w as i64 + t - 1) / t, (h as i64 + t - 1) / t);
        let texel = glam::DVec2::new(2.0 * hx as f64 / w as f64, 2.0 * hz as f64 / h as f64);
        // Whether a footprint grown by `grow` texels holds a centre of texels `range` of a side.
        let holds = |lo: f32, hi: f32, half: f32, t: f64, n: i64, range: std::ops::RangeInclusive<i64>, grow: f64| {
            range.filter(|x| (-1..=n).contains(x)).any(|x| {
                let c = -(half as f64) + (x as f64 + 0.5) * t;
                lo as f64 - grow * t <= c && c <= hi as f64 + grow * t
            })
        };
        for r in 0..ty {
            for c in 0..tx {
                let reads = |grow: f64| {
                    prims.iter().any(|p| {
                        let [x0, z0, x1, z1] = footprint(p);
                        holds(x0, x1, hx, texel.x, w as i64, c * t - 1..=c * t + t, grow)
                            && holds(z0, z1, hz, texel.y, h as i64, r * t - 1..=r * t + t, grow)
                    })
                };
                let n = list.iter().filter(|&&e| e == [3, ((r as u32) << 16) | c as u32]).count();
                prop_assert!(n <= 1, "tile ({}, {}) listed {} times", c, r, n);
                prop_assert!(!reads(0.0) || n == 1, "tile ({}, {}) missed", c, r);
                prop_assert!(reads(2.0 / 64.0) || n == 0, "tile ({}, {}) listed", c, r);
            }
        }
    }
}
