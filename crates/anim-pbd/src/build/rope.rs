//! Ropes: a [`Chain`] of particles spaced evenly on a segment, each joined to the next by a
//! distance constraint at its rest length and recorded as an edge for rendering. With XPBD
//! compliance `alpha` a hanging chain stretches by `alpha T` under tension `T`.

use super::builder::{PbdBuilder, bad, check_vec};
use super::error::BuildError;
use crate::constraint::ConstraintParams;
use std::ops::Range;

/// A straight chain (rope) of `count` particles from `start` to `end`, joined by `count - 1`
/// distance constraints at their rest length.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct Chain {
    /// Number of particles (>= 2).
    pub count: usize,
    /// First particle.
    pub start: [f64; 3],
    /// Last particle (distinct from `start`).
    pub end: [f64; 3],
    /// Mass of each particle (kg).
    pub mass: f64,
    /// The distance constraints.
    pub stretch: ConstraintParams,
}

impl PbdBuilder {
    /// A chain; returns the range of its particles.
    ///
    /// # Errors
    /// [`InputError::BadParameter`](super::InputError::BadParameter) for fewer than 2 particles, coincident ends or non-finite input.
    pub fn chain(&mut self, c: &Chain) -> Result<Range<usize>, BuildError> {
        if c.count < 2 {
            return Err(bad("chain", "count", "must be at least 2", c.count));
        }
        let a = check_vec("chain", "start", c.start)?;
        let b = check_vec("chain", "end", c.end)?;
        if a == b {
            return Err(bad("chain", "end", "must differ from start", format!("{:?}", c.end)));
        }
        let first = self.positions.len();
        for k in 0..c.count {
            let s = k as f64 / (c.count - 1) as f64;
            self.particle(a.lerp(b, s).to_array(), c.mass);
        }
        for k in first..first + c.count - 1 {
            self.distance(k, k + 1, c.stretch);
            self.edge([k, k + 1]);
        }
        Ok(first..first + c.count)
    }
}
