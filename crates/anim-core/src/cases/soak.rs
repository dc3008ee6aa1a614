//! Soak runs: a crate's hard case stepped for a step count or a wall-time budget, whichever ends
//! first, checking finiteness at every step and an energy bound or invariant on a stride.

use super::Outcome;
use std::time::{Duration, Instant};

/// How long each case runs.
#[derive(Debug, Clone, Copy)]
pub struct Budget {
    /// Step count to reach.
    pub steps: u64,
    /// Wall-time cap.
    pub wall: Duration,
}

impl Budget {
    /// `10^5` steps or ten minutes; `--quick`: 2000 steps or 20 s (a smoke run of the harness).
    pub fn new(quick: bool) -> Self {
        if quick {
            Self { steps: 2_000, wall: Duration::from_secs(20) }
        } else {
            Self { steps: 100_000, wall: Duration::from_secs(600) }
        }
    }
}

/// Counts steps against a [`Budget`].
pub struct Clock {
    budget: Budget,
    start: Instant,
    /// Steps completed.
    pub steps: u64,
}

impl Clock {
    /// A clock started now.
    pub fn start(budget: Budget) -> Self {
        Self { budget, start: Instant::now(), steps: 0 }
    }

    /// Whether another step fits the budget (the clock is read every 16 steps).
    pub fn more(&self) -> bool {
        self.steps < self.budget.steps
            && (!self.steps.is_multiple_of(16) || self.start.elapsed() < self.budget.wall)
    }

    /// Counts one step.
    pub fn tick(&mut self) {
        self.steps += 1;
    }

    /// Wall time since the start, seconds.
    pub fn seconds(&self) -> f64 {
        self.start.elapsed().as_secs_f64()
    }

    /// What ended the run.
    pub fn stopped_by(&self) -> &'static str {
        if self.steps >= self.budget.steps { "step count" } else { "time budget" }
    }
}

/// What a soak run did.
pub struct Soak {
    /// Steps taken.
    pub steps: u64,
    /// Simulated time reached, seconds.
    pub simulated: f64,
    /// Wall time, seconds.
    pub wall: f64,
    /// What ended the run.
    pub stopped_by: &'static str,
    /// The verdict.
    pub outcome: Outcome,
}

impl Soak {
    /// The run of `clock` ending with `outcome` after `simulated` seconds of simulated time.
    pub fn new(clock: &Clock, simulated: f64, outcome: Outcome) -> Self {
        let stopped_by = if matches!(outcome, Outcome::Stable(_)) { clock.stopped_by() } else { "failure" };
        Self { steps: clock.steps, simulated, wall: clock.seconds(), stopped_by, outcome }
    }
}

/// Steps until the budget ends: `step(k)` takes step `k` (1-based) and checks what it must; an
/// error ends the run as a detected divergence with that text.
pub fn drive(
    budget: Budget,
    dt: f64,
    mut step: impl FnMut(u64) -> Result<(), String>,
) -> Result<Clock, Soak> {
    let mut clock = Clock::start(budget);
    while clock.more() {
        if let Err(e) = step(clock.steps + 1) {
            return Err(Soak::new(&clock, clock.steps as f64 * dt, Outcome::Diverged(e)));
        }
        clock.tick();
    }
    Ok(clock)
}

/// A setup that failed: rejected before the first step.
pub fn rejected(budget: Budget, e: impl std::fmt::Display) -> Soak {
    Soak::new(&Clock::start(budget), 0.0, Outcome::Rejected(e.to_string()))
}

/// The verdict of a finished run: stable when `ok`, else diverged, with `detail`.
pub fn finish(clock: &Clock, dt: f64, ok: bool, detail: String) -> Soak {
    Soak::new(
        clock,
        clock.steps as f64 * dt,
        if ok { Outcome::Stable(detail) } else { Outcome::Diverged(detail) },
    )
}

/// A named soak case.
pub struct SoakCase {
    /// The crate.
    pub crate_name: &'static str,
    /// The hard case's name.
    pub name: &'static str,
    /// The bound checked, in words (for the table).
    pub bound: &'static str,
    /// Runs the case within the budget.
    pub run: fn(Budget) -> Soak,
}

/// Steps (or frames) between the energy checks of a soak case.
pub const ENERGY_STRIDE: u64 = 10;

/// Whether energy `e` is above the initial `e0` beyond rounding (relative `1e-9`); true for NaN.
#[must_use]
pub fn energy_exceeds(e: f64, e0: f64) -> bool {
    !(e <= e0 + 1e-9 * e0.abs().max(1e-12))
}

/// The detail of an energy bound broken at step `k`.
#[must_use]
pub fn energy_above(k: u64, e: f64, e0: f64) -> String {
    format!("step {k}: energy {e} J above its initial value {e0} J")
}
