//! `cargo xtask stability --long`: soak runs. Each crate's hard case runs for `10^5` steps or
//! ten minutes of wall time, whichever comes first, checking finiteness at every step (the
//! solvers' own guards) and an energy bound or invariant on a fixed stride; the table goes to
//! the terminal and to `<out>/soak.md` (default `docs/report/`), which the report links.
//!
//! A soak case is stable when it reaches its step count or its time budget without an error and
//! without breaking its bound; anything else is a failure and `stability --long` exits 1.

use crate::registry::{Outcome, fmt_num};
use std::fmt::Write as _;
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
    pub fn start(budget: Budget) -> Self {
        Self { budget, start: Instant::now(), steps: 0 }
    }

    /// Whether another step fits the budget (the clock is read every 16 steps).
    pub fn more(&self) -> bool {
        self.steps < self.budget.steps
            && (!self.steps.is_multiple_of(16) || self.start.elapsed() < self.budget.wall)
    }

    pub fn tick(&mut self) {
        self.steps += 1;
    }

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
    pub steps: u64,
    pub simulated: f64,
    pub wall: f64,
    pub stopped_by: &'static str,
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
    pub crate_name: &'static str,
    pub name: &'static str,
    /// The bound checked, in words (for the table).
    pub bound: &'static str,
    pub run: fn(Budget) -> Soak,
}

/// Runs the selected soak cases, prints the table, writes `<out>/soak.md`; true when all are
/// stable.
pub fn run(quick: bool, filter: Option<&str>, out: &str) -> bool {
    let budget = Budget::new(quick);
    let mut rows = Vec::new();
    for case in crate::cases::soak::cases() {
        let selected = filter.is_none_or(|f| {
            let f = f.to_lowercase();
            case.crate_name.to_lowercase().contains(&f) || case.name.to_lowercase().contains(&f)
        });
        if !selected {
            continue;
        }
        eprintln!("soak: {} / {} ...", case.crate_name, case.name);
        let soak = (case.run)(budget);
        eprintln!(
            "soak: {} / {}: {} after {} steps, {:.0} s",
            case.crate_name,
            case.name,
            soak.outcome.kind(),
            soak.steps,
            soak.wall
        );
        rows.push((case, soak));
    }
    let mut md = String::new();
    let _ = writeln!(
        md,
        "# Long runs (soak)\n\nEach crate's hard case for {} steps or {} s of wall time, whichever comes \
         first (`cargo xtask stability --long{}`). Finiteness is checked by the solvers at every \
         step; the bound is checked on the stride given in the detail. Wall times are on the \
         machine that wrote this file, shared with other work.\n",
        budget.steps,
        budget.wall.as_secs(),
        if quick { " --quick" } else { "" }
    );
    md.push_str(
        "| crate | hard case | bound checked | steps | simulated time | wall time | ended by | outcome | detail |\n\
         | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n",
    );
    let mut failed = 0;
    for (case, soak) in &rows {
        let stable = matches!(soak.outcome, Outcome::Stable(_));
        if !stable {
            failed += 1;
        }
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {} s | {:.0} s | {} | {} | {} |",
            case.crate_name,
            case.name,
            case.bound,
            soak.steps,
            fmt_num(soak.simulated),
            soak.wall,
            soak.stopped_by,
            if stable { "stable".to_string() } else { format!("**{}**", soak.outcome.kind()) },
            soak.outcome.detail().replace('|', "/")
        );
    }
    println!("{md}");
    println!("soak: {} stable, {failed} failed", rows.len() - failed);
    // A filtered or quick run prints only; the full run is the one recorded.
    if filter.is_none() && !quick {
        let dir = std::path::Path::new(out);
        if let Err(e) = std::fs::create_dir_all(dir).and_then(|()| std::fs::write(dir.join("soak.md"), &md)) {
            eprintln!("could not write {}: {e}", dir.join("soak.md").display());
            return false;
        }
        eprintln!("wrote {}", dir.join("soak.md").display());
    }
    failed == 0
}
