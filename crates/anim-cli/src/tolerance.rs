//! `anim run SCENE --tolerance TOL`: the scene states the accuracy it needs instead of a method,
//! and the method comes from the measured work-precision studies of the workspace report
//! (`docs/report/cheapest.json`, written by `cargo xtask report`, embedded in the binary at build
//! time so that no repository is needed at run time). The table holds every measured point of
//! every method; the picker keeps the methods the scene can run without changing its physics,
//! and among their points with an error at most `TOL` takes the cheapest on the scene.
//!
//! Mapped scenes (the study runs the same problem, or one whose settings transfer):
//!
//! | scene | study | what is picked | kept (physics) | the run's error on the study's measure |
//! | --- | --- | --- | --- | --- |
//! | `harmonic-oscillator` | `core-oscillator` (`m = k = 1`, 10.3 periods) | integrator, `dt` (in units of `1/omega`) | everything else | `|(x - x_e, (v - v_e)/omega)| / |(x0, v0/omega)|` against the exact solution |
//! | `kepler-orbit` | `core-kepler` (`e = 0.5`, 1.3 orbits, `a = mu = 1`) | integrator, `dt` | everything else | `|x - x_e|` against Kepler's equation |
//! | `fem`, preset `cantilever-beam` | `fem-beam` (the same beam with E = 1 MPa, 2 cells across, 0.5 s) | integrator, Newton's linear solver, `dt` | the preset's material model (stable Neo-Hookean): only that model's series are candidates | not measured (no reference trajectory in the scene) |
//! | `springs`, preset `hanging-cloth` | `springs-cloth` (a 0.5 m cloth, 6 x 6 or 10 x 10, 100 N/m, 0.25 s) | explicit integrator, `dt` | the network; implicit methods are left out (the scene takes one linearised Newton iteration per step, the study converged Newton to 1e-10) | not measured (no reference trajectory in the scene) |
//! | `fluid`, preset `lid-driven-cavity` | `fluid_cavity_ghia` (the same preset at Re = 100 to steady state) | resolution `N`, pressure solver (at the study's pressure tolerance), `dt <= 1/N` | Re, walls, advection | max error of the final velocity against Ghia et al. (1982) |
//! | `fluid`, preset `smoke-plume-3d` | `fluid_pressure_divergence` (a 2D box with a sphere) | pressure solver and its tolerance, from the series measured at the grid size nearest the scene's | the grid and everything else | the largest relative pressure residual of the run's projections |
//! | `pbd`, preset `hanging-cloth` | `pbd-cloth-position` (the same cloth, 8 x 8 or 14 x 14, 0.5 s at dt = 1/60) | method (PBD or XPBD), iterations and substeps, `dt <= 1/60` | the cloth | not measured (the study's reference is a converged XPBD run, not part of the scene) |
//! | `mpm`, preset `dam-break-2d` | `mpm_dam_break` (the same dam break) | resolution, transfer (APIC or MLS-MPM), kernel (quadratic or cubic), particles per cell, `dt = h / 100` | the water, the tank | rms relative surge-front error against Martin & Moyce (1952) at the table's times the run passed |
//!
//! Transfers between a study's problem and a scene's:
//!
//! - A scene that runs longer (`T`) than the study's horizon `H` gets a smaller step: the error of
//!   an order-`p` method grows at most like `T^2 dt^p` over a time `T` (linearly for the
//!   symplectic ones, quadratically when the energy drifts), so `dt` is scaled by
//!   `(H / T)^(2/p)` (the FEM integrators are first order).
//! - The oscillator's times are in units of `1/omega`.
//! - The FEM beam's step is scaled by the ratio of wave speeds `sqrt(E/rho)` (study over scene:
//!   every frequency of the same geometry scales with it) and by the ratio of cell sizes when the
//!   scene's cells are smaller (the explicit stability limit and the highest resolved mode scale
//!   with the cell).
//! - The cloth's step is scaled by the ratio of the highest spring frequencies estimated as
//!   `sqrt(k_max N / M)` (stiffest spring, particle count, total mass) when the scene's is higher.
//! - The PBD cloth's iteration or substep count is scaled by the ratio of cloth sides (particles
//!   per side, scene over study) when the scene's cloth is finer: a Gauss-Seidel sweep carries a
//!   correction one constraint further per iteration or substep, so crossing the cloth takes
//!   counts in proportion to its side. A run longer than the study's horizon multiplies the
//!   substeps by `(T/H)^2` (the first-order bound above, the substep being the step); the series
//!   that sweep iterations at one substep are then left out (no step to shrink).
//!
//! Candidates are ranked by the study's wall time per run times the number of scene steps per
//! study step (the steps' count differs between methods when the transfer scales their `dt`
//! differently). The run keeps the scene's frame times: each frame takes `ceil(frame / dt)`
//! steps.
//!
//! The mapping of each scene kind lives in its crate: a kind's optional
//! [`tolerance`](anim_core::scene::SceneKind::tolerance) field
//! ([`Tolerance`](anim_core::scene::study::Tolerance)) turns each measured point into the
//! scene's settings, step and cost, and measures a run on the study's error; this module only
//! finds the study, ranks the candidates and fits the step into the frames.
//!
//! Not mapped: the other presets (their problems are not a study's), and the `pbd-cloth-constraint`
//! study (the same cloth and methods as `pbd-cloth-position`, measured on the mean stretch; the
//! picker reads the position study). Those scenes get an error naming the mapped ones.

