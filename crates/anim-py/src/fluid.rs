//! `anim.fluid`: anim-fluid's grid fluids (Stam's stable fluids, the MAC solver with its
//! pressure solvers) through the crate's scenes, with the density and velocity fields as numpy
//! arrays shaped like the grid.

use crate::arrays;
use crate::errors;
use anim::fluid::FluidError;
use anim::fluid::scenes::{self, FluidScene};
use numpy::PyArrayDyn;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

/// A grid fluid scene of anim-fluid.
#[pyclass(module = "anim.fluid")]
pub struct Scene {
    inner: FluidScene,
}

impl Scene {
    /// The grid shape as numpy indexes it: (ny, nx) or (nz, ny, nx).
    fn shape(&self) -> Vec<usize> {
        let [nx, ny, nz] = self.inner.dims();
        if self.inner.dim() == 2 { vec![ny, nx] } else { vec![nz, ny, nx] }
    }
}

#[pymethods]
impl Scene {
    /// The crate's scene `name` (`smoke-box-2d`, `smoke-plume-3d`, `lid-driven-cavity`) at
    /// `resolution` cells per axis (default the scene's).
    #[new]
    #[pyo3(signature = (name, resolution = None))]
    fn new(py: Python<'_>, name: &str, resolution: Option<usize>) -> PyResult<Self> {
        let built = py.detach(|| scenes::by_name(name, resolution));
        let inner = built
            .ok_or_else(|| {
                PyValueError::new_err(format!(
                    "name: no scene {name:?} (one of {})",
                    scenes::NAMES.join(", ")
                ))
            })?
            .map_err(errors::build)?;
        Ok(Self { inner })
    }

    /// Advances `steps` steps of the scene's step, or of `dt` seconds when given, without the GIL.
    #[pyo3(signature = (steps = 1, dt = None))]
    fn step(&mut self, py: Python<'_>, steps: usize, dt: Option<f64>) -> PyResult<()> {
        if let Some(dt) = dt {
            arrays::time_step(dt)?;
        }
        let inner = &mut self.inner;
        crate::threads::detached(py, || {
            for _ in 0..steps {
                match dt {
                    Some(dt) => inner.step_by(dt)?,
                    None => inner.step()?,
                };
            }
            Ok(())
        })
        .map_err(|e: FluidError| errors::step(e))
    }

    /// 2 or 3.
    #[getter]
    fn dim(&self) -> usize {
        self.inner.dim()
    }
    /// Simulated time (s).
    #[getter]
    fn time(&self) -> f64 {
        self.inner.time()
    }
    /// Cell size (m).
    #[getter]
    fn cell_size(&self) -> f64 {
        self.inner.cell_size()
    }
    /// The density of every cell, (ny, nx) or (nz, ny, nx) float64 (a new array).
    fn density<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let (d, _) = self.inner.density();
        arrays::to_array(py, &d, &self.shape())
    }
    /// The velocity at the cell centres, (ny, nx, 2) or (nz, ny, nx, 3) float64 (a new array).
    fn velocity<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let (v, _) = self.inner.velocity();
        let dim = self.inner.dim();
        let flat: Vec<f64> = v.iter().flat_map(|c| c[..dim].to_vec()).collect();
        let mut shape = self.shape();
        shape.push(dim);
        arrays::to_array(py, &flat, &shape)
    }
}

/// Registers `anim.fluid`.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Scene>()?;
    m.add("SCENES", scenes::NAMES.to_vec())?;
    Ok(())
}
