//! A posable character: a skeleton, its skins, skinned meshes and clips (the model), and
//! [`CharacterData`], every buffer posing needs (sized once; posing allocates nothing).

use crate::SkinError;
use crate::clip::Clip;
use crate::mesh::SkinnedMesh;
use crate::skeleton::{Pose, Skeleton, Skin};
use crate::skinning::{Skinned, SkinningMethod, skin};
use anim_core::glam::DMat4;

/// A skinned mesh with the index of the skin it is bound to.
#[derive(Debug, Clone)]
pub struct CharacterMesh {
    /// Name (glTF mesh name and primitive, or made up).
    pub name: String,
    /// Index into [`Character::skins`].
    pub skin: usize,
    /// The mesh.
    pub mesh: SkinnedMesh,
    /// Where it came from in a glTF file (`None` for meshes built in code).
    pub source: Option<GltfSource>,
}

/// The glTF elements a [`CharacterMesh`] was read from: one per skinned node and primitive (a
/// glTF mesh used by two skinned nodes gives two meshes).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct GltfSource {
    /// Index of the node in the file's `nodes`.
    pub node: usize,
    /// Index of the mesh in `meshes`.
    pub mesh: usize,
    /// Index of the primitive in the mesh's `primitives`.
    pub primitive: usize,
}

/// Skeleton, skins, meshes and clips. Never modified by posing.
#[derive(Debug, Clone)]
pub struct Character {
    /// The joint hierarchy (for glTF: every node on a path to a joint, parents first).
    pub skeleton: Skeleton,
    /// Skins over the skeleton.
    pub skins: Vec<Skin>,
    /// Skinned meshes.
    pub meshes: Vec<CharacterMesh>,
    /// Animation clips.
    pub clips: Vec<Clip>,
}

/// Scratch and outputs of posing a [`Character`].
#[derive(Debug, Clone)]
pub struct CharacterData {
    /// The local pose last sampled.
    pub pose: Pose,
    /// Global joint matrices.
    pub global: Vec<DMat4>,
    /// Skinning matrices per skin.
    pub skinning: Vec<Vec<DMat4>>,
    /// Posed meshes, one per [`Character::meshes`].
    pub skinned: Vec<Skinned>,
}

impl Character {
    /// A character after checking that every mesh's skin exists and matches its joint count.
    ///
    /// # Errors
    /// [`SkinError::BadSkin`] on a mismatch.
    pub fn new(
        skeleton: Skeleton,
        skins: Vec<Skin>,
        meshes: Vec<CharacterMesh>,
        clips: Vec<Clip>,
    ) -> Result<Self, SkinError> {
        for (i, m) in meshes.iter().enumerate() {
            let Some(s) = skins.get(m.skin) else {
                return Err(SkinError::BadSkin(format!("mesh {i} uses skin {} of {}", m.skin, skins.len())));
            };
            if s.len() != m.mesh.num_joints() {
                return Err(SkinError::BadSkin(format!(
                    "mesh {i} is bound to {} joints, skin {} has {}",
                    m.mesh.num_joints(),
                    m.skin,
                    s.len()
                )));
            }
        }
        Ok(Self { skeleton, skins, meshes, clips })
    }

    /// Buffers for posing this character.
    #[must_use]
    pub fn data(&self) -> CharacterData {
        CharacterData {
            pose: self.skeleton.rest_pose(),
            global: vec![DMat4::IDENTITY; self.skeleton.len()],
            skinning: self.skins.iter().map(|s| vec![DMat4::IDENTITY; s.len()]).collect(),
            skinned: self.meshes.iter().map(|m| Skinned::new(&m.mesh)).collect(),
        }
    }

    /// Total vertex count over all meshes.
    #[must_use]
    pub fn num_vertices(&self) -> usize {
        self.meshes.iter().map(|m| m.mesh.len()).sum()
    }

