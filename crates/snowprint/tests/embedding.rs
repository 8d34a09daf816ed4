//! Embedding in an engine: the engine creates the device (and is told plainly when its limits
//! fall short), records the snow into its own command encoder between its own passes, and reads
//! GPU times that never make the frame wait.

mod common;

use glam::Vec3;
use snowprint::low_level::gpu::download;
use snowprint::render::{
    Environment, OUTPUT_FORMAT, RenderConfig, RenderError, RenderFrame, Renderer, Tier,
};
use snowprint::{
    Camera, Capabilities, Deformer, GpuContext, GroundMaterial, Pose, Shape, SnowError, SnowWorld,
    SurfaceDesc, WorldConfig, required_features, required_limits,
};

/// An adapter and a device on it, created the way an engine creates its own.
fn engine_device(
    limits: wgpu::Limits,
    timestamps: bool,
) -> (wgpu::Adapter, wgpu::Device, wgpu::Queue) {
    pollster::block_on(async {
        let instance =
            wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
        let adapter = instance
            .request_adapter(&wgpu::RequestAdapterOptions::default())
            .await
            .expect("GPU tests need an adapter (apt-get install mesa-vulkan-drivers)");
        let mut features = required_features();
        if timestamps {
            features |= adapter.features() & wgpu::Features::TIMESTAMP_QUERY;
        }
        let (device, queue) = adapter
            .request_device(&wgpu::DeviceDescriptor {
                label: Some("engine"),
                required_features: features,
                required_limits: limits,
                ..Default::default()
            })
            .await
            .expect("the adapter gives the limits asked for");
        (adapter, device, queue)
    })
}

fn engine_gpu(timestamps: bool) -> GpuContext {
    let (adapter, device, queue) = engine_device(required_limits(), timestamps);
    GpuContext::from_device(&adapter, device, queue).expect("required_limits() are enough")
}

fn roof(world: &mut SnowWorld) -> snowprint::SurfaceId {
    world
        .add_surface(SurfaceDesc::new("roof", [0.0, 0.0, 0.0], [2.0, 2.0], 0.3))
        .unwrap()
}

fn foot() -> Deformer {
    Deformer::new(Shape::Sphere { radius: 0.25 }, Pose::at([0.1, 0.15, -0.2]))
}

#[test]
fn downlevel_defaults_are_refused_naming_the_limit() {
    let (adapter, device, queue) = engine_device(wgpu::Limits::downlevel_defaults(), false);
    let expect_limit = |e: SnowError| match e {
        SnowError::DeviceLimit {
            limit,
            required,
            available,
        } => {
            assert_eq!(limit, "max_storage_buffers_per_shader_stage");
            assert_eq!((required, available), (8, 4));
            let sentence = SnowError::DeviceLimit {
                limit,
                required,
                available,
            }
            .to_string();
            assert!(sentence.contains("max_storage_buffers_per_shader_stage"));
            assert!(sentence.contains("required_limits()"), "{sentence}");
        }
        other => panic!("expected DeviceLimit, got {other}"),
    };
    let err = GpuContext::from_device(&adapter, device.clone(), queue.clone()).unwrap_err();
    expect_limit(err);

    // A context filled in by hand reaches the world's and the renderer's own checks.
    let gpu = GpuContext {
        device,
        queue,
        info: adapter.get_info(),
        caps: Capabilities {
            timestamps: false,
            max_storage_binding: 1 << 30,
            max_texture_side: 16384,
            filterable_rgba16f: true,
            warnings: Vec::new(),
        },
    };
    expect_limit(SnowWorld::new(&gpu, WorldConfig::default()).unwrap_err());
    match Renderer::new(&gpu, RenderConfig::new(32, 32, Tier::Relief)) {
        Err(RenderError::World(e)) => expect_limit(e),
        other => panic!("expected the world's DeviceLimit, got {:?}", other.err()),
    }
}

