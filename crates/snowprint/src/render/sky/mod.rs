//! The `sky` pass (`sky.wgsl`): the night sky, the moon and the haze, drawn as one triangle behind
//! everything (depth test only).

use super::graph::PASSES;
use super::pipeline;
use super::readback::{Timestamps, render_writes};
use super::targets::Targets;

pub(super) struct SkyPass {
    pipeline: wgpu::RenderPipeline,
}

impl SkyPass {
    pub(super) fn new(device: &wgpu::Device, frame_layout: &wgpu::BindGroupLayout) -> Self {
        let module = pipeline::shader(device, "sky.wgsl", crate::wgsl::SKY.wgsl());
        let pipeline = pipeline::Raster {
            label: "sky",
            module: &module,
            vs: "vs_sky",
            fs: "fs_sky",
            buffers: &[],
            groups: &[frame_layout],
            primitive: wgpu::PrimitiveState::default(),
            depth: pipeline::depth_state(wgpu::CompareFunction::LessEqual, false),
            targets: &pipeline::hdr_target(),
            constants: &[],
        }
        .build(device);
        Self { pipeline }
    }

    pub(super) fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        ts: Option<&Timestamps>,
        slot: usize,
        targets: &Targets,
        frame: &wgpu::BindGroup,
    ) {
        let mut p = targets.scene_pass(
            encoder,
            PASSES[slot].name,
            wgpu::LoadOp::Load,
            None,
            render_writes(ts, slot),
        );
        p.set_pipeline(&self.pipeline);
        p.set_bind_group(0, frame, &[]);
        p.draw(0..3, 0..1);
    }
}
