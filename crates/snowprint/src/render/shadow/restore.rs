//! The shadow pass's restore (`restore.wgsl`): a cascade's cache copied back over rectangles of
//! its map, one instanced draw of quads writing the cached depth (`cache.rs` says when).

use super::cache::clip_rect;
use crate::gpu::resources::{Growable, KeptGroups};
use crate::render::pipeline;

/// What a cascade restores this frame: texel rectangles and the view of its cache.
pub(super) type Job<'a> = (&'a [[u32; 4]], &'a wgpu::TextureView);

pub(super) struct Restore {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    /// Both cascades' rectangles in clip space, the near cascade's first.
    rects: Growable,
    /// This frame, per cascade: its group (the cache and the rectangles) and its instances.
    groups: [Option<(wgpu::BindGroup, std::ops::Range<u32>)>; 2],
    /// The groups by cascade, kept while the cache and the rectangles' buffer stay.
    kept: KeptGroups,
}

impl Restore {
    pub(super) fn new(device: &wgpu::Device, format: wgpu::TextureFormat) -> Self {
        let source = crate::wgsl::SHADOW_RESTORE.wgsl();
        let module = pipeline::shader(device, "restore.wgsl", source);
        let layout = crate::wgsl::SHADOW_RESTORE.bind_group_layout(device, "shadow restore", 0);
        let pipeline = pipeline::Raster {
            label: "shadow restore",
            module: &module,
            vs: "vs_restore",
            fs: "fs_restore",
            buffers: &[],
            groups: &[&layout],
            primitive: wgpu::PrimitiveState {
                topology: wgpu::PrimitiveTopology::TriangleStrip,
                ..Default::default()
            },
            // Whatever the map holds there is replaced by the cache's depth.
            depth: Some(wgpu::DepthStencilState {
                format,
                depth_write_enabled: Some(true),
                depth_compare: Some(wgpu::CompareFunction::Always),
                stencil: wgpu::StencilState::default(),
                bias: wgpu::DepthBiasState::default(),
            }),
            targets: &[],
            constants: &[],
        }
        .build(device);
        Self {
            pipeline,
            layout,
            rects: Growable::new(
                device,
                "shadow restore rectangles",
                wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
                16 * 64,
            ),
            groups: [None, None],
            kept: KeptGroups::default(),
        }
    }

    /// Upload the rectangles `per_cascade` restores (texels of a `size` map; `None`: the cascade
    /// restores nothing this frame) and bind each with its cascade's `caches` view.
    pub(super) fn prepare(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        size: u32,
        per_cascade: [Option<Job<'_>>; 2],
    ) {
        let mut clip: Vec<[f32; 4]> = Vec::new();
        let mut ranges = [None, None];
        for (range, job) in ranges.iter_mut().zip(&per_cascade) {
            if let Some((rects, _)) = job.filter(|(r, _)| !r.is_empty()) {
                let first = clip.len() as u32;
                clip.extend(rects.iter().map(|&r| clip_rect(r, size)));
                *range = Some(first..clip.len() as u32);
            }
        }
        if !clip.is_empty() {
            self.rects
                .write_whole(device, queue, bytemuck::cast_slice(&clip));
        }
        let (kept, layout, rects) = (&mut self.kept, &self.layout, &self.rects);
        self.groups = [0, 1].map(|c| {
            let (range, (_, cache)) = (ranges[c].clone()?, per_cascade[c]?);
            let group = kept.get(
                device,
                "shadow restore",
                layout,
                c,
                &[
                    wgpu::BindingResource::TextureView(cache),
                    rects.buffer.as_entire_binding(),
                ],
            );
            Some((group, range))
        });
    }

    /// Draw cascade `cascade`'s rectangles, if it restores any this frame.
    pub(super) fn draw(&self, p: &mut wgpu::RenderPass<'_>, cascade: usize) {
        if let Some((group, range)) = &self.groups[cascade] {
            p.set_pipeline(&self.pipeline);
            p.set_bind_group(0, group, &[]);
            p.draw(0..4, range.clone());
        }
    }
}
