//! Joint hierarchies, local TRS poses and forward kinematics.
//!
//! A [`Skeleton`] is a tree of joints stored parents before children (index order is a
//! topological order), each with a rest (bind-time) local transform. A [`Pose`] holds one local
//! [`Trs`] per joint; [`Skeleton::forward_kinematics`] composes them down the tree,
//! `G_j = G_parent(j) * L_j`. A [`Skin`] selects the joints a mesh is bound to and their inverse
//! bind matrices; its skinning matrices are `G_joint * B_joint^-1` (glTF 2.0, section 3.7.3).
//!
//! The skeleton is the model: no algorithm modifies it. Poses and global matrices are caller
//! buffers, sized once and reused (no allocation per pose).

use crate::SkinError;
use anim_core::glam::{DMat4, DQuat, DVec3};

/// A local transform: translation, unit-quaternion rotation and non-uniform scale, applied as
/// `T * R * S` (scale first), as in glTF.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Trs {
    /// Translation.
    pub translation: DVec3,
    /// Rotation (unit quaternion).
    pub rotation: DQuat,
    /// Per-axis scale.
    pub scale: DVec3,
}

impl Default for Trs {
    fn default() -> Self {
        Self::IDENTITY
    }
}

impl Trs {
    /// The identity transform.
    pub const IDENTITY: Self =
        Self { translation: DVec3::ZERO, rotation: DQuat::IDENTITY, scale: DVec3::ONE };

    /// A transform from its parts.
    #[inline]
    #[must_use]
    pub const fn new(translation: DVec3, rotation: DQuat, scale: DVec3) -> Self {
        Self { translation, rotation, scale }
    }

    /// The homogeneous matrix `T * R * S`.
    #[inline]
    #[must_use]
    pub fn to_matrix(&self) -> DMat4 {
        DMat4::from_scale_rotation_translation(self.scale, self.rotation, self.translation)
    }

    /// Whether every component is finite and the rotation is unit within `1e-6`.
    #[must_use]
    pub fn is_valid(&self) -> bool {
        self.translation.is_finite()
            && self.scale.is_finite()
            && self.rotation.is_finite()
            && (self.rotation.length() - 1.0).abs() <= 1e-6
    }
}

/// One joint of a [`Skeleton`].
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Joint {
    /// Name (from the file, or made up).
    pub name: String,
    /// Parent joint; always a smaller index. `None` for a root.
    pub parent: Option<usize>,
    /// Rest local transform (the node's TRS in glTF), used for channels a clip does not animate.
    pub rest: Trs,
}

/// A joint hierarchy, parents before children.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Skeleton {
    joints: Vec<Joint>,
}

impl Skeleton {
    /// A skeleton from joints listed parents before children.
    ///
    /// # Errors
    /// [`SkinError::BadParent`] if a parent index is not smaller than the joint's own,
    /// [`SkinError::BadRestTransform`] if a rest transform is non-finite or its rotation is not
    /// a unit quaternion.
    pub fn new(joints: Vec<Joint>) -> Result<Self, SkinError> {
        for (j, joint) in joints.iter().enumerate() {
            if let Some(p) = joint.parent
                && p >= j
            {
                return Err(SkinError::BadParent { joint: j, parent: p });
            }
            if !joint.rest.is_valid() {
                return Err(SkinError::BadRestTransform { joint: j });
            }
        }
        Ok(Self { joints })
    }

    /// The joints, parents before children.
    #[must_use]
    pub fn joints(&self) -> &[Joint] {
        &self.joints
    }

    /// Number of joints.
    #[must_use]
    pub fn len(&self) -> usize {
        self.joints.len()
    }

