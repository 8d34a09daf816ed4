//! What every pass shares: the frame uniform (camera, moon, sky, lights, options; `frame.wgsl`),
//! its bind groups with the moon's shadow map and the samplers, and the frame's list of surfaces
//! as extracted from the world.

use glam::{Vec2, Vec3};

pub(super) mod seen;

use super::cascades::ShadowCascades;
use super::config::{RenderConfig, Tier};
use super::error::RenderResult;
use super::gpu::{FrameUniform, MAX_POINT_LIGHTS, PointLightRaw};
use super::heightfield::{self, Beside, SIDES};

/// Texels the heightfield and bank textures hold beyond each side of a heightmap.
const BORDER: i32 = crate::wgsl::consts::HEIGHTFIELD_BORDER;
use super::inputs::{PointLight, RenderFrame};
use super::tessellate::SurfaceGeometry;
use crate::extract::{FrameView, SurfaceView};
use crate::gpu::resources::bind_group;
use crate::surface::SurfaceId;
use crate::view::GroundMaterial;
use std::collections::HashMap;

/// Near and far planes of the camera, metres.
pub(super) const NEAR: f32 = 0.05;
pub(super) const FAR: f32 = 600.0;

/// A surface of the frame, in the frame's order (its slot in every per-surface table).
pub(super) struct FrameSurface<'a> {
    /// The surface as the world's extract gives it.
    pub view: &'a SurfaceView<'a>,
    /// The ground under its snow.
    pub ground: GroundMaterial,
    /// Its tessellated-tier settings.
    pub geometry: &'a SurfaceGeometry,
    /// Whether it is diced this frame (the tessellated tier, and its geometry asks for it).
    pub tessellated: bool,
    /// The surfaces of the world beside its sides, local -x, +x, -z, +z (`heightfield::sides`).
    pub sides: [Option<Beside<'a>>; SIDES],
    /// Whether it lies in a coarser terrain window level's hole (`tessellate::seams::enclosed`).
    pub enclosed: bool,
    /// Whether anything of the frame can show it (`seen::mark_seen`): the heightfield and bank
    /// passes and the dicing skip the others.
    pub seen: bool,
}

impl FrameSurface<'_> {
    /// Sides of a heightmap texel, metres.
    pub(super) fn texel(&self) -> Vec2 {
        let (desc, layout) = (self.view.desc, self.view.layout);
        Vec2::new(
            desc.size.x / layout.width as f32,
            desc.size.y / layout.height as f32,
        )
    }

    /// Whether its material throws rims (states a compressibility): the relief and POM tiers
    /// then draw the banks above the snow top too.
    pub(super) fn rims(&self) -> bool {
        self.view.desc.material.rim_fraction().is_some()
    }

    /// The texels the bank passes run over, `[x0, z0, x1, z1)` of its heightmap's (its first
    /// at 0): its own and, beyond a side with a surface beside it, the bank texture's border and
    /// as far again as banks reach (the banks there gather snow pushed beyond the line, and need
    /// the norm of where it lands).
    pub(super) fn bank_domain(&self) -> [i32; 4] {
        let texel = self.texel();
        let width = self.banks().width;
        let reach = [width / texel.x, width / texel.y].map(|r| r.floor() as i32 + BORDER);
        let [x0, z0, x1, z1] = self.beyond([reach[0], reach[0], reach[1], reach[1]]);
        let layout = self.view.layout;
        [
            -x0,
            -z0,
            layout.width as i32 + x1,
            layout.height as i32 + z1,
        ]
    }

    /// The texels the heightfield pass runs over: its own and the textures' border beyond each
    /// side with a surface beside it (the border beyond the others repeats the edge, which the
    /// edge's invocations store), as `[x0, z0, x1, z1)`.
    pub(super) fn heightfield_domain(&self) -> [i32; 4] {
        let [x0, z0, x1, z1] = self.beyond([BORDER; 4]);
        let layout = self.view.layout;
        [
            -x0,
            -z0,
            layout.width as i32 + x1,
            layout.height as i32 + z1,
        ]
    }

    /// The heightfield pass's workgroups (8 x 8 texels each) over [`Self::heightfield_domain`].
    pub(super) fn heightfield_workgroups(&self) -> (u32, u32) {
        workgroups(self.heightfield_domain())
    }

    /// The bank passes' workgroups (8 x 8 texels each) over [`Self::bank_domain`].
    pub(super) fn bank_workgroups(&self) -> (u32, u32) {
        workgroups(self.bank_domain())
    }

    /// `by` (texels past -x, +x, -z, +z) where a surface lies beside that side, else 0, as
    /// `[-x, -z, +x, +z]`.
    fn beyond(&self, by: [i32; 4]) -> [i32; 4] {
        let out = |side: usize| {
            if self.sides[side].is_some() {
                by[side]
            } else {
                0
            }
        };
        [out(0), out(2), out(1), out(3)]
    }

    /// Its banks: the geometry's, with the share of the pushed volume set by the material's
    /// compressibility where the material states one (`Material::rim_fraction`).
    pub(super) fn banks(&self) -> crate::render::BankSettings {
        let banks = self.geometry.banks;
        match self.view.desc.material.rim_fraction() {
            Some(fraction) => crate::render::BankSettings { fraction, ..banks },
            None => banks,
        }
    }
}

