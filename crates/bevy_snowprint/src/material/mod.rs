//! The snow material: Bevy's `StandardMaterial` extended with snowprint's relief tier
//! (`snow_material.wesl`), and the box of snow each [`SnowSurface`] is drawn as.

use bevy::asset::{RenderAssetUsages, uuid_handle};
use bevy::light::NotShadowCaster;
use bevy::pbr::{ExtendedMaterial, MaterialExtension, MaterialPlugin};
use bevy::prelude::*;
use bevy::render::render_resource::AsBindGroup;
use bevy::render::storage::ShaderBuffer;
use bevy::shader::ShaderRef;
use snowprint::wgsl::{ImportOptions, material_module};

use crate::SnowSurface;

/// Bevy's PBR material with snowprint's relief-mapped snow on top: what the plugin gives every
/// [`SnowSurface`].
pub type SnowMaterial = ExtendedMaterial<StandardMaterial, SnowExtension>;

/// The snow's part of [`SnowMaterial`]: where its surface and heights are bound. Both buffers are
/// written by the render world each frame, after the snow's update, in the same command encoder.
#[derive(Asset, AsBindGroup, Reflect, Debug, Clone)]
pub struct SnowExtension {
    /// The surface as snowprint's material sees it (`SurfaceUniform`, its heights at word 0).
    #[storage(100, read_only)]
    pub surface: Handle<ShaderBuffer>,
    /// This surface's heights, copied from the pool each frame.
    #[storage(101, read_only)]
    pub heights: Handle<ShaderBuffer>,
}

/// The material's fragment shader, put into `Assets<Shader>` by the plugin.
pub const SNOW_SHADER: Handle<Shader> = uuid_handle!("5b0f6a47-2c1e-4d0b-9a7e-3c5f1d2e8b41");

impl MaterialExtension for SnowExtension {
    fn fragment_shader() -> ShaderRef {
        SNOW_SHADER.into()
    }
}

/// Where the material binds the heights: Bevy's material group, after StandardMaterial's.
const POOL_BINDING: ImportOptions = ImportOptions {
    group: 3,
    pool_binding: 101,
};

/// The fragment shader's full text: this crate's WESL, then snowprint's material module (plain
/// WGSL, its names prefixed `snow`/`snowprint_`, which WESL reads as is).
pub fn shader_source() -> String {
    format!(
        "{}\n// ---- snowprint::wgsl::material_module ----\n{}",
        include_str!("snow_material.wesl"),
        material_module(&POOL_BINDING)
    )
}

/// Register the material and its shader.
pub(crate) fn build(app: &mut App) {
    app.add_plugins(MaterialPlugin::<SnowMaterial>::default());
    let shader = Shader::from_wesl(shader_source(), "bevy_snowprint/snow_material.wesl");
    let _ = app
        .world_mut()
        .resource_mut::<Assets<Shader>>()
        .insert(SNOW_SHADER.id(), shader);
    app.add_systems(PostUpdate, dress_new_surfaces);
}

/// The buffers a surface's material reads, kept on its entity for the render world.
#[derive(Component, Clone, Debug)]
pub struct SnowSurfaceBuffers {
    /// `SurfaceUniform` (336 bytes).
    pub surface: Handle<ShaderBuffer>,
    /// The heights region, as many bytes as the surface can take at any precision.
    pub heights: Handle<ShaderBuffer>,
}

/// Bytes of a surface's heights at the widest precision (32 bits: two planes of a word a texel).
pub(crate) fn heights_capacity(resolution: UVec2) -> u64 {
    2 * 4 * u64::from(resolution.x) * u64::from(resolution.y)
}

/// Give each new surface its box mesh, its material and the buffers the material reads.
#[allow(clippy::type_complexity)]
fn dress_new_surfaces(
    mut commands: Commands,
    surfaces: Query<(Entity, &SnowSurface), Without<SnowSurfaceBuffers>>,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<SnowMaterial>>,
    mut buffers: ResMut<Assets<ShaderBuffer>>,
) {
    for (entity, surface) in &surfaces {
        let uniform = ShaderBuffer::with_size(
            std::mem::size_of::<snowprint::SurfaceUniform>() as u64,
            RenderAssetUsages::RENDER_WORLD,
        );
        let heights = ShaderBuffer::with_size(
            heights_capacity(surface.resolution()),
            RenderAssetUsages::RENDER_WORLD,
        );
        let handles = SnowSurfaceBuffers {
            surface: buffers.add(uniform),
            heights: buffers.add(heights),
        };
        let depth = surface.snow_depth;
        let mesh = Cuboid::new(surface.size.x, depth, surface.size.y)
            .mesh()
            .build()
            .translated_by(Vec3::Y * depth * 0.5);
        let material = materials.add(SnowMaterial {
            base: StandardMaterial::default(),
            extension: SnowExtension {
                surface: handles.surface.clone(),
                heights: handles.heights.clone(),
            },
        });
        commands.entity(entity).insert((
            Mesh3d(meshes.add(mesh)),
            MeshMaterial3d(material),
            // The box's top would shade the prints and the feet in them; the relief search
            // shadows the prints' walls itself.
            NotShadowCaster,
            handles,
        ));
    }
}
