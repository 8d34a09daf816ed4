//! The capture's two paths for analytic deformers write the same bits: the compute path (one
//! dispatch for every surface only analytic deformers press) and the raster path (each surface in
//! its viewport of the atlas, each primitive a rectangle of fragments). Random worlds of yawed
//! surfaces, some on hills, pressed by moving spheres, capsules and boxes, are run through both,
//! with the update dispatched over its grid and over the capture's list of tiles; every frame's
//! capture of every surface's region (its texels and the apron around them) is compared texel by
//! texel, and the heightmaps at the end.

mod common;

use glam::{Quat, Vec3};
use proptest::prelude::*;
use snowprint::low_level::capture::{self, CaptureVolume};
use snowprint::reference::capture as cap_cpu;
use snowprint::{
    CapturePath, Deformer, Ground, HeightGrid, PoolFormat, Pose, Precision, Shape, SlopeRule,
    SnowWorld, SurfaceDesc, SurfaceId, WorldConfig,
};

fn world(path: CapturePath, listed: bool) -> SnowWorld {
    SnowWorld::new(
        common::gpu(),
        WorldConfig {
            capture_path: path,
            list_tiles_from: if listed { 0 } else { u32::MAX },
            ..WorldConfig::default()
        },
    )
    .expect("world")
}

/// A surface `i` of the row, its size, yaw, and whether it lies on hills.
#[derive(Clone, Debug)]
struct Spot {
    size: (f32, f32),
    yaw: f32,
    hills: bool,
}

fn desc(i: usize, s: &Spot) -> SurfaceDesc {
    let mut d = SurfaceDesc::new(
        &format!("s{i}"),
        [i as f32 * 12.0, 1.0, 0.0],
        [s.size.0, s.size.1],
        0.3,
    );
    d.yaw_degrees = s.yaw;
    d.replenish_rate = if i.is_multiple_of(3) { 0.05 } else { 0.0 };
    d
}

fn hills(d: &SurfaceDesc) -> Ground {
    let l = d.layout();
    let heights = (0..l.height)
        .flat_map(|r| {
            (0..l.width).map(move |c| 0.15 * (c as f32 * 0.21).sin() * (r as f32 * 0.17).cos())
        })
        .collect();
    Ground::Grid(HeightGrid {
        columns: l.width,
        rows: l.height,
        heights,
    })
}

/// Shape `k` of a deformer, and where it goes on surface `i` at frame `f`.
fn deformer(i: usize, k: u32, f: u32, seed: f32) -> Deformer {
    let shape = match k % 3 {
        0 => Shape::Sphere {
            radius: 0.15 + 0.1 * seed,
        },
        1 => Shape::Capsule {
            radius: 0.08,
            half_height: 0.2 + 0.1 * seed,
        },
        _ => Shape::Box {
            half_extents: Vec3::new(0.2, 0.1, 0.12 + 0.05 * seed),
        },
    };
    let at = |f: u32| {
        let t = f as f32 * 0.07 + seed * 3.0 + k as f32;
        Pose {
            position: Vec3::new(
                i as f32 * 12.0 + 1.6 * t.sin(),
                1.0 + 0.22 + 0.1 * (t * 1.7).cos(),
                1.2 * (t * 0.8).cos(),
            ),
            rotation: Quat::from_rotation_y(t) * Quat::from_rotation_x(0.4 * seed),
        }
    };
    Deformer::moving(shape, at(f.saturating_sub(1)), at(f))
}

/// What the two paths captured over every frame of a random world.
#[derive(Default)]
struct Compared {
    /// Texels both captured, over every frame and surface.
    both: usize,
    /// Of those, where the codes differ.
    unequal: usize,
    /// Texels one path captured and the other did not.
    edges: usize,
    /// Of those (on flat surfaces), where the compute path disagrees with the CPU reference.
    compute_wrong: usize,
    /// The heightmaps at the end, raster then compute.
    maps: Vec<(Vec<u16>, Vec<u16>)>,
}

