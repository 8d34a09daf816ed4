//! The renderer's passes moved to compute, against what they replace: the tonemap's compute pass
//! against its raster fallback (bit for bit on the same `Rgba8Unorm` output; within one unit of
//! the sRGB render target the raster pass wrote before, which the driver encodes itself); the
//! opaque meshes through the visibility buffer against the forward path, by NVIDIA FLIP within
//! the bounds of the goldens (`tests/golden/tolerances.toml`), and against the goldens themselves.

mod common;
mod golden_scene;
mod golden_support;

use golden_scene::{lights, overview_camera, render_golden_view, scene, scene_with};
use golden_support::{check, diff_dir, rgb, save_png, tolerance};
use snowprint::render::{OUTPUT_FORMAT, OpaquePath, RenderOutput, Tier};

/// Render the overview into a texture of the caller's (`render_to_view`) and read its bytes back.
fn render_into(
    scene: &mut golden_scene::Scene,
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
) -> Vec<u8> {
    let gpu = common::gpu();
    let (device, queue) = (&gpu.device, &gpu.queue);
    let (w, h) = (golden_scene::WIDTH, golden_scene::HEIGHT);
    let target = device.create_texture(&wgpu::TextureDescriptor {
        label: Some("caller's view"),
        size: wgpu::Extent3d {
            width: w,
            height: h,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage: usage | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    });
    let view = target.create_view(&Default::default());
    let instances = scene.instances.clone();
    let lights = lights();
    let frame = golden_scene::frame(&scene.surfaces, overview_camera(), &instances, &lights);
    scene
        .renderer
        .render_to_view(&scene.world, &frame, &view, format)
        .expect("render to view");
    let row = (w * 4).div_ceil(256) * 256;
    let buffer = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("view readback"),
        size: (row * h) as u64,
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    let mut encoder = device.create_command_encoder(&Default::default());
    encoder.copy_texture_to_buffer(
        target.as_image_copy(),
        wgpu::TexelCopyBufferInfo {
            buffer: &buffer,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(row),
                rows_per_image: Some(h),
            },
        },
        target.size(),
    );
    queue.submit([encoder.finish()]);
    let slice = buffer.slice(..);
    slice.map_async(wgpu::MapMode::Read, |r| r.expect("map"));
    device
        .poll(wgpu::PollType::wait_indefinitely())
        .expect("poll");
    let data = slice.get_mapped_range().expect("mapped");
    (0..h as usize)
        .flat_map(|y| data[y * row as usize..][..w as usize * 4].to_vec())
        .collect()
}

/// The compute tonemap writes what its raster fallback writes into the same `Rgba8Unorm` output,
/// byte for byte: the maths are one module (`resolve.wgsl`), only the way the pixel is written
/// differs. Against an sRGB render target (what the tonemap wrote before it moved to compute,
/// and still writes into a window's sRGB surface), where the driver encodes the linear value
/// itself, no byte differs by more than one unit.
#[test]
fn the_compute_tonemap_writes_what_the_raster_tonemap_writes() {
    let mut scene = scene();
    scene.renderer.set_tier(Tier::Relief);
    use wgpu::TextureUsages as U;
    let compute = render_into(&mut scene, OUTPUT_FORMAT, U::STORAGE_BINDING);
    let offscreen = golden_scene::render(&mut scene, Tier::Relief).rgba8;
    assert!(compute == offscreen, "render_to_view and render differ");
    let raster = render_into(&mut scene, OUTPUT_FORMAT, U::RENDER_ATTACHMENT);
    let differing = compute.iter().zip(&raster).filter(|(a, b)| a != b).count();
    assert_eq!(
        differing, 0,
        "bytes differing between compute and raster on Rgba8Unorm"
    );
    let srgb = render_into(
        &mut scene,
        wgpu::TextureFormat::Rgba8UnormSrgb,
        U::RENDER_ATTACHMENT,
    );
    let mut off_by_one = 0;
    for (a, b) in compute.iter().zip(&srgb) {
        let d = (*a as i32 - *b as i32).abs();
        assert!(d <= 1, "compute {a} against the sRGB target's {b}");
        off_by_one += usize::from(d == 1);
    }
    eprintln!(
        "compute against the sRGB render target: {off_by_one} of {} bytes differ by one unit",
        compute.len()
    );
}

/// FLIP of `test` against `reference`: mean and weighted 99th percentile.
fn flip(reference: &RenderOutput, test: &RenderOutput) -> (f64, f64) {
    let (w, h) = (reference.width, reference.height);
    let error = nv_flip::flip(
        nv_flip::FlipImageRgb8::with_data(w, h, &rgb(&reference.rgba8)),
        nv_flip::FlipImageRgb8::with_data(w, h, &rgb(&test.rgba8)),
        nv_flip::DEFAULT_PIXELS_PER_DEGREE,
    );
    let pool = nv_flip::FlipPool::from_image(&error);
    (pool.mean() as f64, pool.get_weighted_percentile(0.99))
}

