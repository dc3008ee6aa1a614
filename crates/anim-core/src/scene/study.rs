//! The report's measured work-precision table (`docs/report/cheapest.json`, written by
//! `cargo xtask report`) and what a scene kind provides so that `anim run SCENE --tolerance TOL`
//! can pick a method from it: a [`Tolerance`] in its [`SceneKind`](super::SceneKind), whose
//! adapter says what each measured point means on a scene of the kind (the parameters to set, the
//! step, the cost) and whose error measures a run on the study's measure.
//!
//! The picker itself (find the study of a scene, rank the candidates, fit the step into the
//! frames) is the command line's; a kind only maps its own parameters.

use super::dynamic::DynScene;
use super::preset::RunDefaults;
use std::collections::BTreeMap;

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

/// A measured point the scene can run, and what running it there takes.
#[derive(Debug, Clone, PartialEq)]
pub struct Candidate {
    /// Scene-file parameters to set (merged into the `[scene]` table).
    pub settings: serde_json::Map<String, serde_json::Value>,
    /// The settings in scene-file terms (`"integrator = rk4"`).
    pub summary: String,
    /// The scene's step (before fitting it into the frames); `None`: the scene's own.
    pub dt: Option<f64>,
    /// Scene steps per study step (ranks candidates with their study wall time).
    pub cost: f64,
    /// Whether the study's parameter is the step (`dt` is then the transferred one).
    pub dt_swept: bool,
    /// How the study's step was scaled for the scene (empty: not scaled).
    pub note: String,
}

/// What a measured method means on one scene.
pub trait StudyAdapter {
    /// The candidate of `method` at `point`, or why the scene cannot run it.
    ///
    /// # Errors
    /// Why the scene cannot run the method (another material, an implicit method, a count out
    /// of range, a label this build does not know).
    fn candidate(&self, method: &str, point: &Point) -> Result<Candidate, String>;
}

/// The adapter of a kind: the scene's parameters, its run and the study in, an adapter out.
pub type AdapterFn = fn(
    params: &serde_json::Value,
    run: &RunDefaults,
    family: &Family,
) -> Result<Box<dyn StudyAdapter>, String>;

/// The error of a run on the study's measure: the scene's parameters, the scene as run so far
/// and the largest relative pressure residual of its steps (where the run measures one).
pub type ErrorFn =
    fn(params: &serde_json::Value, scene: &dyn DynScene, max_residual: Option<f64>) -> Option<f64>;

/// How a kind maps the report's studies for `--tolerance`.
#[derive(Debug, Clone, Copy)]
pub struct Tolerance {
    /// The adapter of a scene of the kind to the study of `family` (an error when the scene's
    /// parameters cannot be read or the study does not map to this scene).
    pub adapter: AdapterFn,
    /// The run's error on the study's measure (`None`: not measured in the run).
    pub error: ErrorFn,
}

/// `(H / T)^(2/p)` when the run (`duration`) is longer than the study's horizon `H`, else 1:
/// the error of an order-`p` method grows at most like `T^2 dt^p` over a time `T`.
#[must_use]
pub fn horizon_factor(horizon: f64, duration: f64, order: u32) -> f64 {
    if duration > horizon { (horizon / duration).powf(2.0 / f64::from(order.max(1))) } else { 1.0 }
}

/// The study problem's parameter `key`, positive and finite.
///
/// # Errors
/// A message naming the study when the entry has no such parameter.
pub fn problem(family: &Family, key: &str) -> Result<f64, String> {
    family.problem.get(key).copied().filter(|v| v.is_finite() && *v > 0.0).ok_or_else(|| {
        format!("--tolerance: the {} study's entry has no problem parameter `{key}`", family.study)
    })
}

/// The study's horizon, positive and finite.
///
/// # Errors
/// A message naming the study when the entry has none.
pub fn horizon(family: &Family) -> Result<f64, String> {
    family
        .horizon
        .filter(|h| h.is_finite() && *h > 0.0)
        .ok_or_else(|| format!("--tolerance: the {} study's entry has no horizon", family.study))
}

/// The simulated time of a run.
#[must_use]
pub fn duration(run: &RunDefaults) -> f64 {
    run.dt * (run.steps_per_frame * run.frames) as f64
}

/// The message of a scene whose parameters cannot be read.
#[must_use]
pub fn unreadable(e: impl std::fmt::Display) -> String {
    format!("--tolerance: cannot build the scene to read its parameters: {e}")
}

/// The message of a study that does not map to the scene.
#[must_use]
pub fn unmapped(family: &Family) -> String {
    format!("--tolerance: the {} study has no mapping to this scene", family.study)
}

/// The message of a method label the adapter does not know.
#[must_use]
pub fn unknown_method(method: &str) -> String {
    format!("`{method}` is not a method this build knows")
}

/// A test family built by hand: one study of `scene` with the given problem and series.
#[doc(hidden)]
#[must_use]
pub fn family(
    study: &str,
    scene: &str,
    horizon: Option<f64>,
    problem: &[(&str, f64)],
    series: &[(&str, Vec<Point>)],
) -> Family {
    Family {
        study: study.into(),
        scene: Some(scene.into()),
        horizon,
        error: "e".into(),
        param: "p".into(),
        problem: problem.iter().map(|(k, v)| ((*k).to_string(), *v)).collect(),
        series: series.iter().map(|(m, p)| Series { method: (*m).into(), points: p.clone() }).collect(),
    }
}

/// The error of a kind whose studies measure the scene's own reference error
/// ([`DynScene::reference_error`]; `None` when the scene has none).
#[must_use]
pub fn reference_error(_: &serde_json::Value, scene: &dyn DynScene, _: Option<f64>) -> Option<f64> {
    scene.reference_error()
}
