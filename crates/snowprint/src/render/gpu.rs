//! The Rust side of every uniform and table the renderer's WGSL reads. Each struct names the WGSL
//! struct it must match; the unit tests below parse the WGSL with naga and compare sizes and member
//! offsets, so a change made on one side only fails `cargo test`, not the first frame.

use bytemuck::{Pod, Zeroable};

/// Per-surface words in the surface state table written by `classify.wgsl`.
pub const STATE_WORDS: u64 = crate::wgsl::consts::STATE_WORDS as u64;
/// Offset (in words) of the basic material's indirect draw arguments.
pub const STATE_BASIC_DRAW: u64 = 0;
/// Offset of the deformable material's indirect draw arguments.
pub const STATE_DEFORMABLE_DRAW: u64 = 4;
/// Offset of the flag the heightfield and bank passes run by (1: the surface is shaded this
/// frame), which they read themselves (`heightfield.wgsl`, `banks.wgsl`).
pub const STATE_SHADED: u64 = crate::wgsl::consts::STATE_SHADED as u64;
/// Offset of the "deformed" flag.
pub const STATE_TOUCHED: u64 = crate::wgsl::consts::STATE_TOUCHED as u64;
/// Offset of the deepest depression (an f32 fraction of the snow depth, as bits).
pub const STATE_DEEPEST: u64 = 12;
/// Vertices of a surface's box: six faces of two triangles (the bottom for a camera inside the
/// box, looking down through it).
pub const BOX_VERTICES: u32 = 36;
/// Alignment of uniform blocks addressed by offset.
pub const UNIFORM_STRIDE: u64 = crate::gpu::resources::UNIFORM_STRIDE;
/// Spacing of the per-surface [`SurfaceUniform`] blocks in the snow pass's buffer, bytes: two
/// [`UNIFORM_STRIDE`]s, since the material's look made the struct outgrow one.
pub const SURFACE_STRIDE: u64 = 2 * UNIFORM_STRIDE;
/// Point lights the frame uniform holds.
pub const MAX_POINT_LIGHTS: usize = crate::wgsl::consts::MAX_POINT_LIGHTS as usize;

/// One point light. Must match `PointLight` in `frame.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct PointLightRaw {
    /// World position and radius of influence.
    pub position_radius: [f32; 4],
    /// Colour times intensity; w unused.
    pub color: [f32; 4],
}

/// The frame's uniforms. Must match `Frame` in `frame.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct FrameUniform {
    /// World to clip.
    pub view_proj: [[f32; 4]; 4],
    /// Clip to world.
    pub inv_view_proj: [[f32; 4]; 4],
    /// World to the moon's near shadow cascade.
    pub shadow_near: [[f32; 4]; 4],
    /// World to the moon's far shadow cascade.
    pub shadow_far: [[f32; 4]; 4],
    /// Eye position; w: time.
    pub eye: [f32; 4],
    /// Towards the moon; w: cosine of the moon's angular radius.
    pub moon_dir: [f32; 4],
    /// Moonlight; w unused.
    pub moon_color: [f32; 4],
    /// Sky overhead; w: exposure.
    pub sky_zenith: [f32; 4],
    /// Sky at the horizon; w: fog density.
    pub sky_horizon: [f32; 4],
    /// Bounce from below; w: city glow.
    pub ground_bounce: [f32; 4],
    /// Sky tint of the snow's transition zone; w: strength.
    pub sss_tint: [f32; 4],
    /// Light from the whole sky on a surface facing up; w unused.
    pub sky_ambient: [f32; 4],
    /// Internal width, height and reciprocals.
    pub viewport: [f32; 4],
    /// Debug view, point lights, tier, snowflakes.
    pub options: [u32; 4],
    /// Shadow texels in metres: near cascade, far cascade.
    pub shadow_texels: [f32; 4],
    /// Point lights.
    pub lights: [PointLightRaw; MAX_POINT_LIGHTS],
}

