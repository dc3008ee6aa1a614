//! `anim.pbd`: anim-pbd's position based dynamics (PBD, Müller et al. 2007; XPBD, Macklin et al.
//! 2016): cloth from triangle meshes, soft bodies from tetrahedral meshes, ropes as chains, built
//! by [`anim::pbd::PbdBuilder`] and stepped by [`anim::pbd::PbdSimulation`].

use crate::arrays;
use crate::errors;
use anim::core::integrate::State;
use anim::pbd::{
    Bending, Chain, Collider, ConstraintParams, MeshMass, MeshParams, Method, PbdBuilder, PbdParams,
    PbdSimulation, SolverKind, TetMeshParams,
};
use numpy::PyArray2;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

/// A name of the crate's serde spelling (`"xpbd"`, `"colored-gauss-seidel"`) as its enum.
fn named<T: serde::de::DeserializeOwned>(name: &str, arg: &str, choices: &str) -> PyResult<T> {
    serde_json::from_value(serde_json::Value::String(name.to_string()))
        .map_err(|_| PyValueError::new_err(format!("{arg}: unknown value {name:?} (one of {choices})")))
}

/// Distance-constraint parameters: XPBD compliance, PBD stiffness and XPBD damping.
fn params(compliance: f64, stiffness: f64, damping: f64) -> ConstraintParams {
    ConstraintParams::with_compliance(compliance).stiffness(stiffness).damping(damping)
}

/// The mass rule: exactly one of a per-vertex mass and a density.
fn mass(mass: Option<f64>, density: Option<f64>) -> PyResult<MeshMass> {
    match (mass, density) {
        (Some(m), None) => Ok(MeshMass::PerVertex(m)),
        (None, Some(d)) => Ok(MeshMass::Density(d)),
        (None, None) => Err(PyValueError::new_err("mass, density: give one of them")),
        (Some(_), Some(_)) => Err(PyValueError::new_err("mass, density: give only one of them")),
    }
}

/// Collects particles, constraints, pins and colliders (anim-pbd's `PbdBuilder`); gravity is
/// zero until set. Every method checks its input; `build` checks the whole model.
#[pyclass(module = "anim.pbd")]
pub struct Builder {
    inner: PbdBuilder,
}

#[pymethods]
impl Builder {
    /// A builder with the given gravity (m/s^2, default none).
    #[new]
    #[pyo3(signature = (gravity = None))]
    fn new(gravity: Option<&Bound<'_, PyAny>>) -> PyResult<Self> {
        let mut inner = PbdBuilder::new();
        if let Some(g) = gravity {
            inner.gravity(arrays::point::<3>(g, "gravity")?);
        }
        Ok(Self { inner })
    }

    /// Number of particles so far.
    #[getter]
    fn num_particles(&self) -> usize {
        self.inner.num_particles()
    }