fn compare(listed: bool, spots: &[Spot], per: u32, seed: f32) -> Compared {
    let mut worlds = [
        world(CapturePath::Raster, listed),
        world(CapturePath::Compute, listed),
    ];
    let descs: Vec<SurfaceDesc> = spots.iter().enumerate().map(|(i, s)| desc(i, s)).collect();
    let mut ids: Vec<Vec<SurfaceId>> = vec![Vec::new(), Vec::new()];
    for (w, ids) in worlds.iter_mut().zip(&mut ids) {
        for (d, s) in descs.iter().zip(spots) {
            let id = w.add_surface(d.clone()).unwrap();
            if s.hills {
                w.set_ground(id, &hills(d), SlopeRule::default()).unwrap();
            }
            ids.push(id);
        }
    }
    let mut out = Compared::default();
    for f in 0..6 {
        let ds: Vec<Deformer> = (0..spots.len())
            .flat_map(|i| (0..per).map(move |k| deformer(i, k, f, seed)))
            .collect();
        for w in &mut worlds {
            w.step(1.0 / 30.0, &ds).unwrap();
        }
        for (i, d) in descs.iter().enumerate() {
            let raster = worlds[0].read_last_capture_region(ids[0][i]).unwrap();
            let compute = worlds[1].read_last_capture_region(ids[1][i]).unwrap();
            let (Some(raster), Some(compute)) = (raster, compute) else {
                assert_eq!(
                    worlds[0].read_last_capture(ids[0][i]).unwrap().is_some(),
                    worlds[1].read_last_capture(ids[1][i]).unwrap().is_some()
                );
                continue;
            };
            let reference = (!spots[i].hills).then(|| cpu_capture(d, &ds));
            for (k, (r, c)) in raster.iter().zip(&compute).enumerate() {
                match (*r < 1.0, *c < 1.0) {
                    (true, true) => {
                        out.both += 1;
                        out.unequal += usize::from(r.to_bits() != c.to_bits());
                    }
                    (false, false) => {}
                    _ => {
                        out.edges += 1;
                        if let Some(cpu) = &reference {
                            out.compute_wrong += usize::from((cpu[k] < 1.0) != (*c < 1.0));
                        }
                    }
                }
            }
        }
    }
    for (&a, &b) in ids[0].iter().zip(&ids[1]) {
        let map = |w: &SnowWorld, id| {
            let m = w.read_heightmap(id).unwrap();
            m.depression.iter().chain(&m.displaced).copied().collect()
        };
        out.maps.push((map(&worlds[0], a), map(&worlds[1], b)));
    }
    out
}

/// The CPU reference's capture of a flat surface's region pressed by `deformers`.
fn cpu_capture(d: &SurfaceDesc, deformers: &[Deformer]) -> Vec<f32> {
    let l = d.layout();
    let volume = CaptureVolume {
        world_to_local: d.world_to_local(),
        half_size: CaptureVolume::of_region(d.size * 0.5, l.width, l.height),
        frustum_height: d.snow_depth + 0.25,
        ground: (0.0, 0.0),
    };
    let mut prims = Vec::new();
    for x in deformers {
        capture::push_primitives(x, &volume, &mut prims);
    }
    cap_cpu::capture_region(
        l.width,
        l.height,
        d.size * 0.5,
        volume.frustum_height,
        &prims,
        &[],
    )
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(6))]

    /// Where both paths capture a texel they write the same code. The raster path may miss a
    /// texel whose centre lies on a primitive's rectangle's edge (the rasterizer's rule): at most
    /// one in a thousand, and there the compute path agrees with the CPU reference. With no such
    /// texel, the heightmaps are the same bit for bit.
    #[test]
    fn compute_and_raster_capture_write_the_same_bits(
        spots in prop::collection::vec(
            ((1.5f32..6.0, 1.5f32..6.0), -60.0f32..60.0, any::<bool>())
                .prop_map(|(size, yaw, hills)| Spot { size, yaw, hills }),
            1..5,
        ),
        per in 1u32..12,
        seed in 0.0f32..1.0,
        listed in any::<bool>(),
    ) {
        let c = compare(listed, &spots, per, seed);
        // A surface under 2 m across with one deformer lies off that deformer's path (it runs
        // 1.2 m out along z): neither path may capture anything there, and the case compares
        // nothing, so another is drawn.
        prop_assert!(c.both > 0 || c.edges == 0, "only one path captured");
        prop_assume!(c.both > 0);
        prop_assert_eq!(c.unequal, 0, "codes differ where both captured");
        prop_assert!(c.edges * 1000 <= c.both, "{} edge texels of {}", c.edges, c.both);
        prop_assert_eq!(c.compute_wrong, 0, "the compute path misses the reference");
        if c.edges == 0 {
            for (i, (a, b)) in c.maps.iter().enumerate() {
                let diff = a.iter().zip(b).filter(|(x, y)| x != y).count();
                prop_assert_eq!(diff, 0, "surface {} ({:?}) differs", i, spots[i]);
            }
        }
    }
}

