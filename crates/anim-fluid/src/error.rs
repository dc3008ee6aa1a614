//! The crate's error type: bad parameters and grids are rejected up front, a step that produces
//! a non-finite value or a failed pressure solve is reported with the step and the cell.

/// Everything that can go wrong building or stepping a fluid.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum FluidError {
    /// A grid with no interior cells, or one too small for the method.
    #[error("grid {what} must be at least {min} cells, got {got}")]
    BadGrid {
        /// Which extent (`"N"`, `"nx"`, `"ny"`, `"nz"`).
        what: &'static str,
        /// Smallest accepted value.
        min: usize,
        /// The value given.
        got: usize,
    },
    /// A parameter outside its valid range.
    #[error("parameter {name} {requirement}, got {value}")]
    BadParameter {
        /// The parameter's name.
        name: &'static str,
        /// What it must satisfy.
        requirement: &'static str,
        /// The value given.
        value: String,
    },
    /// An input array of the wrong length.
    #[error("{name} has {got} values, expected {expected}")]
    BadLength {
        /// The array.
        name: &'static str,
        /// Its length.
        got: usize,
        /// The length the grid needs.
        expected: usize,
    },
    /// A step produced NaN or infinity.
    #[error("non-finite {field} at step {step}, cell ({i}, {j}, {k}) (value {value})")]
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
    },
    /// The pressure (or viscosity) solve did not reach its tolerance.
    #[error(
        "{solve} solve at step {step} did not converge: residual {residual:.3e} after {iterations} iterations (tolerance {tolerance:.3e})"
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
