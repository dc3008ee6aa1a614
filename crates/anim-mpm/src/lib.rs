#![doc = include_str!("../README.md")]

#[cfg(target_arch = "x86_64")]
mod avx2;
pub mod bodies;
pub mod boundary;
#[cfg(feature = "cases")]
pub mod cases;
mod grid;
pub mod hencky;
pub mod kernel;
pub mod kind;
pub mod material;
pub mod memory;
pub mod mesh_collider;
mod particle_transfer;
mod particles;
pub mod plasticity;
pub mod scenes;
mod sim;
mod simd;
mod transfer;

#[cfg(test)]
mod bodies_tests;
#[cfg(test)]
mod kind_tests;
#[cfg(test)]
mod mesh_collider_tests;
#[cfg(test)]
mod tests;

pub use boundary::{Boundary, Collider, Shape};
pub use kernel::Kernel;
pub use kind::KIND;
pub use material::{Elastic, ElasticModel, Fluid, Material, Sand, Snow};
pub use particles::Particles;
pub use sim::{MpmParams, MpmSimulation, OutOfDomain, StepStats, Totals, Transfer, max_resolution};

/// anim-core, the math and contracts this crate builds on: its `glam`, integrators and scene
/// traits, without a dependency of your own.
pub use anim_core;
/// The trait whose `step` advances this crate's simulations.
pub use anim_core::solver::Solver;

/// A `D`-vector of the particle precision.
pub type Vector<const D: usize> = nalgebra::SVector<f32, D>;
/// A `D x D` matrix of the particle precision.
pub type Mat<const D: usize> = nalgebra::SMatrix<f32, D, D>;

/// Errors of the MPM crate: bad input (named) and numerical failure (step and particle named).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum MpmError {
    /// A checkpointed memory that does not belong to this simulation.
    #[error("checkpoint does not fit this simulation: {0}")]
    Checkpoint(String),
    /// Only 2 and 3 dimensions are supported.
    #[error("dimension {0} is not supported (2 or 3)")]
    Dimension(usize),
    /// A simulation parameter is out of range.
    #[error("parameter `{name}`: {reason}")]
    BadParameter {
        /// The parameter.
        name: &'static str,
        /// Why it was refused.
        reason: String,
    },
    /// A material of the table has a bad parameter.
    #[error("material {index}, field `{field}`: {reason}")]
    BadMaterial {
        /// Index in the material table.
        index: usize,
        /// The field.
        field: &'static str,
        /// Why it was refused.
        reason: String,
    },
    /// A collider is malformed.
    #[error("collider {index}: {reason}")]
    BadCollider {
        /// Index in the collider list.
        index: usize,
        /// Why it was refused.
        reason: String,
    },
    /// A particle is invalid (given by its id, its index at creation).
    #[error("particle {index}: {reason}")]
    BadParticle {
        /// The particle's id.
        index: usize,
        /// Why it was refused.
        reason: String,
    },
    /// The particle arrays are inconsistent.
    #[error("particle state, array `{field}`: {reason}")]
    BadState {
        /// The array.
        field: &'static str,
        /// What is wrong.
        reason: String,
    },
    /// The CFL limits would need more substeps than allowed.
    #[error(
        "step {step}: CFL number {cfl:.3} (elastic waves {wave_cfl:.3}) needs {needed} substeps, more than max_substeps = {limit}"
    )]
    TooManySubsteps {
        /// The step.
        step: u64,
        /// Advective CFL number of the requested step.
        cfl: f64,
        /// Elastic-wave CFL number of the requested step.
        wave_cfl: f64,
        /// Substeps needed.
        needed: f64,
        /// The limit.
        limit: usize,
    },
    /// The step produced a NaN or infinity; the particles are left as they were before the step.
    #[error(
        "anim-mpm: step {step}: non-finite {field} of particle {particle}{} (value {value}); last finite {field} of particle {particle}: {last_finite:?}",
        describe_component(*component, last_finite.len())
    )]
    NonFinite {
        /// Completed steps before the failing one.
        step: u64,
        /// The particle's id.
        particle: usize,
        /// Which quantity: "position", "velocity", "deformation gradient", "affine matrix" or
        /// "plastic state".
        field: &'static str,
        /// The first offending entry of that quantity: the axis (0, 1, 2 for `x`, `y`, `z`) of a
        /// vector, the column-major index of a matrix, 0 for the plastic state.
        component: usize,
        /// The value.
        value: f64,
        /// The particle's whole quantity before the step (the `D` entries of a vector, the `D^2`
        /// column-major entries of a matrix, or the one plastic value).
        last_finite: Vec<f64>,
    },
}

/// `", component y"` for an entry of a vector of `len <= 3`, `", entry (row r, column c)"` for
/// a column-major matrix entry, nothing for a scalar.
fn describe_component(component: usize, len: usize) -> String {
    match len {
        0 | 1 => String::new(),
        2 | 3 => format!(", component {}", ["x", "y", "z"][component.min(2)]),
        _ => {
            let d = if len == 4 { 2 } else { 3 };
            format!(", entry (row {}, column {})", component % d, component / d)
        }
    }
}
