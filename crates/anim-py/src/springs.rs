//! `anim.springs`: anim-springs' mass-spring networks (Hooke springs with damping, pins,
//! penalty contact) from numpy vertices and triangles or as chains, stepped by any integrator
//! of anim-core ([`anim::springs::SpringSimulation`]).

use crate::arrays;
use crate::errors;
use anim::core::integrate::{IntegratorKind, NewtonParams, State};
use anim::core::linalg::LinearSolverKind;
use anim::springs::{
    Chain, Collider, MeshMass, MeshSprings, NetworkBuilder, Solver, SpringError, SpringParams,
    SpringSimulation,
};
use numpy::PyArray2;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use std::sync::Mutex;

/// Collects particles, springs, pins and colliders (anim-springs' `NetworkBuilder`); gravity is
/// zero until set.
#[pyclass(module = "anim.springs")]
pub struct Builder {
    inner: NetworkBuilder,
}

#[pymethods]
impl Builder {
    /// A builder with the given gravity (m/s^2, default none).
    #[new]
    #[pyo3(signature = (gravity = None))]
    fn new(gravity: Option<&Bound<'_, PyAny>>) -> PyResult<Self> {
        let mut inner = NetworkBuilder::new();
        if let Some(g) = gravity {
            inner.gravity(arrays::point::<3>(g, "gravity")?);
        }
        Ok(Self { inner })
    }

    /// A spring mesh from a triangle mesh: `vertices` (n, 3) float64, `triangles` (m, 3)
    /// integers; one spring of `stiffness` (N/m) and `damping` (N s/m) per edge, bending springs
    /// across interior edges when `bending_stiffness` is given. Give `mass` (kg per vertex) or
    /// `density` (kg/m^2). Returns the index of the first particle.
    #[pyo3(signature = (vertices, triangles, *, stiffness, damping = 0.0, mass = None, density = None,
        bending_stiffness = None, bending_damping = 0.0))]
    fn mesh(
        &mut self,
        vertices: &Bound<'_, PyAny>,
        triangles: &Bound<'_, PyAny>,
        stiffness: f64,
        damping: f64,
        mass: Option<f64>,
        density: Option<f64>,
        bending_stiffness: Option<f64>,
        bending_damping: f64,
    ) -> PyResult<usize> {
        let v = arrays::rows::<3>(vertices, "vertices")?;
        let t = arrays::indices::<3>(triangles, "triangles", v.len())?;
        let mass = match (mass, density) {
            (Some(m), None) => MeshMass::PerVertex(m),
            (None, Some(d)) => MeshMass::AreaDensity(d),
            _ => return Err(PyValueError::new_err("mass, density: give exactly one of them")),
        };
        let params = MeshSprings {
            mass,
            edge: SpringParams::new(stiffness, damping),
            bending: bending_stiffness.map(|k| SpringParams::new(k, bending_damping)),
        };
        Ok(self.inner.mesh(&v, &t, &params).map_err(errors::build)?.start)
    }

    /// A chain of `count` particles of `mass` kg from `start` to `end`. Returns the first index.
    #[pyo3(signature = (count, start, end, *, mass, stiffness, damping = 0.0))]
    fn chain(
        &mut self,
        count: usize,
        start: &Bound<'_, PyAny>,
        end: &Bound<'_, PyAny>,
        mass: f64,
        stiffness: f64,
        damping: f64,
    ) -> PyResult<usize> {
        let c = Chain {
            count,
            start: arrays::point::<3>(start, "start")?,
            end: arrays::point::<3>(end, "end")?,
            mass,
            spring: SpringParams::new(stiffness, damping),
        };
        Ok(self.inner.chain(&c).map_err(errors::build)?.start)
    }

    /// Pins particles (an index or a list of indices).
    fn pin(&mut self, particles: &Bound<'_, PyAny>) -> PyResult<()> {
        let n = self.inner.num_particles();
        let list = arrays::index_or_list(particles, "particles", n)?;
        for p in list {
            self.inner.pin(p);
        }
        Ok(())
    }

    /// A penalty ground plane `z = height` of `stiffness` N/m (anim-springs is z up).
    #[pyo3(signature = (height, *, stiffness))]
    fn ground(&mut self, height: f64, stiffness: f64) {
        self.inner.collider(Collider::ground(height, stiffness));
    }

    /// Checks the network and makes the simulation with `integrator` (anim-core's names:
    /// `"symplectic-euler"`, `"backward-euler"`, `"rk4"`, ..., or `{"beta-blend": {"beta": 0.5}}`)
    /// and, for implicit integrators, `linear_solver` (`"cholesky"`, `"cg"`, ...).
    #[pyo3(signature = (*, integrator = None, linear_solver = "cholesky"))]
    fn build(&self, integrator: Option<&Bound<'_, PyAny>>, linear_solver: &str) -> PyResult<Simulation> {
        let kind: IntegratorKind = match integrator {
            Some(i) => serde_json::from_value(crate::json::of(i, "integrator")?)
                .map_err(|e| PyValueError::new_err(format!("integrator: {e}")))?,
            None => IntegratorKind::SymplecticEuler,
        };
        let linear: LinearSolverKind =
            serde_json::from_value(serde_json::Value::String(linear_solver.into()))
                .map_err(|e| PyValueError::new_err(format!("linear_solver: {e}")))?;
        let network = self.inner.build().map_err(errors::build)?;
        let state = network.rest_state();
        let sim =
            SpringSimulation::new(network, kind, NewtonParams::default(), linear).map_err(errors::build)?;
        Ok(Simulation { inner: Mutex::new((sim, state)) })
    }
}

/// A mass-spring simulation and its state (behind a lock: the integrator is `Send` only).
#[pyclass(module = "anim.springs")]
pub struct Simulation {
    inner: Mutex<(SpringSimulation, State)>,
}

impl Simulation {
    fn lock(&self) -> PyResult<std::sync::MutexGuard<'_, (SpringSimulation, State)>> {
        self.inner
            .lock()
            .map_err(|_| errors::step("the simulation was poisoned by a panic in an earlier step"))
    }
}

#[pymethods]
impl Simulation {
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
        .map_err(|e: SpringError| errors::step(e))
    }
    /// Positions, (n, 3) float64 (a copy).
    #[getter]
    fn positions<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        arrays::to_rows(py, &self.lock()?.1.x, 3)
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
    /// Number of particles.
    #[getter]
    fn num_particles(&self) -> PyResult<usize> {
        Ok(self.lock()?.1.x.len() / 3)
    }
}

/// Registers `anim.springs`.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Builder>()?;
    m.add_class::<Simulation>()?;
    Ok(())
}
