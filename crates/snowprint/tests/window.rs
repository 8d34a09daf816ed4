//! A terrain's sliding window (`Terrain`, `window/`): a walker leaves the near level's window and
//! comes back to find its trail as a window that never scrolled keeps it; a scroll by k columns
//! writes exactly the entering strip's bytes and nothing else in the pool; wrapped and unwrapped
//! storage give the same logical heightmap; the far level keeps the trail's broad shape after the
//! near one paged it out; a level on hills moves its ground field as laying it whole at the new
//! origin would, bit for bit, writing only its part of the ground buffers; a level and a surface
//! beside it draw untouched as one surface over both; refusals in one sentence.

mod common;

use glam::Vec3;
use snowprint::{
    Deformer, LevelDesc, Material, PoolFormat, Pose, Precision, Shape, SnowError, SnowWorld,
    Terrain, TerrainDesc, WorldConfig,
};

const DEPTH: f32 = 0.3;

fn world(precision: Precision) -> SnowWorld {
    let config = WorldConfig {
        format: PoolFormat::new(precision),
        ..WorldConfig::default()
    };
    SnowWorld::new(common::gpu(), config).expect("world")
}

fn terrain(name: &str, levels: &[([u32; 2], f32)]) -> TerrainDesc {
    TerrainDesc {
        name: name.into(),
        ground_height: 1.0,
        ground: None,
        snow_depth: DEPTH,
        replenish_rate: 0.0,
        material: Material::snow(),
        levels: levels
            .iter()
            .map(|&(texels, texel_size)| LevelDesc { texels, texel_size })
            .collect(),
    }
}

/// A foot: a 6 cm ball pressed 15 cm into the snow at world (x, z).
fn foot(x: f32, z: f32) -> Deformer {
    Deformer::new(
        Shape::Sphere { radius: 0.06 },
        Pose::at([x, 1.0 + DEPTH - 0.15 + 0.06, z]),
    )
}

/// The walker's prints: left and right of a line along x, one a frame.
fn walk() -> Vec<Deformer> {
    (0..40)
        .map(|i| foot(0.3 + i as f32 * 0.07, if i % 2 == 0 { 0.1 } else { -0.1 }))
        .collect()
}

/// Depression channel of a level, logical order, by world texel.
fn by_world(
    w: &SnowWorld,
    t: &Terrain,
    level: usize,
) -> std::collections::HashMap<(i64, i64), u32> {
    let id = t.surfaces()[level];
    let l = w.layout(id).unwrap();
    let (dep, _) = w.read_channels(id).unwrap();
    let o = t.origin(level).unwrap();
    let mut m = std::collections::HashMap::new();
    for y in 0..l.height {
        for x in 0..l.width {
            m.insert(
                (o[0] + x as i64, o[1] + y as i64),
                dep[(y * l.width + x) as usize],
            );
        }
    }
    m
}

/// The walker prints its trail while a camera a little behind it is the near window's focus; the
/// camera then goes 12 m away (the near window pages the trail out and rewrites itself twice
/// over) and comes back. The trail it finds is texel for texel the trail of a window large enough
/// never to scroll, and without the page store it would be gone.
#[test]
fn a_walker_leaves_the_window_and_finds_its_trail_texel_for_texel() {
    let (mut w, mut big) = (world(Precision::Bits16), world(Precision::Bits16));
    let near = [([64, 48], 0.05)];
    let mut t = Terrain::new(&mut w, terrain("valley", &near), Vec3::ZERO).unwrap();
    let never = Terrain::new(
        &mut big,
        terrain("valley", &[([256, 64], 0.05)]),
        Vec3::new(2.0, 0.0, 0.0),
    )
    .unwrap();
    for d in walk() {
        let camera = d.pose.position - Vec3::new(0.3, 0.0, 0.0);
        t.follow(&mut w, camera).unwrap();
        w.step(1.0 / 60.0, std::slice::from_ref(&d)).unwrap();
        big.step(1.0 / 60.0, std::slice::from_ref(&d)).unwrap();
    }
    assert_eq!(never.stats().scrolls, 0);
    let reference = by_world(&big, &never, 0);
    assert!(
        t.scrolls_in_flight() <= 2,
        "readbacks pile up: {}",
        t.scrolls_in_flight()
    );
    for x in [6.0f32, 12.0, 6.0, 1.5] {
        t.follow(&mut w, Vec3::new(x, 0.0, 0.0)).unwrap();
        w.step(1.0 / 60.0, &[]).unwrap();
    }
    let back = by_world(&w, &t, 0);
    let (mut compared, mut pressed) = (0, 0);
    for (texel, &v) in &back {
        let r = reference[texel];
        assert_eq!(
            v, r,
            "world texel {texel:?}: {v} after the walk out and back, {r} in the window that never scrolled"
        );
        compared += 1;
        pressed += (r > 0) as u32;
    }
    assert_eq!(compared, 64 * 48);
    assert!(
        pressed > 200,
        "only {pressed} texels of the trail were compared"
    );
    let s = t.stats();
    assert!(s.texels_paged_in >= pressed as u64, "{s:?}");
    println!("walk out and back: {compared} texels compared, {pressed} pressed, {s:?}");
}

/// A scroll by k columns writes k x rows texels' bytes, counted by the GPU as it stores them, at
/// every precision; in the pool, only the entering strip's storage changed.
#[test]
fn scrolling_by_k_columns_writes_exactly_the_entering_strip() {
    for (p, texel_bytes) in [
        (Precision::Bits8, 2u64),
        (Precision::Bits16, 4),
        (Precision::Bits32, 8),
    ] {
        let mut w = world(p);
        let (cols, rows) = (64u32, 48u32);
        let mut t = Terrain::new(
            &mut w,
            terrain("strip", &[([cols, rows], 0.05)]),
            Vec3::ZERO,
        )
        .unwrap();
        let id = t.surfaces()[0];
        // Press the whole window so that fresh snow entering shows.
        let slab = Deformer::new(
            Shape::Box {
                half_extents: Vec3::new(2.0, 0.1, 2.0),
            },
            Pose::at([0.0, 1.2, 0.0]),
        );
        w.step(1.0 / 60.0, &[slab]).unwrap();
        let before = w.read_packed(id).unwrap();
        let wrap0 = w.wrap(id).unwrap();
        for k in [2u32, 6] {
            let focus = Vec3::new(k as f32 * 0.05, 0.0, 0.0);
            let packed = w.read_packed(id).unwrap();
            t.follow(&mut w, focus).unwrap();
            // Nothing waited: the scroll's readback lands at the next call or at flush.
            assert_eq!(t.scrolls_in_flight(), 1);
            t.flush(&mut w).unwrap();
            assert_eq!(t.scrolls_in_flight(), 0);
            let written = t.last_bytes_written();
            assert_eq!(
                written,
                k as u64 * rows as u64 * texel_bytes,
                "{p}: scroll by {k} columns"
            );
            let after = w.read_packed(id).unwrap();
            let changed = packed.iter().zip(&after).filter(|(a, b)| a != b).count();
            // The pressed texels of the strip came back as fresh snow; nothing else moved.
            let words_a_column = match p {
                Precision::Bits8 => rows as usize / 2,
                Precision::Bits16 => rows as usize,
                Precision::Bits32 => 2 * rows as usize,
            };
            assert_eq!(changed, k as usize * words_a_column, "{p}: {k}");
            // Back at once: the strips that enter are those still on their way, so this waits.
            t.follow(&mut w, Vec3::ZERO).unwrap();
        }
        t.flush(&mut w).unwrap();
        // Back where it started: the same storage, the same offsets, every texel as before.
        assert_eq!(w.wrap(id).unwrap(), wrap0);
        assert_eq!(w.read_packed(id).unwrap(), before, "{p}");
        let s = t.stats();
        assert_eq!(s.bytes_written, s.texels_in * texel_bytes, "{p}: {s:?}");
    }
}

