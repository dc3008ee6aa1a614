//! Stam's solver against its C transcription (`testdata/stable_fluids.c`), compiled
//! here and run side by side: bit for bit at N = 64 and 128 after 100 steps.

use super::check;
use crate::FluidError;
use crate::stam::{StamFluid, StamParams};
use anim_core::cases::{Check, Ctx, Judge};
use std::path::PathBuf;
use std::process::Command;

/// Where the C transcription is built: `fluid-c` in `CARGO_TARGET_DIR` when set, else a folder
/// of this process in the system's temporary directory (never beside the crate's sources).
fn c_dir() -> PathBuf {
    match std::env::var_os("CARGO_TARGET_DIR") {
        Some(target) => PathBuf::from(target).join("fluid-c"),
        None => std::env::temp_dir().join(format!("anim-fluid-c-{}", std::process::id())),
    }
}

/// Compiles the C transcription of Stam's routines (the crate's `testdata/stable_fluids.c`) with
/// the C compiler (`$CC`, else `cc`) and `flags` into the executable `name` (see `c_dir`), and
/// returns its path. The conformance case runs it with `-O2 -ffp-contract=off` (bit for bit with
/// Stam's solver); `cargo xtask bench --peers` times it with `-O3 -march=native`.
///
/// # Errors
/// A message when the directory cannot be created, the compiler cannot be run or fails.
pub fn compile_c(name: &str, flags: &[&str]) -> Result<PathBuf, String> {
    let dir = c_dir();
    std::fs::create_dir_all(&dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    let exe = dir.join(name);
    let src = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("testdata/stable_fluids.c");
    if !src.is_file() {
        return Err(format!("the C transcription {} is missing", src.display()));
    }
    let cc = std::env::var("CC").unwrap_or_else(|_| "cc".into());
    let out = Command::new(&cc)
        .args(flags)
        .arg("-o")
        .arg(&exe)
        .arg(&src)
        .output()
        .map_err(|e| format!("cannot run {cc}: {e}"))?;
    if !out.status.success() {
        return Err(format!("{cc} failed: {}", String::from_utf8_lossy(&out.stderr)));
    }
    Ok(exe)
}

fn stam_run(n: usize, steps: usize) -> Result<StamFluid, FluidError> {
    let mut f = StamFluid::new(n, StamParams::default())?;
    for _ in 0..steps {
        f.apply_source_pattern();
        f.step()?;
    }
    Ok(f)
}

pub(super) fn stam_bitwise(_ctx: &Ctx) -> Vec<Check> {
    let case = "Stam's solver vs C (cc -O2 -ffp-contract=off), 100 steps";
    let src = "anim-fluid testdata/stable_fluids.c (Stam 2003)";
    let exe = match compile_c("stable_fluids_exact", &["-O2", "-ffp-contract=off"]) {
        Ok(e) => e,
        Err(e) => {
            eprintln!("NOTE: {e}");
            return vec![check(
                case,
                format!("C transcription compiled ({e})"),
                0.0,
                1.0,
                1.0,
                Judge::AtLeast,
                src,
            )];
        }
    };
    let mut out = Vec::new();
    for n in [64, 128] {
        let file = c_dir().join(format!("stam_{n}.bin"));
        let ok = Command::new(&exe)
            .args(["dump", &n.to_string(), "100"])
            .arg(&file)
            .status()
            .is_ok_and(|s| s.success());
        let c_bytes = if ok { std::fs::read(&file).unwrap_or_default() } else { Vec::new() };
        let ours = stam_run(n, 100).map(|f| f.to_le_bytes()).unwrap_or_default();
        let differing = if c_bytes.len() == ours.len() && !ours.is_empty() {
            ours.chunks(4).zip(c_bytes.chunks(4)).filter(|(a, b)| a != b).count() as f64
        } else {
            f64::INFINITY
        };
        out.push(check(
            case,
            format!("N = {n}: values differing (of {})", ours.len() / 4),
            differing,
            0.0,
            0.0,
            Judge::AtMost,
            src,
        ));
    }
    out
}
