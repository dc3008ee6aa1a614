//! `anim.rigid`: anim-rigid's articulated-body algorithms with Pinocchio's names and argument
//! order (`rnea(model, data, q, v, a)`, `crba(model, data, q)`, `aba(model, data, q, v, tau)`,
//! `forward_kinematics`, `get_frame_jacobian`, ...), through the crate's checked entry points
//! ([`anim::rigid::checked`]): a wrong length, a non-finite entry, a joint or frame index out of
//! range or a `Data` made for another model raises `ValueError` with the crate's message.
//!
//! Joint order, names, frames and the velocity layout are Pinocchio's; the configuration `q`
//! differs for continuous joints (an angle here, `(cos, sin)` in Pinocchio): `to_pinocchio` and
//! `from_pinocchio` convert ([`anim::rigid::pinocchio`]).

use crate::arrays;
use crate::errors;
use anim::core::glam::{DMat3, DVec3};
use anim::core::lie::Se3;
use anim::rigid::{
    self as rigid, IkParams, Jacobian, NumericalIk, ReferenceFrame, UrdfCause, UrdfOptions, checked,
};
use numpy::{PyArray1, PyArray2, PyArray3, PyArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use std::sync::Arc;

/// A kinematic tree with its inertias and frames (anim-rigid's `Model`), immutable.
#[pyclass(module = "anim.rigid", frozen)]
pub struct Model {
    inner: Arc<rigid::Model>,
}

/// The workspace of the algorithms for one model (anim-rigid's `Data`): placements, Jacobians,
/// the mass matrix, torques; read its fields after the algorithm that fills them.
#[pyclass(module = "anim.rigid")]
pub struct Data {
    inner: rigid::Data,
    jacobian: Jacobian,
    model: Arc<rigid::Model>,
}

/// A URDF error: `FileNotFoundError`/`OSError` when the file cannot be read, else
/// `anim.BuildError` with the crate's message (file, line, element, cause).
fn urdf_error(e: rigid::UrdfError, path: Option<&str>) -> PyErr {
    if let (UrdfCause::Io(message), Some(path)) = (&*e.cause, path) {
        let p = std::path::Path::new(path);
        if !p.exists() {
            return pyo3::exceptions::PyFileNotFoundError::new_err(format!("{path}: {message}"));
        }
        return pyo3::exceptions::PyOSError::new_err(format!("{path}: {message}"));
    }
    errors::build(e)
}

/// The loading options; `locked_joints` is a list of joint names (locked at 0) or a dict of
/// names to positions.
fn options(
    floating_base: bool,
    mimic: bool,
    locked_joints: Option<&Bound<'_, PyAny>>,
) -> PyResult<UrdfOptions> {
    let mut o = UrdfOptions::default().floating_base(floating_base).couple_mimic_joints(mimic);
    if let Some(locked) = locked_joints {
        let pairs: Vec<(String, f64)> =
            if let Ok(map) = locked.extract::<std::collections::BTreeMap<String, f64>>() {
                map.into_iter().collect()
            } else if let Ok(names) = locked.extract::<Vec<String>>() {
                names.into_iter().map(|n| (n, 0.0)).collect()
            } else {
                return Err(pyo3::exceptions::PyTypeError::new_err(
                    "locked_joints: expected a list of joint names or a dict of names to positions",
                ));
            };
        for (name, position) in pairs {
            o = o.lock_joint(&name, position);
        }
    }
    Ok(o)
}

/// Loads a URDF file (Pinocchio's `buildModelFromUrdf`): fixed joints merged into frames;
/// `floating_base` carries the root by a free joint `root_joint`; `mimic` couples `<mimic>`
/// joints to their masters; `locked_joints` (names, or names to positions) become fixed.
#[pyfunction]
#[pyo3(signature = (path, *, floating_base = false, mimic = false, locked_joints = None))]
fn build_model_from_urdf(
    path: std::path::PathBuf,
    floating_base: bool,
    mimic: bool,
    locked_joints: Option<&Bound<'_, PyAny>>,
) -> PyResult<Model> {
    let text = path.to_string_lossy().into_owned();
    let o = options(floating_base, mimic, locked_joints)?;
    let model = rigid::load_urdf(&path, &o).map_err(|e| urdf_error(e, Some(&text)))?;
    Ok(Model { inner: Arc::new(model) })
}

/// Parses URDF text (Pinocchio's `buildModelFromXML`); options as `build_model_from_urdf`.
#[pyfunction]
#[pyo3(signature = (xml, *, floating_base = false, mimic = false, locked_joints = None))]
fn build_model_from_xml(
    xml: &str,
    floating_base: bool,
    mimic: bool,
    locked_joints: Option<&Bound<'_, PyAny>>,
) -> PyResult<Model> {
    let o = options(floating_base, mimic, locked_joints)?;
    let model = rigid::parse_urdf(xml, &o).map_err(|e| urdf_error(e, None))?;
    Ok(Model { inner: Arc::new(model) })
}

#[pymethods]
impl Model {
    /// The model's name.
    #[getter]
    fn name(&self) -> String {
        self.inner.name().to_string()
    }
    /// Size of a configuration `q`.
    #[getter]
    fn nq(&self) -> usize {
        self.inner.nq()
    }
    /// Size of a velocity `v` (and of `a`, `tau`).
    #[getter]
    fn nv(&self) -> usize {
        self.inner.nv()
    }
    /// Number of joints, the universe (joint 0) included.
    #[getter]
    fn njoints(&self) -> usize {
        self.inner.njoints()
    }
    /// Number of frames.
    #[getter]
    fn nframes(&self) -> usize {
        self.inner.frames().len()
    }
    /// Joint names, in joint order (`names[0]` is `universe`).
    #[getter]
    fn names(&self) -> Vec<String> {
        self.inner.joints().iter().map(|j| j.name.clone()).collect()
    }
    /// Frame names, in frame order.
    #[getter]
    fn frame_names(&self) -> Vec<String> {
        self.inner.frames().iter().map(|f| f.name.clone()).collect()
    }
    /// Lower joint limits, (nq,) float64 (a copy; -inf where unlimited).
    #[getter]
    fn lower_position_limit<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, self.inner.lower_limits())
    }
    /// Upper joint limits, (nq,) float64 (a copy; inf where unlimited).
    #[getter]
    fn upper_position_limit<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, self.inner.upper_limits())
    }
    /// Gravity (m/s^2), (3,) float64.
    #[getter]
    fn gravity<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.inner.gravity().to_array())
    }
    /// Total mass (kg).
    fn total_mass(&self) -> f64 {
        self.inner.total_mass()
    }
    /// The index of frame `name` (Pinocchio's `getFrameId`); `ValueError` if there is none.
    fn get_frame_id(&self, name: &str) -> PyResult<usize> {
        self.inner
            .frame_id(name)
            .ok_or_else(|| PyValueError::new_err(format!("name: no frame named {name:?}")))
    }
    /// The index of joint `name` (Pinocchio's `getJointId`); `ValueError` if there is none.
    fn get_joint_id(&self, name: &str) -> PyResult<usize> {
        self.inner
            .joint_id(name)
            .ok_or_else(|| PyValueError::new_err(format!("name: no joint named {name:?}")))
    }
    /// A new `Data` for this model (Pinocchio's `createData`).
    fn create_data(&self) -> Data {
        Data::for_model(&self.inner)
    }
    fn __repr__(&self) -> String {
        format!(
            "Model(name={:?}, nq={}, nv={}, njoints={})",
            self.inner.name(),
            self.inner.nq(),
            self.inner.nv(),
            self.inner.njoints()
        )
    }
}

