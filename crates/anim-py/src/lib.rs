//! Python bindings of the anim workspace: the native module `anim._anim` behind the Python
//! package `anim` (`pip install ./crates/anim-py`).
//!
//! Each submodule calls one crate's own library code with the crate's own names and parameter
//! spellings: [`scene`] the scene registry of the `anim` crate and the scene files and
//! `--tolerance` pick of `anim-cli`; [`pbd`] anim-pbd's builder and simulation; [`rigid`]
//! anim-rigid's checked entry points, named as in Pinocchio; [`mpm`] anim-mpm's particles;
//! [`io`] anim-io's mesh readers and writers; [`springs`] anim-springs' networks;
//! [`skin`] anim-skin's glTF characters; [`fem`] anim-fem's bodies and their stresses;
//! [`flip`] anim-flip's particle fluid; [`fluid`] anim-fluid's grids.
//! Arrays go in as numpy arrays checked at the boundary ([`arrays`]) and come back as new
//! arrays; steps and batch calls release the GIL.

pub mod arrays;
pub mod errors;
pub mod fem;
pub mod flip;
pub mod fluid;
pub mod io;
pub mod json;
pub mod mpm;
pub mod pbd;
pub mod rigid;
pub mod scene;
pub mod skin;
pub mod springs;
pub mod threads;

use pyo3::prelude::*;

/// Adds `child` as the submodule `name` of `parent`, importable as `anim.NAME`.
fn submodule(
    parent: &Bound<'_, PyModule>,
    name: &str,
    fill: impl FnOnce(&Bound<'_, PyModule>) -> PyResult<()>,
) -> PyResult<()> {
    let child = PyModule::new(parent.py(), name)?;
    fill(&child)?;
    parent.add_submodule(&child)?;
    Ok(())
}

/// The native module.
#[pymodule]
#[pyo3(name = "_anim")]
fn anim_native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    errors::register(m)?;
    submodule(m, "scene", scene::register)?;
    submodule(m, "pbd", pbd::register)?;
    submodule(m, "rigid", rigid::register)?;
    submodule(m, "mpm", mpm::register)?;
    submodule(m, "io", io::register)?;
    submodule(m, "springs", springs::register)?;
    submodule(m, "skin", skin::register)?;
    submodule(m, "fem", fem::register)?;
    submodule(m, "flip", flip::register)?;
    submodule(m, "fluid", fluid::register)?;
    Ok(())
}