/// The compute path records no viewport: a frame of analytic deformers alone renders nothing
/// over the atlas.
#[test]
fn analytic_deformers_alone_need_no_pass_over_the_atlas() {
    let spots = [Spot {
        size: (4.0, 3.0),
        yaw: 20.0,
        hills: false,
    }];
    let mut w = world(CapturePath::Compute, false);
    w.add_surface(desc(0, &spots[0])).unwrap();
    let stats = w.step(1.0 / 30.0, &[deformer(0, 0, 1, 0.5)]).unwrap();
    assert_eq!((stats.captured, stats.capture_batches), (1, 0));
    let mut w = world(CapturePath::Raster, false);
    w.add_surface(desc(0, &spots[0])).unwrap();
    let stats = w.step(1.0 / 30.0, &[deformer(0, 0, 1, 0.5)]).unwrap();
    assert_eq!((stats.captured, stats.capture_batches), (1, 1));
}

/// The compute path leaves the capture buffer uncleared: it writes every texel of the tiles it
/// takes and of the tiles beside them, all that the update may read. A surface pressed at one spot,
/// whose region now lies where another surface's capture, pressed all over, lay the frame before,
/// updates as the raster path (whose regions are cleared) updates it: none of the earlier capture
/// is read back, with the fused pass on its grid or on its list of tiles.
#[test]
fn a_region_over_an_earlier_frames_capture_reads_none_of_it() {
    for listed in [false, true] {
        let mut worlds = [
            world(CapturePath::Raster, listed),
            world(CapturePath::Compute, listed),
        ];
        let first = SurfaceDesc::new("first", [0.0, 0.0, 0.0], [2.0, 2.0], 0.3);
        let second = SurfaceDesc::new("second", [10.0, 0.0, 0.0], [2.0, 2.0], 0.3);
        let a = worlds[0].add_surface(first.clone()).unwrap();
        let texel = 2.0 / worlds[0].layout(a).unwrap().width as f32;
        worlds[1].add_surface(first.clone()).unwrap();
        let ids = [
            worlds[0].add_surface(second.clone()).unwrap(),
            worlds[1].add_surface(second.clone()).unwrap(),
        ];
        // Frame 1: a ball 5 m across presses the first surface all over (to 10 cm above the ground
        // at its corners), and a small one the second. Frame 2: only the small one, so the second
        // surface's region comes first in the capture buffer, where the first's lay. It presses
        // region tile 1 only (surface texels 16 to 19, the footprint's margin included), and flags
        // surface tile 0 too, whose blur reads region tile 0.
        let small = Deformer::new(
            Shape::Sphere { radius: 0.05 },
            Pose::at([10.0 - 1.0 + 18.0 * texel, 0.2, 0.0]),
        );
        let big = Deformer::new(Shape::Sphere { radius: 5.0 }, Pose::at([0.0, 4.95, 0.0]));
        for w in &mut worlds {
            w.step(1.0 / 30.0, &[big, small]).unwrap();
            w.step(1.0 / 30.0, &[small]).unwrap();
        }
        let maps: Vec<_> = worlds
            .iter()
            .zip(ids)
            .map(|(w, id)| w.read_heightmap(id).unwrap())
            .collect();
        assert!(
            maps[0].depression.iter().any(|&d| d > 0),
            "the small ball pressed"
        );
        let differ = |a: &[u16], b: &[u16]| a.iter().zip(b).filter(|(x, y)| x != y).count();
        let (d, g) = (
            differ(&maps[0].depression, &maps[1].depression),
            differ(&maps[0].displaced, &maps[1].displaced),
        );
        assert_eq!(
            (d, g),
            (0, 0),
            "texels that differ (depression, displaced), listed: {listed}"
        );
    }
}

