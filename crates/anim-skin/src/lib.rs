// The README, with its links to what feature `serde` adds resolved: to the items with it,
// else to the features table that says how to get them.
#![cfg_attr(feature = "serde", doc = concat!(include_str!("../README.md"), "\n[`KIND`]: KIND\n[`scene`]: anim_core::scene\n[`kind::SkinParams`]: kind::SkinParams\n[`kind::SkinPlayback`]: kind::SkinPlayback\n[`kind`]: kind\n"))]
#![cfg_attr(not(feature = "serde"), doc = concat!(include_str!("../README.md"), "\n[`KIND`]: #features\n[`scene`]: #features\n[`kind::SkinParams`]: #features\n[`kind::SkinPlayback`]: #features\n[`kind`]: #features\n"))]

#[cfg(feature = "cases")]
pub mod cases;
pub mod character;
pub mod clip;
#[cfg(feature = "gltf")]
pub mod gltf_io;
#[cfg(feature = "serde")]
pub mod kind;
pub mod mesh;
pub mod rotation;
pub mod scenes;
pub mod skeleton;
pub mod skinning;

pub use character::{Character, CharacterData, CharacterMesh, GltfSource};
pub use clip::{Channel, Clip, Interpolation, Property};
#[cfg(feature = "gltf")]
pub use gltf_io::{LoadError, Loaded, Renormalised};
#[cfg(feature = "serde")]
pub use kind::KIND;
pub use mesh::{MAX_INFLUENCES, SkinnedMesh, signed_volume};
pub use skeleton::{Joint, Pose, Skeleton, Skin, Trs};
pub use skinning::{Skinned, SkinningMethod, skin};

/// anim-core, the math and contracts this crate builds on: its `glam`, integrators and scene
/// traits, without a dependency of your own.
pub use anim_core;
/// The trait whose `step` advances this crate's simulations.
pub use anim_core::solver::Solver;

/// Invalid skeletons, skins, meshes, channels, and joint transforms DQS cannot blend.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SkinError {
    /// A joint's parent does not precede it.
    #[error("joint {joint}: parent {parent} does not precede it (joints must be listed parents first)")]
    BadParent {
        /// The joint.
        joint: usize,
        /// Its parent.
        parent: usize,
    },
    /// A rest transform is not finite or its rotation is not a unit quaternion.
    #[error("joint {joint}: rest transform is not finite or its rotation is not a unit quaternion")]
    BadRestTransform {
        /// The joint.
        joint: usize,
    },
    /// A skin is inconsistent.
    #[error("skin: {0}")]
    BadSkin(String),
    /// A mesh is inconsistent.
    #[error("mesh: {0}")]
    BadMesh(String),
    /// A vertex weight is negative or not finite, or all of a vertex's weights are zero.
    #[error(
        "vertex {vertex}, influence {slot}: weight {weight} (weights must be finite, non-negative and not all zero)"
    )]
    BadWeight {
        /// The vertex.
        vertex: usize,
        /// The influence slot.
        slot: usize,
        /// The weight.
        weight: f64,
    },
    /// A vertex has a non-zero weight on a joint the skin does not have.
    #[error(
        "vertex {vertex}, influence {slot}: joint {joint} is out of range (skin has {num_joints} joints)"
    )]
    BadJoint {
        /// The vertex.
        vertex: usize,
        /// The influence slot.
        slot: usize,
        /// The joint index.
        joint: usize,
        /// Joints of the skin.
        num_joints: usize,
    },
    /// An animation channel is invalid.
    #[error("channel on joint {joint}: {why}")]
    BadChannel {
        /// The animated joint.
        joint: usize,
        /// What is wrong.
        why: String,
    },
    /// A skinning matrix is not finite.
    #[error("skin joint {joint}: skinning matrix is not finite")]
    NonFiniteJoint {
        /// The skin joint.
        joint: usize,
    },
    /// DQS was asked to blend a joint transform with scale, shear or reflection beyond its
    /// rigidity tolerance.
    #[error(
        "skin joint {joint}: skinning matrix is not rigid (max |R^T R - I| = {deviation:.3e}, det = {determinant:.6}, \
         tolerance {tolerance:.1e}); dual-quaternion skinning needs rigid joints, use linear blend skinning \
         for scaled joints"
    )]
    NonRigidJoint {
        /// The skin joint.
        joint: usize,
        /// Largest entry of `|R^T R - I|`.
        deviation: f64,
        /// Determinant of the 3x3 block.
        determinant: f64,
        /// The tolerance it exceeded ([`Skinned::rigid_tolerance`]).
        tolerance: f64,
    },
    /// A DQS rigidity tolerance outside `[0, 1)`.
    #[error("rigid_tolerance {tolerance}: must be at least 0 and below 1")]
    BadTolerance {
        /// The tolerance given.
        tolerance: f64,
    },
}
