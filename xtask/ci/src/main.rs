//! `cargo ci`: what CI runs, in order. It goes on after a failed lint or doc step (so one run
//! shows every problem) and stops after failed tests.
//!
//! | step | command |
//! | --- | --- |
//! | format | `cargo fmt --all -- --check` |
//! | clippy | `cargo clippy --workspace --all-targets -- -D warnings` |
//! | tests | `cargo test --workspace --lib --bins --tests`, without the two tests below |
//! | suites | the same command, running only `xtask/tests/suites.rs`: the quick conformance and stability suites through the `xtask` binary of this build |
//! | doc tests | `cargo test --workspace --doc` |
//! | docs | `cargo doc --workspace --no-deps` with warnings denied |
//! | python | the Python bindings (`crates/anim-py`): a virtual environment under the target folder with maturin, numpy and pytest from PyPI, the module built by `maturin develop` with the dev profile into it, and pytest on `crates/anim-py/tests/`; without Python, venv or pip it prints a note and is skipped |
//! | dependency versions | the library crates' unit tests (`cargo test --workspace --lib`, without xtask, this runner and the benches) against the newest versions the dependency ranges allow (`cargo update`); the committed `Cargo.lock` is put back afterwards |
//! | crates alone | each library crate as a user who picks it alone gets it: clippy on anim-core, anim-rigid, anim-pbd, anim-skin and anim-springs, and on anim-fem alone, with `--no-default-features`; the same crates' unit and integration tests without their default features (no faer, no rayon, no serde; anim-fem without anim-io, built on its own so that features do not unify); `xtask packaged` (every publishable crate checked from its `.crate` archive, libraries and programs with every feature, against the lowest versions our direct requirements allow); `xtask consumer` (a project outside the workspace on anim-pbd and anim-rigid without their default features, newest compatible dependency versions, no serde crate in its tree) |
//!
//! The runner has no dependencies, so it starts at once, and the suites run in the test build
//! (one build of the workspace, the features of every member unified) instead of a build of
//! their own. Each crate's own quick-mode case test
//! (`anim_core::quick_cases_test!`) is skipped: the suites run the same cases, all crates in
//! one process; `cargo test -p <crate> --features cases` runs it.

use std::process::{Command, ExitCode};
use std::time::Instant;

/// The name of the test `anim_core::quick_cases_test!` declares in every crate.
const QUICK_CASES_TEST: &str = "conformance_and_hard_cases_pass_in_quick_mode";

/// The test of `xtask/tests/suites.rs`.
const SUITES_TEST: &str = "quick_conformance_and_stability_suites_pass";

/// The test build's command; the tests and suites steps give it the same arguments before
/// `--`, so the second builds nothing.
const TEST: [&str; 5] = ["test", "--workspace", "--lib", "--bins", "--tests"];

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

/// Runs a program built by the tests step (the `xtask` binary).
fn run(program: &std::path::Path, args: &[&str]) -> bool {
    eprintln!("\n== {} {}", program.display(), args.join(" "));
    let start = Instant::now();
    let ok = match Command::new(program).args(args).status() {
        Ok(status) => status.success(),
        Err(e) => {
            eprintln!("could not run {}: {e}", program.display());
            false
        }
    };
    eprintln!("== {} in {:.0} s", if ok { "ok" } else { "FAILED" }, start.elapsed().as_secs_f64());
    ok
}

/// The Python step: a virtual environment in `<target>/py-venv`, maturin, numpy and pytest
/// installed by pip, the bindings built into it with the dev profile (whose dependencies are
/// optimised, as the tests' are), and their pytest suite. A machine without Python, `venv` or a
/// reachable package index skips the step with a note; a failed build or test fails it.
fn python(target: &str) -> bool {
    let start = Instant::now();
    eprintln!("\n== python bindings (crates/anim-py)");
    // Absolute: maturin reads the environment from VIRTUAL_ENV.
    let root = std::env::current_dir().unwrap_or_default();
    let venv = root.join(target).join("py-venv");
    let bin = venv.join("bin");
    let py = bin.join("python");
    let quiet = |cmd: &mut Command| cmd.status().map(|s| s.success()).unwrap_or(false);
    if !py.exists() && !quiet(Command::new("python3").args(["-m", "venv"]).arg(&venv)) {
        eprintln!(
            "note: python3 -m venv failed or python3 is missing; the Python bindings' tests are skipped"
        );
        return true;
    }
    let pip = [
        "-m",
        "pip",
        "install",
        "--quiet",
        "--disable-pip-version-check",
        "maturin>=1.9,<2",
        "numpy",
        "pytest",
    ];
    if !quiet(Command::new(&py).args(pip)) {
        eprintln!(
            "note: pip could not install maturin, numpy and pytest; the Python bindings' tests are skipped"
        );
        return true;
    }
    let path = format!("{}:{}", bin.display(), std::env::var("PATH").unwrap_or_default());
    let built = quiet(
        Command::new(bin.join("maturin"))
            .args(["develop", "--profile", "dev", "--manifest-path", "crates/anim-py/Cargo.toml"])
            .env("VIRTUAL_ENV", &venv)
            .env("PATH", &path)
            .env("CARGO_TARGET_DIR", target),
    );
    let ok = built && quiet(Command::new(&py).args(["-m", "pytest", "-q", "crates/anim-py/tests"]));
    eprintln!("== {} in {:.0} s", if ok { "ok" } else { "FAILED" }, start.elapsed().as_secs_f64());
    ok
}

