//! The time-stepping [`Solver`] trait and the [`StepReport`] every step returns.
//!
//! Every simulation in the workspace (a spring network, a PBD cloth, an articulated robot, an FEM
//! body, an MPM snowball, a smoke grid) is a `Solver`: it owns its model (immutable topology and
//! parameters) and its scratch data, advances a separate, serialisable state by `dt`, and reports
//! what it did. `cargo xtask` and the `anim` command line drive every crate through this trait.

/// What one step did: iteration counts, residuals and the conserved quantities the scene defines.
///
/// Fields a solver cannot define stay `None` (a dissipative grid fluid has no total energy in
/// this sense; a 2D solver reports a 1-component angular momentum in `angular_momentum[2]`).
#[derive(Debug, Clone, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[non_exhaustive]
pub struct StepReport {
    /// Simulated time after the step.
    pub time: f64,
    /// Iterations spent by the inner solve (Newton, CG, constraint sweeps); 0 for explicit steps.
    pub iterations: usize,
    /// Final residual of the inner solve (solver-defined norm), if there was one.
    pub residual: Option<f64>,
    /// Total energy (kinetic + potential) after the step, where defined.
    pub energy: Option<f64>,
    /// The parts of [`StepReport::energy`], where the solver tells them apart: the scale its
    /// changes are measured against (see [`EnergyParts`]).
    pub energy_parts: Option<EnergyParts>,
    /// Total linear momentum after the step, where defined.
    pub linear_momentum: Option<[f64; 3]>,
    /// Total angular momentum about the origin after the step, where defined.
    pub angular_momentum: Option<[f64; 3]>,
    /// Constraint violation (PBD, joints) or velocity divergence (fluids), where defined.
    pub constraint_violation: Option<f64>,
}

/// The parts of a total energy: kinetic, gravitational (whose zero is wherever the scene's
/// origin is) and the rest of the potential (springs, elasticity, contact and limit
/// penalties, attraction to a centre), in joules (or per unit mass where the solver says so).
///
/// The total can pass through zero while its parts are large (a chain released at rest at the
/// height of its pivot has total energy 0 all along), so a relative change of the total is
/// measured against [`EnergyParts::scale`] instead.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct EnergyParts {
    /// Kinetic energy.
    pub kinetic: f64,
    /// Gravitational potential energy.
    pub gravity: f64,
    /// Every other potential energy (elastic, contact, limits, an attracting centre).
    pub elastic: f64,
}

impl EnergyParts {
    /// The total energy.
    #[must_use]
    pub fn total(&self) -> f64 {
        self.kinetic + self.gravity + self.elastic
    }

    /// The energy in play relative to a reference state's gravitational energy `gravity0`:
    /// `|kinetic| + |gravity - gravity0| + |elastic|`. It does not depend on where the zero of
    /// height is, and it is never small while something moves, is lifted or deformed.
    ///
    /// ```
    /// use anim_core::solver::EnergyParts;
    /// // A mass of 1 kg released from rest: after falling 1 m (g = 9.81) the total is unchanged,
    /// // 9.81 J moved from gravity to motion, and that is the scale.
    /// let start = EnergyParts { kinetic: 0.0, gravity: 0.0, elastic: 0.0 };
    /// let later = EnergyParts { kinetic: 9.81, gravity: -9.81, elastic: 0.0 };
    /// assert_eq!(later.total(), start.total());
    /// assert_eq!(later.scale(start.gravity), 19.62);
    /// ```
    #[must_use]
    pub fn scale(&self, gravity0: f64) -> f64 {
        self.kinetic.abs() + (self.gravity - gravity0).abs() + self.elastic.abs()
    }
}

impl StepReport {
    /// A report carrying only the time after the step.
    #[must_use]
    pub fn at_time(time: f64) -> Self {
        Self { time, ..Self::default() }
    }
}

/// A simulation that advances its state by a time step.
///
/// **Invariants** every implementation keeps:
/// - `step` does not allocate once the solver is built (scratch lives in the solver's data);
/// - on error the state is left as it was before the step;
/// - the result does not depend on the number of rayon threads.
pub trait Solver {
    /// The integrated state (positions, velocities, grids): what a checkpoint saves.
    type State;
    /// The error a step can return (bad parameters, non-finite state, a failed inner solve).
    type Error: std::error::Error + Send + Sync + 'static;

    /// Advances `state` by `dt` seconds.
    ///
    /// # Errors
    /// A solver-specific error; the state is unchanged when one is returned.
    fn step(&mut self, state: &mut Self::State, dt: f64) -> Result<StepReport, Self::Error>;
}

/// The clock a simulation keeps for checkpoints: steps taken and simulated time. Simulations
/// whose other state is rebuilt every step (the grid of a particle method) need nothing else.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepClock {
    /// Steps taken.
    pub steps: u64,
    /// Simulated time (s).
    pub time: f64,
}

impl StepClock {
    /// `{"steps": ..., "time": ...}`.
    #[cfg(feature = "serde")]
    #[must_use]
    pub fn to_memory(self) -> serde_json::Value {
        serde_json::json!({ "steps": self.steps, "time": self.time })
    }

    /// Reads what [`StepClock::to_memory`] wrote.
    ///
    /// # Errors
    /// `"no step count"` or `"no finite time"` when a field is missing, of the wrong type or,
    /// for the time, not finite.
    #[cfg(feature = "serde")]
    pub fn from_memory(memory: &serde_json::Value) -> Result<Self, &'static str> {
        let steps = memory.get("steps").and_then(serde_json::Value::as_u64).ok_or("no step count")?;
        let time = memory
            .get("time")
            .and_then(serde_json::Value::as_f64)
            .filter(|t| t.is_finite())
            .ok_or("no finite time")?;
        Ok(Self { steps, time })
    }
}

#[cfg(test)]
#[cfg(feature = "serde")]
mod tests {
    use super::StepClock;

    #[test]
    fn step_clock_round_trips_and_refuses_bad_memories() {
        let c = StepClock { steps: 42, time: 0.1 + 0.2 };
        let text = c.to_memory().to_string();
        let back = StepClock::from_memory(&serde_json::from_str(&text).expect("json")).expect("clock");
        assert_eq!(back.steps, 42);
        assert_eq!(back.time.to_bits(), c.time.to_bits());
        for (bad, why) in [
            (serde_json::json!({ "time": 1.0 }), "no step count"),
            (serde_json::json!({ "steps": -1, "time": 1.0 }), "no step count"),
            (serde_json::json!({ "steps": 1 }), "no finite time"),
            (serde_json::json!({ "steps": 1, "time": "1" }), "no finite time"),
            (serde_json::json!(null), "no step count"),
        ] {
            assert_eq!(StepClock::from_memory(&bad), Err(why), "{bad}");
        }
    }
}