impl Data {
    fn for_model(model: &Arc<rigid::Model>) -> Self {
        Self {
            inner: rigid::Data::new(model),
            jacobian: Jacobian::zeros(model.nv()),
            model: Arc::clone(model),
        }
    }
}

/// A placement as a (4, 4) homogeneous matrix, row-major.
fn homogeneous(g: &Se3) -> [f64; 16] {
    let r = g.rotation;
    let t = g.translation;
    let mut m = [0.0; 16];
    for i in 0..3 {
        for j in 0..3 {
            m[4 * i + j] = r.col(j)[i];
        }
        m[4 * i + 3] = t[i];
    }
    m[15] = 1.0;
    m
}

/// Placements as an (n, 4, 4) array.
fn placements<'py>(py: Python<'py>, gs: &[Se3]) -> PyResult<Bound<'py, PyArray3<f64>>> {
    let flat: Vec<f64> = gs.iter().flat_map(homogeneous).collect();
    PyArray1::from_vec(py, flat).reshape([gs.len(), 4, 4])
}

#[pymethods]
impl Data {
    /// A new `Data` for `model`.
    #[new]
    fn new(model: &Model) -> Self {
        Self::for_model(&model.inner)
    }
    /// World placements of the joints, (njoints, 4, 4) float64 (a copy; Pinocchio's `oMi`).
    #[getter(oMi)]
    fn o_m_i<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray3<f64>>> {
        placements(py, &self.inner.world_placements)
    }
    /// World placements of the frames, (nframes, 4, 4) float64 (a copy; Pinocchio's `oMf`).
    #[getter(oMf)]
    fn o_m_f<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray3<f64>>> {
        placements(py, &self.inner.frame_placements)
    }
    /// The last torques of `rnea`, (nv,) float64 (a copy).
    #[getter]
    fn tau<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.inner.tau)
    }
    /// The last accelerations of `aba`, (nv,) float64 (a copy).
    #[getter]
    fn ddq<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.inner.ddq)
    }
    /// The last mass matrix of `crba`, (nv, nv) float64, both triangles (a copy; Pinocchio's `M`).
    #[getter(M)]
    fn mass_matrix<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let m = &self.inner.mass_matrix;
        arrays::to_rows(py, m.as_slice(), m.n())
    }
    /// The world Jacobian of every joint from `compute_joint_jacobians`, (6, nv) float64 (a copy;
    /// Pinocchio's `J`), rows (linear, angular).
    #[getter(J)]
    fn joint_jacobians<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        jacobian_array(py, &self.inner.jacobian)
    }
}

