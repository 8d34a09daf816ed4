//! The `shadow` pass: the shadow casters' meshes into the moon's two shadow cascades (the near
//! one first), with `vs_shadow` of `opaque/mesh.wgsl`. The pass owns the shadow map; the frame's
//! bind group samples it, and the tessellated tier's `snow_shadow` draws over it.
//!
//! A cascade whose still casters ([`Instance::still`](super::Instance::still)) and projection
//! held still since the frame before keeps their depth in a cache of its own (`cache.rs`): its
//! map is then neither cleared nor redrawn whole, only restored from the cache where the frame
//! before's moving casters and displaced snow drew (`restore.wgsl`), before this frame's moving
//! casters are drawn.

mod cache;
mod restore;

pub(super) use cache::sphere_rect;

use super::meshes::{DrawSet, MeshSet};
use super::readback::{Timestamps, render_span};
use super::{gpu, pipeline};
use cache::{CacheState, CascadeStep};

pub(super) struct ShadowPass {
    /// One pipeline per cascade (the cascade is an override constant of `vs_shadow`).
    pipelines: [wgpu::RenderPipeline; 2],
    /// Both cascades, for sampling.
    pub view: wgpu::TextureView,
    /// Each cascade, for rendering into.
    pub cascade_views: [wgpu::TextureView; 2],
    /// The map of both cascades (copied into from the caches).
    texture: wgpu::Texture,
    /// Per cascade: its still casters' depth (made when first kept), to render into, copy from
    /// and restore from.
    maps: [Option<(wgpu::Texture, wgpu::TextureView)>; 2],
    /// Per cascade: what its cache and its map hold.
    states: [CacheState; 2],
    /// This frame's step of each cascade.
    steps: [CascadeStep; 2],
    /// This frame's restored texels of each cascade.
    restored: [u64; 2],
    /// Where the near cascade stood last frame (`cascades::shadow_cascades` keeps it there while
    /// the view's focus stays near).
    pub near_hold: Option<super::cascades::NearHold>,
    /// Whether the last frame planned was submitted ([`ShadowPass::confirm`]): if not, neither
    /// its cache nor its map hold what the states say, and the next frame starts afresh.
    confirmed: bool,
    restore: restore::Restore,
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
        let (texture, view, cascade_views) = cascade_maps(device, size, format);
        Self {
            pipelines,
            view,
            cascade_views,
            texture,
            maps: [None, None],
            states: Default::default(),
            steps: Default::default(),
            restored: [0, 0],
            confirmed: true,
            near_hold: None,
            restore: restore::Restore::new(device, format),
            size,
            format,
        }
    }

    /// A new map of `size` texels a side in place of the old one (the pipelines stay; the
    /// caches go).
    pub(super) fn resize(&mut self, device: &wgpu::Device, size: u32) {
        (self.texture, self.view, self.cascade_views) = cascade_maps(device, size, self.format);
        self.maps = [None, None];
        self.states = Default::default();
        self.size = size;
    }

    /// This frame's step of each cascade ([`cache::cascade_step`]) from its still casters' keys
    /// (`MeshSet::still_keys`), with the rectangles it restores. What each cascade's moving
    /// casters (`MeshSet::moving_rects`, taken) and displaced snow (`snow`) cover this frame is
    /// what the next frame restores.
    pub(super) fn plan(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        enabled: bool,
        meshes: &mut MeshSet,
        snow: [Vec<[u32; 4]>; 2],
    ) {
        if !self.confirmed {
            self.states = Default::default();
        }
        self.confirmed = false;
        let keys = meshes.still_keys;
        let mut drawn = std::mem::take(&mut meshes.moving_rects);
        for (d, s) in drawn.iter_mut().zip(snow) {
            d.extend(s);
        }
        let (size, format) = (self.size, self.format);
        let texels = u64::from(size) * u64::from(size);
        let mut restored: [Vec<[u32; 4]>; 2] = Default::default();
        for (c, drawn) in drawn.into_iter().enumerate() {
            let state = &mut self.states[c];
            let step = cache::cascade_step(enabled, keys[c], state, texels);
            if step == CascadeStep::Keep && self.maps[c].is_none() {
                self.maps[c] = Some(cache_map(device, size, format));
            }
            if step == CascadeStep::Restore {
                restored[c] = std::mem::take(&mut state.dirty);
            }
            state.advance(step, keys[c], drawn);
            self.steps[c] = step;
            self.restored[c] = restored[c].iter().map(|&r| cache::area(r)).sum();
        }
        let jobs = [0, 1].map(|c| {
            let view = self.maps[c].as_ref().map(|(_, v)| v);
            view.filter(|_| self.steps[c] == CascadeStep::Restore)
                .map(|v| (restored[c].as_slice(), v))
        });
        self.restore.prepare(device, queue, size, jobs);
    }

    /// The frame last planned was submitted: the next may build on what it leaves.
    pub(super) fn confirm(&mut self) {
        self.confirmed = true;
    }

    /// Whether each cascade's still casters come from its cache this frame (copied in or
    /// restored, not drawn).
    pub(super) fn cached(&self) -> [bool; 2] {
        (self.steps).map(|s| matches!(s, CascadeStep::CopyIn | CascadeStep::Restore))
    }

    /// Texels of each cascade's map that this frame's restore copies back (overlaps counted
    /// twice).
    pub(super) fn restored_texels(&self) -> [u64; 2] {
        self.restored
    }

    /// A render pass into a depth view (`clear`: the first to draw into it this frame) with the
    /// timestamps of `slot` at its `begin` and `end`.
    fn depth_pass<'e>(
        encoder: &'e mut wgpu::CommandEncoder,
        (view, label): (&wgpu::TextureView, &str),
        clear: bool,
        ts: Option<&Timestamps>,
        slot: usize,
        (begin, end): (bool, bool),
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
            timestamp_writes: render_span(ts, slot, begin, end),
            occlusion_query_set: None,
            multiview_mask: None,
        })
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
        let target = (&self.cascade_views[cascade], label);
        Self::depth_pass(
            encoder,
            target,
            clear,
            ts,
            slot,
            (cascade == 0, cascade == 1),
        )
    }

    /// Both cascades, the near one first, each as [`ShadowPass::plan`] stepped it; the pass's
    /// timestamps span both, copies included.
    pub(super) fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        ts: Option<&Timestamps>,
        slot: usize,
        frame: &wgpu::BindGroup,
        meshes: &MeshSet,
    ) {
        if self.steps[0] == CascadeStep::CopyIn {
            // The span opens before the near cascade's copy.
            open_span(encoder, ts, slot);
        }
        for (cascade, &step) in self.steps.iter().enumerate() {
            let near = cascade == 0;
            let draw = |p: &mut wgpu::RenderPass<'_>, set: DrawSet| {
                if meshes.has_draws(set) {
                    p.set_pipeline(&self.pipelines[cascade]);
                    p.set_bind_group(0, frame, &[]);
                    meshes.draw(p, set);
                }
            };
            let cache = self.maps[cascade].as_ref();
            if let (CascadeStep::Keep, Some((_, view))) = (step, cache) {
                let target = (view, "shadow (still casters into the cache)");
                let span = (near, false);
                let mut p = Self::depth_pass(encoder, target, true, ts, slot, span);
                draw(&mut p, DrawSet::Still(cascade));
            }
            if let (CascadeStep::Keep | CascadeStep::CopyIn, Some((texture, _))) = (step, cache) {
                self.copy_in(encoder, texture, cascade);
            }
            let label = if near {
                "shadow (near cascade)"
            } else {
                "shadow (far cascade)"
            };
            let target = (&self.cascade_views[cascade], label);
            let cleared = step == CascadeStep::Draw;
            let span = (
                near && matches!(step, CascadeStep::Draw | CascadeStep::Restore),
                !near,
            );
            let mut p = Self::depth_pass(encoder, target, cleared, ts, slot, span);
            match step {
                CascadeStep::Draw => draw(&mut p, DrawSet::Still(cascade)),
                CascadeStep::Restore => self.restore.draw(&mut p, cascade),
                CascadeStep::Keep | CascadeStep::CopyIn => {}
            }
            draw(&mut p, DrawSet::Moving(cascade));
        }
    }

    /// Copy a cascade's cache into its layer of the map.
    fn copy_in(&self, encoder: &mut wgpu::CommandEncoder, cache: &wgpu::Texture, cascade: usize) {
        let at = |texture, z| wgpu::TexelCopyTextureInfo {
            texture,
            mip_level: 0,
            origin: wgpu::Origin3d { x: 0, y: 0, z },
            aspect: wgpu::TextureAspect::All,
        };
        let extent = wgpu::Extent3d {
            width: self.size,
            height: self.size,
            depth_or_array_layers: 1,
        };
        encoder.copy_texture_to_texture(at(cache, 0), at(&self.texture, cascade as u32), extent);
    }
}

