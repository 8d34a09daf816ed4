//! The deformation core on the GPU: every stage against its CPU reference, and analytic cases
//! computed by hand.

mod common;

use glam::{Quat, Vec2, Vec3};
use snowprint::low_level::capture::{self, CaptureVolume};
use snowprint::reference::accumulate::{self as acc_cpu, BlurInput};
use snowprint::reference::capture as cap_cpu;
use snowprint::{
    CaptureConfig, CaptureMode, Deformer, Mesh, PassMode, PoolFormat, Pose, Precision, Shape,
    SnowError, SnowWorld, SurfaceDesc, WorldConfig,
};

const ANKLE: f32 = 0.25;

/// Largest difference in captured height between GPU and CPU, metres (a 1/800 of a 4 cm texel),
/// beyond the range the CPU's heights span with the deformers nudged by
/// `common::POSITION_SLACK`. GPU compilers contract `a * b + c` into fused multiply-adds and use
/// approximate square roots and divisions; where a vertical ray grazes a silhouette, the root of a
/// nearly-zero discriminant amplifies those last-bit differences without bound (an H100 put one
/// texel 78 um from the CPU's height at its centre, inside the nudged range). Software Vulkan
/// matches the CPU to about 1e-7.
const CAPTURE_HEIGHT_TOLERANCE: f32 = 5e-5;

fn world(mode: CaptureMode) -> SnowWorld {
    world_with(mode, true)
}

fn world_with(mode: CaptureMode, fused: bool) -> SnowWorld {
    world_format(mode, fused, PoolFormat::default())
}

fn world_format(mode: CaptureMode, fused: bool, format: PoolFormat) -> SnowWorld {
    let d = WorldConfig::default();
    world_listing(mode, fused, format, d.list_tiles_from, d.refill_stream_from)
}

/// A world whose fused update lists touched tiles from `list_tiles_from` tiles on (0: always)
/// and streams snowfall's refill from `refill_stream_from` words on (0: always).
fn world_listing(
    mode: CaptureMode,
    fused: bool,
    format: PoolFormat,
    list_tiles_from: u32,
    refill_stream_from: u32,
) -> SnowWorld {
    SnowWorld::new(
        common::gpu(),
        WorldConfig {
            capture: CaptureConfig {
                mode,
                ankle_height: ANKLE,
                mask_depth: 0.6,
            },
            pool_bytes: 16 << 20,
            passes: if fused {
                PassMode::Fused
            } else {
                PassMode::Separate
            },
            format,
            list_tiles_from,
            refill_stream_from,
            ..Default::default()
        },
    )
    .expect("world")
}

/// Channel units GPU and CPU merges may differ by: one unit (the f32 blur may round the other way
/// across a quantization step); at 32 bits, where a unit is 2^-32 of the snow depth, a millionth
/// of the snow depth (a few last places of the f32 blur).
fn merge_slack(precision: Precision) -> u32 {
    match precision {
        Precision::Bits32 => (u32::MAX as f64 * 1e-6) as u32,
        _ => 1,
    }
}

fn volume(desc: &SurfaceDesc) -> CaptureVolume {
    CaptureVolume {
        world_to_local: desc.world_to_local(),
        half_size: desc.size * 0.5,
        frustum_height: desc.snow_depth + ANKLE,
        ground: (0.0, 0.0),
    }
}

fn blur_input(desc: &SurfaceDesc, mode: CaptureMode) -> BlurInput {
    let l = desc.layout();
    BlurInput {
        width: l.width,
        height: l.height,
        mode,
        mask_fraction: 0.6,
        snow_depth: desc.snow_depth,
        frustum_height: desc.snow_depth + ANKLE,
    }
}

/// A mixed set of analytic deformers over a surface centred at `c` (ground height c.y).
fn crowd(c: Vec3) -> Vec<Deformer> {
    vec![
        Deformer::new(
            Shape::Sphere { radius: 0.3 },
            Pose::at((c + Vec3::new(-0.8, 0.2, 0.3)).into()),
        ),
        Deformer::moving(
            Shape::Sphere { radius: 0.15 },
            Pose::at((c + Vec3::new(0.2, 0.1, -0.9)).into()),
            Pose::at((c + Vec3::new(1.3, 0.05, -0.4)).into()),
        ),
        Deformer::new(
            Shape::Capsule {
                radius: 0.1,
                half_height: 0.4,
            },
            Pose {
                position: c + Vec3::new(0.6, 0.12, 0.7),
                rotation: Quat::from_euler(glam::EulerRot::YXZ, 0.5, 0.3, 1.2),
            },
        ),
        Deformer::new(
            Shape::Box {
                half_extents: Vec3::new(0.3, 0.1, 0.15),
            },
            Pose {
                position: c + Vec3::new(-1.2, 0.15, -0.8),
                rotation: Quat::from_euler(glam::EulerRot::YXZ, 0.7, 0.2, -0.3),
            },
        ),
        // Sunk into the ground.
        Deformer::new(
            Shape::Sphere { radius: 0.4 },
            Pose::at((c + Vec3::new(1.4, -0.25, 0.9)).into()),
        ),
        // Above the frustum: leaves nothing.
        Deformer::new(
            Shape::Sphere { radius: 0.2 },
            Pose::at((c + Vec3::new(0.0, 0.3 + ANKLE + 0.21, 0.0)).into()),
        ),
    ]
}

/// Every stage of one update against its CPU reference, on several sizes, non-square and yawed,
/// at every precision (odd widths at 8 bits, whose rows are padded to whole words).
#[test]
fn every_stage_matches_its_cpu_reference() {
    for (size, yaw, precision) in [
        ([4.0, 3.0], 0.0, Precision::Bits16),
        ([3.3, 2.1], 30.0, Precision::Bits8),
        ([1.0, 4.5], -75.0, Precision::Bits32),
        ([6.0, 6.0], 0.0, Precision::Bits16),
    ] {
        let format = PoolFormat {
            precision,
            normals: true,
        };
        let mut w = world_format(CaptureMode::Depth, false, format);
        let mut desc = SurfaceDesc::new("s", [2.0, 1.0, -3.0], size, 0.3);
        desc.yaw_degrees = yaw;
        desc.replenish_rate = 0.5;
        let id = w.add_surface(desc.clone()).unwrap();
        let deformers = crowd(desc.center);
        let l = desc.layout();
        if precision == Precision::Bits8 {
            assert_eq!(
                l.width % 2,
                1,
                "an odd width exercises the padded 8-bit rows"
            );
        }
        // Two frames: the second merges into a non-empty history and replenishes.
        let zero = vec![0u32; l.texels() as usize];
        let mut before = (zero.clone(), zero);
        for frame in 0..2 {
            let dt = 0.1;
            let stats = w.step(dt, &deformers[frame..]).unwrap();
            assert_eq!(stats.updated, 1);
            let vol = volume(&desc);
            let cpu_of = |ds: &[Deformer]| {
                let mut prims = vec![];
                for d in ds {
                    capture::push_primitives(d, &vol, &mut prims);
                }
                cap_cpu::capture(
                    l.width,
                    l.height,
                    vol.half_size,
                    vol.frustum_height,
                    &prims,
                    &[],
                )
            };
            // Capture.
            let gpu_cap = w
                .read_last_capture(id)
                .unwrap()
                .expect("captured in the last batch");
            let cpu_cap = cpu_of(&deformers[frame..]);
            let envelope = common::capture_envelope(&cpu_cap, &deformers[frame..], cpu_of);
            let mut coverage_mismatch = 0;
            for ((g, c), range) in gpu_cap.iter().zip(&cpu_cap).zip(&envelope) {
                if (*g < 1.0) != (*c < 1.0) {
                    coverage_mismatch += 1;
                } else {
                    let dh = common::outside(*g, *range) * vol.frustum_height;
                    assert!(
                        dh <= CAPTURE_HEIGHT_TOLERANCE,
                        "capture {g} vs cpu {c} (nudged {range:?}): {dh} m apart ({size:?})"
                    );
                }
            }
            assert!(
                coverage_mismatch * 1000 <= gpu_cap.len(),
                "{coverage_mismatch} texels differ in coverage"
            );
            assert!(gpu_cap.iter().any(|&d| d < 1.0), "something was captured");
            // Stage 1.
            let inp = blur_input(&desc, CaptureMode::Depth);
            let gpu_blur = w.read_last_blurred(id).unwrap().unwrap();
            // The blur reads the capture's apron too: the GPU's region, the surface's texels and
            // one around them.
            let gpu_region = w.read_last_capture_region(id).unwrap().unwrap();
            let cpu_blur = acc_cpu::blur(&inp, &gpu_region);
            for (g, c) in gpu_blur.iter().zip(&cpu_blur) {
                assert!((g - c).abs() < 1e-5, "blur {g} vs {c}");
            }
            // Stage 2: 0.5/s x 0.1 s x channel_max units a frame, applied whole, the fraction
            // carried (at 16 bits: 3276.75, so 3276 then 3277).
            let rate = 0.05 * precision.channel_max() as f64;
            let units =
                ((frame + 1) as f64 * rate).floor() as u32 - (frame as f64 * rate).floor() as u32;
            let gpu = w.read_channels(id).unwrap();
            let cpu = acc_cpu::merge(&before.0, &before.1, Some(&gpu_blur), units, precision);
            let slack = merge_slack(precision);
            for i in 0..gpu.0.len() {
                let dd = gpu.0[i].abs_diff(cpu.0[i]);
                let dg = gpu.1[i].abs_diff(cpu.1[i]);
                assert!(
                    dd <= slack && dg <= slack,
                    "merge at {precision}: ({}, {}) vs ({}, {})",
                    gpu.0[i],
                    gpu.1[i],
                    cpu.0[i],
                    cpu.1[i]
                );
            }
            assert!(gpu.0.iter().any(|&v| v > 0), "something was pressed");
            // Normals.
            let texel = desc.size / Vec2::new(l.width as f32, l.height as f32);
            let cpu_n = acc_cpu::normals(
                &gpu.0,
                precision,
                l.width,
                l.height,
                desc.snow_depth,
                texel.x,
                texel.y,
            );
            let gpu_n = w.read_normals_packed(id).unwrap();
            for (g, c) in gpu_n.iter().zip(&cpu_n) {
                let (gx, gz) = acc_cpu::unpack2x16snorm(*g);
                let (cx, cz) = acc_cpu::unpack2x16snorm(*c);
                assert!(
                    (gx - cx).abs() < 1e-3 && (gz - cz).abs() < 1e-3,
                    "normal {gx},{gz} vs {cx},{cz}"
                );
            }
            before = gpu;
        }
    }
}

