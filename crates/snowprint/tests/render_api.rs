//! The renderer's contract: what it refuses (with the value that was wrong), what it reports (the
//! material of each surface, pass times), and rendering into a caller's texture.

mod common;

use glam::{Mat4, Vec3};
use snowprint::render::{
    Environment, Instance, OpaquePath, PASSES, RenderConfig, RenderError, RenderFrame, Renderer,
    SnowMaterialKind, Tier,
};
use snowprint::{
    Camera, Deformer, GroundMaterial, Mesh, Pose, Shape, SnowWorld, SurfaceDesc, WorldConfig,
};

fn world() -> SnowWorld {
    SnowWorld::new(
        common::gpu(),
        WorldConfig {
            pool_bytes: 2 << 20,
            ..Default::default()
        },
    )
    .expect("world")
}

fn camera() -> Camera {
    Camera {
        eye: Vec3::new(0.0, 3.0, 3.0),
        target: Vec3::ZERO,
        fov_y_degrees: 50.0,
    }
}

fn frame<'a>(
    surfaces: &'a [(snowprint::SurfaceId, GroundMaterial)],
    instances: &'a [Instance],
) -> RenderFrame<'a> {
    RenderFrame {
        camera: camera(),
        time: 0.0,
        surfaces,
        instances,
        lights: &[],
        environment: Environment::moonlit_night(),
        snowfall: true,
    }
}

fn small(tier: Tier) -> RenderConfig {
    let mut c = RenderConfig::new(64, 36, tier);
    c.shadow_map_size = 256;
    c.snowflakes = 200;
    c
}

#[test]
fn a_surface_switches_to_the_deformable_material_when_pressed() {
    let mut world = world();
    let a = world
        .add_surface(SurfaceDesc::new("a", [0.0, 0.0, 0.0], [2.0, 2.0], 0.2))
        .unwrap();
    let b = world
        .add_surface(SurfaceDesc::new("b", [3.0, 0.0, 0.0], [2.0, 2.0], 0.2))
        .unwrap();
    let surfaces = [
        (a, GroundMaterial::Concrete),
        (b, GroundMaterial::RoofTiles),
    ];
    let mut r = Renderer::new(common::gpu(), small(Tier::Relief)).unwrap();
    let out = r.render(&world, &frame(&surfaces, &[])).unwrap();
    assert_eq!(out.basic_material_surfaces, vec![a, b]);
    assert_eq!(out.rgba8.len(), 64 * 36 * 4);

    world
        .step(
            1.0 / 30.0,
            &[Deformer::new(
                Shape::Sphere { radius: 0.2 },
                Pose::at([0.0, 0.1, 0.0]),
            )],
        )
        .unwrap();
    let out = r.render(&world, &frame(&surfaces, &[])).unwrap();
    assert_eq!(out.basic_material_surfaces, vec![b]);
    let shading_a = out.surfaces.iter().find(|s| s.surface == a).unwrap();
    assert_eq!(shading_a.material, SnowMaterialKind::Deformable);
    // The sphere's bottom is 0.1 m below the ground under 0.2 m of snow: pressed to the ground.
    assert!(shading_a.deepest > 0.9, "{}", shading_a.deepest);
    // The CPU's steps of the frame, in order, within the time to build and submit it.
    let names: Vec<&str> = out.cpu_phases.iter().map(|p| p.name).collect();
    assert_eq!(
        names,
        [
            "surfaces",
            "classify",
            "heightfield",
            "snow",
            "dice",
            "banks",
            "tess_surface",
            "meshes",
            "opaque_tonemap",
            "record",
            "finish",
            "submit"
        ]
    );
    let steps: f64 = out.cpu_phases.iter().map(|p| p.ms).sum();
    assert!(
        out.cpu_phases.iter().all(|p| p.ms >= 0.0) && steps <= out.cpu_encode_ms,
        "{:?} against {} ms",
        out.cpu_phases,
        out.cpu_encode_ms
    );

    if r.has_timestamps() {
        let names: Vec<&str> = out.pass_times.iter().map(|p| p.name).collect();
        let expected: Vec<&str> = PASSES.iter().map(|p| p.name).collect();
        assert_eq!(names, expected);
        assert!(
            out.pass_times
                .iter()
                .all(|p| p.gpu_ms.is_finite() && p.gpu_ms >= 0.0)
        );
    } else {
        assert!(out.pass_times.is_empty());
    }
}