    /// A cloth or shell from a triangle mesh: `vertices` (n, 3) float64, `triangles` (m, 3)
    /// integers. A distance constraint per edge, a bending constraint (`"isometric"`,
    /// `"dihedral"` or `"none"`) across every interior edge. Give `mass` (kg per vertex) or
    /// `density` (kg/m^2). Returns the index of the first particle.
    #[pyo3(signature = (vertices, triangles, *, mass = None, density = None, stretch_compliance = 0.0,
        stretch_stiffness = 1.0, bending = "isometric", bending_compliance = 0.0, bending_stiffness = 1.0, damping = 0.0))]
    fn triangle_mesh(
        &mut self,
        vertices: &Bound<'_, PyAny>,
        triangles: &Bound<'_, PyAny>,
        mass: Option<f64>,
        density: Option<f64>,
        stretch_compliance: f64,
        stretch_stiffness: f64,
        bending: &str,
        bending_compliance: f64,
        bending_stiffness: f64,
        damping: f64,
    ) -> PyResult<usize> {
        let positions = arrays::rows::<3>(vertices, "vertices")?;
        let tris = arrays::indices::<3>(triangles, "triangles", positions.len())?;
        let bend = params(bending_compliance, bending_stiffness, damping);
        let bending = match bending {
            "isometric" => Bending::Isometric(bend),
            "dihedral" => Bending::Dihedral(bend),
            "none" => Bending::None,
            other => {
                return Err(PyValueError::new_err(format!(
                    "bending: unknown value {other:?} (one of isometric, dihedral, none)"
                )));
            }
        };
        let mesh = MeshParams {
            mass: self::mass(mass, density)?,
            stretch: params(stretch_compliance, stretch_stiffness, damping),
            bending,
        };
        let range = self.inner.triangle_mesh(&positions, &tris, &mesh).map_err(errors::build)?;
        Ok(range.start)
    }

    /// A soft body from a tetrahedral mesh: `vertices` (n, 3) float64, `tets` (m, 4) integers,
    /// with a volume constraint per tetrahedron (`volume_compliance`) and, when
    /// `stretch_compliance` is given, a distance constraint per edge. Give `mass` (kg per
    /// vertex) or `density` (kg/m^3). Returns the index of the first particle.
    #[pyo3(signature = (vertices, tets, *, mass = None, density = None, volume_compliance = 0.0,
        stretch_compliance = None, damping = 0.0))]
    fn tet_mesh(
        &mut self,
        vertices: &Bound<'_, PyAny>,
        tets: &Bound<'_, PyAny>,
        mass: Option<f64>,
        density: Option<f64>,
        volume_compliance: f64,
        stretch_compliance: Option<f64>,
        damping: f64,
    ) -> PyResult<usize> {
        let positions = arrays::rows::<3>(vertices, "vertices")?;
        let elements = arrays::indices::<4>(tets, "tets", positions.len())?;
        let mesh = TetMeshParams {
            mass: self::mass(mass, density)?,
            stretch: stretch_compliance.map(|c| params(c, 1.0, damping)),
            volume: Some(params(volume_compliance, 1.0, damping)),
        };
        let range = self.inner.tet_mesh(&positions, &elements, &mesh).map_err(errors::build)?;
        Ok(range.start)
    }

    /// A rope: `count` particles of `mass` kg each from `start` to `end`, joined by distance
    /// constraints. Returns the index of the first particle.
    #[pyo3(signature = (count, start, end, *, mass, compliance = 0.0, stiffness = 1.0, damping = 0.0))]
    fn chain(
        &mut self,
        count: usize,
        start: &Bound<'_, PyAny>,
        end: &Bound<'_, PyAny>,
        mass: f64,
        compliance: f64,
        stiffness: f64,
        damping: f64,
    ) -> PyResult<usize> {
        let chain = Chain {
            count,
            start: arrays::point::<3>(start, "start")?,
            end: arrays::point::<3>(end, "end")?,
            mass,
            stretch: params(compliance, stiffness, damping),
        };
        let range = self.inner.chain(&chain).map_err(errors::build)?;
        Ok(range.start)
    }

    /// Pins particles (an index or a list of indices): their inverse mass becomes 0.
    fn pin(&mut self, particles: &Bound<'_, PyAny>) -> PyResult<()> {
        let n = self.inner.num_particles();
        let list = arrays::index_or_list(particles, "particles", n)?;
        for p in list {
            self.inner.pin(p);
        }
        Ok(())
    }

    /// A static sphere collider with a contact `thickness` and Coulomb friction.
    #[pyo3(signature = (center, radius, *, thickness = 0.0, friction = 0.0))]
    fn sphere(
        &mut self,
        center: &Bound<'_, PyAny>,
        radius: f64,
        thickness: f64,
        friction: f64,
    ) -> PyResult<()> {
        let c = arrays::point::<3>(center, "center")?;
        self.inner.collider(
            Collider::sphere(c, radius).with_thickness(thickness).with_friction(friction, friction),
        );
        Ok(())
    }

    /// The ground plane `z = height` (anim-pbd is z up), with Coulomb friction.
    #[pyo3(signature = (height = 0.0, *, friction = 0.0))]
    fn ground(&mut self, height: f64, friction: f64) {
        self.inner.collider(Collider::ground(height).with_friction(friction, friction));
    }

    /// Checks the model and makes the simulation: `method` `"xpbd"` or `"pbd"`, `solver`
    /// `"gauss-seidel"`, `"colored-gauss-seidel"` or `"jacobi"`, `iterations` per substep and
    /// `substeps` per step.
    #[pyo3(signature = (*, method = "xpbd", solver = "gauss-seidel", iterations = 10, substeps = 1))]
    fn build(&self, method: &str, solver: &str, iterations: usize, substeps: usize) -> PyResult<Simulation> {
        let method: Method = named(method, "method", "xpbd, pbd")?;
        let solver: SolverKind = named(solver, "solver", "gauss-seidel, colored-gauss-seidel, jacobi")?;
        let model = self.inner.build().map_err(errors::build)?;
        let state = model.rest_state();
        let params = PbdParams::new(method, solver, iterations, substeps);
        let sim = PbdSimulation::new(model, params).map_err(errors::build)?;
        Ok(Simulation { sim, state })
    }
}

