//! The `opaque` pass: the frame's meshes (rooftops, props, people) into the scene colour and
//! depth, lit by the moon through its shadow map and by the point lights. `mesh.wgsl` also holds
//! the shadow pass's `vs_shadow`: both passes build on the module made by [`mesh_module`].

use super::graph::PASSES;
use super::meshes::MeshSet;
use super::readback::{Timestamps, render_writes};
use super::targets::Targets;
use super::{gpu, pipeline};

/// The module of `mesh.wgsl` (after `frame.wgsl` and `snow.wgsl`).
pub(super) fn mesh_module(device: &wgpu::Device) -> wgpu::ShaderModule {
    pipeline::shader(device, "mesh.wgsl", crate::wgsl::MESH.wgsl())
}

pub(super) struct OpaquePass {
    pipeline: wgpu::RenderPipeline,
}

impl OpaquePass {
    pub(super) fn new(
        device: &wgpu::Device,
        mesh_module: &wgpu::ShaderModule,
        frame_layout: &wgpu::BindGroupLayout,
    ) -> Self {
        let buffers: Vec<Option<wgpu::VertexBufferLayout>> =
            gpu::mesh_vertex_layouts().into_iter().map(Some).collect();
        let pipeline = pipeline::Raster {
            label: "opaque meshes",
            module: mesh_module,
            vs: "vs_mesh",
            fs: "fs_mesh",
            buffers: &buffers,
            groups: &[frame_layout],
            primitive: pipeline::back_culled(),
            depth: pipeline::depth_state(wgpu::CompareFunction::Less, true),
            targets: &pipeline::hdr_target(),
            constants: &[],
        }
        .build(device);
        Self { pipeline }
    }

    /// Clear colour and depth, then draw every instance.
    pub(super) fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        ts: Option<&Timestamps>,
        slot: usize,
        targets: &Targets,
        frame: &wgpu::BindGroup,
        meshes: &MeshSet,
    ) {
        let clear_depth = wgpu::Operations {
            load: wgpu::LoadOp::Clear(1.0),
            store: wgpu::StoreOp::Store,
        };
        let mut p = targets.scene_pass(
            encoder,
            PASSES[slot].name,
            wgpu::LoadOp::Clear(wgpu::Color::BLACK),
            Some(clear_depth),
            render_writes(ts, slot),
        );
        if meshes.has_draws(false) {
            p.set_pipeline(&self.pipeline);
            p.set_bind_group(0, frame, &[]);
            meshes.draw(&mut p, false);
        }
    }
}
