//! `anim.fem`: anim-fem's tetrahedral finite elements (Sifakis & Barbič 2012): a body from
//! numpy vertices and tetrahedra with one of the crate's hyperelastic models, pinned vertices,
//! stepped by symplectic or backward Euler, with positions and per-element stresses out.

use crate::arrays;
use crate::errors;
use anim::core::integrate::State;
use anim::fem::element::{deformation_gradient, gather};
use anim::fem::material::{Material, MaterialModel};
use anim::fem::mesh::TetMesh;
use anim::fem::model::FemModel;
use anim::fem::sim::{FemParams, FemSimulation, TimeIntegrator};
use anim::fem::{FemError, Solver};
use numpy::{PyArray1, PyArray2, PyArray3, PyArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use std::sync::Mutex;

/// A name in the crate's serde spelling as its enum.
fn named<T: serde::de::DeserializeOwned>(name: &str, arg: &str) -> PyResult<T> {
    serde_json::from_value(serde_json::Value::String(name.to_string()))
        .map_err(|e| PyValueError::new_err(format!("{arg}: {e}")))
}

/// An FEM body and its state (behind a lock: the linear solver is `Send` only).
#[pyclass(module = "anim.fem")]
pub struct Simulation {
    inner: Mutex<(FemSimulation, State)>,
}

impl Simulation {
    fn lock(&self) -> PyResult<std::sync::MutexGuard<'_, (FemSimulation, State)>> {
        self.inner
            .lock()
            .map_err(|_| errors::step("the simulation was poisoned by a panic in an earlier step"))
    }

    /// Per element: `F` and `P(F)` at the current positions.
    fn per_element(&self, cauchy: bool) -> PyResult<Vec<f64>> {
        let guard = self.lock()?;
        let (sim, state) = &*guard;
        let model = sim.model();
        let mut out = Vec::with_capacity(9 * model.elements());
        for (e, tet) in model.mesh().tets.iter().enumerate() {
            let f = deformation_gradient(&gather(&state.x, tet), &model.dm_inv()[e]);
            let mat = model.material_of(e);
            let p = mat.model.pk1(&mat.lame, &f);
            let s = if cauchy { p * f.transpose() / f.determinant() } else { p };
            for i in 0..3 {
                for j in 0..3 {
                    out.push(s[(i, j)]);
                }
            }
        }
        Ok(out)
    }
}