/// One snow surface: where it lies, where its texels are in the pool, and the renderer's
/// material settings. Must match `SnowSurface` in `snow.wgsl` and `snowprint_Surface` in
/// `wgsl/engine.wgsl` ([`crate::wgsl::engine_module`]); fill it with [`Self::for_surface`].
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct SurfaceUniform {
    /// Local to world.
    pub local_to_world: [[f32; 4]; 4],
    /// World to local.
    pub world_to_local: [[f32; 4]; 4],
    /// Half the sides, metres.
    pub half_size: [f32; 2],
    /// Snow depth, metres.
    pub snow_depth: f32,
    /// Texel side, metres.
    pub texel: f32,
    /// Heightmap width and height.
    pub grid: [f32; 2],
    /// Ground material (0 tiles, 1 concrete).
    pub ground: u32,
    /// Slot in the per-surface tables.
    pub index: u32,
    /// Search parameters: taps per texel, min taps, max taps, binary refinement taps.
    pub search: [f32; 4],
    /// Look: ground from, ground full, AO strength, POM self-shadow taps.
    pub look: [f32; 4],
    /// Pattern offset (xy), switched-off terms (z, `SnowLook::switch_bits`), macro wave strength (w).
    pub pattern: [f32; 4],
    /// Word offset of the heights region in the pool buffer.
    pub heights: u32,
    /// Words a row of the heights region (a plane's, at 32 bits: [`crate::PoolFormat::row_words`]).
    pub row_words: u32,
    /// Bits a channel of the pool: 8, 16 or 32.
    pub bits: u32,
    /// A channel pressed to the ground ([`crate::Precision::channel_max`]), as a float.
    pub channel_max: f32,
    /// Texels along local x.
    pub width: u32,
    /// Texels along local z.
    pub height: u32,
    /// Texel side along local x, metres.
    pub texel_x: f32,
    /// Texel side along local z, metres.
    pub texel_z: f32,
    /// The material's look ([`crate::MaterialLook`]): untouched albedo (xyz), dry roughness (w).
    pub albedo: [f32; 4],
    /// Disturbed albedo at the bottom of prints (xyz), wet roughness (w).
    pub disturbed: [f32; 4],
    /// Grain, sparkle, wetness, water depth below the top in metres (0: no water).
    pub grain: [f32; 4],
    /// Translucency (x: the sky tint of prints' walls and the diffuse wrap); yzw unused.
    pub translucency: [f32; 4],
    /// First texel of the surface's ground field in [`crate::FrameView::ground_buffer`], or
    /// [`crate::low_level::ground::NO_GROUND`] on flat ground.
    pub terrain: u32,
    /// Lowest base of the snow columns, local metres (0 on flat ground): the slab's floor.
    pub terrain_low: f32,
    /// Highest untouched snow top, local metres (the snow depth on flat ground): the slab's top
    /// below the room for rims.
    pub terrain_top: f32,
    /// The heights' toroidal storage offsets, `ox | oy << 16` ([`crate::SurfaceView::wrap`]).
    pub wrap: u32,
    /// A rectangle of the surface's local xz `(x0, z0, x1, z1)` it does not draw, because a finer
    /// level of the same terrain window draws it (`crate::Terrain`); empty (`x1 < x0`) otherwise.
    pub hole: [f32; 4],
}

/// `SurfaceUniform::hole` of a surface that draws all of itself.
pub const NO_HOLE: [f32; 4] = [1.0, 1.0, -1.0, -1.0];

/// Room for rims above the snow top that the relief and POM tiers raise their slab by, metres:
/// the material's share of the pushed volume times the snow depth (a rim a whole depth high needs
/// the whole depth pushed out beside a print a bank's width wide; higher rims are cut flat); 0
/// for a material without rims (the talk's snow: the slab as before).
pub(crate) fn rim_room(material: &crate::Material, snow_depth: f32) -> f32 {
    material.rim_fraction().map_or(0.0, |f| f * snow_depth)
}

