//! The tessellated tier's snow (`tess_surface.wgsl`): the diced mesh displaced in the vertex
//! stage and shaded with the snow material, drawn into the moon's shadow cascades by the
//! `snow_shadow` pass and into the scene by the `snow` pass (after the relief-mapped surfaces).
//! Both draws bind a surface's uniform, heightfield and bank textures and state as group 1. On
//! the visibility path the scene's draw writes the visibility buffer, and `shade_tess` shades it
//! in the `snow_shade` pass (as the relief tier's `snow/visible.rs`).

use super::VERTEX_BYTES;
use super::dice::DicePass;
use crate::gpu::resources::KeptGroups;
use crate::render::frame::FrameSurface;
use crate::render::gpu::SurfaceUniform;
use crate::render::heightfield::HeightfieldPass;
use crate::render::pipeline;
use crate::render::readback::{Timestamps, compute_pass};
use crate::render::shadow::ShadowPass;

pub(in crate::render) struct TessSurface {
    layout: wgpu::BindGroupLayout,
    /// The tessellated snow into the scene.
    draw: wgpu::RenderPipeline,
    /// The tessellated snow into each shadow cascade.
    shadow: [wgpu::RenderPipeline; 2],
    /// This frame's group 1 per surface slot; `None` where it is not diced.
    pub bind_groups: Vec<Option<wgpu::BindGroup>>,
    /// The groups by surface slot, kept while what they bind stays.
    kept: KeptGroups,
    /// On the visibility path: the draw into the visibility buffer, and its shading.
    visible: Option<(wgpu::RenderPipeline, wgpu::ComputePipeline)>,
}

impl TessSurface {
    pub(crate) fn new(
        device: &wgpu::Device,
        frame_layout: &wgpu::BindGroupLayout,
        (shadow_layout, shadow_format): (&wgpu::BindGroupLayout, wgpu::TextureFormat),
        filterable: bool,
        visible_targets: Option<&wgpu::BindGroupLayout>,
    ) -> Self {
        let layout = crate::wgsl::TESS_SURFACE.bind_group_layout_for(
            device,
            "tessellated snow surface",
            1,
            filterable,
        );
        let module = pipeline::shader(
            device,
            "tess_surface.wgsl",
            crate::wgsl::TESS_SURFACE.wgsl(),
        );
        const VERTEX: [wgpu::VertexAttribute; 2] =
            wgpu::vertex_attr_array![0 => Float32x4, 1 => Float32x4];
        let buffers = [Some(wgpu::VertexBufferLayout {
            array_stride: VERTEX_BYTES,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &VERTEX,
        })];
        let raster = |label, fs, targets: &[Option<wgpu::ColorTargetState>]| {
            pipeline::Raster {
                label,
                module: &module,
                vs: "vs_tess",
                fs,
                buffers: &buffers,
                groups: &[frame_layout, &layout],
                // Skirts face outwards whichever way a mesh is wound: no culling.
                primitive: wgpu::PrimitiveState::default(),
                depth: pipeline::depth_state(wgpu::CompareFunction::LessEqual, true),
                targets,
                constants: pipeline::manual_filter(filterable),
            }
            .build(device)
        };
        let draw = raster("snow tessellated", "fs_tess", &pipeline::hdr_target());
        let visible = visible_targets.map(|targets_layout| {
            let draw = raster(
                "snow tessellated (visibility)",
                "fs_tess_visible",
                &pipeline::visibility_targets(),
            );
            let shade = pipeline::compute_with(
                device,
                "snow shade (tessellated)",
                (&module, "shade_tess"),
                &[frame_layout, &layout, targets_layout],
                pipeline::manual_filter(filterable),
            );
            (draw, shade)
        });
        let shadow_pipeline_layout =
            pipeline::layout(device, "snow shadow", &[shadow_layout, &layout]);
        let shadow = pipeline::ShadowCaster {
            label: "snow shadow",
            layout: &shadow_pipeline_layout,
            module: &module,
            entry: "vs_tess_shadow",
            buffers: &buffers,
            constant: "TESS_SHADOW_CASCADE",
            format: shadow_format,
            // Skirts face outwards whichever way a mesh is wound: no culling.
            primitive: wgpu::PrimitiveState::default(),
        }
        .build(device);
        Self {
            layout,
            draw,
            shadow,
            bind_groups: Vec::new(),
            kept: KeptGroups::default(),
            visible,
        }
    }