/// Mesh deformers rasterized from below agree with ray casts, including a mesh sunk below the
/// ground, where the back faces seen through the cut must fill the ground and never leak the
/// far side.
#[test]
fn mesh_capture_matches_cpu_and_clamps_to_the_ground() {
    let mut w = world(CaptureMode::Depth);
    let desc = SurfaceDesc::new("m", [0.0, 0.0, 0.0], [3.0, 2.0], 0.3);
    let id = w.add_surface(desc.clone()).unwrap();
    let sphere = Mesh::uv_sphere(0.4, 24, 48);
    let boxy = Mesh::cuboid(Vec3::new(0.25, 0.2, 0.15));
    let ms = w.add_mesh("sphere", &sphere).unwrap();
    let mb = w.add_mesh("box", &boxy).unwrap();
    let poses = [
        (ms, &sphere, Pose::at([-0.7, -0.2, 0.0])),
        (
            mb,
            &boxy,
            Pose {
                position: Vec3::new(0.7, 0.1, 0.2),
                rotation: Quat::from_rotation_y(0.6) * Quat::from_rotation_x(0.4),
            },
        ),
    ];
    let deformers: Vec<Deformer> = poses
        .iter()
        .map(|(m, _, p)| Deformer::new(Shape::Mesh(*m), *p))
        .collect();
    w.step(1.0 / 60.0, &deformers).unwrap();
    let l = desc.layout();
    let vol = volume(&desc);
    let mut tris = vec![];
    for (_, mesh, pose) in &poses {
        let m = vol.world_to_local
            * glam::Mat4::from_rotation_translation(pose.rotation, pose.position);
        let t = mesh.transformed(m);
        for i in t.indices.chunks(3) {
            tris.push([
                t.positions[i[0] as usize],
                t.positions[i[1] as usize],
                t.positions[i[2] as usize],
            ]);
        }
    }
    let gpu_cap = w.read_last_capture(id).unwrap().unwrap();
    let cpu_cap = cap_cpu::capture(
        l.width,
        l.height,
        vol.half_size,
        vol.frustum_height,
        &[],
        &tris,
    );
    // Only texels whose centre lies on a triangle edge may differ, and by no more than the edge
    // can move a value: the GPU's value must be one the ray cast finds within a texel of it (the
    // range of the CPU values of the 3x3 texels around it), never an arbitrary one.
    let mut mismatch = 0;
    for row in 0..l.height {
        for col in 0..l.width {
            let i = (row * l.width + col) as usize;
            let (g, c) = (gpu_cap[i], cpu_cap[i]);
            if (g < 1.0) == (c < 1.0) && (g - c).abs() <= 1e-4 {
                continue;
            }
            mismatch += 1;
            let mut range = (f32::MAX, f32::MIN);
            for dr in -1i32..=1 {
                for dc in -1i32..=1 {
                    let (r, q) = (row as i32 + dr, col as i32 + dc);
                    if r >= 0 && q >= 0 && (r as u32) < l.height && (q as u32) < l.width {
                        let v = cpu_cap[(r as u32 * l.width + q as u32) as usize];
                        range = (range.0.min(v), range.1.max(v));
                    }
                }
            }
            assert!(
                g >= range.0 - 1e-4 && g <= range.1 + 1e-4,
                "texel ({col}, {row}): GPU {g}, ray cast {c}, and its neighbours span {range:?}"
            );
        }
    }
    assert!(
        mismatch * 100 <= gpu_cap.len(),
        "{mismatch} of {} texels differ",
        gpu_cap.len()
    );
    // The sunk sphere (centre 0.2 below the ground, radius 0.4) fills a disc of radius
    // sqrt(0.16 - 0.04) = 0.346 at ground level with depth 0, and nothing outside it.
    let texel = 3.0 / l.width as f32;
    for row in 0..l.height {
        for col in 0..l.width {
            let c = cap_cpu::texel_center(col, row, l.width, l.height, vol.half_size);
            let d = (c - Vec2::new(-0.7, 0.0)).length();
            let v = gpu_cap[(row * l.width + col) as usize];
            if d < 0.346 - texel {
                assert_eq!(v, 0.0, "inside the cross-section at {c:?}");
            } else if d > 0.346 + texel && d < 1.0 {
                assert_eq!(v, 1.0, "outside the cross-section at {c:?}");
            }
        }
    }
}

/// The analytic depression of a sphere: clamp((top - (c - sqrt(r^2 - d^2))) / D, 0, 1).
fn sphere_depression(top: f32, c: f32, r: f32, d: f32, depth: f32) -> f32 {
    if d >= r {
        return 0.0;
    }
    ((top - (c - (r * r - d * d).sqrt())) / depth).clamp(0.0, 1.0)
}

/// Each texel lies within the analytic values of its 3x3 neighbourhood (the capture samples texel
/// centres, the blur mixes the 3x3 centres around a texel), give or take one unit of quantization.
/// Each centre is also probed 0.5 mm away, so that a centre lying exactly on a rim (where the
/// depression jumps) may fall on either side of it, as it may on the GPU.
fn assert_within_blur_spread(
    map: &snowprint::Heightmap,
    half: Vec2,
    analytic: impl Fn(Vec2) -> f32,
) {
    let (w, h) = (map.width, map.height);
    let mut checked = 0;
    let probes = [Vec2::ZERO, Vec2::X, -Vec2::X, Vec2::Y, -Vec2::Y].map(|v| v * 5e-4);
    for row in 0..h {
        for col in 0..w {
            let mut lo = f32::MAX;
            let mut hi = f32::MIN;
            for dy in -1i32..=1 {
                for dx in -1i32..=1 {
                    let (x, y) = (
                        (col as i32 + dx).clamp(0, w as i32 - 1),
                        (row as i32 + dy).clamp(0, h as i32 - 1),
                    );
                    let n = cap_cpu::texel_center(x as u32, y as u32, w, h, half);
                    for p in probes {
                        let v = analytic(n + p);
                        lo = lo.min(v);
                        hi = hi.max(v);
                    }
                }
            }
            let got = map.fraction(col, row);
            let unit = 1.5 / 65535.0;
            assert!(
                got >= lo - unit && got <= hi + unit,
                "texel ({col},{row}): {got} not in [{lo}, {hi}]"
            );
            if hi > 0.0 {
                checked += 1;
            }
        }
    }
    assert!(checked > 50, "the deformer touched only {checked} texels");
}

