//! Forward dynamics by whichever of the two independent methods is faster for the tree: the
//! mass matrix and its sparse `LᵀDL` factorisation ([`forward_dynamics_cholesky`]) on shallow
//! trees, the articulated-body algorithm ([`aba`]) on deep ones.

use crate::data::Data;
use crate::dynamics::aba::aba;
use crate::dynamics::check::{check_q, check_v};
use crate::dynamics::cholesky::forward_dynamics_cholesky;
use crate::model::Model;

/// Mean depth of the degrees of freedom up to which [`forward_dynamics`] solves `H v̇ = τ - C`:
/// on the Panda (mean depth 4) and the UR5 (3.5) CRBA, the bias forces and the factorisation
/// together took 0.89-0.94 of ABA's time, on a 32-joint chain 3.5 times it.
pub const CHOLESKY_DEPTH: f64 = 4.5;

/// Forward dynamics `v̇ = FD(q, v, τ)`, gravity included, written into `data.ddq` and returned:
/// [`forward_dynamics_cholesky`] when the degrees of freedom are on average at most
/// [`CHOLESKY_DEPTH`] deep and the model has no coupled joints, [`aba`] otherwise (the same
/// accelerations to rounding; the tests compare them).
///
/// A mass matrix that is not positive definite (a massless subtree) falls back to [`aba`],
/// which gives non-finite accelerations there, as it does for such a model.
///
/// # Panics
/// When `q`, `v`, `tau` or `data` does not match `model`, or when the model has coupled joints
/// and ABA is taken (see [`aba`]).
#[track_caller]
pub fn forward_dynamics<'d>(
    model: &Model,
    data: &'d mut Data,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
) -> &'d [f64] {
    check_q(model, data, q);
    check_v(model, "v", v);
    check_v(model, "tau", tau);
    if data.mean_dof_depth <= CHOLESKY_DEPTH && forward_dynamics_cholesky(model, data, q, v, tau).is_ok() {
        return &data.ddq;
    }
    aba(model, data, q, v, tau)
}
