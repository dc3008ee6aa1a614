#![doc = include_str!("../README.md")]

pub mod advection;
#[cfg(feature = "cases")]
pub mod cases;
pub mod error;
mod grain;
pub mod kind;
pub mod mac;
pub mod memory;
pub mod pressure;
pub mod scenes;
pub mod smoke;
pub mod stam;

pub use error::FluidError;
pub use kind::KIND;

/// anim-core, the math and contracts this crate builds on: its `glam`, integrators and scene
/// traits, without a dependency of your own.
pub use anim_core;
/// The trait whose `step` advances this crate's simulations.
pub use anim_core::solver::Solver;