#[test]
fn sphere_leaves_the_analytic_depression() {
    let mut w = world(CaptureMode::Depth);
    let depth = 0.3;
    let desc = SurfaceDesc::new("a", [0.0, 5.0, 0.0], [2.0, 2.0], depth);
    let id = w.add_surface(desc.clone()).unwrap();
    let (r, c) = (0.35f32, 0.2f32); // centre 0.2 above the ground: bottom 0.15 below it... clamped
    for (r, c) in [(r, c), (0.25, 0.3), (0.5, 0.62)] {
        let mut w2 = world(CaptureMode::Depth);
        let id2 = w2.add_surface(desc.clone()).unwrap();
        w2.step(
            1.0 / 60.0,
            &[Deformer::new(
                Shape::Sphere { radius: r },
                Pose::at([0.1, 5.0 + c, -0.2]),
            )],
        )
        .unwrap();
        let map = w2.read_heightmap(id2).unwrap();
        assert_within_blur_spread(&map, Vec2::ONE, |p| {
            sphere_depression(depth, c, r, (p - Vec2::new(0.1, -0.2)).length(), depth)
        });
    }
    // Untouched surface reads all zero.
    assert!(
        w.read_heightmap(id)
            .unwrap()
            .depression
            .iter()
            .all(|&v| v == 0)
    );
}

#[test]
fn dragged_sphere_leaves_a_trench_with_the_same_cross_section() {
    let mut w = world(CaptureMode::Depth);
    let depth = 0.3;
    let desc = SurfaceDesc::new("t", [0.0, 0.0, 0.0], [4.0, 2.0], depth);
    let id = w.add_surface(desc.clone()).unwrap();
    let (r, c, z0) = (0.2f32, 0.15f32, 0.1f32);
    let frames = 40;
    let pos = |f: u32| Pose::at([-1.5 + 3.0 * f as f32 / frames as f32, c, z0]);
    for f in 1..=frames {
        w.step(
            1.0 / 60.0,
            &[Deformer::moving(
                Shape::Sphere { radius: r },
                pos(f - 1),
                pos(f),
            )],
        )
        .unwrap();
    }
    let map = w.read_heightmap(id).unwrap();
    // Distance from the segment the centre travelled.
    assert_within_blur_spread(&map, Vec2::new(2.0, 1.0), |p| {
        let x = p.x.clamp(-1.5, 1.5);
        sphere_depression(depth, c, r, (p - Vec2::new(x, z0)).length(), depth)
    });
}

#[test]
fn replenishment_refills_at_the_given_rate() {
    let mut w = world(CaptureMode::Depth);
    let mut desc = SurfaceDesc::new("r", [0.0, 0.0, 0.0], [1.0, 1.0], 0.3);
    desc.replenish_rate = 0.05;
    let id = w.add_surface(desc).unwrap();
    // Press the middle fully to the ground with a sunk sphere, in a step of dt = 0.
    w.step(
        0.0,
        &[Deformer::new(
            Shape::Sphere { radius: 0.3 },
            Pose::at([0.0, -0.1, 0.0]),
        )],
    )
    .unwrap();
    let centre = |w: &SnowWorld| {
        let m = w.read_heightmap(id).unwrap();
        m.depression[(m.height / 2 * m.width + m.width / 2) as usize]
    };
    assert_eq!(centre(&w), 65535);
    let dt = 1.0 / 60.0f32;
    for n in 1..=600u32 {
        w.step(dt, &[]).unwrap();
        if n % 150 == 0 {
            let t = n as f64 * dt as f64;
            let expect = (1.0 - 0.05 * t).max(0.0) * 65535.0;
            let got = centre(&w) as f64;
            assert!(
                (got - expect).abs() <= 1.0,
                "after {t} s: {got} vs {expect}"
            );
        }
    }
    // After 20 s at 5 %/s it is untouched again; 600 frames = 10 s, half refilled.
    for _ in 0..700 {
        w.step(dt, &[]).unwrap();
    }
    assert_eq!(centre(&w), 0);
}

#[test]
fn deformer_above_the_ankle_zone_leaves_nothing() {
    let mut w = world(CaptureMode::Depth);
    let desc = SurfaceDesc::new("h", [0.0, 2.0, 0.0], [2.0, 2.0], 0.3);
    let id = w.add_surface(desc).unwrap();
    let top_of_frustum = 2.0 + 0.3 + ANKLE;
    let d = [
        Deformer::new(
            Shape::Sphere { radius: 0.2 },
            Pose::at([0.0, top_of_frustum + 0.2 + 1e-3, 0.0]),
        ),
        // Inside the ankle zone but above the snow: captured, yet it presses nothing.
        Deformer::new(
            Shape::Box {
                half_extents: Vec3::splat(0.1),
            },
            Pose::at([0.5, 2.3 + 0.11, 0.5]),
        ),
    ];
    let stats = w.step(1.0 / 60.0, &d).unwrap();
    assert_eq!(
        stats.primitives, 1,
        "the sphere above the frustum is culled"
    );
    assert!(
        w.read_heightmap(id)
            .unwrap()
            .depression
            .iter()
            .all(|&v| v == 0)
    );
}

#[test]
fn sunk_sphere_flattens_exactly_its_ground_cross_section() {
    let mut w = world(CaptureMode::Depth);
    let desc = SurfaceDesc::new("g", [0.0, 0.0, 0.0], [2.0, 2.0], 0.3);
    let id = w.add_surface(desc.clone()).unwrap();
    // Centre 0.3 below the ground, radius 0.5: cross-section radius 0.4 at the ground.
    w.step(
        1.0 / 60.0,
        &[Deformer::new(
            Shape::Sphere { radius: 0.5 },
            Pose::at([0.0, -0.3, 0.0]),
        )],
    )
    .unwrap();
    let map = w.read_heightmap(id).unwrap();
    let l = desc.layout();
    let texel = 2.0 / l.width as f32;
    let (mut inside, mut outside) = (0, 0);
    for row in 0..l.height {
        for col in 0..l.width {
            let c = cap_cpu::texel_center(col, row, l.width, l.height, Vec2::ONE);
            let d = c.length();
            let v = map.depression[(row * l.width + col) as usize];
            if d < 0.4 - 1.5 * texel {
                assert_eq!(v, 65535, "inside at {c:?}");
                inside += 1;
            } else if d > 0.4 + 1.5 * texel {
                assert_eq!(v, 0, "outside at {c:?}");
                outside += 1;
            }
        }
    }
    assert!(inside > 100 && outside > 100);
}

#[test]
fn surfaces_side_by_side_each_see_only_what_is_over_them() {
    let mut w = world(CaptureMode::Depth);
    let a = w
        .add_surface(SurfaceDesc::new("a", [-1.0, 0.0, 0.0], [2.0, 2.0], 0.3))
        .unwrap();
    let b = w
        .add_surface(SurfaceDesc::new("b", [1.0, 0.0, 0.0], [2.0, 2.0], 0.3))
        .unwrap();
    // Only over a:
    w.step(
        1.0 / 60.0,
        &[Deformer::new(
            Shape::Sphere { radius: 0.2 },
            Pose::at([-1.0, 0.1, 0.0]),
        )],
    )
    .unwrap();
    assert!(
        w.read_heightmap(a)
            .unwrap()
            .depression
            .iter()
            .any(|&v| v > 0)
    );
    assert!(
        w.read_heightmap(b)
            .unwrap()
            .depression
            .iter()
            .all(|&v| v == 0)
    );
    // On a fresh pair, a box straddling the seam at x = 0: a sees its right edge, b its left edge,
    // nothing else.
    let mut w = world(CaptureMode::Depth);
    let a = w
        .add_surface(SurfaceDesc::new("a", [-1.0, 0.0, 0.0], [2.0, 2.0], 0.3))
        .unwrap();
    let b = w
        .add_surface(SurfaceDesc::new("b", [1.0, 0.0, 0.0], [2.0, 2.0], 0.3))
        .unwrap();
    w.step(
        1.0 / 60.0,
        &[Deformer::new(
            Shape::Box {
                half_extents: Vec3::new(0.3, 0.5, 0.3),
            },
            Pose::at([0.0, 0.0, 0.5]),
        )],
    )
    .unwrap();
    let (ma, mb) = (w.read_heightmap(a).unwrap(), w.read_heightmap(b).unwrap());
    let l = ma.width;
    let pressed_cols = |m: &snowprint::Heightmap| {
        (0..m.width)
            .filter(|&c| (0..m.height).any(|r| m.depression[(r * m.width + c) as usize] == 65535))
            .collect::<Vec<_>>()
    };
    let ca = pressed_cols(&ma);
    let cb = pressed_cols(&mb);
    // 0.3 m of box over each side at 4 cm texels: 7 full columns (the eighth is blurred).
    assert!(ca.iter().all(|&c| c >= l - 8) && ca.len() >= 6, "a: {ca:?}");
    assert!(cb.iter().all(|&c| c < 8) && cb.len() >= 6, "b: {cb:?}");
}

