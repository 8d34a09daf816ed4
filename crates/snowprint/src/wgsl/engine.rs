//! WGSL for an engine's own shaders: the pool read by prefixed functions ([`engine_module`]), and
//! the snow material on it ([`material_module`]).
//!
//! The engine module (`src/wgsl/engine.wgsl`) is self-contained: every type, variable and function
//! it declares starts with `snowprint_`, and the importer defines nothing. Its binding contract:
//!
//! | binding | WGSL | bind |
//! |---|---|---|
//! | `@group(group) @binding(pool_binding)` | `var<storage, read> snowprint_pool: array<u32>` | [`crate::FrameView::pool_buffer`], whole |
//!
//! and, per surface, a `snowprint_Surface` where the importer likes (a uniform, a storage array,
//! a constant), filled with [`crate::render::gpu::SurfaceUniform::for_surface`]. Its functions, by
//! value of the surface: `snowprint_depression(s, texel: vec2<u32>)`,
//! `snowprint_depression_uv(s, uv)` (bilinear), `snowprint_displaced(s, texel)`,
//! `snowprint_snow_depth_at(s, uv)` (metres of snow left), `snowprint_normal(s, uv)` (local frame,
//! +y up), `snowprint_uv(s, local_xz)`, `snowprint_to_local(s, world)` and
//! `snowprint_to_world(s, local)`; every pool precision is read.

/// Where the engine module binds the pool.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ImportOptions {
    /// `@group` of the pool.
    pub group: u32,
    /// `@binding` of the pool in that group.
    pub pool_binding: u32,
}

/// The pool's declaration as `engine.wgsl` stores it, which [`engine_module`] re-binds.
const POOL_DECLARATION: &str =
    "@group(0) @binding(0) var<storage, read> snowprint_pool: array<u32>;";

/// The engine module with the pool at `options`' group and binding: WGSL to put into a shader
/// module (declarations may come in any order). The contract is in the module's documentation (`wgsl/engine.rs`).
pub fn engine_module(options: &ImportOptions) -> String {
    rebind(super::libraries::ENGINE, options)
}

/// The snow material (`render/snow/snow.wgsl`: `SnowSurface`, `snow_trace`, `snow_deformable`,
/// `snow_basic`, ...) with the engine module and the material's heightfield contract filled from
/// the pool (`src/wgsl/engine_material.wgsl`), the pool at `options`' group and binding.
/// `SnowSurface` has `snowprint_Surface`'s layout: fill it with
/// [`crate::render::gpu::SurfaceUniform::for_surface`]. The material's own names start with
/// `snow_`, `Snow` or `SNOW_`.
pub fn material_module(options: &ImportOptions) -> String {
    rebind(super::libraries::ENGINE_MATERIAL, options)
}

