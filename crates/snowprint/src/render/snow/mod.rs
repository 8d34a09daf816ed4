//! The `snow` pass (`surface.wgsl` over the material `snow.wgsl`): each snow surface drawn as the
//! box of its slab, with indirect draws written by `classify`: the basic material for untouched
//! snow, the deformable one (relief mapping or POM through the heightfield) for the rest. In the
//! tessellated tier the diced surfaces are drawn after, in a second render pass (see
//! [`TessSurface`]); the pass's timestamps span both. On the visibility path the relief-mapped
//! surfaces' fragments only trace, and the `snow_shade` pass shades their hits in compute
//! ([`visible`]).

mod visible;

/// Most surfaces a frame may draw ([`super::RenderFrame`]'s check refuses more).
pub(super) const SURFACES_MAX: usize = visible::SLOTS;

use super::config::{OpaquePath, RenderConfig};
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
use super::tessellate::seams::seam_sides;
use super::tessellate::snow_shadow::TessSurface;
use crate::gpu::resources::{Growable, KeptGroups};
use crate::view::GroundMaterial;

pub(super) struct SnowPass {
    layout: wgpu::BindGroupLayout,
    basic: wgpu::RenderPipeline,
    /// Both sides of the box: for a box the eye is in (or too near to tell).
    deformable: wgpu::RenderPipeline,
    /// Front faces only: for a box the eye is outside of, whose back faces would all be
    /// discarded (on GPUs with few graphics units, launching them costs).
    deformable_outside: wgpu::RenderPipeline,
    /// Per surface slot this frame: whether the eye is clearly outside its box.
    outside: Vec<bool>,
    /// This frame's tessellated surfaces: each one's uniform and how far its snow may rise above
    /// its box (what `snow_shadow` draws into the moon's cascades).
    tessellated: Vec<(SurfaceUniform, f32)>,
    /// Per surface: `SurfaceUniform` in a uniform block (also bound by the tessellated draws).
    pub uniforms: Growable,
    /// This frame's group 1 per surface slot; `None` where the tessellated tier dices it.
    bind_groups: Vec<Option<wgpu::BindGroup>>,
    /// The groups by surface slot, kept while what they bind stays.
    kept: KeptGroups,
    /// The pipelines of the visibility path (only on `OpaquePath::Visibility`).
    visible: Option<visible::VisiblePath>,
}