#[test]
fn mask_capture_presses_a_fixed_imprint() {
    let mut w = world(CaptureMode::Mask);
    let desc = SurfaceDesc::new("k", [0.0, 0.0, 0.0], [2.0, 2.0], 0.3);
    let id = w.add_surface(desc.clone()).unwrap();
    // A sphere that barely dips into the snow still presses the full mask depth.
    w.step(
        1.0 / 60.0,
        &[Deformer::new(
            Shape::Sphere { radius: 0.3 },
            Pose::at([0.0, 0.55, 0.0]),
        )],
    )
    .unwrap();
    let map = w.read_heightmap(id).unwrap();
    let centre = map.depression[(map.height / 2 * map.width + map.width / 2) as usize];
    assert_eq!(centre as u32, acc_cpu::to_units(0.6, Precision::Bits16));
    assert_eq!(
        *map.depression.iter().max().unwrap() as u32,
        acc_cpu::to_units(0.6, Precision::Bits16)
    );
    assert_eq!(map.depression[0], 0);
}

#[test]
fn displaced_snow_accounts_for_what_was_pressed() {
    let mut w = world(CaptureMode::Depth);
    let id = w
        .add_surface(SurfaceDesc::new("v", [0.0, 0.0, 0.0], [2.0, 2.0], 0.3))
        .unwrap();
    for k in 0..10 {
        let x = -0.5 + 0.1 * k as f32;
        w.step(
            1.0 / 60.0,
            &[Deformer::new(
                Shape::Sphere { radius: 0.2 },
                Pose::at([x, 0.2, 0.0]),
            )],
        )
        .unwrap();
    }
    // With no snowfall, every unit pressed out of a texel is counted once in the displaced channel.
    let map = w.read_heightmap(id).unwrap();
    assert!(map.pressed_volume() > 10.0);
    assert_eq!(map.depression, map.displaced);
}

#[test]
fn pool_exhaustion_is_an_error_not_a_panic() {
    let mut w = SnowWorld::new(
        common::gpu(),
        WorldConfig {
            pool_bytes: 256 << 10,
            ..Default::default()
        },
    )
    .unwrap();
    // 8 m x 6 m = 200 x 150 texels x 4 bytes (16-bit channels) = 120,000 bytes, 120,064 with
    // alignment: two fit in 256 KiB, the third does not.
    let a = w
        .add_surface(SurfaceDesc::new("a", [0.0; 3], [8.0, 6.0], 0.3))
        .unwrap();
    w.add_surface(SurfaceDesc::new("b", [10.0, 0.0, 0.0], [8.0, 6.0], 0.3))
        .unwrap();
    let e = w
        .add_surface(SurfaceDesc::new("c", [20.0, 0.0, 0.0], [8.0, 6.0], 0.3))
        .unwrap_err();
    assert!(
        matches!(
            e,
            SnowError::PoolExhausted {
                needed: 120_064,
                ..
            }
        ),
        "{e}"
    );
    assert_eq!(w.memory().pool_used, 2 * 120_064);
    // Freed memory is reused, and a reused slot starts untouched.
    w.step(
        1.0 / 60.0,
        &[Deformer::new(
            Shape::Sphere { radius: 0.3 },
            Pose::at([0.0, 0.1, 0.0]),
        )],
    )
    .unwrap();
    w.remove_surface(a).unwrap();
    let c = w
        .add_surface(SurfaceDesc::new("c", [20.0, 0.0, 0.0], [8.0, 6.0], 0.3))
        .unwrap();
    assert!(
        w.read_heightmap(c)
            .unwrap()
            .depression
            .iter()
            .all(|&v| v == 0)
    );
    // `c` takes `a`'s freed slot, but `a` is stale: it names neither `c` nor anything else.
    assert_eq!(c.index(), a.index());
    assert_ne!(c, a);
    assert_stale(w.read_heightmap(a).map(|_| ()));
    assert_stale(w.surface(a).map(|_| ()));
    assert_stale(w.layout(a).map(|_| ()));
    assert_stale(w.gpu_offsets(a).map(|_| ()));
    assert_stale(w.read_last_capture(a).map(|_| ()));
    assert_stale(w.remove_surface(a));
    let update = [snowprint::SurfaceUpdate {
        surface: a,
        elapsed: 0.0,
        deformers: &[],
    }];
    assert_stale(w.update(&update).map(|_| ()));
    // The stale calls changed nothing: `c` is still live, listed once, and removable.
    assert_eq!(w.surfaces().filter(|(id, _)| *id == c).count(), 1);
    assert!(w.surfaces().all(|(id, _)| id != a));
    w.remove_surface(c).unwrap();
    assert_stale(w.read_heightmap(c).map(|_| ()));
}

/// `r` must be [`SnowError::StaleHandle`] for a surface.
fn assert_stale(r: snowprint::Result<()>) {
    match r {
        Err(SnowError::StaleHandle {
            what: "surface", ..
        }) => {}
        other => panic!("expected a stale surface handle, got {other:?}"),
    }
}

#[test]
fn yawed_surface_maps_world_to_its_texels() {
    let mut w = world(CaptureMode::Depth);
    let mut desc = SurfaceDesc::new("y", [3.0, 0.0, 3.0], [4.0, 2.0], 0.3);
    desc.yaw_degrees = 90.0;
    let id = w.add_surface(desc.clone()).unwrap();
    // Local (x = 1.5, z = -0.5) after a 90 degree yaw about +Y is world offset (-0.5, 0, -1.5):
    // x' = x cos + z sin, z' = -x sin + z cos.
    let local = Vec3::new(1.5, 0.0, -0.5);
    let world_p = desc.center + Quat::from_rotation_y(90f32.to_radians()) * local;
    assert!((world_p - Vec3::new(2.5, 0.0, 1.5)).length() < 1e-5);
    w.step(
        1.0 / 60.0,
        &[Deformer::new(
            Shape::Sphere { radius: 0.1 },
            Pose::at([world_p.x, 0.0, world_p.z]),
        )],
    )
    .unwrap();
    let map = w.read_heightmap(id).unwrap();
    let (col, row) = (
        (1.5 + 2.0) / 4.0 * map.width as f32,
        (-0.5 + 1.0) / 2.0 * map.height as f32,
    );
    let (imax, _) = map
        .depression
        .iter()
        .enumerate()
        .max_by_key(|(_, v)| **v)
        .unwrap();
    let (mc, mr) = (
        (imax as u32 % map.width) as f32,
        (imax as u32 / map.width) as f32,
    );
    assert!(
        (mc + 0.5 - col).abs() <= 1.5 && (mr + 0.5 - row).abs() <= 1.5,
        "peak at {mc},{mr}, expected {col},{row}"
    );
}

#[test]
fn bad_input_is_an_error() {
    let mut w = world(CaptureMode::Depth);
    assert!(matches!(
        w.step(f32::NAN, &[]),
        Err(SnowError::InvalidTimeStep { .. })
    ));
    let e = w
        .step(
            0.1,
            &[Deformer::new(
                Shape::Sphere { radius: -1.0 },
                Pose::at([0.0; 3]),
            )],
        )
        .unwrap_err();
    assert!(e.to_string().contains("radius"), "{e}");
    assert!(
        w.add_surface(SurfaceDesc::new("z", [0.0; 3], [0.0, 1.0], 0.3))
            .is_err()
    );
    let m = w.add_mesh("cube", &Mesh::cuboid(Vec3::ONE)).unwrap();
    assert!(matches!(
        w.pose_mesh(m, &[Vec3::ZERO; 3]),
        Err(SnowError::PoseMismatch { .. })
    ));
}

