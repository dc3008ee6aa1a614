//! `cargo xtask stability --long`: soak runs. Each crate's hard case runs for `10^5` steps or
//! ten minutes of wall time, whichever comes first, checking finiteness at every step (the
//! solvers' own guards) and an energy bound or invariant on a fixed stride; the table goes to
//! the terminal and to `<out>/soak.md` (default `docs/report/`), which the report links.
//!
//! A soak case is stable when it reaches its step count or its time budget without an error and
//! without breaking its bound; anything else is a failure and `stability --long` exits 1.

use crate::registry::{Budget, Outcome, fmt_num};
use std::fmt::Write as _;

/// Runs the selected soak cases, prints the table, writes `<out>/soak.md`; true when all are
/// stable.
pub fn run(quick: bool, filter: Option<&str>, out: &str) -> bool {
    let budget = Budget::new(quick);
    let mut rows = Vec::new();
    for case in crate::cases::all().soak {
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
