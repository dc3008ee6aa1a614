use super::*;
use crate::scene;

fn builtin(name: &str) -> SceneFile {
    scene::builtin(name).unwrap_or_else(|| panic!("no built-in scene {name}"))
}

/// The scene file's parameter `key`.
fn param(file: &SceneFile, key: &str) -> serde_json::Value {
    file.scene.params.get(key).cloned().unwrap_or_default()
}

/// Asserts the scene file's parameters `expected` (key, JSON value).
fn assert_params(file: &SceneFile, expected: serde_json::Value) {
    for (k, v) in expected.as_object().expect("a table") {
        assert_eq!(&param(file, k), v, "{k}");
    }
}

fn pt(param: f64, seconds: f64, error: f64) -> Point {
    Point { param, seconds, error }
}

use anim_core::scene::study::family;

fn made(families: Vec<Family>) -> Table {
    Table {
        format: FORMAT,
        date: "2026-11-25".into(),
        machine: Machine { cpu: "CPU".into(), cores: 2 },
        mode: "full".into(),
        families,
    }
}

fn frame(file: &SceneFile) -> f64 {
    file.run.dt * file.run.steps_per_frame as f64
}

/// The run's step is the largest that divides the frame into whole steps and is at most `dt`.
fn assert_fits(c: &Choice, before: &SceneFile, after: &SceneFile, dt: f64) {
    let f = frame(before);
    assert!((frame(after) - f).abs() < 1e-12 * f, "frame time changed");
    assert_eq!(after.run.frames, before.run.frames);
    assert!(c.dt <= dt * (1.0 + 1e-12), "{} > {dt}", c.dt);
    assert_eq!(c.steps_per_frame, (f / dt * (1.0 - 1e-12)).ceil() as usize);
    assert_eq!((after.run.dt, after.run.steps_per_frame), (c.dt, c.steps_per_frame));
}

#[test]
fn the_embedded_table_parses_and_its_scene_families_name_known_methods() {
    let t = table_or_panic();
    assert!(!t.date.is_empty() && t.machine.cores >= 1);
    let scenes: Vec<&str> = t.families.iter().filter_map(|f| f.scene.as_deref()).collect();
    for s in [
        "harmonic-oscillator",
        "kepler-orbit",
        "springs/hanging-cloth",
        "fem/cantilever-beam",
        "fluid/lid-driven-cavity",
        "fluid/smoke-plume-3d",
        "pbd/hanging-cloth",
        "mpm/dam-break-2d",
    ] {
        assert!(scenes.contains(&s), "{s} missing from {scenes:?}");
    }
    // Every method of a mapped study is one the kind's adapter knows, on the kind's preset of
    // the study's scene.
    for f in t.families.iter().filter(|f| f.scene.is_some()) {
        assert!(!f.series.is_empty(), "{}", f.study);
        let scene = f.scene.as_deref().unwrap_or_default();
        let (kind, preset) = scene.split_once('/').map_or((scene, None), |(k, p)| (k, Some(p)));
        let kind = anim::kind(kind).unwrap_or_else(|| panic!("{scene}: no kind"));
        let tolerance = kind.tolerance.unwrap_or_else(|| panic!("{scene}: not mapped"));
        let p = (kind.presets)()
            .into_iter()
            .find(|p| preset.is_none_or(|name| p.params.get("preset").and_then(|v| v.as_str()) == Some(name)))
            .unwrap_or_else(|| panic!("{scene}: no preset"));
        let adapter = (tolerance.adapter)(&p.params, &p.run, f).unwrap_or_else(|e| panic!("{e}"));
        for s in &f.series {
            for p in &s.points {
                assert!(p.error.is_finite() && p.error >= 0.0 && p.seconds > 0.0 && p.param > 0.0, "{p:?}");
                if let Err(e) = adapter.candidate(&s.method, p) {
                    assert!(!e.contains("is not a method this build knows"), "{}: {e}", f.study);
                }
            }
        }
    }
}