/// A Jacobian as a (6, nv) array, rows (linear, angular) as in Pinocchio.
fn jacobian_array<'py>(py: Python<'py>, j: &Jacobian) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let rows = j.to_rows();
    let flat: Vec<f64> = rows.iter().flatten().copied().collect();
    PyArray1::from_vec(py, flat).reshape([6, j.ncols()])
}

/// `data` checked against `model`: `ValueError` when it was made for another model.
fn fits(model: &Model, data: &Data) -> PyResult<()> {
    if Arc::ptr_eq(&model.inner, &data.model) || data.inner.fits(&model.inner) {
        Ok(())
    } else {
        Err(PyValueError::new_err("data: made for another model (use model.create_data())"))
    }
}

/// The configuration of every joint at zero (identity quaternions; Pinocchio's `neutral`).
#[pyfunction]
fn neutral<'py>(py: Python<'py>, model: &Model) -> Bound<'py, PyArray1<f64>> {
    PyArray1::from_vec(py, rigid::config::neutral(&model.inner))
}

/// A random configuration within the joint limits (Pinocchio's `randomConfiguration`),
/// reproducible from `seed`.
#[pyfunction]
#[pyo3(signature = (model, seed = 0))]
fn random_configuration<'py>(py: Python<'py>, model: &Model, seed: u64) -> Bound<'py, PyArray1<f64>> {
    // SplitMix64 (Steele et al. 2014), mapped to [0, 1) with 53 bits.
    let mut s = seed;
    let mut uniform = move || {
        s = s.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = s;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^= z >> 31;
        (z >> 11) as f64 / (1u64 << 53) as f64
    };
    PyArray1::from_vec(py, rigid::config::random_configuration(&model.inner, &mut uniform))
}

/// `q ⊕ v`: integrates the velocity `v` over unit time from `q` (Pinocchio's `integrate`).
#[pyfunction]
fn integrate<'py>(
    py: Python<'py>,
    model: &Model,
    q: &Bound<'_, PyAny>,
    v: &Bound<'_, PyAny>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let q = arrays::vector(q, "q", None)?;
    let v = arrays::vector(v, "v", None)?;
    let out = checked::integrate(&model.inner, &q, &v, 1.0).map_err(errors::value)?;
    Ok(PyArray1::from_vec(py, out))
}

/// `q1 ⊖ q0`: the velocity that takes `q0` to `q1` in unit time (Pinocchio's `difference`).
#[pyfunction]
fn difference<'py>(
    py: Python<'py>,
    model: &Model,
    q0: &Bound<'_, PyAny>,
    q1: &Bound<'_, PyAny>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let q0 = arrays::vector(q0, "q0", None)?;
    let q1 = arrays::vector(q1, "q1", None)?;
    let out = checked::difference(&model.inner, &q0, &q1).map_err(errors::value)?;
    Ok(PyArray1::from_vec(py, out))
}