/// A surface's own list is checked as the plan walks it: a bad deformer or a removed mesh there is
/// refused, the first fault of the update named, and nothing changes (no frame counted, no snow
/// refilled, nothing pressed).
#[test]
fn a_bad_deformer_in_a_surfaces_own_list_changes_nothing() {
    let mut w = world(CaptureMode::Depth);
    let mut desc = SurfaceDesc::new("own1", [0.0; 3], [2.0, 2.0], 0.3);
    desc.replenish_rate = 0.5;
    let a = w.add_surface(desc.clone()).unwrap();
    desc.name = "own2".into();
    let b = w.add_surface(desc).unwrap();
    let good = Deformer::new(Shape::Sphere { radius: 0.3 }, Pose::at([0.0, -0.1, 0.0]));
    let far = Pose::at([f32::NAN, 0.0, 0.0]);
    let bad = Deformer::new(Shape::Sphere { radius: 0.3 }, far);
    fn update(
        surface: snowprint::SurfaceId,
        deformers: &[Deformer],
    ) -> snowprint::SurfaceUpdate<'_> {
        snowprint::SurfaceUpdate {
            surface,
            elapsed: 1.0,
            deformers,
        }
    }
    let e = w
        .update(&[update(a, &[good]), update(b, &[good, bad])])
        .unwrap_err();
    assert!(
        matches!(&e, SnowError::InvalidDeformer { name, what: "position", .. } if name == "#1"),
        "{e}"
    );
    // A bad deformer before a repeated surface: the deformer is the first fault.
    let e = w
        .update(&[update(a, &[bad]), update(a, &[good])])
        .unwrap_err();
    assert!(matches!(e, SnowError::InvalidDeformer { .. }), "{e}");
    let m = w.add_mesh("cube", &Mesh::cuboid(Vec3::ONE)).unwrap();
    w.remove_mesh(m).unwrap();
    let removed = [good, Deformer::new(Shape::Mesh(m), Pose::at([0.0; 3]))];
    let e = w.update(&[update(a, &removed)]).unwrap_err();
    assert!(
        matches!(e, SnowError::StaleHandle { what: "mesh", .. }),
        "{e}"
    );
    for s in [a, b] {
        let h = w.read_heightmap(s).unwrap();
        assert!(h.depression.iter().all(|&v| v == 0), "pressed");
    }
    // The first frame that goes through is the first counted, and refills the one second it
    // was given, not the refused ones' too.
    let stats = w.update(&[update(b, &[])]).unwrap();
    assert_eq!(stats.frame, 1);
    let after = w.read_heightmap(b).unwrap();
    let one_second = w.read_heightmap(a).unwrap();
    assert!(one_second.depression.iter().all(|&v| v == 0));
    let refilled = after.depression.iter().copied().max();
    w.update(&[update(a, &[])]).unwrap();
    assert_eq!(
        w.read_heightmap(a)
            .unwrap()
            .depression
            .iter()
            .copied()
            .max(),
        refilled
    );
}

#[test]
fn update_touches_only_the_listed_surfaces() {
    let mut w = world(CaptureMode::Depth);
    let mut desc = SurfaceDesc::new("u1", [0.0, 0.0, 0.0], [2.0, 2.0], 0.3);
    desc.replenish_rate = 0.1;
    let a = w.add_surface(desc.clone()).unwrap();
    desc.name = "u2".into();
    let b = w.add_surface(desc).unwrap();
    let sphere = [Deformer::new(
        Shape::Sphere { radius: 0.3 },
        Pose::at([0.0, -0.1, 0.0]),
    )];
    let stats = w
        .update(&[snowprint::SurfaceUpdate {
            surface: a,
            elapsed: 0.0,
            deformers: &sphere,
        }])
        .unwrap();
    assert_eq!(stats.updated, 1);
    assert!(w.read_heightmap(a).unwrap().depression.contains(&65535));
    assert!(
        w.read_heightmap(b)
            .unwrap()
            .depression
            .iter()
            .all(|&v| v == 0)
    );
    // A surface updated late replenishes by all the time it waited: 2 s at 10 %/s.
    w.update(&[snowprint::SurfaceUpdate {
        surface: a,
        elapsed: 2.0,
        deformers: &[],
    }])
    .unwrap();
    assert_eq!(
        *w.read_heightmap(a)
            .unwrap()
            .depression
            .iter()
            .max()
            .unwrap(),
        65535 - 13107
    );
    let twice = [
        snowprint::SurfaceUpdate {
            surface: b,
            elapsed: 0.0,
            deformers: &[],
        },
        snowprint::SurfaceUpdate {
            surface: b,
            elapsed: 0.0,
            deformers: &[],
        },
    ];
    assert!(matches!(
        w.update(&twice),
        Err(SnowError::DuplicateUpdate { .. })
    ));
}

/// The fused pass (blur and merge in one dispatch, in place) gives what the CPU references give in
/// sequence, and what the separate passes give, at every precision; normals follow it. Without
/// snowfall it skips the tiles the capture did not flag: every texel still matches, so no tile
/// that a deformer reached was skipped and the skipped ones kept their earlier prints. Snowfall is
/// refilled both ways: by the fused pass, and by the refill pass streaming whole regions.
#[test]
fn fused_pass_matches_the_cpu_chain_and_the_separate_passes() {
    for refill_stream_from in [u32::MAX, 0] {
        fused_against_cpu_and_separate(refill_stream_from);
    }
}

fn fused_against_cpu_and_separate(refill_stream_from: u32) {
    for (size, yaw, precision, rate) in [
        ([4.0, 3.0], 20.0, Precision::Bits16, 0.3),
        ([1.3, 2.7], 0.0, Precision::Bits8, 0.3),
        ([2.1, 1.7], -10.0, Precision::Bits32, 0.3),
        ([6.0, 5.0], 10.0, Precision::Bits16, 0.0),
        ([5.3, 4.1], 0.0, Precision::Bits8, 0.0),
    ] {
        let format = PoolFormat {
            precision,
            normals: true,
        };
        // Always listing: the cases without snowfall update only the listed tiles.
        let mut fused = world_listing(CaptureMode::Depth, true, format, 0, refill_stream_from);
        let mut separate = world_format(CaptureMode::Depth, false, format);
        let mut desc = SurfaceDesc::new("f", [0.5, 2.0, 1.0], size, 0.3);
        desc.yaw_degrees = yaw;
        desc.replenish_rate = rate;
        let a = fused.add_surface(desc.clone()).unwrap();
        let b = separate.add_surface(desc.clone()).unwrap();
        let l = desc.layout();
        let texel = desc.size / Vec2::new(l.width as f32, l.height as f32);
        let deformers = crowd(desc.center);
        let zero = vec![0u32; l.texels() as usize];
        let mut before = (zero.clone(), zero);
        let slack = merge_slack(precision);
        for frame in 0..3 {
            let d = &deformers[frame..];
            let stats = fused.step(0.1, d).unwrap();
            separate.step(0.1, d).unwrap();
            assert_eq!(stats.updated, 1);
            let capture = fused
                .read_last_capture_region(a)
                .unwrap()
                .expect("captured");
            let inp = blur_input(&desc, CaptureMode::Depth);
            // rate x 0.1 s x channel_max a frame, the fraction carried.
            let per_frame = rate as f64 * 0.1 * precision.channel_max() as f64;
            let units = ((frame + 1) as f64 * per_frame).floor() as u32
                - (frame as f64 * per_frame).floor() as u32;
            let cpu = acc_cpu::merge(
                &before.0,
                &before.1,
                Some(&acc_cpu::blur(&inp, &capture)),
                units,
                precision,
            );
            let gpu = fused.read_channels(a).unwrap();
            let off_by = |x: &(Vec<u32>, Vec<u32>), y: &(Vec<u32>, Vec<u32>)| {
                (0..x.0.len())
                    .map(|i| x.0[i].abs_diff(y.0[i]).max(x.1[i].abs_diff(y.1[i])))
                    .max()
                    .unwrap_or(0)
            };
            assert!(
                off_by(&gpu, &cpu) <= slack,
                "fused vs CPU at {precision}, frame {frame}, streaming from {refill_stream_from}"
            );
            assert!(
                off_by(&gpu, &separate.read_channels(b).unwrap()) <= slack,
                "fused vs separate at {precision}"
            );
            assert!(gpu.0.iter().any(|&v| v > 0));
            // Normals after the fused pass against the CPU normals of the fused heights.
            let cpu_n = acc_cpu::normals(
                &gpu.0,
                precision,
                l.width,
                l.height,
                desc.snow_depth,
                texel.x,
                texel.y,
            );
            for (g, c) in fused.read_normals_packed(a).unwrap().iter().zip(&cpu_n) {
                let (gx, gz) = acc_cpu::unpack2x16snorm(*g);
                let (cx, cz) = acc_cpu::unpack2x16snorm(*c);
                assert!(
                    (gx - cx).abs() < 1e-3 && (gz - cz).abs() < 1e-3,
                    "normal {gx},{gz} vs {cx},{cz}"
                );
            }
            before = gpu;
        }
        assert!(
            fused.read_last_blurred(a).unwrap().is_none(),
            "the fused pass keeps stage 1 in registers"
        );
    }
}