impl SurfaceUniform {
    /// Surface `id` of a frame's view ([`crate::SnowWorld::frame_view`]): its transforms, size,
    /// snow depth and texel sides, where its heights lie in the pool and at what precision, and the
    /// default renderer's material settings (ground tiles, the relief tier's search, the default
    /// look). Fails with [`crate::SnowError::StaleHandle`] for a surface the view does not hold.
    pub fn for_surface(view: &crate::FrameView<'_>, id: crate::SurfaceId) -> crate::Result<Self> {
        let surface = view.surface(id)?;
        Ok(Self::for_view(surface))
    }

    /// [`Self::for_surface`] from one surface of a view.
    pub fn for_view(surface: &crate::SurfaceView<'_>) -> Self {
        let config = crate::render::RenderConfig::new(1, 1, crate::render::Tier::Relief);
        let shading = Shading {
            search: config.search_settings(),
            look: config.look,
            ground: 0,
            index: surface.id.index(),
            macro_waves: 1.0,
            seams: 0,
        };
        Self::shaded(surface, &shading)
    }

    /// One surface of a view with the material settings of `shading`.
    pub(crate) fn shaded(surface: &crate::SurfaceView<'_>, shading: &Shading) -> Self {
        let (desc, layout) = (surface.desc, surface.layout);
        let texel_x = desc.size.x / layout.width as f32;
        let texel_z = desc.size.y / layout.height as f32;
        let local_to_world = desc.local_to_world();
        let (search, look) = (&shading.search, &shading.look);
        let m = &desc.material.look;
        Self {
            local_to_world: local_to_world.to_cols_array_2d(),
            world_to_local: local_to_world.inverse().to_cols_array_2d(),
            half_size: (desc.size * 0.5).to_array(),
            snow_depth: desc.snow_depth,
            texel: texel_x.max(texel_z),
            grid: [layout.width as f32, layout.height as f32],
            ground: shading.ground,
            index: shading.index,
            search: [
                search.taps_per_texel,
                search.min_taps as f32,
                search.max_taps as f32,
                search.refine_taps as f32,
            ],
            look: [
                look.ground_from,
                look.ground_full,
                look.occlusion,
                search.shadow_taps as f32,
            ],
            pattern: [
                desc.center.x,
                desc.center.z,
                (look.switch_bits() | shading.seams << SEAM_SWITCH_SHIFT) as f32,
                shading.macro_waves,
            ],
            heights: surface.heights,
            row_words: crate::PoolFormat::new(surface.precision).row_words(layout.width),
            bits: surface.precision.bits(),
            channel_max: surface.precision.channel_max() as f32,
            width: layout.width,
            height: layout.height,
            texel_x,
            texel_z,
            albedo: [m.albedo[0], m.albedo[1], m.albedo[2], m.roughness],
            disturbed: [
                m.disturbed_albedo[0],
                m.disturbed_albedo[1],
                m.disturbed_albedo[2],
                m.wet_roughness,
            ],
            grain: [m.grain, m.sparkle, m.wetness, m.water_depth.unwrap_or(0.0)],
            // y: where the material's own ground blend starts (0: the renderer's look), z: where
            // it ends (pressed through); w: room for rims above the snow top (metres, 0: none).
            translucency: [
                m.translucency,
                m.ground_from.unwrap_or(0.0),
                1.0,
                rim_room(&desc.material, desc.snow_depth),
            ],
            terrain: surface.ground,
            terrain_low: surface.ground_range.0,
            terrain_top: surface.ground_range.1 + desc.snow_depth,
            wrap: surface.wrap,
            hole: surface.hole.unwrap_or(NO_HOLE),
        }
    }

    /// Block `index` of a buffer of these, [`SURFACE_STRIDE`] apart, as a binding.
    pub(crate) fn block(buffer: &wgpu::Buffer, index: usize) -> wgpu::BindingResource<'_> {
        wgpu::BindingResource::Buffer(wgpu::BufferBinding {
            buffer,
            offset: index as u64 * SURFACE_STRIDE,
            size: std::num::NonZeroU64::new(std::mem::size_of::<Self>() as u64),
        })
    }
}

