//! `anim.flip`: anim-flip's incompressible particle fluid (PIC, FLIP and APIC on a MAC grid,
//! Zhu & Bridson 2005, Jiang et al. 2015) in 2D and 3D, with particles from numpy and back.

use crate::arrays;
use crate::errors;
use anim::flip::{FlipError, FlipParams, FlipSimulation, Particles};
use numpy::PyArray2;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

/// A simulation of either dimension with its particles.
enum Sim {
    Two(FlipSimulation<2>, Particles<2>),
    Three(FlipSimulation<3>, Particles<3>),
}

/// Runs `$body` with the simulation `$s`, particles `$p` and dimension `$d`.
macro_rules! each {
    ($sim:expr, $s:ident, $p:ident, $d:ident => $body:expr) => {
        match $sim {
            Sim::Two($s, $p) => {
                const $d: usize = 2;
                $body
            }
            Sim::Three($s, $p) => {
                const $d: usize = 3;
                $body
            }
        }
    };
}

/// A FLIP/APIC fluid on a grid of `cells` cells of side `h` (m), its particles.
#[pyclass(module = "anim.flip")]
pub struct Simulation {
    inner: Sim,
}

/// `FlipParams` from the defaults with the keys of `params` replaced (the crate's names:
/// `transfer`, `gravity`, `cfl`, `pressure`, `tolerance`, ...).
fn flip_params<const D: usize>(params: Option<&Bound<'_, PyAny>>) -> PyResult<FlipParams<D>> {
    let mut value = serde_json::to_value(FlipParams::<D>::default()).map_err(errors::build)?;
    if let Some(p) = params {
        let serde_json::Value::Object(given) = crate::json::of(p, "params")? else {
            return Err(PyValueError::new_err("params: expected a dict"));
        };
        let Some(base) = value.as_object_mut() else {
            return Err(errors::build("FlipParams is not a table"));
        };
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

fn flip_error(e: FlipError) -> PyErr {
    errors::step(e)
}

#[pymethods]
impl Simulation {
    /// A fluid domain of `cells` (2 or 3 counts: the dimension) cells of side `h` metres, with
    /// `params` over the crate's defaults; no particles yet.
    #[new]
    #[pyo3(signature = (cells, h, params = None))]
    fn new(cells: Vec<usize>, h: f64, params: Option<&Bound<'_, PyAny>>) -> PyResult<Self> {
        let inner = match cells.as_slice() {
            &[a, b] => Sim::Two(
                FlipSimulation::new([a, b], h, flip_params::<2>(params)?).map_err(errors::build)?,
                Particles::new(),
            ),
            &[a, b, c] => Sim::Three(
                FlipSimulation::new([a, b, c], h, flip_params::<3>(params)?).map_err(errors::build)?,
                Particles::new(),
            ),
            other => {
                return Err(PyValueError::new_err(format!(
                    "cells: expected 2 or 3 counts, got {}",
                    other.len()
                )));
            }
        };
        Ok(Self { inner })
    }

    /// Adds particles at `positions` (n, D) float64 with `velocities` (default at rest).
    #[pyo3(signature = (positions, velocities = None))]
    fn add_particles(
        &mut self,
        positions: &Bound<'_, PyAny>,
        velocities: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        each!(&mut self.inner, _s, p, D => {
            let (x, shape) = arrays::floats(positions, "positions", &[None, Some(D)])?;
            let n = shape[0];
            let v = match velocities {
                Some(v) => arrays::floats(v, "velocities", &[Some(n), Some(D)])?.0,
                None => vec![0.0; n * D],
            };
            for k in 0..n {
                p.push(std::array::from_fn(|i| x[k * D + i]), std::array::from_fn(|i| v[k * D + i]));
            }
            Ok(())
        })
    }

    /// Advances `steps` steps of `dt` seconds without the GIL (substeps where the CFL limit
    /// needs them); a failed step raises `anim.SimulationError`.
    #[pyo3(signature = (dt, steps = 1))]
    fn step(&mut self, py: Python<'_>, dt: f64, steps: usize) -> PyResult<()> {
        arrays::time_step(dt)?;
        each!(&mut self.inner, s, p, _D => {
            crate::threads::detached(py, || {
                for _ in 0..steps {
                    s.advance(p, dt)?;
                }
                Ok(())
            })
            .map_err(flip_error)
        })
    }

    /// Positions, (n, D) float64 (a copy).
    #[getter]
    fn positions<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        each!(&self.inner, _s, p, D => {
            let flat: Vec<f64> = p.x.iter().flatten().copied().collect();
            arrays::to_rows(py, &flat, D)
        })
    }
    /// Velocities, (n, D) float64 (a copy).
    #[getter]
    fn velocities<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        each!(&self.inner, _s, p, D => {
            let flat: Vec<f64> = p.v.iter().flatten().copied().collect();
            arrays::to_rows(py, &flat, D)
        })
    }
    /// Number of particles.
    #[getter]
    fn num_particles(&self) -> usize {
        each!(&self.inner, _s, p, _D => p.len())
    }
    /// Simulated time (s).
    #[getter]
    fn time(&self) -> f64 {
        each!(&self.inner, s, _p, _D => s.time())
    }
    /// The largest divergence of the grid velocity after the last projection.
    fn max_divergence(&self) -> f64 {
        each!(&self.inner, s, _p, _D => s.max_divergence())
    }
}

/// Registers `anim.flip`.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Simulation>()?;
    Ok(())
}