/// The same walk on a level stored wrapped (offsets (13, 7) after a scroll) and on an ordinary
/// surface of the same rectangle and layout: the same logical heightmap bit for bit, and the
/// level's storage is the surface's rotated by the offsets. Also while snow refills the prints
/// (the tiles the walk does not reach refill as a stream over the stored words, whose texels and
/// tiles are found through the offsets).
#[test]
fn wrapped_and_unwrapped_storage_give_the_same_logical_heightmap() {
    let cases = [Precision::Bits8, Precision::Bits16, Precision::Bits32]
        .into_iter()
        .flat_map(|p| [(p, 0.0), (p, 0.05)]);
    for (p, rate) in cases {
        let (mut a, mut b) = (world(p), world(p));
        let mut desc = terrain("wrapped", &[([64, 48], 0.04)]);
        desc.replenish_rate = rate;
        let mut t = Terrain::new(&mut a, desc, Vec3::new(-5.0, 0.0, 3.0)).unwrap();
        // A window whose first world texel is (14, 7): stored with offsets (14, 7).
        let focus = Vec3::new((14.0 + 32.0) * 0.04, 0.0, (7.0 + 24.0) * 0.04);
        t.follow(&mut a, focus).unwrap();
        let level = t.surfaces()[0];
        assert_eq!(a.wrap(level).unwrap(), 14 | 7 << 16, "{p}");
        let plain = b.add_surface(a.surface(level).unwrap().clone()).unwrap();
        assert_eq!(b.layout(plain).unwrap(), a.layout(level).unwrap());
        assert_eq!(b.wrap(plain).unwrap(), 0);
        for d in walk() {
            let d = Deformer {
                pose: Pose::at((d.pose.position + Vec3::new(0.4, 0.0, 1.2)).to_array()),
                ..d
            };
            a.step(1.0 / 60.0, std::slice::from_ref(&d)).unwrap();
            b.step(1.0 / 60.0, std::slice::from_ref(&d)).unwrap();
        }
        let (la, lb) = (
            a.read_channels(level).unwrap(),
            b.read_channels(plain).unwrap(),
        );
        assert!(
            la.0.iter().filter(|&&v| v > 0).count() > 200,
            "{p}: the walk pressed nothing"
        );
        assert_eq!(la, lb, "{p}: wrapped and unwrapped heightmaps differ");
        assert_ne!(
            a.read_packed(level).unwrap(),
            b.read_packed(plain).unwrap(),
            "{p}: not stored wrapped"
        );
        // Snapshots are in logical order too.
        let sa = a.snapshot_surfaces(&[level]).unwrap();
        let sb = b.snapshot_surfaces(&[plain]).unwrap();
        assert_eq!(sa[0].words, sb[0].words, "{p}");
        // Probes read through the wrap: the same answers at the prints.
        let points: Vec<Vec3> = (0..8)
            .map(|i| Vec3::new(0.7 + 0.07 * i as f32, 1.0, 1.3))
            .collect();
        let (pa, pb) = (probe(&mut a, &points), probe(&mut b, &points));
        assert!(
            pa.iter().any(|x| x.depression_m > 0.01),
            "{p}: the probes missed the prints"
        );
        for (x, y) in pa.iter().zip(&pb) {
            assert_eq!(
                (x.depression_m, x.normal),
                (y.depression_m, y.normal),
                "{p}"
            );
        }
    }
}

fn probe(w: &mut SnowWorld, points: &[Vec3]) -> Vec<snowprint::ProbeSample> {
    let ticket = w.probe(points).unwrap();
    for _ in 0..4 {
        w.step(1.0 / 60.0, &[]).unwrap();
        if let snowprint::ProbeStatus::Ready(s) = w.probe_result(ticket).unwrap() {
            return s;
        }
    }
    panic!("probes not answered in 4 frames");
}

/// Two levels: the near one (5 cm) pages the trail out when the focus walks 5 m away; the far one
/// (40 cm) covers it, and its own coarse capture missed the 6 cm balls (its texel centres lie
/// 20 cm either side of the line); the near level's leaving strips folded into it give it the
/// trail's broad shape: pressed along the line, untouched beside it.
#[test]
fn the_far_level_keeps_the_trails_broad_shape() {
    let mut w = world(Precision::Bits16);
    let levels = [([80, 48], 0.05), ([64, 64], 0.4)];
    let mut t = Terrain::new(&mut w, terrain("clip", &levels), Vec3::new(1.5, 0.0, 0.0)).unwrap();
    for d in walk() {
        w.step(1.0 / 60.0, std::slice::from_ref(&d)).unwrap();
    }
    // World texels of 40 cm: the trail runs along z = 0 (rows -1 and 0) from x = 0.3 to 3.0 m.
    let line = |far: &std::collections::HashMap<(i64, i64), u32>| -> Vec<u32> {
        (1..8).map(|i| far[&(i, -1)].max(far[&(i, 0)])).collect()
    };
    assert!(
        line(&by_world(&w, &t, 1)).iter().all(|&v| v == 0),
        "the far level captured the balls itself"
    );
    // The fold's reference: the deepest near texel whose centre lies in each 40 cm texel (8 x 8
    // near texels of 5 cm), from the near level before it scrolls.
    let mut expected = std::collections::HashMap::<(i64, i64), u32>::new();
    for (&(x, z), &v) in &by_world(&w, &t, 0) {
        let e = expected
            .entry((x.div_euclid(8), z.div_euclid(8)))
            .or_default();
        *e = (*e).max(v);
    }
    t.follow(&mut w, Vec3::new(6.5, 0.0, 0.0)).unwrap();
    t.flush(&mut w).unwrap();
    let near = by_world(&w, &t, 0);
    assert!(
        near.values().all(|&v| v == 0),
        "the near level still holds the trail"
    );
    let far = by_world(&w, &t, 1);
    let on_trail = line(&far);
    let beside: Vec<u32> = (1..8).flat_map(|i| [far[&(i, -3)], far[&(i, 2)]]).collect();
    assert!(
        on_trail.iter().all(|&v| v > 65535 / 5),
        "far level along the trail: {on_trail:?}"
    );
    for i in 1..8 {
        for z in [-3, -1, 0, 2] {
            assert_eq!(far[&(i, z)], expected[&(i, z)], "far texel ({i}, {z})");
        }
    }
    assert!(
        beside.iter().all(|&v| v == 0),
        "far level beside the trail: {beside:?}"
    );
    let s = t.stats();
    assert!(s.texels_out > 0 && s.bytes_folded > 0, "{s:?}");
}