/// `q` in Pinocchio's layout: each continuous joint's angle as `(cos θ, sin θ)`, each planar
/// joint's `(x, y, θ)` as `(x, y, cos θ, sin θ)`.
#[pyfunction]
fn to_pinocchio<'py>(
    py: Python<'py>,
    model: &Model,
    q: &Bound<'_, PyAny>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let q = arrays::vector(q, "q", None)?;
    let out = rigid::pinocchio::to_pinocchio(&model.inner, &q).map_err(errors::value)?;
    Ok(PyArray1::from_vec(py, out))
}

/// `q` from Pinocchio's layout (the inverse of `to_pinocchio`; angles wrapped into (-π, π]).
#[pyfunction]
fn from_pinocchio<'py>(
    py: Python<'py>,
    model: &Model,
    q: &Bound<'_, PyAny>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let q = arrays::vector(q, "q", None)?;
    let out = rigid::pinocchio::from_pinocchio(&model.inner, &q).map_err(errors::value)?;
    Ok(PyArray1::from_vec(py, out))
}

/// Pinocchio's `nq` of `model` (one more per continuous or planar joint).
#[pyfunction]
fn pinocchio_nq(model: &Model) -> usize {
    rigid::pinocchio::nq(&model.inner)
}

/// Joint placements for `q` (Pinocchio's `forwardKinematics`); read `data.oMi`.
#[pyfunction]
fn forward_kinematics(model: &Model, data: &mut Data, q: &Bound<'_, PyAny>) -> PyResult<()> {
    fits(model, data)?;
    let q = arrays::vector(q, "q", None)?;
    checked::forward_kinematics(&model.inner, &mut data.inner, &q).map_err(errors::value)
}

/// Frame placements from the joint placements (Pinocchio's `updateFramePlacements`).
#[pyfunction]
fn update_frame_placements(model: &Model, data: &mut Data) -> PyResult<()> {
    fits(model, data)?;
    rigid::update_frame_placements(&model.inner, &mut data.inner);
    Ok(())
}

/// `forward_kinematics` then `update_frame_placements` (Pinocchio's `framesForwardKinematics`).
#[pyfunction]
fn frames_forward_kinematics(model: &Model, data: &mut Data, q: &Bound<'_, PyAny>) -> PyResult<()> {
    fits(model, data)?;
    let q = arrays::vector(q, "q", None)?;
    checked::frames_forward_kinematics(&model.inner, &mut data.inner, &q).map_err(errors::value)
}

/// The world placement of frame `frame_id`, (4, 4) float64 (a copy), after
/// `frames_forward_kinematics`.
#[pyfunction]
fn frame_placement<'py>(
    py: Python<'py>,
    model: &Model,
    data: &Data,
    frame_id: usize,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    fits(model, data)?;
    let n = model.inner.frames().len();
    let g = data
        .inner
        .frame_placements
        .get(frame_id)
        .filter(|_| frame_id < n)
        .ok_or_else(|| PyValueError::new_err(format!("frame_id: {frame_id} is outside 0..{n}")))?;
    PyArray1::from_slice(py, &homogeneous(g)).reshape([4, 4])
}

/// A rotation (3, 3) and a translation (3,).
type RotationTranslation<'py> = (Bound<'py, PyArray2<f64>>, Bound<'py, PyArray1<f64>>);

/// The world placement of frame `frame_id` as `(R, p)`: (3, 3) and (3,) float64 (copies).
#[pyfunction]
fn frame_rotation_translation<'py>(
    py: Python<'py>,
    model: &Model,
    data: &Data,
    frame_id: usize,
) -> PyResult<RotationTranslation<'py>> {
    let m = frame_placement(py, model, data, frame_id)?;
    let m = m.readonly();
    let a = m.as_array();
    let r: Vec<f64> = (0..3).flat_map(|i| (0..3).map(move |j| (i, j))).map(|(i, j)| a[[i, j]]).collect();
    let p = vec![a[[0, 3]], a[[1, 3]], a[[2, 3]]];
    Ok((PyArray1::from_vec(py, r).reshape([3, 3])?, PyArray1::from_vec(py, p)))
}