use crate::scene::{SceneFile, SceneSpec};
use anim_core::scene::DynScene;
use anim_core::scene::study::Candidate;
pub use anim_core::scene::study::{FORMAT, Family, Machine, Point, Series, Table, parse_table};

/// The report's table, embedded at build time.
pub const TABLE: &str = include_str!("../cheapest.json");

/// What `--tolerance` did to a scene.
#[derive(Debug, Clone, PartialEq)]
pub struct Choice {
    /// The study's label of the method picked.
    pub method: String,
    /// The study's swept parameter at the picked point.
    pub param: f64,
    /// The settings the scene now runs, in scene-file terms.
    pub settings: String,
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
/// A message if the embedded text is not a valid table of this format (a build from a broken or
/// older report).
pub fn table() -> Result<Table, String> {
    parse_table(TABLE)
}

/// The family for a scene of `kind` and `preset`: the one naming its `KIND/PRESET`, else its
/// `KIND`.
fn family_of<'a>(table: &'a Table, kind: &str, preset: Option<&str>) -> Option<&'a Family> {
    let full = preset.map(|p| format!("{kind}/{p}"));
    table
        .families
        .iter()
        .find(|f| f.scene.is_some() && f.scene == full)
        .or_else(|| table.families.iter().find(|f| f.scene.as_deref() == Some(kind)))
}

