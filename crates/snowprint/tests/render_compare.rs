//! The snow material's GPU maths against their CPU references (`snowprint::reference::material`), on the
//! same inputs: the heightfield pass (Sobel normals, horizon AO, moon visibility) on a synthetic
//! heightmap (and on ground that is a plane, the moon turned by its slope), and the relief search,
//! POM search and RNM of `snow.wgsl` run in a compute harness on analytic heightfields (and on
//! snow over a sloped ground plane, the hit computed by hand).

mod common;

use glam::{Vec2, Vec3};
use snowprint::low_level::render::HeightfieldParams;
use snowprint::reference::material as cpu;
use wgpu::util::DeviceExt;

fn f16_to_f32(h: u16) -> f32 {
    let sign = if h & 0x8000 != 0 { -1.0 } else { 1.0 };
    let exp = ((h >> 10) & 0x1f) as i32;
    let frac = (h & 0x3ff) as f32;
    sign * match exp {
        0 => frac * 2f32.powi(-24),
        31 => f32::INFINITY,
        _ => (1.0 + frac / 1024.0) * 2f32.powi(exp - 15),
    }
}

fn read_buffer(buffer: &wgpu::Buffer) -> Vec<u8> {
    let gpu = common::gpu();
    buffer.slice(..).map_async(wgpu::MapMode::Read, |_| {});
    gpu.wait_idle().expect("gpu");
    let data = buffer
        .slice(..)
        .get_mapped_range()
        .expect("mapped")
        .to_vec();
    buffer.unmap();
    data
}

/// Depressions of a synthetic 64 x 48 heightmap: two dents, a trench and a ramp.
fn synthetic(width: u32, height: u32) -> Vec<f32> {
    let mut d = vec![0.0f32; (width * height) as usize];
    for r in 0..height {
        for c in 0..width {
            let (x, y) = (c as f32, r as f32);
            let mut v: f32 = 0.0;
            for (cx, cy, rad, depth) in [(16.0, 14.0, 5.0, 1.0), (44.0, 30.0, 8.0, 0.6)] {
                let q = ((x - cx).powi(2) + (y - cy).powi(2)).sqrt() / rad;
                if q < 1.0 {
                    v = v.max(depth * (1.0 - q * q));
                }
            }
            if (y - 38.0).abs() < 2.5 && x > 6.0 && x < 36.0 {
                v = v.max(0.9);
            }
            v = v.max((x - 54.0).max(0.0) * 0.05);
            d[(r * width + c) as usize] = v.min(1.0);
        }
    }
    d
}

#[test]
fn heightfield_pass_matches_its_cpu_reference() {
    heightfield_case(None);
}

/// On ground that is a plane (rising 0.3 m a metre along x, falling 0.2 along z) the pass turns the
/// moon by the rotation that takes the plane's normal to up before marching over the prints: the
/// CPU reference marches with the moon turned by `Quat::from_rotation_arc` (computed here, not by
/// the shader's formula). Texels on the border, where the pass's differences are one-sided, are
/// left out.
#[test]
fn heightfield_pass_turns_the_moon_by_the_slope_of_the_ground() {
    heightfield_case(Some(Vec2::new(0.3, -0.2)));
}