/// The frame uniform's buffer, its layouts and bind groups (with the shadow map and samplers).
pub(super) struct FrameResources {
    /// Group 0 of the colour passes: uniform, shadow map, comparison and heightfield samplers.
    pub layout: wgpu::BindGroupLayout,
    /// Group 0 of the shadow passes: the uniform alone.
    pub shadow_layout: wgpu::BindGroupLayout,
    buffer: wgpu::Buffer,
    shadow_sampler: wgpu::Sampler,
    linear_sampler: wgpu::Sampler,
    /// Bind groups of `layout` and `shadow_layout` (made once, and `bind_group` again when the
    /// shadow map is replaced: what they bind lives as long).
    pub bind_group: wgpu::BindGroup,
    pub shadow_bind_group: wgpu::BindGroup,
}

/// The frame's bind group layouts (made before the passes, whose pipelines use them).
pub(super) struct FrameLayouts {
    pub layout: wgpu::BindGroupLayout,
    pub shadow_layout: wgpu::BindGroupLayout,
}

impl FrameLayouts {
    pub(super) fn new(device: &wgpu::Device, filterable: bool) -> Self {
        // frame.wgsl's group 0, the same in every module that imports it (OVERRIDES give it the
        // stages of all of them); the shadow passes' is what their vertex entry points read.
        let layout = crate::wgsl::SURFACE.bind_group_layout_for(device, "frame", 0, filterable);
        let shadow_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("shadow frame"),
            entries: &crate::wgsl::MESH.layout_entries_of(&["vs_shadow"], 0, filterable),
        });
        Self {
            layout,
            shadow_layout,
        }
    }
}

impl FrameResources {
    /// The uniform buffer, samplers and bind groups over the moon's shadow map `shadow_view`.
    pub(super) fn new(
        device: &wgpu::Device,
        layouts: FrameLayouts,
        shadow_view: &wgpu::TextureView,
        filterable: bool,
    ) -> Self {
        let shadow_sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("shadow comparison"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            compare: Some(wgpu::CompareFunction::LessEqual),
            ..Default::default()
        });
        let filter = if filterable {
            wgpu::FilterMode::Linear
        } else {
            wgpu::FilterMode::Nearest
        };
        let linear_sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("heightfield"),
            mag_filter: filter,
            min_filter: filter,
            ..Default::default()
        });
        let buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("frame uniforms"),
            size: std::mem::size_of::<FrameUniform>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let colour_group = colour_group(
            device,
            &layouts.layout,
            &buffer,
            shadow_view,
            [&shadow_sampler, &linear_sampler],
        );
        let shadow_bind_group = bind_group(
            device,
            "shadow frame",
            &layouts.shadow_layout,
            &[buffer.as_entire_binding()],
        );
        Self {
            layout: layouts.layout,
            shadow_layout: layouts.shadow_layout,
            buffer,
            shadow_sampler,
            linear_sampler,
            bind_group: colour_group,
            shadow_bind_group,
        }
    }

    /// The colour passes' group over a new shadow map.
    pub(super) fn rebind_shadow_map(
        &mut self,
        device: &wgpu::Device,
        shadow_view: &wgpu::TextureView,
    ) {
        self.bind_group = colour_group(
            device,
            &self.layout,
            &self.buffer,
            shadow_view,
            [&self.shadow_sampler, &self.linear_sampler],
        );
    }

    /// Upload the frame's uniform.
    pub(super) fn prepare(&self, queue: &wgpu::Queue, uniform: &FrameUniform) {
        queue.write_buffer(&self.buffer, 0, bytemuck::bytes_of(uniform));
    }
}

/// Group 0 of the colour passes: the uniform, the shadow map and the two samplers.
fn colour_group(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    buffer: &wgpu::Buffer,
    shadow_view: &wgpu::TextureView,
    [shadow_sampler, linear_sampler]: [&wgpu::Sampler; 2],
) -> wgpu::BindGroup {
    bind_group(
        device,
        "frame",
        layout,
        &[
            buffer.as_entire_binding(),
            wgpu::BindingResource::TextureView(shadow_view),
            wgpu::BindingResource::Sampler(shadow_sampler),
            wgpu::BindingResource::Sampler(linear_sampler),
        ],
    )
}

