//! `anim.scene`: the scene registry of the `anim` crate ([`anim::CRATES`]) and the scene files
//! of the `anim` command ([`anim_cli::scene`]): list the kinds and presets, build a preset or a
//! scene file, step it, read its frames as arrays, checkpoint and resume it, and pick the
//! cheapest measured method for a tolerance ([`anim_cli::tolerance`], as `anim run --tolerance`).

use crate::arrays;
use crate::errors;
use anim::core::scene::{DynScene, Frame};
use anim_cli::scene::{self as files, SceneError, SceneFile};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use std::path::PathBuf;
use std::sync::Mutex;

/// The checkpoint kind this module writes.
const CHECKPOINT_KIND: &str = "anim-python-scene-1";
/// The checkpoint kind `anim run --checkpoint-every` writes; `Scene.resume` reads it too.
const RUN_CHECKPOINT_KIND: &str = "anim-run-2";

/// A scene-file error as a Python exception: unreadable file `FileNotFoundError`/`OSError`, any
/// other `anim.BuildError` with the message naming the file and field.
fn scene_error(e: SceneError) -> PyErr {
    match &e {
        SceneError::Io { path, source } => errors::file(path, source),
        _ => errors::build(e),
    }
}

/// Every registered scene kind: a list of dicts with `kind`, `crate`, `summary`, `presets`
/// (names) and `tolerance` (whether `tolerance=` can pick its method).
#[pyfunction]
fn kinds(py: Python<'_>) -> PyResult<Bound<'_, PyList>> {
    let list = PyList::empty(py);
    for k in anim::kinds() {
        let d = PyDict::new(py);
        d.set_item("kind", k.kind)?;
        d.set_item("crate", k.crate_name)?;
        d.set_item("summary", k.summary)?;
        let names: Vec<&str> = (k.presets)().iter().map(|p| p.name).collect();
        d.set_item("presets", names)?;
        d.set_item("tolerance", k.tolerance.is_some())?;
        list.append(d)?;
    }
    Ok(list)
}

/// Every preset (the built-in scenes of `anim run`): a list of dicts with `name`, `kind`,
/// `description`, `dt`, `frames`, `steps_per_frame`.
#[pyfunction]
fn presets(py: Python<'_>) -> PyResult<Bound<'_, PyList>> {
    let list = PyList::empty(py);
    for (k, p) in anim::presets() {
        let d = PyDict::new(py);
        d.set_item("name", p.name)?;
        d.set_item("kind", k.kind)?;
        d.set_item("description", p.description)?;
        d.set_item("dt", p.run.dt)?;
        d.set_item("frames", p.run.frames)?;
        d.set_item("steps_per_frame", p.run.steps_per_frame)?;
        list.append(d)?;
    }
    Ok(list)
}

/// A built scene: the scene file it came from and the registered kind's `DynScene`.
#[pyclass(module = "anim.scene")]
pub struct Scene {
    file: SceneFile,
    origin: PathBuf,
    runner: Mutex<Box<dyn DynScene>>,
    choice: Option<anim_cli::tolerance::Choice>,
}

impl Scene {
    /// Applies `set` (parameter overrides), `dt`, `frames` and `tolerance`, then builds.
    fn make(
        mut file: SceneFile,
        origin: PathBuf,
        text: Option<&str>,
        set: Option<&Bound<'_, PyAny>>,
        tolerance: Option<f64>,
    ) -> PyResult<Self> {
        if let Some(set) = set {
            let serde_json::Value::Object(map) = crate::json::of(set, "set")? else {
                return Err(PyValueError::new_err("set: expected a dict of parameter names to values"));
            };
            for (k, v) in map {
                file.scene.params.insert(k, v);
            }
        }
        let choice = match tolerance {
            Some(tol) => {
                if !(tol > 0.0 && tol.is_finite()) {
                    return Err(PyValueError::new_err(format!(
                        "tolerance: must be positive and finite, got {tol}"
                    )));
                }
                let table = anim_cli::tolerance::table().map_err(errors::build)?;
                Some(anim_cli::tolerance::choose(&mut file, tol, &table).map_err(errors::build)?)
            }
            None => None,
        };
        let runner = files::build(&file, &origin, text).map_err(scene_error)?;
        Ok(Self { file, origin, runner: Mutex::new(runner), choice })
    }

    fn runner(&self) -> PyResult<std::sync::MutexGuard<'_, Box<dyn DynScene>>> {
        self.runner.lock().map_err(|_| errors::step("the scene was poisoned by a panic in an earlier step"))
    }
}

/// A frame as a dict of arrays (copies).
fn frame_dict<'py>(py: Python<'py>, frame: &Frame, runner: &dyn DynScene) -> PyResult<Bound<'py, PyDict>> {
    let context = runner.context();
    let d = PyDict::new(py);
    d.set_item("time", frame.time)?;
    let dim = context.point_dim.max(1);
    d.set_item("points", arrays::to_rows(py, &frame.points, dim)?)?;
    let fields = PyDict::new(py);
    // Image scenes: cells x fastest, shaped (ny, nx) or (nz, ny, nx), components last.
    let cells = context
        .image
        .map(|g| if g.dim == 2 { vec![g.dims[1], g.dims[0]] } else { vec![g.dims[2], g.dims[1], g.dims[0]] });
    for f in &frame.fields {
        let c = f.components.max(1);
        let n = f.values.len() / c;
        let mut shape = match &cells {
            Some(s) if s.iter().product::<usize>() == n => s.clone(),
            _ => vec![n],
        };
        if c > 1 {
            shape.push(c);
        }
        fields.set_item(f.name, arrays::to_array(py, &f.values, &shape)?)?;
    }
    d.set_item("fields", fields)?;
    Ok(d)
}

