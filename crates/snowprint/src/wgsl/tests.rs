use super::*;

/// Every entry module of the table is in the registry, with its source and bindings.
#[test]
fn registry_lists_every_entry_module() {
    let names: Vec<_> = all().iter().map(|m| m.name).collect();
    for name in [
        "capture",
        "blur",
        "merge",
        "normals",
        "fused",
        "seal",
        "surface",
        "tess_surface",
        "mesh",
        "sky",
        "snowfall",
        "tonemap",
        "classify",
        "heightfield",
        "banks",
        "dice",
    ] {
        assert!(names.contains(&name), "{name} missing from {names:?}");
        let module = get(name).unwrap();
        assert!(module.source.contains("@compute") || module.source.contains("@vertex"));
    }
    // Every override names a binding that exists.
    for (module, binding, _) in OVERRIDES {
        let has = |m: &ShaderModule| m.bindings.iter().any(|b| b.name == *binding);
        if *module == "*" {
            assert!(all().iter().any(|m| has(m)), "*.{binding}");
        } else {
            let m = get(module).unwrap_or_else(|| panic!("override of unknown module {module}"));
            assert!(has(m), "{module}.{binding}");
        }
    }
}

/// The composed modules parse and validate with naga here too (build.rs already failed the build
/// otherwise; this keeps the check visible in `cargo test`).
#[test]
fn registry_validates() {
    for module in all() {
        let parsed = naga::front::wgsl::parse_str(module.source)
            .unwrap_or_else(|e| panic!("{}: {}", module.name, e.emit_to_string(module.source)));
        naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::all(),
        )
        .validate(&parsed)
        .unwrap_or_else(|e| panic!("{}: {e:?}", module.name));
    }
}

// Today's hand-written bind-group layouts, transcribed from where pipelines are created
// (`accumulate/mod.rs`, `capture/mod.rs`, `render/mod.rs`, `render/tessellate/gpu.rs`), as
// (module, group, entries), with the helpers those files use.

use crate::gpu::resources::{compute_storage, uniform};
use wgpu::ShaderStages as S;

type Layouts = Vec<(&'static str, u32, Vec<wgpu::BindGroupLayoutEntry>)>;

fn entry(binding: u32, visibility: S, ty: wgpu::BindingType) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty,
        count: None,
    }
}

fn buffer(ty: wgpu::BufferBindingType, has_dynamic_offset: bool) -> wgpu::BindingType {
    wgpu::BindingType::Buffer {
        ty,
        has_dynamic_offset,
        min_binding_size: None,
    }
}

fn storage(read_only: bool) -> wgpu::BufferBindingType {
    wgpu::BufferBindingType::Storage { read_only }
}

fn texture(
    sample_type: wgpu::TextureSampleType,
    view_dimension: wgpu::TextureViewDimension,
) -> wgpu::BindingType {
    wgpu::BindingType::Texture {
        sample_type,
        view_dimension,
        multisampled: false,
    }
}

fn float(filterable: bool) -> wgpu::BindingType {
    texture(
        wgpu::TextureSampleType::Float { filterable },
        wgpu::TextureViewDimension::D2,
    )
}

fn storage_texture(binding: u32) -> wgpu::BindGroupLayoutEntry {
    entry(
        binding,
        S::COMPUTE,
        wgpu::BindingType::StorageTexture {
            access: wgpu::StorageTextureAccess::WriteOnly,
            format: wgpu::TextureFormat::Rgba16Float,
            view_dimension: wgpu::TextureViewDimension::D2,
        },
    )
}

/// The update's layouts: capture and accumulation.
fn update_layouts() -> Layouts {
    let vf = S::VERTEX_FRAGMENT;
    let dynamic_uniform = |binding, visibility| {
        entry(
            binding,
            visibility,
            buffer(wgpu::BufferBindingType::Uniform, true),
        )
    };
    let fragment_storage = |binding| entry(binding, S::FRAGMENT, buffer(storage(false), false));
    let cs = compute_storage;
    vec![
        (
            "capture",
            0,
            vec![
                dynamic_uniform(0, vf),
                entry(1, vf, buffer(storage(true), false)),
                fragment_storage(2),
                fragment_storage(3),
                fragment_storage(4),
                fragment_storage(5),
            ],
        ),
        ("capture", 1, vec![dynamic_uniform(0, S::VERTEX)]),
        (
            "blur",
            0,
            vec![cs(0, true), cs(1, true), cs(2, true), cs(3, false)],
        ),
        ("merge", 0, vec![cs(0, true), cs(1, true), cs(2, false)]),
        (
            "fused",
            0,
            vec![
                cs(0, true),
                cs(1, true),
                cs(2, false),
                cs(3, true),
                cs(4, true),
                cs(5, true),
            ],
        ),
        ("seal", 0, vec![cs(0, false)]),
        ("normals", 0, vec![cs(0, true), cs(1, false)]),
    ]
}