/// A reference frame by name: `"world"`, `"local"` or `"local_world_aligned"` (Pinocchio's
/// `ReferenceFrame.WORLD`, `LOCAL`, `LOCAL_WORLD_ALIGNED`).
fn reference(name: &str) -> PyResult<ReferenceFrame> {
    match name.to_ascii_lowercase().as_str() {
        "world" => Ok(ReferenceFrame::World),
        "local" => Ok(ReferenceFrame::Local),
        "local_world_aligned" => Ok(ReferenceFrame::LocalWorldAligned),
        _ => Err(PyValueError::new_err(format!(
            "reference_frame: unknown value {name:?} (one of world, local, local_world_aligned)"
        ))),
    }
}

/// Every joint's world Jacobian and placement for `q` (Pinocchio's `computeJointJacobians`).
#[pyfunction]
fn compute_joint_jacobians(model: &Model, data: &mut Data, q: &Bound<'_, PyAny>) -> PyResult<()> {
    fits(model, data)?;
    let q = arrays::vector(q, "q", None)?;
    checked::compute_joint_jacobians(&model.inner, &mut data.inner, &q).map_err(errors::value)
}

/// The Jacobian of frame `frame_id` in `reference_frame`, (6, nv) float64 (a new array), rows
/// (linear, angular), from the last `compute_joint_jacobians` (Pinocchio's `getFrameJacobian`).
#[pyfunction]
#[pyo3(signature = (model, data, frame_id, reference_frame = "local"))]
fn get_frame_jacobian<'py>(
    py: Python<'py>,
    model: &Model,
    data: &mut Data,
    frame_id: usize,
    reference_frame: &str,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    fits(model, data)?;
    let rf = reference(reference_frame)?;
    let Data { inner, jacobian, .. } = data;
    checked::frame_jacobian(&model.inner, inner, frame_id, rf, jacobian).map_err(errors::value)?;
    jacobian_array(py, jacobian)
}

/// `compute_joint_jacobians(q)` then `get_frame_jacobian` (Pinocchio's `computeFrameJacobian`).
#[pyfunction]
#[pyo3(signature = (model, data, q, frame_id, reference_frame = "local"))]
fn compute_frame_jacobian<'py>(
    py: Python<'py>,
    model: &Model,
    data: &mut Data,
    q: &Bound<'_, PyAny>,
    frame_id: usize,
    reference_frame: &str,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    compute_joint_jacobians(model, data, q)?;
    get_frame_jacobian(py, model, data, frame_id, reference_frame)
}

/// Inverse dynamics by the recursive Newton-Euler algorithm: `tau = M(q) a + C(q, v) v + g(q)`,
/// (nv,) float64 (a new array; also `data.tau`).
#[pyfunction]
fn rnea<'py>(
    py: Python<'py>,
    model: &Model,
    data: &mut Data,
    q: &Bound<'_, PyAny>,
    v: &Bound<'_, PyAny>,
    a: &Bound<'_, PyAny>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    fits(model, data)?;
    let q = arrays::vector(q, "q", None)?;
    let v = arrays::vector(v, "v", None)?;
    let a = arrays::vector(a, "a", None)?;
    let tau = checked::rnea(&model.inner, &mut data.inner, &q, &v, &a).map_err(errors::value)?;
    Ok(PyArray1::from_slice(py, tau))
}

/// The bias forces `C(q, v) v + g(q)`, (nv,) float64 (Pinocchio's `nonLinearEffects`).
#[pyfunction]
fn nonlinear_effects<'py>(
    py: Python<'py>,
    model: &Model,
    data: &mut Data,
    q: &Bound<'_, PyAny>,
    v: &Bound<'_, PyAny>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    fits(model, data)?;
    let q = arrays::vector(q, "q", None)?;
    let v = arrays::vector(v, "v", None)?;
    let out = checked::nonlinear_effects(&model.inner, &mut data.inner, &q, &v).map_err(errors::value)?;
    Ok(PyArray1::from_slice(py, out))
}

