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

/// Today's hand-written bind-group layouts, transcribed from where pipelines are created
/// (`accumulate/mod.rs`, `capture/mod.rs`, `render/mod.rs`, `render/tessellate/gpu.rs`), as
/// (module, group, entries on a device that filters Rgba16Float or not).
fn hand_written(filterable: bool) -> Vec<(&'static str, u32, Vec<wgpu::BindGroupLayoutEntry>)> {
    use crate::gpu::resources::{compute_storage, uniform};
    use wgpu::ShaderStages as S;
    let entry = |binding, visibility, ty| wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty,
        count: None,
    };
    let buffer = |ty, has_dynamic_offset| wgpu::BindingType::Buffer {
        ty,
        has_dynamic_offset,
        min_binding_size: None,
    };
    let storage = |read_only| wgpu::BufferBindingType::Storage { read_only };
    let texture = |sample_type, view_dimension| wgpu::BindingType::Texture {
        sample_type,
        view_dimension,
        multisampled: false,
    };
    let float = |filterable| wgpu::TextureSampleType::Float { filterable };
    let d2 = wgpu::TextureViewDimension::D2;
    let storage_texture = |binding| {
        entry(
            binding,
            S::COMPUTE,
            wgpu::BindingType::StorageTexture {
                access: wgpu::StorageTextureAccess::WriteOnly,
                format: wgpu::TextureFormat::Rgba16Float,
                view_dimension: d2,
            },
        )
    };
    let vf = S::VERTEX_FRAGMENT;
    let dynamic_uniform = |binding, visibility| {
        entry(
            binding,
            visibility,
            buffer(wgpu::BufferBindingType::Uniform, true),
        )
    };
    let fragment_storage = |binding| entry(binding, S::FRAGMENT, buffer(storage(false), false));
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
        entry(
            3,
            S::FRAGMENT,
            wgpu::BindingType::Sampler(if filterable {
                wgpu::SamplerBindingType::Filtering
            } else {
                wgpu::SamplerBindingType::NonFiltering
            }),
        ),
    ];
    let c = S::COMPUTE;
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
            vec![
                compute_storage(0, true),
                compute_storage(1, true),
                compute_storage(2, true),
                compute_storage(3, false),
            ],
        ),
        (
            "merge",
            0,
            vec![
                compute_storage(0, true),
                compute_storage(1, true),
                compute_storage(2, false),
            ],
        ),
        (
            "fused",
            0,
            vec![
                compute_storage(0, true),
                compute_storage(1, true),
                compute_storage(2, false),
                compute_storage(3, true),
                compute_storage(4, true),
                compute_storage(5, true),
            ],
        ),
        ("seal", 0, vec![compute_storage(0, false)]),
        (
            "normals",
            0,
            vec![compute_storage(0, true), compute_storage(1, false)],
        ),
        ("surface", 0, frame.clone()),
        ("sky", 0, frame.clone()),
        ("snowfall", 0, frame.clone()),
        ("tonemap", 0, frame.clone()),
        ("mesh", 0, frame.clone()),
        ("tess_surface", 0, frame),
        (
            "surface",
            1,
            vec![
                uniform(0, vf),
                entry(1, S::FRAGMENT, texture(float(filterable), d2)),
                entry(2, S::FRAGMENT, texture(float(filterable), d2)),
            ],
        ),
        (
            "tonemap",
            1,
            vec![
                entry(0, S::FRAGMENT, texture(float(false), d2)),
                entry(1, S::FRAGMENT, texture(wgpu::TextureSampleType::Depth, d2)),
            ],
        ),
        (
            "classify",
            0,
            vec![
                compute_storage(0, true),
                compute_storage(1, true),
                compute_storage(2, false),
            ],
        ),
        (
            "heightfield",
            0,
            vec![
                compute_storage(0, true),
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
                entry(1, c, texture(float(false), d2)),
                entry(2, c, texture(float(false), d2)),
                entry(3, c, texture(float(false), d2)),
                storage_texture(4),
            ],
        ),
        (
            "dice",
            0,
            vec![
                uniform(0, c),
                compute_storage(1, true),
                entry(2, c, texture(float(false), d2)),
                entry(3, c, texture(float(false), d2)),
                compute_storage(4, true),
                compute_storage(5, false),
                compute_storage(6, false),
                compute_storage(7, false),
            ],
        ),
        (
            "tess_surface",
            1,
            vec![
                uniform(0, vf),
                entry(1, vf, texture(float(filterable), d2)),
                entry(2, vf, texture(float(filterable), d2)),
                entry(3, vf, texture(float(false), d2)),
                entry(4, vf, buffer(storage(true), false)),
            ],
        ),
    ]
}

/// The layouts reflected from the modules (with `OVERRIDES`) are the hand-written ones, on devices
/// that filter Rgba16Float and on those that do not.
#[test]
fn reflected_layouts_match_hand_written() {
    for filterable in [true, false] {
        for (name, group, expected) in hand_written(filterable) {
            let reflected = get(name).unwrap().layout_entries_for(group, filterable);
            assert_eq!(
                reflected, expected,
                "{name} group {group} (filterable {filterable}): reflected vs hand-written"
            );
        }
    }
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