#[test]
fn mistakes_are_refused_with_the_value() {
    let gpu = common::gpu();
    let mut bad = small(Tier::Pom);
    bad.supersample = 7;
    let e = Renderer::new(gpu, bad).unwrap_err().to_string();
    assert!(e.contains("supersample") && e.contains('7'), "{e}");

    let mut bad = small(Tier::Relief);
    bad.look.ground_full = 0.1;
    let e = Renderer::new(gpu, bad).unwrap_err().to_string();
    assert!(e.contains("look"), "{e}");

    let mut world = world();
    let a = world
        .add_surface(SurfaceDesc::new("a", [0.0, 0.0, 0.0], [1.0, 1.0], 0.2))
        .unwrap();
    let mut r = Renderer::new(gpu, small(Tier::Relief)).unwrap();
    let mut other = Renderer::new(gpu, small(Tier::Relief)).unwrap();
    let foreign = other.add_mesh(&Mesh::cuboid(Vec3::ONE)).unwrap();
    let _ = other.add_mesh(&Mesh::cuboid(Vec3::ONE)).unwrap();
    let inst = [Instance::new(foreign, Mat4::IDENTITY, [1.0; 3])];
    match r.render(&world, &frame(&[], &inst)) {
        Err(RenderError::StaleMesh { index: 0 }) => {}
        other => panic!("expected a stale mesh, got {other:?}"),
    }

    let twice = [(a, GroundMaterial::Concrete), (a, GroundMaterial::Concrete)];
    let e = r
        .render(&world, &frame(&twice, &[]))
        .unwrap_err()
        .to_string();
    assert!(e.contains("listed twice"), "{e}");

    world.remove_surface(a).unwrap();
    let gone = [(a, GroundMaterial::Concrete)];
    let e = r.render(&world, &frame(&gone, &[])).unwrap_err();
    assert!(matches!(e, RenderError::World(_)), "{e}");

    let mut f = frame(&[], &[]);
    f.camera.target = f.camera.eye;
    let e = r.render(&world, &f).unwrap_err().to_string();
    assert!(e.contains("camera"), "{e}");

    let m = r.add_mesh(&Mesh::cuboid(Vec3::ONE)).unwrap();
    let nan = [Instance::new(
        m,
        Mat4::from_translation(Vec3::new(f32::NAN, 0.0, 0.0)),
        [1.0; 3],
    )];
    let e = r.render(&world, &frame(&[], &nan)).unwrap_err().to_string();
    assert!(e.contains("instance 0 transform"), "{e}");
    let flat = [Instance::new(
        m,
        Mat4::from_scale(Vec3::new(1.0, 0.0, 1.0)),
        [1.0; 3],
    )];
    let e = r
        .render(&world, &frame(&[], &flat))
        .unwrap_err()
        .to_string();
    assert!(e.contains("invertible"), "{e}");

    let broken = Mesh {
        positions: vec![Vec3::ZERO],
        indices: vec![0, 1, 2],
    };
    let e = r.add_mesh(&broken).unwrap_err().to_string();
    assert!(e.contains("out of range"), "{e}");
}