#[test]
fn required_limits_run_the_update_and_every_render_tier() {
    let gpu = engine_gpu(false);
    assert_eq!(
        gpu.device.limits().max_storage_buffers_per_shader_stage,
        required_limits().max_storage_buffers_per_shader_stage
    );
    // Validation errors (a limit a pass exceeds) are caught here rather than panicking.
    let scope = gpu.device.push_error_scope(wgpu::ErrorFilter::Validation);
    let mut world = SnowWorld::new(&gpu, WorldConfig::default()).unwrap();
    let id = roof(&mut world);
    world.step(1.0 / 30.0, &[foot()]).unwrap();
    let map = world.read_heightmap(id).unwrap();
    assert!(
        map.depression.iter().any(|&d| d > 0),
        "the foot pressed the snow"
    );
    let surfaces = [(id, GroundMaterial::Concrete)];
    for tier in [Tier::Relief, Tier::Pom, Tier::Tessellated] {
        let mut config = RenderConfig::new(48, 32, tier);
        config.snowflakes = 100;
        let mut renderer = Renderer::new(&gpu, config).unwrap();
        let out = renderer.render(&world, &frame(&surfaces)).unwrap();
        assert_eq!(out.rgba8.len(), 48 * 32 * 4);
    }
    if let Some(e) = pollster::block_on(scope.pop()) {
        panic!("a pass needs more than required_limits(): {e}");
    }
}

fn frame(surfaces: &[(snowprint::SurfaceId, GroundMaterial)]) -> RenderFrame<'_> {
    RenderFrame {
        camera: Camera {
            eye: Vec3::new(0.0, 2.0, 3.0),
            target: Vec3::ZERO,
            fov_y_degrees: 50.0,
        },
        time: 0.0,
        surfaces,
        instances: &[],
        lights: &[],
        environment: Environment::moonlit_night(),
        snowfall: true,
    }
}

#[test]
fn a_frame_recorded_between_two_of_the_callers_passes() {
    let gpu = engine_gpu(false);
    let (device, queue) = (&gpu.device, &gpu.queue);
    let mut world = SnowWorld::new(&gpu, WorldConfig::default()).unwrap();
    let id = roof(&mut world);
    let layout = world.layout(id).unwrap();
    let bytes = world
        .pool_format()
        .heights_bytes(layout.width, layout.height);
    let offset = world.gpu_offsets(id).unwrap().0 as u64 * 4;
    let copy = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("engine copy"),
        size: bytes,
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    let target = common::target(
        device,
        "engine target",
        (16, 16),
        wgpu::TextureFormat::Rgba8Unorm,
        wgpu::TextureUsages::RENDER_ATTACHMENT,
    );
    let view = target.create_view(&Default::default());

    let mut encoder = device.create_command_encoder(&Default::default());
    // The engine's pass before the snow: a render pass of its own, and its buffer filled with
    // a value the pool never holds where the foot pressed.
    drop(encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some("engine pass before"),
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view: &view,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations {
                load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                store: wgpu::StoreOp::Store,
            },
        })],
        ..Default::default()
    }));
    encoder.clear_buffer(&copy, 0, None);
    let pending = world
        .encode_step(&mut encoder, 1.0 / 30.0, &[foot()])
        .unwrap();
    // The engine's pass after: it reads the heightmap the snow just wrote.
    encoder.copy_buffer_to_buffer(world.pool_buffer(), offset, &copy, 0, bytes);
    queue.submit([encoder.finish()]);
    let stats = world.submitted(pending).unwrap();
    assert_eq!((stats.frame, stats.updated, stats.captured), (1, 1, 1));

    let copied = download(device, queue, &copy, 0, bytes).unwrap();
    let pool = download(device, queue, world.pool_buffer(), offset, bytes).unwrap();
    assert_eq!(
        copied, pool,
        "the copy after the snow sees what the snow wrote"
    );
    assert!(copied.iter().any(|&b| b != 0), "the foot pressed the snow");

    // The same frame through the convenience wrapper, on a world of its own, leaves the same
    // heightmap to the bit.
    let mut reference = SnowWorld::new(&gpu, WorldConfig::default()).unwrap();
    let rid = roof(&mut reference);
    reference.step(1.0 / 30.0, &[foot()]).unwrap();
    let (a, b) = (
        world.read_heightmap(id).unwrap(),
        reference.read_heightmap(rid).unwrap(),
    );
    assert_eq!(a.depression, b.depression);
    assert_eq!(a.displaced, b.displaced);
}