fn heightfield_case(slope: Option<Vec2>) {
    let gpu = common::gpu();
    let dev = &gpu.device;
    let (w, h) = (64u32, 48u32);
    let depth = 0.2;
    let texel = Vec2::new(0.04, 0.05);
    let dep = synthetic(w, h);
    // Depression in the low 16 bits; a displaced-snow pattern in the high 16 (the pass copies it
    // into the light texture's .g for the banks).
    let units: Vec<u32> = dep
        .iter()
        .enumerate()
        .map(|(i, &v)| {
            let displaced = ((i as u32).wrapping_mul(2654435761) >> 16) & 0xffff;
            (v * 65535.0).round() as u32 | displaced << 16
        })
        .collect();
    // The heightmap sits at an offset in the pool, as a world's slot does.
    let offset = 100u32;
    let mut pool = vec![0u32; offset as usize];
    pool.extend(&units);
    let pool = dev.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("pool"),
        contents: bytemuck::cast_slice(&pool),
        usage: wgpu::BufferUsages::STORAGE,
    });
    let light = Vec3::new(-0.8, 0.42, 0.35).normalize();
    let params = HeightfieldParams {
        heights: offset,
        width: w,
        height: h,
        bits: 16,
        snow_depth: depth,
        texel_x: texel.x,
        texel_z: texel.y,
        // The field starts 3 texels into the ground buffer, as a world's second surface might.
        ground: slope.map_or(snowprint::low_level::ground::NO_GROUND, |_| 3),
        wrap: 0,
        // The frame's second surface: classify shaded it, and not the first (`state` below).
        slot: 1,
        _pad: [0; 2],
        light: [light.x, light.y, light.z, 0.0],
        // Nothing beside it: every side's texels clamp to the edge.
        sides: Default::default(),
    };
    let uniform = |p: &HeightfieldParams| {
        dev.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("params"),
            contents: bytemuck::bytes_of(p),
            usage: wgpu::BufferUsages::UNIFORM,
        })
    };
    let unshaded = uniform(&HeightfieldParams { slot: 0, ..params });
    let params = uniform(&params);
    let words = snowprint::wgsl::consts::STATE_WORDS as usize;
    let mut state = vec![0u32; 2 * words];
    state[words + snowprint::wgsl::consts::STATE_SHADED as usize] = 1;
    let state = dev.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("state"),
        contents: bytemuck::cast_slice(&state),
        usage: wgpu::BufferUsages::STORAGE,
    });
    // The textures hold a border around the heightmap's texels.
    let b = snowprint::wgsl::consts::HEIGHTFIELD_BORDER as u32;
    let (tw, th) = (w + 2 * b, h + 2 * b);
    let texture = || {
        dev.create_texture(&wgpu::TextureDescriptor {
            label: None,
            size: wgpu::Extent3d {
                width: tw,
                height: th,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba16Float,
            usage: wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        })
    };
    let (shape, lit) = (texture(), texture());
    let (bare_shape, bare_lit) = (texture(), texture());
    // `[base, bare]` per texel: the plane at the texel centres (none bare), after 3 texels of
    // another field; a zero texel on flat ground (never read).
    let mut columns = vec![[9.0f32, 0.0]; 3];
    if let Some(g) = slope {
        for r in 0..h {
            for c in 0..w {
                columns.push([g.x * c as f32 * texel.x + g.y * r as f32 * texel.y, 0.0]);
            }
        }
    }
    let ground = dev.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("ground"),
        contents: bytemuck::cast_slice(&columns),
        usage: wgpu::BufferUsages::STORAGE,
    });
    let module = dev.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("heightfield.wgsl"),
        source: wgpu::ShaderSource::Wgsl(snowprint::wgsl::HEIGHTFIELD.source.into()),
    });
    let pipeline = dev.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: None,
        layout: None,
        module: &module,
        entry_point: Some("heightfield"),
        compilation_options: Default::default(),
        cache: None,
    });
    let bind = |params: &wgpu::Buffer, shape: &wgpu::Texture, lit: &wgpu::Texture| {
        let view = |t: &wgpu::Texture| t.create_view(&Default::default());
        let (shape, lit) = (view(shape), view(lit));
        let resources = [
            pool.as_entire_binding(),
            params.as_entire_binding(),
            wgpu::BindingResource::TextureView(&shape),
            wgpu::BindingResource::TextureView(&lit),
            ground.as_entire_binding(),
            state.as_entire_binding(),
        ];
        let entries: Vec<_> = (0u32..)
            .zip(resources)
            .map(|(binding, resource)| wgpu::BindGroupEntry { binding, resource })
            .collect();
        dev.create_bind_group(&wgpu::BindGroupDescriptor {
            label: None,
            layout: &pipeline.get_bind_group_layout(0),
            entries: &entries,
        })
    };
    let bg = bind(&params, &shape, &lit);
    let bare_bg = bind(&unshaded, &bare_shape, &bare_lit);
    let row = (tw * 8).div_ceil(256) * 256;
    let readback = |t: &wgpu::Texture, enc: &mut wgpu::CommandEncoder| {
        let b = dev.create_buffer(&wgpu::BufferDescriptor {
            label: None,
            size: (row * th) as u64,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        enc.copy_texture_to_buffer(
            t.as_image_copy(),
            wgpu::TexelCopyBufferInfo {
                buffer: &b,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(row),
                    rows_per_image: Some(th),
                },
            },
            wgpu::Extent3d {
                width: tw,
                height: th,
                depth_or_array_layers: 1,
            },
        );
        b
    };
    let mut enc = dev.create_command_encoder(&Default::default());
    {
        let mut pass = enc.begin_compute_pass(&Default::default());
        pass.set_pipeline(&pipeline);
        for bg in [&bg, &bare_bg] {
            pass.set_bind_group(0, bg, &[]);
            pass.dispatch_workgroups(tw.div_ceil(8), th.div_ceil(8), 1);
        }
    }
    let (shape_rb, lit_rb) = (readback(&shape, &mut enc), readback(&lit, &mut enc));
    let bare_rb = [
        readback(&bare_shape, &mut enc),
        readback(&bare_lit, &mut enc),
    ];
    gpu.queue.submit([enc.finish()]);
    let (shape_bytes, lit_bytes) = (read_buffer(&shape_rb), read_buffer(&lit_rb));
    // A surface classify left unshaded (the first's state) is dispatched all the same, and leaves
    // its textures as they were.
    for rb in &bare_rb {
        assert!(
            read_buffer(rb).iter().all(|&b| b == 0),
            "an unshaded surface was written"
        );
    }
    // Texel (c, r) of the heightmap, which may lie in the border.
    let texel_at = |bytes: &[u8], c: i32, r: i32| -> [f32; 4] {
        let (c, r) = ((c + b as i32) as u32, (r + b as i32) as u32);
        let o = (r * row + c * 8) as usize;
        let v: &[u16] = bytemuck::cast_slice(&bytes[o..o + 8]);
        [
            f16_to_f32(v[0]),
            f16_to_f32(v[1]),
            f16_to_f32(v[2]),
            f16_to_f32(v[3]),
        ]
    };

    // The same inputs as the GPU read them: depression from the quantized units, clamped at the
    // edges; nearest texel for the AO's offsets, bilinear for the light march.
    let d = |c: i32, r: i32| {
        let (c, r) = (c.clamp(0, w as i32 - 1), r.clamp(0, h as i32 - 1));
        (units[(r as u32 * w + c as u32) as usize] & 0xffff) as f32 / 65535.0
    };
    let mut worst = [0.0f32; 5];
    // The moon as the prints on the plane see it, and how many texels would be lit otherwise had
    // the pass not turned it (the case must see the turn).
    let turned = slope.map_or(light, |g| {
        glam::Quat::from_rotation_arc(Vec3::new(-g.x, 1.0, -g.y).normalize(), Vec3::Y) * light
    });
    let mut unturned_differs = 0;
    let inner = |c: i32, r: i32| c > 0 && r > 0 && c < w as i32 - 1 && r < h as i32 - 1;
    for r in 0..h as i32 {
        for c in 0..w as i32 {
            if slope.is_some() && !inner(c, r) {
                continue;
            }
            let gpu_texel = texel_at(&shape_bytes, c, r);
            let n = cpu::sobel_normal(d, c, r, depth, texel);
            let ao = cpu::horizon_ao(|dx, dz| {
                let (oc, orow) = ((dx / texel.x).round() as i32, (dz / texel.y).round() as i32);
                depth * (1.0 - d(c + oc, r + orow))
            });
            let march = |l: Vec3| {
                cpu::light_visibility(
                    |x, z| {
                        let (fx, fz) = (x / texel.x, z / texel.y);
                        let (ix, iz) = (fx.floor(), fz.floor());
                        let (wx, wz) = (fx - ix, fz - iz);
                        let (x0, z0) = (c + ix as i32, r + iz as i32);
                        let a = d(x0, z0) * (1.0 - wx) + d(x0 + 1, z0) * wx;
                        let b = d(x0, z0 + 1) * (1.0 - wx) + d(x0 + 1, z0 + 1) * wx;
                        depth * (1.0 - (a * (1.0 - wz) + b * wz))
                    },
                    0.0,
                    0.0,
                    l,
                    depth,
                    texel.x.max(texel.y),
                )
            };
            let vis = march(turned);
            let gpu_light = texel_at(&lit_bytes, c, r);
            let gpu_vis = gpu_light[0];
            if (march(light) - gpu_vis).abs() > 0.05 {
                unturned_differs += 1;
            }
            let displaced = cpu::displaced_fraction(
                units[(r as u32 * w + c as u32) as usize] >> 16,
                snowprint::Precision::Bits16,
            );
            let errors = [
                (gpu_texel[0] - cpu::smoothed_depression(d, c, r)).abs(),
                (gpu_texel[1] - n.x).abs().max((gpu_texel[2] - n.z).abs()),
                (gpu_texel[3] - ao).abs(),
                (gpu_vis - vis).abs(),
                // Half floats: relative error 2^-11 of values up to 1.
                (gpu_light[1] - displaced).abs(),
            ];
            for k in 0..5 {
                worst[k] = worst[k].max(errors[k]);
            }
        }
    }
    // With no surface beside it, each texel of the border repeats the edge texel nearest it, bit
    // for bit, so that filtering across the edge is clamping at it.
    let (bi, wi, hi) = (b as i32, w as i32, h as i32);
    for r in -bi..hi + bi {
        for c in -bi..wi + bi {
            if c >= 0 && r >= 0 && c < wi && r < hi {
                continue;
            }
            let (ec, er) = (c.clamp(0, wi - 1), r.clamp(0, hi - 1));
            for bytes in [&shape_bytes, &lit_bytes] {
                assert_eq!(
                    texel_at(bytes, c, r),
                    texel_at(bytes, ec, er),
                    "border texel ({c}, {r}) against edge texel ({ec}, {er})"
                );
            }
        }
    }
    // Half-float storage keeps about three decimal digits: 1e-3 relative, within 2e-3 here.
    assert!(
        worst.iter().all(|&e| e < 2e-3),
        "worst |GPU - CPU| (depression, normal, AO, light, displaced): {worst:?}"
    );
    if slope.is_some() {
        eprintln!("{unturned_differs} texels would be lit otherwise without the turn");
        assert!(
            unturned_differs > 50,
            "only {unturned_differs} texels see the moon turned by the slope"
        );
    }
}

