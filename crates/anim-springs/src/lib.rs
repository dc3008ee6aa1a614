#![doc = include_str!("../README.md")]

pub mod analytic;
pub mod body;
mod build;
#[cfg(feature = "cases")]
pub mod cases;
pub mod contact;
mod error;
mod geom;
pub mod kind;
pub mod memory;
mod mesh;
pub mod network;
mod obstacles;
pub mod scenes;
mod sim;

pub use build::{Chain, Cloth, EARTH_GRAVITY, Lattice, MeshMass, MeshSprings, NetworkBuilder, SpringParams};
pub use contact::{Collider, MeshCollider, Shape};
pub use error::{BuildError, InputError};
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