    /// Whether there are no joints.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.joints.is_empty()
    }

    /// The index of the first joint called `name`.
    #[must_use]
    pub fn find(&self, name: &str) -> Option<usize> {
        self.joints.iter().position(|j| j.name == name)
    }

    /// The rest pose (every joint at its rest transform).
    #[must_use]
    pub fn rest_pose(&self) -> Pose {
        Pose { local: self.joints.iter().map(|j| j.rest).collect() }
    }

    /// Global joint matrices by forward kinematics: `global[j] = global[parent(j)] * local[j]`.
    ///
    /// # Panics
    /// If `pose` or `global` does not have one entry per joint (API misuse).
    #[track_caller]
    pub fn forward_kinematics(&self, pose: &Pose, global: &mut [DMat4]) {
        assert_eq!(
            pose.local.len(),
            self.joints.len(),
            "pose has {} joints, skeleton {}",
            pose.local.len(),
            self.joints.len()
        );
        assert_eq!(
            global.len(),
            self.joints.len(),
            "global has {} entries, skeleton {} joints",
            global.len(),
            self.joints.len()
        );
        for (j, joint) in self.joints.iter().enumerate() {
            let local = pose.local[j].to_matrix();
            global[j] = match joint.parent {
                Some(p) => global[p] * local,
                None => local,
            };
        }
    }
}

/// A local transform per joint of a skeleton.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Pose {
    /// Local transforms, indexed like the skeleton's joints.
    pub local: Vec<Trs>,
}

impl Pose {
    /// Resets every joint to the skeleton's rest transform (no allocation once sized).
    pub fn reset(&mut self, skeleton: &Skeleton) {
        self.local.clear();
        self.local.extend(skeleton.joints.iter().map(|j| j.rest));
    }

    /// Blends two poses: `out = (1 - w) a + w b`, translations and scales lerped, rotations
    /// slerped along the shorter arc ([`crate::rotation::slerp`]). `w = 0` gives `a` exactly and
    /// `w = 1` gives `b` exactly.
    ///
    /// # Panics
    /// If the poses have different lengths (API misuse).
    #[track_caller]
    pub fn blend(a: &Pose, b: &Pose, w: f64, out: &mut Pose) {
        assert_eq!(a.local.len(), b.local.len(), "blending poses of different sizes");
        out.local.clear();
        out.local.extend(a.local.iter().zip(&b.local).map(|(x, y)| Trs {
            translation: x.translation.lerp(y.translation, w),
            rotation: crate::rotation::slerp(x.rotation, y.rotation, w),
            scale: x.scale.lerp(y.scale, w),
        }));
    }
}

/// The joints a mesh is bound to and their inverse bind matrices (glTF `skin`).
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Skin {
    /// Skeleton joint of each skin joint (vertex joint indices index this list).
    pub joints: Vec<usize>,
    /// Inverse bind matrix of each skin joint: maps the mesh's bind space into the joint's frame.
    pub inverse_bind: Vec<DMat4>,
}

impl Skin {
    /// A skin over `skeleton`.
    ///
    /// # Errors
    /// [`SkinError::BadSkin`] if the lists differ in length, a joint is out of range, or an
    /// inverse bind matrix is not finite.
    pub fn new(skeleton: &Skeleton, joints: Vec<usize>, inverse_bind: Vec<DMat4>) -> Result<Self, SkinError> {
        if joints.len() != inverse_bind.len() {
            return Err(SkinError::BadSkin(format!(
                "{} joints but {} inverse bind matrices",
                joints.len(),
                inverse_bind.len()
            )));
        }
        if let Some((i, j)) = joints.iter().enumerate().find(|(_, j)| **j >= skeleton.len()) {
            return Err(SkinError::BadSkin(format!(
                "skin joint {i} names skeleton joint {j} of {}",
                skeleton.len()
            )));
        }
        if let Some(i) = inverse_bind.iter().position(|m| !m.is_finite()) {
            return Err(SkinError::BadSkin(format!("inverse bind matrix {i} is not finite")));
        }
        Ok(Self { joints, inverse_bind })
    }

    /// Number of skin joints.
    #[must_use]
    pub fn len(&self) -> usize {
        self.joints.len()
    }

    /// Whether the skin has no joints.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.joints.is_empty()
    }

    /// Skinning matrices `out[i] = global[joints[i]] * inverse_bind[i]`.
    ///
    /// # Panics
    /// If `out` does not have one entry per skin joint (API misuse).
    #[track_caller]
    pub fn skinning_matrices(&self, global: &[DMat4], out: &mut [DMat4]) {
        assert_eq!(out.len(), self.joints.len(), "one skinning matrix per skin joint");
        for ((o, &j), ib) in out.iter_mut().zip(&self.joints).zip(&self.inverse_bind) {
            *o = global[j] * *ib;
        }
    }
}