    /// Bind each diced surface's uniform (in the snow pass's `surfaces` buffer), textures, the
    /// world's ground fields and the surface state.
    pub(crate) fn prepare(
        &mut self,
        device: &wgpu::Device,
        surfaces: &[FrameSurface<'_>],
        uniforms: &wgpu::Buffer,
        heightfields: &HeightfieldPass,
        state: &wgpu::Buffer,
        ground: &wgpu::Buffer,
    ) {
        let tv = wgpu::BindingResource::TextureView;
        self.kept.truncate(surfaces.len());
        let (kept, layout) = (&mut self.kept, &self.layout);
        self.bind_groups = surfaces
            .iter()
            .enumerate()
            .map(|(s, surface)| {
                if !surface.tessellated {
                    return None;
                }
                let tex = heightfields.texture(surface.view.id)?;
                Some(kept.get(
                    device,
                    "tessellated snow surface",
                    layout,
                    s,
                    &[
                        SurfaceUniform::block(uniforms, s),
                        tv(&tex.shape),
                        tv(&tex.light),
                        tv(&tex.bank),
                        ground.as_entire_binding(),
                        state.as_entire_binding(),
                    ],
                ))
            })
            .collect();
    }

    /// The `snow_shadow` pass: the displaced snow into both cascades, over the meshes' shadows.
    pub(crate) fn encode_shadow(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        ts: Option<&Timestamps>,
        slot: usize,
        shadow_frame: &wgpu::BindGroup,
        shadow: &ShadowPass,
        dice: &DicePass,
    ) {
        if !dice.any() {
            // Nothing diced (the relief and POM tiers): no render pass into the cascades, which
            // would only load and store them; an empty compute pass keeps the pass's timestamps.
            if ts.is_some() {
                drop(compute_pass(encoder, ts, slot));
            }
            return;
        }
        for cascade in 0..2 {
            let label = if cascade == 0 {
                "snow shadow (near cascade)"
            } else {
                "snow shadow (far cascade)"
            };
            let mut p = shadow.cascade_pass(encoder, ts, slot, cascade, label, false);
            p.set_pipeline(&self.shadow[cascade]);
            p.set_bind_group(0, shadow_frame, &[]);
            dice.draw(&mut p, &self.bind_groups);
        }
    }

    /// The tessellated snow into the scene (within the `snow` pass): into the visibility buffer
    /// where `visible` (the pass's attachments are then the visibility buffer and the hits).
    pub(crate) fn draw(
        &self,
        p: &mut wgpu::RenderPass<'_>,
        frame: &wgpu::BindGroup,
        dice: &DicePass,
        visible: bool,
    ) {
        if dice.any() {
            match (&self.visible, visible) {
                (Some((draw, _)), true) => p.set_pipeline(draw),
                _ => p.set_pipeline(&self.draw),
            }
            p.set_bind_group(0, frame, &[]);
            dice.draw(p, &self.bind_groups);
        }
    }

    /// The diced surfaces' dispatches of the `snow_shade` pass (`dispatches`: workgroups per
    /// surface slot, `None` where it is not shaded), with the shading's targets bound as group 2.
    pub(crate) fn encode_shade(
        &self,
        p: &mut wgpu::ComputePass<'_>,
        dispatches: &[Option<(u32, u32)>],
    ) {
        let Some((_, shade)) = &self.visible else {
            return;
        };
        p.set_pipeline(shade);
        for (group, dispatch) in self.bind_groups.iter().zip(dispatches) {
            if let (Some(group), Some((x, y))) = (group, dispatch) {
                p.set_bind_group(1, group, &[]);
                p.dispatch_workgroups(*x, *y, 1);
            }
        }
    }
}