/// A compute harness around snow.wgsl: analytic heightfields as the contract, every search and
/// RNM on inputs from a buffer.
const HARNESS: &str = r#"
struct Case {
    origin: vec4<f32>,   // xyz, w: which heightfield (0 plane, 1 dent)
    dir: vec4<f32>,
}
@group(0) @binding(0) var<storage, read> cases: array<Case>;
@group(0) @binding(1) var<storage, read_write> results: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read> normals: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read_write> blended: array<vec4<f32>>;

var<private> field: u32;
const DEPTH: f32 = 0.3;
const GROUND_SLOPE: f32 = 0.5;

fn analytic_height(xz: vec2<f32>) -> f32 {
    if field == 2u {
        return DEPTH;
    }
    if field == 0u {
        return 0.15 + 0.04 * xz.x;
    }
    let c = vec3<f32>(0.3, DEPTH + 0.25 - 0.2, -0.2);
    let r2 = dot(xz - c.xz, xz - c.xz);
    if r2 >= 0.0625 {
        return DEPTH;
    }
    return min(DEPTH, c.y - sqrt(0.0625 - r2));
}

fn snow_depression(s: SnowSurface, uv: vec2<f32>) -> f32 {
    let xz = uv * 2.0 * s.half_size - s.half_size;
    return 1.0 - analytic_height(xz) / s.snow_depth;
}
fn snow_heightfield(s: SnowSurface, uv: vec2<f32>) -> vec4<f32> {
    return vec4<f32>(snow_depression(s, uv), 0.0, 0.0, 1.0);
}
fn snow_light_visibility(s: SnowSurface, uv: vec2<f32>) -> f32 {
    return 1.0;
}
// Field 2: untouched snow on ground that is a plane rising along x (GROUND_SLOPE metres a metre).
fn snow_ground_base(s: SnowSurface, uv: vec2<f32>) -> f32 {
    if field != 2u {
        return 0.0;
    }
    let xz = uv * 2.0 * s.half_size - s.half_size;
    return GROUND_SLOPE * xz.x;
}

