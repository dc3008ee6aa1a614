//! Errors of the particle fluid.

use anim_fluid::FluidError;

/// What can go wrong building or advancing a [`crate::FlipSimulation`].
#[derive(Debug, thiserror::Error)]
pub enum FlipError {
    /// A parameter is out of its range.
    #[error("anim-flip: parameter `{name}` {requirement}, got {value}")]
    BadParameter {
        /// The parameter.
        name: &'static str,
        /// What it must satisfy.
        requirement: &'static str,
        /// The value given.
        value: String,
    },
    /// A particle is invalid (non-finite, outside the domain, arrays of different lengths).
    #[error("anim-flip: particle {index}: {field} {cause}")]
    BadParticle {
        /// Particle index.
        index: usize,
        /// Which array (`x`, `v`, `c`).
        field: &'static str,
        /// What is wrong.
        cause: String,
    },
    /// The pressure operator or solver refused its input.
    #[error("anim-flip: pressure projection: {0}")]
    Pressure(#[from] FluidError),
    /// The state became non-finite; the particles are as they were before the call.
    #[error(
        "anim-flip: non-finite {field} of particle {particle} at step {step} (value {value}, last finite {last_finite:?})"
    )]
    NonFinite {
        /// Substep counter at which it happened.
        step: u64,
        /// Particle index.
        particle: usize,
        /// `x`, `v` or `c`.
        field: &'static str,
        /// The offending value.
        value: f64,
        /// The value that component had before the call, if finite.
        last_finite: Option<f64>,
    },
    /// The pressure solve missed its tolerance (only when `require_convergence` is set).
    #[error(
        "anim-flip: pressure solve at step {step} stopped at residual {residual:e} after {iterations} iterations"
    )]
    NotConverged {
        /// Substep counter.
        step: u64,
        /// Final relative residual.
        residual: f64,
        /// Iterations spent.
        iterations: usize,
    },
    /// A step needed more CFL substeps than `max_substeps`.
    #[error("anim-flip: dt = {dt} needs more than {max} CFL substeps (max particle speed {speed} m/s)")]
    TooManySubsteps {
        /// The requested step.
        dt: f64,
        /// The cap.
        max: usize,
        /// Largest particle speed at the time.
        speed: f64,
    },
    /// A checkpoint could not be restored.
    #[error("anim-flip: checkpoint: {0}")]
    Checkpoint(String),
}

pub(crate) fn positive(name: &'static str, value: f64) -> Result<(), FlipError> {
    if value > 0.0 && value.is_finite() {
        Ok(())
    } else {
        Err(FlipError::BadParameter {
            name,
            requirement: "must be positive and finite",
            value: value.to_string(),
        })
    }
}
