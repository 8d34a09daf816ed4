//! The `shadow` pass: the shadow casters' meshes into the moon's two shadow cascades (the near
//! one first), with `vs_shadow` of `opaque/mesh.wgsl`. The pass owns the shadow map; the frame's
//! bind group samples it, and the tessellated tier's `snow_shadow` draws over it.
//!
//! The far cascade covers the whole scene and stays put while nothing leaves it, and most casters
//! (buildings, walls) rest from frame to frame: what the resting casters cast into it is kept in a
//! depth texture of its own, drawn again only when the resting set or the cascade changes; each
//! frame copies it into the far cascade and draws the moving casters over it. The depth test keeps
//! the nearest depth whatever the order, so the map is the one drawing everything would give, bit
//! for bit. The near cascade follows the camera and is drawn whole every frame.

use std::cell::Cell;

use super::meshes::{Draws, MeshSet};
use super::readback::{Timestamps, render_span};
use super::targets::DEPTH_FORMAT;
use super::{gpu, pipeline};

pub(super) struct ShadowPass {
    /// One pipeline per cascade (the cascade is an override constant of `vs_shadow`).
    pipelines: [wgpu::RenderPipeline; 2],
    /// Both cascades, for sampling.
    pub view: wgpu::TextureView,
    /// Each cascade, for rendering into.
    pub cascade_views: [wgpu::TextureView; 2],
    shadow_texture: wgpu::Texture,
    /// Side of the shadow map, texels.
    pub size: u32,
    /// The resting casters' depth in the far cascade, and what it was drawn for: the resting set
    /// and the cascade's matrix. `pending` is drawn by an encoded frame not yet submitted; it
    /// becomes `cached` at [`ShadowPass::submitted`] (a frame never submitted leaves nothing).
    resting: wgpu::Texture,
    resting_view: wgpu::TextureView,
    cached: Cell<Option<RestingKey>>,
    pending: Cell<Option<RestingKey>>,
}

/// What the kept far-cascade depth was drawn for: the resting casters and the cascade's matrix.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct RestingKey {
    casters: u64,
    cascade: [u32; 16],
}

impl RestingKey {
    pub(super) fn new(meshes: &MeshSet, far: glam::Mat4) -> Self {
        Self {
            casters: meshes.resting_key,
            cascade: far.to_cols_array().map(f32::to_bits),
        }
    }
}

impl ShadowPass {
    pub(super) fn new(
        device: &wgpu::Device,
        mesh_module: &wgpu::ShaderModule,
        shadow_layout: &wgpu::BindGroupLayout,
        size: u32,
    ) -> Self {
        let buffers: Vec<Option<wgpu::VertexBufferLayout>> =
            gpu::mesh_vertex_layouts().into_iter().map(Some).collect();
        let layout = pipeline::layout(device, "shadow", &[shadow_layout]);
        let pipelines = pipeline::shadow_caster(
            device,
            "shadow",
            &layout,
            mesh_module,
            "vs_shadow",
            &buffers,
            "SHADOW_CASCADE",
        );
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
            format: DEPTH_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT
                | wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        let resting = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("moon shadow: resting casters in the far cascade"),
            size: wgpu::Extent3d {
                width: size,
                height: size,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: DEPTH_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        let resting_view = resting.create_view(&Default::default());
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
        Self {
            pipelines,
            view,
            cascade_views,
            size,
            shadow_texture: texture,
            resting,
            resting_view,
            cached: Cell::new(None),
            pending: Cell::new(None),
        }
    }

    /// The frame last encoded was submitted: what it drew of the resting casters is kept.
    pub(super) fn submitted(&self) {
        if let Some(k) = self.pending.take() {
            self.cached.set(Some(k));
        }
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
        let span = render_span(ts, slot, cascade == 0, cascade == 1);
        Self::depth_pass(encoder, &self.cascade_views[cascade], label, clear, span)
    }

    fn depth_pass<'e>(
        encoder: &'e mut wgpu::CommandEncoder,
        view: &wgpu::TextureView,
        label: &str,
        clear: bool,
        timestamp_writes: Option<wgpu::RenderPassTimestampWrites<'_>>,
    ) -> wgpu::RenderPass<'e> {
        encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some(label),
            color_attachments: &[],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view,
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
            timestamp_writes,
            occlusion_query_set: None,
            multiview_mask: None,
        })
    }

    /// Both cascades, the near one first; the pass's timestamps span both. `far`: the far
    /// cascade's resting casters and matrix, whose kept depth is reused when it matches.
    pub(super) fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        ts: Option<&Timestamps>,
        slot: usize,
        frame: &wgpu::BindGroup,
        meshes: &MeshSet,
        far: RestingKey,
    ) {
        let mut p = self.cascade_pass(encoder, ts, slot, 0, "shadow (near cascade)", true);
        if meshes.has_draws(Draws::Casters) {
            p.set_pipeline(&self.pipelines[0]);
            p.set_bind_group(0, frame, &[]);
            meshes.draw(&mut p, Draws::Casters);
        }
        drop(p);
        let miss = self.cached.get() != Some(far);
        self.pending.set(miss.then_some(far));
        if miss {
            let mut p = Self::depth_pass(
                encoder,
                &self.resting_view,
                "shadow (far cascade, resting casters)",
                true,
                None,
            );
            if meshes.has_draws(Draws::Resting) {
                p.set_pipeline(&self.pipelines[1]);
                p.set_bind_group(0, frame, &[]);
                meshes.draw(&mut p, Draws::Resting);
            }
            drop(p);
        }
        encoder.copy_texture_to_texture(
            self.resting.as_image_copy(),
            wgpu::TexelCopyTextureInfo {
                texture: &self.shadow_texture,
                mip_level: 0,
                origin: wgpu::Origin3d { x: 0, y: 0, z: 1 },
                aspect: wgpu::TextureAspect::All,
            },
            self.resting.size(),
        );
        let mut p = self.cascade_pass(encoder, ts, slot, 1, "shadow (far cascade)", false);
        if meshes.has_draws(Draws::Moving) {
            p.set_pipeline(&self.pipelines[1]);
            p.set_bind_group(0, frame, &[]);
            meshes.draw(&mut p, Draws::Moving);
        }
    }
}
