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
//! Not mapped: the other presets (their problems are not a study's), and the `pbd-cloth-constraint`
//! study (the same cloth and methods as `pbd-cloth-position`, measured on the mean stretch; the
//! picker reads the position study). Those scenes get an error naming the mapped ones.

use crate::scene::{SceneFile, SceneSpec};
use anim_core::integrate::systems::{HarmonicOscillator, KeplerOrbit};
use anim_core::integrate::{IntegratorKind, State};
use anim_core::scene::{DynScene, Frame, RunDefaults};
use anim_fem::material::MaterialModel;
use anim_fem::sim::{LinearSolverChoice, TimeIntegrator};
use anim_fluid::pressure::PressureMethod;
use std::collections::BTreeMap;
use typed::{MpmKernel, MpmTransfer, PressureSolver, Scene};

/// The report's table, embedded at build time.
pub const TABLE: &str = include_str!("../../../docs/report/cheapest.json");

/// The version of `cheapest.json` this build reads.
pub const FORMAT: u32 = 2;

/// The parts of `cheapest.json` the picker reads.
#[derive(Debug, Clone, serde::Deserialize)]
pub struct Table {
    /// Format version ([`FORMAT`]).
    pub format: u32,
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

/// One study.
#[derive(Debug, Clone, serde::Deserialize)]
pub struct Family {
    /// The study's name in the report.
    pub study: String,
    /// The scene the study's problem is: `KIND` or `KIND/PRESET` (`None`: no scene).
    pub scene: Option<String>,
    /// Simulated time the study measured over (`None`: not a trajectory's error).
    pub horizon: Option<f64>,
    /// What the error measures.
    pub error: String,
    /// What the swept parameter is.
    pub param: String,
    /// The study problem's parameters the transfer scales by.
    #[serde(default)]
    pub problem: BTreeMap<String, f64>,
    /// Every measured point, per method.
    pub series: Vec<Series>,
}

/// One method's measured points.
#[derive(Debug, Clone, serde::Deserialize)]
pub struct Series {
    /// The method label.
    pub method: String,
    /// Its points.
    pub points: Vec<Point>,
}

/// One measured point.
#[derive(Debug, Clone, Copy, serde::Deserialize)]
pub struct Point {
    /// The swept parameter (`dt`, resolution, pressure tolerance).
    pub param: f64,
    /// Wall time of one run of the study's problem, seconds.
    pub seconds: f64,
    /// The study's error.
    pub error: f64,
}

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

/// A table from the text of a `cheapest.json`.
///
/// # Errors
/// A message if `text` is not a valid table of this format.
pub fn parse_table(text: &str) -> Result<Table, String> {
    let t: Table = serde_json::from_str(text)
        .map_err(|e| format!("the embedded docs/report/cheapest.json is not valid: {e}"))?;
    if t.format != FORMAT {
        return Err(format!(
            "the embedded docs/report/cheapest.json has format {}, this build reads {FORMAT}",
            t.format
        ));
    }
    Ok(t)
}

/// The integrator a table label names.
#[must_use]
pub fn integrator(label: &str) -> Option<IntegratorKind> {
    IntegratorKind::ALL.into_iter().find(|k| k.label() == label)
}

/// A label of the FEM beam study: `"<model> symplectic-euler"` or
/// `"<model> backward-euler (<solver>)"` (names of [`MaterialModel::name`],
/// [`TimeIntegrator::name`], [`LinearSolverChoice::name`]); reports from before the solver sweep
/// wrote `"<model> backward-euler"`, the default solver (`None` here; Cholesky).
#[must_use]
pub fn fem_label(label: &str) -> Option<(MaterialModel, TimeIntegrator, Option<LinearSolverChoice>)> {
    let (model, rest) = label.split_once(' ')?;
    let model = MaterialModel::ALL.into_iter().find(|m| m.name() == model)?;
    let explicit = TimeIntegrator::SymplecticEuler;
    if rest == explicit.name() {
        return Some((model, explicit, None));
    }
    let implicit = TimeIntegrator::BackwardEuler;
    let rest = rest.strip_prefix(implicit.name())?;
    if rest.is_empty() {
        return Some((model, implicit, None));
    }
    let solver = rest.strip_prefix(" (")?.strip_suffix(')')?;
    let solver = LinearSolverChoice::ALL.into_iter().find(|s| s.name() == solver)?;
    Some((model, implicit, Some(solver)))
}

/// A label of the PBD cloth studies: `"<Pbd|Xpbd> substeps (1 iteration)"` (`true`: substeps
/// swept) or `"<Pbd|Xpbd> iterations (1 substep)"` (`false`).
#[must_use]
pub fn pbd_label(label: &str) -> Option<(anim_pbd::Method, bool)> {
    let (method, rest) = label.split_once(' ')?;
    let method =
        [anim_pbd::Method::Pbd, anim_pbd::Method::Xpbd].into_iter().find(|m| format!("{m:?}") == method)?;
    match rest {
        "substeps (1 iteration)" => Some((method, true)),
        "iterations (1 substep)" => Some((method, false)),
        _ => None,
    }
}

/// A label of the MPM dam-break study: `"<MLS-MPM|APIC> <quadratic|cubic>, <k>x<k> ppc"`.
#[must_use]
pub fn mpm_label(label: &str) -> Option<(MpmTransfer, MpmKernel, usize)> {
    let (method, ppc) = label.split_once(", ")?;
    let (transfer, kernel) = method.split_once(' ')?;
    let transfer = match transfer {
        "MLS-MPM" => MpmTransfer::MlsMpm,
        "APIC" => MpmTransfer::Apic,
        _ => return None,
    };
    let kernel = [MpmKernel::Quadratic, MpmKernel::Cubic].into_iter().find(|k| k.name() == kernel)?;
    let (a, b) = ppc.strip_suffix(" ppc")?.split_once('x')?;
    let k: usize = a.parse().ok()?;
    (b.parse::<usize>().ok()? == k).then_some((transfer, kernel, k))
}

/// A label of the pressure study: `"<solver> N=<n>"`.
#[must_use]
pub fn pressure_label(label: &str) -> Option<(PressureMethod, usize)> {
    let (name, n) = label.split_once(" N=")?;
    Some((PressureSolver::by_name(name)?.0, n.parse().ok()?))
}

/// The scene's kind as scene files spell it, and its preset if it has one.
fn kind_of(scene: &Scene) -> (&'static str, Option<&str>) {
    match scene {
        Scene::HarmonicOscillator { .. } => ("harmonic-oscillator", None),
        Scene::KeplerOrbit { .. } => ("kepler-orbit", None),
        Scene::Skinning { preset, .. } => ("skinning", preset.as_deref()),
        Scene::Rigid { preset } => ("rigid", Some(preset.as_str())),
        Scene::Pbd { preset, .. } => ("pbd", Some(preset.as_str())),
        Scene::Fem { preset, .. } => ("fem", Some(preset.as_str())),
        Scene::Mpm { preset, .. } => ("mpm", Some(preset.as_str())),
        Scene::Fluid { preset, .. } => ("fluid", Some(preset.as_str())),
        Scene::Springs { preset, .. } => ("springs", Some(preset.as_str())),
        Scene::Flip { preset, .. } => ("flip", Some(preset.as_str())),
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

/// `(H / T)^(2/p)` when the run is longer than the study's horizon, else 1.
fn horizon_factor(horizon: f64, duration: f64, order: u32) -> f64 {
    if duration > horizon { (horizon / duration).powf(2.0 / f64::from(order.max(1))) } else { 1.0 }
}

/// Settings a measured method gives the scene.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Settings {
    /// An ODE scene's integrator.
    Integrator(IntegratorKind),
    /// The FEM scene's integrator and Newton solver.
    Fem(TimeIntegrator, LinearSolverChoice),
    /// A spring scene's (explicit) integrator.
    Springs(IntegratorKind),
    /// A MAC fluid scene's resolution (if picked), pressure solver and tolerance.
    Fluid(Option<usize>, PressureMethod, f64),
    /// A PBD scene's method, iterations and substeps.
    Pbd(anim_pbd::Method, usize, usize),
    /// An MPM scene's resolution, transfer, kernel and particles per cell.
    Mpm(usize, MpmTransfer, MpmKernel, usize),
}

/// A measured point the scene can run, and what running it there takes.
#[derive(Debug, Clone)]
struct Candidate {
    settings: Settings,
    /// The scene's step (before fitting it into the frames); `None`: the scene's own.
    dt: Option<f64>,
    /// Scene steps per study step (ranks candidates with their study wall time).
    cost: f64,
    /// Whether the study's parameter is the step (`dt` is then the transferred one).
    dt_swept: bool,
    /// How the study's step was scaled for the scene.
    note: String,
}

/// What the picker knows about the scene, per mapped family.
enum Adapter {
    Ode { unit: f64, horizon: f64, duration: f64 },
    Fem { model: MaterialModel, scale: f64, horizon: f64, duration: f64 },
    Springs { scale: f64, horizon: f64, duration: f64 },
    Cavity { pressure_tolerance: f64 },
    Pressure { n: usize, nearest: usize },
    Pbd { scale: f64, study_dt: f64, horizon: f64, duration: f64 },
    DamBreak,
}

fn problem(family: &Family, key: &str) -> Result<f64, String> {
    family.problem.get(key).copied().filter(|v| v.is_finite() && *v > 0.0).ok_or_else(|| {
        format!("--tolerance: the {} study's entry has no problem parameter `{key}`", family.study)
    })
}

fn horizon(family: &Family) -> Result<f64, String> {
    family
        .horizon
        .filter(|h| h.is_finite() && *h > 0.0)
        .ok_or_else(|| format!("--tolerance: the {} study's entry has no horizon", family.study))
}

impl Adapter {
    fn new(run: &RunDefaults, scene: &Scene, family: &Family) -> Result<Self, String> {
        let duration = run.dt * (run.steps_per_frame * run.frames) as f64;
        let build = |e: String| format!("--tolerance: cannot build the scene to read its parameters: {e}");
        Ok(match scene {
            Scene::HarmonicOscillator { .. } | Scene::KeplerOrbit { .. } => {
                Adapter::Ode { unit: time_unit(scene), horizon: horizon(family)?, duration }
            }
            Scene::Fem { preset, resolution, .. } => {
                let scene = anim_fem::scenes::by_name(preset, *resolution)
                    .ok_or_else(|| format!("--tolerance: unknown fem preset `{preset}`"))?
                    .map_err(|e| build(e.to_string()))?;
                let material = *scene.model.material();
                let mesh = scene.model.mesh();
                let cell = mesh
                    .tets
                    .iter()
                    .flat_map(|t| {
                        let p = |i: usize| anim_core::glam::DVec3::from_array(mesh.positions[t[i]]);
                        [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)].map(|(a, b)| p(a).distance(p(b)))
                    })
                    .fold(f64::INFINITY, f64::min);
                let speed = |young: f64, density: f64| (young / density).sqrt();
                let ratio = speed(problem(family, "young")?, problem(family, "density")?)
                    / speed(material.lame.young(), material.density);
                let scale = ratio * (cell / problem(family, "cell")?).min(1.0);
                Adapter::Fem { model: material.model, scale, horizon: horizon(family)?, duration }
            }
            Scene::Springs { preset, resolution, .. } => {
                let scene = anim_springs::scenes::by_name(preset, *resolution)
                    .ok_or_else(|| format!("--tolerance: unknown springs preset `{preset}`"))?
                    .map_err(|e| build(e.to_string()))?;
                let net = &scene.network;
                let k = net.springs().iter().map(|s| s.stiffness).fold(0.0, f64::max);
                let count = (scene.state.x.len() / 3) as f64;
                let omega_scene = (k * count / net.total_mass()).sqrt();
                let n = problem(family, "n")?;
                let omega_study = (problem(family, "stiffness")? * n * n / problem(family, "mass")?).sqrt();
                Adapter::Springs {
                    scale: (omega_study / omega_scene).min(1.0),
                    horizon: horizon(family)?,
                    duration,
                }
            }
            Scene::Fluid { preset, .. } if preset.as_str() == "lid-driven-cavity" => {
                Adapter::Cavity { pressure_tolerance: problem(family, "pressure_tolerance")? }
            }
            Scene::Fluid { preset, resolution, .. } => {
                let scene = anim_fluid::scenes::by_name(preset, *resolution)
                    .ok_or_else(|| format!("--tolerance: unknown fluid preset `{preset}`"))?
                    .map_err(|e| build(e.to_string()))?;
                let n = scene.dims().into_iter().max().unwrap_or(1);
                let sizes: Vec<usize> =
                    family.series.iter().filter_map(|s| pressure_label(&s.method).map(|(_, n)| n)).collect();
                let nearest = sizes
                    .iter()
                    .copied()
                    .min_by(|a, b| {
                        let d = |m: usize| (m as f64 / n as f64).ln().abs();
                        d(*a).total_cmp(&d(*b)).then(a.cmp(b))
                    })
                    .ok_or_else(|| {
                        format!("--tolerance: the {} study measured no grid size", family.study)
                    })?;
                Adapter::Pressure { n, nearest }
            }
            Scene::Pbd { preset, resolution, .. } => {
                let scene = anim_pbd::scenes::by_name(preset, *resolution)
                    .ok_or_else(|| format!("--tolerance: unknown pbd preset `{preset}`"))?
                    .map_err(|e| build(e.to_string()))?;
                // The cloth's side in particles (the scene and the study's cloths are square).
                let side = ((scene.state.x.len() / 3) as f64).sqrt();
                Adapter::Pbd {
                    scale: (side / problem(family, "n")?).max(1.0),
                    study_dt: problem(family, "dt")?,
                    horizon: horizon(family)?,
                    duration,
                }
            }
            Scene::Mpm { preset, .. } if preset.as_str() == "dam-break-2d" => Adapter::DamBreak,
            _ => return Err(format!("--tolerance: the {} study has no mapping to this scene", family.study)),
        })
    }

    /// The candidate of `method` at `point`, or why the scene cannot run it.
    fn candidate(&self, method: &str, point: &Point) -> Result<Candidate, String> {
        let unknown = || format!("`{method}` is not a method this build knows");
        match *self {
            Adapter::Ode { unit, horizon, duration } => {
                let kind = integrator(method).ok_or_else(unknown)?;
                let factor = horizon_factor(horizon / unit, duration, kind.order());
                let mut note = Vec::new();
                if unit != 1.0 {
                    note.push(format!("1/omega = {:.4}", 1.0 / unit));
                }
                if factor != 1.0 {
                    note.push(format!("run length (H/T)^(2/p) = {factor:.4}"));
                }
                Ok(Candidate {
                    settings: Settings::Integrator(kind),
                    dt: Some(point.param / unit * factor),
                    cost: 1.0 / factor,
                    dt_swept: true,
                    note: note.join(" x "),
                })
            }
            Adapter::Fem { model, scale, horizon, duration } => {
                let (m, integrator, solver) = fem_label(method).ok_or_else(unknown)?;
                if m != model {
                    return Err(format!("{} material (the scene's is {})", m.name(), model.name()));
                }
                let length = horizon_factor(horizon, duration, 1);
                let factor = scale * length;
                let solver = solver.unwrap_or(LinearSolverChoice::Cholesky);
                Ok(Candidate {
                    settings: Settings::Fem(integrator, solver),
                    dt: Some(point.param * factor),
                    cost: 1.0 / factor,
                    dt_swept: true,
                    note: format!("wave speed and cell ratios {scale:.4} x run length (H/T)^2 = {length:.4}"),
                })
            }
            Adapter::Springs { scale, horizon, duration } => {
                if method.contains(" / ") {
                    return Err("implicit (the scene takes one linearised Newton iteration per step, the study converged Newton)".into());
                }
                let kind = integrator(method).ok_or_else(unknown)?;
                let length = horizon_factor(horizon, duration, kind.order());
                let factor = scale * length;
                Ok(Candidate {
                    settings: Settings::Springs(kind),
                    dt: Some(point.param * factor),
                    cost: 1.0 / factor,
                    dt_swept: true,
                    note: format!("spring frequency ratio {scale:.4} x run length (H/T)^(2/p) = {length:.4}"),
                })
            }
            Adapter::Cavity { pressure_tolerance } => {
                let solver = PressureSolver::by_name(method).ok_or_else(unknown)?.0;
                let n = point.param.round();
                if !(2.0..=2048.0).contains(&n) {
                    return Err(format!("resolution {n} out of range"));
                }
                let n = n as usize;
                Ok(Candidate {
                    settings: Settings::Fluid(Some(n), solver, pressure_tolerance),
                    dt: Some(1.0 / n as f64),
                    cost: 1.0,
                    dt_swept: false,
                    note: String::new(),
                })
            }
            Adapter::Pbd { scale, study_dt, horizon, duration } => {
                let (m, substeps) = pbd_label(method).ok_or_else(unknown)?;
                let k = point.param.round();
                if !(1.0..=1e4).contains(&k) {
                    return Err(format!("count {k} out of range"));
                }
                let length = horizon_factor(horizon, duration, 1);
                let (iterations, substeps, note) = if substeps {
                    let count = (k * scale / length * (1.0 - 1e-12)).ceil();
                    let note = format!(
                        "{count} substeps: cloth side ratio {scale:.4} x run length (H/T)^2 = {length:.4}"
                    );
                    (1.0, count, note)
                } else {
                    if length < 1.0 {
                        return Err(format!(
                            "swept iterations at one substep: the error was measured over the study's {horizon} s and \
                             iterations do not shrink the step, so it does not bound a {duration:.4} s run"
                        ));
                    }
                    let count = (k * scale * (1.0 - 1e-12)).ceil();
                    (count, 1.0, format!("{count} iterations: cloth side ratio {scale:.4}"))
                };
                if iterations.max(substeps) > anim_pbd::kind::MAX_PBD_COUNT as f64 {
                    return Err(format!("{} per step needed on this scene", iterations.max(substeps)));
                }
                Ok(Candidate {
                    settings: Settings::Pbd(m, iterations as usize, substeps as usize),
                    dt: Some(study_dt),
                    cost: iterations * substeps / k,
                    dt_swept: false,
                    note,
                })
            }
            Adapter::DamBreak => {
                let (transfer, kernel, ppc) = mpm_label(method).ok_or_else(unknown)?;
                let n = point.param.round();
                if !(8.0..=4096.0).contains(&n) {
                    return Err(format!("resolution {n} out of range"));
                }
                let n = n as usize;
                Ok(Candidate {
                    settings: Settings::Mpm(n, transfer, kernel, ppc),
                    dt: Some(anim_mpm::scenes::dam_break_2d_dt(n)),
                    cost: 1.0,
                    dt_swept: false,
                    note: String::new(),
                })
            }
            Adapter::Pressure { n, nearest } => {
                let (solver, measured) = pressure_label(method).ok_or_else(unknown)?;
                if measured != nearest {
                    return Err(format!(
                        "measured at N = {measured}; the scene's grid ({n} cells) is nearest N = {nearest}"
                    ));
                }
                Ok(Candidate {
                    settings: Settings::Fluid(None, solver, point.param),
                    dt: None,
                    cost: 1.0,
                    dt_swept: false,
                    note: String::new(),
                })
            }
        }
    }
}

/// The family for `scene`: the one naming its `KIND/PRESET`, else its `KIND`.
fn family_of<'a>(table: &'a Table, scene: &Scene) -> Option<&'a Family> {
    let (kind, preset) = kind_of(scene);
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
    let mut scene = typed::typed(&file.scene).map_err(|e| format!("--tolerance: {}: {e}", file.name))?;
    let Some(family) = family_of(table, &scene) else {
        let (kind, preset) = kind_of(&scene);
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
    if let Scene::Fluid { advection, splitting, .. } = &scene {
        let set: Vec<&str> = [("advection", advection.is_some()), ("splitting", splitting.is_some())]
            .into_iter()
            .filter_map(|(name, on)| on.then_some(name))
            .collect();
        if !set.is_empty() {
            return Err(format!(
                "--tolerance: {} sets `{}`, but the {} study measured the preset's own; remove the field or --tolerance",
                file.name,
                set.join("` and `"),
                family.study
            ));
        }
    }
    let adapter = Adapter::new(&file.run, &scene, family)?;
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
    let settings = apply(&mut scene, candidate.settings)?;
    file.scene = typed::untyped(&scene)?;
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

/// Writes `settings` into the scene; returns them in scene-file terms.
fn apply(scene: &mut Scene, settings: Settings) -> Result<String, String> {
    let mismatch = || "--tolerance: the picked settings do not fit this scene kind".to_string();
    Ok(match (scene, settings) {
        (
            Scene::HarmonicOscillator { integrator, .. } | Scene::KeplerOrbit { integrator, .. },
            Settings::Integrator(kind),
        ) => {
            *integrator = kind;
            format!("integrator = {}", kind.label())
        }
        (Scene::Fem { integrator, linear_solver, .. }, Settings::Fem(i, l)) => {
            *integrator = Some(i);
            *linear_solver = Some(l);
            match i {
                TimeIntegrator::SymplecticEuler => format!("integrator = {}", i.name()),
                TimeIntegrator::BackwardEuler => {
                    format!("integrator = {}, linear_solver = {}", i.name(), l.name())
                }
            }
        }
        (Scene::Springs { integrator, .. }, Settings::Springs(kind)) => {
            *integrator = Some(kind);
            format!("integrator = {}", kind.label())
        }
        (
            Scene::Fluid { resolution, pressure_solver, pressure_tolerance, .. },
            Settings::Fluid(n, solver, tol),
        ) => {
            if let Some(n) = n {
                *resolution = Some(n);
            }
            *pressure_solver = Some(PressureSolver(solver));
            *pressure_tolerance = Some(tol);
            format!(
                "{}pressure_solver = {}, pressure_tolerance = {tol:e}",
                n.map(|n| format!("resolution = {n}, ")).unwrap_or_default(),
                solver.name()
            )
        }
        (Scene::Pbd { method, iterations, substeps, .. }, Settings::Pbd(m, i, k)) => {
            *method = Some(m);
            *iterations = Some(i);
            *substeps = Some(k);
            format!("method = {}, iterations = {i}, substeps = {k}", format!("{m:?}").to_lowercase())
        }
        (
            Scene::Mpm { resolution, transfer, kernel, particles_per_cell, .. },
            Settings::Mpm(n, t, k, ppc),
        ) => {
            *resolution = Some(n);
            *transfer = Some(t);
            *kernel = Some(k);
            *particles_per_cell = Some(ppc);
            format!(
                "resolution = {n}, transfer = {}, kernel = {}, particles_per_cell = {ppc}",
                t.name(),
                k.name()
            )
        }
        _ => return Err(mismatch()),
    })
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
/// without a reference in the run): the exact solution of the ODE scenes, for the smoke plume
/// `max_residual`, the largest relative pressure residual of the run's steps so far, and the
/// scene's own reference error otherwise (Ghia's velocities for the cavity; for the MPM dam
/// break the rms relative surge-front error against Martin & Moyce at the table's times the run
/// has passed).
#[must_use]
pub fn table_error(spec: &SceneSpec, runner: &dyn DynScene, max_residual: Option<f64>) -> Option<f64> {
    let scene = typed::typed(spec).ok()?;
    match &scene {
        Scene::Fluid { preset, .. } if preset.as_str() == "smoke-plume-3d" => max_residual,
        Scene::HarmonicOscillator { .. } | Scene::KeplerOrbit { .. } => {
            let mut frame = Frame::default();
            runner.frame(&mut frame);
            let v = frame.field("velocity").map(|f| f.values.clone()).unwrap_or_default();
            ode_error(&scene, &State { t: frame.time, x: frame.points, v })
        }
        _ => runner.reference_error(),
    }
}

/// The ODE scenes' error against their exact solution (`None` for other scenes).
#[must_use]
pub fn ode_error(scene: &Scene, state: &State) -> Option<f64> {
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
mod tests;
pub mod typed;