#[test]
fn renders_into_a_callers_texture() {
    let gpu = common::gpu();
    let world = world();
    let mut r = Renderer::new(gpu, small(Tier::Relief)).unwrap();
    let cube = r.add_mesh(&Mesh::cuboid(Vec3::splat(0.5))).unwrap();
    let inst = [Instance::new(cube, Mat4::IDENTITY, [0.6, 0.2, 0.1])];
    // A window's surface is often Bgra8Unorm (not sRGB): the tonemap pass then encodes sRGB itself.
    let texture = common::target(
        &gpu.device,
        "window stand-in",
        (64, 36),
        wgpu::TextureFormat::Bgra8Unorm,
        wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
    );
    let view = texture.create_view(&Default::default());
    for _ in 0..3 {
        r.render_to_view(
            &world,
            &frame(&[], &inst),
            &view,
            wgpu::TextureFormat::Bgra8Unorm,
        )
        .unwrap();
    }
    gpu.wait_idle().unwrap();
    // The offscreen path agrees with the window path on the centre pixel (the cube).
    let out = r.render(&world, &frame(&[], &inst)).unwrap();
    let staging = gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size: 256 * 36,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    r.render_to_view(
        &world,
        &frame(&[], &inst),
        &view,
        wgpu::TextureFormat::Bgra8Unorm,
    )
    .unwrap();
    let mut enc = gpu.device.create_command_encoder(&Default::default());
    enc.copy_texture_to_buffer(
        texture.as_image_copy(),
        wgpu::TexelCopyBufferInfo {
            buffer: &staging,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(256),
                rows_per_image: Some(36),
            },
        },
        wgpu::Extent3d {
            width: 64,
            height: 36,
            depth_or_array_layers: 1,
        },
    );
    gpu.queue.submit([enc.finish()]);
    staging.slice(..).map_async(wgpu::MapMode::Read, |_| {});
    gpu.wait_idle().unwrap();
    let data = staging.slice(..).get_mapped_range().unwrap().to_vec();
    // The two paths agree on every pixel, not only where they might both be black.
    for y in 0..36usize {
        for x in 0..64usize {
            let bgra = &data[y * 256 + x * 4..y * 256 + x * 4 + 4];
            let rgba = &out.rgba8[(y * 64 + x) * 4..(y * 64 + x) * 4 + 4];
            for c in 0..3 {
                let window = bgra[2 - c] as i32;
                assert!(
                    (window - rgba[c] as i32).abs() <= 2,
                    "pixel ({x}, {y}) channel {c}: window {window} vs offscreen {}",
                    rgba[c]
                );
            }
        }
    }
    // And what they agree on is the scene: the cube (albedo 0.6, 0.2, 0.1) in the middle is red
    // and lit, the sky in the corner is the blue night.
    let px = |x: usize, y: usize| {
        let p = &out.rgba8[(y * 64 + x) * 4..(y * 64 + x) * 4 + 3];
        (p[0] as u32, p[1] as u32, p[2] as u32)
    };
    let (cr, cg, cb) = px(32, 18);
    assert!(
        cr >= 60 && cr * 10 >= cg * 15 && cg >= cb,
        "cube {cr} {cg} {cb}"
    );
    let (sr, sg, sb) = px(0, 0);
    assert!(sb > sr && sb >= 20, "sky {sr} {sg} {sb}");
    assert!(r.latest_report().is_some());

    // A target of the wrong size is refused.
    let wrong = common::target(
        &gpu.device,
        "",
        (32, 36),
        wgpu::TextureFormat::Bgra8Unorm,
        wgpu::TextureUsages::RENDER_ATTACHMENT,
    );
    let e = r
        .render_to_view(
            &world,
            &frame(&[], &inst),
            &wrong.create_view(&Default::default()),
            wgpu::TextureFormat::Bgra8Unorm,
        )
        .unwrap_err();
    assert!(
        matches!(
            e,
            RenderError::TargetSize {
                got: (32, 36),
                expected: (64, 36)
            }
        ),
        "{e}"
    );
}