impl SnowPass {
    pub(super) fn new(
        device: &wgpu::Device,
        frame_layout: &wgpu::BindGroupLayout,
        filterable: bool,
        path: OpaquePath,
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
        // Seen from outside, the ray enters at the rasterised face and the hit lies beyond it:
        // the depth written is never less than the face's, which the device may be told
        // (conservative depth), so that it rejects a fragment behind what is already drawn
        // before tracing it.
        let outside_module = device
            .features()
            .contains(wgpu::Features::SHADER_EARLY_DEPTH_TEST)
            .then(conservative_surface_wgsl)
            .flatten()
            .map(|text| pipeline::shader(device, "surface.wgsl (outside)", text));
        let outside_module = outside_module.as_ref().unwrap_or(&module);
        let deformable_outside = pipeline::Raster {
            label: "snow deformable (outside)",
            module: outside_module,
            vs: "vs_surface_deformable",
            fs: "fs_deformable",
            buffers: &[],
            groups: &[frame_layout, &layout],
            primitive: pipeline::back_culled(),
            depth: pipeline::depth_state(wgpu::CompareFunction::LessEqual, true),
            targets: &pipeline::hdr_target(),
            constants: pipeline::manual_filter(filterable),
        }
        .build(device);
        let visible = (path == OpaquePath::Visibility).then(|| {
            visible::VisiblePath::new(
                device,
                &visible::Modules {
                    plain: &module,
                    outside: outside_module,
                    frame_layout,
                    surface_layout: &layout,
                    constants: pipeline::manual_filter(filterable),
                },
            )
        });
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
            deformable_outside,
            outside: Vec::new(),
            tessellated: Vec::new(),
            bind_groups: Vec::new(),
            kept: KeptGroups::default(),
            visible,
        }
    }

    /// Upload each surface's uniform (transform, grid, ground, search, look and its material's
    /// look), bind it with its heightfield textures and the world's ground fields, and note
    /// whether `eye` (world) is outside its box; on the visibility path, where on the `targets`
    /// each relief-mapped box lies under `view_proj`.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn prepare(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        cfg: &RenderConfig,
        surfaces: &[FrameSurface<'_>],
        heightfields: &HeightfieldPass,
        ground: &wgpu::Buffer,
        targets: &Targets,
        (eye, view_proj): (glam::Vec3, glam::Mat4),
    ) {
        let search = cfg.search_settings();
        self.outside.clear();
        self.tessellated.clear();
        let look = cfg.look;
        let stride = SURFACE_STRIDE as usize;
        let mut bytes = vec![0u8; surfaces.len().max(1) * stride];
        let mut uniforms = Vec::with_capacity(surfaces.len());
        for (s, surface) in surfaces.iter().enumerate() {
            let shading = Shading {
                search,
                look,
                ground: match surface.ground {
                    GroundMaterial::RoofTiles => 0,
                    GroundMaterial::Concrete => 1,
                    GroundMaterial::Rock => 2,
                },
                index: s as u32,
                macro_waves: surface.geometry.macro_waves,
                seams: seam_sides(surface.enclosed, surface.sides.map(|s| s.is_some())),
            };
            let u = SurfaceUniform::shaded(surface.view, &shading);
            self.outside.push(eye_outside_box(&u, eye));
            if surface.tessellated {
                self.tessellated.push((u, tessellated_rise(&u)));
            }
            uniforms.push(u);
            bytes[s * stride..s * stride + std::mem::size_of::<SurfaceUniform>()]
                .copy_from_slice(bytemuck::bytes_of(&u));
        }
        self.uniforms.write_whole(device, queue, &bytes);
        self.kept.truncate(surfaces.len());
        let (kept, layout) = (&mut self.kept, &self.layout);
        self.bind_groups = surfaces
            .iter()
            .enumerate()
            .map(|(s, surface)| {
                if surface.tessellated {
                    return None;
                }
                let tex = heightfields.texture(surface.view.id)?;
                Some(kept.get(
                    device,
                    "snow surface",
                    layout,
                    s,
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
        if let Some(v) = &mut self.visible {
            let shaded: Vec<Option<f32>> = surfaces
                .iter()
                .zip(&self.bind_groups)
                .zip(&uniforms)
                .map(|((surface, group), u)| match (surface.tessellated, group) {
                    (true, _) => heightfields
                        .texture(surface.view.id)
                        .map(|_| tessellated_rise(u)),
                    (false, Some(_)) => Some(0.0),
                    (false, None) => None,
                })
                .collect();
            v.prepare(device, queue, targets, &uniforms, &shaded, view_proj);
        }
    }

    /// Per shadow cascade (world to its clip space, `cascades`), the texels of a `size` map that
    /// this frame's displaced snow can cover.
    pub(super) fn shadow_rects(&self, cascades: [glam::Mat4; 2], size: u32) -> [Vec<[u32; 4]>; 2] {
        cascades.map(|m| {
            self.tessellated
                .iter()
                .filter_map(|(u, rise)| visible::screen_rect(u, *rise, m, (size, size)))
                .collect()
        })
    }

    /// The layout of the visibility path's shading targets (`None` on the forward path).
    pub(super) fn shade_targets_layout(&self) -> Option<&wgpu::BindGroupLayout> {
        self.visible
            .as_ref()
            .map(visible::VisiblePath::targets_layout)
    }

    /// The `snow_shade` pass: on the visibility path, the snow's hits shaded in compute, the
    /// relief-mapped surfaces' and the diced ones' (an empty compute pass on the forward path).
    pub(super) fn encode_shade(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        ts: Option<&Timestamps>,
        slot: usize,
        frame: &wgpu::BindGroup,
        tess: &TessSurface,
    ) {
        match &self.visible {
            Some(v) => v.encode_shade(encoder, ts, slot, frame, &self.bind_groups, tess),
            None => drop(super::readback::compute_pass(encoder, ts, slot)),
        }
    }

    /// The relief-mapped surfaces (indirect draws of both materials), then the diced ones. Only
    /// the render passes that draw are recorded (an empty one costs the CPU its encoding all the
    /// same): the slot's time spans the first to the last, and a frame that draws no snow records
    /// the last one empty for its timestamps.
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
        let scene = targets.color(wgpu::LoadOp::Load);
        let visible = self.visible.as_ref().zip(targets.snow_visible());
        let relief = self.bind_groups.iter().any(Option::is_some);
        let recorded = [
            relief,
            relief && visible.is_some(),
            dice.any() || (!relief && ts.is_some()),
        ];
        let first = recorded.iter().position(|&r| r);
        let last = recorded.iter().rposition(|&r| r);
        let span = |k: usize| render_span(ts, slot, first == Some(k), last == Some(k));
        if recorded[0] {
            // On the visibility path the basic material tells the visibility buffer too.
            let basic_visible = visible.as_ref().zip(targets.snow_basic_visible());
            let (attachments, basic): (&[_], _) = match &basic_visible {
                Some(((v, _), attachments)) => (attachments, &v.basic),
                None => (&scene, &self.basic),
            };
            let mut p = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some(PASSES[slot].name),
                color_attachments: attachments,
                depth_stencil_attachment: targets.depth(KEEP),
                timestamp_writes: span(0),
                occlusion_query_set: None,
                multiview_mask: None,
            });
            p.set_bind_group(0, frame, &[]);
            p.set_pipeline(basic);
            self.draw_each(&mut p, state, STATE_BASIC_DRAW, |_| true);
            if visible.is_none() {
                self.draw_deformable(&mut p, state, [&self.deformable_outside, &self.deformable]);
            }
        }
        // On the visibility path the deformable material writes the visibility buffer and its
        // hits, not the scene's colour: a render pass of its own (depth orders it against the
        // basic material's pixels as in one pass: nothing blends).
        if let Some((v, attachments)) = visible.as_ref().filter(|_| recorded[1]) {
            let mut p = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("snow (visibility)"),
                color_attachments: attachments,
                depth_stencil_attachment: targets.depth(KEEP),
                timestamp_writes: span(1),
                occlusion_query_set: None,
                multiview_mask: None,
            });
            p.set_bind_group(0, frame, &[]);
            self.draw_deformable(&mut p, state, [&v.deformable_outside, &v.deformable]);
        }
        if !recorded[2] {
            return;
        }
        let attachments: &[_] = match &visible {
            Some((_, attachments)) => attachments,
            None => &scene,
        };
        let mut p = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("snow (tessellated)"),
            color_attachments: attachments,
            depth_stencil_attachment: targets.depth(KEEP),
            timestamp_writes: span(2),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        tess.draw(&mut p, frame, dice, visible.is_some());
    }

    /// The deformable surfaces seen from outside their box (`pipelines[0]`), then those the eye
    /// is in (`pipelines[1]`).
    fn draw_deformable(
        &self,
        p: &mut wgpu::RenderPass<'_>,
        state: &wgpu::Buffer,
        pipelines: [&wgpu::RenderPipeline; 2],
    ) {
        p.set_pipeline(pipelines[0]);
        self.draw_each(p, state, STATE_DEFORMABLE_DRAW, |s| self.outside[s]);
        p.set_pipeline(pipelines[1]);
        self.draw_each(p, state, STATE_DEFORMABLE_DRAW, |s| !self.outside[s]);
    }

    /// Each relief-mapped surface that `keep` takes: its group and its indirect draw at `offset`.
    fn draw_each(
        &self,
        p: &mut wgpu::RenderPass<'_>,
        state: &wgpu::Buffer,
        offset: u64,
        keep: impl Fn(usize) -> bool,
    ) {
        for (s, bg) in self.bind_groups.iter().enumerate() {
            if let Some(bg) = bg.as_ref().filter(|_| keep(s)) {
                p.set_bind_group(1, bg, &[]);
                p.draw_indirect(state, (s as u64 * STATE_WORDS + offset) * 4);
            }
        }
    }
}