    /// All triangles, meshes concatenated in order (indices offset like [`CharacterData::positions`]).
    #[must_use]
    pub fn triangles(&self) -> Vec<[u32; 3]> {
        let mut out = Vec::new();
        let mut offset = 0u32;
        for m in &self.meshes {
            out.extend(m.mesh.triangles().iter().map(|t| t.map(|i| i + offset)));
            offset += m.mesh.len() as u32;
        }
        out
    }

    /// Samples clip `clip` at `t` (`None`: the rest pose) and skins every mesh.
    ///
    /// # Errors
    /// What [`skin`] returns.
    ///
    /// # Panics
    /// If `clip` is out of range or `data` was made for another character (API misuse).
    #[track_caller]
    pub fn pose(
        &self,
        data: &mut CharacterData,
        clip: Option<usize>,
        t: f64,
        method: SkinningMethod,
    ) -> Result<(), SkinError> {
        match clip {
            Some(c) => self.clips[c].sample(&self.skeleton, t, &mut data.pose),
            None => data.pose.reset(&self.skeleton),
        }
        self.pose_with(data, method)
    }

    /// Skins every mesh from the local pose already in `data.pose` (for blended or hand-made
    /// poses).
    ///
    /// # Errors
    /// What [`skin`] returns.
    pub fn pose_with(&self, data: &mut CharacterData, method: SkinningMethod) -> Result<(), SkinError> {
        self.skeleton.forward_kinematics(&data.pose, &mut data.global);
        for (s, out) in self.skins.iter().zip(&mut data.skinning) {
            s.skinning_matrices(&data.global, out);
        }
        for (m, out) in self.meshes.iter().zip(&mut data.skinned) {
            skin(&m.mesh, &data.skinning[m.skin], method, out)?;
        }
        Ok(())
    }
}

impl CharacterData {
    /// Sets DQS's rigidity tolerance of every mesh ([`Skinned::set_rigid_tolerance`]; default
    /// [`crate::skinning::RIGID_TOLERANCE`]).
    ///
    /// # Errors
    /// [`SkinError::BadTolerance`] unless `0 <= tolerance < 1`; nothing is changed then.
    pub fn set_rigid_tolerance(&mut self, tolerance: f64) -> Result<(), SkinError> {
        for s in &mut self.skinned {
            s.set_rigid_tolerance(tolerance)?;
        }
        Ok(())
    }

    /// Posed positions of mesh `mesh` alone ([`Character::meshes`] order), written into `out`
    /// (cleared first).
    ///
    /// # Panics
    /// If `mesh` is out of range (API misuse).
    #[track_caller]
    pub fn mesh_positions(&self, mesh: usize, out: &mut Vec<[f64; 3]>) {
        let s = &self.skinned[mesh];
        out.clear();
        out.extend((0..s.x.len()).map(|v| s.position(v)));
    }

    /// Posed normals of mesh `mesh` alone, written into `out` (cleared first).
    ///
    /// # Panics
    /// If `mesh` is out of range (API misuse).
    #[track_caller]
    pub fn mesh_normals(&self, mesh: usize, out: &mut Vec<[f64; 3]>) {
        let s = &self.skinned[mesh];
        out.clear();
        out.extend((0..s.x.len()).map(|v| s.normal(v)));
    }

    /// Posed positions of all meshes, concatenated, written into `out` (cleared first);
    /// [`CharacterData::mesh_positions`] gives one mesh's.
    pub fn positions(&self, out: &mut Vec<[f64; 3]>) {
        out.clear();
        for s in &self.skinned {
            out.extend((0..s.x.len()).map(|v| s.position(v)));
        }
    }

    /// Posed normals of all meshes, concatenated, written into `out` (cleared first).
    pub fn normals(&self, out: &mut Vec<[f64; 3]>) {
        out.clear();
        for s in &self.skinned {
            out.extend((0..s.x.len()).map(|v| s.normal(v)));
        }
    }
}