/// Bit of the material's switches (`pattern.z`) where the seam sides begin (`SNOW_SEAM_SIDES` in
/// `snow.wgsl`).
const SEAM_SWITCH_SHIFT: u32 = 2;

/// The material settings of one surface's [`SurfaceUniform`].
pub(crate) struct Shading {
    /// The relief or POM search.
    pub search: crate::render::SearchSettings,
    /// The material's look and switches.
    pub look: crate::render::SnowLook,
    /// `SNOW_GROUND_TILES`, `SNOW_GROUND_CONCRETE` or `SNOW_GROUND_ROCK`.
    pub ground: u32,
    /// The surface's slot in the renderer's per-surface tables.
    pub index: u32,
    /// Strength of the macro waves.
    pub macro_waves: f32,
    /// Sides (bits 0-3: local -x, +x, -z, +z) where its snow meets another surface's
    /// (`tessellate::seams::seam_sides`).
    pub seams: u32,
}

/// One surface for the classify pass. Must match `ClassifyRecord` in `classify.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Pod, Zeroable)]
pub struct ClassifyRecord {
    /// Element offset of the current heightmap in the pool.
    pub heights: u32,
    /// Texels along x.
    pub width: u32,
    /// Texels along z.
    pub height: u32,
    /// Vertices of the box.
    pub box_vertices: u32,
    /// Bits a channel of the pool's heightmaps.
    pub bits: u32,
    /// 1 when the surface takes the deformable material even untouched: on ground that is not
    /// flat (the basic one draws a flat top), or with a hole (the basic one cannot meet the step
    /// at its edge, `surface.wgsl`'s `through_hole`), else 0.
    pub always_deformable: u32,
    /// Toroidal storage offsets (`pool::wrapped`).
    pub wrap: u32,
    /// 1 when anything of the frame can show the surface (`frame::seen`), else 0: its heightfield
    /// and bank passes do not run then.
    pub seen: u32,
    /// Padding.
    pub _pad: [u32; 4],
}

/// One surface for the heightfield pass. Must match `HeightfieldParams` in `heightfield.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct HeightfieldParams {
    /// Element offset of the current heightmap in the pool.
    pub heights: u32,
    /// Texels along x.
    pub width: u32,
    /// Texels along z.
    pub height: u32,
    /// Bits a channel of the pool's heightmaps.
    pub bits: u32,
    /// Snow depth, metres.
    pub snow_depth: f32,
    /// Texel side along x, metres.
    pub texel_x: f32,
    /// Texel side along z, metres.
    pub texel_z: f32,
    /// First texel of the surface's ground field ([`crate::FrameView::ground_buffer`]), or
    /// [`crate::low_level::ground::NO_GROUND`] on flat ground.
    pub ground: u32,
    /// Toroidal storage offsets (`pool::wrapped`).
    pub wrap: u32,
    /// The surface's slot in the frame: its words in the surface state table start at
    /// `slot * STATE_WORDS`.
    pub slot: u32,
    /// Padding (two members, as in WGSL).
    pub _pad: [u32; 2],
    /// Unit direction towards the moon in the surface's local frame; w unused.
    pub light: [f32; 4],
    /// The surfaces beside its sides (local -x, +x, -z, +z), whose texels the pass reads beyond
    /// its edges (`heightfield::sides`).
    pub sides: [HeightfieldSide; 4],
}

