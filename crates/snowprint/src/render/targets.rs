//! The frame's render targets: the supersampled HDR colour and depth the passes draw into, and
//! the offscreen output with its readback buffer.

/// Format of the offscreen output ([`Renderer::render`](super::Renderer::render)): RGBA8 whose
/// bytes are sRGB encoded by the tonemap itself, stored as `Rgba8Unorm` so that its compute pass
/// can write it as a storage texture (an sRGB format cannot be one). A caller's view of this
/// format made with `STORAGE_BINDING` is written by the compute pass too; any other view by the
/// raster fallback.
pub const OUTPUT_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;
pub(super) const HDR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
pub(super) const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
/// The visibility buffer: an opaque pixel's instance and triangle, or a snow hit's tagged slot and flags and its footprint (`snow/visible.rs`).
pub(super) const VISIBILITY_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rg32Uint;
/// The snow's hits on the visibility path, as bits: the surface-local point and the self-shadow (or, diced, the slope as two halves).
pub(super) const SNOW_HITS_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Uint;
pub(super) const HEIGHTFIELD_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;

pub(super) struct Targets {
    pub size: (u32, u32),
    pub color_view: wgpu::TextureView,
    pub depth_view: wgpu::TextureView,
    /// The visibility buffer (only on `OpaquePath::Visibility`).
    pub visibility_view: Option<wgpu::TextureView>,
    /// The snow's hits, beside the visibility buffer (only on `OpaquePath::Visibility`).
    pub snow_hits_view: Option<wgpu::TextureView>,
    pub output: wgpu::Texture,
    pub output_view: wgpu::TextureView,
    pub readback: wgpu::Buffer,
    pub padded_row: u32,
}

impl Targets {
    /// The targets of a `width` x `height` output drawn `supersample` times larger, with a
    /// visibility buffer when `visibility`.
    pub(super) fn new(
        device: &wgpu::Device,
        width: u32,
        height: u32,
        supersample: u32,
        visibility: bool,
    ) -> Self {
        let texture = |label, w, h, format, usage| {
            device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size: wgpu::Extent3d {
                    width: w,
                    height: h,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage,
                view_formats: &[],
            })
        };
        use wgpu::TextureUsages as U;
        let (iw, ih) = (width * supersample, height * supersample);
        let color = texture(
            "scene colour",
            iw,
            ih,
            HDR_FORMAT,
            // Storage only for the visibility buffer's shading, which writes it from compute
            // (storage use can cost a render target its compression on some GPUs).
            if visibility {
                U::RENDER_ATTACHMENT | U::TEXTURE_BINDING | U::STORAGE_BINDING
            } else {
                U::RENDER_ATTACHMENT | U::TEXTURE_BINDING
            },
        );
        let visibility_view = visibility.then(|| {
            texture(
                "visibility",
                iw,
                ih,
                VISIBILITY_FORMAT,
                U::RENDER_ATTACHMENT | U::TEXTURE_BINDING,
            )
            .create_view(&Default::default())
        });
        let snow_hits_view = visibility.then(|| {
            texture(
                "snow hits",
                iw,
                ih,
                SNOW_HITS_FORMAT,
                U::RENDER_ATTACHMENT | U::TEXTURE_BINDING,
            )
            .create_view(&Default::default())
        });
        let depth = texture(
            "scene depth",
            iw,
            ih,
            DEPTH_FORMAT,
            U::RENDER_ATTACHMENT | U::TEXTURE_BINDING,
        );
        let output = texture(
            "output",
            width,
            height,
            OUTPUT_FORMAT,
            U::STORAGE_BINDING | U::RENDER_ATTACHMENT | U::COPY_SRC,
        );
        let padded_row = (width * 4).div_ceil(256) * 256;
        let readback = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("output readback"),
            size: padded_row as u64 * height as u64,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        Self {
            size: (width, height),
            color_view: color.create_view(&Default::default()),
            depth_view: depth.create_view(&Default::default()),
            visibility_view,
            snow_hits_view,
            output_view: output.create_view(&Default::default()),
            output,
            readback,
            padded_row,
        }
    }

    /// The scene colour as a pass's only colour attachment.
    pub(super) fn color(
        &self,
        load: wgpu::LoadOp<wgpu::Color>,
    ) -> [Option<wgpu::RenderPassColorAttachment<'_>>; 1] {
        [Some(wgpu::RenderPassColorAttachment {
            view: &self.color_view,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations {
                load,
                store: wgpu::StoreOp::Store,
            },
        })]
    }

    /// The visibility path's attachments of the basic snow: the scene colour and the visibility
    /// buffer, loaded; `None` on the forward path.
    pub(super) fn snow_basic_visible(
        &self,
    ) -> Option<[Option<wgpu::RenderPassColorAttachment<'_>>; 2]> {
        let v = self.visibility_view.as_ref()?;
        let [color] = self.color(wgpu::LoadOp::Load);
        Some([
            color,
            Some(wgpu::RenderPassColorAttachment {
                view: v,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Load,
                    store: wgpu::StoreOp::Store,
                },
            }),
        ])
    }

    /// The visibility path's attachments of the deformable snow: the visibility buffer and the
    /// snow's hits, loaded (a pixel's hit is read only where the snow wrote it this frame, which
    /// its depth tells); `None` on the forward path.
    pub(super) fn snow_visible(&self) -> Option<[Option<wgpu::RenderPassColorAttachment<'_>>; 2]> {
        let load = |view| {
            Some(wgpu::RenderPassColorAttachment {
                view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Load,
                    store: wgpu::StoreOp::Store,
                },
            })
        };
        match (&self.visibility_view, &self.snow_hits_view) {
            (Some(v), Some(h)) => Some([load(v), load(h)]),
            _ => None,
        }
    }

    /// Begin a render pass over the scene colour (loaded as `color`) and depth (`depth`, `None`:
    /// read-only), as the passes that draw into the scene do.
    pub(super) fn scene_pass<'e>(
        &self,
        encoder: &'e mut wgpu::CommandEncoder,
        label: &str,
        color: wgpu::LoadOp<wgpu::Color>,
        depth: Option<wgpu::Operations<f32>>,
        timestamp_writes: Option<wgpu::RenderPassTimestampWrites<'_>>,
    ) -> wgpu::RenderPass<'e> {
        let attachments = self.color(color);
        encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some(label),
            color_attachments: &attachments,
            depth_stencil_attachment: self.depth(depth),
            timestamp_writes,
            occlusion_query_set: None,
            multiview_mask: None,
        })
    }

    /// The scene depth as a pass's depth attachment (`None`: read-only).
    pub(super) fn depth(
        &self,
        ops: Option<wgpu::Operations<f32>>,
    ) -> Option<wgpu::RenderPassDepthStencilAttachment<'_>> {
        Some(wgpu::RenderPassDepthStencilAttachment {
            view: &self.depth_view,
            depth_ops: ops,
            stencil_ops: None,
        })
    }
}

/// Load and store: a pass that draws over what earlier passes left.
pub(super) const KEEP: Option<wgpu::Operations<f32>> = Some(wgpu::Operations {
    load: wgpu::LoadOp::Load,
    store: wgpu::StoreOp::Store,
});
