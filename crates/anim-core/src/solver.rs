//! The time-stepping [`Solver`] trait and the [`StepReport`] every step returns.
//!
//! Every simulation in the workspace (a spring network, a PBD cloth, an articulated robot, an FEM
//! body, an MPM snowball, a smoke grid) is a `Solver`: it owns its model (immutable topology and
//! parameters) and its scratch data, advances a separate, serialisable state by `dt`, and reports
//! what it did. `cargo xtask` and the `anim` command line drive every crate through this trait.

use serde::{Deserialize, Serialize};

/// What one step did: iteration counts, residuals and the conserved quantities the scene defines.
///
/// Fields a solver cannot define stay `None` (a dissipative grid fluid has no total energy in
/// this sense; a 2D solver reports a 1-component angular momentum in `angular_momentum[2]`).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
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
    /// Total linear momentum after the step, where defined.
    pub linear_momentum: Option<[f64; 3]>,
    /// Total angular momentum about the origin after the step, where defined.
    pub angular_momentum: Option<[f64; 3]>,
    /// Constraint violation (PBD, joints) or velocity divergence (fluids), where defined.
    pub constraint_violation: Option<f64>,
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
    #[must_use]
    pub fn to_memory(self) -> serde_json::Value {
        serde_json::json!({ "steps": self.steps, "time": self.time })
    }

    /// Reads what [`StepClock::to_memory`] wrote.
    ///
    /// # Errors
    /// `"no step count"` or `"no finite time"` when a field is missing, of the wrong type or,
    /// for the time, not finite.
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
