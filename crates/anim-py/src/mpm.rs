//! `anim.mpm`: anim-mpm's material point method (APIC, Jiang et al. 2015; MLS-MPM, Hu et al.
//! 2018) in 2D and 3D: the crate's built-in scenes ([`anim::mpm::scenes`]) or a simulation from
//! the crate's own parameters and materials (the scene-file spellings) with particles from numpy.
//!
//! Particles are `f32` in the crate; positions and velocities come back as float32 `(n, D)`
//! arrays in the order the particles were added (the solver sorts them internally; the
//! particle ids undo that), as new arrays.

use crate::arrays;
use crate::errors;
use anim::mpm::scenes::{self, MpmScene, Scene as MpmSceneD};
use anim::mpm::{Material, MpmError, MpmParams, MpmSimulation, Particles};
use numpy::{PyArray1, PyArray2, PyArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

/// Runs `$body` with `$s` bound to the scene of either dimension and `$d` to its dimension.
macro_rules! each {
    ($scene:expr, $s:ident, $d:ident => $body:expr) => {
        match $scene {
            MpmScene::Two($s) => {
                const $d: usize = 2;
                $body
            }
            MpmScene::Three($s) => {
                const $d: usize = 3;
                $body
            }
        }
    };
}

/// An MPM simulation and its particles, in 2D or 3D.
#[pyclass(module = "anim.mpm")]
pub struct Simulation {
    inner: MpmScene,
}

/// `MpmParams` from the defaults with the keys of `params` replaced (the crate's field names:
/// `resolution`, `size`, `transfer`, `kernel`, `gravity`, `wall`, `cfl`, ...).
fn mpm_params(params: Option<&Bound<'_, PyAny>>) -> PyResult<MpmParams> {
    let mut value = serde_json::to_value(MpmParams::default()).map_err(errors::build)?;
    if let Some(p) = params {
        let serde_json::Value::Object(given) = crate::json::of(p, "params")? else {
            return Err(PyValueError::new_err("params: expected a dict"));
        };
        let Some(base) = value.as_object_mut() else { return Err(errors::build("MpmParams is not a table")) };
        for (k, v) in given {
            if !base.contains_key(&k) {
                let names: Vec<&String> = base.keys().collect();
                return Err(PyValueError::new_err(format!("params: unknown key {k:?} (one of {names:?})")));
            }
            base.insert(k, v);
        }
    }
    serde_json::from_value(value).map_err(|e| PyValueError::new_err(format!("params: {e}")))
}

/// Positions or velocities in id order, as a float32 `(n, D)` array.
fn by_id<'py, const D: usize>(
    py: Python<'py>,
    values: &[f32],
    ids: &[u32],
) -> PyResult<Bound<'py, PyArray2<f32>>> {
    let mut out = vec![0.0f32; values.len()];
    for (p, &id) in ids.iter().enumerate() {
        let id = id as usize;
        out[id * D..(id + 1) * D].copy_from_slice(&values[p * D..(p + 1) * D]);
    }
    PyArray1::from_vec(py, out).reshape([ids.len(), D])
}

fn mpm_error(e: MpmError) -> PyErr {
    match e {
        MpmError::BadParameter { .. } | MpmError::Dimension(_) => errors::build(e),
        _ => errors::step(e),
    }
}

#[pymethods]
impl Simulation {
    /// A simulation of `dim` (2 or 3) dimensions from the crate's parameters (`params`, a dict
    /// over the defaults) and materials (a list of dicts in the scene-file form, e.g.
    /// `{"fluid": {"bulk": 1e5}}`, `{"elastic": {"young": 2e4, "poisson": 0.3}}`), without particles.
    #[new]
    #[pyo3(signature = (dim, materials, params = None))]
    fn new(dim: usize, materials: &Bound<'_, PyAny>, params: Option<&Bound<'_, PyAny>>) -> PyResult<Self> {
        let params = mpm_params(params)?;
        let materials: Vec<Material> = serde_json::from_value(crate::json::of(materials, "materials")?)
            .map_err(|e| PyValueError::new_err(format!("materials: {e}")))?;
        let inner = match dim {
            2 => MpmScene::Two(MpmSceneD {
                name: "python",
                description: "built from Python",
                sim: MpmSimulation::<2>::new(params, materials).map_err(mpm_error)?,
                state: Particles::new(),
                dt: 1e-4,
                duration: 1.0,
            }),
            3 => MpmScene::Three(MpmSceneD {
                name: "python",
                description: "built from Python",
                sim: MpmSimulation::<3>::new(params, materials).map_err(mpm_error)?,
                state: Particles::new(),
                dt: 1e-4,
                duration: 1.0,
            }),
            d => return Err(PyValueError::new_err(format!("dim: must be 2 or 3, got {d}"))),
        };
        Ok(Self { inner })
    }