#[test]
fn bad_terrains_and_foci_are_refused_in_one_sentence() {
    let mut w = SnowWorld::new(
        common::gpu(),
        WorldConfig {
            pool_bytes: 1 << 20,
            ..WorldConfig::default()
        },
    )
    .unwrap();
    let cases: [(TerrainDesc, &str); 4] = [
        (
            terrain("a", &[([0, 16], 0.05)]),
            "level 0's texels is [0, 16]",
        ),
        (
            terrain("b", &[([16, 16], 0.05), ([16, 16], f32::NAN)]),
            "level 1's texel_size is NaN",
        ),
        (
            terrain("c", &[([1024, 1024], 0.05)]),
            "the levels' heightmaps is 4194304 bytes, but it must be at most the pool's 1048576 bytes",
        ),
        (terrain("d", &[]), "levels is empty"),
    ];
    for (desc, expected) in cases {
        let e = Terrain::new(&mut w, desc, Vec3::ZERO)
            .err()
            .expect("refused")
            .to_string();
        assert!(e.contains(expected), "{e}");
        assert_eq!(e.lines().count(), 1);
    }
    assert_eq!(
        w.surfaces().count(),
        0,
        "a refused terrain left surfaces behind"
    );
    let mut t = Terrain::new(&mut w, terrain("e", &[([16, 16], 0.05)]), Vec3::ZERO).unwrap();
    let e = t.follow(&mut w, Vec3::new(f32::NAN, 0.0, 0.0)).unwrap_err();
    assert!(matches!(e, SnowError::InvalidTerrain { .. }), "{e}");
    assert!(
        e.to_string().contains("the focus is [NaN, 0.0, 0.0]"),
        "{e}"
    );
    // Between encode_step and submitted the window cannot move: refused, nothing recorded.
    let id = t.surfaces()[0];
    let wrap = w.wrap(id).unwrap();
    let mut enc = w.device().create_command_encoder(&Default::default());
    let pending = w.encode_step(&mut enc, 1.0 / 60.0, &[]).unwrap();
    let e = t
        .follow(&mut w, Vec3::new(3.0, 0.0, 0.0))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("cannot scroll while a snow frame is encoded"),
        "{e}"
    );
    assert_eq!(
        (w.wrap(id).unwrap(), t.origin(0), t.scrolls_in_flight()),
        (wrap, Some([-8, -8]), 0)
    );
    w.queue().submit([enc.finish()]);
    w.submitted(pending).unwrap();
    t.follow(&mut w, Vec3::new(3.0, 0.0, 0.0)).unwrap();
    assert_eq!(t.origin(0), Some([52, -8]));
}

mod render {
    use super::*;
    use snowprint::render::{
        Environment, RenderConfig, RenderFrame, Renderer, SearchSettings, Tier,
    };
    use snowprint::{Camera, GroundMaterial, SurfaceId};

    fn shoot(
        w: &SnowWorld,
        ids: &[SurfaceId],
        tier: Tier,
        camera: Camera,
        size: (u32, u32),
    ) -> Vec<u8> {
        shot(w, ids, tier, camera, size).1
    }

    /// A frame of `ids` drawn: the renderer that drew it, and its pixels.
    fn shot(
        w: &SnowWorld,
        ids: &[SurfaceId],
        tier: Tier,
        camera: Camera,
        size: (u32, u32),
    ) -> (Renderer, Vec<u8>) {
        shot_searching(w, ids, tier, camera, size, None)
    }

    /// [`shot`] with the relief search's settings (`None`: the tier's).
    fn shot_searching(
        w: &SnowWorld,
        ids: &[SurfaceId],
        tier: Tier,
        camera: Camera,
        size: (u32, u32),
        search: Option<SearchSettings>,
    ) -> (Renderer, Vec<u8>) {
        let mut c = RenderConfig::new(size.0, size.1, tier);
        c.shadow_map_size = 256;
        c.snowflakes = 0;
        c.search = search;
        let surfaces: Vec<_> = ids.iter().map(|&i| (i, GroundMaterial::Concrete)).collect();
        let mut r = Renderer::new(common::gpu(), c).unwrap();
        let f = RenderFrame {
            camera,
            time: 0.0,
            surfaces: &surfaces,
            instances: &[],
            lights: &[],
            environment: Environment::moonlit_night(),
            snowfall: false,
        };
        let rgba = r.render(w, &f).unwrap().rgba8;
        (r, rgba)
    }

    fn save(name: &str, rgba: &[u8], size: (u32, u32)) {
        let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("window");
        std::fs::create_dir_all(&dir).unwrap();
        image::save_buffer(
            dir.join(name),
            rgba,
            size.0,
            size.1,
            image::ColorType::Rgba8,
        )
        .unwrap();
    }

    /// The renderer's heightfield pass reads a wrapped level through the wrap: the walk on a level
    /// stored with offsets (14, 7) and on the same rectangle stored plainly give the same image,
    /// bit for bit, in the relief and tessellated tiers (and not the untouched snow's).
    #[test]
    fn a_wrapped_level_renders_as_the_same_surface_stored_plainly() {
        let (mut a, mut b) = (world(Precision::Bits16), world(Precision::Bits16));
        let mut t =
            Terrain::new(&mut a, terrain("wrapped", &[([64, 48], 0.04)]), Vec3::ZERO).unwrap();
        t.follow(&mut a, Vec3::new(46.0 * 0.04, 0.0, 31.0 * 0.04))
            .unwrap();
        let level = t.surfaces()[0];
        let plain = b.add_surface(a.surface(level).unwrap().clone()).unwrap();
        let camera = Camera {
            eye: Vec3::new(1.9, 2.6, -0.9),
            target: Vec3::new(1.9, 1.0, 1.25),
            fov_y_degrees: 50.0,
        };
        let size = (160, 90);
        let untouched = shoot(&a, &[level], Tier::Relief, camera, size);
        for d in walk() {
            let d = Deformer {
                pose: Pose::at((d.pose.position + Vec3::new(0.4, 0.0, 1.2)).to_array()),
                ..d
            };
            a.step(1.0 / 60.0, std::slice::from_ref(&d)).unwrap();
            b.step(1.0 / 60.0, std::slice::from_ref(&d)).unwrap();
        }
        for tier in [Tier::Relief, Tier::Tessellated] {
            let wrapped = shoot(&a, &[level], tier, camera, size);
            let plainly = shoot(&b, &[plain], tier, camera, size);
            save(&format!("wrapped_{tier:?}.png"), &wrapped, size);
            assert!(
                wrapped == plainly,
                "{tier:?}: the wrapped level renders differently"
            );
            if tier == Tier::Relief {
                let changed = wrapped
                    .iter()
                    .zip(&untouched)
                    .filter(|(x, y)| x != y)
                    .count();
                assert!(
                    changed > 2000,
                    "the trail changed only {changed} bytes of the image"
                );
            }
        }
    }