/// One fused update of surfaces that refill snow (every tile, by the grid, or every word, by the
/// refill pass) and surfaces that do not (only the tiles the capture listed, or the grid skipping
/// unflagged tiles): each agrees with the separate passes, frame after frame, and the still
/// surfaces keep their earlier prints where nothing presses them again.
#[test]
fn fused_update_mixes_snowing_and_still_surfaces() {
    for list_tiles_from in [0, u32::MAX] {
        for refill_stream_from in [0, u32::MAX] {
            mixed_frames(list_tiles_from, refill_stream_from);
        }
    }
}

fn mixed_frames(list_tiles_from: u32, refill_stream_from: u32) {
    let format = PoolFormat::default();
    let mut fused = world_listing(
        CaptureMode::Depth,
        true,
        format,
        list_tiles_from,
        refill_stream_from,
    );
    let mut separate = world_with(CaptureMode::Depth, false);
    let mut ids = Vec::new();
    for (i, rate) in [0.0, 0.4, 0.0, 0.2].into_iter().enumerate() {
        let mut desc = SurfaceDesc::new("m", [i as f32 * 8.0, 0.0, 0.0], [5.0, 4.0], 0.3);
        desc.replenish_rate = rate;
        ids.push((
            fused.add_surface(desc.clone()).unwrap(),
            separate.add_surface(desc.clone()).unwrap(),
            desc,
        ));
    }
    for frame in 0..4usize {
        // Each frame presses the crowd's members from `frame % 3` on, over every surface.
        let deformers: Vec<Deformer> = ids
            .iter()
            .flat_map(|(_, _, d)| crowd(d.center).into_iter().skip(frame % 3))
            .collect();
        fused.step(0.1, &deformers).unwrap();
        separate.step(0.1, &deformers).unwrap();
        for (a, b, desc) in &ids {
            let (g, c) = (
                fused.read_channels(*a).unwrap(),
                separate.read_channels(*b).unwrap(),
            );
            let worst = (0..g.0.len())
                .map(|i| g.0[i].abs_diff(c.0[i]).max(g.1[i].abs_diff(c.1[i])))
                .max()
                .unwrap_or(0);
            assert!(
                worst <= 1,
                "listing from {list_tiles_from} tiles, streaming from {refill_stream_from} words, frame {frame}, surface at {:?} (refill {}): {worst} units apart",
                desc.center,
                desc.replenish_rate
            );
            assert!(g.0.iter().any(|&v| v > 0));
        }
    }
}

/// An animated mesh is given as posed vertices each frame: the capture follows the new vertices.
#[test]
fn posed_mesh_vertices_move_the_imprint() {
    let mut w = world(CaptureMode::Depth);
    let id = w
        .add_surface(SurfaceDesc::new("p", [0.0, 0.0, 0.0], [2.0, 1.0], 0.3))
        .unwrap();
    let cube = Mesh::cuboid(Vec3::new(0.1, 0.2, 0.1));
    let m = w.add_mesh("cube", &cube).unwrap();
    let at_origin = [Deformer::new(Shape::Mesh(m), Pose::at([0.0; 3]))];
    w.step(1.0 / 60.0, &at_origin).unwrap();
    // Pose the same mesh 0.6 m along +x by moving its vertices, not its pose.
    let moved: Vec<Vec3> = cube
        .positions
        .iter()
        .map(|p| *p + Vec3::new(0.6, 0.0, 0.0))
        .collect();
    w.pose_mesh(m, &moved).unwrap();
    w.step(1.0 / 60.0, &at_origin).unwrap();
    let map = w.read_heightmap(id).unwrap();
    // 4 cm texels: the cube spans columns 22..27 at first (x in -0.1..0.1), then 37..42.
    let pressed = |col: u32| map.depression[(12 * map.width + col) as usize] == 65535;
    assert!(pressed(25) && pressed(40), "both imprints are there");
    assert!(!pressed(32), "nothing between them");
}

/// A closed mesh wholly inside the frustum presses the snow to its lowest point, not to the ground:
/// its upper faces, seen from below behind the lower ones, must not count as a solid cut open by
/// the ground. A mesh ball above the snow presses nothing; one dipping into the snow matches the
/// analytic ball within the blur's spread and the mesh's faceting.
#[test]
fn mesh_inside_the_frustum_presses_to_its_lowest_point() {
    let depth = 0.3;
    let r = 0.2;
    let ball = Mesh::uv_sphere(r, 48, 96);
    for (c, expect_pressed) in [(depth + r + 0.02, false), (0.25, true)] {
        let mut w = world(CaptureMode::Depth);
        let id = w
            .add_surface(SurfaceDesc::new("b", [0.0, 0.0, 0.0], [1.0, 1.0], depth))
            .unwrap();
        let m = w.add_mesh("ball", &ball).unwrap();
        w.step(
            1.0 / 60.0,
            &[Deformer::new(Shape::Mesh(m), Pose::at([0.0, c, 0.0]))],
        )
        .unwrap();
        let map = w.read_heightmap(id).unwrap();
        let max = *map.depression.iter().max().unwrap() as f32 / 65535.0;
        if !expect_pressed {
            assert_eq!(max, 0.0, "a ball above the snow presses nothing");
            continue;
        }
        // Bottom at 0.05 m above the ground in 0.3 m of snow: the deepest point is pressed to
        // (0.3 - 0.05) / 0.3 = 0.833 of the depth, nowhere near the ground; the blur mixes in the
        // neighbours 4 cm away, 4 mm higher up the ball (0.013 of the depth).
        assert!(max <= 0.8334 && max > 0.8333 - 0.02, "deepest {max}");
        // The uv sphere's facets lie inside the true ball by at most r(1 - cos(pi/48)) = 0.4 mm.
        let facet = r * (1.0 - (std::f32::consts::PI / 48.0).cos()) / depth;
        for row in 0..map.height {
            for col in 0..map.width {
                let p = cap_cpu::texel_center(col, row, map.width, map.height, Vec2::splat(0.5));
                let d = p.length();
                if d > r - 0.06 {
                    continue; // the rim, where the blur and the facets both act
                }
                let got = map.fraction(col, row);
                // The blur mixes the 3x3 texels around: up to one texel diagonal (5.7 cm) away.
                let reach = 0.04 * std::f32::consts::SQRT_2;
                let lo = sphere_depression(depth, c, r, d + reach, depth) - facet;
                let hi = sphere_depression(depth, c, r, (d - reach).max(0.0), depth);
                assert!(
                    got >= lo - 1e-4 && got <= hi + 1e-4,
                    "at {d}: {got} not in [{lo}, {hi}]"
                );
            }
        }
    }
}

