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

/// Every binding's layout entry is visible to the stages of every entry point that uses it (an
/// `Override::Stages` may widen the reflected stages, never narrow them), on devices that filter
/// Rgba16Float and on those that do not.
#[test]
fn layout_visibility_covers_every_use() {
    for module in all() {
        for filterable in [true, false] {
            for group in 0..4 {
                let entries = module.layout_entries_for(group, filterable);
                for b in module.bindings.iter().filter(|b| b.group == group) {
                    let entry = entries.iter().find(|e| e.binding == b.binding).unwrap();
                    let used = module
                        .entry_points
                        .iter()
                        .enumerate()
                        .filter(|(i, _)| b.entry_points & (1 << i) != 0)
                        .fold(0, |s, (_, ep)| s | ep.stages);
                    assert_eq!(used, b.stages, "{}.{}", module.name, b.name);
                    assert!(
                        entry
                            .visibility
                            .contains(wgpu::ShaderStages::from_bits_truncate(used)),
                        "{}.{}: {:?} misses stages {used:#b}",
                        module.name,
                        b.name,
                        entry.visibility
                    );
                }
            }
        }
    }
}

/// frame.wgsl's group 0 is one layout that every pass of the renderer shares (`render/frame`
/// makes it from the snow pass's module): every module that imports it reflects the same one.
#[test]
fn frame_layout_is_the_same_in_every_module() {
    let importers: Vec<_> = all()
        .iter()
        .filter(|m| m.bindings.iter().any(|b| b.group == 0 && b.name == "frame"))
        .collect();
    let names: Vec<_> = importers.iter().map(|m| m.name).collect();
    for name in [
        "surface",
        "sky",
        "snowfall",
        "tonemap",
        "mesh",
        "tess_surface",
    ] {
        assert!(names.contains(&name), "{name} does not bind the frame");
    }
    for filterable in [true, false] {
        let shared = SURFACE.layout_entries_for(0, filterable);
        for module in &importers {
            assert_eq!(
                module.layout_entries_for(0, filterable),
                shared,
                "{} group 0 (filterable {filterable})",
                module.name
            );
        }
    }
}

/// The shadow passes' group 0 is the frame uniform alone, seen by the vertex stage: what their
/// vertex entry points use, the same for both (`render/frame` makes it from `mesh`'s).
#[test]
fn shadow_layouts_from_their_entry_points() {
    let expected = vec![wgpu::BindGroupLayoutEntry {
        binding: 0,
        visibility: wgpu::ShaderStages::VERTEX,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }];
    for (module, entry) in [("mesh", "vs_shadow"), ("tess_surface", "vs_tess_shadow")] {
        for filterable in [true, false] {
            let reflected = get(module)
                .unwrap()
                .layout_entries_of(&[entry], 0, filterable);
            assert_eq!(reflected, expected, "{module}::{entry}");
        }
    }
    // The snow pass's own entry points need the whole group, as shared.
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
    assert_eq!(consts::TILE_LIST_HEADER, 8);
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