/// The gravity torques `g(q)`, (nv,) float64 (Pinocchio's `computeGeneralizedGravity`).
#[pyfunction]
fn compute_generalized_gravity<'py>(
    py: Python<'py>,
    model: &Model,
    data: &mut Data,
    q: &Bound<'_, PyAny>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    fits(model, data)?;
    let q = arrays::vector(q, "q", None)?;
    let out = checked::gravity_torques(&model.inner, &mut data.inner, &q).map_err(errors::value)?;
    Ok(PyArray1::from_slice(py, out))
}

/// The joint-space mass matrix by the composite-rigid-body algorithm, (nv, nv) float64, both
/// triangles (a new array; also `data.M`).
#[pyfunction]
fn crba<'py>(
    py: Python<'py>,
    model: &Model,
    data: &mut Data,
    q: &Bound<'_, PyAny>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    fits(model, data)?;
    let q = arrays::vector(q, "q", None)?;
    let m = checked::crba(&model.inner, &mut data.inner, &q).map_err(errors::value)?;
    arrays::to_rows(py, m.as_slice(), m.n())
}

/// Forward dynamics by the articulated-body algorithm: `ddq = M(q)^-1 (tau - C(q, v) v - g(q))`,
/// (nv,) float64 (a new array; also `data.ddq`).
#[pyfunction]
fn aba<'py>(
    py: Python<'py>,
    model: &Model,
    data: &mut Data,
    q: &Bound<'_, PyAny>,
    v: &Bound<'_, PyAny>,
    tau: &Bound<'_, PyAny>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    fits(model, data)?;
    let q = arrays::vector(q, "q", None)?;
    let v = arrays::vector(v, "v", None)?;
    let tau = arrays::vector(tau, "tau", None)?;
    let ddq = checked::aba(&model.inner, &mut data.inner, &q, &v, &tau).map_err(errors::value)?;
    Ok(PyArray1::from_slice(py, ddq))
}

/// A batch of `rnea` calls on the rows of `q` (N, nq), `v` and `a` (N, nv), without the GIL:
/// (N, nv) float64.
#[pyfunction]
fn rnea_batch<'py>(
    py: Python<'py>,
    model: &Model,
    data: &mut Data,
    q: &Bound<'_, PyAny>,
    v: &Bound<'_, PyAny>,
    a: &Bound<'_, PyAny>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    fits(model, data)?;
    let (nq, nv) = (model.inner.nq(), model.inner.nv());
    let (q, shape) = arrays::floats(q, "q", &[None, Some(nq)])?;
    let n = shape[0];
    let (v, _) = arrays::floats(v, "v", &[Some(n), Some(nv)])?;
    let (a, _) = arrays::floats(a, "a", &[Some(n), Some(nv)])?;
    let m = &model.inner;
    let d = &mut data.inner;
    let out = py
        .detach(|| {
            let mut out = Vec::with_capacity(n * nv);
            for k in 0..n {
                let tau = checked::rnea(
                    m,
                    d,
                    &q[k * nq..(k + 1) * nq],
                    &v[k * nv..(k + 1) * nv],
                    &a[k * nv..(k + 1) * nv],
                )
                .map_err(|e| format!("row {k}: {e}"))?;
                out.extend_from_slice(tau);
            }
            Ok::<_, String>(out)
        })
        .map_err(PyValueError::new_err)?;
    arrays::to_rows(py, &out, nv)
}