/// The surface beside one side of a surface, for the heightfield pass. Must match
/// `HeightfieldSide` in `heightfield.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct HeightfieldSide {
    /// Element offset of its heightmap in the pool.
    pub heights: u32,
    /// Texels along x.
    pub width: u32,
    /// Texels along z.
    pub height: u32,
    /// Bits a channel of its heightmap.
    pub bits: u32,
    /// Its toroidal storage offsets.
    pub wrap: u32,
    /// Its texel along the side is the surface's plus this.
    pub offset: i32,
    /// 1 when a surface lies beside this side, else 0 (the side's texels clamp to the edge).
    pub present: u32,
    /// Padding.
    pub _pad: u32,
}

/// A mesh vertex. Must match `MeshVertex` in `mesh.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct MeshVertexRaw {
    /// Position in the mesh's frame.
    pub position: [f32; 3],
    /// Unit normal.
    pub normal: [f32; 3],
}

/// One instance of a mesh. Must match `MeshInstance` in `mesh.wgsl` (locations 2 to 10).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct InstanceRaw {
    /// Model matrix columns.
    pub model: [[f32; 4]; 4],
    /// Normal matrix columns (inverse transpose of the model's 3x3), w unused.
    pub normal: [[f32; 4]; 3],
    /// Albedo and material.
    pub albedo_material: [f32; 4],
    /// Roughness, emission, snow cover, seed.
    pub params: [f32; 4],
}

