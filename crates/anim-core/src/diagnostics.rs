//! Diagnostics shared by every simulation: detection of non-finite state.
//!
//! **Invariant:** a solver that produces a NaN or infinity reports it at the step that produced it,
//! naming the degree of freedom, and leaves the previous state intact. Nothing in the workspace lets
//! a NaN propagate silently.

use serde::{Deserialize, Serialize};

/// Which array of the state held the non-finite value.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Field {
    /// Positions (generalised coordinates).
    Position,
    /// Velocities.
    Velocity,
    /// Forces or accelerations.
    Force,
    /// Any other named quantity.
    Other(&'static str),
}

impl std::fmt::Display for Field {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Field::Position => f.write_str("position"),
            Field::Velocity => f.write_str("velocity"),
            Field::Force => f.write_str("force"),
            Field::Other(name) => f.write_str(name),
        }
    }
}

/// A non-finite value found in a state array.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[error(
    "non-finite {field} at step {step}, degree of freedom {dof} (value {value}, last finite value {last_finite})"
)]
pub struct NonFinite {
    /// The step (0-based count of completed steps before the failing one) that produced it.
    pub step: u64,
    /// Which array.
    pub field: Field,
    /// Index of the first offending degree of freedom.
    pub dof: usize,
    /// The offending value (NaN or +/- infinity).
    pub value: f64,
    /// The value of that degree of freedom before the step.
    pub last_finite: f64,
}

/// Arrays at least this long are scanned in parallel (in fixed chunks; the answer is the same).
const PARALLEL_LEN: usize = 1 << 15;
const CHUNK: usize = 1 << 13;

/// Whether any entry is NaN or infinite: `v * 0` is `0` for finite `v` and NaN otherwise, and
/// the sum of those products vectorises.
#[inline]
fn has_non_finite(values: &[f64]) -> bool {
    values.iter().fold(0.0, |acc, &v| acc + v * 0.0) != 0.0
}

/// Returns the index of the first non-finite entry of `values`, if any.
#[inline]
#[must_use]
pub fn first_non_finite(values: &[f64]) -> Option<usize> {
    use rayon::prelude::*;
    let bad = if values.len() >= PARALLEL_LEN {
        values.par_chunks(CHUNK).any(has_non_finite)
    } else {
        has_non_finite(values)
    };
    if bad { values.iter().position(|v| !v.is_finite()) } else { None }
}

/// Checks `new` for non-finite entries; `old` supplies the last finite value for the report.
///
/// # Errors
/// [`NonFinite`] naming the step, field and first offending degree of freedom.
pub fn check_finite(step: u64, field: Field, new: &[f64], old: &[f64]) -> Result<(), NonFinite> {
    match first_non_finite(new) {
        None => Ok(()),
        Some(dof) => Err(NonFinite {
            step,
            field,
            dof,
            value: new[dof],
            last_finite: old.get(dof).copied().unwrap_or(f64::NAN),
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_nan_and_infinity() {
        assert_eq!(first_non_finite(&[0.0, 1.0, -2.0]), None);
        assert_eq!(first_non_finite(&[0.0, f64::NAN, 1.0]), Some(1));
        assert_eq!(first_non_finite(&[0.0, 1.0, f64::NEG_INFINITY]), Some(2));
        assert_eq!(first_non_finite(&[f64::MAX, f64::MAX]), None);
        // Long arrays take the parallel path and still name the first offender.
        let mut long = vec![1.0; 3 * PARALLEL_LEN + 5];
        assert_eq!(first_non_finite(&long), None);
        long[2 * PARALLEL_LEN + 7] = f64::NAN;
        long[PARALLEL_LEN + 3] = f64::INFINITY;
        assert_eq!(first_non_finite(&long), Some(PARALLEL_LEN + 3));
    }

    #[test]
    fn report_names_dof_and_last_value() {
        let err = check_finite(7, Field::Velocity, &[1.0, f64::INFINITY], &[1.0, 3.5]).unwrap_err();
        assert_eq!(err.step, 7);
        assert_eq!(err.dof, 1);
        assert_eq!(err.last_finite, 3.5);
        let msg = err.to_string();
        assert!(msg.contains("velocity") && msg.contains("step 7") && msg.contains("freedom 1"));
    }
}