/// A mesh moving fast is drawn at sub-steps: a cube swept 0.5 m in one frame leaves a continuous
/// trench, not two separate imprints.
#[test]
fn moving_mesh_is_swept_within_a_frame() {
    let mut w = world(CaptureMode::Depth);
    let id = w
        .add_surface(SurfaceDesc::new("s", [0.0, 0.0, 0.0], [2.0, 1.0], 0.3))
        .unwrap();
    let m = w
        .add_mesh("cube", &Mesh::cuboid(Vec3::new(0.05, 0.2, 0.05)))
        .unwrap();
    let stats = w
        .step(
            1.0 / 60.0,
            &[Deformer::moving(
                Shape::Mesh(m),
                Pose::at([-0.25, 0.0, 0.0]),
                Pose::at([0.25, 0.0, 0.0]),
            )],
        )
        .unwrap();
    // 0.5 m at most 3 cm a step: capped at 8 draws.
    assert_eq!(
        stats.mesh_draws,
        snowprint::low_level::capture::MAX_MESH_SUBSTEPS
    );
    let map = w.read_heightmap(id).unwrap();
    let row = map.height / 2;
    // 4 cm texels, x = -0.25 .. 0.25 is columns 19 .. 31: every column between is pressed.
    for col in 20..=30 {
        assert_eq!(
            map.depression[(row * map.width + col) as usize],
            65535,
            "column {col}"
        );
    }
}

/// Shapes up to `MAX_DEFORMER_SIZE` that hold the whole 2 x 2 m surface press every texel to the
/// ground (before the bound was stated and the footprint clamped to the surface, a sphere of radius
/// 1e8 pressed only the -X half and one of 3e38 nothing); larger ones are refused with a sentence.
#[test]
fn huge_shapes_cover_the_surface_up_to_the_bound_and_are_refused_beyond() {
    let mut w = world(CaptureMode::Depth);
    let id = w
        .add_surface(SurfaceDesc::new("yard", [0.0; 3], [2.0, 2.0], 0.3))
        .unwrap();
    let texels = w.layout(id).unwrap().texels() as usize;
    let max = snowprint::MAX_DEFORMER_SIZE;
    for shape in [
        Shape::Sphere { radius: 1.5 },
        Shape::Sphere { radius: max },
        Shape::Capsule {
            radius: max,
            half_height: max,
        },
        Shape::Box {
            half_extents: Vec3::splat(max),
        },
    ] {
        w.step(0.0, &[Deformer::new(shape, Pose::at([0.0; 3]))])
            .unwrap();
        let capture = w.read_last_capture(id).unwrap().expect("captured");
        assert_eq!(capture.len(), texels);
        let pressed = capture.iter().filter(|&&d| d == 0.0).count();
        assert_eq!(pressed, texels, "{shape:?} pressed {pressed} of {texels}");
    }
    for radius in [max * 1.001, 1e8, 1e36, 3e38] {
        let e = w
            .step(
                0.0,
                &[Deformer::new(Shape::Sphere { radius }, Pose::at([0.0; 3]))],
            )
            .unwrap_err();
        let msg = e.to_string();
        assert!(
            matches!(e, SnowError::InvalidDeformer { what: "radius", .. })
                && msg.contains("at most MAX_DEFORMER_SIZE (1000)"),
            "{msg}"
        );
    }
}

/// A sphere of radius R resting `gap` above the ground, R up to the bound: the capture's height at
/// each texel centre (x, z) is `c - sqrt(R^2 - x^2 - z^2)`, evaluated here in f64 from the f32
/// inputs. The naive `c - sqrt(R^2 - d^2)` in f32 is off by up to ulp(R^2) / 2R (31 um at
/// R = 1000, 0.4 mm at 1e4); the capture's form is exact to well under a micrometre.
#[test]
fn huge_shapes_resting_on_the_snow_are_placed_exactly() {
    let mut w = world(CaptureMode::Depth);
    let desc = SurfaceDesc::new("yard", [0.0; 3], [2.0, 2.0], 0.3);
    let id = w.add_surface(desc.clone()).unwrap();
    let l = w.layout(id).unwrap();
    let frustum = f64::from(0.3 + ANKLE);
    let gap = 0.1f32;
    for radius in [1.0f32, 30.0, 1000.0] {
        let cy = radius + gap;
        let (r, c) = (f64::from(radius), f64::from(cy));
        // Lowest point of a round section of radius r centred at height c, at distance d.
        let round = move |d2: f64| (d2 < r * r).then(|| c - (r * r - d2).sqrt());
        type Want = Box<dyn Fn(f64, f64) -> Option<f64>>;
        let cases: [(&str, Shape, Quat, Want, f64); 3] = [
            (
                "sphere",
                Shape::Sphere { radius },
                Quat::IDENTITY,
                Box::new(move |x, z| round(x * x + z * z)),
                1e-6,
            ),
            (
                // Laid along x (a quarter about +Z), its straight part longer than the surface:
                // every texel sees the cylinder, whose section is a circle in (y, z).
                "capsule",
                Shape::Capsule {
                    radius,
                    half_height: 1.5,
                },
                Quat::from_rotation_z(std::f32::consts::FRAC_PI_2),
                Box::new(move |_, z| round(z * z)),
                50e-6,
            ),
            (
                "box",
                Shape::Box {
                    half_extents: Vec3::splat(radius),
                },
                Quat::IDENTITY,
                Box::new(move |_, _| Some(c - r)),
                50e-6,
            ),
        ];
        for (what, shape, rotation, want, tolerance) in &cases {
            w.step(
                0.0,
                &[Deformer::new(
                    *shape,
                    Pose {
                        position: Vec3::new(0.0, cy, 0.0),
                        rotation: *rotation,
                    },
                )],
            )
            .unwrap();
            let capture = w.read_last_capture(id).unwrap().expect("captured");
            let mut worst = 0.0f64;
            let mut covered = 0;
            for row in 0..l.height {
                for col in 0..l.width {
                    // Texel centres by hand: the surface spans -1..1 m on both axes.
                    let x = -1.0 + (f64::from(col) + 0.5) * 2.0 / f64::from(l.width);
                    let z = -1.0 + (f64::from(row) + 0.5) * 2.0 / f64::from(l.height);
                    let got = f64::from(capture[(row * l.width + col) as usize]);
                    match want(x, z).filter(|&h| h < frustum) {
                        None => assert_eq!(got, 1.0, "{what} r {r} ({col}, {row}): nothing there"),
                        Some(h) => {
                            covered += 1;
                            worst = worst.max((got * frustum - h).abs());
                        }
                    }
                }
            }
            assert!(covered > 100, "{what} r {r}: {covered} texels");
            eprintln!("{what} r {r}: worst {worst:e} m");
            assert!(worst < *tolerance, "{what} r {r}: height off by {worst} m");
        }
    }
}

/// What a hand-derived case expects at a texel centre: the lowest height pressed there, nothing, or
/// no claim (within 2 mm of the footprint's edge, where the texel centre's rounding decides).
enum Expect {
    Height(f64),
    Nothing,
    Edge,
}