#[pymethods]
impl Scene {
    /// The preset `name` (`anim.scene.presets()`), with parameter overrides `set` (as
    /// `anim run --set KEY=VALUE`) and, with `tolerance`, the cheapest measured method that
    /// reaches it (as `anim run --tolerance`).
    #[staticmethod]
    #[pyo3(signature = (name, *, set = None, tolerance = None))]
    fn preset(name: &str, set: Option<&Bound<'_, PyAny>>, tolerance: Option<f64>) -> PyResult<Self> {
        let file = files::builtin(name).ok_or_else(|| {
            let names: Vec<&str> = files::builtins().iter().map(|b| b.0).collect();
            PyValueError::new_err(format!("name: no preset {name:?} (one of {})", names.join(", ")))
        })?;
        Self::make(file, PathBuf::from(format!("<built-in scene {name}>")), None, set, tolerance)
    }

    /// The scene file at `path` (TOML, `docs/SCENES.md`); relative asset paths are read from
    /// its folder. `set` and `tolerance` as in `preset`.
    #[staticmethod]
    #[pyo3(signature = (path, *, set = None, tolerance = None))]
    fn from_file(path: PathBuf, set: Option<&Bound<'_, PyAny>>, tolerance: Option<f64>) -> PyResult<Self> {
        let text = std::fs::read_to_string(&path).map_err(|e| errors::file(&path, &e))?;
        let file = files::parse(&text, &path).map_err(scene_error)?;
        Self::make(file, path, Some(&text), set, tolerance)
    }

    /// A scene from TOML text; `base` is the folder relative asset paths are read from.
    #[staticmethod]
    #[pyo3(signature = (text, *, base = None, set = None, tolerance = None))]
    fn from_toml(
        text: &str,
        base: Option<PathBuf>,
        set: Option<&Bound<'_, PyAny>>,
        tolerance: Option<f64>,
    ) -> PyResult<Self> {
        let origin = base.unwrap_or_default().join("<text>");
        let file = files::parse(text, &origin).map_err(scene_error)?;
        Self::make(file, origin, Some(text), set, tolerance)
    }

