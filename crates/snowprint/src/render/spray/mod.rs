//! The `spray` pass (`spray.wgsl`): the world's kicked-up snow (`crate::spray`), its ring's live
//! particles as instanced quads lit like the snowfall, blended over the scene and hidden by its
//! depth. Encoded empty when the world has no spray.

use super::graph::PASSES;
use super::pipeline;
use super::readback::{Timestamps, render_writes};
use super::targets::Targets;

/// The world's ring and its capacity, particles.
pub(super) type SprayRing<'a> = Option<(&'a wgpu::Buffer, u32)>;

pub(super) struct SprayPass {
    pipeline: wgpu::RenderPipeline,
}

impl SprayPass {
    pub(super) fn new(device: &wgpu::Device, frame_layout: &wgpu::BindGroupLayout) -> Self {
        let module = pipeline::shader(device, "spray.wgsl", crate::wgsl::SPRAY.wgsl());
        let blended = [Some(wgpu::ColorTargetState {
            format: super::targets::HDR_FORMAT,
            blend: Some(wgpu::BlendState::PREMULTIPLIED_ALPHA_BLENDING),
            write_mask: wgpu::ColorWrites::ALL,
        })];
        // One instance a particle: `Particle` of src/spray/mod.rs (position, life; velocity, age;
        // albedo as RGBA8; radius and drag).
        let particle = [Some(wgpu::VertexBufferLayout {
            array_stride: std::mem::size_of::<crate::spray::Particle>() as u64,
            step_mode: wgpu::VertexStepMode::Instance,
            attributes: &wgpu::vertex_attr_array![
                0 => Float32x4, 1 => Float32x4, 2 => Unorm8x4, 3 => Float32x2
            ],
        })];
        let pipeline = pipeline::Raster {
            label: "spray",
            module: &module,
            vs: "vs_spray",
            fs: "fs_spray",
            buffers: &particle,
            groups: &[frame_layout],
            primitive: wgpu::PrimitiveState::default(),
            depth: pipeline::depth_state(wgpu::CompareFunction::Less, false),
            targets: &blended,
            constants: &[],
        }
        .build(device);
        Self { pipeline }
    }

    /// Draw every slot of the world's ring (dead ones drop out in the vertex shader).
    pub(super) fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        ts: Option<&Timestamps>,
        slot: usize,
        targets: &Targets,
        frame: &wgpu::BindGroup,
        ring: SprayRing<'_>,
    ) {
        let mut p = targets.scene_pass(
            encoder,
            PASSES[slot].name,
            wgpu::LoadOp::Load,
            None,
            render_writes(ts, slot),
        );
        if let Some((buffer, capacity)) = ring {
            p.set_pipeline(&self.pipeline);
            p.set_bind_group(0, frame, &[]);
            p.set_vertex_buffer(0, buffer.slice(crate::spray::SPRAY_RING_HEADER..));
            p.draw(0..6, 0..capacity);
        }
    }
}