    /// Two levels of one window, both untouched, drawn together look as the far level alone: the
    /// far one leaves the near one's extent to it (no overlap, no seam where they meet); with a
    /// trail across the near level, the still shows it inside the far level's snow.
    #[test]
    fn near_and_far_levels_meet_without_a_seam() {
        let mut w = world(Precision::Bits16);
        let levels = [([64, 64], 0.05), ([64, 64], 0.2)];
        let t = Terrain::new(&mut w, terrain("clip", &levels), Vec3::new(1.6, 0.0, 0.0)).unwrap();
        let [near, far] = [t.surfaces()[0], t.surfaces()[1]];
        let hole = w
            .frame_view()
            .surface(far)
            .unwrap()
            .hole
            .expect("the far level has a hole");
        // The near level's extent, inset by a quarter of its texel (the two overlap that much).
        let q = 0.25 * 0.05;
        for (h, e) in hole.iter().zip([-1.6 + q, -1.6 + q, 1.6 - q, 1.6 - q]) {
            assert!((h - e).abs() < 1e-5, "{hole:?}");
        }
        let camera = Camera {
            eye: Vec3::new(1.6, 5.0, -5.5),
            target: Vec3::new(1.6, 1.0, 0.5),
            fov_y_degrees: 55.0,
        };
        let size = (320, 180);
        let mut alone = world(Precision::Bits16);
        let only = Terrain::new(
            &mut alone,
            terrain("clip", &levels[1..]),
            Vec3::new(1.6, 0.0, 0.0),
        )
        .unwrap();
        let far_only = only.surfaces()[0];
        assert_eq!(
            alone.surface(far_only).unwrap().center,
            w.surface(far).unwrap().center
        );
        for tier in [Tier::Relief, Tier::Tessellated] {
            let both = shoot(&w, &[near, far], tier, camera, size);
            let reference = shoot(&alone, &[far_only], tier, camera, size);
            save(&format!("levels_untouched_{tier:?}.png"), &both, size);
            // The tessellated tier dices the far level with the near level's extent cut out
            // (render/tessellate/seams.rs), along lines that cross its rectangle from side to side,
            // so its outline against the sky is rasterised from other triangles than the far level
            // alone: a pixel on that outline may flip (one did on lavapipe). Only pixels inside a
            // smooth region of the reference count there; in the relief tier every pixel does.
            let differ: Vec<(u32, u32)> = match tier {
                Tier::Tessellated => seam_pixels(&both, &reference, size),
                _ => (0..both.len() / 4)
                    .filter(|&i| (0..3).any(|c| both[4 * i + c].abs_diff(reference[4 * i + c]) > 2))
                    .map(|i| (i as u32 % size.0, i as u32 / size.0))
                    .collect(),
            };
            let at = &differ[..differ.len().min(8)];
            println!(
                "{tier:?}: untouched levels against the far level alone: {} pixels differ by more than 2 of 255, at {at:?}",
                differ.len()
            );
            // A crack where the meshes meet is a pixel or two: none is allowed.
            assert!(
                differ.is_empty(),
                "{tier:?}: {} pixels differ, at {at:?}",
                differ.len()
            );
        }
        for d in walk() {
            w.step(1.0 / 60.0, std::slice::from_ref(&d)).unwrap();
        }
        let trail = shoot(&w, &[near, far], Tier::Relief, camera, size);
        save("levels_trail.png", &trail, size);
        let trail_t = shoot(&w, &[near, far], Tier::Tessellated, camera, size);
        save("levels_trail_tessellated.png", &trail_t, size);
        // The window moves 2 m on (-x): the trail's far end leaves the near level, and the far
        // level draws it from what the near one folded into it (coarse, as it must be).
        let mut t = t;
        t.follow(&mut w, Vec3::new(-0.4, 0.0, 0.0)).unwrap();
        t.flush(&mut w).unwrap();
        w.step(1.0 / 60.0, &[]).unwrap();
        let moved = shoot(&w, &[near, far], Tier::Relief, camera, size);
        save("levels_trail_moved.png", &moved, size);
        assert_ne!(
            moved, trail,
            "the window moved and nothing changed on screen"
        );
    }

    /// A trail along the near level's edge, seen from inside the near level looking out: the
    /// near level's snow is pressed at its edge and the far level's, which does not hold the
    /// trail, is not, so the two tops step up there by the print's depth. The step is closed in
    /// both tiers (the far level's skirts on its hole's sides in the tessellated tier, the hole's
    /// edge met by the ray in the relief tier), never a gap through to what lies under the snow:
    /// no pixel of the snow in the untouched view is darker than 40 % of it, where the gap showed
    /// the night sky behind (about a fifth of the snow's brightness).
    #[test]
    fn the_step_between_levels_at_a_trail_is_closed() {
        let mut w = world(Precision::Bits16);
        let levels = [([64, 64], 0.05), ([64, 64], 0.2)];
        let t = Terrain::new(&mut w, terrain("clip", &levels), Vec3::new(1.6, 0.0, 0.0)).unwrap();
        let [near, far] = [t.surfaces()[0], t.surfaces()[1]];
        let camera = Camera {
            eye: Vec3::new(1.6, 1.9, 0.3),
            target: Vec3::new(1.6, 1.0, 2.0),
            fov_y_degrees: 50.0,
        };
        let size = (320, 180);
        let untouched: Vec<_> = [Tier::Relief, Tier::Tessellated]
            .map(|tier| shoot(&w, &[near, far], tier, camera, size))
            .into();
        // The near level reaches z = 1.6: prints 3 cm inside its edge, along it.
        for i in 0..30 {
            let d = foot(0.5 + i as f32 * 0.07, 1.57);
            w.step(1.0 / 60.0, std::slice::from_ref(&d)).unwrap();
        }
        let near_to =
            |a: &[u8], b: &[u8], i: usize| (0..3).all(|c| a[4 * i + c].abs_diff(b[4 * i + c]) <= 4);
        for (tier, before) in [Tier::Relief, Tier::Tessellated]
            .into_iter()
            .zip(&untouched)
        {
            let trail = shoot(&w, &[near, far], tier, camera, size);
            let sky = shoot(&w, &[], tier, camera, size);
            save(&format!("levels_step_{tier:?}.png"), &trail, size);
            let gaps: Vec<(usize, usize)> = (0..trail.len() / 4)
                .filter(|&i| !near_to(before, &sky, i) && near_to(&trail, &sky, i))
                .map(|i| (i % size.0 as usize, i / size.0 as usize))
                .collect();
            let changed = (0..trail.len()).filter(|&i| trail[i] != before[i]).count();
            println!(
                "{tier:?}: {} gap pixels, {changed} bytes changed",
                gaps.len()
            );
            assert!(
                changed > 500,
                "{tier:?}: the trail changed only {changed} bytes"
            );
            assert!(
                gaps.is_empty(),
                "{tier:?}: {} pixels see through the step, first at {:?}",
                gaps.len(),
                &gaps[..gaps.len().min(8)]
            );
        }
    }