/// The unit tests of every library crate: the workspace without the tools (xtask, this runner)
/// and the benchmarks, which users never depend on.
const LIBRARY_TESTS: [&str; 9] =
    ["test", "--workspace", "--lib", "--exclude", "xtask", "--exclude", "ci", "--exclude", "anim-benches"];

/// Runs the library crates' unit tests under the lock file that `cargo update` writes (the
/// newest versions the ranges allow), then puts the committed `Cargo.lock` back, whatever
/// happened.
fn newest_versions() -> bool {
    let lock = std::path::Path::new("Cargo.lock");
    let committed = match std::fs::read(lock) {
        Ok(bytes) => bytes,
        Err(e) => {
            eprintln!("could not read {}: {e}", lock.display());
            return false;
        }
    };
    let ok = cargo(&["update"], &[]) && cargo(&LIBRARY_TESTS, &[]);
    if let Err(e) = std::fs::write(lock, &committed) {
        eprintln!("could not put the committed {} back: {e}", lock.display());
        return false;
    }
    ok
}

fn main() -> ExitCode {
    if let Some(arg) = std::env::args().nth(1) {
        eprintln!("error: `cargo ci` takes no arguments, got '{arg}'");
        return ExitCode::from(2);
    }
    let start = Instant::now();
    let tests = [&TEST[..], &["--", "--skip", QUICK_CASES_TEST, "--skip", SUITES_TEST]].concat();
    let suites = [&TEST[..], &["--", "--exact", SUITES_TEST]].concat();
    let target = std::env::var("CARGO_TARGET_DIR").unwrap_or_else(|_| "target".into());
    let xtask = std::path::Path::new(&target).join("debug").join("xtask");
    let alone = [
        "clippy",
        "-p",
        "anim-core",
        "-p",
        "anim-rigid",
        "-p",
        "anim-pbd",
        "-p",
        "anim-skin",
        "-p",
        "anim-springs",
        "--no-default-features",
        "--all-targets",
        "--",
        "-D",
        "warnings",
    ];
    let steps: [(&str, &dyn Fn() -> bool); 9] = [
        ("format", &|| cargo(&["fmt", "--all", "--", "--check"], &[])),
        ("clippy", &|| cargo(&["clippy", "--workspace", "--all-targets", "--", "-D", "warnings"], &[])),
        // The examples are type-checked and linted by clippy above; linking each of them here
        // would add minutes and test nothing more.
        ("tests", &|| cargo(&tests, &[])),
        ("suites", &|| cargo(&suites, &[])),
        ("doc tests", &|| cargo(&["test", "--workspace", "--doc"], &[])),
        ("docs", &|| cargo(&["doc", "--workspace", "--no-deps"], &[("RUSTDOCFLAGS", "-D warnings")])),
        ("python", &|| python(&target)),
        ("dependency versions", &newest_versions),
        ("crates alone", &|| {
            // Each part runs even when one before it failed, so one run shows every problem.
            let lint = cargo(&alone, &[]);
            let tests = [&["test"], &alone[1..12], &["--lib", "--tests"]].concat();
            let core = cargo(&tests, &[]);
            // anim-fem alone: its own command, since one build of several packages unifies
            // features, and anim-fem turns on anim-core's faer that the five above go without.
            let fem = ["-p", "anim-fem", "--no-default-features"];
            let fem_lint =
                cargo(&[&["clippy"], &fem[..], &["--all-targets", "--", "-D", "warnings"]].concat(), &[]);
            let fem_tests = cargo(&[&["test"], &fem[..], &["--lib", "--tests"]].concat(), &[]);
            let packaged = run(&xtask, &["packaged"]);
            let consumer = run(&xtask, &["consumer"]);
            lint && core && fem_lint && fem_tests && packaged && consumer
        }),
    ];
    let mut failed = Vec::new();
    for (name, step) in steps {
        eprintln!("\n### {name}");
        if !step() {
            failed.push(name);
            // Keep going after lint failures so one run shows every problem; stop on test failures.
            if name == "tests" || name == "suites" {
                break;
            }
        }
    }
    eprintln!("\nci finished in {:.0} s", start.elapsed().as_secs_f64());
    if failed.is_empty() {
        eprintln!("ci: all steps passed");
        ExitCode::SUCCESS
    } else {
        eprintln!("ci: FAILED steps: {}", failed.join(", "));
        ExitCode::FAILURE
    }
}