/// A placement from a (4, 4) homogeneous matrix whose rotation block is orthonormal.
fn se3_from(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<Se3> {
    let (m, _) = arrays::floats(obj, name, &[Some(4), Some(4)])?;
    let col = |j: usize| DVec3::new(m[j], m[4 + j], m[8 + j]);
    let rotation = DMat3::from_cols(col(0), col(1), col(2));
    let off = (rotation.transpose() * rotation - DMat3::IDENTITY)
        .abs()
        .to_cols_array()
        .iter()
        .fold(0.0f64, |a, b| a.max(*b));
    if off > 1e-6 || rotation.determinant() <= 0.0 {
        return Err(PyValueError::new_err(format!(
            "{name}: the rotation block is not a rotation (|RᵀR - I| = {off:.2e})"
        )));
    }
    Ok(Se3 { rotation, translation: DVec3::new(m[3], m[7], m[11]) })
}

/// Damped-least-squares inverse kinematics of frame `frame_id` to the (4, 4) placement
/// `target`, from `q_init` (default the middle of the joint ranges), with random restarts
/// (anim-rigid's `NumericalIk`, Levenberg-Marquardt). Returns a dict: `q`, `success`, `error`,
/// `position_error`, `rotation_error`, `iterations`, `attempts`.
#[pyfunction]
#[pyo3(signature = (model, frame_id, target, q_init = None, *, tolerance = 1e-10, max_iterations = 100, restarts = 30, seed = 0x5eed))]
fn inverse_kinematics<'py>(
    py: Python<'py>,
    model: &Model,
    frame_id: usize,
    target: &Bound<'_, PyAny>,
    q_init: Option<&Bound<'_, PyAny>>,
    tolerance: f64,
    max_iterations: usize,
    restarts: usize,
    seed: u64,
) -> PyResult<Bound<'py, pyo3::types::PyDict>> {
    let m = &model.inner;
    let n = m.frames().len();
    if frame_id >= n {
        return Err(PyValueError::new_err(format!("frame_id: {frame_id} is outside 0..{n}")));
    }
    let target = se3_from(target, "target")?;
    let mut params = IkParams::default();
    params.tolerance = tolerance;
    params.max_iterations = max_iterations;
    params.restarts = restarts;
    params.seed = seed;
    let mut ik = NumericalIk::new(m, frame_id, params);
    let q0 = match q_init {
        Some(q) => {
            let q = arrays::vector(q, "q_init", None)?;
            rigid::checked::check_configuration(m, "q_init", &q).map_err(errors::value)?;
            q
        }
        None => ik.mid_configuration(m),
    };
    let report = py.detach(|| ik.solve(m, &target, &q0));
    let d = pyo3::types::PyDict::new(py);
    d.set_item("q", PyArray1::from_vec(py, report.q))?;
    d.set_item("success", report.success)?;
    d.set_item("error", report.error)?;
    d.set_item("position_error", report.position_error)?;
    d.set_item("rotation_error", report.rotation_error)?;
    d.set_item("iterations", report.iterations)?;
    d.set_item("attempts", report.attempts)?;
    Ok(d)
}

/// Registers `anim.rigid`.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Model>()?;
    m.add_class::<Data>()?;
    m.add("WORLD", "world")?;
    m.add("LOCAL", "local")?;
    m.add("LOCAL_WORLD_ALIGNED", "local_world_aligned")?;
    m.add_function(wrap_pyfunction!(build_model_from_urdf, m)?)?;
    m.add_function(wrap_pyfunction!(build_model_from_xml, m)?)?;
    m.add_function(wrap_pyfunction!(neutral, m)?)?;
    m.add_function(wrap_pyfunction!(random_configuration, m)?)?;
    m.add_function(wrap_pyfunction!(integrate, m)?)?;
    m.add_function(wrap_pyfunction!(difference, m)?)?;
    m.add_function(wrap_pyfunction!(to_pinocchio, m)?)?;
    m.add_function(wrap_pyfunction!(from_pinocchio, m)?)?;
    m.add_function(wrap_pyfunction!(pinocchio_nq, m)?)?;
    m.add_function(wrap_pyfunction!(forward_kinematics, m)?)?;
    m.add_function(wrap_pyfunction!(update_frame_placements, m)?)?;
    m.add_function(wrap_pyfunction!(frames_forward_kinematics, m)?)?;
    m.add_function(wrap_pyfunction!(frame_placement, m)?)?;
    m.add_function(wrap_pyfunction!(frame_rotation_translation, m)?)?;
    m.add_function(wrap_pyfunction!(compute_joint_jacobians, m)?)?;
    m.add_function(wrap_pyfunction!(get_frame_jacobian, m)?)?;
    m.add_function(wrap_pyfunction!(compute_frame_jacobian, m)?)?;
    m.add_function(wrap_pyfunction!(rnea, m)?)?;
    m.add_function(wrap_pyfunction!(rnea_batch, m)?)?;
    m.add_function(wrap_pyfunction!(nonlinear_effects, m)?)?;
    m.add_function(wrap_pyfunction!(compute_generalized_gravity, m)?)?;
    m.add_function(wrap_pyfunction!(crba, m)?)?;
    m.add_function(wrap_pyfunction!(aba, m)?)?;
    m.add_function(wrap_pyfunction!(inverse_kinematics, m)?)?;
    Ok(())
}