@compute @workgroup_size(64)
fn search(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= arrayLength(&cases) {
        return;
    }
    let c = cases[id.x];
    field = u32(c.origin.w);
    var s: SnowSurface;
    s.half_size = vec2<f32>(2.0, 1.5);
    s.snow_depth = DEPTH;
    s.texel = 0.04;
    s.search = vec4<f32>(0.5, 4.0, 12.0, 5.0);
    // Flat ground, but for field 2: its plane spans -1 to 1 m over the 4 m of x.
    s.terrain = 0xffffffffu;
    s.terrain_low = 0.0;
    s.terrain_top = DEPTH;
    if field == 2u {
        s.terrain = 0u;
        s.terrain_low = -2.0 * GROUND_SLOPE;
        s.terrain_top = 2.0 * GROUND_SLOPE + DEPTH;
    }
    let o = c.origin.xyz;
    let d = c.dir.xyz;
    let exit = snow_slab_exit(s, o, d);
    let taps = snow_linear_taps(s, d, exit.x);
    let relief = snow_relief_search(s, o, d, exit.x, taps, 5u);
    let pom = snow_pom_search(s, o, d, exit.x, taps, 3u);
    results[2u * id.x] = vec4<f32>(relief.x, relief.y, pom.x, pom.y);
    results[2u * id.x + 1u] = vec4<f32>(exit.x, exit.y, f32(taps), 0.0);
}