/// The frame uniform of a frame: camera, moon and sky, the 8 lights nearest the camera, options.
pub(super) fn frame_uniform(
    cfg: &RenderConfig,
    frame: &RenderFrame<'_>,
    shadow: &ShadowCascades,
) -> FrameUniform {
    let (w, h) = (cfg.width * cfg.supersample, cfg.height * cfg.supersample);
    let aspect = w as f32 / h as f32;
    let view_proj = frame.camera.projection(aspect, NEAR, FAR) * frame.camera.view();
    let e = &frame.environment;
    let v4 = |v: Vec3, w: f32| [v.x, v.y, v.z, w];
    // The 8 lights nearest the camera.
    let mut lights: Vec<&PointLight> = frame.lights.iter().collect();
    lights.sort_by(|a, b| {
        a.position
            .distance_squared(frame.camera.eye)
            .total_cmp(&b.position.distance_squared(frame.camera.eye))
    });
    lights.truncate(MAX_POINT_LIGHTS);
    let mut raw = [PointLightRaw::default(); MAX_POINT_LIGHTS];
    for (r, l) in raw.iter_mut().zip(&lights) {
        *r = PointLightRaw {
            position_radius: v4(l.position, l.radius),
            color: v4(l.color, 0.0),
        };
    }
    // Surfaces the tessellated tier does not tessellate are relief mapped.
    let tier = match cfg.tier {
        Tier::Relief | Tier::Tessellated => 0,
        Tier::Pom => 1,
    };
    FrameUniform {
        view_proj: view_proj.to_cols_array_2d(),
        inv_view_proj: view_proj.inverse().to_cols_array_2d(),
        shadow_near: shadow.near.to_cols_array_2d(),
        shadow_far: shadow.far.to_cols_array_2d(),
        shadow_texels: [shadow.near_texel, shadow.far_texel, 0.0, 0.0],
        eye: v4(frame.camera.eye, frame.time),
        moon_dir: v4(
            e.moon_direction.normalize(),
            e.moon_radius_degrees.to_radians().cos(),
        ),
        moon_color: v4(e.moon_color, 0.0),
        sky_zenith: v4(e.sky_zenith, e.exposure),
        sky_horizon: v4(e.sky_horizon, e.fog_density),
        ground_bounce: v4(e.ground_bounce, e.city_glow),
        sss_tint: v4(e.sss_tint, e.sss_strength),
        sky_ambient: v4(e.sky_ambient, 0.0),
        viewport: [w as f32, h as f32, 1.0 / w as f32, 1.0 / h as f32],
        options: [
            cfg.debug_view.code(),
            lights.len() as u32,
            tier,
            if frame.snowfall { cfg.snowflakes } else { 0 },
        ],
        lights: raw,
    }
}

/// The frame's surfaces in its order, each looked up in the world's extract (a surface the world
/// does not hold is the world's error), with its tessellated-tier settings.
pub(super) fn frame_surfaces<'a>(
    view: &'a FrameView<'a>,
    frame: &RenderFrame<'_>,
    geometry: &'a HashMap<SurfaceId, SurfaceGeometry>,
    default_geometry: &'a SurfaceGeometry,
    tessellated_tier: bool,
) -> RenderResult<Vec<FrameSurface<'a>>> {
    let mut besides = heightfield::besides(&view.surfaces, frame.surfaces.iter().map(|s| s.0));
    let drawn: Vec<_> = frame
        .surfaces
        .iter()
        .map(|&(id, _)| view.surface(id))
        .collect::<Result<_, _>>()?;
    frame
        .surfaces
        .iter()
        .zip(&drawn)
        .zip(besides.drain(..))
        .map(|((&(id, ground), &view), sides)| {
            let geometry = geometry.get(&id).unwrap_or(default_geometry);
            Ok(FrameSurface {
                view,
                ground,
                geometry,
                tessellated: tessellated_tier && geometry.tessellate,
                sides,
                enclosed: super::tessellate::seams::enclosed(view, &drawn),
                seen: true,
            })
        })
        .collect()
}

/// The workgroups of 8 x 8 texels that cover a domain `[x0, z0, x1, z1)`.
fn workgroups([x0, z0, x1, z1]: [i32; 4]) -> (u32, u32) {
    let side = |a: i32, b: i32| (b - a).max(0).unsigned_abs().div_ceil(8);
    (side(x0, x1), side(z0, z1))
}
