//! The visibility path of the `opaque` pass (`OpaquePath::Visibility`): `visibility.wgsl`
//! rasterises the meshes into depth and an `Rg32Uint` target of (instance, triangle), then,
//! after the snow pass (which writes the buffer where it draws), the `opaque_shade` compute pass
//! (`shade.wgsl`) shades the pixels where an opaque triangle is still what the buffer holds, with
//! the forward path's shading function.

use super::super::graph::PASSES;
use super::super::meshes::{DrawSet, MeshSet};
use super::super::pipeline;
use super::super::readback::{Timestamps, compute_pass, render_writes};
use super::super::targets::{Targets, VISIBILITY_FORMAT};
use super::geometry::MeshGeometry;
use crate::gpu::resources::KeptGroups;

/// Pixels a workgroup of `shade.wgsl` covers along each axis.
const WORKGROUP: u32 = 8;

pub(super) struct VisibilityPass {
    raster: wgpu::RenderPipeline,
    shade: wgpu::ComputePipeline,
    raster_layout: wgpu::BindGroupLayout,
    shade_layout: wgpu::BindGroupLayout,
    targets_layout: wgpu::BindGroupLayout,
    geometry: MeshGeometry,
    /// This frame's bind groups: the raster's geometry, the shading's geometry and targets; and
    /// the scene's size.
    current: Option<([wgpu::BindGroup; 3], (u32, u32))>,
    /// The three groups (slots 0, 1, 2), kept while what they bind stays.
    kept: KeptGroups,
}

impl VisibilityPass {
    pub(super) fn new(device: &wgpu::Device, frame_layout: &wgpu::BindGroupLayout) -> Self {
        let vis = &crate::wgsl::MESH_VISIBILITY;
        let raster_layout = vis.bind_group_layout(device, "visibility geometry", 1);
        let module = pipeline::shader(device, "visibility.wgsl", vis.wgsl());
        let raster = pipeline::Raster {
            label: "opaque visibility",
            module: &module,
            vs: "vs_visibility",
            fs: "fs_visibility",
            buffers: &[],
            groups: &[frame_layout, &raster_layout],
            primitive: pipeline::back_culled(),
            depth: pipeline::depth_state(wgpu::CompareFunction::Less, true),
            targets: &[Some(wgpu::ColorTargetState {
                format: VISIBILITY_FORMAT,
                blend: None,
                write_mask: wgpu::ColorWrites::ALL,
            })],
            constants: &[],
        }
        .build(device);
        let shade_module = &crate::wgsl::MESH_SHADE;
        let shade_layout = shade_module.bind_group_layout(device, "shade geometry", 1);
        let targets_layout = shade_module.bind_group_layout(device, "shade targets", 2);
        let module = pipeline::shader(device, "shade.wgsl", shade_module.wgsl());
        let shade = pipeline::compute(
            device,
            "opaque shade",
            &module,
            "shade",
            &[frame_layout, &shade_layout, &targets_layout],
        );
        Self {
            raster,
            shade,
            raster_layout,
            shade_layout,
            targets_layout,
            geometry: MeshGeometry::new(device),
            current: None,
            kept: KeptGroups::default(),
        }
    }

    /// Upload the geometry and make the frame's bind groups.
    pub(super) fn prepare(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        meshes: &MeshSet,
        targets: &Targets,
    ) {
        self.geometry.prepare(device, queue, meshes);
        let Some(visibility) = &targets.visibility_view else {
            self.current = None;
            return;
        };
        let raster = self.kept.get(
            device,
            "visibility geometry",
            &self.raster_layout,
            0,
            &self.geometry.entries(meshes),
        );
        let shade = self.kept.get(
            device,
            "shade geometry",
            &self.shade_layout,
            1,
            &self.geometry.entries(meshes),
        );
        let outputs = self.kept.get(
            device,
            "shade targets",
            &self.targets_layout,
            2,
            &[
                wgpu::BindingResource::TextureView(visibility),
                wgpu::BindingResource::TextureView(&targets.color_view),
                wgpu::BindingResource::TextureView(&targets.depth_view),
            ],
        );
        let t = targets.color_view.texture();
        self.current = Some(([raster, shade, outputs], (t.width(), t.height())));
    }

    /// Clear depth, then draw every instance into it and the visibility target. The visibility
    /// target is not cleared (on the H100 that took 0.6 ms at 1080p): every fragment that writes
    /// the scene's depth before the shading passes writes it too (the snow's basic material a
    /// word that nothing is to be shaded), and where nothing was drawn the depth says so.
    pub(super) fn encode_raster(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        ts: Option<&Timestamps>,
        slot: usize,
        targets: &Targets,
        frame: &wgpu::BindGroup,
        meshes: &MeshSet,
    ) {
        let Some(visibility) = &targets.visibility_view else {
            return;
        };
        let mut p = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some(PASSES[slot].name),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: visibility,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Load,
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: targets.depth(Some(wgpu::Operations {
                load: wgpu::LoadOp::Clear(1.0),
                store: wgpu::StoreOp::Store,
            })),
            timestamp_writes: render_writes(ts, slot),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        if let (true, Some((groups, _))) = (meshes.has_draws(DrawSet::Opaque), &self.current) {
            p.set_pipeline(&self.raster);
            p.set_bind_group(0, frame, &[]);
            p.set_bind_group(1, &groups[0], &[]);
            meshes.draw_pulled(&mut p);
        }
    }

    /// Shade the pixels of the scene whose opaque triangle the snow left visible.
    pub(super) fn encode_shade(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        ts: Option<&Timestamps>,
        slot: usize,
        frame: &wgpu::BindGroup,
    ) {
        let mut p = compute_pass(encoder, ts, slot);
        if let Some((groups, (w, h))) = &self.current {
            p.set_pipeline(&self.shade);
            p.set_bind_group(0, frame, &[]);
            p.set_bind_group(1, &groups[1], &[]);
            p.set_bind_group(2, &groups[2], &[]);
            p.dispatch_workgroups(w.div_ceil(WORKGROUP), h.div_ceil(WORKGROUP), 1);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::super::targets::{HDR_FORMAT, OUTPUT_FORMAT};
    use crate::wgsl::{BindingKind, ShaderModule};

    fn storage_format(module: &ShaderModule, name: &str) -> wgpu::TextureFormat {
        match module
            .bindings
            .iter()
            .find(|b| b.name == name)
            .map(|b| b.kind)
        {
            Some(BindingKind::StorageTexture { format, .. }) => format,
            other => panic!("{}: {name} is {other:?}", module.name),
        }
    }

    /// The compute passes' storage textures are declared in WGSL with the formats of the targets
    /// they are bound to.
    #[test]
    fn storage_targets_match_their_wgsl() {
        assert_eq!(
            storage_format(&crate::wgsl::MESH_SHADE, "scene_color"),
            HDR_FORMAT
        );
        assert_eq!(
            storage_format(&crate::wgsl::TONEMAP_COMPUTE, "output"),
            OUTPUT_FORMAT
        );
    }
}