/// The heightmaps of every surface after each frame of a random world run with `first` and then
/// with `second`, the update on its list of tiles or on its grid, the snowfall streamed or not, the
/// heights stored at `precision`, the update's own cast in workgroups of 128 invocations (`many`)
/// or of 256.
fn heightmaps_of_two_paths(
    paths: [CapturePath; 2],
    (listed, streamed, many): (bool, bool, bool),
    precision: Precision,
    spots: &[Spot],
    per: u32,
    seed: f32,
) -> Vec<[Vec<u16>; 2]> {
    let mut worlds = paths.map(|path| {
        SnowWorld::new(
            common::gpu(),
            WorldConfig {
                capture_path: path,
                list_tiles_from: if listed { 0 } else { u32::MAX },
                refill_stream_from: if streamed { 0 } else { u32::MAX },
                cast_many_from: if many { 0 } else { u32::MAX },
                format: PoolFormat::new(precision),
                ..WorldConfig::default()
            },
        )
        .expect("world")
    });
    let descs: Vec<SurfaceDesc> = spots.iter().enumerate().map(|(i, s)| desc(i, s)).collect();
    let mut ids: Vec<SurfaceId> = Vec::new();
    for w in &mut worlds {
        ids.clear();
        for (d, s) in descs.iter().zip(spots) {
            let id = w.add_surface(d.clone()).unwrap();
            if s.hills {
                w.set_ground(id, &hills(d), SlopeRule::default()).unwrap();
            }
            ids.push(id);
        }
    }
    let mut maps = Vec::new();
    for f in 0..5 {
        let ds: Vec<Deformer> = (0..spots.len())
            .flat_map(|i| (0..per).map(move |k| deformer(i, k, f, seed)))
            .collect();
        for w in &mut worlds {
            w.step(1.0 / 30.0, &ds).unwrap();
        }
        for &id in &ids {
            maps.push(worlds.each_ref().map(|w| {
                let m = w.read_heightmap(id).unwrap();
                m.depression.iter().chain(&m.displaced).copied().collect()
            }));
        }
    }
    maps
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(4))]

    /// The update's own ray cast (`CapturePath::Update`: no capture) leaves every heightmap, after
    /// every frame, as the compute path's capture does, bit for bit: on hills and on flat ground,
    /// yawed, with the update on its grid (the tiles test the footprints) and on its list (the plan
    /// lists the tiles), snow refilling in the fused pass or streamed before it, at each precision
    /// (8 bits: a workgroup's invocation takes a unit of two texels), the cast's workgroups of 128
    /// invocations and of 256 each taking one precision or two.
    #[test]
    fn the_updates_own_ray_cast_gives_the_compute_paths_heights(
        spots in prop::collection::vec(
            ((1.5f32..6.0, 1.5f32..6.0), -60.0f32..60.0, any::<bool>())
                .prop_map(|(size, yaw, hills)| Spot { size, yaw, hills }),
            1..4,
        ),
        per in 1u32..12,
        seed in 0.0f32..1.0,
        listed in any::<bool>(),
        streamed in any::<bool>(),
        flip in any::<bool>(),
    ) {
        let paths = [CapturePath::Compute, CapturePath::Update];
        let mut pressed = false;
        for (i, precision) in [Precision::Bits8, Precision::Bits16, Precision::Bits32]
            .into_iter()
            .enumerate()
        {
            let many = (i % 2 == 1) != flip;
            let ways = (listed, streamed, many);
            let maps = heightmaps_of_two_paths(paths, ways, precision, &spots, per, seed);
            for (k, [a, b]) in maps.iter().enumerate() {
                let diff = a.iter().zip(b).filter(|(x, y)| x != y).count();
                let (frame, surface) = (k / spots.len(), k % spots.len());
                prop_assert_eq!(
                    diff, 0, "{:?}, many {}: frame {} surface {} differs", precision, many, frame, surface
                );
            }
            pressed |= maps.iter().any(|[a, _]| a.iter().any(|&v| v > 0));
        }
        // A surface under 2 m across with one deformer lies off that deformer's path (it runs
        // 1.2 m out along z): both paths leave it untouched (above), and the case counts only
        // where something was pressed.
        prop_assume!(pressed);
    }
}

