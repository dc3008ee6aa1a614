//! `anim run SCENE --tolerance TOL`: the picked method's measured error, against the exact
//! solution on the cheapest-method table's measure, is within the tolerance.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::process::Command;

fn run(args: &[&str]) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_anim")).args(args).output().expect("the anim binary runs");
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn the_picked_method_meets_the_tolerance_on_oscillator_and_kepler() {
    for scene in ["oscillator", "kepler"] {
        for tol in ["1e-2", "1e-3"] {
            let dir = std::env::temp_dir().join(format!("anim-tol-{scene}-{tol}-{}", std::process::id()));
            let out = dir.to_str().unwrap();
            let (ok, stdout, stderr) =
                run(&["run", scene, "--tolerance", tol, "--out", out, "--no-preview", "--format", "none"]);
            assert!(ok, "{scene} {tol}: {stderr}");
            assert!(
                stdout.contains("picked ") && stdout.contains("cheapest measured method with error <="),
                "{stdout}"
            );
            let m: serde_json::Value =
                serde_json::from_str(&std::fs::read_to_string(dir.join("metrics.json")).unwrap()).unwrap();
            let tol: f64 = tol.parse().unwrap();
            assert_eq!(m["tolerance"].as_f64(), Some(tol));
            let last = m["tolerance_error_final"].as_f64().unwrap();
            let max = m["tolerance_error_max"].as_f64().unwrap();
            assert!(last > 0.0 && last <= tol, "{scene}: final error {last:e} above {tol:e}\n{stdout}");
            assert!(max >= last, "{scene}: max {max:e} below final {last:e}");
            assert!(stdout.contains(&format!("tolerance {tol:e} met")), "{stdout}");
            // The run covered the scene's whole duration (frames kept).
            let simulated = m["simulated_seconds"].as_f64().unwrap();
            let expect = if scene == "kepler" { 20.0 } else { 10.0 };
            assert!((simulated - expect).abs() < 1e-9, "{scene}: simulated {simulated}");
            std::fs::remove_dir_all(&dir).ok();
        }
    }
}

#[test]
fn unmapped_scenes_and_conflicting_flags_are_refused() {
    let dir = std::env::temp_dir().join(format!("anim-tol-refused-{}", std::process::id()));
    let out = dir.to_str().unwrap();
    let (ok, _, err) = run(&["run", "cloth", "--tolerance", "1e-2", "--out", out]);
    assert!(!ok);
    assert!(err.contains("no entry for springs scenes") && err.contains("kepler-orbit"), "{err}");
    let (ok, _, err) = run(&["run", "kepler", "--tolerance", "1e-2", "--dt", "0.01", "--out", out]);
    assert!(!ok);
    assert!(err.contains("give --dt or --tolerance, not both"), "{err}");
    let (ok, _, err) = run(&["run", "kepler", "--tolerance", "-1", "--out", out]);
    assert!(!ok);
    assert!(err.contains("--tolerance must be a positive finite number, got -1"), "{err}");
    assert!(!dir.exists(), "a refused run wrote {}", dir.display());
}
