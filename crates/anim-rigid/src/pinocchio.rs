//! Configurations in Pinocchio's layout.
//!
//! Joint order, joint names, frames and the velocity `v` (and so `a`, `tau`, Jacobian columns)
//! are the same here and in a Pinocchio model built from the same URDF. The configuration `q`
//! differs in one place: a joint that turns without position limits (URDF `continuous`, loaded
//! here as a [`JointType::Revolute`] whose limits are both infinite) stores its **angle** `θ`
//! here (one entry) and **`(cos θ, sin θ)`** in Pinocchio (`JointModelRevoluteUnbounded`, two
//! entries). A planar joint is `(x, y, θ)` here and `(x, y, cos θ, sin θ)` in Pinocchio
//! (`JointModelPlanar`). Every joint after one of these therefore sits at a different index of
//! `q`. Quaternions of spherical and free joints are `(x, y, z, w)` in both.
//!
//! | joint | `q` here | `q` in Pinocchio |
//! | --- | --- | --- |
//! | revolute with a position limit, prismatic | `θ` or `d` | the same |
//! | revolute without position limits (`continuous`) | `θ` | `(cos θ, sin θ)` |
//! | planar | `(x, y, θ)` | `(x, y, cos θ, sin θ)` |
//! | spherical, free | `(x, y, z, w)`, `(x, y, z, qx, qy, qz, qw)` | the same |
//!
//! A joint coupled to another ([`crate::model::Mimic`]) has no entry in either layout, and its
//! `idx_q`, `idx_v` are its master's in both, as in a Pinocchio model built with `mimic=True`.
//!
//! [`to_pinocchio`] and [`from_pinocchio`] convert whole vectors; going to Pinocchio and back
//! returns `θ` wrapped into `(-π, π]`, which places every frame at the same pose.

use crate::checked::{InputError, check_configuration};
use crate::model::{Joint, JointIndex, JointType, Model};

/// Whether Pinocchio stores `joint` as `(cos θ, sin θ)`: a revolute joint without position limits
/// (URDF `continuous`).
#[must_use]
pub fn is_unbounded_revolute(joint: &Joint) -> bool {
    matches!(joint.kind, JointType::Revolute(_))
        && joint.limits.lower == f64::NEG_INFINITY
        && joint.limits.upper == f64::INFINITY
}

/// How many more entries `joint` has in Pinocchio's `q` than here: one for an unbounded
/// revolute or a planar joint (an angle stored as `(cos θ, sin θ)`), else none.
fn extra(joint: &Joint) -> usize {
    usize::from(
        joint.mimic.is_none() && (is_unbounded_revolute(joint) || matches!(joint.kind, JointType::Planar(_))),
    )
}

/// Pinocchio's `nq` for `model`: [`Model::nq`] plus one per unbounded revolute or planar joint.
#[must_use]
pub fn nq(model: &Model) -> usize {
    model.nq() + model.joints().iter().map(extra).sum::<usize>()
}

/// Pinocchio's `idx_q` of joint `joint` (its first entry in Pinocchio's `q`).
///
/// # Panics
/// When `joint >= model.njoints()`.
#[must_use]
#[track_caller]
pub fn idx_q(model: &Model, joint: JointIndex) -> usize {
    let j = model.joint(joint);
    if let Some(m) = &j.mimic {
        // A coupled joint has its master's index, in Pinocchio as here.
        return idx_q(model, m.master);
    }
    j.idx_q + model.joints()[1..joint].iter().map(extra).sum::<usize>()
}

/// Writes `q` (this crate's layout) into `out` in Pinocchio's layout.
///
/// # Errors
/// A `q` of the wrong length or with non-finite entries, or an `out` whose length is not
/// [`nq`].
pub fn to_pinocchio_into(model: &Model, q: &[f64], out: &mut [f64]) -> Result<(), InputError> {
    check_configuration(model, "q", q)?;
    let n = nq(model);
    if out.len() != n {
        return Err(InputError::Length { name: "out", expected: n, got: out.len(), size: "Pinocchio nq" });
    }
    let mut k = 0;
    for j in model.joints()[1..].iter().filter(|j| j.mimic.is_none()) {
        let src = &q[j.idx_q..j.idx_q + j.nq()];
        if matches!(j.kind, JointType::Planar(_)) {
            let (s, c) = src[2].sin_cos();
            out[k..k + 4].copy_from_slice(&[src[0], src[1], c, s]);
            k += 4;
        } else if is_unbounded_revolute(j) {
            let (s, c) = src[0].sin_cos();
            out[k] = c;
            out[k + 1] = s;
            k += 2;
        } else {
            out[k..k + src.len()].copy_from_slice(src);
            k += src.len();
        }
    }
    Ok(())
}

/// `q` (this crate's layout) in Pinocchio's layout.
///
/// # Errors
/// As [`to_pinocchio_into`].
pub fn to_pinocchio(model: &Model, q: &[f64]) -> Result<Vec<f64>, InputError> {
    let mut out = vec![0.0; nq(model)];
    to_pinocchio_into(model, q, &mut out)?;
    Ok(out)
}

/// Writes Pinocchio's `q_pin` into `out` in this crate's layout. The angle of an unbounded
/// revolute or planar joint is `atan2(sin, cos)`, in `(-π, π]`; `(cos, sin)` need not be of unit length.
///
/// # Errors
/// A `q_pin` whose length is not [`nq`] or with non-finite entries, a `(cos, sin)` pair or a
/// quaternion that is zero, or an `out` whose length is not [`Model::nq`].
pub fn from_pinocchio_into(model: &Model, q_pin: &[f64], out: &mut [f64]) -> Result<(), InputError> {
    let n = nq(model);
    if q_pin.len() != n {
        return Err(InputError::Length {
            name: "q_pin",
            expected: n,
            got: q_pin.len(),
            size: "Pinocchio nq",
        });
    }
    if out.len() != model.nq() {
        return Err(InputError::Length { name: "out", expected: model.nq(), got: out.len(), size: "nq" });
    }
    let mut k = 0;
    for (index, j) in model.joints().iter().enumerate().skip(1) {
        let width = j.nq() + extra(j);
        let src = &q_pin[k..k + width];
        if let Some(bad) = src.iter().position(|x| !x.is_finite()) {
            return Err(InputError::NonFinite {
                name: "q_pin",
                index: k + bad,
                value: src[bad],
                joint: j.name.clone(),
            });
        }
        if extra(j) == 1 {
            // The angle is the last two entries: (cos, sin) of a continuous joint, or (x, y,
            // cos, sin) of a planar one.
            let (c, s) = (src[width - 2], src[width - 1]);
            if c == 0.0 && s == 0.0 {
                return Err(InputError::ZeroCosSin {
                    index: idx_q(model, index) + width - 2,
                    joint: j.name.clone(),
                });
            }
            out[j.idx_q..j.idx_q + width - 2].copy_from_slice(&src[..width - 2]);
            out[j.idx_q + width - 2] = s.atan2(c);
        } else {
            out[j.idx_q..j.idx_q + width].copy_from_slice(src);
        }
        k += width;
    }
    check_configuration(model, "q_pin", out)
}

/// Pinocchio's `q_pin` in this crate's layout.
///
/// # Errors
/// As [`from_pinocchio_into`].
pub fn from_pinocchio(model: &Model, q_pin: &[f64]) -> Result<Vec<f64>, InputError> {
    let mut out = vec![0.0; model.nq()];
    from_pinocchio_into(model, q_pin, &mut out)?;
    Ok(out)
}
