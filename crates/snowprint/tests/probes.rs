//! Gameplay queries on the GPU: probes answered from the pool within two frames without a blocking
//! call, checked against the heightmap read back and against values computed by hand; the keyed
//! cache; footstep events.

mod common;

use glam::{Quat, Vec2, Vec3};
use snowprint::{
    CaptureConfig, Deformer, Footstep, Mesh, PoolFormat, Pose, Precision, ProbeSample, ProbeStatus,
    ProbeTicket, Shape, SnowError, SnowWorld, SurfaceDesc, SurfaceId, WorldConfig,
};

const DT: f32 = 1.0 / 60.0;
const DEPTH: f32 = 0.2;

fn world(precision: Precision) -> SnowWorld {
    SnowWorld::new(
        common::gpu(),
        WorldConfig {
            capture: CaptureConfig {
                ankle_height: 0.25,
                ..Default::default()
            },
            pool_bytes: 8 << 20,
            format: PoolFormat::new(precision),
            ..Default::default()
        },
    )
    .unwrap()
}

/// A 3 m x 2 m yard turned 30 degrees, its ground at y = 1, and a small roof over part of it.
fn yard(world: &mut SnowWorld) -> (SurfaceId, SurfaceId, SurfaceDesc) {
    let mut desc = SurfaceDesc::new("yard", [2.0, 1.0, -1.0], [3.0, 2.0], DEPTH);
    desc.yaw_degrees = 30.0;
    let yard = world.add_surface(desc.clone()).unwrap();
    let roof = world
        .add_surface(SurfaceDesc::new("roof", [3.0, 3.0, -1.0], [0.6, 0.6], 0.1))
        .unwrap();
    (yard, roof, desc)
}

/// A point of the yard's local frame (metres from its centre along its sides) at height `y`.
fn at(desc: &SurfaceDesc, x: f32, z: f32, y: f32) -> Vec3 {
    desc.local_to_world().transform_point3(Vec3::new(x, y, z))
}

/// The heightmap texel under a local point, by the surface's texel rule.
fn texel(desc: &SurfaceDesc, width: u32, height: u32, x: f32, z: f32) -> (u32, u32) {
    let t = desc.size / Vec2::new(width as f32, height as f32);
    (
        ((x + desc.size.x / 2.0) / t.x).floor() as u32,
        ((z + desc.size.y / 2.0) / t.y).floor() as u32,
    )
}

/// Step with a sphere resting far from the probes (a frame with real GPU work) until the ticket
/// is answered; fails past two frames. No call here waits for the GPU.
fn answer_within_two_frames(
    world: &mut SnowWorld,
    ticket: ProbeTicket,
    busy: &Deformer,
) -> Vec<ProbeSample> {
    let mut frames = 0;
    loop {
        if let ProbeStatus::Ready(samples) = world.probe_result(ticket).unwrap() {
            return samples;
        }
        assert!(
            frames < 2,
            "ticket {ticket:?} not answered after {frames} frames"
        );
        world.step(DT, std::slice::from_ref(busy)).unwrap();
        frames += 1;
    }
}