#[pymethods]
impl Simulation {
    /// A body from `vertices` (n, 3) float64 and `tets` (m, 4) integers (positively oriented),
    /// of `material` (`"linear"`, `"st-venant-kirchhoff"`, `"corotated-linear"`, `"neo-hookean"`,
    /// `"fixed-corotated"`, `"stable-neo-hookean"`) with Young's modulus `young` (Pa), Poisson's
    /// ratio `poisson` and `density` (kg/m^3); `pins` are fixed vertices; `integrator`
    /// `"backward-euler"` or `"symplectic-euler"`.
    #[new]
    #[pyo3(signature = (vertices, tets, *, young, poisson, density, material = "stable-neo-hookean",
        gravity = None, pins = None, integrator = "backward-euler"))]
    fn new(
        vertices: &Bound<'_, PyAny>,
        tets: &Bound<'_, PyAny>,
        young: f64,
        poisson: f64,
        density: f64,
        material: &str,
        gravity: Option<&Bound<'_, PyAny>>,
        pins: Option<&Bound<'_, PyAny>>,
        integrator: &str,
    ) -> PyResult<Self> {
        let positions = arrays::rows::<3>(vertices, "vertices")?;
        let elements = arrays::indices::<4>(tets, "tets", positions.len())?;
        let n = positions.len();
        let model_kind: MaterialModel = named(material, "material")?;
        let integrator: TimeIntegrator = named(integrator, "integrator")?;
        let mat = Material::new(model_kind, young, poisson, density).map_err(errors::build)?;
        let mesh = TetMesh { positions, tets: elements };
        let mut model = FemModel::new(mesh, mat).map_err(errors::build)?;
        if let Some(g) = gravity {
            model = model.with_gravity(arrays::point::<3>(g, "gravity")?);
        }
        if let Some(p) = pins {
            let list = arrays::index_list(p, "pins", n)?;
            model.pin_vertices(&list).map_err(errors::build)?;
        }
        let sim = FemSimulation::new(model, FemParams::new(integrator)).map_err(errors::build)?;
        let state = sim.rest_state();
        Ok(Self { inner: Mutex::new((sim, state)) })
    }

    /// Advances `steps` steps of `dt` seconds without the GIL; a failed step raises
    /// `anim.SimulationError` and leaves the state as before it.
    #[pyo3(signature = (dt, steps = 1))]
    fn step(&self, py: Python<'_>, dt: f64, steps: usize) -> PyResult<()> {
        arrays::time_step(dt)?;
        let mut guard = self.lock()?;
        let (sim, state) = &mut *guard;
        crate::threads::detached(py, || {
            for _ in 0..steps {
                sim.step(state, dt)?;
            }
            Ok(())
        })
        .map_err(|e: FemError| errors::step(e))
    }

    /// The static equilibrium under the loads, by Newton in `load_steps` increments, without the
    /// GIL; the velocities are set to zero. Returns the Newton iterations taken.
    #[pyo3(signature = (load_steps = 1))]
    fn solve_static(&self, py: Python<'_>, load_steps: usize) -> PyResult<usize> {
        let mut guard = self.lock()?;
        let (sim, state) = &mut *guard;
        let info = crate::threads::detached(py, || sim.solve_static(&mut state.x, load_steps.max(1)))
            .map_err(errors::step)?;
        state.v.iter_mut().for_each(|v| *v = 0.0);
        Ok(info.iterations)
    }

    /// Positions, (n, 3) float64 (a copy).
    #[getter]
    fn positions<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        arrays::to_rows(py, &self.lock()?.1.x, 3)
    }
    /// Sets the positions from an (n, 3) float64 array (copied in; pinned vertices too).
    #[setter]
    fn set_positions(&self, value: &Bound<'_, PyAny>) -> PyResult<()> {
        let mut guard = self.lock()?;
        let n = guard.1.x.len() / 3;
        guard.1.x = arrays::floats(value, "positions", &[Some(n), Some(3)])?.0;
        Ok(())
    }
    /// Velocities, (n, 3) float64 (a copy).
    #[getter]
    fn velocities<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        arrays::to_rows(py, &self.lock()?.1.v, 3)
    }
    /// Simulated time (s).
    #[getter]
    fn time(&self) -> PyResult<f64> {
        Ok(self.lock()?.1.t)
    }
    /// The Cauchy stress of every element at the current positions, (m, 3, 3) float64 (Pa, a
    /// new array): `σ = P Fᵀ / det F` from the crate's first Piola-Kirchhoff stress.
    fn stresses<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray3<f64>>> {
        let s = self.per_element(true)?;
        let m = s.len() / 9;
        PyArray1::from_vec(py, s).reshape([m, 3, 3])
    }
    /// The first Piola-Kirchhoff stress `P(F)` of every element, (m, 3, 3) float64 (Pa, a new
    /// array).
    fn first_piola<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray3<f64>>> {
        let s = self.per_element(false)?;
        let m = s.len() / 9;
        PyArray1::from_vec(py, s).reshape([m, 3, 3])
    }
}

/// A box of `cells` hexahedra split into tetrahedra (anim-fem's `box_mesh`): `(vertices, tets)`.
#[pyfunction]
fn box_mesh<'py>(
    py: Python<'py>,
    origin: &Bound<'_, PyAny>,
    size: &Bound<'_, PyAny>,
    cells: [usize; 3],
) -> PyResult<arrays::MeshArrays<'py>> {
    let o = arrays::point::<3>(origin, "origin")?;
    let s = arrays::point::<3>(size, "size")?;
    let mesh = anim::fem::generate::box_mesh(o, s, cells).map_err(errors::build)?;
    let flat: Vec<f64> = mesh.positions.iter().flatten().copied().collect();
    Ok((arrays::to_rows(py, &flat, 3)?, arrays::to_index_rows(py, &mesh.tets)?))
}

/// Registers `anim.fem`.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Simulation>()?;
    m.add_function(wrap_pyfunction!(box_mesh, m)?)?;
    Ok(())
}