    /// Continues from a checkpoint written by `Scene.checkpoint` or by `anim run
    /// --checkpoint-every` (the scene is rebuilt from the checkpoint's copy and restored bit for
    /// bit).
    #[staticmethod]
    fn resume(path: PathBuf) -> PyResult<Self> {
        let (header, payload): (_, serde_json::Value) =
            anim::io::read_checkpoint(&path).map_err(|e| match &e {
                anim::io::IoError::Io { source, .. } => errors::file(&path, source),
                _ => errors::checkpoint(e),
            })?;
        if header.kind != CHECKPOINT_KIND && header.kind != RUN_CHECKPOINT_KIND {
            return Err(errors::checkpoint(format!(
                "{}: a checkpoint of kind `{}`, not of a scene (`{CHECKPOINT_KIND}` or `{RUN_CHECKPOINT_KIND}`)",
                path.display(),
                header.kind
            )));
        }
        let field = |k: &str| {
            payload
                .get(k)
                .cloned()
                .ok_or_else(|| errors::checkpoint(format!("{}: no `{k}` in the checkpoint", path.display())))
        };
        let file: SceneFile = serde_json::from_value(field("scene")?)
            .map_err(|e| errors::checkpoint(format!("{}: scene: {e}", path.display())))?;
        let origin: PathBuf = serde_json::from_value(field("origin")?)
            .map_err(|e| errors::checkpoint(format!("{}: origin: {e}", path.display())))?;
        let saved = field("runner")?;
        let scene = Self::make(file, origin, None, None, None)?;
        scene
            .runner()?
            .restore(&saved)
            .map_err(|e| errors::checkpoint(format!("{}: {e}", path.display())))?;
        Ok(scene)
    }

    /// Writes a checkpoint file that `Scene.resume` continues bit for bit.
    fn checkpoint(&self, path: PathBuf) -> PyResult<()> {
        let runner = self.runner()?.save();
        let payload = serde_json::json!({ "scene": self.file, "origin": self.origin, "runner": runner });
        anim::io::write_checkpoint(&path, CHECKPOINT_KIND, &payload).map_err(|e| match &e {
            anim::io::IoError::Io { source, .. } => errors::file(&path, source),
            _ => errors::checkpoint(e),
        })
    }

    /// The scene's checkpoint as JSON text (`DynScene::save`).
    fn save(&self) -> PyResult<String> {
        Ok(self.runner()?.save().to_string())
    }

    /// Restores what `save` of a scene built from the same parameters returned.
    fn restore(&self, saved: &str) -> PyResult<()> {
        let value: serde_json::Value = serde_json::from_str(saved)
            .map_err(|e| PyValueError::new_err(format!("saved: not JSON: {e}")))?;
        self.runner()?.restore(&value).map_err(errors::checkpoint)
    }

    /// Advances `steps` steps of `dt` seconds (default the scene's `dt`), without the GIL. A
    /// failed step raises `anim.SimulationError` and leaves the scene as before it.
    #[pyo3(signature = (steps = 1, dt = None))]
    fn step(&self, py: Python<'_>, steps: usize, dt: Option<f64>) -> PyResult<()> {
        let dt = dt.unwrap_or(self.file.run.dt);
        arrays::time_step(dt)?;
        let mut runner = self.runner()?;
        let runner = &mut **runner;
        crate::threads::detached(py, || {
            for _ in 0..steps {
                runner.step(dt)?;
            }
            Ok(())
        })
        .map_err(|e: anim::core::scene::StepError| errors::step(e))
    }

    /// Advances `frames` frames of the scene's `steps_per_frame` steps (without the GIL).
    #[pyo3(signature = (frames = 1))]
    fn advance_frames(&self, py: Python<'_>, frames: usize) -> PyResult<()> {
        self.step(py, frames * self.file.run.steps_per_frame, None)
    }