#[test]
fn probes_read_the_print_at_every_precision() {
    for precision in Precision::ALL {
        let mut w = world(precision);
        let (yard, roof, desc) = yard(&mut w);
        // A 0.3 m ball pressed 0.15 m into 0.2 m of snow at the yard's local (-0.6, 0).
        let press = Deformer::new(
            Shape::Sphere { radius: 0.3 },
            Pose::at(at(&desc, -0.6, 0.0, DEPTH - 0.15 + 0.3).into()),
        );
        w.step(DT, &[press]).unwrap();
        let map = w.read_heightmap(yard).unwrap();
        let layout = w.layout(yard).unwrap();
        let busy = Deformer::new(
            Shape::Sphere { radius: 0.1 },
            Pose::at(at(&desc, 1.3, 0.8, DEPTH).into()),
        );

        // Off texel boundaries (texels are 4 cm here), so that the texel is the same by either rule.
        let local = [
            (-0.6, 0.01),
            (-0.6 + 0.19, 0.01),
            (-0.6 - 0.19, 0.01),
            (0.51, -0.49),
        ];
        let mut points: Vec<Vec3> = local.iter().map(|&(x, z)| at(&desc, x, z, 1.1)).collect();
        points.push(Vec3::new(40.0, 1.0, 40.0)); // Outside every surface.
        points.push(Vec3::new(3.1, 3.05, -0.9)); // On the roof.
        points.push(Vec3::new(3.1, 1.05, -0.9)); // Under the roof, on the yard.
        let ticket = w.probe(&points).unwrap();
        let samples = answer_within_two_frames(&mut w, ticket, &busy);
        assert_eq!(samples.len(), points.len());

        let quantum = DEPTH * (0.5 / 65535.0 + 1e-6);
        for (k, &(x, z)) in local.iter().enumerate() {
            let s = samples[k];
            assert_eq!(s.surface, Some(yard), "{precision:?} point {k}");
            assert_eq!(s.point, points[k]);
            let (c, r) = texel(&desc, layout.width, layout.height, x, z);
            let expected = map.fraction(c, r) * DEPTH;
            assert!(
                (s.depression_m - expected).abs() <= quantum,
                "{precision:?} point {k}: depression {} against {expected} read back",
                s.depression_m
            );
            assert!((s.snow_depth_m - (DEPTH - s.depression_m)).abs() < 1e-6);
            assert!((s.normal.length() - 1.0).abs() < 1e-5);
        }
        // The centre of the print is pressed about 0.15 m (the blur softens it a little).
        assert!(samples[0].depression_m > 0.1, "{:?}", samples[0]);
        // Untouched snow: full depth, flat.
        assert_eq!(samples[3].depression_m, 0.0);
        assert_eq!(samples[3].snow_depth_m, DEPTH);
        assert!((samples[3].normal - Vec3::Y).length() < 1e-6);
        // On the walls the normal leans towards the print's centre, along the yard's local x.
        let along = desc.rotation() * Vec3::X;
        assert!(
            samples[1].normal.dot(along) < -0.1,
            "{:?}",
            samples[1].normal
        );
        assert!(
            samples[2].normal.dot(along) > 0.1,
            "{:?}",
            samples[2].normal
        );
        // The same slope from the heightmap read back, by central differences.
        let (c, r) = texel(&desc, layout.width, layout.height, local[1].0, local[1].1);
        let t = desc.size.x / layout.width as f32;
        let top = |c: u32| DEPTH * (1.0 - map.fraction(c, r));
        let slope = (top(c + 1) - top(c - 1)) / (2.0 * t);
        let n = samples[1].normal;
        let local_n = desc.rotation().inverse() * n;
        assert!(
            (-local_n.x / local_n.y - slope).abs() < 1e-3,
            "{precision:?}: slope {} against {slope}",
            -local_n.x / local_n.y
        );
        // Nothing outside; the roof where the point stands on it; the yard under the roof.
        assert_eq!(samples[4].surface, None);
        assert_eq!(samples[4].snow_depth_m, 0.0);
        assert_eq!(samples[5].surface, Some(roof));
        assert_eq!(samples[5].snow_depth_m, 0.1);
        assert_eq!(samples[6].surface, Some(yard));

        // Answered once, then forgotten.
        assert!(matches!(
            w.probe_result(ticket),
            Err(SnowError::UnknownProbe { .. })
        ));
    }
}

