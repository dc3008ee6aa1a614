//! `cargo ci` (`cargo xtask ci` built in the test profile): what CI runs, in order; it goes on after a failed lint or doc step (so one run
//! shows every problem) and stops after failed tests.

use crate::registry::Ctx;
use crate::suites;
use std::process::Command;
use std::time::Instant;

fn cargo(args: &[&str], env: &[(&str, &str)]) -> bool {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    eprintln!("\n== cargo {}", args.join(" "));
    let start = Instant::now();
    let mut cmd = Command::new(cargo);
    cmd.args(args);
    for (k, v) in env {
        cmd.env(k, v);
    }
    let ok = match cmd.status() {
        Ok(status) => status.success(),
        Err(e) => {
            eprintln!("could not run cargo: {e}");
            false
        }
    };
    eprintln!("== {} in {:.0} s", if ok { "ok" } else { "FAILED" }, start.elapsed().as_secs_f64());
    ok
}

/// The name of the test `anim_core::quick_cases_test!` declares in every crate.
const QUICK_CASES_TEST: &str = "conformance_and_hard_cases_pass_in_quick_mode";

pub fn run() -> bool {
    let start = Instant::now();
    let steps: [(&str, &dyn Fn() -> bool); 7] = [
        ("format", &|| cargo(&["fmt", "--all", "--", "--check"], &[])),
        ("clippy", &|| cargo(&["clippy", "--workspace", "--all-targets", "--", "-D", "warnings"], &[])),
        // The crates' quick-mode case tests are skipped here: the conformance and stability steps
        // below run the same cases once more, all crates in one process. The
        // examples are type-checked and linted by clippy above; linking each of them here would
        // add minutes and test nothing more.
        ("tests", &|| {
            cargo(
                &["test", "--workspace", "--lib", "--bins", "--tests", "--", "--skip", QUICK_CASES_TEST],
                &[],
            )
        }),
        ("doc tests", &|| cargo(&["test", "--workspace", "--doc"], &[])),
        ("docs", &|| cargo(&["doc", "--workspace", "--no-deps"], &[("RUSTDOCFLAGS", "-D warnings")])),
        ("conformance (quick)", &|| suites::conformance(&Ctx { quick: true }, None).passed()),
        ("stability (quick)", &|| suites::stability(&Ctx { quick: true }, None).passed()),
    ];
    let mut failed = Vec::new();
    for (name, step) in steps {
        eprintln!("\n### {name}");
        if !step() {
            failed.push(name);
            // Keep going after lint failures so one run shows every problem; stop on test failures.
            if name == "tests" {
                break;
            }
        }
    }
    eprintln!("\nci finished in {:.0} s", start.elapsed().as_secs_f64());
    if failed.is_empty() {
        eprintln!("ci: all steps passed");
        true
    } else {
        eprintln!("ci: FAILED steps: {}", failed.join(", "));
        false
    }
}