#[test]
fn supersampling_and_resize() {
    let gpu = common::gpu();
    let world = world();
    let mut r = Renderer::new(gpu, small(Tier::Relief)).unwrap();
    r.resize(48, 32, 2).unwrap();
    let mut f = frame(&[], &[]);
    // No flakes: they fall where the random stream puts them, which depends on the resolution.
    f.snowfall = false;
    f.camera = Camera {
        eye: Vec3::new(0.0, 1.0, 0.0),
        target: Vec3::new(0.0, 1.25, -1.0),
        fov_y_degrees: 50.0,
    };
    let out = r.render(&world, &f).unwrap();
    assert_eq!(
        (out.width, out.height, out.rgba8.len()),
        (48, 32, 48 * 32 * 4)
    );
    assert!(out.rgba8.chunks_exact(4).all(|p| p[3] == 255), "opaque");
    // Only sky, looking 14 degrees up with a 50 degree field: the horizon (0 degrees) is row 23 of
    // 32. The night sky is blue at the zenith side and brightens towards the horizon glow.
    let row = |y: usize| &out.rgba8[y * 48 * 4..(y + 1) * 48 * 4];
    let lum = |y: usize| {
        row(y)
            .chunks_exact(4)
            .map(|p| p[0] as u32 + p[1] as u32 + p[2] as u32)
            .sum::<u32>()
    };
    let (r0, g0, b0) = row(0)
        .chunks_exact(4)
        .fold((0u32, 0u32, 0u32), |(r, g, b), p| {
            (r + p[0] as u32, g + p[1] as u32, b + p[2] as u32)
        });
    assert!(
        b0 > r0 && b0 > g0,
        "the top row is the blue night sky: {r0} {g0} {b0}"
    );
    assert!(lum(0) >= 48 * 3 * 8, "the top row is not black: {}", lum(0));
    for y in 1..=23 {
        assert!(
            lum(y) + 48 >= lum(y - 1),
            "row {y} ({}) is darker than row {} ({}) above the horizon",
            lum(y),
            y - 1,
            lum(y - 1)
        );
    }
    assert!(
        lum(23) * 10 >= lum(0) * 18,
        "the horizon glow ({}) is not clearly brighter than the top ({})",
        lum(23),
        lum(0)
    );
    // Supersampling averages: the smooth sky at 2x2 samples is the 1x sky within a level or two;
    // only the stars (points, resolved differently at each resolution) may differ more, and they
    // are a few pixels: each row's sum stays within 8 %.
    r.resize(48, 32, 1).unwrap();
    let one = r.render(&world, &f).unwrap();
    assert_ne!(
        out.rgba8, one.rgba8,
        "the 2x2 samples were averaged: the stars differ"
    );
    let close = out
        .rgba8
        .iter()
        .zip(&one.rgba8)
        .filter(|(a, b)| a.abs_diff(**b) <= 2)
        .count();
    assert!(
        close * 100 >= out.rgba8.len() * 98,
        "only {close} of {} channels of the supersampled sky are within 2 levels of the 1x sky",
        out.rgba8.len()
    );
    for y in 0..32 {
        let one_lum = one.rgba8[y * 48 * 4..(y + 1) * 48 * 4]
            .chunks_exact(4)
            .map(|p| p[0] as u32 + p[1] as u32 + p[2] as u32)
            .sum::<u32>();
        assert!(
            lum(y).abs_diff(one_lum) * 100 <= one_lum * 8,
            "row {y}: supersampled {} vs 1x {one_lum}",
            lum(y)
        );
    }
}

/// A shadow map set on a running renderer is the map a renderer made with that side has: a cube
/// casting on snow renders bit for bit as by a renderer built with it, the map of the first side
/// does not (the shadow's edge falls on other pixels), and a side out of range is refused with
/// its value, the renderer unchanged.
#[test]
fn the_shadow_map_can_be_resized_on_a_running_renderer() {
    let gpu = common::gpu();
    let mut world = world();
    let s = world
        .add_surface(SurfaceDesc::new("s", [0.0, 0.0, 0.0], [3.0, 3.0], 0.2))
        .unwrap();
    let surfaces = [(s, GroundMaterial::Concrete)];
    let shoot = |r: &mut Renderer| {
        let cube = r.add_mesh(&Mesh::cuboid(Vec3::splat(0.3))).unwrap();
        let inst = [Instance::new(
            cube,
            Mat4::from_translation(Vec3::new(0.2, 0.7, 0.1)),
            [0.6, 0.2, 0.1],
        )];
        let mut f = frame(&surfaces, &inst);
        f.snowfall = false;
        r.render(&world, &f).unwrap().rgba8
    };
    let config = |size| RenderConfig {
        shadow_map_size: size,
        ..small(Tier::Relief)
    };
    let mut resized = Renderer::new(gpu, config(64)).unwrap();
    let coarse = shoot(&mut resized);
    resized.set_shadow_map_size(1024).unwrap();
    assert_eq!(resized.config().shadow_map_size, 1024);
    let fine = shoot(&mut resized);
    let built = shoot(&mut Renderer::new(gpu, config(1024)).unwrap());
    assert!(fine == built, "the resized map renders differently");
    let moved = coarse
        .chunks_exact(4)
        .zip(fine.chunks_exact(4))
        .filter(|(a, b)| a != b)
        .count();
    assert!(
        moved > 0,
        "a 64-texel map and a 1024-texel one gave the same image"
    );
    let e = resized.set_shadow_map_size(32).unwrap_err().to_string();
    assert!(e.contains("shadow_map_size") && e.contains("32"), "{e}");
    assert_eq!(resized.config().shadow_map_size, 1024);
    assert!(shoot(&mut resized) == built);
}