/// The renderer's layouts on a device that filters Rgba16Float or not.
fn render_layouts(filterable: bool) -> Layouts {
    let vf = S::VERTEX_FRAGMENT;
    let c = S::COMPUTE;
    let linear = if filterable {
        wgpu::SamplerBindingType::Filtering
    } else {
        wgpu::SamplerBindingType::NonFiltering
    };
    let frame = vec![
        uniform(0, vf),
        entry(
            1,
            S::FRAGMENT,
            texture(
                wgpu::TextureSampleType::Depth,
                wgpu::TextureViewDimension::D2Array,
            ),
        ),
        entry(
            2,
            S::FRAGMENT,
            wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Comparison),
        ),
        entry(3, S::FRAGMENT, wgpu::BindingType::Sampler(linear)),
    ];
    let depth = texture(
        wgpu::TextureSampleType::Depth,
        wgpu::TextureViewDimension::D2,
    );
    let cs = compute_storage;
    let mut layouts: Layouts = [
        "surface",
        "sky",
        "snowfall",
        "tonemap",
        "mesh",
        "tess_surface",
    ]
    .into_iter()
    .map(|name| (name, 0, frame.clone()))
    .collect();
    layouts.extend([
        (
            "surface",
            1,
            vec![
                uniform(0, vf),
                entry(1, S::FRAGMENT, float(filterable)),
                entry(2, S::FRAGMENT, float(filterable)),
            ],
        ),
        (
            "tonemap",
            1,
            vec![
                entry(0, S::FRAGMENT, float(false)),
                entry(1, S::FRAGMENT, depth),
            ],
        ),
        ("classify", 0, vec![cs(0, true), cs(1, true), cs(2, false)]),
        (
            "heightfield",
            0,
            vec![
                cs(0, true),
                uniform(1, c),
                storage_texture(2),
                storage_texture(3),
            ],
        ),
        (
            "banks",
            0,
            vec![
                uniform(0, c),
                entry(1, c, float(false)),
                entry(2, c, float(false)),
                entry(3, c, float(false)),
                storage_texture(4),
            ],
        ),
        (
            "dice",
            0,
            vec![
                uniform(0, c),
                cs(1, true),
                entry(2, c, float(false)),
                entry(3, c, float(false)),
                cs(4, true),
                cs(5, false),
                cs(6, false),
                cs(7, false),
            ],
        ),
        (
            "tess_surface",
            1,
            vec![
                uniform(0, vf),
                entry(1, vf, float(filterable)),
                entry(2, vf, float(filterable)),
                entry(3, vf, float(false)),
                entry(4, vf, buffer(storage(true), false)),
            ],
        ),
    ]);
    layouts
}

/// The layouts reflected from the modules (with `OVERRIDES`) are the hand-written ones, on devices
/// that filter Rgba16Float and on those that do not.
#[test]
fn reflected_layouts_match_hand_written() {
    for filterable in [true, false] {
        for (name, group, expected) in update_layouts()
            .into_iter()
            .chain(render_layouts(filterable))
        {
            let reflected = get(name).unwrap().layout_entries_for(group, filterable);
            assert_eq!(
                reflected, expected,
                "{name} group {group} (filterable {filterable}): reflected vs hand-written"
            );
        }
    }
}

/// The shadow passes' group 0 is the frame uniform alone, seen by the vertex stage: what their
/// vertex entry points use (`render/mod.rs` and `render/tessellate/gpu.rs` write it by hand).
#[test]
fn shadow_layouts_from_their_entry_points() {
    let expected = vec![uniform(0, S::VERTEX)];
    for (module, entry) in [("mesh", "vs_shadow"), ("tess_surface", "vs_tess_shadow")] {
        for filterable in [true, false] {
            let reflected = get(module)
                .unwrap()
                .layout_entries_of(&[entry], 0, filterable);
            assert_eq!(reflected, expected, "{module}::{entry}");
        }
    }
    // The snow pass's own entry points need the whole frame group, as shared.
    let surface = get("surface").unwrap();
    let names: Vec<_> = surface.entry_points.iter().map(|e| e.name).collect();
    assert_eq!(
        surface.layout_entries_of(&names, 1, true),
        surface.layout_entries(1)
    );
}

/// The constants reflected from constants.wgsl are the values the Rust code used before.
#[test]
fn shared_constants() {
    assert_eq!(consts::ONE_BITS, 1.0f32.to_bits());
    assert_eq!(consts::TILE, 16);
    assert_eq!(consts::WORKGROUP, 8);
    assert_eq!(consts::TILE_LIST_HEADER, 4);
    assert_eq!(consts::NO_LIST, u32::MAX);
    assert_eq!(consts::NO_CAPTURE, u32::MAX);
    assert_eq!(consts::NO_NORMALS, u32::MAX);
    assert_eq!(
        (consts::MODE_DEPTH, consts::MODE_MASK, consts::MODE_MESHES),
        (0, 1, 2)
    );
    assert_eq!((consts::PRIM_CAPSULE, consts::PRIM_BOX), (0, 1));
    assert_eq!((consts::STATE_WORDS, consts::STATE_TOUCHED), (16, 11));
    assert_eq!((consts::ARGS_BASE, consts::ARGS_STRIDE), (8, 8));
    assert_eq!(consts::COUNTER_VERTICES, 0);
    assert_eq!(consts::COUNTER_INDICES, 1);
    assert_eq!(consts::COUNTER_SEALED, 2);
    assert_eq!(consts::COUNTER_OVERFLOW, 3);
    assert_eq!(consts::MAX_POINT_LIGHTS, 8);
    assert_eq!(
        (consts::PENUMBRA_SLOPE, consts::PENUMBRA_BASE),
        (0.12, 0.01)
    );
    assert_eq!((consts::LIGHT_TAPS, consts::AO_DIRECTIONS), (16, 8));
    assert_eq!(consts::RECEPTIVITY_FLOOR, 0.001);
}

/// The update compiles each of its passes with the pool's `PRECISION` override, which wgpu refuses
/// for a module that does not declare it.
#[test]
fn update_passes_declare_precision() {
    for name in ["blur", "merge", "normals", "fused", "seal"] {
        let module = naga::front::wgsl::parse_str(get(name).unwrap().source).unwrap();
        assert!(
            module
                .overrides
                .iter()
                .any(|(_, o)| o.name.as_deref() == Some("PRECISION")),
            "{name}"
        );
    }
}
