//! `anim.io`: anim-io's mesh readers (OBJ, Gmsh `.msh`, TetGen `.node`/`.ele`, with validation)
//! and writers (OBJ, PLY, VTK `.vtu`).

use crate::arrays;
use crate::errors;
use anim::io::ply::Ply;
use anim::io::{IoError, UnstructuredGrid, VtkEncoding};
use pyo3::prelude::*;
use std::path::PathBuf;

/// An anim-io error: the file's I/O failures as `FileNotFoundError`/`OSError`, a malformed or
/// invalid mesh as `anim.BuildError` with the crate's message (file, line, element).
pub fn io_error(e: IoError) -> PyErr {
    match &e {
        IoError::Io { path, source } => errors::file(path, source),
        _ => errors::build(e),
    }
}

/// Reads and validates a triangle mesh by extension (`.obj`, polygons fan-triangulated;
/// `.msh`): `(vertices (n, 3) float64, triangles (m, 3) int64)`, new arrays.
#[pyfunction]
fn read_tri_mesh(py: Python<'_>, path: PathBuf) -> PyResult<arrays::MeshArrays<'_>> {
    let mesh = py.detach(|| anim::io::read_tri_mesh(&path)).map_err(io_error)?;
    let flat: Vec<f64> = mesh.positions.iter().flatten().copied().collect();
    Ok((arrays::to_rows(py, &flat, 3)?, arrays::to_index_rows(py, &mesh.triangles)?))
}

/// Reads and validates a tetrahedral mesh by extension (`.msh`, `.node`/`.ele`):
/// `(vertices (n, 3) float64, tets (m, 4) int64)`, new arrays.
#[pyfunction]
fn read_tet_mesh(py: Python<'_>, path: PathBuf) -> PyResult<arrays::MeshArrays<'_>> {
    let mesh = py.detach(|| anim::io::read_tet_mesh(&path)).map_err(io_error)?;
    let flat: Vec<f64> = mesh.positions.iter().flatten().copied().collect();
    Ok((arrays::to_rows(py, &flat, 3)?, arrays::to_index_rows(py, &mesh.tets)?))
}

/// Writes a triangle mesh as OBJ.
#[pyfunction]
fn write_obj(path: PathBuf, vertices: &Bound<'_, PyAny>, triangles: &Bound<'_, PyAny>) -> PyResult<()> {
    let v = arrays::rows::<3>(vertices, "vertices")?;
    let t = arrays::indices::<3>(triangles, "triangles", v.len())?;
    anim::io::obj::write_obj(&path, &v, &t, &[]).map_err(io_error)
}

/// Writes points and, optionally, triangles as binary PLY.
#[pyfunction]
#[pyo3(signature = (path, vertices, triangles = None))]
fn write_ply(
    path: PathBuf,
    vertices: &Bound<'_, PyAny>,
    triangles: Option<&Bound<'_, PyAny>>,
) -> PyResult<()> {
    let v = arrays::rows::<3>(vertices, "vertices")?;
    let t = match triangles {
        Some(t) => arrays::indices::<3>(t, "triangles", v.len())?,
        None => Vec::new(),
    };
    Ply::new(&v).triangles(&t).write(&path).map_err(io_error)
}

/// Writes a VTK unstructured grid (`.vtu`, base64-encoded) of points with optional triangles and
/// tetrahedra.
#[pyfunction]
#[pyo3(signature = (path, vertices, *, triangles = None, tets = None))]
fn write_vtu(
    path: PathBuf,
    vertices: &Bound<'_, PyAny>,
    triangles: Option<&Bound<'_, PyAny>>,
    tets: Option<&Bound<'_, PyAny>>,
) -> PyResult<()> {
    let v = arrays::rows::<3>(vertices, "vertices")?;
    let t = match triangles {
        Some(t) => arrays::indices::<3>(t, "triangles", v.len())?,
        None => Vec::new(),
    };
    let k = match tets {
        Some(k) => arrays::indices::<4>(k, "tets", v.len())?,
        None => Vec::new(),
    };
    UnstructuredGrid::new(&v).triangles(&t).tetrahedra(&k).write(&path, VtkEncoding::Base64).map_err(io_error)
}

/// Registers `anim.io`.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(read_tri_mesh, m)?)?;
    m.add_function(wrap_pyfunction!(read_tet_mesh, m)?)?;
    m.add_function(wrap_pyfunction!(write_obj, m)?)?;
    m.add_function(wrap_pyfunction!(write_ply, m)?)?;
    m.add_function(wrap_pyfunction!(write_vtu, m)?)?;
    Ok(())
}