    /// The crate's built-in scene `name` (`three-materials`, `dam-break-2d`, `dam-break-3d`,
    /// `snowball`, `benchmark-2d`, `benchmark-3d`) at `resolution` cells per axis (default the
    /// scene's).
    #[staticmethod]
    #[pyo3(signature = (name, resolution = None))]
    fn scene(name: &str, resolution: Option<usize>) -> PyResult<Self> {
        let inner = scenes::by_name(name, resolution)
            .ok_or_else(|| {
                PyValueError::new_err(format!(
                    "name: no scene {name:?} (one of {})",
                    scenes::NAMES.join(", ")
                ))
            })?
            .map_err(mpm_error)?;
        Ok(Self { inner })
    }

    /// Adds particles at rest shape (`F = I`): `positions` and `velocities` (n, D) float64,
    /// `mass` and `volume` per particle (scalars or (n,) arrays), `material` an index into the
    /// materials. Returns the index of the first.
    #[pyo3(signature = (positions, *, mass, volume, material = 0, velocities = None))]
    fn add_particles(
        &mut self,
        positions: &Bound<'_, PyAny>,
        mass: &Bound<'_, PyAny>,
        volume: &Bound<'_, PyAny>,
        material: u16,
        velocities: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<usize> {
        each!(&mut self.inner, s, D => {
            let (x, shape) = arrays::floats(positions, "positions", &[None, Some(D)])?;
            let n = shape[0];
            let v = match velocities {
                Some(v) => arrays::floats(v, "velocities", &[Some(n), Some(D)])?.0,
                None => vec![0.0; n * D],
            };
            let per = |obj: &Bound<'_, PyAny>, name: &str| -> PyResult<Vec<f64>> {
                if let Ok(c) = obj.extract::<f64>() {
                    Ok(vec![c; n])
                } else {
                    arrays::vector(obj, name, Some(n))
                }
            };
            let (m, vol) = (per(mass, "mass")?, per(volume, "volume")?);
            if usize::from(material) >= s.sim.materials().len() {
                return Err(PyValueError::new_err(format!("material: {material} is outside 0..{}", s.sim.materials().len())));
            }
            let first = s.state.len();
            let mut added = s.state.clone();
            for p in 0..n {
                let xp: [f32; D] = std::array::from_fn(|i| x[p * D + i] as f32);
                let vp: [f32; D] = std::array::from_fn(|i| v[p * D + i] as f32);
                added.push(xp, vp, m[p] as f32, vol[p] as f32, material).map_err(|e| PyValueError::new_err(format!("particle {p}: {e}")))?;
            }
            s.state = added;
            Ok(first)
        })
    }

    /// Advances `steps` steps of `dt` seconds (default the scene's) by `MpmSimulation::advance`,
    /// without the GIL; the solver adds substeps where its CFL limits need them (the step
    /// report's totals are not computed: `totals()` gives them).
    #[pyo3(signature = (steps = 1, dt = None))]
    fn step(&mut self, py: Python<'_>, steps: usize, dt: Option<f64>) -> PyResult<()> {
        each!(&mut self.inner, s, _D => {
            let dt = dt.unwrap_or(s.dt);
            arrays::time_step(dt)?;
            let (sim, state) = (&mut s.sim, &mut s.state);
            crate::threads::detached(py, || {
                for _ in 0..steps {
                    sim.advance(state, dt)?;
                }
                Ok(())
            })
            .map_err(mpm_error)
        })
    }

    /// 2 or 3.
    #[getter]
    fn dim(&self) -> usize {
        self.inner.dim()
    }
    /// Number of particles.
    #[getter]
    fn num_particles(&self) -> usize {
        each!(&self.inner, s, _D => s.state.len())
    }
    /// The scene's step (s).
    #[getter]
    fn dt(&self) -> f64 {
        self.inner.dt()
    }
    /// Simulated time (s).
    #[getter]
    fn time(&self) -> f64 {
        each!(&self.inner, s, _D => s.sim.time())
    }
    /// Positions, (n, D) float32 in the order added (a copy).
    #[getter]
    fn positions<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f32>>> {
        each!(&self.inner, s, D => by_id::<D>(py, &s.state.x, &s.state.id))
    }
    /// Velocities, (n, D) float32 in the order added (a copy).
    #[getter]
    fn velocities<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f32>>> {
        each!(&self.inner, s, D => by_id::<D>(py, &s.state.v, &s.state.id))
    }
    /// Material index per particle, (n,) int64 in the order added (a copy).
    #[getter]
    fn materials<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<i64>> {
        each!(&self.inner, s, _D => {
            let mut out = vec![0i64; s.state.len()];
            for (p, &id) in s.state.id.iter().enumerate() {
                out[id as usize] = i64::from(s.state.material[p]);
            }
            PyArray1::from_vec(py, out)
        })
    }
    /// Total mass, linear momentum and angular momentum of the particles: `(m, p, L)`.
    fn totals(&mut self) -> (f64, [f64; 3], [f64; 3]) {
        each!(&mut self.inner, s, _D => {
            let t = s.sim.totals(&s.state);
            (t.mass, t.momentum, t.angular_momentum)
        })
    }
}

/// Registers `anim.mpm`.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Simulation>()?;
    m.add("SCENES", scenes::NAMES.to_vec())?;
    Ok(())
}
