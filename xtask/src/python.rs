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

/// Runs the peer script `script` (a path under `xtask/`) with `args` and the environment
/// variables `envs`, and returns the first line it printed that starts with `{` (its result).
pub fn result_line(script: &str, args: &[String], envs: &[(&str, &str)]) -> Result<String, String> {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(script);
    let out = Command::new(python())
        .arg(&path)
        .args(args)
        .envs(envs.iter().copied())
        .output()
        .map_err(|e| format!("could not run {}: {e}", python()))?;
    if !out.status.success() {
        return Err(format!(
            "{script} failed: {}",
            String::from_utf8_lossy(&out.stderr).lines().last().unwrap_or("")
        ));
    }
    String::from_utf8_lossy(&out.stdout)
        .lines()
        .find(|l| l.starts_with('{'))
        .map(str::to_string)
        .ok_or_else(|| format!("{script} printed no result"))
}

/// The value of `key` in a one-line JSON object printed by a peer script, as text (quotes
/// removed); `None` when the key is absent. Read by hand rather than with `serde_json`: Python's
/// `json.dumps` writes a diverged peer's non-finite numbers as `NaN` or `Infinity`, which
/// `serde_json` refuses for the whole line, losing the other fields (the timing, the
/// divergence flag). The scripts print flat objects of numbers and comma-free strings.
pub fn json_field(line: &str, key: &str) -> Option<String> {
    let rest = &line[line.find(&format!("\"{key}\":"))? + key.len() + 3..];
    let rest = rest.trim_start();
    let end = rest.find([',', '}']).unwrap_or(rest.len());
    Some(rest[..end].trim().trim_matches('"').to_string())
}

#[cfg(test)]
mod tests {
    #[test]
    fn json_field_reads_numbers_strings_and_absent_keys() {
        let line = r#"{"per_step_s": 0.25, "taichi": "1.7.4", "front":3}"#;
        assert_eq!(super::json_field(line, "per_step_s").as_deref(), Some("0.25"));
        assert_eq!(super::json_field(line, "taichi").as_deref(), Some("1.7.4"));
        assert_eq!(super::json_field(line, "front").as_deref(), Some("3"));
        assert_eq!(super::json_field(line, "dt"), None);
        // A diverged peer's NaN does not hide the other fields.
        let line = r#"{"per_step_s": 0.5, "min_height": NaN, "diverged": true}"#;
        assert!(
            super::json_field(line, "min_height")
                .and_then(|v| v.parse::<f64>().ok())
                .is_some_and(f64::is_nan)
        );
        assert_eq!(super::json_field(line, "per_step_s").as_deref(), Some("0.5"));
        assert_eq!(super::json_field(line, "diverged").as_deref(), Some("true"));
    }
}
