//! The checked entry points: the algorithms of the crate root with every input validated first,
//! returning an [`InputError`] instead of panicking.
//!
//! The functions of the crate root ([`crate::forward_kinematics`], [`crate::rnea`],
//! [`crate::aba`], [`crate::config::integrate`], ...) are the **unchecked hot path**: they
//! assume well-formed input, panic (with a message naming the slice and the lengths) when a
//! slice has the wrong length or `data` was made for another model, and let a NaN or an
//! infinity in `q`, `v`, `a` or `tau` flow into their results. They are what a simulation step
//! calls thousands of times.
//!
//! The functions here have the same names and arguments and check, before calling them:
//!
//! - the length of every joint-space slice (`q`: `nq`; `v`, `a`, `tau`: `nv`; outputs likewise);
//! - that every entry is finite ([`InputError::NonFinite`] names the slice, the entry and the
//!   joint it belongs to), and that `dt` is;
//! - that the quaternion of every spherical and free joint is not zero (it is normalised);
//! - that `data` was made for `model` ([`Data::new`]), that joint and frame indices exist and an
//!   output Jacobian has `nv` columns.
//!
//! They allocate nothing more than the algorithm they call (checks read the slices only), and cost
//! one pass over the inputs. Use them at a program's boundary, where `q` comes from a user, a file
//! or another library.

use thiserror::Error;

use crate::data::Data;
use crate::dense::SquareMatrix;
use crate::dynamics::DynamicsError;
use crate::jacobian::ReferenceFrame;
use crate::matrix6x::Jacobian;
use crate::model::{FrameIndex, JointIndex, JointType, Model};

/// Why a checked entry point refused its input.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum InputError {
    /// A slice of the wrong length.
    #[error("{name} has length {got}, the model needs {expected} ({size})")]
    Length {
        /// The argument (`q`, `v`, `a`, `tau`, `out`, ...).
        name: &'static str,
        /// The length it must have.
        expected: usize,
        /// The length it has.
        got: usize,
        /// `nq` or `nv`.
        size: &'static str,
    },
    /// An entry that is NaN or infinite.
    #[error("{name}[{index}] = {value} is not finite (joint '{joint}')")]
    NonFinite {
        /// The argument.
        name: &'static str,
        /// The entry.
        index: usize,
        /// Its value.
        value: f64,
        /// The joint the entry belongs to.
        joint: String,
    },
    /// A scalar argument (`dt`) that is NaN or infinite.
    #[error("{name} = {value} is not finite")]
    NonFiniteScalar {
        /// The argument.
        name: &'static str,
        /// Its value.
        value: f64,
    },
    /// The quaternion of a spherical or free joint is zero.
    #[error("{name}[{index}..{}]: the quaternion of joint '{joint}' is zero", index + 4)]
    ZeroQuaternion {
        /// The argument.
        name: &'static str,
        /// Its first entry.
        index: usize,
        /// The joint.
        joint: String,
    },
    /// A `(cos θ, sin θ)` pair of Pinocchio's layout that is zero ([`crate::pinocchio`]).
    #[error("q_pin[{index}..{}]: the (cos, sin) of joint '{joint}' is zero", index + 2)]
    ZeroCosSin {
        /// Its first entry in Pinocchio's `q`.
        index: usize,
        /// The joint.
        joint: String,
    },
    /// `data` was not made for `model`.
    #[error("this Data was not made for this Model (Data::new(&model))")]
    DataMismatch,
    /// A joint or frame index past the end.
    #[error("{what} index {index} does not exist (the model has {count})")]
    IndexOutOfRange {
        /// `joint` or `frame`.
        what: &'static str,
        /// The index given.
        index: usize,
        /// How many there are.
        count: usize,
    },
    /// An output Jacobian with the wrong number of columns.
    #[error("the output Jacobian has {got} columns, the model nv = {expected}")]
    JacobianColumns {
        /// `nv`.
        expected: usize,
        /// Its columns.
        got: usize,
    },
    /// The algorithm does not handle this model.
    #[error("{algorithm} does not handle this model: {reason}")]
    Unsupported {
        /// The algorithm.
        algorithm: &'static str,
        /// Why not, and what to use instead.
        reason: &'static str,
    },
    /// The dynamics failed on valid input (a mass matrix that is not positive definite).
    #[error(transparent)]
    Dynamics(#[from] DynamicsError),
}

fn joint_of(model: &Model, index: usize, in_q: bool) -> String {
    model.joints()[1..]
        .iter()
        .find(|j| {
            let (start, len) = if in_q { (j.idx_q, j.nq()) } else { (j.idx_v, j.nv()) };
            (start..start + len).contains(&index)
        })
        .map_or_else(String::new, |j| j.name.clone())
}

fn check_len(name: &'static str, s: &[f64], expected: usize, size: &'static str) -> Result<(), InputError> {
    if s.len() == expected { Ok(()) } else { Err(InputError::Length { name, expected, got: s.len(), size }) }
}

