//! The manager in an engine's frame: `encode_tick` records page-outs, page-ins, catch-up layers
//! and probes into the caller's encoder between the caller's own passes, waits for nothing, and
//! leaves the snow `tick` leaves; probes answer over resident, paged and untouched surfaces.

mod common;

use glam::Vec3;
use snowprint::manager::{
    ManagedDeformer, ManagedId, ManagedProbeStatus, ManagedProbeTicket, ManagedSample,
    ManagerConfig, SnowManager, ZoneId,
};
use snowprint::{Deformer, Heightmap, Pose, Shape, SnowError, SurfaceDesc};

const DT: f32 = 1.0 / 60.0;

fn manager(config: ManagerConfig, surfaces: &[SurfaceDesc]) -> (SnowManager, Vec<ManagedId>) {
    let mut m = SnowManager::new(common::gpu(), config).expect("manager");
    let ids = surfaces
        .iter()
        .enumerate()
        .map(|(i, s)| {
            m.add_surface(s.clone(), ZoneId(i as u32 % 2))
                .expect("surface")
        })
        .collect();
    (m, ids)
}

fn read_all(m: &SnowManager, ids: &[ManagedId]) -> Vec<Heightmap> {
    ids.iter()
        .map(|&id| m.read_heightmap(id).expect("read"))
        .collect()
}

/// Six 3 m roofs in a row, a pool that holds two: a walker crosses each in turn and comes back to
/// the first, so heightmaps go out and come back in.
fn six_roofs() -> Vec<SurfaceDesc> {
    (0..6)
        .map(|i| {
            SurfaceDesc::new(
                &format!("s{i}"),
                [i as f32 * 5.0, 0.0, 0.0],
                [3.0, 3.0],
                0.2,
            )
        })
        .collect()
}

fn walker(f: u32) -> Vec<ManagedDeformer> {
    let k = (f / 20) as usize % 7;
    let k = if k == 6 { 0 } else { k };
    let t = (f % 20) as f32 / 20.0;
    let x = k as f32 * 5.0 - 1.2 + 2.4 * t;
    let z = if k == 0 && f >= 120 { 0.8 } else { -0.4 };
    let step = |x: f32| Pose::at([x, 0.17, z]);
    // The player, and a second walker on every roof at once (many due surfaces, one budget:
    // surfaces wait and catch up frame by frame, several layers in one encoder).
    let mut out = vec![ManagedDeformer::player(Deformer::moving(
        Shape::Sphere { radius: 0.12 },
        step(x - 2.4 / 20.0),
        step(x),
    ))];
    for r in 0..6 {
        let x = r as f32 * 5.0 + 1.0;
        let z = -1.2 + 2.4 * (f % 40) as f32 / 40.0;
        out.push(ManagedDeformer::new(Deformer::moving(
            Shape::Sphere { radius: 0.1 },
            Pose::at([x, 0.15, z - 0.06]),
            Pose::at([x, 0.15, z]),
        )));
    }
    out
}

fn small_pool() -> ManagerConfig {
    let slot = snowprint::PoolFormat::default().slot_bytes(75, 75);
    ManagerConfig {
        pool_bytes: 2 * slot + 256,
        active_distance: 500.0,
        // Two resident roofs touched every frame and one update a frame: each waits a frame,
        // and its update catches two frames up, two layers in one encoder.
        updates_per_frame: 1,
        ..ManagerConfig::default()
    }
}

/// A buffer of the caller's, written by the caller's own commands before and after the snow.
fn callers_buffer() -> wgpu::Buffer {
    common::gpu().device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("engine"),
        size: 256,
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    })
}

#[test]
fn a_tick_recorded_between_the_callers_passes_leaves_what_tick_leaves() {
    let gpu = common::gpu();
    let roofs = six_roofs();
    let (mut encoded, ids) = manager(small_pool(), &roofs);
    let (mut ticked, ticked_ids) = manager(small_pool(), &roofs);
    let engine = callers_buffer();
    let (mut paged_out, mut paged_in, mut layers_seen) = (0, 0, 0);
    for f in 0..140 {
        // No call in this loop waits for the GPU.
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        encoder.clear_buffer(&engine, 0, None);
        let pending = encoded
            .encode_tick(&mut encoder, DT, None, &walker(f))
            .unwrap();
        assert!(matches!(
            encoded.encode_tick(&mut encoder, DT, None, &[]),
            Err(SnowError::FramePending)
        ));
        encoder.clear_buffer(&engine, 128, None);
        gpu.queue.submit([encoder.finish()]);
        let s = encoded.submitted(pending).unwrap();
        paged_out += s.paged_out_bytes;
        paged_in += s.paged_in_bytes;
        layers_seen = layers_seen.max(s.max_wait_frames);
        ticked.tick(DT, None, &walker(f)).unwrap();
    }
    assert!(
        paged_out > 0 && paged_in > 0,
        "{paged_out} out, {paged_in} in"
    );
    assert!(
        layers_seen >= 1,
        "surfaces waited and caught up: {layers_seen}"
    );
    encoded.flush().unwrap();
    ticked.flush().unwrap();
    let (a, b) = (read_all(&encoded, &ids), read_all(&ticked, &ticked_ids));
    for (k, (x, y)) in a.iter().zip(&b).enumerate() {
        assert!(x == y, "roof s{k} differs between encode_tick and tick");
        assert!(x.pressed_volume() > 10.0, "s{k} has its trails");
    }
}

