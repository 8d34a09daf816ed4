//! The `snowfall` pass (`snowfall.wgsl`): falling flakes as instanced quads, blended over the
//! scene and hidden by its depth. The frame uniform carries the number of flakes (0: none).

use super::graph::PASSES;
use super::pipeline;
use super::readback::{Timestamps, render_writes};
use super::targets::Targets;

pub(super) struct SnowfallPass {
    pipeline: wgpu::RenderPipeline,
}

impl SnowfallPass {
    pub(super) fn new(device: &wgpu::Device, frame_layout: &wgpu::BindGroupLayout) -> Self {
        let module = pipeline::shader(device, "snowfall.wgsl", crate::wgsl::SNOWFALL.wgsl());
        let blended = [Some(wgpu::ColorTargetState {
            format: super::targets::HDR_FORMAT,
            blend: Some(wgpu::BlendState::PREMULTIPLIED_ALPHA_BLENDING),
            write_mask: wgpu::ColorWrites::ALL,
        })];
        let pipeline = pipeline::Raster {
            label: "snowfall",
            module: &module,
            vs: "vs_flake",
            fs: "fs_flake",
            buffers: &[],
            groups: &[frame_layout],
            primitive: wgpu::PrimitiveState::default(),
            depth: pipeline::depth_state(wgpu::CompareFunction::Less, false),
            targets: &blended,
            constants: &[],
        }
        .build(device);
        Self { pipeline }
    }

    /// Draw `flakes` flakes (the frame uniform's count).
    pub(super) fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        ts: Option<&Timestamps>,
        slot: usize,
        targets: &Targets,
        frame: &wgpu::BindGroup,
        flakes: u32,
    ) {
        let mut p = targets.scene_pass(
            encoder,
            PASSES[slot].name,
            wgpu::LoadOp::Load,
            None,
            render_writes(ts, slot),
        );
        if flakes > 0 {
            p.set_pipeline(&self.pipeline);
            p.set_bind_group(0, frame, &[]);
            p.draw(0..6, 0..flakes);
        }
    }
}
