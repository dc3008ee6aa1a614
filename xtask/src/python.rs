//! The Python interpreter that runs the peer benchmarks (`PYTHON`, default `python3`), and the
//! installation of a peer's packages with pip when its module cannot be imported. The library and
//! its tests never need Python; only `cargo xtask bench --peers` does, and it skips a peer with a
//! visible note when this fails.

use std::process::Command;

/// The interpreter: `$PYTHON`, else `python3`.
pub fn python() -> String {
    std::env::var("PYTHON").unwrap_or_else(|_| "python3".into())
}

/// Whether `import module` works, installing `packages` with pip if it does not; `hint` is added
/// to the error when the installation fails.
pub fn ensure(module: &str, packages: &[&str], hint: &str) -> Result<(), String> {
    let works = || {
        Command::new(python())
            .args(["-c", &format!("import {module}")])
            .output()
            .map(|o| o.status.success())
            .unwrap_or(false)
    };
    if works() {
        return Ok(());
    }
    eprintln!("== {module} not found: {} -m pip install {}", python(), packages.join(" "));
    let out = Command::new(python())
        .args(["-m", "pip", "install", "--quiet"])
        .args(packages)
        .output()
        .map_err(|e| format!("could not run pip: {e}"))?;
    if !out.status.success() || !works() {
        return Err(format!(
            "pip install {} failed{hint}: {}",
            packages.join(" "),
            String::from_utf8_lossy(&out.stderr).lines().last().unwrap_or("")
        ));
    }
    Ok(())
}