    /// A window's level and a surface laid beside it (a rooftop or a deck at the snow's height,
    /// its texels on the level's grid) against one surface over both rectangles. Untouched, the
    /// two draw as the one within 2 of 255 in both tiers: no crack, no overlap, and the open
    /// edge's layers run on across the meeting line. (The outline of the snow against the sky is
    /// rasterised from other triangles, so a pixel on it may flip: in the tessellated tier on
    /// lavapipe, in both on an H100. Only pixels inside a smooth region of the one surface's image
    /// count.) A walk across the line leaves in each, texel for texel, what the one surface holds,
    /// within a unit, the two columns along the line included: each surface's capture covers an
    /// apron of one texel beyond its sides, so both blur what the one surface blurs there.
    #[test]
    fn a_window_and_a_surface_beside_it_meet_without_a_seam() {
        let (mut a, mut b) = (world(Precision::Bits16), world(Precision::Bits16));
        let mut valley = terrain("valley", &[([64, 48], 0.04)]);
        // Glints are single pixels that a rounding of the hit switches on or off.
        valley.material.look.sparkle = 0.0;
        let mut t = Terrain::new(&mut a, valley, Vec3::ZERO).unwrap();
        t.follow(&mut a, Vec3::new(46.0 * 0.04, 0.0, 31.0 * 0.04))
            .unwrap();
        let level = t.surfaces()[0];
        assert_ne!(a.wrap(level).unwrap(), 0, "the level is stored wrapped");
        let desc = a.surface(level).unwrap().clone();
        let line = (t.origin(0).unwrap()[0] + 64) as f32 * 0.04;
        let beside = |name: &str, columns: u32, from: f32| snowprint::SurfaceDesc {
            name: name.into(),
            center: Vec3::new(from + columns as f32 * 0.02, desc.center.y, desc.center.z),
            size: glam::Vec2::new(columns as f32 * 0.04, desc.size.y),
            ..desc.clone()
        };
        let roof = a.add_surface(beside("roof", 32, line)).unwrap();
        let one = b
            .add_surface(beside("one", 96, line - 64.0 * 0.04))
            .unwrap();
        let width = |w: &SnowWorld, id| w.layout(id).unwrap().width;
        assert_eq!(
            (width(&a, level), width(&a, roof), width(&b, one)),
            (64, 32, 96)
        );
        let camera = Camera {
            eye: Vec3::new(line - 0.5, 2.7, desc.center.z - 2.2),
            target: Vec3::new(line, 1.2, desc.center.z),
            fov_y_degrees: 45.0,
        };
        let size = (240, 160);
        for tier in [Tier::Relief, Tier::Tessellated] {
            let two = shoot(&a, &[level, roof], tier, camera, size);
            let reference = shoot(&b, &[one], tier, camera, size);
            save(&format!("beside_untouched_{tier:?}.png"), &two, size);
            let differ = seam_pixels(&two, &reference, size);
            println!(
                "{tier:?}: untouched, {} pixels differ from the one surface by more than 2 of 255, at {:?}",
                differ.len(),
                &differ[..differ.len().min(8)]
            );
            assert!(differ.is_empty(), "{tier:?}: a seam at {differ:?}");
        }
        walk_both(&mut a, &mut b, |p| {
            p + Vec3::new(line - 1.665, 0.0, desc.center.z)
        });
        let (l, r, u) = (
            a.read_channels(level).unwrap().0,
            a.read_channels(roof).unwrap().0,
            b.read_channels(one).unwrap().0,
        );
        let (mut inside, mut edge) = (0u32, 0u32);
        for row in 0..48usize {
            for c in 0..96usize {
                let two = if c < 64 {
                    l[row * 64 + c]
                } else {
                    r[row * 32 + c - 64]
                };
                let d = two.abs_diff(u[row * 96 + c]);
                if c == 63 || c == 64 {
                    edge = edge.max(d);
                } else {
                    inside = inside.max(d);
                }
            }
        }
        let pressed = u.iter().filter(|&&v| v > 65535 / 4).count();
        println!(
            "trodden: {pressed} texels pressed past a quarter; off the line the two differ from the one surface by at most {inside} of 65535, on it by {edge}"
        );
        assert!(pressed > 100, "the walk pressed only {pressed} texels");
        assert!(inside <= 1, "off the line: {inside}");
        assert!(edge <= 1, "on the line: {edge}");
        // What the renderer derives from the heights, texel for texel: each surface reads the
        // other's texels past the line, so the two draw the one surface's fields.
        let (two, reference) = (
            shot(&a, &[level, roof], Tier::Tessellated, camera, size),
            shot(&b, &[one], Tier::Tessellated, camera, size),
        );
        let (l, r, u) = (
            two.0.read_surface_fields(level).unwrap(),
            two.0.read_surface_fields(roof).unwrap(),
            reference.0.read_surface_fields(one).unwrap(),
        );
        let off = fields_off(&l, &r, &u);
        println!(
            "trodden, fields against the one surface's, largest difference on the line and off it: {off:?}"
        );
        let banked = u.bank.iter().filter(|&&h| h > 0.002).count();
        assert!(banked > 50, "the walk raised banks on {banked} texels only");
        for (what, on_line, elsewhere, tolerance) in off {
            assert!(
                on_line <= tolerance && elsewhere <= tolerance,
                "{what}: {on_line} on the line, {elsewhere} elsewhere (tolerance {tolerance})"
            );
        }
        for tier in [Tier::Relief, Tier::Tessellated] {
            let two = shoot(&a, &[level, roof], tier, camera, size);
            let reference = shoot(&b, &[one], tier, camera, size);
            save(&format!("beside_trodden_{tier:?}.png"), &two, size);
            save(
                &format!("beside_trodden_one_{tier:?}.png"),
                &reference,
                size,
            );
            let differ = seam_pixels(&two, &reference, size);
            println!(
                "{tier:?}: trodden, {} pixels differ from the one surface by more than 2 of 255, at {:?}",
                differ.len(),
                &differ[..differ.len().min(8)]
            );
            // The tessellated tier dices the two apart (a base edge runs along the line), so its
            // pixels are compared through the fields above; the relief tier traces the same
            // fields and draws the one surface's pixels.
            if tier == Tier::Relief {
                assert!(differ.is_empty(), "a seam at {differ:?}");
            }
        }
        up_close(&a, &b, &[level, roof], one, camera, line, desc.center.z);
    }