/// Checks a configuration: length `nq`, finite entries, non-zero quaternions.
///
/// # Errors
/// [`InputError::Length`], [`InputError::NonFinite`] or [`InputError::ZeroQuaternion`].
pub fn check_configuration(model: &Model, name: &'static str, q: &[f64]) -> Result<(), InputError> {
    check_len(name, q, model.nq(), "nq")?;
    if let Some(index) = q.iter().position(|x| !x.is_finite()) {
        return Err(InputError::NonFinite {
            name,
            index,
            value: q[index],
            joint: joint_of(model, index, true),
        });
    }
    for j in &model.joints()[1..] {
        let start = match j.kind {
            JointType::Spherical => j.idx_q,
            JointType::Free => j.idx_q + 3,
            _ => continue,
        };
        if q[start..start + 4].iter().all(|x| *x == 0.0) {
            return Err(InputError::ZeroQuaternion { name, index: start, joint: j.name.clone() });
        }
    }
    Ok(())
}

/// Checks a velocity-space vector (`v`, `a`, `tau`): length `nv`, finite entries.
///
/// # Errors
/// [`InputError::Length`] or [`InputError::NonFinite`].
pub fn check_tangent(model: &Model, name: &'static str, v: &[f64]) -> Result<(), InputError> {
    check_len(name, v, model.nv(), "nv")?;
    match v.iter().position(|x| !x.is_finite()) {
        Some(index) => {
            Err(InputError::NonFinite { name, index, value: v[index], joint: joint_of(model, index, false) })
        }
        None => Ok(()),
    }
}

fn check_data(model: &Model, data: &Data) -> Result<(), InputError> {
    if data.fits(model) { Ok(()) } else { Err(InputError::DataMismatch) }
}

fn check_q(model: &Model, data: &Data, q: &[f64]) -> Result<(), InputError> {
    check_data(model, data)?;
    check_configuration(model, "q", q)
}

/// [`crate::forward_kinematics`], checked.
///
/// # Errors
/// A bad `q` or a `data` made for another model.
pub fn forward_kinematics(model: &Model, data: &mut Data, q: &[f64]) -> Result<(), InputError> {
    check_q(model, data, q)?;
    crate::forward_kinematics(model, data, q);
    Ok(())
}

/// [`crate::frames_forward_kinematics`], checked.
///
/// # Errors
/// As [`forward_kinematics`].
pub fn frames_forward_kinematics(model: &Model, data: &mut Data, q: &[f64]) -> Result<(), InputError> {
    check_q(model, data, q)?;
    crate::frames_forward_kinematics(model, data, q);
    Ok(())
}

/// [`crate::compute_joint_jacobians`], checked.
///
/// # Errors
/// As [`forward_kinematics`].
pub fn compute_joint_jacobians(model: &Model, data: &mut Data, q: &[f64]) -> Result<(), InputError> {
    check_q(model, data, q)?;
    crate::compute_joint_jacobians(model, data, q);
    Ok(())
}

/// [`crate::compute_joint_jacobians_time_variation`], checked.
///
/// # Errors
/// A bad `q` or `v`, or a `data` made for another model.
pub fn compute_joint_jacobians_time_variation(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    v: &[f64],
) -> Result<(), InputError> {
    check_q(model, data, q)?;
    check_tangent(model, "v", v)?;
    crate::compute_joint_jacobians_time_variation(model, data, q, v);
    Ok(())
}

fn check_out(model: &Model, data: &Data, out: &Jacobian) -> Result<(), InputError> {
    check_data(model, data)?;
    if out.ncols() == model.nv() {
        Ok(())
    } else {
        Err(InputError::JacobianColumns { expected: model.nv(), got: out.ncols() })
    }
}

/// [`crate::joint_jacobian`], checked (after [`compute_joint_jacobians`]).
///
/// # Errors
/// A joint index past the end, an `out` without `nv` columns, or a `data` made for another model.
pub fn joint_jacobian(
    model: &Model,
    data: &Data,
    joint: JointIndex,
    rf: ReferenceFrame,
    out: &mut Jacobian,
) -> Result<(), InputError> {
    if joint >= model.njoints() {
        return Err(InputError::IndexOutOfRange { what: "joint", index: joint, count: model.njoints() });
    }
    check_out(model, data, out)?;
    crate::joint_jacobian(model, data, joint, rf, out);
    Ok(())
}

/// [`crate::frame_jacobian`], checked (after [`compute_joint_jacobians`]).
///
/// # Errors
/// A frame index past the end, an `out` without `nv` columns, or a `data` made for another model.
pub fn frame_jacobian(
    model: &Model,
    data: &Data,
    frame: FrameIndex,
    rf: ReferenceFrame,
    out: &mut Jacobian,
) -> Result<(), InputError> {
    if frame >= model.frames().len() {
        return Err(InputError::IndexOutOfRange { what: "frame", index: frame, count: model.frames().len() });
    }
    check_out(model, data, out)?;
    crate::frame_jacobian(model, data, frame, rf, out);
    Ok(())
}