/// An empty compute pass that writes the beginning timestamp of `slot`.
fn open_span(encoder: &mut wgpu::CommandEncoder, ts: Option<&Timestamps>, slot: usize) {
    let writes = ts.map(|t| wgpu::ComputePassTimestampWrites {
        query_set: t.query_set(),
        beginning_of_pass_write_index: Some(2 * slot as u32),
        end_of_pass_write_index: None,
    });
    encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
        label: Some("shadow (span)"),
        timestamp_writes: writes,
    });
}

/// A cascade's cache: one layer of `size` texels a side in `format`, to render into, copy from
/// and restore from.
fn cache_map(
    device: &wgpu::Device,
    size: u32,
    format: wgpu::TextureFormat,
) -> (wgpu::Texture, wgpu::TextureView) {
    let usage = wgpu::TextureUsages::COPY_SRC | wgpu::TextureUsages::TEXTURE_BINDING;
    let texture = depth_map(
        device,
        "moon shadow cascade cache",
        (size, 1),
        format,
        usage,
    );
    let view = texture.create_view(&Default::default());
    (texture, view)
}

/// A depth texture of `layers` layers of `size` texels a side in `format`, rendered into and
/// used as `usage` says besides.
fn depth_map(
    device: &wgpu::Device,
    label: &str,
    (size, layers): (u32, u32),
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d {
            width: size,
            height: size,
            depth_or_array_layers: layers,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT | usage,
        view_formats: &[],
    })
}

/// The two cascades' depth map of `size` texels a side in `format`: the view that samples both
/// and one view each to render into.
fn cascade_maps(
    device: &wgpu::Device,
    size: u32,
    format: wgpu::TextureFormat,
) -> (wgpu::Texture, wgpu::TextureView, [wgpu::TextureView; 2]) {
    let usage = wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST;
    let texture = depth_map(device, "moon shadow cascades", (size, 2), format, usage);
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
    (texture, view, cascade_views)
}
