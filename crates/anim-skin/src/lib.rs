//! # anim-skin
//!
//! Skeletal animation and skinning: a joint hierarchy posed by keyframed clips, and meshes
//! deformed by linear blend skinning (LBS) or dual-quaternion skinning (DQS, Kavan et al. 2008),
//! loaded from glTF 2.0.
//!
//! ## What it models
//!
//! - [`Skeleton`]: joints stored parents before children, each with a rest local transform
//!   [`Trs`] (translation, unit quaternion, non-uniform scale, applied `T R S`). A [`Pose`] is one
//!   `Trs` per joint; forward kinematics gives global matrices `G_j = G_parent * L_j`.
//! - [`Skin`]: the joints a mesh is bound to and their inverse bind matrices; skinning matrices
//!   are `M_j = G_j B_j^-1`.
//! - [`Clip`]: [`Channel`]s of translation, rotation or scale keys with STEP, LINEAR (shortest
//!   path slerp for rotations) and CUBICSPLINE interpolation exactly as glTF 2.0 defines them
//!   ([`clip`] gives the formulas); sampling clamps outside the key range; [`Pose::blend`] mixes
//!   two sampled poses (lerp for translations and scales, shortest-arc slerp for rotations).
//! - [`SkinnedMesh`]: structure-of-arrays rest positions and normals, 1 to 8 influences per
//!   vertex (weights normalised; bad joints or weights are errors at construction).
//! - [`skin`]: LBS and DQS, normals with positions, parallel over vertex chunks with rayon and
//!   bitwise identical for any thread count, no allocation per pose.
//! - [`gltf_io::load`]: `.gltf` (external or data-URI buffers) and `.glb` files into a
//!   [`Character`] (skeleton, skins, meshes, clips) plus notes on what was ignored or
//!   renormalised; each mesh keeps the glTF node, mesh and primitive it came from
//!   ([`GltfSource`]) and poses into its own buffers ([`CharacterData::mesh_positions`];
//!   [`CharacterData::positions`] joins all meshes).
//! - [`scenes`]: the twisted cylinder (LBS's candy-wrapper collapse next to DQS) and
//!   [`scenes::from_gltf`], both posable at any time into positions and triangles.
//!
//! [`KIND`] registers these as the `skinning` scene kind of anim-core's
//! [`scene`](anim_core::scene) contracts, with the preset `twist` (the twisted cylinder, LBS
//! beside DQS); a scene file may name any skinned glTF file instead ([`kind::SkinParams`]). The
//! run loop plays it over time through [`kind::SkinPlayback`] (see [`kind`]).
//!
//! ## glTF conventions
//!
//! Right-handed, y-up, metres; quaternions `(x, y, z, w)`; node transforms `T * R * S`; a
//! skinned mesh's own node transform is ignored (glTF 2.0 section 3.7.3.3): posed vertices are in
//! world space, `sum_i w_i G_{j_i} B_{j_i}^-1 p`. Non-joint ancestors of joints are part of the
//! [`Skeleton`] so their transforms (and animations) apply.
//!
//! ## LBS or DQS
//!
//! LBS blends matrices: cheap, exact for rigid single-influence vertices, handles scaled joints,
//! but the blend of two rotations is not a rotation, so twisted joints lose volume. On
//! [`scenes::twisted_cylinder`] at 180 degrees of twist (`cargo xtask conformance --filter skin`),
//! LBS loses 33.3 % of the volume of the cylinder while DQS keeps it within 0.04 %.
//! DQS blends unit dual quaternions: a rigid motion per vertex, no collapse, similar cost, but it
//! needs rigid joints (scaled joint transforms are rejected with
//! [`SkinError::NonRigidJoint`]; transforms rigid within a tolerance, default
//! [`skinning::RIGID_TOLERANCE`], settable with [`CharacterData::set_rigid_tolerance`], are
//! re-orthonormalised, which absorbs exporters' f32 noise) and bulges slightly at bends. Use DQS for characters with
//! twisting joints (forearms, necks), LBS when joints scale or for compatibility with engines
//! that author for LBS. On single-influence vertices both agree to rounding (`1e-12`) when
//! the skinning matrices are rigid; on f32 data they are rigid only to f32 rounding, and DQS
//! (which re-orthonormalises) and LBS (which applies the matrix as stored) differ by up to
//! `|S - I| |p|` (`S` the matrix's stretch, `p` the rest position): on the Fox over its three
//! clips, 1.2e-7 relative to the largest vertex distance from the origin; on SimpleSkin, whose
//! inverse bind matrices are exact in f32, 4.8e-16 (`tests/real_assets.rs`); on data at the
//! edge of the rigidity tolerance, up to about half the tolerance.
//!
//! ## Precision
//!
//! f64 throughout: glTF stores f32, and the conformance reference (an independent numpy
//! implementation) is matched to `1e-5` relative.
//!
//! ```
//! use anim_skin::{scenes, SkinningMethod};
//!
//! let scene = scenes::twisted_cylinder(None)?;
//! let mut data = scene.character.data();
//! // Pose the end of the twist with both methods and compare the enclosed volume.
//! scene.character.pose(&mut data, Some(0), scene.duration, SkinningMethod::Lbs)?;
//! let lbs = scenes::volume(&scene.character, &data);
//! scene.character.pose(&mut data, Some(0), scene.duration, SkinningMethod::Dqs)?;
//! let dqs = scenes::volume(&scene.character, &data);
//! let rest = scene.rest_volume();
//! assert!(lbs < 0.7 * rest && (dqs - rest).abs() < 0.05 * rest);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

#[cfg(feature = "cases")]
pub mod cases;
pub mod character;
pub mod clip;
#[cfg(feature = "gltf")]
pub mod gltf_io;
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
pub use kind::KIND;
pub use mesh::{MAX_INFLUENCES, SkinnedMesh, signed_volume};
pub use skeleton::{Joint, Pose, Skeleton, Skin, Trs};
pub use skinning::{Skinned, SkinningMethod, skin};

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
