//! Skinned mesh deformers: registered with their skeleton and animations, posed each frame by the
//! skinning pass (`skin/`) straight into the vertex buffer the capture draws, before the frame is
//! stepped.
//!
//! Footsteps (`footstep.rs`) judge a skinned mesh by its vertices at registration (the rest pose):
//! the posed vertices stay on the GPU.

use glam::{Mat4, Vec3};

use super::SnowWorld;
use crate::capture::CaptureMesh;
use crate::error::{Result, SnowError};
use crate::mesh::MeshId;
use crate::skin::{Playback, SkinGpu, SkinPipeline, SkinnedMesh};

/// One skinned mesh's pose for a frame: an animation of its file at a time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeshAnimation {
    /// The mesh, registered with [`SnowWorld::add_skinned_mesh`].
    pub mesh: MeshId,
    /// Index of the animation in [`SkinnedMesh::animations`]; `None` poses the rest transforms.
    pub animation: Option<usize>,
    /// Seconds since the animation started (already scaled by any playback speed).
    pub time: f32,
    /// What happens past the animation's end.
    pub playback: Playback,
}

/// A registered skinned mesh.
struct Skin {
    skinned: SkinnedMesh,
    /// Bounds of the vertices each joint moves (for the posed radius).
    bounds: Vec<(Vec3, f32)>,
    gpu: SkinGpu,
}

/// The world's skinned meshes, by mesh index, and the pipeline (made with the first one).
#[derive(Default)]
pub(super) struct Skins {
    pipeline: Option<SkinPipeline>,
    by_mesh: Vec<Option<Skin>>,
}

impl Skins {
    /// Drop a removed mesh's skin, if it had one.
    pub(super) fn forget(&mut self, index: usize) {
        if let Some(s) = self.by_mesh.get_mut(index) {
            *s = None;
        }
    }
}