/// Capture cases derived by hand on a yawed surface, independent of `capture::push_primitives` and
/// of the CPU ray cast: the surface's frame, a box's orientation, a capsule's pose, a box swept
/// within one frame, and culling at the surface's edges and above the frustum. World positions are
/// written out with the yaw's sine and cosine; expectations are the shapes' closed forms in f64.
#[test]
fn capture_matches_hand_derived_cases_on_a_yawed_surface() {
    let mut w = world(CaptureMode::Depth);
    let yaw = 30.0f32;
    let (center, size, snow) = (Vec3::new(2.0, 1.0, -3.0), [3.0f32, 2.0], 0.3f32);
    let mut desc = SurfaceDesc::new("yawed", center.to_array(), size, snow);
    desc.yaw_degrees = yaw;
    let id = w.add_surface(desc).unwrap();
    let l = w.layout(id).unwrap();
    let frustum = f64::from(snow + ANKLE);
    let th = yaw.to_radians();
    let rot = Quat::from_rotation_y(th);
    // Rotation about +Y by th takes local +X to (cos, 0, -sin) and local +Z to (sin, 0, cos).
    let world = |x: f32, y: f32, z: f32| {
        center
            + x * Vec3::new(th.cos(), 0.0, -th.sin())
            + Vec3::new(0.0, y, 0.0)
            + z * Vec3::new(th.sin(), 0.0, th.cos())
    };
    // Texel centres by hand: local x from -1.5 to 1.5 over the width, z from -1 to 1 over the height.
    let centre = |col: u32, row: u32| {
        (
            -1.5 + (f64::from(col) + 0.5) * 3.0 / f64::from(l.width),
            -1.0 + (f64::from(row) + 0.5) * 2.0 / f64::from(l.height),
        )
    };
    const EDGE: f64 = 2e-3;
    // Inside a rectangle |u| <= a, |v| <= b, with the edge band left out.
    let rect = |u: f64, v: f64, a: f64, b: f64, height: f64| {
        let outside = (u.abs() - a).max(v.abs() - b);
        if outside.abs() < EDGE {
            Expect::Edge
        } else if outside < 0.0 {
            Expect::Height(height)
        } else {
            Expect::Nothing
        }
    };
    // Lowest point of a ball of radius r centred at height c, at horizontal distance d.
    let ball = move |d: f64, r: f64, c: f64| {
        if (d - r).abs() < EDGE {
            Expect::Edge
        } else if d < r {
            let low = c - (r * r - d * d).sqrt();
            if low >= frustum {
                Expect::Nothing
            } else {
                Expect::Height(low.max(0.0))
            }
        } else {
            Expect::Nothing
        }
    };
    let boxy = Shape::Box {
        half_extents: Vec3::new(0.4, 0.1, 0.15),
    };
    let quarter = std::f64::consts::FRAC_PI_4;
    type Case = (&'static str, Deformer, Box<dyn Fn(f64, f64) -> Expect>);
    let cases: Vec<Case> = vec![
        (
            "box along the surface's axes",
            Deformer::new(
                boxy,
                Pose {
                    position: world(0.5, 0.2, -0.3),
                    rotation: rot,
                },
            ),
            Box::new(move |x, z| rect(x - 0.5, z + 0.3, 0.4, 0.15, 0.1)),
        ),
        (
            "box turned a quarter about +Y: its long side along local z",
            Deformer::new(
                boxy,
                Pose {
                    position: world(0.5, 0.2, -0.3),
                    rotation: Quat::from_rotation_y(th + std::f32::consts::FRAC_PI_2),
                },
            ),
            Box::new(move |x, z| rect(x - 0.5, z + 0.3, 0.15, 0.4, 0.1)),
        ),
        (
            "box turned 45 degrees: box x = (cos, -sin), box z = (sin, cos) in local (x, z)",
            Deformer::new(
                boxy,
                Pose {
                    position: world(0.5, 0.2, -0.3),
                    rotation: Quat::from_rotation_y(th + std::f32::consts::FRAC_PI_4),
                },
            ),
            Box::new(move |x, z| {
                let (px, pz) = (x - 0.5, z + 0.3);
                let u = px * quarter.cos() - pz * quarter.sin();
                let v = px * quarter.sin() + pz * quarter.cos();
                rect(u, v, 0.4, 0.15, 0.1)
            }),
        ),
        (
            "capsule laid along local x (a quarter about +Z, then the yaw)",
            Deformer::new(
                Shape::Capsule {
                    radius: 0.1,
                    half_height: 0.3,
                },
                Pose {
                    position: world(-0.6, 0.15, 0.4),
                    rotation: rot * Quat::from_rotation_z(std::f32::consts::FRAC_PI_2),
                },
            ),
            Box::new(move |x, z| {
                let along = (x + 0.6).clamp(-0.3, 0.3);
                let d = ((x + 0.6 - along).powi(2) + (z - 0.4).powi(2)).sqrt();
                ball(d, 0.1, 0.15)
            }),
        ),
        (
            "box swept 2.1 m along local x within one frame: one continuous trench",
            Deformer::moving(
                Shape::Box {
                    half_extents: Vec3::new(0.05, 0.1, 0.08),
                },
                Pose {
                    position: world(-1.2, 0.15, 0.6),
                    rotation: rot,
                },
                Pose {
                    position: world(0.9, 0.15, 0.6),
                    rotation: rot,
                },
            ),
            Box::new(move |x, z| rect(x + 0.15, z - 0.6, 1.1, 0.08, 0.05)),
        ),
        (
            "ball centred 20 cm past the surface's +x edge, reaching 10 cm over it",
            Deformer::new(
                Shape::Sphere { radius: 0.3 },
                Pose::at(world(1.7, 0.25, 0.0).to_array()),
            ),
            Box::new(move |x, z| ball(((x - 1.7).powi(2) + z * z).sqrt(), 0.3, 0.25)),
        ),
    ];
    for (what, deformer, expect) in &cases {
        w.step(0.0, std::slice::from_ref(deformer)).unwrap();
        let capture = w.read_last_capture(id).unwrap().expect("captured");
        let (mut pressed, mut empty) = (0, 0);
        for row in 0..l.height {
            for col in 0..l.width {
                let (x, z) = centre(col, row);
                let got = f64::from(capture[(row * l.width + col) as usize]);
                match expect(x, z) {
                    Expect::Edge => {}
                    Expect::Nothing => {
                        assert_eq!(got, 1.0, "{what}: texel ({col}, {row}) at ({x}, {z})");
                        empty += 1;
                    }
                    Expect::Height(h) => {
                        let dh = (got * frustum - h).abs();
                        assert!(
                            dh <= f64::from(CAPTURE_HEIGHT_TOLERANCE),
                            "{what}: texel ({col}, {row}) at ({x}, {z}): height {} for {h}",
                            got * frustum
                        );
                        pressed += 1;
                    }
                }
            }
        }
        assert!(
            pressed >= 10 && empty >= 100,
            "{what}: {pressed} pressed, {empty} empty"
        );
    }
    // Culled: wholly past the -z edge, wholly above the frustum: no primitive reaches the GPU.
    // (Counted from the frame's statistics: `read_last_capture` keeps answering an earlier step's
    // capture after a step in which no surface was updated.)
    for (what, at, kept) in [
        ("past the -z edge", world(0.0, 0.1, -1.25), 0),
        ("over the -z edge", world(0.0, 0.1, -1.15), 1),
        ("above the frustum", world(0.0, snow + ANKLE + 0.21, 0.0), 0),
        (
            "touching the frustum's top",
            world(0.0, snow + ANKLE + 0.19, 0.0),
            1,
        ),
    ] {
        let stats = w
            .step(
                0.0,
                &[Deformer::new(
                    Shape::Sphere { radius: 0.2 },
                    Pose::at(at.to_array()),
                )],
            )
            .unwrap();
        assert_eq!(stats.primitives, kept, "{what}");
    }
}

/// A step that captures nothing leaves no capture to read back: the debug readbacks never show an
/// older step's capture as the last one.
#[test]
fn a_step_that_captures_nothing_clears_the_last_capture() {
    let mut w = SnowWorld::new(common::gpu(), WorldConfig::default()).unwrap();
    let id = w
        .add_surface(SurfaceDesc::new("s", [0.0, 0.0, 0.0], [1.0, 1.0], 0.2))
        .unwrap();
    let ball = Deformer::new(Shape::Sphere { radius: 0.1 }, Pose::at([0.0, 0.15, 0.0]));
    w.step(1.0 / 60.0, &[ball]).unwrap();
    assert!(w.read_last_capture(id).unwrap().is_some());
    w.step(1.0 / 60.0, &[]).unwrap();
    assert_eq!(w.read_last_capture(id).unwrap(), None);
}

/// Under the default passes (`PassMode::Auto`, fused on every adapter) nothing writes the blurred
/// scratch, so there is no stage 1 output to read: `read_last_blurred` answers `None`, as under
/// `PassMode::Fused`, rather than whatever the scratch buffer held; with separate passes it
/// answers.
#[test]
fn the_blurred_capture_is_read_only_where_a_pass_wrote_it() {
    for (passes, written) in [
        (PassMode::Auto, false),
        (PassMode::Fused, false),
        (PassMode::Separate, true),
    ] {
        let mut w = SnowWorld::new(
            common::gpu(),
            WorldConfig {
                passes,
                ..WorldConfig::default()
            },
        )
        .unwrap();
        let id = w
            .add_surface(SurfaceDesc::new("s", [0.0, 0.0, 0.0], [2.0, 2.0], 0.3))
            .unwrap();
        let ball = Deformer::new(Shape::Sphere { radius: 0.3 }, Pose::at([0.0, 0.25, 0.0]));
        w.step(1.0 / 30.0, &[ball]).unwrap();
        assert_eq!(
            w.read_last_blurred(id).unwrap().is_some(),
            written,
            "{passes:?}"
        );
    }
}