@compute @workgroup_size(64)
fn blend(@builtin(global_invocation_id) id: vec3<u32>) {
    if 2u * id.x + 1u >= arrayLength(&normals) {
        return;
    }
    blended[id.x] = vec4<f32>(snow_rnm(normals[2u * id.x].xyz, normals[2u * id.x + 1u].xyz), 0.0);
}
"#;

/// A ray through untouched snow 0.3 m deep on ground that is the plane `y = 0.5 x` (27 degrees):
/// the snow top is `0.5 x + 0.3`, so the ray `o + t d` meets it (within the inside test's slack
/// `SNOW_EPSILON`) at `t = (0.5 o.x + 0.3 + 1e-4 - o.y) / (d.y - 0.5 d.x)`, computed by hand. The
/// slab's floor is the plane's lowest point (-1 m), its top the highest snow top (1.3 m). Relief
/// mapping lands within its last bracket of it, POM (a secant on a plane is exact) within 1e-4.
/// Returns whether the ray met the snow inside the slab (and was checked).
fn on_a_sloped_ground(i: usize, ray: &cpu::SlabRay, g: &[f32], half: Vec2, depth: f32) -> bool {
    let (o, d) = (ray.origin, ray.dir);
    let t = (0.5 * o.x + depth + 1e-4 - o.y) / (d.y - 0.5 * d.x);
    let p = o + d * t;
    let inside = p.x.abs() <= half.x && p.z.abs() <= half.y;
    // The slab's exit: the floor at -1 m or a side.
    let floor = (o.y + 1.0) / -d.y;
    let side = |o: f32, d: f32, h: f32| {
        if d == 0.0 {
            f32::MAX
        } else {
            (h * d.signum() - o) / d
        }
    };
    let t_max = floor
        .min(side(o.x, d.x, half.x))
        .min(side(o.z, d.z, half.y));
    assert!(
        (g[4] - t_max).abs() < 1e-4,
        "case {i}: exit {} vs {t_max}",
        g[4]
    );
    if !inside {
        return false;
    }
    let bracket = t_max / g[6] / 32.0 + 1e-4;
    assert!(
        g[1] == 1.0 && (g[0] - t).abs() <= bracket,
        "case {i}: relief on the slope {} vs {t} by hand",
        g[0]
    );
    assert!(
        g[3] == 1.0 && (g[2] - t).abs() <= 1e-4,
        "case {i}: POM on the slope {} vs {t} by hand",
        g[2]
    );
    true
}