#[test]
fn one_frame_in_flight_at_a_time() {
    let gpu = engine_gpu(false);
    let mut world = SnowWorld::new(&gpu, WorldConfig::default()).unwrap();
    let id = roof(&mut world);
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    let pending = world.encode_step(&mut encoder, 0.01, &[foot()]).unwrap();
    // A second frame would overwrite the first one's tables before it ran.
    assert!(matches!(
        world.encode_step(&mut encoder, 0.01, &[]),
        Err(SnowError::FramePending)
    ));
    assert!(matches!(
        world.step(0.01, &[]),
        Err(SnowError::FramePending)
    ));
    // A frame of another world is refused, and nothing changes.
    let mut other = SnowWorld::new(&gpu, WorldConfig::default()).unwrap();
    let mut other_encoder = gpu.device.create_command_encoder(&Default::default());
    let foreign = other.encode_step(&mut other_encoder, 0.01, &[]).unwrap();
    assert!(matches!(
        world.submitted(foreign),
        Err(SnowError::StaleHandle { .. })
    ));
    // A surface removed while its frame is in flight keeps its bytes until the frame is done.
    let used = world.memory().pool_used;
    world.remove_surface(id).unwrap();
    assert_eq!(world.memory().pool_used, used);
    gpu.queue.submit([encoder.finish()]);
    world.submitted(pending).unwrap();
    assert_eq!(world.memory().pool_used, 0);
    // An encoder dropped unsubmitted: the world is told, and encodes again.
    let mut dropped = gpu.device.create_command_encoder(&Default::default());
    let _lost = world.encode_step(&mut dropped, 0.01, &[]).unwrap();
    world.abandon_pending();
    world.step(0.01, &[]).unwrap();
}

