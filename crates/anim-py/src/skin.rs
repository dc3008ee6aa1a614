//! `anim.skin`: anim-skin's skinned characters loaded from glTF 2.0 (`.gltf`, `.glb`), their
//! animation clips sampled at any time, and the meshes skinned by linear blend (LBS) or
//! dual-quaternion (DQS) skinning.

use crate::arrays;
use crate::errors;
use anim::skin::{Character as SkinCharacter, CharacterData, SkinningMethod};
use numpy::PyArray2;
use pyo3::exceptions::{PyFileNotFoundError, PyValueError};
use pyo3::prelude::*;
use std::path::PathBuf;

/// A skinned character: skeleton, skins, meshes and clips, with its posed meshes.
#[pyclass(module = "anim.skin")]
pub struct Character {
    inner: SkinCharacter,
    data: CharacterData,
    warnings: Vec<String>,
}

#[pymethods]
impl Character {
    /// Loads a glTF 2.0 file (`FileNotFoundError` when missing, `anim.BuildError` naming the
    /// element otherwise); what the loader repaired is in `warnings`.
    #[staticmethod]
    fn load(py: Python<'_>, path: PathBuf) -> PyResult<Self> {
        if !path.exists() {
            return Err(PyFileNotFoundError::new_err(format!("{}: no such file", path.display())));
        }
        let loaded = py.detach(|| anim::skin::gltf_io::load(&path)).map_err(errors::build)?;
        let data = loaded.character.data();
        Ok(Self { inner: loaded.character, data, warnings: loaded.warnings })
    }

    /// What the loader reported and repaired (renormalised weights, ...).
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.warnings.clone()
    }
    /// The clips' names, in file order.
    #[getter]
    fn clips(&self) -> Vec<String> {
        self.inner.clips.iter().map(|c| c.name.clone()).collect()
    }
    /// The end time (s) of clip `clip` (an index or a name).
    fn clip_end(&self, clip: &Bound<'_, PyAny>) -> PyResult<f64> {
        let c = self.clip_index(clip)?;
        Ok(self.inner.clips[c].end())
    }
    /// Number of joints of the skeleton.
    #[getter]
    fn num_joints(&self) -> usize {
        self.inner.skeleton.len()
    }
    /// Number of vertices of all meshes.
    #[getter]
    fn num_vertices(&self) -> usize {
        self.inner.num_vertices()
    }
    /// Triangles of all meshes, (m, 3) int64 indices into the concatenated vertices (a copy).
    #[getter]
    fn triangles<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<i64>>> {
        let t: Vec<[usize; 3]> = self.inner.triangles().iter().map(|t| t.map(|i| i as usize)).collect();
        arrays::to_index_rows(py, &t)
    }

    /// Samples clip `clip` (an index or a name; None: the rest pose) at time `t` (s) and skins
    /// every mesh with `method` (`"lbs"` or `"dqs"`), without the GIL. Returns the posed
    /// positions of all meshes, (n, 3) float64 (a new array).
    #[pyo3(signature = (clip = None, t = 0.0, method = "lbs"))]
    fn pose<'py>(
        &mut self,
        py: Python<'py>,
        clip: Option<&Bound<'_, PyAny>>,
        t: f64,
        method: &str,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        if !t.is_finite() {
            return Err(PyValueError::new_err(format!("t: must be finite, got {t}")));
        }
        let method: SkinningMethod =
            method.parse().map_err(|e: String| PyValueError::new_err(format!("method: {e}")))?;
        let clip = clip.map(|c| self.clip_index(c)).transpose()?;
        let Self { inner, data, .. } = self;
        crate::threads::detached(py, || inner.pose(data, clip, t, method)).map_err(errors::step)?;
        let mut out = Vec::new();
        self.data.positions(&mut out);
        let flat: Vec<f64> = out.iter().flatten().copied().collect();
        arrays::to_rows(py, &flat, 3)
    }
}

impl Character {
    fn clip_index(&self, clip: &Bound<'_, PyAny>) -> PyResult<usize> {
        let n = self.inner.clips.len();
        if let Ok(i) = clip.extract::<i64>() {
            return if i >= 0 && (i as u64) < n as u64 {
                Ok(i as usize)
            } else {
                Err(PyValueError::new_err(format!("clip: {i} is outside 0..{n}")))
            };
        }
        let name: String =
            clip.extract().map_err(|_| PyValueError::new_err("clip: expected an index or a name"))?;
        self.inner.clips.iter().position(|c| c.name == name).ok_or_else(|| {
            let names: Vec<&str> = self.inner.clips.iter().map(|c| c.name.as_str()).collect();
            PyValueError::new_err(format!("clip: no clip named {name:?} (one of {names:?})"))
        })
    }
}

/// Registers `anim.skin`.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Character>()?;
    Ok(())
}
