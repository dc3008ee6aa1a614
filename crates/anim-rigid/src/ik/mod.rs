//! Inverse kinematics: find `q` with `world_M_f(q) = target` for a frame `f`.
//!
//! - [`AnalyticIk`]: closed form for 6R arms by the Paden-Kahan subproblems
//!   ([`crate::paden_kahan`]); every solution (up to 8), each verified by forward kinematics.
//!   Two geometries: a spherical wrist with intersecting shoulder axes (PUMA-like), and UR-type
//!   arms (three parallel middle axes, intersecting last two axes).
//! - [`NumericalIk`]: damped least squares / Levenberg-Marquardt on the SE(3) logarithm of the
//!   pose error, for any chain (redundant arms such as the 7-DoF Panda, spherical and free
//!   joints), with joint limits and a null-space objective.

pub mod analytic;
pub mod numerical;

pub use analytic::{AnalyticIk, AnalyticIkKind, IkError, IkSolution};
pub use numerical::{IkParams, IkReport, NumericalIk};

use anim_core::lie::{Se3, so3};

/// The pose error between `a` and `b`: `(‖t_a - t_b‖, rotation angle of R_aᵀ R_b)`.
#[must_use]
pub fn pose_error(a: &Se3, b: &Se3) -> (f64, f64) {
    ((a.translation - b.translation).length(), so3::angle(a.rotation.transpose() * b.rotation))
}
