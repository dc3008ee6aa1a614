//! `anim run SCENE --tolerance TOL`: the scene states the accuracy it needs instead of a method,
//! and the method comes from the measured cheapest-method table of the workspace report
//! (`docs/report/cheapest.json`, written by `cargo xtask report`, embedded in the binary at build
//! time so that no repository is needed at run time).
//!
//! Mapped scene kinds (the report's studies run the same problem):
//!
//! | scene kind | study | what is picked | the table's error, measured on the run |
//! | --- | --- | --- | --- |
//! | `harmonic-oscillator` | `core-oscillator` (`m = k = 1`, 10.3 periods) | integrator and `dt` (the study's `dt` in units of `1/omega`) | `|(x - x_e, (v - v_e)/omega)| / |(x0, v0/omega)|`, relative |
//! | `kepler-orbit` | `core-kepler` (`e = 0.5`, 1.3 orbits, `a = mu = 1` as in the scene) | integrator and `dt` | `|x - x_e|` (position; `a = 1`, so relative) |
//!
//! A scene that runs longer than the study's horizon `H` gets a smaller step: the error of an
//! order-`p` method grows at most like `T^2 dt^p` over a time `T` (linearly for the symplectic
//! ones, quadratically when the energy drifts), so `dt` is scaled by `(H / T)^(2/p)`. The run
//! keeps the scene's frame times: each frame takes `ceil(frame interval / dt)` steps.
//!
//! Not mapped, and why: the cloth studies of anim-springs and anim-pbd measure their own small
//! cloths (different size, stiffness and Newton settings from the `springs` presets; PBD presets
//! do not take iterations or substeps from scene files), so their dt or iteration counts would not
//! transfer to a scene; the FEM, MPM and fluid studies sweep resolution or pressure tolerance of
//! a reference problem, not settings of a preset. Those scenes get an error naming the mapped
//! kinds.

use crate::scene::{Scene, SceneFile};
use anim_core::integrate::systems::{HarmonicOscillator, KeplerOrbit};
use anim_core::integrate::{IntegratorKind, State};

/// The report's table, embedded at build time.
pub const TABLE: &str = include_str!("../../../docs/report/cheapest.json");

/// The parts of `cheapest.json` the picker reads.
#[derive(Debug, Clone, serde::Deserialize)]
pub struct Table {
    /// UTC date of the report run.
    pub date: String,
    /// Machine the wall times were measured on.
    pub machine: Machine,
    /// `quick` or `full` sweeps.
    pub mode: String,
    /// One entry per study.
    pub families: Vec<Family>,
}

/// The machine of the measurements.
#[derive(Debug, Clone, serde::Deserialize)]
pub struct Machine {
    /// CPU model.
    pub cpu: String,
    /// Logical cores.
    pub cores: usize,
}

/// One study's picks.
#[derive(Debug, Clone, serde::Deserialize)]
pub struct Family {
    /// The study's name in the report.
    pub study: String,
    /// The scene kind the study's problem is, if any.
    pub scene: Option<String>,
    /// Simulated time the study measured over.
    pub horizon: Option<f64>,
    /// What the error measures.
    pub error: String,
    /// The cheapest method per tolerance.
    pub picks: Vec<Pick>,
}

/// The cheapest measured method meeting one tolerance.
#[derive(Debug, Clone, serde::Deserialize)]
pub struct Pick {
    /// The tolerance.
    pub tolerance: f64,
    /// Method label (`None`: no method of the sweep met it).
    pub method: Option<String>,
    /// The swept parameter (here: `dt`).
    pub param: Option<f64>,
    /// Wall time of one run of the study's problem, seconds.
    pub seconds: Option<f64>,
    /// The study's error at that point.
    pub error: Option<f64>,
}

/// What `--tolerance` did to a scene.
#[derive(Debug, Clone, PartialEq)]
pub struct Choice {
    /// The integrator picked.
    pub integrator: IntegratorKind,
    /// The step the run takes (s).
    pub dt: f64,
    /// Steps per frame (the frame times stay the scene's).
    pub steps_per_frame: usize,
    /// Why, in one paragraph.
    pub why: String,
}

