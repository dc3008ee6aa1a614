#![doc = include_str!("../README.md")]

pub mod assembly;
pub mod bodies;
pub mod body;
pub mod boundary;
#[cfg(feature = "cases")]
pub mod cases;
pub mod element;
pub mod error;
pub mod friction;
pub mod generate;
pub mod kind;
pub mod ldlt;
pub mod material;
pub mod memory;
pub mod mesh;
pub mod model;
pub mod newton;
pub mod quadratic;
pub mod scenes;
pub mod sim;
pub mod tet10;

pub use error::FemError;
pub use kind::KIND;

/// anim-core, the math and contracts this crate builds on: its `glam`, integrators and scene
/// traits, without a dependency of your own.
pub use anim_core;
/// The trait whose `step` advances this crate's simulations.
pub use anim_core::solver::Solver;

#[cfg(test)]
mod contact_shape_tests;
#[cfg(test)]
mod contact_tests;
#[cfg(test)]
mod kind_tests;
#[cfg(test)]
#[cfg(feature = "files")]
mod mesh_obstacle_tests;
#[cfg(test)]
mod tests;
#[cfg(test)]
mod tests_quadratic;
#[cfg(test)]
#[cfg(not(feature = "files"))]
mod without_files_tests;
