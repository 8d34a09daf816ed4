//! The `classify` pass (compute, `classify.wgsl`): one workgroup per surface reads its heightmap
//! and writes its state words: whether anything touched it (the basic or the deformable
//! material), the deepest point, whether the heightfield and bank passes run over it, and the
//! indirect arguments of the two snow draws.

use super::frame::FrameSurface;
use super::gpu::{BOX_VERTICES, ClassifyRecord, STATE_WORDS};
use super::pipeline;
use super::readback::{Timestamps, compute_pass};
use crate::gpu::resources::{Growable, KeptGroups};

pub(super) struct ClassifyPass {
    layout: wgpu::BindGroupLayout,
    pipeline: wgpu::ComputePipeline,
    /// Per surface: where its heightmap lies in the pool.
    records: Growable,
    /// Per surface: [`STATE_WORDS`] words of state and indirect arguments, read by the later
    /// passes.
    pub state: Growable,
    bind_group: Option<wgpu::BindGroup>,
    /// The group, kept while the pool and the two buffers stay.
    kept: KeptGroups,
    surfaces: u32,
}

impl ClassifyPass {
    pub(super) fn new(device: &wgpu::Device) -> Self {
        let layout = crate::wgsl::CLASSIFY.bind_group_layout(device, "classify", 0);
        let module = pipeline::shader(device, "classify.wgsl", crate::wgsl::CLASSIFY.wgsl());
        let pipeline = pipeline::compute(device, "classify", &module, "classify", &[&layout]);
        use wgpu::BufferUsages as U;
        Self {
            records: Growable::new(
                device,
                "classify records",
                U::STORAGE | U::COPY_DST,
                std::mem::size_of::<ClassifyRecord>() as u64 * 8,
            ),
            state: Growable::new(
                device,
                "surface state",
                U::STORAGE | U::INDIRECT | U::COPY_SRC,
                STATE_WORDS * 4 * 8,
            ),
            layout,
            pipeline,
            bind_group: None,
            kept: KeptGroups::default(),
            surfaces: 0,
        }
    }

    /// Upload the surfaces' records and make room for their state.
    pub(super) fn prepare(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        pool: &wgpu::Buffer,
        surfaces: &[FrameSurface<'_>],
    ) {
        let n = surfaces.len();
        let records: Vec<ClassifyRecord> = surfaces
            .iter()
            .map(|s| ClassifyRecord {
                heights: s.view.heights,
                width: s.view.layout.width,
                height: s.view.layout.height,
                box_vertices: BOX_VERTICES,
                bits: s.view.precision.bits(),
                always_deformable: u32::from(
                    s.view.ground != crate::capture::NO_GROUND || s.view.hole.is_some(),
                ),
                wrap: s.view.wrap,
                seen: u32::from(s.seen),
                _pad: [0; 4],
            })
            .collect();
        if n > 0 {
            self.records
                .write_whole(device, queue, bytemuck::cast_slice(&records));
        }
        self.state.ensure(device, n.max(1) as u64 * STATE_WORDS * 4);
        self.surfaces = n as u32;
        self.bind_group = (n > 0).then(|| {
            self.kept.get(
                device,
                "classify",
                &self.layout,
                0,
                &[
                    pool.as_entire_binding(),
                    self.records.buffer.as_entire_binding(),
                    self.state.buffer.as_entire_binding(),
                ],
            )
        });
    }

    pub(super) fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        ts: Option<&Timestamps>,
        slot: usize,
    ) {
        let mut p = compute_pass(encoder, ts, slot);
        if let Some(bg) = &self.bind_group {
            p.set_pipeline(&self.pipeline);
            p.set_bind_group(0, bg, &[]);
            p.dispatch_workgroups(self.surfaces, 1, 1);
        }
    }
}
