//! Your own renderer: draws a snow surface with a pipeline of its own, whose shader reads the
//! world's heightmap pool through `snowprint::wgsl::engine_module` (prefixed names, the pool at a
//! binding this program chooses) and finds the surface's texels with a `SurfaceUniform` filled by
//! `SurfaceUniform::for_surface`.
//!
//! A sphere is pressed into a 4 m x 3 m roof; the roof is drawn top-down (orthographic, three
//! pixels a texel) into two targets: a picture (snow lit by a low light through
//! `snowprint_normal`, shaded by the snow left, `snowprint_snow_depth_at`) and a data target whose
//! red channel is the fraction of snow left. Both are read back and checked against
//! `SnowWorld::read_heightmap` at texels in and around the print; the program exits non-zero with
//! one sentence when they disagree.
//!
//! ```text
//! cargo run --release -p snowprint --example custom_renderer [picture.png]
//! ```

use std::process::ExitCode;

use glam::{Mat4, Vec3, Vec4};
use snowprint::wgsl::{ImportOptions, engine_module};
use snowprint::{
    Deformer, GpuContext, GpuOptions, Pose, Shape, SnowWorld, SurfaceDesc, SurfaceUniform,
    WorldConfig,
};

/// Pixels a texel along each side: odd, so that a texel's centre is a pixel's centre.
const SCALE: u32 = 3;
const FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;

/// The program's own shader: the engine module supplies the pool and `snowprint_*`; the pool is
/// put at group 0, binding 1, after this shader's own uniforms.
const SHADER: &str = r#"
struct Camera {
    view_proj: mat4x4<f32>,
    light: vec4<f32>,   // xyz: unit direction towards the light, world
}
@group(0) @binding(0) var<uniform> camera: Camera;
@group(0) @binding(2) var<uniform> roof: snowprint_Surface;

struct Varying {
    @builtin(position) clip: vec4<f32>,
    @location(0) local_xz: vec2<f32>,
}

// The top face of the surface's snow, two triangles, in its local frame.
@vertex
fn vs(@builtin(vertex_index) i: u32) -> Varying {
    let corner = array<vec2<f32>, 6>(
        vec2<f32>(-1.0, -1.0), vec2<f32>(1.0, -1.0), vec2<f32>(1.0, 1.0),
        vec2<f32>(-1.0, -1.0), vec2<f32>(1.0, 1.0), vec2<f32>(-1.0, 1.0),
    )[i];
    let local = vec3<f32>(corner.x * roof.half_size.x, roof.snow_depth, corner.y * roof.half_size.y);
    var out: Varying;
    out.clip = camera.view_proj * vec4<f32>(snowprint_to_world(roof, local), 1.0);
    out.local_xz = local.xz;
    return out;
}

struct Targets {
    @location(0) picture: vec4<f32>,
    @location(1) data: vec4<f32>,
}

@fragment
fn fs(in: Varying) -> Targets {
    let uv = snowprint_uv(roof, in.local_xz);
    let left = snowprint_snow_depth_at(roof, uv) / roof.snow_depth;
    let n_local = snowprint_normal(roof, uv);
    let n = normalize((roof.local_to_world * vec4<f32>(n_local, 0.0)).xyz);
    let lambert = max(dot(n, camera.light.xyz), 0.0);
    let snow = vec3<f32>(0.92, 0.95, 1.0) * (0.25 + 0.75 * lambert);
    let ground = vec3<f32>(0.20, 0.12, 0.08);
    var out: Targets;
    out.picture = vec4<f32>(mix(ground, snow, 0.35 + 0.65 * left), 1.0);
    out.data = vec4<f32>(left, 0.0, 0.0, 1.0);
    return out;
}
"#;

fn main() -> ExitCode {
    match run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(sentence) => {
            eprintln!("custom_renderer: {sentence}");
            ExitCode::FAILURE
        }
    }
}

fn run() -> Result<(), String> {
    let gpu = GpuContext::new(&GpuOptions::default()).map_err(|e| e.to_string())?;
    let mut world = SnowWorld::new(&gpu, WorldConfig::default()).map_err(|e| e.to_string())?;
    let desc = SurfaceDesc::new("roof", [2.0, 5.0, -1.0], [4.0, 3.0], 0.3);
    let roof = world.add_surface(desc).map_err(|e| e.to_string())?;
    // A ball whose bottom is 5 cm above the roof: it leaves a 25 cm deep print.
    let ball = Deformer::new(Shape::Sphere { radius: 0.4 }, Pose::at([2.6, 5.45, -0.7]));
    world.step(1.0 / 60.0, &[ball]).map_err(|e| e.to_string())?;
    let map = world.read_heightmap(roof).map_err(|e| e.to_string())?;

    let view = world.frame_view();
    let surface = SurfaceUniform::for_surface(&view, roof).map_err(|e| e.to_string())?;
    let (width, height) = (surface.width * SCALE, surface.height * SCALE);
    let desc = view.surface(roof).map_err(|e| e.to_string())?.desc;
    let view_proj = top_down(desc.center, desc.size.x, desc.size.y);
    let image = draw(&gpu, view.pool_buffer, &surface, view_proj, width, height)?;

    // `cargo test` runs this example as a test (no harness): flags it passes on are not paths.
    if let Some(path) = std::env::args().nth(1).filter(|a| !a.starts_with('-')) {
        write_png(&path, width, height, &image.picture)?;
        println!("custom_renderer: wrote {path}");
    }
    check(&map, desc, view_proj, &image, width, height)
}

