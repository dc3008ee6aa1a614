//! Diagnostics shared by every simulation: detection of non-finite state.
//!
//! **Invariant:** a solver that produces a NaN or infinity reports it at the step that produced it,
//! naming the crate, the element (particle, vertex, joint, ... and its component) and the last
//! finite value, and leaves the previous state intact. Nothing in the workspace lets a NaN
//! propagate silently.
//!
//! [`check_finite`] scans a flat array and reports the first offending degree of freedom in
//! anim-core's own terms; a crate that knows what its degrees of freedom are renames the report
//! with [`NonFinite::in_elements`] (fixed-width elements such as particles with `x, y, z`) or
//! [`NonFinite::at_element`] (elements of varying width such as joints).

/// Which array of the state held the non-finite value.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
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

/// Which entry of an element held the non-finite value.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Component {
    /// The element is a single value (a bare degree of freedom).
    Whole,
    /// A Cartesian axis: 0, 1, 2 are `x`, `y`, `z`.
    Axis(u32),
    /// The index of a degree of freedom within the element (a joint's coordinates).
    Dof(u32),
}

impl std::fmt::Display for Component {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Component::Whole => Ok(()),
            Component::Axis(a @ 0..=2) => write!(f, ", component {}", ["x", "y", "z"][*a as usize]),
            Component::Axis(a) => write!(f, ", component {a}"),
            Component::Dof(k) => write!(f, ", coordinate {k}"),
        }
    }
}

/// The element that held a non-finite value, in the terms of the model that owns the array.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Element {
    /// What the model calls its elements: "particle", "vertex", "joint", or "degree of freedom"
    /// for a bare array.
    pub kind: &'static str,
    /// The element's index.
    pub index: usize,
    /// The entry within the element.
    pub component: Component,
}

/// A non-finite value found in a state array.
///
/// Its message reads, e.g.,
/// `anim-springs: step 41: non-finite velocity of particle 12, component y (value inf); last
/// finite velocity of particle 12: [0.5, -3.25, 0]`.
#[derive(Debug, Clone, PartialEq)]
pub struct NonFinite {
    /// The crate whose simulation produced it ("anim-core" for an integrator used directly).
    pub origin: &'static str,
    /// The step (0-based count of completed steps before the failing one) that produced it.
    pub step: u64,
    /// Which array.
    pub field: Field,
    /// Index of the first offending degree of freedom in the flat array.
    pub dof: usize,
    /// The element and component that degree of freedom belongs to.
    pub element: Element,
    /// The offending value (NaN or +/- infinity).
    pub value: f64,
    /// The value of that degree of freedom before the step (for a force: the force at the start
    /// of the step, itself not finite when the force was never finite).
    pub last_finite: f64,
    /// The whole element before the step (its `x, y, z`, or all of a joint's coordinates).
    pub last_finite_element: Box<[f64]>,
}

impl std::fmt::Display for NonFinite {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let e = &self.element;
        write!(
            f,
            "{}: step {}: non-finite {} of {} {}{} (value {})",
            self.origin, self.step, self.field, e.kind, e.index, e.component, self.value
        )?;
        if !self.last_finite.is_finite() {
            // A force that was already non-finite at the start of the step.
            write!(f, "; it was not finite before the step either ({})", self.last_finite)
        } else if e.component == Component::Whole || self.last_finite_element.is_empty() {
            write!(f, "; last finite value {}", self.last_finite)
        } else {
            write!(
                f,
                "; last finite {} of {} {}: {:?}",
                self.field, e.kind, e.index, self.last_finite_element
            )
        }
    }
}

impl std::error::Error for NonFinite {}

impl NonFinite {
    /// A report made by anim-core on degree of freedom `dof` of a flat array, with the value
    /// found and the value before the step.
    #[must_use]
    pub fn at_dof(step: u64, field: Field, dof: usize, value: f64, last_finite: f64) -> Self {
        NonFinite {
            origin: "anim-core",
            step,
            field,
            dof,
            element: Element { kind: "degree of freedom", index: dof, component: Component::Whole },
            value,
            last_finite,
            last_finite_element: Box::new([last_finite]),
        }
    }

    /// Renames the report for an array of elements of `width` entries each (3 for particles
    /// and vertices: the component is then the axis `x, y, z`), made by the crate `origin`;
    /// `old` is the array before the step, from which the whole last finite element is taken.
    #[must_use]
    pub fn in_elements(
        mut self,
        origin: &'static str,
        kind: &'static str,
        width: usize,
        old: &[f64],
    ) -> Self {
        let width = width.max(1);
        let index = self.dof / width;
        let k = self.dof % width;
        let k = u32::try_from(k).unwrap_or(u32::MAX);
        let component = if width <= 3 { Component::Axis(k) } else { Component::Dof(k) };
        self.origin = origin;
        self.element = Element { kind, index, component };
        self.last_finite_element = old.get(index * width..(index + 1) * width).unwrap_or(&[]).into();
        self
    }

    /// Renames the report for an element of its own layout (a joint whose coordinates occupy
    /// `old_element` in the array before the step), made by the crate `origin`.
    #[must_use]
    pub fn at_element(mut self, origin: &'static str, element: Element, old_element: &[f64]) -> Self {
        self.origin = origin;
        self.element = element;
        self.last_finite_element = old_element.into();
        self
    }
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
    use crate::par::prelude::*;
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
/// [`NonFinite`] naming the step, field and first offending degree of freedom, as made by
/// anim-core (rename it with [`NonFinite::in_elements`] or [`NonFinite::at_element`]).
pub fn check_finite(step: u64, field: Field, new: &[f64], old: &[f64]) -> Result<(), NonFinite> {
    match first_non_finite(new) {
        None => Ok(()),
        Some(dof) => {
            Err(NonFinite::at_dof(step, field, dof, new[dof], old.get(dof).copied().unwrap_or(f64::NAN)))
        }
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
        assert!(msg.starts_with("anim-core: step 7: non-finite velocity of degree of freedom 1"), "{msg}");
        assert!(msg.contains("value inf") && msg.contains("last finite value 3.5"), "{msg}");
    }

    #[test]
    fn report_renamed_to_particles_and_joints() {
        let old = [0.0, 1.0, 2.0, 3.0, 4.5, 5.0];
        let new = [0.0, 1.0, 2.0, 3.0, f64::NAN, 5.0];
        let err = check_finite(3, Field::Position, &new, &old).unwrap_err().in_elements(
            "anim-springs",
            "particle",
            3,
            &old,
        );
        assert_eq!(err.element, Element { kind: "particle", index: 1, component: Component::Axis(1) });
        assert_eq!(err.dof, 4);
        assert_eq!(err.last_finite, 4.5);
        assert_eq!(*err.last_finite_element, [3.0, 4.5, 5.0]);
        let msg = err.to_string();
        assert!(
            msg.starts_with("anim-springs: step 3: non-finite position of particle 1, component y"),
            "{msg}"
        );
        assert!(msg.contains("last finite position of particle 1: [3.0, 4.5, 5.0]"), "{msg}");

        let joint = Element { kind: "joint", index: 2, component: Component::Dof(3) };
        let err = check_finite(0, Field::Velocity, &new, &old).unwrap_err().at_element(
            "anim-rigid",
            joint,
            &old[1..5],
        );
        let msg = err.to_string();
        assert!(
            msg.starts_with("anim-rigid: step 0: non-finite velocity of joint 2, coordinate 3 (value NaN)"),
            "{msg}"
        );
        assert!(msg.contains("[1.0, 2.0, 3.0, 4.5]"), "{msg}");
    }
}