/// The renderer keeps its bind groups from frame to frame and makes one again when what it binds
/// is replaced: a renderer that drew two surfaces, then twelve (every per-surface buffer grows
/// past its first eight slots, under the groups of the first two), then the twelve in reverse
/// order (each slot binds another surface's textures), renders each frame bit for bit as a fresh
/// renderer does, in the relief and the tessellated tier.
#[test]
fn kept_bind_groups_follow_grown_buffers_and_reordered_surfaces() {
    let gpu = common::gpu();
    let mut world = world();
    let centres: Vec<[f32; 3]> = (0..12)
        .map(|i| [(i % 4) as f32 * 1.2 - 1.8, 0.0, (i / 4) as f32 * 1.2 - 1.2])
        .collect();
    let ids: Vec<_> = centres
        .iter()
        .enumerate()
        .map(|(i, &c)| {
            let desc = SurfaceDesc::new(&format!("s{i}"), c, [1.0, 1.0], 0.2);
            world.add_surface(desc).unwrap()
        })
        .collect();
    // Every surface pressed, so that each runs the heightfield (and, diced, the bank) passes.
    let presses: Vec<Deformer> = centres
        .iter()
        .map(|&[x, _, z]| Deformer::new(Shape::Sphere { radius: 0.2 }, Pose::at([x, 0.1, z])))
        .collect();
    world.step(1.0 / 30.0, &presses).unwrap();
    let all: Vec<_> = ids
        .iter()
        .map(|&id| (id, GroundMaterial::Concrete))
        .collect();
    let reversed: Vec<_> = all.iter().rev().copied().collect();
    let shoot = |r: &mut Renderer, surfaces: &[(snowprint::SurfaceId, GroundMaterial)]| {
        r.render(&world, &frame(surfaces, &[])).unwrap().rgba8
    };
    for tier in [Tier::Relief, Tier::Tessellated] {
        let mut kept = Renderer::new(gpu, small(tier)).unwrap();
        shoot(&mut kept, &all[..2]);
        for (name, surfaces) in [("twelve", &all), ("reversed", &reversed)] {
            let fresh = shoot(&mut Renderer::new(gpu, small(tier)).unwrap(), surfaces);
            let again = shoot(&mut kept, surfaces);
            assert!(
                again == fresh,
                "{tier:?}, {name}: the running renderer differs"
            );
        }
    }
}

