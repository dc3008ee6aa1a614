//! The crate's error type: bad parameters and grids are rejected up front, a step that produces
//! a non-finite value or a failed pressure solve is reported with the step and the cell, and a
//! checkpoint that does not fit the simulation is refused naming what is wrong. Every message
//! begins with `anim-fluid: `, so a run driving several crates tells where it came from.

/// Everything that can go wrong building or stepping a fluid.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum FluidError {
    /// A grid with no interior cells, or one too small for the method.
    #[error("anim-fluid: grid {what} must be at least {min} cells, got {got}")]
    BadGrid {
        /// Which extent (`"N"`, `"nx"`, `"ny"`, `"nz"`).
        what: &'static str,
        /// Smallest accepted value.
        min: usize,
        /// The value given.
        got: usize,
    },
    /// A parameter outside its valid range.
    #[error("anim-fluid: parameter {name} {requirement}, got {value}")]
    BadParameter {
        /// The parameter's name.
        name: &'static str,
        /// What it must satisfy.
        requirement: &'static str,
        /// The value given.
        value: String,
    },
    /// An input array of the wrong length.
    #[error("anim-fluid: {name} has {got} values, expected {expected}")]
    BadLength {
        /// The array.
        name: &'static str,
        /// Its length.
        got: usize,
        /// The length the grid needs.
        expected: usize,
    },
    /// A step produced NaN or infinity. The simulation is left as it was before the step.
    #[error(
        "anim-fluid: step {step}: non-finite {field} {value} at cell ({i}, {j}, {k}); {}",
        last_finite_text(*last_finite)
    )]
    NonFinite {
        /// Steps completed before the failing one.
        step: u64,
        /// Which field (`"density"`, `"u"`, `"v"`, `"w"`, `"temperature"`).
        field: &'static str,
        /// Cell or face index along x.
        i: usize,
        /// Along y.
        j: usize,
        /// Along z (0 in 2D).
        k: usize,
        /// The offending value.
        value: f64,
        /// The value the same cell (or face) held before the failing step, if that was finite.
        last_finite: Option<f64>,
    },
    /// The pressure (or viscosity) solve did not reach its tolerance.
    #[error(
        "anim-fluid: {solve} solve at step {step} did not converge: residual {residual:.3e} after {iterations} iterations (tolerance {tolerance:.3e})"
    )]
    NotConverged {
        /// Steps completed before the failing one.
        step: u64,
        /// `"pressure"` or `"viscosity"`.
        solve: &'static str,
        /// Iterations spent.
        iterations: usize,
        /// Final relative residual.
        residual: f64,
        /// The requested tolerance.
        tolerance: f64,
    },
    /// A checkpointed memory that does not belong to this simulation, or a malformed one.
    #[error("anim-fluid: checkpoint does not fit this simulation: {0}")]
    Checkpoint(String),
}

fn last_finite_text(last: Option<f64>) -> String {
    match last {
        Some(v) => format!("last finite value there {v}"),
        None => "no finite value there before the step".into(),
    }
}

/// Checks `value > 0` and finite.
pub(crate) fn positive(name: &'static str, value: f64) -> Result<(), FluidError> {
    if value > 0.0 && value.is_finite() {
        Ok(())
    } else {
        Err(FluidError::BadParameter {
            name,
            requirement: "must be positive and finite",
            value: value.to_string(),
        })
    }
}

/// Checks `value >= 0` and finite.
pub(crate) fn non_negative(name: &'static str, value: f64) -> Result<(), FluidError> {
    if value >= 0.0 && value.is_finite() {
        Ok(())
    } else {
        Err(FluidError::BadParameter {
            name,
            requirement: "must be non-negative and finite",
            value: value.to_string(),
        })
    }
}

/// Checks that `value` is finite.
pub(crate) fn finite(name: &'static str, value: f64) -> Result<(), FluidError> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(FluidError::BadParameter { name, requirement: "must be finite", value: value.to_string() })
    }
}