/// An orthographic camera straight down on a `sx` x `sz` rectangle about `center`, the image's
/// right along world +x and its top towards world -z.
fn top_down(center: Vec3, sx: f32, sz: f32) -> Mat4 {
    let eye = center + Vec3::new(0.0, 10.0, 0.0);
    let view = glam::camera::rh::view::look_at_mat4(eye, center, Vec3::NEG_Z);
    let proj = glam::camera::rh::proj::directx::orthographic(
        -sx / 2.0,
        sx / 2.0,
        -sz / 2.0,
        sz / 2.0,
        0.1,
        20.0,
    );
    proj * view
}

/// The two targets' pixels, RGBA8, rows top to bottom.
struct Image {
    picture: Vec<u8>,
    data: Vec<u8>,
}

fn draw(
    gpu: &GpuContext,
    pool: &wgpu::Buffer,
    surface: &SurfaceUniform,
    view_proj: Mat4,
    width: u32,
    height: u32,
) -> Result<Image, String> {
    let device = &gpu.device;
    let source = format!(
        "{}\n{SHADER}",
        engine_module(&ImportOptions {
            group: 0,
            pool_binding: 1,
        })
    );
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("custom renderer"),
        source: wgpu::ShaderSource::Wgsl(source.into()),
    });
    let uniform = |label, bytes: &[u8]| {
        let buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: bytes.len() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        gpu.queue.write_buffer(&buffer, 0, bytes);
        buffer
    };
    let light = Vec3::new(-0.8, 0.5, -0.3).normalize();
    let mut camera = view_proj.to_cols_array().to_vec();
    camera.extend_from_slice(&light.extend(0.0).to_array());
    let camera = uniform("camera", bytemuck::cast_slice(&camera));
    let roof = uniform("roof", bytemuck::bytes_of(surface));

    let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("custom renderer"),
        layout: None,
        vertex: wgpu::VertexState {
            module: &module,
            entry_point: Some("vs"),
            compilation_options: Default::default(),
            buffers: &[],
        },
        fragment: Some(wgpu::FragmentState {
            module: &module,
            entry_point: Some("fs"),
            compilation_options: Default::default(),
            targets: &[Some(FORMAT.into()), Some(FORMAT.into())],
        }),
        primitive: wgpu::PrimitiveState::default(),
        depth_stencil: None,
        multisample: wgpu::MultisampleState::default(),
        multiview_mask: None,
        cache: None,
    });
    let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("custom renderer"),
        layout: &pipeline.get_bind_group_layout(0),
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: camera.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: pool.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 2,
                resource: roof.as_entire_binding(),
            },
        ],
    });
    let target = |label| {
        device.create_texture(&wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        })
    };
    let targets = [target("picture"), target("data")];
    let views: Vec<_> = targets
        .iter()
        .map(|t| t.create_view(&Default::default()))
        .collect();
    let mut encoder = device.create_command_encoder(&Default::default());
    {
        let attachments: Vec<_> = views
            .iter()
            .map(|view| {
                Some(wgpu::RenderPassColorAttachment {
                    view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                        store: wgpu::StoreOp::Store,
                    },
                })
            })
            .collect();
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("custom renderer"),
            color_attachments: &attachments,
            ..Default::default()
        });
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &bind_group, &[]);
        pass.draw(0..6, 0..1);
    }
    read_back(gpu, encoder, &targets, width, height)
}

/// Copy both targets to the CPU after `encoder`'s commands (waits for the GPU).
fn read_back(
    gpu: &GpuContext,
    mut encoder: wgpu::CommandEncoder,
    targets: &[wgpu::Texture],
    width: u32,
    height: u32,
) -> Result<Image, String> {
    let device = &gpu.device;
    // Rows of a texture copy are padded to 256 bytes.
    let row = (width * 4).div_ceil(256) * 256;
    let staging = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("custom renderer readback"),
        size: 2 * u64::from(row) * u64::from(height),
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    for (i, texture) in targets.iter().enumerate() {
        encoder.copy_texture_to_buffer(
            texture.as_image_copy(),
            wgpu::TexelCopyBufferInfo {
                buffer: &staging,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: i as u64 * u64::from(row) * u64::from(height),
                    bytes_per_row: Some(row),
                    rows_per_image: Some(height),
                },
            },
            texture.size(),
        );
    }
    gpu.queue.submit([encoder.finish()]);
    let slice = staging.slice(..);
    let (tx, rx) = std::sync::mpsc::channel();
    slice.map_async(wgpu::MapMode::Read, move |r| {
        let _ = tx.send(r);
    });
    device
        .poll(wgpu::PollType::wait_indefinitely())
        .map_err(|e| format!("the GPU did not finish drawing ({e})"))?;
    rx.recv()
        .map_err(|e| e.to_string())?
        .map_err(|e| format!("the image could not be read back ({e})"))?;
    let bytes = slice
        .get_mapped_range()
        .map_err(|e| format!("the image could not be read back ({e:?})"))?
        .to_vec();
    let unpad = |plane: usize| -> Vec<u8> {
        let start = plane * (row * height) as usize;
        (0..height as usize)
            .flat_map(|y| {
                let at = start + y * row as usize;
                bytes[at..at + width as usize * 4].iter().copied()
            })
            .collect()
    };
    Ok(Image {
        picture: unpad(0),
        data: unpad(1),
    })
}