#[test]
fn a_pending_tick_refuses_what_needs_the_gpu_and_an_abandoned_one_says_what_it_lost() {
    let gpu = common::gpu();
    let roofs = six_roofs();
    let (mut m, ids) = manager(small_pool(), &roofs);
    // Press roofs 0 and 1 (both resident), then walk on roof 2: one of them is evicted.
    for f in 0..20 {
        m.tick(DT, None, &walker(f)).unwrap();
    }
    m.flush().unwrap();
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    let mut evicting = None;
    for f in 40..80 {
        let pending = m.encode_tick(&mut encoder, DT, None, &walker(f)).unwrap();
        if !pending_evicts(&m) {
            gpu.queue.submit([std::mem::replace(
                &mut encoder,
                gpu.device.create_command_encoder(&Default::default()),
            )
            .finish()]);
            m.submitted(pending).unwrap();
            continue;
        }
        // While it is pending: reads, saves, unloads and ticks are refused, nothing changes.
        assert!(matches!(
            m.read_heightmap(ids[0]),
            Err(SnowError::FramePending)
        ));
        assert!(matches!(m.to_save_bytes(), Err(SnowError::FramePending)));
        assert!(matches!(
            m.unload_zone(ZoneId(0)),
            Err(SnowError::FramePending)
        ));
        assert!(matches!(
            m.tick(DT, None, &[]),
            Err(SnowError::FramePending)
        ));
        evicting = Some(pending);
        break;
    }
    let pending = evicting.expect("the walk evicts a roof");
    let evicted = m.planner().last_plan().stats.evicted.clone();
    drop(encoder);
    drop(pending);
    let lost = m.abandon_pending();
    let names: Vec<String> = lost
        .iter()
        .map(|&id| m.surface(id).unwrap().name.clone())
        .collect();
    assert_eq!(
        names, evicted,
        "the surfaces paged out in the dropped encoder"
    );
    // They read as untouched snow from now on, and the manager goes on.
    for &id in &lost {
        let map = m.read_heightmap(id).unwrap();
        assert!(map.depression.iter().all(|&d| d == 0));
    }
    m.tick(DT, None, &walker(80)).unwrap();
}

fn pending_evicts(m: &SnowManager) -> bool {
    !m.planner().last_plan().stats.evicted.is_empty()
}

/// Ticks (without waiting) until the ticket is answered; fails past three ticks.
fn answer(m: &mut SnowManager, ticket: ManagedProbeTicket) -> Vec<ManagedSample> {
    let gpu = common::gpu();
    for _ in 0..3 {
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        let pending = m.encode_tick(&mut encoder, DT, None, &[]).unwrap();
        gpu.queue.submit([encoder.finish()]);
        m.submitted(pending).unwrap();
        if let ManagedProbeStatus::Ready(samples) = m.probe_result(ticket).unwrap() {
            return samples;
        }
        // The engine's frame pacing (a swapchain waits so), not the library's.
        gpu.device
            .poll(wgpu::PollType::wait_indefinitely())
            .unwrap();
    }
    panic!("ticket {ticket:?} not answered in three ticks");
}

#[test]
fn probes_answer_over_resident_paged_and_untouched_surfaces() {
    let roofs = six_roofs();
    let (mut m, ids) = manager(small_pool(), &roofs);
    // Press roof 0 at its local (-0.4, 0.5) with a ball, nothing else.
    let press = Deformer::new(
        Shape::Sphere { radius: 0.3 },
        Pose::at([-0.4, 0.2 - 0.12 + 0.3, 0.5]),
    );
    m.tick(DT, None, &[ManagedDeformer::player(press)]).unwrap();
    m.flush().unwrap();
    assert!(m.world_id(ids[0]).is_some());
    let points = [
        Vec3::new(-0.4, 0.1, 0.5),  // In the print, roof 0.
        Vec3::new(-0.25, 0.1, 0.5), // On the print's slope.
        Vec3::new(10.0, 0.1, 0.0),  // Roof 2, never given a heightmap.
        Vec3::new(2.5, 0.1, 0.0),   // Between roofs.
    ];
    let ticket = m.probe(&points).unwrap();
    let resident = answer(&mut m, ticket);
    assert_eq!(resident.len(), 4);
    assert_eq!(resident[0].surface, Some(ids[0]));
    assert_eq!(resident[0].sample.surface, m.world_id(ids[0]));
    assert!(resident[0].sample.depression_m > 0.08, "{:?}", resident[0]);
    assert!(
        resident[1].sample.normal.x.abs() > 0.05,
        "a slope: {:?}",
        resident[1]
    );
    assert_eq!(resident[2].surface, Some(ids[2]));
    assert_eq!(resident[2].sample.depression_m, 0.0);
    assert_eq!(resident[2].sample.snow_depth_m, 0.2);
    assert_eq!(resident[2].sample.normal, Vec3::Y);
    assert_eq!(resident[3].surface, None);

    // Roof 0 pages out with its zone: the same points now read its page on the CPU, by the
    // GPU pass's rule, and agree with what the pass read.
    m.unload_zone(ZoneId(0)).unwrap();
    let ticket = m.probe(&points).unwrap();
    let paged = answer(&mut m, ticket);
    assert!(m.world_id(ids[0]).is_none() && m.pages().get(ids[0].index()).is_some());
    for k in 0..2 {
        let (g, c) = (resident[k].sample, paged[k].sample);
        assert_eq!(paged[k].surface, Some(ids[0]));
        assert_eq!(c.surface, None, "not read from the pool");
        assert!(
            (g.depression_m - c.depression_m).abs() < 1e-6,
            "{g:?} {c:?}"
        );
        assert!((g.snow_depth_m - c.snow_depth_m).abs() < 1e-6);
        assert!((g.displaced_m - c.displaced_m).abs() < 1e-6);
        assert!((g.normal - c.normal).length() < 1e-5, "{g:?} {c:?}");
    }
    assert_eq!(paged[2], resident[2]);
    assert!(matches!(
        m.probe_result(ticket),
        Err(SnowError::UnknownProbe { .. })
    ));
}
