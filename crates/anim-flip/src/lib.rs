#![doc = include_str!("../README.md")]

pub mod body;
#[cfg(feature = "cases")]
pub mod cases;
pub mod classify;
pub mod error;
pub mod kind;
pub mod mac;
pub mod memory;
mod par;
pub mod particles;
pub mod project;
pub mod reseed;
pub mod scenes;
pub mod sim;
pub mod surface;
pub mod tank;
pub mod transfer;

#[cfg(test)]
mod tests;

pub use error::FlipError;
pub use kind::KIND;
pub use particles::Particles;
pub use reseed::Reseed;
pub use sim::{FlipParams, FlipSimulation, Sampling, StepInfo, StepTimes};
pub use surface::{Contour, Mesh, ParticleSurface, SurfaceParams};
pub use tank::TankMotion;
pub use transfer::Transfer;

/// anim-core, the math and contracts this crate builds on: its `glam`, integrators and scene
/// traits, without a dependency of your own.
pub use anim_core;
/// The trait whose `step` advances this crate's simulations.
pub use anim_core::solver::Solver;
