//! The engine module (`wgsl::engine_module`) read by a compute shader of the test's own, with a
//! `SurfaceUniform` from `SurfaceUniform::for_surface`, against the world's CPU readbacks: every
//! texel at 8, 16 and 32 bits a channel (odd widths, a surface that does not start the pool),
//! bilinear reads between texel centres, and normals by hand.

mod common;

use snowprint::wgsl::{ImportOptions, engine_module};
use snowprint::{
    Deformer, PoolFormat, Pose, Precision, Shape, SnowError, SnowWorld, SurfaceDesc, SurfaceId,
    SurfaceUniform, WorldConfig,
};

/// Per texel (depression, displaced, depression at the texel's upper-right corner, snow depth at
/// the centre) and the normal at the centre (xyz).
const SHADER: &str = r#"
@group(1) @binding(0) var<uniform> surface: snowprint_Surface;
@group(1) @binding(1) var<storage, read_write> out: array<vec4<f32>>;
@group(1) @binding(2) var<storage, read_write> normals: array<vec4<f32>>;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let s = surface;
    if id.x >= s.width || id.y >= s.height {
        return;
    }
    let size = vec2<f32>(f32(s.width), f32(s.height));
    let centre = (vec2<f32>(id.xy) + 0.5) / size;
    let corner = (vec2<f32>(id.xy) + 1.0) / size;
    let i = id.y * s.width + id.x;
    out[i] = vec4<f32>(
        snowprint_depression(s, id.xy),
        snowprint_displaced(s, id.xy),
        snowprint_depression_uv(s, corner),
        snowprint_snow_depth_at(s, centre),
    );
    normals[i] = vec4<f32>(snowprint_normal(s, centre), 0.0);
}
"#;

/// A world at `precision` with two surfaces (the second, odd-sized, is read) and a sphere pressed
/// into the second.
fn pressed_world(precision: Precision) -> (SnowWorld, SurfaceId) {
    let mut world = SnowWorld::new(
        common::gpu(),
        WorldConfig {
            format: PoolFormat::new(precision),
            ..Default::default()
        },
    )
    .expect("world");
    world
        .add_surface(SurfaceDesc::new(
            "first",
            [-10.0, 0.0, 0.0],
            [1.0, 1.0],
            0.3,
        ))
        .expect("first");
    let id = world
        .add_surface(SurfaceDesc::new(
            "read",
            [3.0, 2.0, 1.0],
            [2.98, 2.02],
            0.25,
        ))
        .expect("second");
    let ball = Deformer::new(Shape::Sphere { radius: 0.35 }, Pose::at([3.2, 2.38, 1.1]));
    world.step(1.0 / 60.0, &[ball]).expect("step");
    (world, id)
}

/// Run the shader over every texel of `id`: (per-texel values, normals).
fn read_on_gpu(world: &SnowWorld, id: SurfaceId) -> (Vec<[f32; 4]>, Vec<[f32; 4]>) {
    let gpu = common::gpu();
    let device = &gpu.device;
    let view = world.frame_view();
    let surface = SurfaceUniform::for_surface(&view, id).expect("surface");
    let texels = (surface.width * surface.height) as u64;
    let source = format!(
        "{}\n{SHADER}",
        engine_module(&ImportOptions {
            group: 0,
            pool_binding: 5,
        })
    );
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("engine module test"),
        source: wgpu::ShaderSource::Wgsl(source.into()),
    });
    let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some("engine module test"),
        layout: None,
        module: &module,
        entry_point: Some("main"),
        compilation_options: Default::default(),
        cache: None,
    });
    let buffer = |usage, size| {
        device.create_buffer(&wgpu::BufferDescriptor {
            label: None,
            size,
            usage,
            mapped_at_creation: false,
        })
    };
    let uniform = buffer(
        wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        std::mem::size_of::<SurfaceUniform>() as u64,
    );
    gpu.queue
        .write_buffer(&uniform, 0, bytemuck::bytes_of(&surface));
    let storage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC;
    let out = buffer(storage, texels * 16);
    let normals = buffer(storage, texels * 16);
    let pool_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout: &pipeline.get_bind_group_layout(0),
        entries: &[wgpu::BindGroupEntry {
            binding: 5,
            resource: view.pool_buffer.as_entire_binding(),
        }],
    });
    let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout: &pipeline.get_bind_group_layout(1),
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: uniform.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: out.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 2,
                resource: normals.as_entire_binding(),
            },
        ],
    });
    let mut encoder = device.create_command_encoder(&Default::default());
    {
        let mut pass = encoder.begin_compute_pass(&Default::default());
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &pool_group, &[]);
        pass.set_bind_group(1, &group, &[]);
        pass.dispatch_workgroups(surface.width.div_ceil(8), surface.height.div_ceil(8), 1);
    }
    gpu.queue.submit([encoder.finish()]);
    // Read back through a staging buffer, as an engine would (no library readback helper).
    let read = |b: &wgpu::Buffer| -> Vec<[f32; 4]> {
        let staging = buffer(
            wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            texels * 16,
        );
        let mut encoder = device.create_command_encoder(&Default::default());
        encoder.copy_buffer_to_buffer(b, 0, &staging, 0, texels * 16);
        gpu.queue.submit([encoder.finish()]);
        let slice = staging.slice(..);
        slice.map_async(wgpu::MapMode::Read, |r| r.expect("map"));
        device
            .poll(wgpu::PollType::wait_indefinitely())
            .expect("poll");
        bytemuck::cast_slice(&slice.get_mapped_range().expect("mapped")).to_vec()
    };
    (read(&out), read(&normals))
}

