// The README, with its links to what feature `serde` adds resolved: to the items with it,
// else to the features table that says how to get them.
#![cfg_attr(feature = "serde", doc = concat!(include_str!("../README.md"), "\n[`KIND`]: KIND\n[`anim_core::scene`]: anim_core::scene\n[`body`]: body\n[`kind`]: kind\n"))]
#![cfg_attr(not(feature = "serde"), doc = concat!(include_str!("../README.md"), "\n[`KIND`]: #features\n[`anim_core::scene`]: #features\n[`body`]: #features\n[`kind`]: #features\n"))]

pub mod analytic;
#[cfg(feature = "serde")]
pub mod body;
mod build;
#[cfg(feature = "cases")]
pub mod cases;
pub mod contact;
mod error;
mod geom;
#[cfg(feature = "serde")]
pub mod kind;
#[cfg(feature = "serde")]
pub mod memory;
mod mesh;
pub mod network;
#[cfg(feature = "serde")]
mod obstacles;
pub mod scenes;
mod sim;

pub use build::{Chain, Cloth, EARTH_GRAVITY, Lattice, MeshMass, MeshSprings, NetworkBuilder, SpringParams};
pub use contact::{Collider, MeshCollider, Shape};
pub use error::{BuildError, InputError};
#[cfg(feature = "serde")]
pub use kind::KIND;
pub use mesh::TriangleMesh;
pub use network::{
    EnergyParts, JacobianMode, Particle, Spring, SpringKind, SpringModel, SpringNetwork, Stretch,
};
pub use sim::{DEFAULT_MAX_STRETCH, SpringError, SpringSimulation};

/// anim-core, the math and contracts this crate builds on: its `glam`, integrators and scene
/// traits, without a dependency of your own.
pub use anim_core;
/// The trait whose `step` advances this crate's simulations.
pub use anim_core::solver::Solver;

#[cfg(test)]
mod tests;