#[test]
fn snow_wgsl_searches_and_rnm_match_their_cpu_references() {
    let gpu = common::gpu();
    let dev = &gpu.device;
    let half = Vec2::new(2.0, 1.5);
    let depth = 0.3f32;
    // Rays entering the top over the plane and over the dent, in many directions.
    let mut cases: Vec<[f32; 8]> = Vec::new();
    for field in 0..3 {
        for i in 0..48 {
            let a = std::f32::consts::TAU * i as f32 / 48.0;
            let down = 0.25 + 1.5 * ((i * 7) % 11) as f32 / 11.0;
            let dir = Vec3::new(a.cos(), -down, a.sin()).normalize();
            let origin = if field == 0 {
                Vec3::new(-1.0 + 0.03 * i as f32, depth, 0.2)
            } else if field == 2 {
                // On the top face of the sloped slab (y = 1.3).
                Vec3::new(-1.0 + 0.03 * i as f32, 1.0 + depth, 0.2)
            } else {
                Vec3::new(0.25 + 0.002 * i as f32, depth, -0.15)
            };
            cases.push([
                origin.x,
                origin.y,
                origin.z,
                field as f32,
                dir.x,
                dir.y,
                dir.z,
                0.0,
            ]);
        }
    }
    let normals: Vec<Vec3> = (0..40)
        .map(|i| {
            let phi = 0.7 * i as f32;
            let theta = 1.2 * ((i * 5) % 9) as f32 / 9.0;
            Vec3::new(
                theta.sin() * phi.cos(),
                theta.sin() * phi.sin(),
                theta.cos(),
            )
        })
        .collect();
    let pairs: Vec<[f32; 4]> = normals
        .iter()
        .zip(normals.iter().rev())
        .flat_map(|(a, b)| [[a.x, a.y, a.z, 0.0], [b.x, b.y, b.z, 0.0]])
        .collect();

    let source = format!("{}\n{HARNESS}", snowprint::wgsl::files::SNOW);
    let module = dev.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("snow.wgsl harness"),
        source: wgpu::ShaderSource::Wgsl(source.into()),
    });
    let storage = |contents: &[u8], rw: bool| {
        dev.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: None,
            contents,
            usage: wgpu::BufferUsages::STORAGE
                | if rw {
                    wgpu::BufferUsages::COPY_SRC
                } else {
                    wgpu::BufferUsages::empty()
                },
        })
    };
    let case_buf = storage(bytemuck::cast_slice(&cases), false);
    let result_buf = storage(&vec![0u8; cases.len() * 32], true);
    let normal_buf = storage(bytemuck::cast_slice(&pairs), false);
    let blended_buf = storage(&vec![0u8; normals.len() * 16], true);
    let layout = dev.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: None,
        entries: &(0..4)
            .map(|b| wgpu::BindGroupLayoutEntry {
                binding: b,
                visibility: wgpu::ShaderStages::COMPUTE,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Storage {
                        read_only: b % 2 == 0,
                    },
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                count: None,
            })
            .collect::<Vec<_>>(),
    });
    let pl = dev.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: None,
        bind_group_layouts: &[Some(&layout)],
        immediate_size: 0,
    });
    let pipeline = |entry: &str| {
        dev.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: None,
            layout: Some(&pl),
            module: &module,
            entry_point: Some(entry),
            compilation_options: Default::default(),
            cache: None,
        })
    };
    let bg = dev.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout: &layout,
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: case_buf.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: result_buf.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 2,
                resource: normal_buf.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 3,
                resource: blended_buf.as_entire_binding(),
            },
        ],
    });
    let copy = |src: &wgpu::Buffer, enc: &mut wgpu::CommandEncoder| {
        let b = dev.create_buffer(&wgpu::BufferDescriptor {
            label: None,
            size: src.size(),
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        enc.copy_buffer_to_buffer(src, 0, &b, 0, src.size());
        b
    };
    let mut enc = dev.create_command_encoder(&Default::default());
    {
        let mut pass = enc.begin_compute_pass(&Default::default());
        pass.set_bind_group(0, &bg, &[]);
        pass.set_pipeline(&pipeline("search"));
        pass.dispatch_workgroups((cases.len() as u32).div_ceil(64), 1, 1);
        pass.set_pipeline(&pipeline("blend"));
        pass.dispatch_workgroups((normals.len() as u32).div_ceil(64), 1, 1);
    }
    let (results_rb, blended_rb) = (copy(&result_buf, &mut enc), copy(&blended_buf, &mut enc));
    gpu.queue.submit([enc.finish()]);
    let results: Vec<f32> = bytemuck::cast_slice(&read_buffer(&results_rb)).to_vec();
    let blended: Vec<f32> = bytemuck::cast_slice(&read_buffer(&blended_rb)).to_vec();

    let mut sloped_hits = 0;
    for (i, c) in cases.iter().enumerate() {
        let ray = cpu::SlabRay {
            origin: Vec3::new(c[0], c[1], c[2]),
            dir: Vec3::new(c[4], c[5], c[6]),
        };
        let g = &results[8 * i..8 * i + 8];
        if c[3] == 2.0 {
            sloped_hits += usize::from(on_a_sloped_ground(i, &ray, g, half, depth));
            continue;
        }
        let plane = c[3] == 0.0;
        let height = |p: Vec2| {
            if plane {
                0.15 + 0.04 * p.x
            } else {
                let r2 = (p - Vec2::new(0.3, -0.2)).length_squared();
                if r2 >= 0.0625 {
                    depth
                } else {
                    depth.min(depth + 0.05 - (0.0625 - r2).sqrt())
                }
            }
        };
        let (t_max, ground) = cpu::slab_exit(&ray, half, depth);
        let taps = cpu::linear_taps(ray.dir, t_max, 0.04, 0.5, 4.0, 12.0);
        assert!(
            (g[4] - t_max).abs() < 1e-4 && (g[5] == 1.0) == ground,
            "case {i}: exit {g:?} vs {t_max} {ground}"
        );
        assert_eq!(g[6] as u32, taps, "case {i}: taps");
        // The two sides round differently (the GPU goes through UVs), so a hit may land on the
        // other side of one tiny bracket: within the bracket's width.
        let bracket = t_max / taps as f32 / 32.0 + 1e-4;
        match cpu::relief_search(height, &ray, t_max, taps, 5) {
            Some(t) => assert!(
                g[1] == 1.0 && (g[0] - t).abs() <= bracket,
                "case {i}: relief {} vs {t}",
                g[0]
            ),
            None => assert_eq!(g[1], 0.0, "case {i}: relief found a hit the CPU did not"),
        }
        match cpu::pom_search(height, &ray, t_max, taps, 3) {
            Some(t) => assert!(
                g[3] == 1.0 && (g[2] - t).abs() <= t_max / taps as f32 * 0.02 + 1e-4,
                "case {i}: pom {} vs {t}",
                g[2]
            ),
            None => assert_eq!(g[3], 0.0, "case {i}: pom found a hit the CPU did not"),
        }
    }
    eprintln!("sloped ground: {sloped_hits} of 48 rays met the snow and were checked by hand");
    assert!(
        sloped_hits >= 24,
        "only {sloped_hits} rays met the sloped snow"
    );
    for (k, (a, b)) in normals.iter().zip(normals.iter().rev()).enumerate() {
        let want = cpu::rnm(*a, *b);
        let got = Vec3::new(blended[4 * k], blended[4 * k + 1], blended[4 * k + 2]);
        assert!(
            (got - want).abs().max_element() < 1e-5,
            "rnm {a} {b}: {got} vs {want}"
        );
    }
}