/// Every texel's channels as the shader reads them are the world's, at every precision; a
/// bilinear read at a texel corner is the mean of the four texels around it; the snow depth and
/// the normal at a texel centre are the heights and their central differences.
#[test]
fn engine_module_reads_the_pool_as_the_world_does() {
    for precision in [Precision::Bits8, Precision::Bits16, Precision::Bits32] {
        let (world, id) = pressed_world(precision);
        let (depression, displaced) = world.read_channels(id).expect("channels");
        let layout = world.layout(id).unwrap();
        let (w, h) = (layout.width, layout.height);
        assert_eq!(
            (w % 2, h % 2),
            (1, 1),
            "odd sides exercise the 8-bit row padding"
        );
        let max = precision.channel_max() as f32;
        let cpu =
            |c: u32, r: u32| depression[(r.min(h - 1) * w + c.min(w - 1)) as usize] as f32 / max;
        assert!(
            depression.iter().any(|&d| d as f32 / max > 0.5),
            "{precision:?}: the sphere pressed the snow"
        );
        assert!(
            displaced.iter().any(|&d| d > 0),
            "{precision:?}: the sphere displaced snow (the second channel is read too)"
        );
        let (values, normals) = read_on_gpu(&world, id);
        let desc = world.surface(id).unwrap();
        let (tx, tz) = (desc.size.x / w as f32, desc.size.y / h as f32);
        for r in 0..h {
            for c in 0..w {
                let i = (r * w + c) as usize;
                let [dep, disp, corner, depth] = values[i];
                let at = format!("{precision:?} texel ({c}, {r})");
                assert_eq!(dep, cpu(c, r), "{at}");
                assert_eq!(disp, displaced[i] as f32 / max, "{at}");
                let mean = (cpu(c, r) + cpu(c + 1, r) + cpu(c, r + 1) + cpu(c + 1, r + 1)) / 4.0;
                assert!(
                    (corner - mean).abs() < 1e-5,
                    "{at}: corner {corner} against {mean}"
                );
                let left = desc.snow_depth * (1.0 - cpu(c, r));
                assert!(
                    (depth - left).abs() < 1e-5,
                    "{at}: depth {depth} against {left}"
                );
                // Central differences one texel apart (clamped at the edges like the shader).
                let height = |c: i64, r: i64| {
                    let c = c.clamp(0, w as i64 - 1) as u32;
                    let r = r.clamp(0, h as i64 - 1) as u32;
                    desc.snow_depth * (1.0 - cpu(c, r))
                };
                let (ci, ri) = (c as i64, r as i64);
                let dx = (height(ci + 1, ri) - height(ci - 1, ri)) / (2.0 * tx);
                let dz = (height(ci, ri + 1) - height(ci, ri - 1)) / (2.0 * tz);
                let n = glam::Vec3::new(-dx, 1.0, -dz).normalize();
                let got = glam::Vec3::from_slice(&normals[i][..3]);
                assert!((got - n).length() < 1e-4, "{at}: normal {got} against {n}");
            }
        }
    }
}

/// A handle the view does not hold is the world's error, not a panic or a zeroed surface.
#[test]
fn for_surface_of_a_removed_surface_is_stale() {
    let (mut world, id) = pressed_world(Precision::Bits16);
    assert!(SurfaceUniform::for_surface(&world.frame_view(), id).is_ok());
    world.remove_surface(id).expect("remove");
    assert!(matches!(
        SurfaceUniform::for_surface(&world.frame_view(), id),
        Err(SnowError::StaleHandle { .. })
    ));
}