/// The embedded table.
///
/// # Errors
/// A message if the embedded text is not a valid table (a build from a broken report).
pub fn table() -> Result<Table, String> {
    serde_json::from_str(TABLE)
        .map_err(|e| format!("the embedded docs/report/cheapest.json is not valid: {e}"))
}

/// The integrator a table label names.
#[must_use]
pub fn integrator(label: &str) -> Option<IntegratorKind> {
    IntegratorKind::ALL.into_iter().find(|k| k.label() == label)
}

/// The scene kind's name in scene files.
fn kind_of(scene: &Scene) -> &'static str {
    match scene {
        Scene::HarmonicOscillator { .. } => "harmonic-oscillator",
        Scene::KeplerOrbit { .. } => "kepler-orbit",
        Scene::Skinning { .. } => "skinning",
        Scene::Rigid { .. } => "rigid",
        Scene::Pbd { .. } => "pbd",
        Scene::Fem { .. } => "fem",
        Scene::Mpm { .. } => "mpm",
        Scene::Fluid { .. } => "fluid",
        Scene::Springs { .. } => "springs",
        Scene::Flip { .. } => "flip",
    }
}

/// The scene's time unit relative to the study's: the oscillator study has `omega = 1`, so its
/// times are scene times times `omega`; the Kepler study and scene share `a = mu = 1`.
fn time_unit(scene: &Scene) -> f64 {
    match *scene {
        Scene::HarmonicOscillator { mass, stiffness, .. } => (stiffness / mass).sqrt(),
        _ => 1.0,
    }
}

/// Sets the integrator, `dt` and steps per frame of `file` to meet `tol` on the table's error,
/// from `table`.
///
/// # Errors
/// A message when `tol` is not a positive finite number, when the scene kind has no table entry
/// (listing those that have one), or when no measured method meets `tol`.
pub fn choose(file: &mut SceneFile, tol: f64, table: &Table) -> Result<Choice, String> {
    if !(tol > 0.0 && tol.is_finite()) {
        return Err(format!("--tolerance must be a positive finite number, got {tol}"));
    }
    let kind = kind_of(&file.scene);
    let mapped: Vec<&Family> = table.families.iter().filter(|f| f.scene.is_some()).collect();
    let Some(family) = mapped.iter().find(|f| f.scene.as_deref() == Some(kind)) else {
        let names: Vec<String> = mapped
            .iter()
            .map(|f| format!("{} (study {})", f.scene.as_deref().unwrap_or(""), f.study))
            .collect();
        return Err(format!(
            "--tolerance: the report's cheapest-method table has no entry for {} scenes ({}); \
             scene kinds with one: {}",
            kind,
            file.name,
            names.join(", ")
        ));
    };
    // The largest measured tolerance not above the one asked for (the table is per decade).
    let row = family
        .picks
        .iter()
        .filter(|p| p.tolerance <= tol * (1.0 + 1e-12))
        .max_by(|a, b| a.tolerance.total_cmp(&b.tolerance));
    let (Some(row), Some(label), Some(dt_study)) =
        (row, row.and_then(|r| r.method.as_deref()), row.and_then(|r| r.param))
    else {
        let reached: Vec<String> = family
            .picks
            .iter()
            .filter(|p| p.method.is_some())
            .map(|p| format!("{:e}", p.tolerance))
            .collect();
        return Err(format!(
            "--tolerance {tol:e}: no method of the {} study met it (measured tolerances met: {})",
            family.study,
            reached.join(", ")
        ));
    };
    let integrator = integrator(label).ok_or_else(|| {
        format!("--tolerance: the table names `{label}`, which is not an integrator this build knows")
    })?;
    let unit = time_unit(&file.scene);
    let frame = file.run.dt * file.run.steps_per_frame as f64;
    let duration = frame * file.run.frames as f64;
    let horizon = family.horizon.unwrap_or(f64::INFINITY);
    let mut dt = dt_study / unit;
    let mut scaled = String::new();
    if duration * unit > horizon {
        let factor = (horizon / (duration * unit)).powf(2.0 / f64::from(integrator.order()));
        dt *= factor;
        scaled = format!(
            "; the scene runs {:.3} s, longer than the study's {:.3} s, so dt is scaled by (H/T)^(2/p) = {factor:.3}",
            duration,
            horizon / unit
        );
    }
    let steps_per_frame = (frame / dt * (1.0 - 1e-12)).ceil().max(1.0) as usize;
    let dt_run = frame / steps_per_frame as f64;
    match &mut file.scene {
        Scene::HarmonicOscillator { integrator: i, .. } | Scene::KeplerOrbit { integrator: i, .. } => {
            *i = integrator;
        }
        _ => return Err(format!("--tolerance: {kind} scenes are not mapped")),
    }
    file.run.dt = dt_run;
    file.run.steps_per_frame = steps_per_frame;
    let why = format!(
        "cheapest measured method with error <= {:e}: {label} dt={} in the {} study, error {:.2e}, {} per run \
         (report of {}, {} mode, {}, {} cores){}; running {steps_per_frame} step{} of {dt_run:.4e} s per frame",
        row.tolerance,
        short(dt_study),
        family.study,
        row.error.unwrap_or(f64::NAN),
        wall(row.seconds.unwrap_or(f64::NAN)),
        table.date,
        table.mode,
        table.machine.cpu,
        table.machine.cores,
        if unit == 1.0 {
            scaled
        } else {
            format!(" (= {:.4e} s at omega = {unit:.4}){scaled}", dt_study / unit)
        },
        if steps_per_frame == 1 { "" } else { "s" },
    );
    Ok(Choice { integrator, dt: dt_run, steps_per_frame, why })
}