#[test]
fn profiling_times_arrive_later_without_waiting() {
    let gpu = engine_gpu(true);
    let mut world = SnowWorld::new(&gpu, WorldConfig::default()).unwrap();
    if !world.has_timestamps() {
        // Without timestamp queries profiling measures nothing, and says so.
        world.set_profiling(true);
        roof(&mut world);
        assert_eq!(world.step(0.01, &[foot()]).unwrap().gpu, None);
        return;
    }
    roof(&mut world);
    world.set_profiling(true);
    let mut arrived = Vec::new();
    // No call below waits for the GPU: frames are encoded, submitted and reported, and the
    // times of earlier frames turn up as the GPU finishes them.
    for _ in 0..200 {
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        let pending = world.encode_step(&mut encoder, 0.01, &[foot()]).unwrap();
        gpu.queue.submit([encoder.finish()]);
        let stats = world.submitted(pending).unwrap();
        if let (Some(frame), Some(times)) = (stats.gpu_frame, stats.gpu) {
            assert!(frame <= stats.frame, "times of a frame not yet run");
            assert!(times.capture_ms >= 0.0 && times.total_ms() > 0.0);
            arrived.push(frame);
        }
        if arrived.len() >= 3 {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    assert!(arrived.len() >= 3, "GPU times arrived for {arrived:?} only");
    assert!(arrived.windows(2).all(|w| w[0] < w[1]), "{arrived:?}");
    // After the last frame, the times still on their way are collected.
    gpu.wait_idle().unwrap();
    let mut last = *arrived.last().unwrap();
    while let Some((frame, _)) = world.take_gpu_times().unwrap() {
        assert!(frame > last);
        last = frame;
    }
    assert_eq!(world.take_gpu_times().unwrap(), None);
}

#[test]
fn the_per_frame_path_has_no_blocking_wait() {
    // The profiling readback and the encode forms poll; only readbacks meant for tools wait.
    for (file, text) in [
        ("src/gpu/ring.rs", include_str!("../src/gpu/ring.rs")),
        ("src/world/frame.rs", include_str!("../src/world/frame.rs")),
        (
            "src/world/probe/batch.rs",
            include_str!("../src/world/probe/batch.rs"),
        ),
        (
            "src/manager/frame.rs",
            include_str!("../src/manager/frame.rs"),
        ),
        (
            "src/manager/apply.rs",
            include_str!("../src/manager/apply.rs"),
        ),
        (
            "src/manager/probe.rs",
            include_str!("../src/manager/probe.rs"),
        ),
    ] {
        let code = text.lines().filter(|l| !l.trim_start().starts_with("//"));
        for line in code {
            for blocking in [
                "wait_indefinitely",
                "map_read",
                "wait_idle",
                "block_on",
                ".wait(",
                ".peek(",
                "snapshot_surfaces",
                "read_heightmap",
            ] {
                assert!(!line.contains(blocking), "{file} calls {blocking}: {line}");
            }
        }
    }
}

#[test]
fn the_renderer_records_into_the_callers_encoder() {
    let gpu = engine_gpu(false);
    let (device, queue) = (&gpu.device, &gpu.queue);
    let mut world = SnowWorld::new(&gpu, WorldConfig::default()).unwrap();
    let id = roof(&mut world);
    world.step(1.0 / 30.0, &[foot()]).unwrap();
    let (w, h) = (48u32, 32u32);
    let mut config = RenderConfig::new(w, h, Tier::Relief);
    config.snowflakes = 100;
    let mut renderer = Renderer::new(&gpu, config).unwrap();
    let surfaces = [(id, GroundMaterial::Concrete)];
    let target = common::target(
        device,
        "engine swapchain stand-in",
        (w, h),
        OUTPUT_FORMAT,
        wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
    );
    let view = target.create_view(&Default::default());
    let row = 256u32;
    let pixels = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("engine readback"),
        size: (row * h) as u64,
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });

    let mut encoder = device.create_command_encoder(&Default::default());
    // The engine's pass before: it clears the target to a colour the snow frame covers.
    drop(encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some("engine pass before"),
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view: &view,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations {
                load: wgpu::LoadOp::Clear(wgpu::Color::RED),
                store: wgpu::StoreOp::Store,
            },
        })],
        ..Default::default()
    }));
    // A world frame with nothing to do, and the snow frame, in the engine's encoder.
    let snow = world.encode_step(&mut encoder, 0.0, &[]).unwrap();
    let pending = renderer
        .encode_to_view(
            &mut encoder,
            &world,
            &frame(&surfaces),
            &view,
            OUTPUT_FORMAT,
        )
        .unwrap();
    // The engine's pass after: it copies what the snow frame drew.
    encoder.copy_texture_to_buffer(
        target.as_image_copy(),
        wgpu::TexelCopyBufferInfo {
            buffer: &pixels,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(row),
                rows_per_image: Some(h),
            },
        },
        target.size(),
    );
    queue.submit([encoder.finish()]);
    world.submitted(snow).unwrap();
    let _ = renderer.submitted(pending);

    let padded = download(device, queue, &pixels, 0, (row * h) as u64).unwrap();
    let drawn: Vec<u8> = padded
        .chunks(row as usize)
        .flat_map(|r| r[..4 * w as usize].to_vec())
        .collect();
    let offscreen = renderer.render(&world, &frame(&surfaces)).unwrap();
    assert_eq!(
        drawn, offscreen.rgba8,
        "the frame recorded into the engine's encoder is the offscreen frame"
    );
}

