//! The `snow` pass (`surface.wgsl` over the material `snow.wgsl`): each snow surface drawn as the
//! box of its slab, with indirect draws written by `classify`: the basic material for untouched
//! snow, the deformable one (relief mapping or POM through the heightfield) for the rest. In the
//! tessellated tier the diced surfaces are drawn after, in a second render pass (see
//! [`TessSurface`]); the pass's timestamps span both.

use super::config::RenderConfig;
use super::frame::FrameSurface;
use super::gpu::{
    STATE_BASIC_DRAW, STATE_DEFORMABLE_DRAW, STATE_WORDS, SURFACE_STRIDE, Shading, SurfaceUniform,
};
use super::graph::PASSES;
use super::heightfield::HeightfieldPass;
use super::pipeline;
use super::readback::{Timestamps, render_span};
use super::targets::{KEEP, Targets};
use super::tessellate::dice::DicePass;
use super::tessellate::snow_shadow::TessSurface;
use crate::gpu::resources::{Growable, bind_group};
use crate::view::GroundMaterial;

pub(super) struct SnowPass {
    layout: wgpu::BindGroupLayout,
    basic: wgpu::RenderPipeline,
    deformable: wgpu::RenderPipeline,
    /// Per surface: `SurfaceUniform` in a uniform block (also bound by the tessellated draws).
    pub uniforms: Growable,
    /// This frame's group 1 per surface slot; `None` where the tessellated tier dices it.
    bind_groups: Vec<Option<wgpu::BindGroup>>,
}

impl SnowPass {
    pub(super) fn new(
        device: &wgpu::Device,
        frame_layout: &wgpu::BindGroupLayout,
        filterable: bool,
    ) -> Self {
        let layout =
            crate::wgsl::SURFACE.bind_group_layout_for(device, "snow surface", 1, filterable);
        let module = pipeline::shader(device, "surface.wgsl", crate::wgsl::SURFACE.wgsl());
        let snow = |label, vs, fs, constants, primitive| {
            pipeline::Raster {
                label,
                module: &module,
                vs,
                fs,
                buffers: &[],
                groups: &[frame_layout, &layout],
                primitive,
                depth: pipeline::depth_state(wgpu::CompareFunction::LessEqual, true),
                targets: &pipeline::hdr_target(),
                constants,
            }
            .build(device)
        };
        let basic = snow(
            "snow basic",
            "vs_surface",
            "fs_basic",
            &[],
            pipeline::back_culled(),
        );
        // Both sides: `fs_deformable` keeps the front faces of a box seen from outside and the back
        // faces of one seen from inside.
        let deformable = snow(
            "snow deformable",
            "vs_surface_deformable",
            "fs_deformable",
            pipeline::manual_filter(filterable),
            wgpu::PrimitiveState::default(),
        );
        Self {
            uniforms: Growable::new(
                device,
                "snow surfaces",
                wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                SURFACE_STRIDE * 8,
            ),
            layout,
            basic,
            deformable,
            bind_groups: Vec::new(),
        }
    }

    /// Upload each surface's uniform (transform, grid, ground, search, look and its material's
    /// look) and bind it with its heightfield textures and the world's ground fields.
    pub(super) fn prepare(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        cfg: &RenderConfig,
        surfaces: &[FrameSurface<'_>],
        heightfields: &HeightfieldPass,
        ground: &wgpu::Buffer,
    ) {
        let search = cfg.search_settings();
        let look = cfg.look;
        let stride = SURFACE_STRIDE as usize;
        let mut bytes = vec![0u8; surfaces.len().max(1) * stride];
        for (s, surface) in surfaces.iter().enumerate() {
            let shading = Shading {
                search,
                look,
                ground: match surface.ground {
                    GroundMaterial::RoofTiles => 0,
                    GroundMaterial::Concrete => 1,
                },
                index: s as u32,
                macro_waves: surface.geometry.macro_waves,
            };
            let u = SurfaceUniform::shaded(surface.view, &shading);
            bytes[s * stride..s * stride + std::mem::size_of::<SurfaceUniform>()]
                .copy_from_slice(bytemuck::bytes_of(&u));
        }
        self.uniforms.ensure(device, bytes.len() as u64);
        queue.write_buffer(&self.uniforms.buffer, 0, &bytes);
        self.bind_groups = surfaces
            .iter()
            .enumerate()
            .map(|(s, surface)| {
                if surface.tessellated {
                    return None;
                }
                let tex = heightfields.texture(surface.view.id)?;
                Some(bind_group(
                    device,
                    "snow surface",
                    &self.layout,
                    &[
                        SurfaceUniform::block(&self.uniforms.buffer, s),
                        wgpu::BindingResource::TextureView(&tex.shape),
                        wgpu::BindingResource::TextureView(&tex.light),
                        wgpu::BindingResource::TextureView(&tex.bank),
                        ground.as_entire_binding(),
                    ],
                ))
            })
            .collect();
    }

    /// The relief-mapped surfaces (indirect draws of both materials), then the diced ones.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        ts: Option<&Timestamps>,
        slot: usize,
        targets: &Targets,
        frame: &wgpu::BindGroup,
        state: &wgpu::Buffer,
        tess: &TessSurface,
        dice: &DicePass,
    ) {
        {
            let attachments = targets.color(wgpu::LoadOp::Load);
            let mut p = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some(PASSES[slot].name),
                color_attachments: &attachments,
                depth_stencil_attachment: targets.depth(KEEP),
                // The pass's time spans this render pass and the tessellated one after it.
                timestamp_writes: render_span(ts, slot, true, false),
                occlusion_query_set: None,
                multiview_mask: None,
            });
            p.set_bind_group(0, frame, &[]);
            for (pipeline, offset) in [
                (&self.basic, STATE_BASIC_DRAW),
                (&self.deformable, STATE_DEFORMABLE_DRAW),
            ] {
                p.set_pipeline(pipeline);
                for (s, bg) in self.bind_groups.iter().enumerate() {
                    if let Some(bg) = bg {
                        p.set_bind_group(1, bg, &[]);
                        p.draw_indirect(state, (s as u64 * STATE_WORDS + offset) * 4);
                    }
                }
            }
        }
        let attachments = targets.color(wgpu::LoadOp::Load);
        let mut p = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("snow (tessellated)"),
            color_attachments: &attachments,
            depth_stencil_attachment: targets.depth(KEEP),
            timestamp_writes: render_span(ts, slot, false, true),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        tess.draw(&mut p, frame, dice);
    }
}