/// The passes keep a table the CPU wrote while the next frame's is the same, byte for byte: a
/// frame whose tables change but not their sizes (the surfaces in another order, an instance
/// moved) draws what a fresh renderer draws.
#[test]
fn tables_kept_between_frames_are_written_again_when_they_change() {
    let gpu = common::gpu();
    let mut world = world();
    let ids: Vec<_> = [[-0.7, 0.0, 0.0], [0.7, 0.0, 0.0]]
        .iter()
        .enumerate()
        .map(|(i, &c)| {
            let desc = SurfaceDesc::new(&format!("s{i}"), c, [1.2, 1.2], 0.2);
            world.add_surface(desc).unwrap()
        })
        .collect();
    // Prints in different places, so that each surface's tables are its own.
    let presses = [[-0.9, 0.1, 0.2], [0.6, 0.1, -0.3]]
        .map(|at| Deformer::new(Shape::Sphere { radius: 0.2 }, Pose::at(at)));
    world.step(1.0 / 30.0, &presses).unwrap();
    let concrete = |id| (id, GroundMaterial::Concrete);
    let (first, second) = (
        [concrete(ids[0]), concrete(ids[1])],
        [concrete(ids[1]), concrete(ids[0])],
    );
    let cube = Mesh::cuboid(Vec3::splat(0.2));
    let at = |mesh, x: f32| {
        let place = Mat4::from_translation(Vec3::new(x, 0.5, 0.0));
        [Instance::new(mesh, place, [0.7, 0.5, 0.3])]
    };
    for tier in [Tier::Relief, Tier::Tessellated] {
        let mut kept = Renderer::new(gpu, small(tier)).unwrap();
        let mesh = kept.add_mesh(&cube).unwrap();
        let before = kept
            .render(&world, &frame(&first, &at(mesh, -0.5)))
            .unwrap()
            .rgba8;
        let again = kept
            .render(&world, &frame(&second, &at(mesh, 0.5)))
            .unwrap()
            .rgba8;
        let mut fresh = Renderer::new(gpu, small(tier)).unwrap();
        let mesh = fresh.add_mesh(&cube).unwrap();
        let expected = fresh
            .render(&world, &frame(&second, &at(mesh, 0.5)))
            .unwrap()
            .rgba8;
        assert!(
            expected != before,
            "{tier:?}: the second frame changes nothing"
        );
        assert!(again == expected, "{tier:?}: the running renderer differs");
    }
}

/// The meshes live in one vertex and one index buffer: a mesh replaced by one of its own size is
/// written in place, by one of another size (or a mesh added) every mesh is laid out again. Either
/// way the frame is the one a renderer given the new meshes from the start draws, on both opaque
/// paths (the visibility path pulls the same buffers).
#[test]
fn replaced_meshes_draw_as_meshes_registered_anew() {
    let gpu = common::gpu();
    let world = world();
    let place = |mesh, x: f32| {
        Instance::new(
            mesh,
            Mat4::from_translation(Vec3::new(x, 0.4, 0.0)),
            [0.7, 0.5, 0.3],
        )
    };
    let shoot = |r: &mut Renderer, meshes: &[snowprint::render::RenderMeshId]| {
        let instances = [place(meshes[0], -0.6), place(meshes[1], 0.6)];
        r.render(&world, &frame(&[], &instances)).unwrap().rgba8
    };
    let first = [Mesh::cuboid(Vec3::splat(0.3)), Mesh::uv_sphere(0.3, 6, 8)];
    // The same sizes as `first` (in place), then the sphere finer (laid out again).
    let second = [Mesh::cuboid(Vec3::new(0.2, 0.5, 0.25)), first[1].clone()];
    let third = [second[0].clone(), Mesh::uv_sphere(0.35, 12, 16)];
    for opaque in [OpaquePath::Forward, OpaquePath::Visibility] {
        let config = RenderConfig {
            opaque,
            ..small(Tier::Relief)
        };
        let mut kept = Renderer::new(gpu, config).unwrap();
        let ids: Vec<_> = first.iter().map(|m| kept.add_mesh(m).unwrap()).collect();
        let before = shoot(&mut kept, &ids);
        for (name, meshes) in [("same sizes", &second), ("another size", &third)] {
            for (id, mesh) in ids.iter().zip(meshes) {
                kept.update_mesh(*id, mesh).unwrap();
            }
            let mut fresh = Renderer::new(gpu, config).unwrap();
            let fresh_ids: Vec<_> = meshes.iter().map(|m| fresh.add_mesh(m).unwrap()).collect();
            let expected = shoot(&mut fresh, &fresh_ids);
            assert!(
                expected != before,
                "{opaque:?}, {name}: the new meshes change nothing"
            );
            assert!(
                shoot(&mut kept, &ids) == expected,
                "{opaque:?}, {name}: the replaced meshes draw otherwise"
            );
        }
    }
}
