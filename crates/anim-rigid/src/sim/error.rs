//! Why a rigid simulation could not be built or a step failed.

use anim_core::diagnostics::NonFinite;
use thiserror::Error;

/// Why a simulation could not be built or a step failed. After a failed step the state and the
/// simulation's memory (step count, kept Newton matrix) are the ones before it.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum SimError {
    /// A checkpointed memory that does not belong to this simulation.
    #[error("checkpoint does not fit this simulation: {0}")]
    Checkpoint(String),
    /// A parameter out of its range.
    #[error("parameter '{name}' = {value}: {requirement}")]
    BadParameter {
        /// The parameter.
        name: &'static str,
        /// Its value, as text.
        value: String,
        /// What it must satisfy.
        requirement: &'static str,
    },
    /// The time step is not a positive finite number.
    #[error("time step must be positive and finite, got {dt}")]
    BadTimeStep {
        /// The offending step.
        dt: f64,
    },
    /// The state does not have the model's sizes.
    #[error("state has q of length {q} and v of length {v}, the model has nq = {nq}, nv = {nv}")]
    StateMismatch {
        /// `q.len()`.
        q: usize,
        /// `v.len()`.
        v: usize,
        /// The model's `nq`.
        nq: usize,
        /// The model's `nv`.
        nv: usize,
    },
    /// The step produced a NaN or infinity. The report's message begins with
    /// `anim-rigid: step N:` and names the joint (`element.index`, in [`Model::joints`] order),
    /// the coordinate within it, the value and the joint's whole last finite `q` or `v` block.
    ///
    /// [`Model::joints`]: crate::Model::joints
    #[error(transparent)]
    NonFinite(#[from] NonFinite),
    /// The implicit midpoint's Newton iteration did not converge.
    #[error("Newton did not converge at step {step}: residual {residual:e} after {iterations} iterations")]
    NewtonNotConverged {
        /// Step index.
        step: u64,
        /// Iterations performed.
        iterations: usize,
        /// Residual reached (`‖r‖∞`).
        residual: f64,
    },
    /// The implicit midpoint's Newton matrix is singular.
    #[error("singular Newton matrix at step {step}")]
    SingularNewtonMatrix {
        /// Step index.
        step: u64,
    },
    /// The stepper needs a model it cannot handle (the free-body midpoint rule on anything but
    /// one free body without applied torques).
    #[error("{integrator} cannot step this model: {reason}")]
    Unsupported {
        /// The stepper.
        integrator: &'static str,
        /// Why.
        reason: String,
    },
}
