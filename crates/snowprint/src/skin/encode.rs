//! The skinning pass (compute, `skin.wgsl`): for each posed skinned mesh, one dispatch that blends
//! its joint matrices into the vertex buffer the capture draws for it. The bind pose and
//! influences are uploaded once, with the mesh; a frame uploads only the joint matrices.

use glam::Mat4;

use super::SkinnedMesh;
use crate::gpu::resources::bind_group;

/// Vertices a workgroup skins (`SKIN_WORKGROUP` in `wgsl/constants.wgsl`).
pub const SKIN_WORKGROUP: u32 = crate::wgsl::consts::SKIN_WORKGROUP;

/// A bind-pose vertex as the pass reads it. Must match `BindVertex` in `skin.wgsl` (48 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct GpuBindVertex {
    /// Bind-pose position, `w` unused.
    pub position: [f32; 4],
    /// Weights of the four joints.
    pub weights: [f32; 4],
    /// The four joints.
    pub joints: [u32; 4],
}

/// The pass's uniform. Must match `SkinParams` in `skin.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
struct SkinParams {
    vertex_count: u32,
    joint_count: u32,
    _pad: [u32; 2],
}

/// The skinning pipeline and its bind-group layout (made once a world has a skinned mesh).
#[derive(Debug)]
pub(crate) struct SkinPipeline {
    layout: wgpu::BindGroupLayout,
    pipeline: wgpu::ComputePipeline,
}

impl SkinPipeline {
    pub(crate) fn new(device: &wgpu::Device) -> Self {
        let layout = crate::wgsl::SKIN.bind_group_layout(device, "skin", 0);
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("skin.wgsl"),
            source: wgpu::ShaderSource::Wgsl(crate::wgsl::SKIN.wgsl().into()),
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("skin"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("skin"),
            layout: Some(&pipeline_layout),
            module: &module,
            entry_point: Some("skin"),
            compilation_options: Default::default(),
            cache: None,
        });
        Self { layout, pipeline }
    }
}

/// One skinned mesh's GPU side: its bind pose and influences, its joint matrices (rewritten each
/// frame it is posed) and the bind group that writes its capture vertex buffer.
#[derive(Debug)]
pub(crate) struct SkinGpu {
    joints: wgpu::Buffer,
    bind_group: wgpu::BindGroup,
    vertex_count: u32,
    joint_count: usize,
}

impl SkinGpu {
    /// Upload `skinned`'s bind pose and influences; `vertices` is the capture's vertex buffer of
    /// the mesh (`STORAGE` usage, 12 bytes a vertex).
    pub(crate) fn new(
        device: &wgpu::Device,
        pipe: &SkinPipeline,
        skinned: &SkinnedMesh,
        vertices: &wgpu::Buffer,
    ) -> Self {
        use wgpu::util::DeviceExt;
        let bind: Vec<GpuBindVertex> = skinned
            .mesh
            .positions
            .iter()
            .zip(&skinned.influences)
            .map(|(p, inf)| GpuBindVertex {
                position: p.extend(1.0).to_array(),
                weights: inf.weights,
                joints: inf.joints,
            })
            .collect();
        let init = |label: &str, contents: &[u8], usage: wgpu::BufferUsages| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents,
                usage,
            })
        };
        use wgpu::BufferUsages as U;
        let params = SkinParams {
            vertex_count: bind.len() as u32,
            joint_count: skinned.joints.len() as u32,
            _pad: [0; 2],
        };
        let params = init("skin params", bytemuck::bytes_of(&params), U::UNIFORM);
        let bind_buf = init("skin bind pose", bytemuck::cast_slice(&bind), U::STORAGE);
        let identity = vec![Mat4::IDENTITY; skinned.joints.len().max(1)];
        let joints = init(
            "skin joint matrices",
            bytemuck::cast_slice(&identity),
            U::STORAGE | U::COPY_DST,
        );
        let bind_group = bind_group(
            device,
            "skin",
            &pipe.layout,
            &[
                params.as_entire_binding(),
                bind_buf.as_entire_binding(),
                joints.as_entire_binding(),
                vertices.as_entire_binding(),
            ],
        );
        Self {
            joints,
            bind_group,
            vertex_count: bind.len() as u32,
            joint_count: skinned.joints.len(),
        }
    }

    /// Joint matrices the mesh takes.
    pub(crate) fn joint_count(&self) -> usize {
        self.joint_count
    }

    /// Upload this frame's joint matrices (as many as [`SkinGpu::joint_count`]).
    pub(crate) fn write_joints(&self, queue: &wgpu::Queue, joints: &[Mat4]) {
        queue.write_buffer(&self.joints, 0, bytemuck::cast_slice(joints));
    }
}

/// Record one compute pass that skins every mesh of `meshes` (their joints already written).
pub(crate) fn encode(enc: &mut wgpu::CommandEncoder, pipe: &SkinPipeline, meshes: &[&SkinGpu]) {
    if meshes.is_empty() {
        return;
    }
    let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
        label: Some("skin"),
        timestamp_writes: None,
    });
    pass.set_pipeline(&pipe.pipeline);
    for m in meshes {
        pass.set_bind_group(0, &m.bind_group, &[]);
        pass.dispatch_workgroups(m.vertex_count.div_ceil(SKIN_WORKGROUP), 1, 1);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `GpuBindVertex` and `SkinParams` as naga lays out `BindVertex` and `SkinParams`.
    #[test]
    fn bind_vertex_layout_matches_wgsl() {
        let module = naga::front::wgsl::parse_str(crate::wgsl::SKIN.source).unwrap();
        let mut layouter = naga::proc::Layouter::default();
        layouter.update(module.to_ctx()).unwrap();
        let size_of = |name: &str| {
            let (handle, _) = module
                .types
                .iter()
                .find(|(_, t)| t.name.as_deref() == Some(name))
                .unwrap();
            layouter[handle].size as usize
        };
        assert_eq!(size_of("BindVertex"), std::mem::size_of::<GpuBindVertex>());
        assert_eq!(size_of("SkinParams"), std::mem::size_of::<SkinParams>());
        assert_eq!(std::mem::size_of::<GpuBindVertex>(), 48);
    }
}