/// Probes queued before an `encode_step` ride the caller's encoder: nothing is answered before
/// the caller submits; after it submits (and, as a swapchain would, lets the GPU finish that
/// frame) the answer is there. An abandoned frame queues its probes again.
#[test]
fn probes_ride_the_callers_encoder_and_survive_an_abandoned_frame() {
    let gpu = engine_gpu(false);
    let mut world = SnowWorld::new(&gpu, WorldConfig::default()).unwrap();
    roof(&mut world);
    world.step(0.01, &[foot()]).unwrap();
    let point = Vec3::new(0.1, 0.2, -0.2);
    let ticket = world.probe(&[point]).unwrap();

    // Recorded into an encoder that is dropped: the request is queued again, not lost.
    let mut dropped = gpu.device.create_command_encoder(&Default::default());
    let _lost = world.encode_step(&mut dropped, 0.01, &[]).unwrap();
    drop(dropped);
    world.abandon_pending();
    assert_eq!(world.probes_in_flight(), 0);
    assert_eq!(
        world.probe_result(ticket).unwrap(),
        snowprint::ProbeStatus::Pending
    );

    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    let pending = world.encode_step(&mut encoder, 0.01, &[]).unwrap();
    assert_eq!(
        world.probes_in_flight(),
        1,
        "recorded into the caller's encoder"
    );
    assert_eq!(
        world.probe_result(ticket).unwrap(),
        snowprint::ProbeStatus::Pending
    );
    let index = gpu.queue.submit([encoder.finish()]);
    world.submitted(pending).unwrap();
    // The engine's frame pacing, not the library: the frame has run on the GPU.
    gpu.device
        .poll(wgpu::PollType::Wait {
            submission_index: Some(index),
            timeout: None,
        })
        .unwrap();
    let snowprint::ProbeStatus::Ready(samples) = world.probe_result(ticket).unwrap() else {
        panic!("the frame that carried the probe has run, its answer must be there");
    };
    let map = world
        .read_heightmap(world.surfaces().next().unwrap().0)
        .unwrap();
    let deepest = map.depression.iter().copied().max().unwrap();
    assert!(deepest > 0);
    // The sphere's centre is over the point: the probe reads a pressed texel.
    assert!(samples[0].depression_m > 0.05, "{:?}", samples[0]);
    assert!(samples[0].surface.is_some());
}

/// While it snows, an abandoned frame's replenishment is not kept: the carry a snapshot shows is
/// the one before the frame, and a submitted frame moves it on exactly as `step` does.
#[test]
fn an_abandoned_frame_keeps_no_replenishment() {
    let gpu = engine_gpu(false);
    let mut world = SnowWorld::new(&gpu, WorldConfig::default()).unwrap();
    let mut twin = SnowWorld::new(&gpu, WorldConfig::default()).unwrap();
    let mut desc = SurfaceDesc::new("roof", [0.0, 0.0, 0.0], [2.0, 2.0], 0.3);
    desc.replenish_rate = 0.0123;
    let id = world.add_surface(desc.clone()).unwrap();
    let twin_id = twin.add_surface(desc).unwrap();
    let carry = |w: &SnowWorld, id| w.snapshot_surfaces(&[id]).unwrap()[0].carry;
    world.step(0.013, &[foot()]).unwrap();
    twin.step(0.013, &[foot()]).unwrap();
    let before = carry(&world, id);
    assert!(before > 0.0, "the step's snowfall leaves a fraction behind");

    let mut dropped = gpu.device.create_command_encoder(&Default::default());
    let _lost = world.encode_step(&mut dropped, 0.017, &[]).unwrap();
    world.abandon_pending();
    assert_eq!(carry(&world, id), before);

    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    let pending = world.encode_step(&mut encoder, 0.017, &[]).unwrap();
    gpu.queue.submit([encoder.finish()]);
    world.submitted(pending).unwrap();
    twin.step(0.017, &[]).unwrap();
    assert_ne!(carry(&world, id), before);
    assert_eq!(carry(&world, id), carry(&twin, twin_id));
    assert_eq!(
        world.read_packed(id).unwrap(),
        twin.read_packed(twin_id).unwrap()
    );
}