#[test]
fn bad_requests_are_refused() {
    let mut w = world(Precision::Bits16);
    let (_, _, desc) = yard(&mut w);
    let err = w.probe(&[Vec3::ZERO, Vec3::new(f32::NAN, 0.0, 0.0)]);
    assert!(matches!(
        err,
        Err(SnowError::InvalidProbePoint { index: 1, .. })
    ));
    let many = vec![Vec3::ZERO; snowprint::MAX_PROBE_POINTS + 1];
    assert!(matches!(
        w.probe(&many),
        Err(SnowError::TooManyProbePoints { .. })
    ));
    // A ticket this world never gave (another world's third).
    let t = w.probe(&[]).unwrap();
    let mut other = world(Precision::Bits16);
    let foreign = (0..3).map(|_| other.probe(&[]).unwrap()).last().unwrap();
    assert_eq!((t.number(), foreign.number()), (0, 2));
    assert!(matches!(
        w.probe_result(foreign),
        Err(SnowError::UnknownProbe { ticket: 2 })
    ));
    // Filling the ring: each batch sent at once and nothing polled; once every slot is in flight,
    // a new batch is refused with the count, and every ticket given is still answered afterwards.
    let mut tickets = vec![t];
    let mut full = None;
    for _ in 0..64 {
        w.send_probes();
        match w.probe(&[at(&desc, 0.0, 0.0, 1.1)]) {
            Ok(t) => tickets.push(t),
            Err(e) => {
                full = Some(e);
                break;
            }
        }
    }
    match full {
        Some(SnowError::ProbeRingFull { in_flight, ring }) => {
            assert_eq!((in_flight, ring), (4, snowprint::PROBE_RING));
        }
        other => panic!("expected a full ring, got {other:?}"),
    }
    let busy = Deformer::new(
        Shape::Sphere { radius: 0.1 },
        Pose::at(at(&desc, 1.3, 0.8, DEPTH).into()),
    );
    for t in tickets {
        let samples = answer_within_two_frames(&mut w, t, &busy);
        assert!(samples.len() <= 1);
    }
}

#[test]
fn the_cache_keeps_the_last_sample_of_each_key() {
    let mut w = world(Precision::Bits16);
    let (yard, _, desc) = yard(&mut w);
    let press = Deformer::new(
        Shape::Sphere { radius: 0.3 },
        Pose::at(at(&desc, 0.0, 0.0, DEPTH - 0.1 + 0.3).into()),
    );
    w.step(DT, &[press]).unwrap();
    let (left, right) = (at(&desc, 0.0, 0.0, 1.1), at(&desc, 1.0, -0.7, 1.1));
    assert!(w.under(1).is_none());
    w.probe_keyed(1, left).unwrap();
    w.probe_keyed(2, right).unwrap();
    // The same points by ticket, as the reference.
    let ticket = w.probe(&[left, right]).unwrap();
    let busy = Deformer::new(
        Shape::Sphere { radius: 0.1 },
        Pose::at(at(&desc, 1.3, 0.8, DEPTH).into()),
    );
    let reference = answer_within_two_frames(&mut w, ticket, &busy);
    let (l, age) = w
        .under(1)
        .expect("answered with the ticket of the same batch");
    assert_eq!(l, reference[0]);
    assert_eq!(w.under(2).unwrap().0, reference[1]);
    assert_eq!(l.surface, Some(yard));
    assert!(l.depression_m > 0.05 && reference[1].depression_m == 0.0);
    // A frame later the sample is a frame older; a new probe replaces it when answered.
    w.step(DT, std::slice::from_ref(&busy)).unwrap();
    assert_eq!(w.under(1).unwrap().1, age + 1);
    w.probe_keyed(1, right).unwrap();
    for _ in 0..2 {
        w.step(DT, std::slice::from_ref(&busy)).unwrap();
    }
    let (moved, age) = w.under(1).unwrap();
    assert_eq!(moved.point, right);
    assert_eq!(moved, reference[1]);
    assert!(age <= 2, "age {age}");
    w.forget_key(1);
    assert!(w.under(1).is_none());
}

