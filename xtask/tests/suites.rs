//! The quick conformance and stability suites, run by the `xtask` binary of this build: every
//! crate's reference checks and hard cases, and the scene contracts of every registered preset
//! (determinism across thread counts, no allocation per step, checkpoint resume, the
//! non-finite guard). `cargo ci` runs this test as its own step; it takes about two minutes.

use std::process::Command;

#[test]
fn quick_conformance_and_stability_suites_pass() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    for suite in ["conformance", "stability"] {
        // The suites print their tables straight to this process's output.
        let status = Command::new(env!("CARGO_BIN_EXE_xtask"))
            .args([suite, "--quick"])
            .current_dir(&root)
            .status()
            .unwrap_or_else(|e| panic!("running xtask {suite}: {e}"));
        assert!(status.success(), "xtask {suite} --quick failed (its table above names the failures)");
    }
}