/// Sets the method (and where the study sweeps it, the step or resolution) of `file` to meet
/// `tol` on the study's error, from `table`.
///
/// # Errors
/// A message when `tol` is not a positive finite number, when the scene has no table entry
/// (listing those that have one), or when no measured method the scene can run meets `tol`
/// (naming the most accurate one measured).
pub fn choose(file: &mut SceneFile, tol: f64, table: &Table) -> Result<Choice, String> {
    if !(tol > 0.0 && tol.is_finite()) {
        return Err(format!("--tolerance must be a positive finite number, got {tol}"));
    }
    let kind = file.scene.kind.clone();
    let preset = file.scene.params.get("preset").and_then(|p| p.as_str()).map(str::to_string);
    let preset = preset.as_deref();
    let Some(family) = family_of(table, &kind, preset) else {
        let names: Vec<String> = table
            .families
            .iter()
            .filter_map(|f| f.scene.as_ref().map(|s| format!("{s} (study {})", f.study)))
            .collect();
        return Err(format!(
            "--tolerance: the report's cheapest-method table has no entry for {}{} scenes ({}); \
             scenes with one: {}",
            kind,
            preset.map(|p| format!("/{p}")).unwrap_or_default(),
            file.name,
            names.join(", ")
        ));
    };
    let Some(tolerance) = anim::kind(&kind).and_then(|k| k.tolerance) else {
        return Err(format!("--tolerance: the {} study has no mapping to this scene", family.study));
    };
    let params = serde_json::Value::Object(file.scene.params.clone());
    // An adapter's message about the file's own settings does not name the file: put it first.
    let adapter = (tolerance.adapter)(&params, &file.run, family).map_err(|e| {
        if e.starts_with("--tolerance") { e } else { format!("--tolerance: {} {e}", file.name) }
    })?;
    let mut best: Option<(f64, &str, Point, Candidate)> = None;
    let mut closest: Option<(&str, Point)> = None;
    // Methods the scene cannot run, grouped by the reason.
    let mut refused: Vec<(String, Vec<&str>)> = Vec::new();
    for series in &family.series {
        for point in &series.points {
            if !(point.error.is_finite() && point.seconds.is_finite()) {
                continue;
            }
            match adapter.candidate(&series.method, point) {
                Err(why) => match refused.iter_mut().find(|(w, _)| *w == why) {
                    Some((_, methods)) => {
                        if !methods.contains(&series.method.as_str()) {
                            methods.push(&series.method);
                        }
                    }
                    None => refused.push((why, vec![&series.method])),
                },
                Ok(c) => {
                    if closest.is_none_or(|(_, p)| point.error < p.error) {
                        closest = Some((&series.method, *point));
                    }
                    let cost = point.seconds * c.cost;
                    if point.error <= tol && best.as_ref().is_none_or(|b| cost < b.0) {
                        best = Some((cost, &series.method, *point, c));
                    }
                }
            }
        }
    }
    let refused: Vec<String> =
        refused.into_iter().map(|(why, methods)| format!("{} ({why})", methods.join(", "))).collect();
    let Some((_, method, point, candidate)) = best else {
        return Err(match closest {
            Some((m, p)) => format!(
                "--tolerance {tol:e}: no method of the {} study that this scene can run met it; the most \
                 accurate measured is {m} at {} = {}, error {:.3e} (ask for {:.1e} or more){}",
                family.study,
                family.param,
                short(p.param),
                p.error,
                round_up(p.error),
                if refused.is_empty() {
                    String::new()
                } else {
                    format!("; left out: {}", refused.join("; "))
                }
            ),
            None => format!(
                "--tolerance: no method of the {} study can run on this scene: {}",
                family.study,
                refused.join("; ")
            ),
        });
    };
    let frame = file.run.dt * file.run.steps_per_frame as f64;
    let (dt_run, steps_per_frame) = match candidate.dt {
        Some(dt) => {
            let steps = (frame / dt * (1.0 - 1e-12)).ceil().max(1.0) as usize;
            (frame / steps as f64, steps)
        }
        None => (file.run.dt, file.run.steps_per_frame),
    };
    let settings = candidate.summary;
    file.scene.params.extend(candidate.settings);
    file.run.dt = dt_run;
    file.run.steps_per_frame = steps_per_frame;
    let scaled = match candidate.dt {
        Some(dt) if candidate.dt_swept && (dt - point.param).abs() > 1e-12 * dt => {
            format!("; on this scene that is dt = {dt:.4e} s ({})", candidate.note)
        }
        _ if !candidate.dt_swept && !candidate.note.is_empty() => {
            format!("; on this scene that is {}", candidate.note)
        }
        _ => String::new(),
    };
    let left_out = if refused.is_empty() {
        String::new()
    } else {
        format!("; left out as not this scene's: {}", refused.join("; "))
    };
    let why = format!(
        "cheapest measured method with error <= {tol:e} that this scene can run: {method} at {} = {} in the {} \
         study, error {:.2e}, {} per run (report of {}, {} mode, {}, {} cores){scaled}{left_out}; running {settings} \
         with {steps_per_frame} step{} of {dt_run:.4e} s per frame",
        family.param,
        short(point.param),
        family.study,
        point.error,
        wall(point.seconds),
        table.date,
        table.mode,
        table.machine.cpu,
        table.machine.cores,
        if steps_per_frame == 1 { "" } else { "s" },
    );
    Ok(Choice { method: method.to_string(), param: point.param, settings, dt: dt_run, steps_per_frame, why })
}

/// `x` rounded up to two significant digits (a tolerance, as typed, that admits it).
fn round_up(x: f64) -> f64 {
    let exponent = x.log10().floor();
    let mantissa = x / 10f64.powf(exponent);
    let mut tenths = (mantissa * 10.0 * (1.0 - 1e-12)).ceil();
    loop {
        let typed: f64 = format!("{}e{exponent}", tenths / 10.0).parse().unwrap_or(f64::INFINITY);
        if typed >= x {
            return typed;
        }
        tenths += 1.0;
    }
}

fn short(x: f64) -> String {
    if x != 0.0 && (x.abs() < 1e-3 || x.abs() >= 1e5) {
        return format!("{x:.3e}");
    }
    let s = format!("{x:.6}");
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

/// The run's error on the measure of the study the scene was picked from (`None` for scenes
/// without a reference in the run): the kind's
/// [`Tolerance::error`](anim_core::scene::study::Tolerance::error) where it maps a study (the
/// exact solution of the ODE scenes, for the smoke plume `max_residual`, the largest relative
/// pressure residual of the run's steps so far), the scene's own reference error otherwise
/// (Ghia's velocities for the cavity; for the MPM dam break the rms relative surge-front error
/// against Martin & Moyce at the table's times the run has passed).
#[must_use]
pub fn table_error(spec: &SceneSpec, runner: &dyn DynScene, max_residual: Option<f64>) -> Option<f64> {
    match anim::kind(&spec.kind).and_then(|k| k.tolerance) {
        Some(t) => (t.error)(&serde_json::Value::Object(spec.params.clone()), runner, max_residual),
        None => runner.reference_error(),
    }
}

#[cfg(test)]
mod tests;