    /// The trodden line of [`a_window_and_a_surface_beside_it_meet_without_a_seam`] at 960x640,
    /// where a ridge between two prints crosses it a few pixels wide.
    ///
    /// Relief: each box spends its own linear taps over its own span, so where the taps step over
    /// a ridge the two boxes and the one wider box can miss it differently (with the tier's 12
    /// taps, 8 pixels of the ridge's outline differ). With a search fine enough to resolve the
    /// ridge, the two draw the one surface's pixels within 2 of 255: the line itself adds nothing.
    ///
    /// Tessellated: the two meshes are diced apart and the one mesh across the line, so their
    /// vertices differ everywhere on the trail and so do a few pixels along every texel line
    /// across it. The meeting line must be no worse than the others: no more pixels differing by
    /// more than 2 of 255 within 1.5 pixels of it and the two texel lines either side than along
    /// any other five texel lines over the trail. (With the sides left unlinked, 831 pixels differ
    /// around the line against at most 133 elsewhere.)
    fn up_close(
        a: &SnowWorld,
        b: &SnowWorld,
        two_ids: &[SurfaceId],
        one: SurfaceId,
        camera: Camera,
        line: f32,
        z: f32,
    ) {
        let size = (960, 640);
        let dense = SearchSettings {
            taps_per_texel: 4.0,
            min_taps: 4,
            max_taps: 256,
            refine_taps: 10,
            shadow_taps: 0,
        };
        let two = shot_searching(a, two_ids, Tier::Relief, camera, size, Some(dense)).1;
        let reference = shot_searching(b, &[one], Tier::Relief, camera, size, Some(dense)).1;
        save("beside_close_Relief.png", &two, size);
        let differ = seam_pixels(&two, &reference, size);
        println!(
            "Relief, 960x640, a search of 4 taps a texel: {} pixels differ from the one surface by more than 2 of 255",
            differ.len()
        );
        assert!(differ.is_empty(), "a seam up close at {differ:?}");

        let two = shoot(a, two_ids, Tier::Tessellated, camera, size);
        let reference = shoot(b, &[one], Tier::Tessellated, camera, size);
        save("beside_close_Tessellated.png", &two, size);
        let project = |p: Vec3| {
            let clip = camera.projection(size.0 as f32 / size.1 as f32, 0.05, 100.0)
                * camera.view()
                * p.extend(1.0);
            let ndc = clip.truncate() / clip.w;
            glam::Vec2::new(
                (ndc.x * 0.5 + 0.5) * size.0 as f32,
                (0.5 - ndc.y * 0.5) * size.1 as f32,
            )
        };
        // Pixels that differ within 1.5 pixels of the texel line `k` texels past the meeting
        // line, over the trail (its prints lie within 25 cm of z).
        let differing_along = |k: i32| {
            let x = line + k as f32 * 0.04;
            let (p, q) = (
                project(Vec3::new(x, 1.0 + DEPTH, z - 0.25)),
                project(Vec3::new(x, 1.0 + DEPTH, z + 0.25)),
            );
            let d = q - p;
            let mut n = 0;
            for y in 0..size.1 {
                for xp in 0..size.0 {
                    let c = glam::Vec2::new(xp as f32, y as f32) - p;
                    let s = c.dot(d) / d.length_squared();
                    let off = (c - d * s).length();
                    let i = 4 * (y * size.0 + xp) as usize;
                    if (0.0..=1.0).contains(&s)
                        && off <= 1.5
                        && (0..3).any(|ch| two[i + ch].abs_diff(reference[i + ch]) > 2)
                    {
                        n += 1;
                    }
                }
            }
            n
        };
        // A seam (the sides left unlinked, say) spreads over the two texels either side of the
        // line, so the five texel lines around it are weighed against every other five.
        let along: Vec<u32> = (-30..=30).map(differing_along).collect();
        let around = |k: i32| {
            (k - 2..=k + 2)
                .map(|j| along[(j + 30) as usize])
                .sum::<u32>()
        };
        let at_line = around(0);
        let worst = (-28..=28)
            .filter(|k: &i32| k.abs() >= 5)
            .map(around)
            .max()
            .unwrap_or(0);
        println!(
            "Tessellated, 960x640: {at_line} pixels differ along the five texel lines around the meeting line, at most {worst} along any other five over the trail"
        );
        assert!(
            at_line <= worst,
            "the meeting line differs in {at_line} pixels, more than anywhere else on the trail ({worst})"
        );
    }

