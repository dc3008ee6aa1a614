//! `anim run SCENE --tolerance TOL`: the picked method's measured error, on the study's measure
//! against the scene's reference (exact solution, Ghia's cavity, the pressure residual, Martin &
//! Moyce's surge front), is within the tolerance; scenes without a reference run the picked method
//! to the end.

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
    let (ok, _, err) = run(&["run", "mpm", "--tolerance", "1e-2", "--out", out]);
    assert!(!ok);
    assert!(err.contains("no entry for mpm/three-materials scenes") && err.contains("kepler-orbit"), "{err}");
    let (ok, _, err) = run(&["run", "kepler", "--tolerance", "1e-2", "--dt", "0.01", "--out", out]);
    assert!(!ok);
    assert!(err.contains("give --dt or --tolerance, not both"), "{err}");
    let (ok, _, err) =
        run(&["run", "lid-driven-cavity", "--tolerance", "0.1", "--resolution", "48", "--out", out]);
    assert!(!ok);
    assert!(err.contains("give --resolution or --tolerance, not both: on lid-driven-cavity"), "{err}");
    let (ok, _, err) = run(&["run", "kepler", "--tolerance", "-1", "--out", out]);
    assert!(!ok);
    assert!(err.contains("--tolerance must be a positive finite number, got -1"), "{err}");
    assert!(!dir.exists(), "a refused run wrote {}", dir.display());
}

fn metrics(dir: &std::path::Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(dir.join("metrics.json")).unwrap()).unwrap()
}

#[test]
fn the_cavity_and_the_plume_meet_the_tolerance_on_their_studies_measures() {
    // The cavity: Ghia's centreline velocities after the scene's 20 s (steady at Re = 100).
    let dir = std::env::temp_dir().join(format!("anim-tol-cavity-{}", std::process::id()));
    let out = dir.to_str().unwrap();
    let (ok, stdout, stderr) = run(&[
        "run",
        "lid-driven-cavity",
        "--tolerance",
        "0.1",
        "--out",
        out,
        "--no-preview",
        "--format",
        "none",
    ]);
    assert!(ok, "{stderr}");
    assert!(
        stdout.contains("in the fluid_cavity_ghia study") && stdout.contains("pressure_tolerance = 1e-5"),
        "{stdout}"
    );
    let m = metrics(&dir);
    let last = m["tolerance_error_final"].as_f64().unwrap();
    assert!(last > 0.0 && last <= 0.1, "Ghia error {last:e}\n{stdout}");
    assert!((m["simulated_seconds"].as_f64().unwrap() - 20.0).abs() < 1e-9);
    std::fs::remove_dir_all(&dir).ok();
    // The plume (coarsened and shortened): every projection's relative residual.
    let dir = std::env::temp_dir().join(format!("anim-tol-plume-{}", std::process::id()));
    let out = dir.to_str().unwrap();
    let args = ["run", "smoke-plume-3d", "--resolution", "8", "--frames", "3", "--tolerance", "1e-3"];
    let (ok, stdout, stderr) =
        run(&[&args[..], &["--out", out, "--no-preview", "--format", "none"]].concat());
    assert!(ok, "{stderr}");
    assert!(stdout.contains("in the fluid_pressure_divergence study"), "{stdout}");
    let m = metrics(&dir);
    let max = m["tolerance_error_max"].as_f64().unwrap();
    assert!(max > 0.0 && max <= 1e-3, "residual {max:e}\n{stdout}");
    assert!(stdout.contains("tolerance 1e-3 met"), "{stdout}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn the_beam_and_the_cloth_run_the_picked_method_to_the_end() {
    // No reference in these scenes: the picked (scaled) step must at least run stably.
    for (scene, extra, tol) in [
        ("beam", ["--resolution", "2"], "1e-2"),
        ("cloth", ["--resolution", "8"], "1e-2"),
        ("pbd-cloth", ["--resolution", "6"], "0.1"),
    ] {
        let dir = std::env::temp_dir().join(format!("anim-tol-{scene}-{}", std::process::id()));
        let out = dir.to_str().unwrap();
        let args = [
            "run",
            scene,
            "--frames",
            "3",
            "--tolerance",
            tol,
            "--out",
            out,
            "--no-preview",
            "--format",
            "none",
        ];
        let (ok, stdout, stderr) = run(&[&args[..], &extra[..]].concat());
        assert!(ok, "{scene}: {stderr}\n{stdout}");
        assert!(stdout.contains("picked ") && stdout.contains("that this scene can run"), "{stdout}");
        let m = metrics(&dir);
        assert_eq!(m["status"], "completed", "{scene}");
        assert!(m["tolerance_error_final"].is_null(), "{scene}: no reference, no error");
        // Said so, and the pick's cost measured against the scene's own method.
        assert!(stdout.contains("error on the table's measure: not measured"), "{stdout}");
        assert!(
            stdout.contains("with the scene's own (measured on a few steps)")
                || stderr.contains("warning: --tolerance: a frame with the picked method takes about"),
            "{stdout}\n{stderr}"
        );
        std::fs::remove_dir_all(&dir).ok();
    }
}

#[test]
fn the_mpm_dam_break_meets_the_tolerance_on_martin_and_moyces_front() {
    let dir = std::env::temp_dir().join(format!("anim-tol-dam-{}", std::process::id()));
    let out = dir.to_str().unwrap();
    let args =
        ["run", "dam-break-2d-mpm", "--tolerance", "0.1", "--out", out, "--no-preview", "--format", "none"];
    let (ok, stdout, stderr) = run(&args);
    assert!(ok, "{stderr}\n{stdout}");
    assert!(
        stdout.contains("in the mpm_dam_break study") && stdout.contains("particles_per_cell = "),
        "{stdout}"
    );
    let m = metrics(&dir);
    // The built-in scene's 35 frames of 0.01 s pass all of Martin & Moyce's times (to 0.336 s).
    assert!((m["simulated_seconds"].as_f64().unwrap() - 0.35).abs() < 1e-9);
    let last = m["tolerance_error_final"].as_f64().unwrap();
    assert!(last > 0.0 && last <= 0.1, "surge-front error {last:e}\n{stdout}");
    assert!(stdout.contains("tolerance 1e-1 met"), "{stdout}");
    std::fs::remove_dir_all(&dir).ok();
    // No measured point is within 1e-3: refused, naming the most accurate one.
    let (ok, _, err) = run(&["run", "dam-break-2d-mpm", "--tolerance", "1e-3", "--out", out]);
    assert!(!ok);
    assert!(err.contains("no method of the mpm_dam_break study that this scene can run met it; the most accurate measured is"), "{err}");
    assert!(!dir.exists());
}
