// The README, with its links to what feature `serde` adds resolved: to the items with it,
// else to the features table that says how to get them.
#![cfg_attr(feature = "serde", doc = concat!(include_str!("../README.md"), "\n[`KIND`]: KIND\n[`anim_core::scene`]: anim_core::scene\n[`kind::BodySpec`]: kind::BodySpec\n[`kind`]: kind\n"))]
#![cfg_attr(not(feature = "serde"), doc = concat!(include_str!("../README.md"), "\n[`KIND`]: #features\n[`anim_core::scene`]: #features\n[`kind::BodySpec`]: #features\n[`kind`]: #features\n"))]

mod angle;
mod build;
#[cfg(feature = "cases")]
pub mod cases;
pub mod collide;
pub mod constraint;
#[cfg(feature = "serde")]
pub mod kind;
#[cfg(feature = "serde")]
pub mod memory;
mod model;
mod project;
pub mod scenes;
pub mod shapes;
mod sim;

pub use build::{
    Bending, BuildError, Chain, Cloth, ClothHandle, EARTH_GRAVITY, InputError, MeshMass, MeshParams,
    PbdBuilder, TetMeshParams,
};
pub use collide::{BodyContact, BodyMotion, Collider, KinematicBody, MeshCollider, Pose, Shape};
pub use constraint::{AttachTarget, Constraint, ConstraintFunction, ConstraintParams, ConstraintType};
#[cfg(feature = "serde")]
pub use kind::KIND;
pub use model::{ContactBody, Particle, PbdModel, SparseGradient, VolumeMesh, Wind};
pub use sim::{Method, PbdError, PbdParams, PbdSimulation, SolverKind, StepInfo};

/// anim-core, the math and contracts this crate builds on: its `glam`, integrators and scene
/// traits, without a dependency of your own.
pub use anim_core;
/// The trait whose `step` advances this crate's simulations.
pub use anim_core::solver::Solver;

#[cfg(test)]
mod tests;
