//! Running the conformance and stability suites and printing their tables.

use crate::registry::{Check, Ctx, Judge, Outcome, fmt_num};
use std::time::Instant;

/// Results of a conformance run.
pub struct ConformanceRun {
    pub checks: Vec<Check>,
    pub seconds: f64,
}

impl ConformanceRun {
    pub fn failures(&self) -> usize {
        self.checks.iter().filter(|c| !c.passed()).count()
    }

    pub fn passed(&self) -> bool {
        self.failures() == 0
    }
}

pub fn selected(filter: Option<&str>, crate_name: &str, name: &str) -> bool {
    filter.is_none_or(|f| crate_name.contains(f) || name.contains(f))
}

pub fn conformance(ctx: &Ctx, filter: Option<&str>) -> ConformanceRun {
    let start = Instant::now();
    let mut checks = Vec::new();
    for case in crate::cases::all().conformance {
        if !selected(filter, case.crate_name, case.name) {
            continue;
        }
        let t = Instant::now();
        let mut got = (case.run)(ctx);
        eprintln!("  {:<40} {:>4} checks  {:>7.2} s", case.name, got.len(), t.elapsed().as_secs_f64());
        if got.is_empty() {
            // A case that measured nothing has failed (its setup, or its reference data).
            got.push(Check {
                crate_name: case.crate_name,
                case: format!("{}: no checks", case.name),
                metric: "checks made".into(),
                measured: f64::NAN,
                reference: 0.0,
                tolerance: 1.0,
                judge: Judge::AtLeast,
                source: "the case's own registration",
            });
        }
        checks.append(&mut got);
    }
    let run = ConformanceRun { checks, seconds: start.elapsed().as_secs_f64() };
    println!("{}", conformance_table(&run.checks));
    println!("conformance took {:.1} s", run.seconds);
    println!("conformance: {} passed, {} failed", run.checks.len() - run.failures(), run.failures());
    run
}

pub fn conformance_table(checks: &[Check]) -> String {
    let mut s = String::from(
        "| crate | case | metric | measured | rule | verdict | reference |\n| --- | --- | --- | --- | --- | --- | --- |\n",
    );
    for c in checks {
        s.push_str(&format!(
            "| {} | {} | {} | {} | {} | {} | {} |\n",
            c.crate_name,
            c.case,
            c.metric,
            fmt_num(c.measured),
            c.rule(),
            if c.passed() { "pass" } else { "**FAIL**" },
            c.source
        ));
    }
    s
}

/// Results of a stability run: (crate, case, expected, outcome).
pub struct StabilityRun {
    pub rows: Vec<(&'static str, &'static str, Outcome, Outcome)>,
}

impl StabilityRun {
    pub fn unexpected(&self) -> usize {
        self.rows.iter().filter(|(_, _, e, o)| !e.same_kind(o)).count()
    }

    pub fn passed(&self) -> bool {
        self.unexpected() == 0
    }
}

pub fn stability(ctx: &Ctx, filter: Option<&str>) -> StabilityRun {
    let mut rows = Vec::new();
    for case in crate::cases::all().stability {
        if !selected(filter, case.crate_name, case.name) {
            continue;
        }
        let outcome = (case.run)(ctx);
        rows.push((case.crate_name, case.name, (case.expected)(), outcome));
    }
    let run = StabilityRun { rows };
    println!("{}", stability_table(&run));
    println!("stability: {} passed, {} failed", run.rows.len() - run.unexpected(), run.unexpected());
    run
}

pub fn stability_table(run: &StabilityRun) -> String {
    let mut s = String::from(
        "| crate | hard case | expected | outcome | detail |\n| --- | --- | --- | --- | --- |\n",
    );
    for (krate, name, expected, outcome) in &run.rows {
        let verdict = if expected.same_kind(outcome) {
            outcome.kind().to_string()
        } else {
            format!("**{}** (unexpected)", outcome.kind())
        };
        s.push_str(&format!(
            "| {krate} | {name} | {} | {verdict} | {} |\n",
            expected.kind(),
            outcome.detail().replace('|', "/")
        ));
    }
    s
}