/// Vertex buffer layouts of the mesh pipelines.
pub fn mesh_vertex_layouts() -> [wgpu::VertexBufferLayout<'static>; 2] {
    const VERTEX: [wgpu::VertexAttribute; 2] =
        wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3];
    const INSTANCE: [wgpu::VertexAttribute; 9] = wgpu::vertex_attr_array![
        2 => Float32x4, 3 => Float32x4, 4 => Float32x4, 5 => Float32x4,
        6 => Float32x4, 7 => Float32x4, 8 => Float32x4, 9 => Float32x4, 10 => Float32x4
    ];
    [
        wgpu::VertexBufferLayout {
            array_stride: std::mem::size_of::<MeshVertexRaw>() as u64,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &VERTEX,
        },
        wgpu::VertexBufferLayout {
            array_stride: std::mem::size_of::<InstanceRaw>() as u64,
            step_mode: wgpu::VertexStepMode::Instance,
            attributes: &INSTANCE,
        },
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Size and member offsets of a WGSL struct, from naga.
    fn layout(source: &str, name: &str) -> (u32, Vec<(String, u32)>) {
        let module = naga::front::wgsl::parse_str(source)
            .unwrap_or_else(|e| panic!("{}", e.emit_to_string(source)));
        let mut validator = naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::all(),
        );
        validator
            .validate(&module)
            .unwrap_or_else(|e| panic!("{}", e.emit_to_string(source)));
        let (_, ty) = module
            .types
            .iter()
            .find(|(_, t)| t.name.as_deref() == Some(name))
            .unwrap_or_else(|| panic!("no struct {name}"));
        match &ty.inner {
            naga::TypeInner::Struct { members, span } => (
                *span,
                members
                    .iter()
                    .map(|m| (m.name.clone().unwrap_or_default(), m.offset))
                    .collect(),
            ),
            _ => panic!("{name} is not a struct"),
        }
    }

    #[test]
    fn frame_uniform_matches_wgsl() {
        let (size, members) = layout(&crate::wgsl::SKY.wgsl(), "Frame");
        assert_eq!(size as usize, std::mem::size_of::<FrameUniform>());
        let offsets = [
            ("view_proj", std::mem::offset_of!(FrameUniform, view_proj)),
            (
                "inv_view_proj",
                std::mem::offset_of!(FrameUniform, inv_view_proj),
            ),
            (
                "shadow_near",
                std::mem::offset_of!(FrameUniform, shadow_near),
            ),
            ("shadow_far", std::mem::offset_of!(FrameUniform, shadow_far)),
            (
                "shadow_texels",
                std::mem::offset_of!(FrameUniform, shadow_texels),
            ),
            ("eye", std::mem::offset_of!(FrameUniform, eye)),
            ("moon_dir", std::mem::offset_of!(FrameUniform, moon_dir)),
            ("moon_color", std::mem::offset_of!(FrameUniform, moon_color)),
            ("sky_zenith", std::mem::offset_of!(FrameUniform, sky_zenith)),
            (
                "sky_horizon",
                std::mem::offset_of!(FrameUniform, sky_horizon),
            ),
            (
                "ground_bounce",
                std::mem::offset_of!(FrameUniform, ground_bounce),
            ),
            ("sss_tint", std::mem::offset_of!(FrameUniform, sss_tint)),
            (
                "sky_ambient",
                std::mem::offset_of!(FrameUniform, sky_ambient),
            ),
            ("viewport", std::mem::offset_of!(FrameUniform, viewport)),
            ("options", std::mem::offset_of!(FrameUniform, options)),
            ("lights", std::mem::offset_of!(FrameUniform, lights)),
        ];
        for (name, offset) in offsets {
            let m = members
                .iter()
                .find(|m| m.0 == name)
                .unwrap_or_else(|| panic!("no member {name}"));
            assert_eq!(m.1 as usize, offset, "{name}");
        }
    }

    /// The visibility path reads the instance buffer as storage: `InstanceData` of
    /// `opaque/geometry.wgsl` must lay out `InstanceRaw` as the vertex stage's attributes do.
    #[test]
    fn instances_as_storage_match_wgsl() {
        let (size, members) = layout(&crate::wgsl::MESH_SHADE.wgsl(), "InstanceData");
        assert_eq!(size as usize, std::mem::size_of::<InstanceRaw>());
        let offsets = [
            ("model", std::mem::offset_of!(InstanceRaw, model)),
            ("normal_0", std::mem::offset_of!(InstanceRaw, normal)),
            ("normal_1", std::mem::offset_of!(InstanceRaw, normal) + 16),
            ("normal_2", std::mem::offset_of!(InstanceRaw, normal) + 32),
            (
                "albedo_material",
                std::mem::offset_of!(InstanceRaw, albedo_material),
            ),
            ("params", std::mem::offset_of!(InstanceRaw, params)),
        ];
        for (name, offset) in offsets {
            let m = members
                .iter()
                .find(|m| m.0 == name)
                .unwrap_or_else(|| panic!("no member {name}"));
            assert_eq!(m.1 as usize, offset, "{name}");
        }
        // Six floats a vertex, as `geometry.wgsl` indexes `mesh_vertices`.
        assert_eq!(std::mem::size_of::<MeshVertexRaw>(), 24);
    }

    #[test]
    fn surface_uniform_matches_wgsl() {
        let (size, members) = layout(&crate::wgsl::SURFACE.wgsl(), "SnowSurface");
        assert_eq!(size as usize, std::mem::size_of::<SurfaceUniform>());
        let offsets = [
            (
                "local_to_world",
                std::mem::offset_of!(SurfaceUniform, local_to_world),
            ),
            (
                "world_to_local",
                std::mem::offset_of!(SurfaceUniform, world_to_local),
            ),
            ("half_size", std::mem::offset_of!(SurfaceUniform, half_size)),
            (
                "snow_depth",
                std::mem::offset_of!(SurfaceUniform, snow_depth),
            ),
            ("texel", std::mem::offset_of!(SurfaceUniform, texel)),
            ("grid", std::mem::offset_of!(SurfaceUniform, grid)),
            ("ground", std::mem::offset_of!(SurfaceUniform, ground)),
            ("index", std::mem::offset_of!(SurfaceUniform, index)),
            ("search", std::mem::offset_of!(SurfaceUniform, search)),
            ("look", std::mem::offset_of!(SurfaceUniform, look)),
            ("pattern", std::mem::offset_of!(SurfaceUniform, pattern)),
            ("albedo", std::mem::offset_of!(SurfaceUniform, albedo)),
            ("disturbed", std::mem::offset_of!(SurfaceUniform, disturbed)),
            ("grain", std::mem::offset_of!(SurfaceUniform, grain)),
            (
                "translucency",
                std::mem::offset_of!(SurfaceUniform, translucency),
            ),
            ("hole", std::mem::offset_of!(SurfaceUniform, hole)),
            ("wrap", std::mem::offset_of!(SurfaceUniform, wrap)),
        ];
        for (name, offset) in offsets {
            let m = members
                .iter()
                .find(|m| m.0 == name)
                .unwrap_or_else(|| panic!("no member {name}"));
            assert_eq!(m.1 as usize, offset, "{name}");
        }
    }

    /// `SurfaceUniform` has the layout of the engine module's `snowprint_Surface` and of the
    /// material's `SnowSurface`, member by member (the pool's fields included).
    #[test]
    fn surface_uniform_matches_engine_module() {
        let engine = crate::wgsl::engine_module(&Default::default());
        let material = crate::wgsl::material_module(&Default::default());
        macro_rules! offsets {
            ($($f:ident),*) => { [$((stringify!($f), std::mem::offset_of!(SurfaceUniform, $f))),*] };
        }
        let offsets = offsets!(
            local_to_world,
            world_to_local,
            half_size,
            snow_depth,
            texel,
            grid,
            ground,
            index,
            search,
            look,
            pattern,
            heights,
            row_words,
            bits,
            channel_max,
            width,
            height,
            texel_x,
            texel_z,
            albedo,
            disturbed,
            grain,
            translucency,
            terrain,
            terrain_low,
            terrain_top,
            wrap,
            hole
        );
        for (source, name) in [
            (&engine, "snowprint_Surface"),
            (&material, "SnowSurface"),
            (&crate::wgsl::SURFACE.wgsl(), "SnowSurface"),
        ] {
            let (size, members) = layout(source, name);
            assert_eq!(
                size as usize,
                std::mem::size_of::<SurfaceUniform>(),
                "{name}"
            );
            assert_eq!(members.len(), offsets.len(), "{name}");
            for ((field, offset), (member, at)) in offsets.iter().zip(&members) {
                assert_eq!((*field, *offset), (member.as_str(), *at as usize), "{name}");
            }
        }
        assert!(std::mem::size_of::<SurfaceUniform>() as u64 <= SURFACE_STRIDE);
    }

    #[test]
    fn compute_tables_match_wgsl() {
        let (size, _) = layout(&crate::wgsl::CLASSIFY.wgsl(), "ClassifyRecord");
        assert_eq!(size as usize, std::mem::size_of::<ClassifyRecord>());
        let (size, _) = layout(&crate::wgsl::HEIGHTFIELD.wgsl(), "HeightfieldParams");
        assert_eq!(size as usize, std::mem::size_of::<HeightfieldParams>());
        // classify.wgsl writes the state table with the registry's constants (it imports them).
        let classify = naga::front::wgsl::parse_str(&crate::wgsl::CLASSIFY.wgsl()).unwrap();
        let constant = |name: &str| {
            let (_, c) = classify
                .constants
                .iter()
                .find(|(_, c)| c.name.as_deref() == Some(name))
                .unwrap_or_else(|| panic!("classify.wgsl has no {name}"));
            match classify.global_expressions[c.init] {
                naga::Expression::Literal(naga::Literal::U32(v)) => u64::from(v),
                ref e => panic!("{name} = {e:?}"),
            }
        };
        assert_eq!(constant("STATE_WORDS"), STATE_WORDS);
        assert_eq!(constant("STATE_TOUCHED"), STATE_TOUCHED);
    }

    #[test]
    fn instance_layout_covers_the_struct() {
        let [v, i] = mesh_vertex_layouts();
        assert_eq!(v.array_stride, 24);
        assert_eq!(i.array_stride as usize, std::mem::size_of::<InstanceRaw>());
        assert_eq!(i.attributes.len() * 16, std::mem::size_of::<InstanceRaw>());
        assert!(crate::wgsl::files::MESH.contains("@location(10) params"));
    }
}