    /// The current frame: a dict with `time`, `points` ((n, point_dim) float64) and `fields`
    /// (name to float64 array: (n,) or (n, components) per point; for grid scenes (ny, nx) or
    /// (nz, ny, nx), components last). Every array is a copy.
    fn frame<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let runner = self.runner()?;
        let mut frame = Frame::default();
        runner.frame(&mut frame);
        frame_dict(py, &frame, &**runner)
    }

    /// The static context: `point_dim`, `lines`, `triangles`, `tetrahedra` (int64 arrays),
    /// `pins`, `image` (dims, origin, spacing, or None) and `notes`.
    fn context<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let c = self.runner()?.context();
        let d = PyDict::new(py);
        d.set_item("point_dim", c.point_dim)?;
        d.set_item("planar", c.planar)?;
        d.set_item("lines", arrays::to_index_rows(py, &c.lines)?)?;
        d.set_item("triangles", arrays::to_index_rows(py, &c.triangles)?)?;
        d.set_item("tetrahedra", arrays::to_index_rows(py, &c.tetrahedra)?)?;
        d.set_item("pins", c.pins.clone())?;
        d.set_item("notes", c.notes.clone())?;
        match c.image {
            Some(g) => {
                let img = PyDict::new(py);
                img.set_item("dims", g.dims.to_vec())?;
                img.set_item("dim", g.dim)?;
                img.set_item("origin", g.origin.to_vec())?;
                img.set_item("spacing", g.spacing)?;
                d.set_item("image", img)?;
            }
            None => d.set_item("image", py.None())?,
        }
        Ok(d)
    }

    /// Simulated time (s).
    #[getter]
    fn time(&self) -> PyResult<f64> {
        Ok(self.runner()?.time())
    }
    /// The scene's name.
    #[getter]
    fn name(&self) -> String {
        self.file.name.clone()
    }
    /// The registered kind.
    #[getter]
    fn kind(&self) -> String {
        self.file.scene.kind.clone()
    }
    /// The method in a few words.
    #[getter]
    fn method(&self) -> PyResult<String> {
        Ok(self.runner()?.method())
    }
    /// Step (s).
    #[getter]
    fn dt(&self) -> f64 {
        self.file.run.dt
    }
    /// Frames of the scene's run.
    #[getter]
    fn frames(&self) -> usize {
        self.file.run.frames
    }
    /// Steps per frame.
    #[getter]
    fn steps_per_frame(&self) -> usize {
        self.file.run.steps_per_frame
    }
    /// The scene's parameters as JSON text (after `set` and `tolerance`).
    #[getter]
    fn params(&self) -> String {
        self.file.scene.params_value().to_string()
    }
    /// What `tolerance=` picked: a dict with `method`, `param`, `settings`, `dt`,
    /// `steps_per_frame`, `why`; None without `tolerance`.
    #[getter]
    fn choice<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        let Some(c) = &self.choice else { return Ok(None) };
        let d = PyDict::new(py);
        d.set_item("method", &c.method)?;
        d.set_item("param", c.param)?;
        d.set_item("settings", &c.settings)?;
        d.set_item("dt", c.dt)?;
        d.set_item("steps_per_frame", c.steps_per_frame)?;
        d.set_item("why", &c.why)?;
        Ok(Some(d))
    }
    /// The error against the scene's reference where it has one (exact solutions, Ghia's
    /// cavity), else None.
    fn reference_error(&self) -> PyResult<Option<f64>> {
        Ok(self.runner()?.reference_error())
    }
    fn __repr__(&self) -> String {
        format!("Scene(name={:?}, kind={:?})", self.file.name, self.file.scene.kind)
    }
}

/// Registers `anim.scene`.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Scene>()?;
    m.add_function(wrap_pyfunction!(kinds, m)?)?;
    m.add_function(wrap_pyfunction!(presets, m)?)?;
    Ok(())
}