/// How far above its box's top (the untouched snow top and the room for rims) the diced snow of a
/// surface may rise, metres: its banks, built of the snow its prints displaced, stay under the
/// snow's depth, and its macro waves under a tenth of their strength (`snow.wgsl`'s
/// `snow_macro_height` stays within 0.062 m of 0, less `tess_surface.wgsl`'s 0.025 m mean).
fn tessellated_rise(u: &SurfaceUniform) -> f32 {
    u.snow_depth + 0.1 * u.pattern[3].abs()
}

/// Whether `eye` (world) is outside the box the deformable material draws for a surface, by more
/// than a margin: then every back face of the box would be discarded (`fs_deformable` keeps the
/// front faces of a box seen from outside), and drawing the front faces alone gives the same
/// pixels. Near a face (within a centimetre and a millionth of the distance) it is not outside,
/// and both sides are drawn as before.
fn eye_outside_box(u: &SurfaceUniform, eye: glam::Vec3) -> bool {
    let to_local = glam::Mat4::from_cols_array_2d(&u.world_to_local);
    let e = to_local.transform_point3(eye);
    let top = u.terrain_top + u.translucency[3];
    let margin = 0.01 + 1e-6 * eye.length();
    e.x.abs() > u.half_size[0] + margin
        || e.z.abs() > u.half_size[1] + margin
        || e.y < u.terrain_low - margin
        || e.y > top + margin
}

/// The declaration of `fs_deformable` in `surface.wgsl`, and the same with conservative depth.
const DEFORMABLE_FS: &str = "@fragment\nfn fs_deformable(";
const DEFORMABLE_FS_GREATER: &str = "@fragment @early_depth_test(greater_equal)\nfn fs_deformable(";

/// `surface.wgsl` with `fs_deformable` declaring that the depth it writes is never less than
/// the rasterised one (`None` if its declaration is not found).
fn conservative_surface_wgsl() -> Option<String> {
    let text = crate::wgsl::SURFACE.wgsl();
    text.contains(DEFORMABLE_FS)
        .then(|| text.replacen(DEFORMABLE_FS, DEFORMABLE_FS_GREATER, 1))
}

#[cfg(test)]
mod tests {
    /// The conservative module is `surface.wgsl` with the attribute on `fs_deformable` alone,
    /// and naga reads it as a fragment entry point whose depth may be tested early.
    #[test]
    fn the_outside_pipeline_declares_conservative_depth() {
        let text = super::conservative_surface_wgsl().expect("fs_deformable's declaration");
        assert_eq!(text.matches("@early_depth_test").count(), 1);
        let module = naga::front::wgsl::parse_str(&text).expect("the conservative module parses");
        let ep = module
            .entry_points
            .iter()
            .find(|e| e.name == "fs_deformable")
            .expect("fs_deformable");
        assert_eq!(
            ep.early_depth_test,
            Some(naga::EarlyDepthTest::Allow {
                conservative: naga::ConservativeDepth::GreaterEqual
            })
        );
    }
}