fn rebind(source: &str, options: &ImportOptions) -> String {
    source.replacen(
        POOL_DECLARATION,
        &format!(
            "@group({}) @binding({}) var<storage, read> snowprint_pool: array<u32>;",
            options.group, options.pool_binding
        ),
        1,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn validate(source: &str) -> naga::Module {
        let module = naga::front::wgsl::parse_str(source)
            .unwrap_or_else(|e| panic!("{}", e.emit_to_string(source)));
        naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::all(),
        )
        .validate(&module)
        .unwrap_or_else(|e| panic!("{}", e.emit_to_string(source)));
        module
    }

    const CHOICES: [ImportOptions; 3] = [
        ImportOptions {
            group: 0,
            pool_binding: 0,
        },
        ImportOptions {
            group: 1,
            pool_binding: 3,
        },
        ImportOptions {
            group: 3,
            pool_binding: 11,
        },
    ];

    /// The pool's binding as the module declares it.
    fn pool_binding(module: &naga::Module) -> naga::ResourceBinding {
        let (_, pool) = module
            .global_variables
            .iter()
            .find(|(_, v)| v.name.as_deref() == Some("snowprint_pool"))
            .expect("snowprint_pool");
        pool.binding.expect("bound")
    }

    /// The engine module validates with the pool wherever the importer puts it, declares nothing
    /// without the `snowprint_` prefix, and has exactly one binding.
    #[test]
    fn engine_module_is_prefixed_and_rebinds() {
        assert_eq!(
            super::super::libraries::ENGINE
                .matches(POOL_DECLARATION)
                .count(),
            1
        );
        for options in CHOICES {
            let source = engine_module(&options);
            let module = validate(&source);
            let binding = pool_binding(&module);
            assert_eq!(
                (binding.group, binding.binding),
                (options.group, options.pool_binding)
            );
            assert_eq!(module.global_variables.len(), 1);
            let mut names: Vec<String> = Vec::new();
            names.extend(module.types.iter().filter_map(|(_, t)| t.name.clone()));
            names.extend(module.functions.iter().filter_map(|(_, f)| f.name.clone()));
            names.extend(module.constants.iter().filter_map(|(_, c)| c.name.clone()));
            names.extend(module.overrides.iter().filter_map(|(_, o)| o.name.clone()));
            names.extend(
                module
                    .global_variables
                    .iter()
                    .filter_map(|(_, v)| v.name.clone()),
            );
            for name in &names {
                assert!(name.starts_with("snowprint_"), "unprefixed `{name}`");
            }
            for needed in [
                "snowprint_Surface",
                "snowprint_depression",
                "snowprint_depression_uv",
                "snowprint_normal",
                "snowprint_snow_depth_at",
            ] {
                assert!(names.iter().any(|n| n == needed), "{needed} missing");
            }
            assert!(module.entry_points.is_empty());
        }
    }

    /// The engine module composes with an importer that has its own bindings and its own names
    /// (`pool`, `depression`, `channel_max`: what texel.wgsl once forced on it).
    #[test]
    fn engine_module_composes_with_an_importer() {
        let importer = "
            @group(0) @binding(0) var<storage, read_write> pool: array<u32>;
            @group(2) @binding(0) var<uniform> surfaces: snowprint_Surface;
            fn depression() -> f32 { return 0.0; }
            fn channel_max(bits: u32) -> u32 { return bits; }
            @compute @workgroup_size(1)
            fn main(@builtin(global_invocation_id) id: vec3<u32>) {
                let s = surfaces;
                pool[id.x] = bitcast<u32>(snowprint_depression(s, id.xy)
                    + snowprint_snow_depth_at(s, vec2<f32>(0.5)) + snowprint_normal(s, vec2<f32>(0.5)).y
                    + depression() + f32(channel_max(8u)));
            }";
        let source = format!(
            "{}\n{importer}",
            engine_module(&ImportOptions {
                group: 1,
                pool_binding: 4
            })
        );
        let module = validate(&source);
        assert_eq!(module.entry_points.len(), 1);
    }

    /// Following snow.wgsl's header in a compute shader and in a fragment shader works with the
    /// material module: 5-argument `snow_trace`, 6-argument `snow_deformable`, and no heightfield
    /// function to write.
    #[test]
    fn material_module_follows_its_header() {
        for options in CHOICES {
            let group = options.group + 1;
            let importer = format!(
                "
                @group({group}) @binding(0) var<uniform> surface: SnowSurface;
                @group({group}) @binding(1) var<storage, read_write> out: array<vec4<f32>>;
                @compute @workgroup_size(8, 8)
                fn main(@builtin(global_invocation_id) id: vec3<u32>) {{
                    let s = surface;
                    let o = vec3<f32>(0.0, s.snow_depth, 0.0);
                    let hit = snow_trace(s, o, vec3<f32>(0.0, -1.0, 0.0), SNOW_TIER_RELIEF, vec3<f32>(0.0, 1.0, 0.0));
                    if hit.found == 0u {{ return; }}
                    let hf = snow_heightfield(s, snow_uv(s, hit.position.xz));
                    let m = snow_deformable(s, hit, hf, vec3<f32>(0.0, 1.0, 0.0), vec3<f32>(1.0), 0.01);
                    let b = snow_basic(s, o, vec3<f32>(0.0, 1.0, 0.0), vec3<f32>(1.0), 0.01);
                    out[id.x] = vec4<f32>(m.albedo * hit.shadow, b.roughness);
                }}
                @fragment
                fn fs(@location(0) local: vec3<f32>) -> @location(0) vec4<f32> {{
                    let hit = snow_trace(surface, local, vec3<f32>(0.0, -1.0, 0.0), SNOW_TIER_POM, vec3<f32>(0.0, 1.0, 0.0));
                    if hit.found == 0u {{ discard; }}
                    let hf = snow_heightfield(surface, snow_uv(surface, hit.position.xz));
                    let m = snow_deformable(surface, hit, hf, vec3<f32>(0.0, 1.0, 0.0), vec3<f32>(1.0), 0.01);
                    return vec4<f32>(m.albedo, 1.0);
                }}"
            );
            let source = format!("{}\n{importer}", material_module(&options));
            let module = validate(&source);
            let binding = pool_binding(&module);
            assert_eq!(
                (binding.group, binding.binding),
                (options.group, options.pool_binding)
            );
            assert_eq!(module.entry_points.len(), 2);
        }
    }
}