/// The opaque meshes through the visibility buffer (depth and (instance, triangle) rasterised, the
/// shading in compute), and the relief-mapped snow with them (its rays traced in the fragments,
/// its hits shaded in compute), against the forward path, in the golden views of the scene:
/// bricks, the ball, the bodies and their shadows, the lantern, the prints in relief and POM. The bound is each golden's own
/// (`tolerances.toml`, the one in force on this driver), and the visibility renders pass the
/// goldens themselves too. The pixels the two paths light differently are counted.
#[test]
fn the_visibility_buffer_draws_what_the_forward_path_draws() {
    let mut forward = scene();
    let mut visibility = scene_with(|c| c.opaque = OpaquePath::Visibility);
    for name in ["relief", "pom", "relief_grazing", "tessellated"] {
        let a = render_golden_view(&mut forward, name);
        let b = render_golden_view(&mut visibility, name);
        let (mean, p99) = flip(&a, &b);
        let differing = a.rgba8.iter().zip(&b.rgba8).filter(|(x, y)| x != y).count();
        let tol = tolerance(name);
        eprintln!(
            "{name}: visibility against forward FLIP mean {mean:.5} (max {}), p99 {p99:.5} (max {}), {differing} of {} bytes differ",
            tol.mean,
            tol.p99,
            a.rgba8.len()
        );
        if mean > tol.mean || p99 > tol.p99 || std::env::var_os("SNOWPRINT_SAVE").is_some() {
            save_png(&diff_dir().join(format!("{name}-forward.png")), &a);
            save_png(&diff_dir().join(format!("{name}-visibility.png")), &b);
        }
        assert!(
            mean <= tol.mean && p99 <= tol.p99,
            "{name}: the visibility path scores FLIP mean {mean} p99 {p99} against the forward path"
        );
        check(name, &b);
    }
}

/// A shadow map of 16-bit depth draws every golden view within the golden's bound (half the
/// bytes the shadow pass clears and writes: `RenderConfig::shadow_depth_bits`); the pixels it
/// changes against the 32-bit map are counted. A width the renderer cannot make is refused.
#[test]
fn a_16_bit_shadow_map_draws_the_goldens() {
    let mut full = scene();
    let mut half = scene_with(|c| c.shadow_depth_bits = 16);
    for name in [
        "relief",
        "pom",
        "relief_grazing",
        "tessellated",
        "tessellated_grazing",
    ] {
        let a = render_golden_view(&mut full, name);
        let b = render_golden_view(&mut half, name);
        let (mean, p99) = flip(&a, &b);
        let differing = a.rgba8.iter().zip(&b.rgba8).filter(|(x, y)| x != y).count();
        eprintln!(
            "{name}: 16-bit shadow depth against 32-bit FLIP mean {mean:.5}, p99 {p99:.5}, {differing} of {} bytes differ",
            a.rgba8.len()
        );
        check(name, &b);
    }
    let mut config = snowprint::render::RenderConfig::new(64, 64, Tier::Relief);
    config.shadow_depth_bits = 24;
    let refused = match snowprint::render::Renderer::new(common::gpu(), config) {
        Ok(_) => panic!("a 24-bit shadow map was made"),
        Err(e) => e.to_string(),
    };
    assert!(
        refused.contains("shadow_depth_bits") && refused.contains("16 or 32"),
        "{refused}"
    );
}

/// Instances outside the view's frustum are culled from the opaque pass and change no pixel: the
/// overview with a second ball behind the camera and one far to the side draws the overview's
/// bytes, and reports both culled.
#[test]
fn instances_out_of_view_are_culled_and_change_nothing() {
    let mut scene = scene();
    let plain = golden_scene::render(&mut scene, Tier::Relief);
    assert_eq!(
        plain.culled_instances, 0,
        "every instance of the overview is in view"
    );
    let ball = scene.instances[1];
    let moved = |to: glam::Vec3| snowprint::render::Instance {
        transform: glam::Mat4::from_translation(to),
        casts_shadow: false,
        ..ball
    };
    scene.instances.push(moved(glam::Vec3::new(0.6, 5.0, 8.0)));
    scene.instances.push(moved(glam::Vec3::new(40.0, 2.0, 0.0)));
    let out = golden_scene::render(&mut scene, Tier::Relief);
    assert_eq!(out.culled_instances, 2);
    assert!(out.rgba8 == plain.rgba8, "culled instances changed pixels");
}

/// Shadow casters are drawn only into the cascades whose box they reach: in the overview every
/// instance (three, all casting) lies within the near cascade's 12 m square around the view's
/// focus; a fourth caster 40 m to the side is out of view and out of the near cascade but in the
/// far one, which is fitted around every caster. The goldens (checked elsewhere with the same
/// culling) keep every shadow the scene casts.
#[test]
fn casters_are_culled_per_cascade() {
    let mut scene = scene();
    let out = golden_scene::render(&mut scene, Tier::Relief);
    assert_eq!(out.shadow.casters, [3, 3]);
    let far_away = snowprint::render::Instance {
        transform: glam::Mat4::from_translation(glam::Vec3::new(40.0, 2.0, 0.0)),
        ..scene.instances[1]
    };
    scene.instances.push(far_away);
    let out = golden_scene::render(&mut scene, Tier::Relief);
    assert_eq!(out.culled_instances, 1);
    assert_eq!(out.shadow.casters, [3, 4]);
    // 12 m over the 1024 texels of the scene's shadow map; the view's pixel at the focus (4.8 m
    // ahead, 52 degrees over 144 rows) is 2 * 4.8 * tan(26 degrees) / 144 = 0.0325 m.
    assert!((out.shadow.texel_m[0] - 12.0 / 1024.0).abs() < 1e-6);
    let pixel = 2.0 * 4.8 * 26f32.to_radians().tan() / 144.0;
    assert!(
        (out.shadow.view_pixel_m - pixel).abs() < 1e-6,
        "{:?}",
        out.shadow
    );
    eprintln!("{:?}", out.shadow);
}
