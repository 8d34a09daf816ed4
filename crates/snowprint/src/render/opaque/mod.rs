//! The `opaque` pass: the frame's meshes (rooftops, props, people) into the scene colour and
//! depth, lit by the moon through its shadow map and by the point lights (`shading.wgsl`).
//! Forward (`mesh.wgsl`), each fragment is shaded; through the visibility buffer
//! (`visibility.rs`), the pass writes depth and each pixel's (instance, triangle) and the
//! `opaque_shade` compute pass shades them. `mesh.wgsl` also holds the shadow pass's `vs_shadow`:
//! both passes build on the module made by [`mesh_module`].

mod geometry;
mod visibility;

use super::config::OpaquePath;
use super::graph::PASSES;
use super::meshes::{DrawSet, MeshSet};
use super::readback::{Timestamps, compute_pass, render_writes};
use super::targets::Targets;
use super::{gpu, pipeline};
use visibility::VisibilityPass;

/// The module of `mesh.wgsl` (after `frame.wgsl` and `snow.wgsl`).
pub(super) fn mesh_module(device: &wgpu::Device) -> wgpu::ShaderModule {
    pipeline::shader(device, "mesh.wgsl", crate::wgsl::MESH.wgsl())
}

pub(super) struct OpaquePass {
    pipeline: wgpu::RenderPipeline,
    /// The visibility path's pipelines (only on `OpaquePath::Visibility`).
    visibility: Option<VisibilityPass>,
}

impl OpaquePass {
    pub(super) fn new(
        device: &wgpu::Device,
        mesh_module: &wgpu::ShaderModule,
        frame_layout: &wgpu::BindGroupLayout,
        path: OpaquePath,
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
        let visibility =
            (path == OpaquePath::Visibility).then(|| VisibilityPass::new(device, frame_layout));
        Self {
            pipeline,
            visibility,
        }
    }

    /// The visibility path's uploads and bind groups (nothing on the forward path).
    pub(super) fn prepare(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        meshes: &MeshSet,
        targets: &Targets,
    ) {
        if let Some(v) = &mut self.visibility {
            v.prepare(device, queue, meshes, targets);
        }
    }

    /// The `opaque_shade` pass: the visibility buffer shaded (an empty compute pass on the
    /// forward path).
    pub(super) fn encode_shade(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        ts: Option<&Timestamps>,
        slot: usize,
        frame: &wgpu::BindGroup,
    ) {
        match &self.visibility {
            Some(v) => v.encode_shade(encoder, ts, slot, frame),
            None => drop(compute_pass(encoder, ts, slot)),
        }
    }

    /// Forward: clear colour and depth, then draw every instance. Visibility: the same into depth
    /// and the visibility buffer.
    pub(super) fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        ts: Option<&Timestamps>,
        slot: usize,
        targets: &Targets,
        frame: &wgpu::BindGroup,
        meshes: &MeshSet,
    ) {
        if let Some(v) = &self.visibility {
            return v.encode_raster(encoder, ts, slot, targets, frame, meshes);
        }
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
        if meshes.has_draws(DrawSet::Opaque) {
            p.set_pipeline(&self.pipeline);
            p.set_bind_group(0, frame, &[]);
            meshes.draw(&mut p, DrawSet::Opaque);
        }
    }
}