#[test]
fn a_footstep_when_a_capsule_foot_comes_down() {
    let mut w = world(Precision::Bits16);
    let (yard, _, desc) = yard(&mut w);
    let foot = Shape::Capsule {
        radius: 0.05,
        half_height: 0.1,
    };
    // The snow top is at 1.2. The foot's lowest point goes from 1.30 to 1.12 while moving 0.04 m
    // sideways in 1/30 s: 0.08 m deep, at |(0.04, -0.18)| * 30 m/s.
    let from = at(&desc, 0.2, 0.1, 0.3 + 0.15);
    let to = at(&desc, 0.24, 0.1, 0.12 + 0.15);
    let other = Deformer::new(
        Shape::Sphere { radius: 0.1 },
        Pose::at(at(&desc, -1.2, -0.8, 0.5).into()),
    );
    let down = Deformer::moving(foot, Pose::at(from.into()), Pose::at(to.into()));
    w.step(1.0 / 30.0, &[other, down]).unwrap();
    let steps: Vec<Footstep> = w.footsteps().to_vec();
    assert_eq!(steps.len(), 1, "{steps:?}");
    let s = steps[0];
    assert_eq!((s.deformer, s.surface), (1, yard));
    assert!(
        (s.point - (to - Vec3::Y * 0.15)).length() < 1e-5,
        "{:?}",
        s.point
    );
    assert!((s.depth_m - 0.08).abs() < 1e-5, "{}", s.depth_m);
    let speed = (0.04f32.powi(2) + 0.18f32.powi(2)).sqrt() * 30.0;
    assert!(
        (s.speed - speed).abs() < 1e-3,
        "{} against {speed}",
        s.speed
    );
    assert_eq!(w.surface(s.surface).unwrap().name, "yard");

    // Resting where it landed, and with no previous pose: no footstep.
    let rest = Deformer::moving(foot, Pose::at(to.into()), Pose::at(to.into()));
    w.step(DT, &[rest]).unwrap();
    assert!(w.footsteps().is_empty());
    w.step(DT, &[Deformer::new(foot, Pose::at(to.into()))])
        .unwrap();
    assert!(w.footsteps().is_empty());
    // Lifting: none. Stamping through the ground: the depth is the snow's.
    let up = Deformer::moving(foot, Pose::at(to.into()), Pose::at(from.into()));
    w.step(DT, &[up]).unwrap();
    assert!(w.footsteps().is_empty());
    let through = Deformer::moving(
        foot,
        Pose::at(from.into()),
        Pose {
            position: at(&desc, 0.2, 0.1, -0.1),
            rotation: Quat::IDENTITY,
        },
    );
    w.step(DT, &[through]).unwrap();
    assert!((w.footsteps()[0].depth_m - DEPTH).abs() < 1e-6);
    // Coming down beside the yard: none.
    let beside = Deformer::moving(
        foot,
        Pose::at(at(&desc, 1.7, 0.0, 0.45).into()),
        Pose::at(at(&desc, 1.7, 0.0, 0.2).into()),
    );
    w.step(DT, &[beside]).unwrap();
    assert!(w.footsteps().is_empty());
    // A boot mesh, a 0.1 x 0.06 x 0.2 m block, comes down flat from 0.05 m above the top to
    // 0.07 m below it: a footstep under its centre, 0.07 m deep.
    let boot = w
        .add_mesh("boot", &Mesh::cuboid(Vec3::new(0.05, 0.03, 0.1)))
        .unwrap();
    let (from, to) = (
        at(&desc, -0.5, 0.3, 0.25 + 0.03),
        at(&desc, -0.5, 0.3, 0.13 + 0.03),
    );
    let stamp = Deformer::moving(
        Shape::Mesh(boot),
        Pose::at(from.into()),
        Pose::at(to.into()),
    );
    w.step(DT, &[stamp]).unwrap();
    let s = w.footsteps()[0];
    assert_eq!((s.deformer, s.surface), (0, yard));
    assert!(
        (s.point - (to - Vec3::Y * 0.03)).length() < 1e-5,
        "{:?}",
        s.point
    );
    assert!((s.depth_m - 0.07).abs() < 1e-5, "{}", s.depth_m);
    assert!((s.speed - 0.12 / DT).abs() < 1e-2, "{}", s.speed);
    // Once removed, the mesh is refused by the update as before; nothing of it is kept.
    w.remove_mesh(boot).unwrap();
    assert!(w.step(DT, &[stamp]).is_err());
}