    /// The largest difference of the level's and the roof's fields (`l`, 64 columns, and `r`, 32)
    /// from the one surface's (`u`, 96), on the two columns along the line and elsewhere, with the
    /// tolerance of each field: the heightmaps are within a unit of 65,535 (asserted above), the
    /// fields are stored as 16-bit floats (an ulp of 2.4e-4 at the depressions' 0.3, of 7.6e-6 at
    /// the banks' 1.6 cm).
    fn fields_off(
        l: &snowprint::render::SurfaceFields,
        r: &snowprint::render::SurfaceFields,
        u: &snowprint::render::SurfaceFields,
    ) -> [(&'static str, f32, f32, f32); 3] {
        let field = |f: &snowprint::render::SurfaceFields, k: usize| match k {
            0 => f.depression.clone(),
            1 => f.displaced.clone(),
            _ => f.bank.clone(),
        };
        let mut out: [(&str, f32, f32, f32); 3] = [
            ("depression", 0.0, 0.0, 5e-4),
            ("displaced", 0.0, 0.0, 5e-4),
            ("bank", 0.0, 0.0, 2e-5),
        ];
        for (k, o) in out.iter_mut().enumerate() {
            let (fl, fr, fu) = (field(l, k), field(r, k), field(u, k));
            for row in 0..u.height as usize {
                for c in 0..96usize {
                    let two = if c < 64 {
                        fl[row * 64 + c]
                    } else {
                        fr[row * 32 + c - 64]
                    };
                    let d = (two - fu[row * 96 + c]).abs();
                    if c == 63 || c == 64 {
                        o.1 = o.1.max(d);
                    } else {
                        o.2 = o.2.max(d);
                    }
                }
            }
        }
        out
    }

    /// Pixels (x, y) where `two` differs from `reference` by more than 2 of 255 in a channel,
    /// where the reference's 3x3 neighbourhood is smooth (within 8 of 255 of the pixel: not an
    /// outline).
    fn seam_pixels(two: &[u8], reference: &[u8], size: (u32, u32)) -> Vec<(u32, u32)> {
        let at = |x: u32, y: u32, c: usize| reference[4 * (y * size.0 + x) as usize + c];
        let smooth = |x: u32, y: u32| {
            (x.saturating_sub(1)..=(x + 1).min(size.0 - 1)).all(|nx| {
                (y.saturating_sub(1)..=(y + 1).min(size.1 - 1))
                    .all(|ny| (0..3).all(|c| at(nx, ny, c).abs_diff(at(x, y, c)) <= 8))
            })
        };
        (0..size.1)
            .flat_map(|y| (0..size.0).map(move |x| (x, y)))
            .filter(|&(x, y)| {
                let i = 4 * (y * size.0 + x) as usize;
                (0..3).any(|c| two[i + c].abs_diff(reference[i + c]) > 2) && smooth(x, y)
            })
            .collect()
    }
}

/// `[[terrain]]` in a scene file: its keys become a `TerrainDesc` (levels finest first, inline or
/// as `[[terrain.levels]]`), and its refusals name the file and line (more in
/// `tests/hostile/scenes/terrain_*`).
#[test]
fn scene_keys_make_a_terrain_and_refuse_bad_ones_with_their_line() {
    use snowprint::scene::{Scene, TerrainFollow};
    let path = std::path::Path::new("valley.toml");
    let text = "version = 1\n\n[[material]]\nname = \"dry\"\nlike = \"powder\"\n\n\
                [[terrain]]\nname = \"valley\"\nground_height = 12.5\nsnow_depth = 0.4\n\
                replenish_rate = 0.01\nmaterial = \"dry\"\n\n\
                [[terrain.levels]]\ntexels = [1024, 1024]\ntexel_size = 0.05\n\n\
                [[terrain.levels]]\ntexels = [512, 256]\ntexel_size = 0.4\n";
    let scene = Scene::parse(text, path).unwrap();
    assert!(scene.surfaces.is_empty());
    let t = &scene.terrains[0];
    assert_eq!((t.line, t.follow), (7, TerrainFollow::Player));
    assert_eq!(t.desc.name, "valley");
    assert_eq!(
        (
            t.desc.ground_height,
            t.desc.snow_depth,
            t.desc.replenish_rate
        ),
        (12.5, 0.4, 0.01)
    );
    assert_eq!(t.desc.material.look, Material::powder().look);
    assert_eq!(
        t.desc.levels,
        vec![
            LevelDesc {
                texels: [1024, 1024],
                texel_size: 0.05
            },
            LevelDesc {
                texels: [512, 256],
                texel_size: 0.4
            },
        ]
    );
    let refused = |extra: &str| {
        Scene::parse(&format!("{text}{extra}"), path)
            .unwrap_err()
            .to_string()
    };
    let twice = refused(
        "\n[[surface]]\nname = \"valley\"\ncenter = [0, 0, 0]\nsize = [1, 1]\nsnow_depth = 0.3\n",
    );
    assert!(
        twice.starts_with("valley.toml:8: surface name \"valley\" is used twice"),
        "{twice}"
    );
    let size = refused(
        "\n[[terrain]]\nname = \"b\"\nsnow_depth = 0.3\nlevels = [{ texels = [64, 64], texel_size = 0.01 }]\n",
    );
    assert!(
        size.starts_with("valley.toml:25: terrain \"b\"'s level 0 has texel_size 0.01"),
        "{size}"
    );
    let pool = refused("\n[budget]\npool_bytes = 4194304\n");
    assert!(pool.starts_with("valley.toml:14: terrain \"valley\"'s levels need 4718592 bytes of heightmap pool, and the pool has 4194304 left"), "{pool}");
}

/// A terrain on sine hills (a height grid over 20 m x 20 m of the world): after the window has
/// scrolled (offsets (14, 7)) a walk leaves on the level what it leaves on a plain surface of the
/// same rectangle laid on the same heights, bit for bit, and the prints follow the hills.
#[test]
fn a_terrain_on_hills_presses_as_a_surface_on_the_same_ground() {
    use snowprint::{Ground, HeightGrid, SlopeRule, TerrainGround};
    let hills = |x: f32, z: f32| 0.4 * (x * 0.9).sin() * (z * 0.7).cos();
    let n = 101u32;
    let grid = HeightGrid {
        columns: n,
        rows: n,
        heights: (0..n * n)
            .map(|i| hills(-10.0 + 0.2 * (i % n) as f32, -10.0 + 0.2 * (i / n) as f32))
            .collect(),
    };
    let mut desc = terrain("hills", &[([64, 48], 0.04)]);
    desc.ground = Some(TerrainGround {
        grid,
        origin: [-10.1, -10.1],
        size: [20.2, 20.2],
        slope: SlopeRule::default(),
    });
    let (mut a, mut b) = (world(Precision::Bits16), world(Precision::Bits16));
    let mut t = Terrain::new(&mut a, desc, Vec3::new(-3.0, 0.0, 0.0)).unwrap();
    t.follow(&mut a, Vec3::new(46.0 * 0.04, 0.0, 31.0 * 0.04))
        .unwrap();
    let level = t.surfaces()[0];
    assert_eq!(a.wrap(level).unwrap(), 14 | 7 << 16);
    let field = a
        .ground(level)
        .unwrap()
        .expect("the level lies on the hills")
        .clone();
    let plain = b.add_surface(a.surface(level).unwrap().clone()).unwrap();
    let heights = HeightGrid {
        columns: 64,
        rows: 48,
        heights: field.ground.clone(),
    };
    b.set_ground(plain, &Ground::Grid(heights), SlopeRule::default())
        .unwrap();
    assert_eq!(b.ground(plain).unwrap().unwrap(), &field);
    // The field follows the hills at the texels' world centres.
    let o = t.origin(0).unwrap();
    for (c, r) in [(0u32, 0u32), (40, 20), (63, 47)] {
        let (x, z) = (
            (o[0] + c as i64) as f32 * 0.04 + 0.02,
            (o[1] + r as i64) as f32 * 0.04 + 0.02,
        );
        let g = field.ground[(r * 64 + c) as usize];
        assert!(
            (g - hills(x, z)).abs() < 0.01,
            "texel ({c}, {r}): {g} against {}",
            hills(x, z)
        );
    }
    walk_both(&mut a, &mut b, |p| {
        let p = p + Vec3::new(0.4, 0.0, 1.2);
        Vec3::new(p.x, p.y + hills(p.x, p.z), p.z)
    });
    let (la, lb) = (
        a.read_channels(level).unwrap(),
        b.read_channels(plain).unwrap(),
    );
    assert!(
        la.0.iter().filter(|&&v| v > 65535 / 4).count() > 100,
        "the walk on the hills pressed little"
    );
    assert_eq!(la, lb, "the level on hills and the plain surface differ");
}

/// `[[terrain]]`'s ground keys: a raw f32 grid laid over `ground_rect`, with the slope rule.
#[test]
fn scene_keys_lay_a_terrain_on_a_grid() {
    use snowprint::scene::Scene;
    let dir = std::env::temp_dir().join(format!("snowprint-window-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let heights: Vec<f32> = (0..12).map(|i| i as f32 * 0.25).collect();
    std::fs::write(dir.join("hills.f32"), bytemuck::cast_slice(&heights)).unwrap();
    let text = "version = 1\n\n[[terrain]]\nname = \"hills\"\nsnow_depth = 0.3\n\
                levels = [{ texels = [64, 64], texel_size = 0.05 }]\nground = \"hills.f32\"\n\
                ground_grid = [4, 3]\nground_rect = [-8, -2, 12, 4]\nbare_slope_degrees = 70\n";
    std::fs::write(dir.join("hills.toml"), text).unwrap();
    let scene = Scene::load(&dir.join("hills.toml")).unwrap();
    let g = scene.terrains[0].desc.ground.as_ref().expect("a ground");
    assert_eq!(
        (g.grid.columns, g.grid.rows, &g.grid.heights),
        (4, 3, &heights)
    );
    assert_eq!((g.origin, g.size), ([-8.0, -2.0], [20.0, 6.0]));
    assert_eq!((g.slope.full_degrees, g.slope.bare_degrees), (35.0, 70.0));
    let bad = text.replace(
        "ground_rect = [-8, -2, 12, 4]",
        "ground_rect = [12, -2, -8, 4]",
    );
    std::fs::write(dir.join("bad.toml"), bad).unwrap();
    let e = Scene::load(&dir.join("bad.toml")).unwrap_err().to_string();
    assert!(
        e.contains("bad.toml:9: terrain \"hills\" has ground_rect [12, -2, -8, 4]"),
        "{e}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// A level of 60 x 44 texels of 4 cm (sizes at which resampling a laid grid again would not give
/// the same heights) on sine hills with a steep ridge (bare at its flanks), followed along moves
/// of 1, 2 and 7 texels in x, in z and diagonally, and one jump larger than the window: after
/// every move its ground field (heights and columns) and its range are bit for bit those of the
/// same level laid whole at that origin, a 2-column move writes only that level's part of the
/// ground buffers (another surface on a ground lies before it there), and at the end a walk
/// presses the moved level as it presses the level laid whole.
#[test]
fn a_level_on_hills_moves_its_ground_as_laying_it_whole_would() {
    use snowprint::{Ground, HeightGrid, SlopeRule, SurfaceDesc, TerrainGround};
    let ground = |x: f32, z: f32| {
        let ridge = 1.2 * (1.0 - (x - 0.9).abs() / 0.25).max(0.0);
        0.4 * (x * 0.9).sin() * (z * 0.7).cos() + ridge
    };
    let n = 121u32;
    let grid = HeightGrid {
        columns: n,
        rows: n,
        heights: (0..n * n)
            .map(|i| ground(-6.0 + 0.1 * (i % n) as f32, -6.0 + 0.1 * (i / n) as f32))
            .collect(),
    };
    let (texels, s) = ([60u32, 44u32], 0.04f32);
    let desc = |name: &str| {
        let mut d = terrain(name, &[(texels, s)]);
        d.ground = Some(TerrainGround {
            grid: grid.clone(),
            origin: [-6.05, -6.05],
            size: [12.1, 12.1],
            slope: SlopeRule::default(),
        });
        d
    };
    // The focus whose window starts at world texel `o` (a quarter texel off the rounding's ties).
    let focus = |o: [i64; 2]| {
        let at = |k: usize| (o[k] as f32 + texels[k] as f32 / 2.0 + 0.25) * s;
        Vec3::new(at(0), 0.0, at(1))
    };
    let bits = |f: &snowprint::GroundField| {
        let g: Vec<u32> = f.ground.iter().map(|v| v.to_bits()).collect();
        let c: Vec<[u32; 2]> = f.columns.iter().map(|c| c.map(f32::to_bits)).collect();
        (g, c)
    };
    let mut a = world(Precision::Bits16);
    let other = a
        .add_surface(SurfaceDesc {
            name: "roof".into(),
            center: Vec3::new(10.0, 1.0, 10.0),
            size: glam::Vec2::new(1.0, 1.0),
            yaw_degrees: 0.0,
            snow_depth: DEPTH,
            replenish_rate: 0.0,
            material: Material::snow(),
        })
        .unwrap();
    let roof = HeightGrid {
        columns: 2,
        rows: 2,
        heights: vec![0.0, 0.5, 0.2, 0.9],
    };
    a.set_ground(other, &Ground::Grid(roof), SlopeRule::default())
        .unwrap();
    let other_field = a.ground(other).unwrap().unwrap().clone();
    let mut origin = [-20i64, -10];
    let mut t = Terrain::new(&mut a, desc("hills"), focus(origin)).unwrap();
    let level = t.surfaces()[0];
    let placement = a.ground_placement(level).unwrap().unwrap();
    assert!(placement.0 > 0, "the level's field lies after the roof's");
    let mut bare = 0;
    let moves: [[i64; 2]; 13] = [
        [1, 0],
        [0, 1],
        [2, 0],
        [0, -2],
        [7, 0],
        [0, 7],
        [-1, -1],
        [2, -2],
        [-7, 7],
        [7, 7],
        [3, -5],
        [97, -71],
        [-2, 0],
    ];
    for (k, by) in moves.into_iter().enumerate() {
        origin = [origin[0] + by[0], origin[1] + by[1]];
        let written = a.ground_bytes_written();
        t.follow(&mut a, focus(origin)).unwrap();
        assert_eq!(t.origin(0).unwrap(), origin);
        let mut b = world(Precision::Bits16);
        let whole = Terrain::new(&mut b, desc("whole"), focus(origin)).unwrap();
        assert_eq!(whole.origin(0).unwrap(), origin);
        let (moved, laid) = (
            a.ground(level).unwrap().unwrap(),
            b.ground(whole.surfaces()[0]).unwrap().unwrap(),
        );
        assert!(
            bits(moved) == bits(laid),
            "move {k} by {by:?}: the fields differ"
        );
        let (pa, pb) = (
            a.ground_placement(level).unwrap().unwrap(),
            b.ground_placement(whole.surfaces()[0]).unwrap().unwrap(),
        );
        assert_eq!(
            (pa.1.to_bits(), pa.2.to_bits()),
            (pb.1.to_bits(), pb.2.to_bits())
        );
        assert_eq!(
            pa.0, placement.0,
            "the level's field moved in the ground buffer"
        );
        bare += moved.columns.iter().filter(|c| c[1] == DEPTH).count();
        if by == [2, 0] || by == [-2, 0] {
            // The field's columns (8 bytes a texel) and its capture codes (4 bytes a texel of
            // its capture region, the level and the apron of a texel around it).
            let field_bytes = texels[0] as u64 * texels[1] as u64 * 8
                + (texels[0] as u64 + 2) * (texels[1] as u64 + 2) * 4;
            assert_eq!(a.ground_bytes_written() - written, field_bytes);
        }
    }
    assert!(
        bare > 100,
        "the ridge bared only {bare} texels along the path"
    );
    assert_eq!(a.ground(other).unwrap().unwrap(), &other_field);
    // The GPU reads the moved field where the whole one lies: a walk presses both alike.
    let mut b = world(Precision::Bits16);
    let whole = Terrain::new(&mut b, desc("whole"), focus(origin)).unwrap();
    let o = focus(origin);
    walk_both(&mut a, &mut b, |p| {
        let p = p + Vec3::new(o.x - 1.5, 0.0, o.z);
        Vec3::new(p.x, p.y + ground(p.x, p.z), p.z)
    });
    let (la, lb) = (
        a.read_channels(level).unwrap(),
        b.read_channels(whole.surfaces()[0]).unwrap(),
    );
    assert!(
        la.0.iter().filter(|&&v| v > 65535 / 4).count() > 100,
        "the walk on the hills pressed little"
    );
    assert_eq!(la, lb, "the moved level and the level laid whole differ");
}

/// The walk, each pose moved by `at`, stepped in both worlds alike.
fn walk_both(a: &mut SnowWorld, b: &mut SnowWorld, at: impl Fn(Vec3) -> Vec3) {
    for d in walk() {
        let d = Deformer {
            pose: Pose::at(at(d.pose.position).to_array()),
            ..d
        };
        a.step(1.0 / 60.0, std::slice::from_ref(&d)).unwrap();
        b.step(1.0 / 60.0, std::slice::from_ref(&d)).unwrap();
    }
}
