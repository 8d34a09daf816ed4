//! The `shadow` pass: the shadow casters' meshes into the moon's two shadow cascades (the near
//! one first), with `vs_shadow` of `opaque/mesh.wgsl`. The pass owns the shadow map; the frame's
//! bind group samples it, and the tessellated tier's `snow_shadow` draws over it.

use super::meshes::{DrawSet, MeshSet};
use super::readback::{Timestamps, render_span};
use super::{gpu, pipeline};

pub(super) struct ShadowPass {
    /// One pipeline per cascade (the cascade is an override constant of `vs_shadow`).
    pipelines: [wgpu::RenderPipeline; 2],
    /// Both cascades, for sampling.
    pub view: wgpu::TextureView,
    /// Each cascade, for rendering into.
    pub cascade_views: [wgpu::TextureView; 2],
    /// Side of the shadow map, texels.
    pub size: u32,
    /// Its depth format (`RenderConfig::shadow_depth_bits`).
    pub format: wgpu::TextureFormat,
}

impl ShadowPass {
    pub(super) fn new(
        device: &wgpu::Device,
        mesh_module: &wgpu::ShaderModule,
        shadow_layout: &wgpu::BindGroupLayout,
        (size, format): (u32, wgpu::TextureFormat),
    ) -> Self {
        let buffers: Vec<Option<wgpu::VertexBufferLayout>> =
            gpu::mesh_vertex_layouts().into_iter().map(Some).collect();
        let layout = pipeline::layout(device, "shadow", &[shadow_layout]);
        let pipelines = pipeline::ShadowCaster {
            label: "shadow",
            layout: &layout,
            module: mesh_module,
            entry: "vs_shadow",
            buffers: &buffers,
            constant: "SHADOW_CASCADE",
            format,
            // Meshes are closed and wound counter-clockwise seen from outside (as the opaque pass
            // draws them): the faces towards the moon hold the nearest depth, and the far side,
            // drawn behind them, would only cost fill (0.5 ms of the H100's 1.9 at 1080p).
            primitive: pipeline::back_culled(),
        }
        .build(device);
        let (view, cascade_views) = cascade_maps(device, size, format);
        Self {
            pipelines,
            view,
            cascade_views,
            size,
            format,
        }
    }

    /// A new map of `size` texels a side in place of the old one (the pipelines stay).
    pub(super) fn resize(&mut self, device: &wgpu::Device, size: u32) {
        (self.view, self.cascade_views) = cascade_maps(device, size, self.format);
        self.size = size;
    }

    /// A render pass into one cascade (`clear`: the first to draw into it this frame); the
    /// pass's timestamps open with the near cascade and close with the far one.
    pub(super) fn cascade_pass<'e>(
        &self,
        encoder: &'e mut wgpu::CommandEncoder,
        ts: Option<&Timestamps>,
        slot: usize,
        cascade: usize,
        label: &str,
        clear: bool,
    ) -> wgpu::RenderPass<'e> {
        encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some(label),
            color_attachments: &[],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &self.cascade_views[cascade],
                depth_ops: Some(wgpu::Operations {
                    load: if clear {
                        wgpu::LoadOp::Clear(1.0)
                    } else {
                        wgpu::LoadOp::Load
                    },
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: render_span(ts, slot, cascade == 0, cascade == 1),
            occlusion_query_set: None,
            multiview_mask: None,
        })
    }

    /// Both cascades, the near one first; the pass's timestamps span both.
    pub(super) fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        ts: Option<&Timestamps>,
        slot: usize,
        frame: &wgpu::BindGroup,
        meshes: &MeshSet,
    ) {
        for cascade in 0..2 {
            let label = if cascade == 0 {
                "shadow (near cascade)"
            } else {
                "shadow (far cascade)"
            };
            let mut p = self.cascade_pass(encoder, ts, slot, cascade, label, true);
            if meshes.has_draws(DrawSet::Cascade(cascade)) {
                p.set_pipeline(&self.pipelines[cascade]);
                p.set_bind_group(0, frame, &[]);
                meshes.draw(&mut p, DrawSet::Cascade(cascade));
            }
        }
    }
}

/// The two cascades' depth map of `size` texels a side in `format`: the view that samples both
/// and one view each to render into.
fn cascade_maps(
    device: &wgpu::Device,
    size: u32,
    format: wgpu::TextureFormat,
) -> (wgpu::TextureView, [wgpu::TextureView; 2]) {
    let texture = device.create_texture(&wgpu::TextureDescriptor {
        label: Some("moon shadow cascades"),
        size: wgpu::Extent3d {
            width: size,
            height: size,
            depth_or_array_layers: 2,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
        view_formats: &[],
    });
    let view = texture.create_view(&wgpu::TextureViewDescriptor {
        dimension: Some(wgpu::TextureViewDimension::D2Array),
        ..Default::default()
    });
    let cascade_views = [0, 1].map(|layer| {
        texture.create_view(&wgpu::TextureViewDescriptor {
            dimension: Some(wgpu::TextureViewDimension::D2),
            base_array_layer: layer,
            array_layer_count: Some(1),
            ..Default::default()
        })
    });
    (view, cascade_views)
}