fn short(x: f64) -> String {
    let s = format!("{x:.4}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}

fn wall(s: f64) -> String {
    if s < 1e-3 {
        format!("{:.0} us", s * 1e6)
    } else if s < 1.0 {
        format!("{:.1} ms", s * 1e3)
    } else {
        format!("{s:.2} s")
    }
}

/// The error the table measures, of `state` of a mapped scene against its exact solution
/// (`None` for other scenes).
#[must_use]
pub fn table_error(scene: &Scene, state: &State) -> Option<f64> {
    match *scene {
        Scene::HarmonicOscillator { mass, stiffness, damping, x0, v0, .. } => {
            let omega = (stiffness / mass).sqrt();
            let (xe, ve) = HarmonicOscillator::damped(mass, stiffness, damping).exact(x0, v0, state.t);
            let scale = x0.hypot(v0 / omega);
            let (dx, dv) = (state.x.first()? - xe, (state.v.first()? - ve) / omega);
            Some(dx.hypot(dv) / scale.max(f64::MIN_POSITIVE))
        }
        Scene::KeplerOrbit { eccentricity, .. } => {
            let (xe, _) = KeplerOrbit::ellipse(eccentricity).exact(state.t);
            Some((state.x.first()? - xe[0]).hypot(state.x.get(1)? - xe[1]))
        }
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene;
    use std::path::Path;

    fn builtin(name: &str) -> SceneFile {
        scene::parse(scene::builtin(name).unwrap_or_default(), Path::new(name))
            .unwrap_or_else(|e| panic!("{e}"))
    }

    #[test]
    fn the_embedded_table_parses_and_names_known_integrators() {
        let t = table().unwrap();
        assert!(!t.date.is_empty() && t.machine.cores >= 1);
        let mapped: Vec<&Family> = t.families.iter().filter(|f| f.scene.is_some()).collect();
        let kinds: Vec<&str> = mapped.iter().filter_map(|f| f.scene.as_deref()).collect();
        assert_eq!(kinds, ["harmonic-oscillator", "kepler-orbit"]);
        for f in mapped {
            assert!(f.horizon.is_some_and(|h| h > 0.0), "{}", f.study);
            for p in &f.picks {
                if let Some(m) = &p.method {
                    assert!(integrator(m).is_some(), "{}: unknown method {m}", f.study);
                    assert!(p.error.is_some_and(|e| e <= p.tolerance), "{}: {p:?}", f.study);
                    assert!(p.param.is_some_and(|dt| dt > 0.0), "{}: {p:?}", f.study);
                }
            }
            // 1e-1 to 1e-3 are met by some measured method.
            for tol in [1e-1, 1e-2, 1e-3] {
                assert!(
                    f.picks.iter().any(|p| p.tolerance == tol && p.method.is_some()),
                    "{}: nothing meets {tol}",
                    f.study
                );
            }
        }
    }

    #[test]
    fn unmapped_scenes_and_bad_tolerances_are_refused() {
        let t = table().unwrap();
        let mut cloth = builtin("cloth");
        let e = choose(&mut cloth, 1e-2, &t).unwrap_err();
        assert!(e.contains("no entry for springs scenes (cloth)"), "{e}");
        assert!(
            e.contains("harmonic-oscillator (study core-oscillator)") && e.contains("kepler-orbit"),
            "{e}"
        );
        let mut kepler = builtin("kepler");
        for bad in [0.0, -1e-2, f64::NAN, f64::INFINITY] {
            assert!(choose(&mut kepler, bad, &t).unwrap_err().contains("--tolerance must be a positive"));
        }
        let e = choose(&mut kepler, 1e-30, &t).unwrap_err();
        assert!(e.contains("no method of the core-kepler study met it"), "{e}");
    }

    #[test]
    fn the_pick_keeps_the_frame_times_and_never_exceeds_the_table_step() {
        let t = table().unwrap();
        for name in ["oscillator", "kepler"] {
            for tol in [1e-1, 1e-2, 1e-3, 3e-3] {
                let original = builtin(name);
                let mut file = original.clone();
                let c = choose(&mut file, tol, &t).unwrap();
                let frame = original.run.dt * original.run.steps_per_frame as f64;
                assert!((c.dt * c.steps_per_frame as f64 - frame).abs() < 1e-12 * frame, "{name} {tol}");
                assert_eq!(file.run.frames, original.run.frames);
                let fam =
                    t.families.iter().find(|f| f.scene.as_deref() == Some(kind_of(&file.scene))).unwrap();
                let row = fam
                    .picks
                    .iter()
                    .filter(|p| p.tolerance <= tol)
                    .max_by(|a, b| a.tolerance.total_cmp(&b.tolerance))
                    .unwrap();
                let dt_table = row.param.unwrap() / time_unit(&file.scene);
                assert!(c.dt <= dt_table * (1.0 + 1e-12), "{name} {tol}: {} > {dt_table}", c.dt);
                assert_eq!(c.integrator.label(), row.method.clone().unwrap());
                assert!(
                    c.why.starts_with(&format!(
                        "cheapest measured method with error <= {:e}: {}",
                        row.tolerance,
                        c.integrator.label()
                    )),
                    "{}",
                    c.why
                );
            }
        }
    }

    #[test]
    fn the_table_error_is_zero_on_the_exact_solution() {
        // Independent of the runner: the exact state at t gives zero, a shifted one its shift.
        let osc = builtin("oscillator");
        let Scene::HarmonicOscillator { mass, stiffness, damping, x0, v0, .. } = osc.scene else { panic!() };
        let (xe, ve) = HarmonicOscillator::damped(mass, stiffness, damping).exact(x0, v0, 0.7);
        let mut s = State::new(vec![xe], vec![ve]);
        s.t = 0.7;
        assert_eq!(table_error(&osc.scene, &s), Some(0.0));
        s.x[0] += 1e-3;
        let e = table_error(&osc.scene, &s).unwrap();
        assert!((e - 1e-3 / x0.hypot(v0 / (stiffness / mass).sqrt())).abs() < 1e-15);
        let kep = builtin("kepler");
        let (xe, ve) = KeplerOrbit::ellipse(0.5).exact(1.3);
        let mut s = State::new(xe.to_vec(), ve.to_vec());
        s.t = 1.3;
        assert_eq!(table_error(&kep.scene, &s), Some(0.0));
    }
}
