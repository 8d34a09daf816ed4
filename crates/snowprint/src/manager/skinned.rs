//! Skinned meshes under the manager. A surface the budget leaves waiting is pressed later, frame by
//! frame, with each queued frame's deformers, so a mesh must be pressed in the pose it had in that
//! frame, not the pose it has when its surface's turn comes. The manager therefore poses a skinned
//! mesh on the CPU (the skinning reference, `skin/cpu.rs`) and hands the vertices to
//! [`SnowManager::pose_mesh`], which keeps every posing a queued imprint still names and frees it
//! once none does. (A plain [`crate::SnowWorld`] skins on the GPU instead: it presses every frame
//! as it comes.)

use std::collections::HashMap;

use super::SnowManager;
use crate::error::{Result, SnowError};
use crate::mesh::MeshId;
use crate::skin::{SkinnedMesh, skin_vertices};
use crate::world::MeshAnimation;

/// The skeletons of the manager's skinned meshes, by the manager's mesh index.
#[derive(Default)]
pub(super) struct ManagedSkins {
    by_mesh: HashMap<u32, SkinnedMesh>,
}

impl SnowManager {
    /// Register a skinned mesh as a deformer shape, in its rest pose; pose it each frame with
    /// [`SnowManager::animate_meshes`] before [`SnowManager::tick`]. The handle is the manager's,
    /// as [`SnowManager::add_mesh`]'s.
    ///
    /// # Errors
    ///
    /// [`SnowError::InvalidMesh`] when the mesh, or its rest pose, is not usable as a deformer.
    pub fn add_skinned_mesh(&mut self, name: &str, skinned: &SkinnedMesh) -> Result<MeshId> {
        let rest = skinned.rest_mesh(name)?;
        let id = self.add_mesh(name, &rest)?;
        self.skins.by_mesh.insert(id.0, skinned.clone());
        Ok(id)
    }

    /// Give mesh `id` (registered with [`SnowManager::add_mesh`], or restored from a save, which
    /// keeps a mesh's last posing but not its skeleton) the skeleton and animations of `skinned`,
    /// whose vertices and triangles it must have.
    ///
    /// # Errors
    ///
    /// [`SnowError::StaleHandle`] for an unknown mesh, [`SnowError::PoseMismatch`] when the
    /// vertex counts differ, [`SnowError::InvalidMesh`] as [`SnowManager::add_skinned_mesh`].
    pub fn set_skin(&mut self, id: MeshId, skinned: &SkinnedMesh) -> Result<()> {
        let m = self.mesh(id)?;
        let rest = skinned.rest_mesh(&m.name)?;
        if rest.positions.len() != m.mesh.positions.len() {
            return Err(SnowError::PoseMismatch {
                mesh: id.0,
                got: rest.positions.len(),
                expected: m.mesh.positions.len(),
            });
        }
        self.skins.by_mesh.insert(id.0, skinned.clone());
        Ok(())
    }

    /// Pose skinned meshes at their animations' times (the manager's mesh handles): each is
    /// skinned on the CPU and re-posed with [`SnowManager::pose_mesh`], so imprints already queued
    /// keep the pose they were made with.
    ///
    /// # Errors
    ///
    /// [`SnowError::StaleHandle`] for a mesh without a skeleton, [`SnowError::InvalidMesh`] for an
    /// animation the mesh does not have; the meshes listed before it are posed.
    pub fn animate_meshes(&mut self, poses: &[MeshAnimation]) -> Result<()> {
        for p in poses {
            let skinned = self
                .skins
                .by_mesh
                .get(&p.mesh.0)
                .ok_or(SnowError::StaleHandle {
                    what: "skinned mesh",
                    index: p.mesh.0,
                })?;
            if let Some(a) = p.animation
                && a >= skinned.animations.len()
            {
                return Err(SnowError::InvalidMesh {
                    name: format!("mesh {}", p.mesh.0),
                    reason: format!(
                        "has no animation {a}; it has {} animations",
                        skinned.animations.len()
                    ),
                });
            }
            let joints = skinned.pose(p.animation, p.time, p.playback);
            let posed = skin_vertices(&skinned.mesh.positions, &skinned.influences, &joints);
            self.pose_mesh(p.mesh, &posed)?;
        }
        Ok(())
    }
}