impl SnowWorld {
    /// Register a skinned mesh as a deformer shape. Its vertices start in the rest pose; pose it
    /// each frame with [`SnowWorld::animate_meshes`] (or [`SnowWorld::skin_meshes`]) before
    /// stepping. The deformer's own [`crate::Pose`] moves the whole figure.
    ///
    /// # Errors
    ///
    /// [`SnowError::InvalidMesh`] when the mesh, or its rest pose, is not usable as a deformer.
    pub fn add_skinned_mesh(&mut self, name: &str, skinned: &SkinnedMesh) -> Result<MeshId> {
        let rest_mesh = skinned.rest_mesh(name)?;
        let rest = skinned.pose(None, 0.0, Playback::Clamp);
        use wgpu::BufferUsages as U;
        use wgpu::util::DeviceExt;
        let vertices = self
            .device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("skinned deformer mesh vertices"),
                contents: bytemuck::cast_slice(&rest_mesh.positions),
                usage: U::VERTEX | U::STORAGE | U::COPY_DST | U::COPY_SRC,
            });
        let indices = self
            .device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("skinned deformer mesh indices"),
                contents: bytemuck::cast_slice(&rest_mesh.indices),
                usage: U::INDEX,
            });
        let device = &self.device;
        let pipe = self
            .skins
            .pipeline
            .get_or_insert_with(|| SkinPipeline::new(device));
        let gpu = SkinGpu::new(device, pipe, skinned, &vertices);
        let bounds = skinned.joint_bounds();
        self.meshes.push(Some(CaptureMesh {
            vertices,
            indices,
            index_count: rest_mesh.indices.len() as u32,
            vertex_count: rest_mesh.positions.len(),
            radius: SkinnedMesh::posed_radius(&bounds, &rest),
        }));
        let index = self.meshes.len() - 1;
        self.probes.keep_mesh(index, &rest_mesh.positions);
        if self.skins.by_mesh.len() <= index {
            self.skins.by_mesh.resize_with(index + 1, || None);
        }
        self.skins.by_mesh[index] = Some(Skin {
            skinned: skinned.clone(),
            bounds,
            gpu,
        });
        Ok(MeshId(index as u32))
    }

    /// The skinned mesh registered as `id`.
    ///
    /// # Errors
    ///
    /// [`SnowError::StaleHandle`] when `id` is not a live skinned mesh of this world.
    pub fn skinned_mesh(&self, id: MeshId) -> Result<&SkinnedMesh> {
        self.skin(id).map(|s| &s.skinned)
    }

    fn skin(&self, id: MeshId) -> Result<&Skin> {
        self.skins
            .by_mesh
            .get(id.0 as usize)
            .and_then(Option::as_ref)
            .ok_or(SnowError::StaleHandle {
                what: "skinned mesh",
                index: id.0,
            })
    }

    /// Pose skinned meshes at their animations' times: the skeletons are posed on the CPU and the
    /// vertices skinned on the GPU, in one compute pass submitted before this returns (so the next
    /// step draws them). [`SnowWorld::encode_animate_meshes`] records it into an engine's encoder.
    ///
    /// # Errors
    ///
    /// [`SnowError::StaleHandle`] for a mesh that is not a live skinned mesh of this world,
    /// [`SnowError::InvalidMesh`] for an animation index the mesh does not have.
    pub fn animate_meshes(&mut self, poses: &[MeshAnimation]) -> Result<()> {
        let mut enc = self.skin_encoder();
        self.encode_animate_meshes(&mut enc, poses)?;
        self.queue.submit([enc.finish()]);
        Ok(())
    }

    /// [`SnowWorld::animate_meshes`] recorded into the caller's `encoder`, ahead of the frame's
    /// [`SnowWorld::encode_step`] in the same encoder (the joints are written with
    /// `queue.write_buffer`, so they land with the caller's submit). Refused with
    /// [`SnowError::FramePending`] while a frame is encoded and not submitted (its capture would
    /// draw the new joints).
    ///
    /// # Errors
    ///
    /// As [`SnowWorld::animate_meshes`].
    pub fn encode_animate_meshes(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        poses: &[MeshAnimation],
    ) -> Result<()> {
        let mut joints = Vec::with_capacity(poses.len());
        for p in poses {
            let skin = self.skin(p.mesh)?;
            if let Some(a) = p.animation
                && a >= skin.skinned.animations.len()
            {
                return Err(SnowError::InvalidMesh {
                    name: format!("mesh {}", p.mesh.0),
                    reason: format!(
                        "has no animation {a}; it has {} animations",
                        skin.skinned.animations.len()
                    ),
                });
            }
            joints.push(skin.skinned.pose(p.animation, p.time, p.playback));
        }
        let posed: Vec<(MeshId, &[Mat4])> = poses
            .iter()
            .zip(&joints)
            .map(|(p, j)| (p.mesh, j.as_slice()))
            .collect();
        self.encode_skin_meshes(encoder, &posed)
    }

    fn skin_encoder(&self) -> wgpu::CommandEncoder {
        self.device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("skin"),
            })
    }

    /// Skin meshes with joint matrices given by the caller (`global * inverse bind` of each joint,
    /// as [`SkinnedMesh::pose`] computes them), in one compute pass submitted before this returns.
    ///
    /// # Errors
    ///
    /// [`SnowError::StaleHandle`] for a mesh that is not a live skinned mesh of this world,
    /// [`SnowError::JointCount`] when the number of matrices is not the mesh's joint count,
    /// [`SnowError::InvalidMesh`] for a matrix that is not finite.
    pub fn skin_meshes(&mut self, poses: &[(MeshId, &[Mat4])]) -> Result<()> {
        let mut enc = self.skin_encoder();
        self.encode_skin_meshes(&mut enc, poses)?;
        self.queue.submit([enc.finish()]);
        Ok(())
    }

    /// [`SnowWorld::skin_meshes`] recorded into the caller's `encoder` (see
    /// [`SnowWorld::encode_animate_meshes`] for where it goes).
    ///
    /// # Errors
    ///
    /// As [`SnowWorld::skin_meshes`], and [`SnowError::FramePending`].
    pub fn encode_skin_meshes(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        poses: &[(MeshId, &[Mat4])],
    ) -> Result<()> {
        if self.in_flight.is_some() {
            return Err(SnowError::FramePending);
        }
        for &(id, joints) in poses {
            let skin = self.skin(id)?;
            if joints.len() != skin.gpu.joint_count() {
                return Err(SnowError::JointCount {
                    mesh: id.0,
                    got: joints.len(),
                    expected: skin.gpu.joint_count(),
                });
            }
            if let Some(m) = joints.iter().find(|m| !m.is_finite()) {
                return Err(SnowError::InvalidMesh {
                    name: format!("mesh {}", id.0),
                    reason: format!("joint matrix {m:?} is not finite"),
                });
            }
        }
        let Some(pipe) = &self.skins.pipeline else {
            return Ok(());
        };
        let mut gpus = Vec::with_capacity(poses.len());
        for &(id, joints) in poses {
            let index = id.0 as usize;
            let Some(skin) = self.skins.by_mesh[index].as_ref() else {
                continue;
            };
            skin.gpu.write_joints(&self.queue, joints);
            if let Some(mesh) = self.meshes[index].as_mut() {
                mesh.radius = SkinnedMesh::posed_radius(&skin.bounds, joints);
            }
            gpus.push(&skin.gpu);
        }
        crate::skin::record(encoder, pipe, &gpus);
        Ok(())
    }

    /// The vertices of a mesh deformer as the capture will draw them (posed or skinned), read back
    /// from the GPU (for tests and tools: it waits for the GPU).
    ///
    /// # Errors
    ///
    /// [`SnowError::StaleHandle`] for a mesh that is not a live skinned mesh of this world;
    /// readback errors.
    pub fn read_skinned_vertices(&self, id: MeshId) -> Result<Vec<Vec3>> {
        self.skin(id)?;
        let mesh = self.meshes[id.0 as usize]
            .as_ref()
            .ok_or(SnowError::StaleHandle {
                what: "mesh",
                index: id.0,
            })?;
        let bytes = crate::gpu::readback::download(
            &self.device,
            &self.queue,
            &mesh.vertices,
            0,
            mesh.vertex_count as u64 * 12,
        )?;
        Ok(bytemuck::pod_collect_to_vec::<u8, f32>(&bytes)
            .chunks_exact(3)
            .map(Vec3::from_slice)
            .collect())
    }
}