/// A surface the update ray-casts has no capture: no pass over the atlas, no bytes cleared, nothing
/// to read back; one pressed by more primitives than the update casts is captured by the compute
/// path, in the same frame.
#[test]
fn what_the_update_casts_is_not_captured() {
    let mut w = world(CapturePath::Update, false);
    let few = w
        .add_surface(desc(
            0,
            &Spot {
                size: (4.0, 3.0),
                yaw: 20.0,
                hills: false,
            },
        ))
        .unwrap();
    let many = w
        .add_surface(desc(
            1,
            &Spot {
                size: (4.0, 3.0),
                yaw: 0.0,
                hills: false,
            },
        ))
        .unwrap();
    let mut ds = vec![deformer(0, 0, 1, 0.5)];
    // Resting spheres (one primitive each) over the second surface, more than the update casts.
    let n = snowprint::low_level::capture::CAST_PRIMS_MAX + 1;
    ds.extend((0..n).map(|k| {
        Deformer::new(
            Shape::Sphere { radius: 0.05 },
            Pose::at([12.0 - 1.5 + 0.09 * k as f32, 1.02, 0.0]),
        )
    }));
    let stats = w.step(1.0 / 30.0, &ds).unwrap();
    assert_eq!((stats.captured, stats.capture_batches), (2, 0));
    assert!(
        w.read_last_capture(few).unwrap().is_none(),
        "cast: nothing captured"
    );
    let captured = w
        .read_last_capture(many)
        .unwrap()
        .expect("the compute path's capture");
    assert!(captured.iter().any(|&d| d < 1.0));
    for id in [few, many] {
        let m = w.read_heightmap(id).unwrap();
        assert!(m.depression.iter().any(|&d| d > 0), "pressed");
    }
}

/// One frame's deformers for `mixed_frames`: a moving sphere over surfaces 0 and 2 (cast by the
/// update), more resting spheres than it casts over surfaces 1 and 3 (captured), none over 4.
fn mixed_deformers(f: u32) -> Vec<Deformer> {
    let mut ds = vec![deformer(0, 0, f, 0.3), deformer(2, 1, f, 0.6)];
    for i in [1usize, 3] {
        let n = snowprint::low_level::capture::CAST_PRIMS_MAX + 3;
        ds.extend((0..n).map(|k| {
            let x = i as f32 * 12.0 - 1.5 + 0.09 * k as f32;
            Deformer::new(
                Shape::Sphere { radius: 0.05 },
                Pose::at([x, 1.02 - 0.002 * f as f32, 0.1 * (k % 3) as f32]),
            )
        }));
    }
    ds
}