/// An engine's device made with `required_limits` binds 128 MiB a storage buffer: a frame that
/// would capture 129 surfaces of 512^2 whole at once (a slab pressed over each) needs 4 bytes a
/// texel of capture over each surface's capture region (its texels and the apron of one around
/// them: 514^2), 136.3 MB. The step is refused in one sentence naming the buffer, its bytes
/// and the limit (wgpu would panic binding it), nothing changes, and fewer surfaces a frame, as
/// the sentence says, are pressed.
#[test]
fn a_frame_larger_than_the_device_binds_is_refused_and_can_be_split() {
    let gpu = engine_gpu(false);
    let max = gpu.device.limits().max_storage_buffer_binding_size;
    // The compute capture (a GPU's path) captures every surface of a frame in one buffer.
    let config = WorldConfig {
        format: snowprint::PoolFormat::new(snowprint::Precision::Bits8),
        capture_path: snowprint::CapturePath::Compute,
        pool_bytes: 72 << 20,
        ..WorldConfig::default()
    };
    let mut world = SnowWorld::new(&gpu, config).unwrap();
    let side = 512.0 * 0.04;
    let n = (max / (4 * 512 * 512) + 1) as usize;
    let ids: Vec<_> = (0..n)
        .map(|i| {
            let c = [i as f32 * (side + 1.0), 0.0, 0.0];
            let id = world
                .add_surface(SurfaceDesc::new(&format!("s{i}"), c, [side, side], 0.3))
                .unwrap();
            (id, c)
        })
        .collect();
    assert_eq!(world.layout(ids[0].0).unwrap().texels(), 512 * 512);
    let feet: Vec<Deformer> = ids
        .iter()
        .map(|&(_, c)| {
            // A slab over the whole surface: the capture reaches all of its texels.
            let half = Vec3::new(side * 0.5, 0.05, side * 0.5);
            Deformer::new(
                Shape::Box { half_extents: half },
                Pose::at([c[0], 0.25, 0.0]),
            )
        })
        .collect();
    let e = world.step(1.0 / 60.0, &feet).unwrap_err();
    assert!(
        matches!(
            e,
            SnowError::FrameTooLarge {
                buffer: "capture",
                bytes,
                max: m,
                surfaces,
            } if bytes == n as u64 * 4 * 514 * 514 && m == max && surfaces == n
        ),
        "{e}"
    );
    println!("{e}");
    assert!(
        e.to_string()
            .contains("update fewer or smaller surfaces a frame")
    );
    let untouched = |w: &SnowWorld, id| w.read_channels(id).unwrap().0.iter().all(|&v| v == 0);
    for k in [0, n / 2, n - 1] {
        assert!(
            untouched(&world, ids[k].0),
            "the refused frame changed the snow"
        );
    }
    // Fewer surfaces a frame, as the sentence says: eight of them, each with its own slab.
    let updates: Vec<snowprint::SurfaceUpdate> = ids[..8]
        .iter()
        .zip(&feet)
        .map(|(&(id, _), foot)| snowprint::SurfaceUpdate {
            surface: id,
            elapsed: 1.0 / 60.0,
            deformers: std::slice::from_ref(foot),
        })
        .collect();
    world.update(&updates).unwrap();
    for &(id, _) in &ids[..8] {
        let (dep, _) = world.read_channels(id).unwrap();
        assert!(
            dep.iter().all(|&v| v > 0),
            "a surface was not pressed whole"
        );
    }
    assert!(untouched(&world, ids[8].0));
}
