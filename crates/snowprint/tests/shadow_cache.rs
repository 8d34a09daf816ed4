//! The shadow cascades' cache of still casters (`RenderConfig::shadow_cache`): frames drawn with
//! it are the frames drawn without it, byte for byte, while a caster moves, the snow is pressed,
//! a still caster is moved, and a frame is recorded into an engine's encoder that is never
//! submitted; and the frames that can use it do (`ShadowStats`).

mod common;

use glam::{Mat4, Vec3};
use snowprint::render::{Environment, Instance, RenderConfig, RenderFrame, Renderer, Tier};
use snowprint::{
    Camera, Deformer, GroundMaterial, Mesh, Pose, Shape, SnowWorld, SurfaceDesc, SurfaceId,
    WorldConfig,
};

/// Frames of each run.
const FRAMES: usize = 7;
/// The frame from which the still caster stands somewhere else.
const MOVED_AT: usize = 4;

/// What one frame of a run gave: its pixels and its cascades' use of the cache.
struct Frame {
    rgba8: Vec<u8>,
    from_cache: [bool; 2],
    restored_texels: [u64; 2],
}

/// A 4 m square of snow, a still block beside a sphere that crosses the square pressing the snow,
/// under a camera that holds still; the block moves at frame [`MOVED_AT`]. With `discard`, before
/// that frame another one (the ball elsewhere) is recorded into an encoder that is dropped.
fn run(tier: Tier, cache: bool, discard: Option<usize>) -> Vec<Frame> {
    let gpu = common::gpu();
    let mut world = SnowWorld::new(
        gpu,
        WorldConfig {
            pool_bytes: 4 << 20,
            ..Default::default()
        },
    )
    .expect("world");
    let id: SurfaceId = world
        .add_surface(SurfaceDesc::new("square", [0.0, 0.0, 0.0], [4.0, 4.0], 0.2))
        .expect("surface");
    let mut config = RenderConfig::new(96, 64, tier);
    config.shadow_map_size = 256;
    config.snowflakes = 0;
    config.shadow_cache = cache;
    let mut renderer = Renderer::new(gpu, config).expect("renderer");
    let block = renderer
        .add_mesh(&Mesh::cuboid(Vec3::new(0.3, 0.6, 0.3)))
        .expect("block");
    let ball = renderer
        .add_mesh(&Mesh::uv_sphere(0.25, 8, 12))
        .expect("ball");
    let surfaces = [(id, GroundMaterial::Concrete)];
    let mut frames = Vec::new();
    for k in 0..FRAMES {
        let x = -1.5 + 0.45 * k as f32;
        let at = Vec3::new(x, 0.15, 0.3);
        world
            .step(
                1.0 / 30.0,
                &[Deformer::new(
                    Shape::Sphere { radius: 0.25 },
                    Pose::at(at.to_array()),
                )],
            )
            .expect("step");
        let block_at = if k < MOVED_AT { 1.2 } else { 0.9 };
        let instances = [
            Instance::new(
                block,
                Mat4::from_translation(Vec3::new(block_at, 0.6, -1.0)),
                [0.4, 0.4, 0.45],
            )
            .with_still(true),
            Instance::new(ball, Mat4::from_translation(at), [0.7, 0.2, 0.1]),
        ];
        let frame = RenderFrame {
            camera: Camera {
                eye: Vec3::new(0.0, 3.5, 4.0),
                target: Vec3::new(0.0, 0.0, -0.3),
                fov_y_degrees: 50.0,
            },
            time: k as f32 / 30.0,
            surfaces: &surfaces,
            instances: &instances,
            lights: &[],
            environment: Environment::moonlit_night(),
            snowfall: false,
        };
        if discard == Some(k) {
            let elsewhere = [
                instances[0],
                Instance::new(ball, Mat4::from_translation(-at), [0.7, 0.2, 0.1]),
            ];
            let target = common::target(
                &gpu.device,
                "a frame never shown",
                (96, 64),
                wgpu::TextureFormat::Rgba8Unorm,
                wgpu::TextureUsages::RENDER_ATTACHMENT,
            );
            let view = target.create_view(&Default::default());
            let mut encoder = gpu.device.create_command_encoder(&Default::default());
            let dropped = RenderFrame {
                instances: &elsewhere,
                ..frame
            };
            // Recorded, then dropped with its encoder: never submitted, never `submitted`.
            let _never_submitted = renderer
                .encode_to_view(
                    &mut encoder,
                    &world,
                    &dropped,
                    &view,
                    wgpu::TextureFormat::Rgba8Unorm,
                )
                .expect("record");
        }
        let out = renderer.render(&world, &frame).expect("render");
        frames.push(Frame {
            rgba8: out.rgba8,
            from_cache: out.shadow.from_cache,
            restored_texels: out.shadow.restored_texels,
        });
    }
    frames
}

fn same_frames_with_and_without_the_cache(tier: Tier) {
    let with = run(tier, true, None);
    let without = run(tier, false, None);
    for (k, (a, b)) in with.iter().zip(&without).enumerate() {
        let differ = a.rgba8.iter().zip(&b.rgba8).filter(|(x, y)| x != y).count();
        assert_eq!(differ, 0, "{tier:?} frame {k}: {differ} bytes differ");
        assert_eq!(
            b.from_cache,
            [false, false],
            "{tier:?} frame {k} without the cache"
        );
    }
    // Frame 0 draws, frame 1 keeps (drawing the still block into the caches), then the cascades
    // restore where the ball and the snow drew; the block's move draws again, then keeps.
    let used: Vec<[bool; 2]> = with.iter().map(|f| f.from_cache).collect();
    let (n, y) = ([false, false], [true, true]);
    assert_eq!(used, [n, n, y, y, n, n, y], "{tier:?}");
    for k in [2, 3, 6] {
        let restored = with[k].restored_texels;
        assert!(
            restored.iter().all(|&t| t > 0),
            "{tier:?} frame {k}: {restored:?}"
        );
    }
    // The ball's shadow moves: the frames are not all the same picture.
    assert_ne!(with[2].rgba8, with[3].rgba8, "{tier:?}");
    // A frame recorded and never submitted before frame 3: frame 3 starts afresh (draws), the
    // frames are still those without the cache.
    let dropped = run(tier, true, Some(3));
    for (k, (a, b)) in dropped.iter().zip(&without).enumerate() {
        assert!(
            a.rgba8 == b.rgba8,
            "{tier:?} frame {k} after a dropped frame"
        );
    }
    let used: Vec<[bool; 2]> = dropped.iter().map(|f| f.from_cache).collect();
    assert_eq!(used, [n, n, y, n, n, n, y], "{tier:?}");
}

#[test]
fn relief_frames_are_the_same_with_the_shadow_cache() {
    same_frames_with_and_without_the_cache(Tier::Relief);
}

#[test]
fn tessellated_frames_are_the_same_with_the_shadow_cache() {
    same_frames_with_and_without_the_cache(Tier::Tessellated);
}