/// The pixel that shows the centre of texel (column, row): its world position, projected.
fn pixel_of(
    map: &snowprint::Heightmap,
    local_to_world: &Mat4,
    view_proj: Mat4,
    size: (f32, f32),
    texel: (u32, u32),
    image: (u32, u32),
) -> (u32, u32) {
    let local = Vec3::new(
        ((texel.0 as f32 + 0.5) / map.width as f32 - 0.5) * size.0,
        0.0,
        ((texel.1 as f32 + 0.5) / map.height as f32 - 0.5) * size.1,
    );
    let clip = view_proj * local_to_world.mul_vec4(local.extend(1.0));
    let ndc = Vec4::new(clip.x / clip.w, clip.y / clip.w, 0.0, 0.0);
    (
        ((ndc.x + 1.0) * 0.5 * image.0 as f32) as u32,
        ((1.0 - ndc.y) * 0.5 * image.1 as f32) as u32,
    )
}

/// The data target shows the snow that `read_heightmap` says is left, and the picture is darker in
/// the print than on untouched snow.
fn check(
    map: &snowprint::Heightmap,
    desc: &SurfaceDesc,
    view_proj: Mat4,
    image: &Image,
    width: u32,
    height: u32,
) -> Result<(), String> {
    let (deepest, _) = (0..map.depression.len())
        .map(|i| (i, map.depression[i]))
        .max_by_key(|&(_, d)| d)
        .ok_or("the heightmap is empty")?;
    let deepest = (deepest as u32 % map.width, deepest as u32 / map.width);
    if map.fraction(deepest.0, deepest.1) < 0.5 {
        return Err(format!(
            "the ball pressed only {:.2} of the snow depth at its deepest texel",
            map.fraction(deepest.0, deepest.1)
        ));
    }
    let sides = (desc.size.x, desc.size.y);
    let local_to_world = desc.local_to_world();
    let local_to_world = &local_to_world;
    let texels = [
        deepest,
        (deepest.0 + 4, deepest.1),
        (deepest.0, deepest.1 + 7),
        (deepest.0 - 6, deepest.1 - 3),
        (deepest.0 + 9, deepest.1 + 9),
        (2, 3),
        (map.width - 1, map.height - 1),
    ];
    let luma = |p: &[u8]| 0.2126 * p[0] as f32 + 0.7152 * p[1] as f32 + 0.0722 * p[2] as f32;
    for texel in texels {
        let (x, y) = pixel_of(
            map,
            local_to_world,
            view_proj,
            sides,
            texel,
            (width, height),
        );
        let at = ((y * width + x) * 4) as usize;
        let shown = image.data[at] as f32 / 255.0;
        let expected = 1.0 - map.fraction(texel.0, texel.1);
        if (shown - expected).abs() > 1.5 / 255.0 {
            return Err(format!(
                "pixel ({x}, {y}) shows {shown:.3} of the snow left at texel {texel:?}, the heightmap says {expected:.3}"
            ));
        }
    }
    let (px, py) = pixel_of(
        map,
        local_to_world,
        view_proj,
        sides,
        deepest,
        (width, height),
    );
    let (ux, uy) = pixel_of(
        map,
        local_to_world,
        view_proj,
        sides,
        (2, 3),
        (width, height),
    );
    let print = luma(&image.picture[((py * width + px) * 4) as usize..]);
    let fresh = luma(&image.picture[((uy * width + ux) * 4) as usize..]);
    if print >= fresh - 40.0 {
        return Err(format!(
            "the print is not darker than untouched snow in the picture ({print:.0} against {fresh:.0})"
        ));
    }
    println!(
        "custom_renderer: {} x {} pixels agree with read_heightmap at {} texels; the print's deepest texel {:?} ({:.2} pressed) is drawn at luma {print:.0}, untouched snow at {fresh:.0}",
        width,
        height,
        texels.len(),
        deepest,
        map.fraction(deepest.0, deepest.1)
    );
    Ok(())
}

fn write_png(path: &str, width: u32, height: u32, rgba: &[u8]) -> Result<(), String> {
    let file = std::fs::File::create(path).map_err(|e| format!("cannot create {path}: {e}"))?;
    let mut encoder = png::Encoder::new(std::io::BufWriter::new(file), width, height);
    encoder.set_color(png::ColorType::Rgba);
    encoder.set_depth(png::BitDepth::Eight);
    encoder
        .write_header()
        .and_then(|mut w| w.write_image_data(rgba))
        .map_err(|e| format!("cannot write {path}: {e}"))
}