/// Surfaces the update casts and surfaces the capture holds in one frame, some refilling snow and
/// some not (surfaces 0, 3 and 4 refill), on the fused pass's grid and on its list, the snowfall
/// streamed or not: every heightmap after every frame is the compute path's, bit for bit. (The
/// grid then starts after the cast records that refill, which the list's header names.)
#[test]
fn cast_and_captured_surfaces_in_one_frame_update_as_the_compute_path() {
    let spot = Spot {
        size: (3.0, 2.5),
        yaw: 15.0,
        hills: false,
    };
    for (listed, streamed) in [(false, false), (true, false), (false, true), (true, true)] {
        let mut worlds = [CapturePath::Compute, CapturePath::Update].map(|path| {
            let config = WorldConfig {
                capture_path: path,
                list_tiles_from: if listed { 0 } else { u32::MAX },
                refill_stream_from: if streamed { 0 } else { u32::MAX },
                ..WorldConfig::default()
            };
            SnowWorld::new(common::gpu(), config).expect("world")
        });
        let mut ids = Vec::new();
        for w in &mut worlds {
            ids = (0..5)
                .map(|i| {
                    let mut d = desc(i, &spot);
                    d.replenish_rate = if [0, 3, 4].contains(&i) { 0.05 } else { 0.0 };
                    w.add_surface(d).unwrap()
                })
                .collect();
        }
        let mut pressed = 0;
        for f in 0..4 {
            let ds = mixed_deformers(f);
            let stats = worlds.each_mut().map(|w| w.step(1.0 / 30.0, &ds).unwrap());
            assert_eq!(stats[0].captured, 4);
            assert_eq!(stats[1].captured, 4);
            for &id in &ids {
                let [a, b] = worlds.each_ref().map(|w| {
                    let m = w.read_heightmap(id).unwrap();
                    let v: Vec<u16> = m.depression.iter().chain(&m.displaced).copied().collect();
                    v
                });
                pressed += a.iter().filter(|&&v| v > 0).count();
                let diff = a.iter().zip(&b).filter(|(x, y)| x != y).count();
                assert_eq!(
                    diff, 0,
                    "frame {f} {id:?}: listed {listed}, streamed {streamed}"
                );
            }
        }
        assert!(pressed > 0);
        assert!(worlds[1].read_last_capture(ids[0]).unwrap().is_none());
        assert!(worlds[1].read_last_capture(ids[1]).unwrap().is_some());
    }
}

/// More cast tiles than a dispatch's row holds (65,535): 257 surfaces of 256^2 texels whose snow
/// refills, so that the fused pass takes every tile of each (65,792 in two rows of workgroups);
/// each pressed in its last tile, then in its first while the first print refills. Every surface's
/// first print refilled says that every tile was updated, in either row.
#[test]
fn more_cast_tiles_than_a_dispatch_row_are_all_updated() {
    let (side, n) = (256u32, 257usize);
    let format = PoolFormat::new(Precision::Bits8);
    let mut w = SnowWorld::new(
        common::gpu(),
        WorldConfig {
            capture_path: CapturePath::Update,
            refill_stream_from: u32::MAX,
            format,
            pool_bytes: format.slot_bytes(side, side) * n as u64,
            ..WorldConfig::default()
        },
    )
    .expect("world");
    // Texels of 4 cm: `side` a side.
    let metres = side as f32 * 0.04;
    let x = |i: usize| i as f32 * (metres + 1.0);
    let ids: Vec<SurfaceId> = (0..n)
        .map(|i| {
            let mut d = SurfaceDesc::new(&format!("s{i}"), [x(i), 0.0, 0.0], [metres; 2], 0.3);
            d.replenish_rate = 0.5;
            w.add_surface(d).unwrap()
        })
        .collect();
    assert_eq!(w.layout(ids[0]).unwrap().width, side);
    // A ball pressing to the ground near the (+x, +z) corner, or the (-x, -z) one.
    let balls = |corner: f32| -> Vec<Deformer> {
        let at = corner * (metres * 0.5 - 0.3);
        (0..n)
            .map(|i| {
                Deformer::new(
                    Shape::Sphere { radius: 0.2 },
                    Pose::at([x(i) + at, 0.1, at]),
                )
            })
            .collect()
    };
    w.step(0.1, &balls(1.0)).unwrap();
    let first: Vec<Vec<u32>> = ids
        .iter()
        .map(|&id| w.read_channels(id).unwrap().0)
        .collect();
    w.step(0.1, &balls(-1.0)).unwrap();
    for (k, &id) in ids.iter().enumerate() {
        let after = w.read_channels(id).unwrap().0;
        let (t, &deep) = first[k]
            .iter()
            .enumerate()
            .max_by_key(|&(_, v)| *v)
            .unwrap();
        assert!(deep > 200, "surface {k} pressed to {deep}");
        assert!(after[t] < deep, "surface {k}: its first print refilled");
    }
}