/// A PBD or XPBD simulation and its state (positions and velocities).
#[pyclass(module = "anim.pbd")]
pub struct Simulation {
    sim: PbdSimulation,
    state: State,
}

#[pymethods]
impl Simulation {
    /// Advances `steps` steps of `dt` seconds, without the GIL. On a failed step the error is
    /// raised and the state is the one before that step.
    #[pyo3(signature = (dt, steps = 1))]
    fn step(&mut self, py: Python<'_>, dt: f64, steps: usize) -> PyResult<()> {
        arrays::time_step(dt)?;
        let Self { sim, state } = self;
        crate::threads::detached(py, || {
            for _ in 0..steps {
                sim.advance(state, dt)?;
            }
            Ok(())
        })
        .map_err(|e: anim::pbd::PbdError| errors::step(e))
    }

    /// Number of particles.
    #[getter]
    fn num_particles(&self) -> usize {
        self.state.x.len() / 3
    }

    /// Positions, (n, 3) float64 (a copy).
    #[getter]
    fn positions<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        arrays::to_rows(py, &self.state.x, 3)
    }

    /// Sets the positions from an (n, 3) float64 array (copied in).
    #[setter]
    fn set_positions(&mut self, value: &Bound<'_, PyAny>) -> PyResult<()> {
        let n = self.state.x.len() / 3;
        let (v, _) = arrays::floats(value, "positions", &[Some(n), Some(3)])?;
        self.state.x = v;
        Ok(())
    }

    /// Velocities, (n, 3) float64 (a copy).
    #[getter]
    fn velocities<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        arrays::to_rows(py, &self.state.v, 3)
    }

    /// Sets the velocities from an (n, 3) float64 array (copied in).
    #[setter]
    fn set_velocities(&mut self, value: &Bound<'_, PyAny>) -> PyResult<()> {
        let n = self.state.v.len() / 3;
        let (v, _) = arrays::floats(value, "velocities", &[Some(n), Some(3)])?;
        self.state.v = v;
        Ok(())
    }

    /// The triangles recorded by the builder, (m, 3) int64 (a copy).
    #[getter]
    fn triangles<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<i64>>> {
        arrays::to_index_rows(py, self.sim.model().triangles())
    }

    /// Number of steps taken.
    #[getter]
    fn steps(&self) -> u64 {
        self.sim.steps()
    }

    /// The largest constraint violation at the current positions.
    fn max_violation(&self) -> f64 {
        self.sim.max_violation(&self.state.x)
    }
}

/// Registers `anim.pbd`.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Builder>()?;
    m.add_class::<Simulation>()?;
    Ok(())
}