/// [`crate::rnea`], checked.
///
/// # Errors
/// A bad `q`, `v` or `a`, or a `data` made for another model.
pub fn rnea<'d>(
    model: &Model,
    data: &'d mut Data,
    q: &[f64],
    v: &[f64],
    a: &[f64],
) -> Result<&'d [f64], InputError> {
    check_q(model, data, q)?;
    check_tangent(model, "v", v)?;
    check_tangent(model, "a", a)?;
    Ok(crate::rnea(model, data, q, v, a))
}

/// [`crate::nonlinear_effects`], checked.
///
/// # Errors
/// A bad `q` or `v`, or a `data` made for another model.
pub fn nonlinear_effects<'d>(
    model: &Model,
    data: &'d mut Data,
    q: &[f64],
    v: &[f64],
) -> Result<&'d [f64], InputError> {
    check_q(model, data, q)?;
    check_tangent(model, "v", v)?;
    Ok(crate::nonlinear_effects(model, data, q, v))
}

/// [`crate::gravity_torques`], checked.
///
/// # Errors
/// A bad `q`, or a `data` made for another model.
pub fn gravity_torques<'d>(model: &Model, data: &'d mut Data, q: &[f64]) -> Result<&'d [f64], InputError> {
    check_q(model, data, q)?;
    Ok(crate::gravity_torques(model, data, q))
}

/// [`crate::crba`], checked.
///
/// # Errors
/// A bad `q`, or a `data` made for another model.
pub fn crba<'d>(model: &Model, data: &'d mut Data, q: &[f64]) -> Result<&'d SquareMatrix, InputError> {
    check_q(model, data, q)?;
    Ok(crate::crba(model, data, q))
}

/// [`crate::aba`], checked.
///
/// # Errors
/// A bad `q`, `v` or `tau`, a `data` made for another model, or [`InputError::Unsupported`]
/// for a model with coupled joints ([`Model::mimic_joints`]; use
/// [`forward_dynamics_cholesky`]).
pub fn aba<'d>(
    model: &Model,
    data: &'d mut Data,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
) -> Result<&'d [f64], InputError> {
    check_q(model, data, q)?;
    check_tangent(model, "v", v)?;
    check_tangent(model, "tau", tau)?;
    if !model.mimic_joints().is_empty() {
        return Err(InputError::Unsupported {
            algorithm: "aba",
            reason: "the model has coupled (mimic) joints; forward_dynamics_cholesky handles them",
        });
    }
    Ok(crate::aba(model, data, q, v, tau))
}

/// [`crate::forward_dynamics_cholesky`], checked.
///
/// # Errors
/// A bad `q`, `v` or `tau`, a `data` made for another model, or
/// [`InputError::Dynamics`] when the mass matrix is not positive definite.
pub fn forward_dynamics_cholesky<'d>(
    model: &Model,
    data: &'d mut Data,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
) -> Result<&'d [f64], InputError> {
    check_q(model, data, q)?;
    check_tangent(model, "v", v)?;
    check_tangent(model, "tau", tau)?;
    Ok(crate::forward_dynamics_cholesky(model, data, q, v, tau)?)
}

/// [`crate::config::integrate_into`], checked.
///
/// # Errors
/// A bad `q` or `v`, a non-finite `dt`, or an `out` whose length is not `nq`.
pub fn integrate_into(
    model: &Model,
    q: &[f64],
    v: &[f64],
    dt: f64,
    out: &mut [f64],
) -> Result<(), InputError> {
    check_configuration(model, "q", q)?;
    check_tangent(model, "v", v)?;
    if !dt.is_finite() {
        return Err(InputError::NonFiniteScalar { name: "dt", value: dt });
    }
    check_len("out", out, model.nq(), "nq")?;
    crate::config::integrate_into(model, q, v, dt, out);
    Ok(())
}

/// [`crate::config::integrate`], checked.
///
/// # Errors
/// As [`integrate_into`].
pub fn integrate(model: &Model, q: &[f64], v: &[f64], dt: f64) -> Result<Vec<f64>, InputError> {
    let mut out = vec![0.0; model.nq()];
    integrate_into(model, q, v, dt, &mut out)?;
    Ok(out)
}

/// [`crate::config::difference_into`], checked.
///
/// # Errors
/// A bad `q0` or `q1`, or an `out` whose length is not `nv`.
pub fn difference_into(model: &Model, q0: &[f64], q1: &[f64], out: &mut [f64]) -> Result<(), InputError> {
    check_configuration(model, "q0", q0)?;
    check_configuration(model, "q1", q1)?;
    check_len("out", out, model.nv(), "nv")?;
    crate::config::difference_into(model, q0, q1, out);
    Ok(())
}

/// [`crate::config::difference`], checked.
///
/// # Errors
/// As [`difference_into`].
pub fn difference(model: &Model, q0: &[f64], q1: &[f64]) -> Result<Vec<f64>, InputError> {
    let mut out = vec![0.0; model.nv()];
    difference_into(model, q0, q1, &mut out)?;
    Ok(out)
}