fn table_or_panic() -> Table {
    table().unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn the_cheapest_on_the_scene_accounts_for_the_step_each_method_needs_there() {
    // The Kepler scene runs 400 frames x 10 steps x 0.005 s = 20 s; a study horizon of 5 makes
    // the run 4 horizons long: a first-order method's step shrinks by (1/4)^2 = 1/16, RK4's by
    // (1/4)^(1/2) = 1/2. Symplectic Euler is the cheapest in the study (1 ms against 5 ms) but on
    // the scene costs 16 ms against RK4's 10 ms.
    let t = made(vec![family(
        "k",
        "kepler-orbit",
        Some(5.0),
        &[],
        &[
            ("symplectic-euler", vec![pt(0.01, 1e-3, 1e-3)]),
            ("rk4", vec![pt(0.1, 5e-3, 1e-3), pt(0.05, 9e-3, 1e-5)]),
            ("velocity-verlet", vec![pt(0.02, 1e-4, 2e-2)]),
        ],
    )]);
    let before = builtin("kepler");
    let mut file = before.clone();
    let c = choose(&mut file, 1e-2, &t).unwrap();
    assert_eq!(c.method, "rk4");
    assert_eq!(c.param, 0.1);
    assert_params(&file, serde_json::json!({ "integrator": "rk4" }));
    assert_fits(&c, &before, &file, 0.1 * 0.5);
    assert!(
        c.why.starts_with(
            "cheapest measured method with error <= 1e-2 that this scene can run: rk4 at p = 0.1"
        ),
        "{}",
        c.why
    );
    // Over a run no longer than the horizon the study's own ranking holds: velocity Verlet at 2e-2.
    let mut short_before = before.clone();
    short_before.run.frames = 5;
    let mut short = short_before.clone();
    let c = choose(&mut short, 3e-2, &t).unwrap();
    assert_eq!((c.method.as_str(), c.param), ("velocity-verlet", 0.02));
    assert_fits(&c, &short_before, &short, 0.02);
    // 1e-6 is met by nothing: the error names the most accurate point.
    let e = choose(&mut before.clone(), 1e-6, &t).unwrap_err();
    assert!(e.contains("no method of the k study that this scene can run met it; the most accurate measured is rk4 at p = 0.05, error 1.000e-5 (ask for 1.0e-5 or more)"), "{e}");
}

#[test]
fn the_oscillator_step_is_in_units_of_one_over_omega() {
    // The built-in oscillator: k = 40, m = 1, so omega = sqrt(40); its 1000 steps of 0.01 s run
    // 10 s = 63 time units, inside a horizon of 100.
    let t = made(vec![family(
        "o",
        "harmonic-oscillator",
        Some(100.0),
        &[],
        &[("rk4", vec![pt(0.5, 1e-5, 1e-3)])],
    )]);
    let before = builtin("oscillator");
    let mut file = before.clone();
    let c = choose(&mut file, 1e-2, &t).unwrap();
    assert_fits(&c, &before, &file, 0.5 / 40f64.sqrt());
}

fn beam_table() -> Table {
    made(vec![family(
        "fem-beam",
        "fem/cantilever-beam",
        Some(0.5),
        &[("young", 1e6), ("density", 1000.0), ("cell", 0.05)],
        &[
            // The cheapest and most accurate, but another material: never the scene's.
            ("neo-hookean symplectic-euler", vec![pt(1e-3, 1e-3, 1e-6)]),
            ("stable-neo-hookean symplectic-euler", vec![pt(6.25e-4, 2e-2, 5e-2)]),
            (
                "stable-neo-hookean backward-euler (cholesky)",
                vec![pt(0.01, 8e-2, 4e-2), pt(2.5e-3, 0.3, 8e-3)],
            ),
            ("stable-neo-hookean backward-euler (ldlt)", vec![pt(0.01, 5e-2, 4e-2), pt(2.5e-3, 0.2, 8e-3)]),
        ],
    )])
}

#[test]
fn the_fem_beam_keeps_its_material_and_takes_the_studys_integrator_solver_and_scaled_step() {
    let t = beam_table();
    let before = builtin("beam");
    let mut file = before.clone();
    let c = choose(&mut file, 1e-2, &t).unwrap();
    assert_eq!((c.method.as_str(), c.param), ("stable-neo-hookean backward-euler (ldlt)", 2.5e-3));
    assert_params(&file, serde_json::json!({ "integrator": "backward-euler", "linear_solver": "ldlt" }));
    assert_eq!(c.settings, "integrator = backward-euler, linear_solver = ldlt");
    // The preset (anim-fem scenes docs): E = 10 MPa, rho = 1000, 4 cells across 0.1 m; the study's
    // beam E = 1 MPa, 2 cells: wave speeds sqrt(1e6 / 1e7), cells 0.025 / 0.05; the scene runs 120
    // frames of 1/60 s = 2 s, four times the 0.5 s horizon, a first-order method: (1/4)^2.
    let dt = 2.5e-3 * (0.1f64).sqrt() * 0.5 / 16.0;
    assert_fits(&c, &before, &file, dt);
    assert!(c.why.contains("left out as not this scene's: neo-hookean symplectic-euler (neo-hookean material (the scene's is stable-neo-hookean))"), "{}", c.why);
    assert!(c.why.contains("wave speed and cell ratios 0.1581 x run length (H/T)^2 = 0.0625"), "{}", c.why);
    // An explicit pick sets the integrator (the solver is unused).
    let mut file = before.clone();
    let c = choose(&mut file, 6e-2, &t).unwrap();
    assert_eq!(c.method, "stable-neo-hookean symplectic-euler");
    assert_params(&file, serde_json::json!({ "integrator": "symplectic-euler" }));
    assert_eq!(c.settings, "integrator = symplectic-euler");
    // 1e-4: the most accurate of the scene's material is named, not the other material's 1e-6.
    let e = choose(&mut before.clone(), 1e-4, &t).unwrap_err();
    assert!(e.contains("the most accurate measured is stable-neo-hookean backward-euler (cholesky) at p = 0.0025, error 8.000e-3 (ask for 8.0e-3 or more)"), "{e}");
    assert!(e.contains("left out: neo-hookean symplectic-euler (neo-hookean material"), "{e}");
    // A table with only other materials: nothing this scene can run.
    let mut only_other = beam_table();
    only_other.families[0].series.truncate(1);
    let e = choose(&mut before.clone(), 1e-2, &only_other).unwrap_err();
    assert!(e.contains("no method of the fem-beam study can run on this scene: neo-hookean symplectic-euler (neo-hookean material"), "{e}");
}

#[test]
fn the_hanging_cloth_takes_explicit_methods_only_at_the_stiffer_cloths_step() {
    let t = made(vec![family(
        "springs-cloth",
        "springs/hanging-cloth",
        Some(0.25),
        &[("n", 10.0), ("size", 0.5), ("mass", 0.1), ("stiffness", 100.0)],
        &[
            ("backward-euler / cholesky", vec![pt(0.01, 1e-4, 1e-4)]),
            ("rk4", vec![pt(6.25e-4, 2e-3, 1e-6)]),
            ("symplectic-euler", vec![pt(6.25e-4, 5e-4, 3e-3)]),
        ],
    )]);
    let before = builtin("cloth");
    let mut file = before.clone();
    let c = choose(&mut file, 1e-4, &t).unwrap();
    assert_eq!(c.method, "rk4");
    assert_params(&file, serde_json::json!({ "integrator": "rk4" }));
    // The preset (anim-springs scenes docs): 32 x 32 particles, 0.2 kg, structural 1000 N/m; the
    // study's 10 x 10, 0.1 kg, 100 N/m. The scene runs 120 x 2 x 0.01 = 2.4 s against 0.25 s.
    let omega = |k: f64, count: f64, mass: f64| (k * count / mass).sqrt();
    let dt = 6.25e-4 * omega(100.0, 100.0, 0.1) / omega(1000.0, 1024.0, 0.2) * (0.25f64 / 2.4).sqrt();
    assert_fits(&c, &before, &file, dt);
    assert!(c.why.contains("left out as not this scene's: backward-euler / cholesky (implicit"), "{}", c.why);
    // Other spring presets have no entry.
    let e = choose(&mut builtin("rope"), 1e-2, &t).unwrap_err();
    assert!(e.contains("no entry for springs/swinging-rope scenes (rope)"), "{e}");
    assert!(e.contains("springs/hanging-cloth (study springs-cloth)"), "{e}");
}

#[test]
fn the_cavity_takes_the_studys_resolution_and_pressure_solver() {
    let t = made(vec![family(
        "fluid_cavity_ghia",
        "fluid/lid-driven-cavity",
        None,
        &[("pressure_tolerance", 1e-5)],
        &[
            ("cg", vec![pt(16.0, 0.1, 0.04), pt(32.0, 0.5, 0.02)]),
            ("mgpcg", vec![pt(32.0, 0.3, 0.02), pt(64.0, 2.0, 0.008)]),
        ],
    )]);
    let before = builtin("lid-driven-cavity");
    let mut file = before.clone();
    let c = choose(&mut file, 0.03, &t).unwrap();
    assert_eq!((c.method.as_str(), c.param), ("mgpcg", 32.0));
    assert_params(
        &file,
        serde_json::json!({ "resolution": 32, "pressure_solver": "mgpcg", "pressure_tolerance": 1e-5 }),
    );
    // The study's dt = h = 1/32; the scene's frames of 10/64 s take 5 steps of exactly 1/32.
    assert_fits(&c, &before, &file, 1.0 / 32.0);
    assert_eq!(file.run.dt, 1.0 / 32.0);
    let e = choose(&mut before.clone(), 1e-3, &t).unwrap_err();
    assert!(e.contains("the most accurate measured is mgpcg at p = 64, error 8.000e-3"), "{e}");
    // The study measured the preset's advection and splitting: a scene that sets either is
    // refused rather than given a pick measured with another scheme.
    let mut changed = before.clone();
    changed.scene.params.insert("splitting".into(), "reflection".into());
    let e = choose(&mut changed, 0.03, &t).unwrap_err();
    assert!(e.contains("sets `splitting`, but the fluid_cavity_ghia study measured the preset's own"), "{e}");
    // Stam's solver's smoke box is not a mapped preset.
    let e = choose(&mut builtin("smoke-box-2d"), 1e-2, &t).unwrap_err();
    assert!(e.contains("no entry for fluid/smoke-box-2d scenes"), "{e}");
}

#[test]
fn the_smoke_plume_takes_the_pressure_solver_measured_at_the_nearest_grid() {
    let t = made(vec![family(
        "fluid_pressure_divergence",
        "fluid/smoke-plume-3d",
        None,
        &[],
        &[
            ("cg N=64", vec![pt(1e-3, 2e-3, 9e-4), pt(1e-5, 4e-3, 9e-6)]),
            ("mgpcg N=64", vec![pt(1e-3, 3e-3, 8e-4), pt(1e-5, 3.5e-3, 8e-6)]),
            ("cg N=256", vec![pt(1e-5, 1e-4, 9e-6)]),
        ],
    )]);
    // 32 x 48 x 32 cells: the largest side, 48, is nearest N = 64 (log scale).
    let before = builtin("smoke-plume-3d");
    let mut file = before.clone();
    let c = choose(&mut file, 1e-4, &t).unwrap();
    assert_eq!((c.method.as_str(), c.param), ("mgpcg N=64", 1e-5));
    assert_params(
        &file,
        serde_json::json!({ "resolution": 32, "pressure_solver": "mgpcg", "pressure_tolerance": 1e-5 }),
    );
    assert_eq!((file.run.dt, file.run.steps_per_frame), (before.run.dt, before.run.steps_per_frame));
    assert!(
        c.why.contains("cg N=256 (measured at N = 256; the scene's grid (48 cells) is nearest N = 64)"),
        "{}",
        c.why
    );
    let c = choose(&mut before.clone(), 1e-3, &t).unwrap();
    assert_eq!((c.method.as_str(), c.param), ("cg N=64", 1e-3));
}

#[test]
fn unmapped_scenes_and_bad_tolerances_are_refused() {
    let t = table_or_panic();
    for name in ["mpm", "drape", "chain", "dam-break-2d", "cube"] {
        let e = choose(&mut builtin(name), 1e-2, &t).unwrap_err();
        assert!(e.contains("has no entry for") && e.contains(&format!("({name})")), "{e}");
        assert!(e.contains("kepler-orbit (study core-kepler)") && e.contains("fem/cantilever-beam"), "{e}");
    }
    let mut kepler = builtin("kepler");
    for bad in [0.0, -1e-2, f64::NAN, f64::INFINITY] {
        assert!(choose(&mut kepler, bad, &t).unwrap_err().contains("--tolerance must be a positive"));
    }
    let e = choose(&mut kepler, 1e-30, &t).unwrap_err();
    assert!(
        e.contains(
            "no method of the core-kepler study that this scene can run met it; the most accurate measured is"
        ),
        "{e}"
    );
}

#[test]
fn the_suggested_tolerance_admits_the_most_accurate_point() {
    for (x, want) in
        [(1e-5, 1e-5), (0.0107, 0.011), (3.46e-4, 3.5e-4), (8e-3, 8e-3), (0.99, 0.99), (0.991, 1.0)]
    {
        let got = round_up(x);
        assert!((got - want).abs() < 1e-12 * want, "{x}: {got} != {want}");
        assert!(got >= x, "{x}: {got} does not admit it");
    }
}

#[test]
fn an_older_table_format_is_refused() {
    let old = TABLE.replacen("\"format\": 2", "\"format\": 1", 1);
    assert_ne!(old, TABLE);
    let e = parse_table(&old).unwrap_err();
    assert!(e.contains("has format 1, this build reads 2"), "{e}");
    assert!(parse_table(TABLE).is_ok());
}

fn pbd_table() -> Table {
    made(vec![family(
        "pbd-cloth-position",
        "pbd/hanging-cloth",
        Some(0.5),
        &[("n", 8.0), ("dt", 1.0 / 60.0)],
        &[
            ("Xpbd iterations (1 substep)", vec![pt(4.0, 1e-3, 1e-3), pt(16.0, 3e-3, 2e-4)]),
            ("Xpbd substeps (1 iteration)", vec![pt(4.0, 2e-3, 1e-3), pt(16.0, 6e-3, 1e-4)]),
            ("Pbd substeps (1 iteration)", vec![pt(16.0, 1e-4, 5e-2)]),
        ],
    )])
}

#[test]
fn the_pbd_cloth_takes_the_studys_method_and_counts_scaled_to_its_side_and_length() {
    let t = pbd_table();
    // The preset's cloth is 14 x 14 (anim-pbd scenes docs) against the study's 8 x 8: counts
    // scale by 14 / 8 = 1.75. The scene runs 30 frames of 1/60 s = the study's 0.5 s.
    let before = builtin("pbd-cloth");
    let mut file = before.clone();
    let c = choose(&mut file, 1e-2, &t).unwrap();
    // Iterations (1 ms x 7/4) beat substeps (2 ms x 7/4); PBD's cheap point misses 1e-2.
    assert_eq!((c.method.as_str(), c.param), ("Xpbd iterations (1 substep)", 4.0));
    assert_params(&file, serde_json::json!({ "method": "xpbd", "iterations": 7, "substeps": 1 }));
    assert_fits(&c, &before, &file, 1.0 / 60.0);
    assert_eq!(c.settings, "method = xpbd, iterations = 7, substeps = 1");
    // A loose tolerance admits PBD's point: 16 x 1.75 = 28 substeps of one iteration.
    let mut file = before.clone();
    let c = choose(&mut file, 0.1, &t).unwrap();
    assert_eq!(c.method, "Pbd substeps (1 iteration)");
    assert_params(&file, serde_json::json!({ "method": "pbd", "iterations": 1, "substeps": 28 }));
    // Twice the study's length: the iteration series are left out, substeps grow by 2^2 = 4:
    // ceil(4 x 1.75 x 4) = 28.
    let mut long = before.clone();
    long.run.frames = 60;
    let mut file = long.clone();
    let c = choose(&mut file, 1e-2, &t).unwrap();
    assert_eq!((c.method.as_str(), c.param), ("Xpbd substeps (1 iteration)", 4.0));
    assert_params(&file, serde_json::json!({ "iterations": 1, "substeps": 28 }));
    assert!(
        c.why.contains("left out as not this scene's: Xpbd iterations (1 substep) (swept iterations"),
        "{}",
        c.why
    );
    // A frame of 1/30 s takes two steps of the study's 1/60 s.
    let mut coarse = before.clone();
    coarse.run.dt = 1.0 / 30.0;
    coarse.run.frames = 15;
    let mut file = coarse.clone();
    let c = choose(&mut file, 1e-2, &t).unwrap();
    assert_fits(&c, &coarse, &file, 1.0 / 60.0);
    assert_eq!(c.steps_per_frame, 2);
    // Nothing measured meets 1e-5: the most accurate point is named.
    let e = choose(&mut before.clone(), 1e-5, &t).unwrap_err();
    assert!(
        e.contains("the most accurate measured is Xpbd substeps (1 iteration) at p = 16, error 1.000e-4"),
        "{e}"
    );
    // Other PBD presets have no entry.
    let e = choose(&mut builtin("drape"), 1e-2, &t).unwrap_err();
    assert!(
        e.contains("no entry for pbd/cloth-drape scenes (drape)") && e.contains("pbd/hanging-cloth"),
        "{e}"
    );
}

#[test]
fn the_mpm_dam_break_takes_the_studys_resolution_transfer_kernel_and_particles_per_cell() {
    let t = made(vec![family(
        "mpm_dam_break",
        "mpm/dam-break-2d",
        None,
        &[],
        &[
            ("MLS-MPM quadratic, 2x2 ppc", vec![pt(32.0, 0.5, 0.2), pt(64.0, 2.0, 0.05)]),
            ("APIC cubic, 2x2 ppc", vec![pt(32.0, 0.8, 0.08)]),
            ("MLS-MPM quadratic, 3x3 ppc", vec![pt(48.0, 3.0, 0.04)]),
        ],
    )]);
    let before = builtin("dam-break-2d-mpm");
    let mut file = before.clone();
    let c = choose(&mut file, 0.1, &t).unwrap();
    assert_eq!((c.method.as_str(), c.param), ("APIC cubic, 2x2 ppc", 32.0));
    assert_params(
        &file,
        serde_json::json!({ "resolution": 32, "transfer": "apic", "kernel": "cubic", "particles_per_cell": 2 }),
    );
    assert_eq!(c.settings, "resolution = 32, transfer = apic, kernel = cubic, particles_per_cell = 2");
    // The study's step: half a cell per sound crossing at c = 50 m/s, h = 1/32 m.
    assert_fits(&c, &before, &file, 0.5 / 32.0 / 50.0);
    let mut file = before.clone();
    let c = choose(&mut file, 0.045, &t).unwrap();
    assert_eq!((c.method.as_str(), c.param), ("MLS-MPM quadratic, 3x3 ppc", 48.0));
    assert_params(
        &file,
        serde_json::json!({ "resolution": 48, "transfer": "mls-mpm", "kernel": "quadratic", "particles_per_cell": 3 }),
    );
    assert_fits(&c, &before, &file, 0.5 / 48.0 / 50.0);
    let e = choose(&mut before.clone(), 0.01, &t).unwrap_err();
    assert!(
        e.contains("the most accurate measured is MLS-MPM quadratic, 3x3 ppc at p = 48, error 4.000e-2 (ask for 4.0e-2 or more)"),
        "{e}"
    );
    // The other MPM presets have no entry.
    let e = choose(&mut builtin("mpm"), 0.1, &t).unwrap_err();
    assert!(
        e.contains("no entry for mpm/three-materials scenes (mpm)") && e.contains("mpm/dam-break-2d"),
        "{e}"
    );
}
