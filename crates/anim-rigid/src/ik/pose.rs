//! The error between two placements, as the inverse kinematics solvers measure a solution: the
//! translation error `‖t_a - t_b‖` and the angle of the relative rotation `R_aᵀ R_b` (the norm
//! of its SO(3) logarithm). `AnalyticIk` keeps the solutions whose error is within its
//! tolerance; `NumericalIk` reports the error of its best configuration.

use anim_core::lie::{Se3, so3};

/// The pose error between `a` and `b`: `(‖t_a - t_b‖, rotation angle of R_aᵀ R_b)`.
#[must_use]
pub fn pose_error(a: &Se3, b: &Se3) -> (f64, f64) {
    ((a.translation - b.translation).length(), so3::angle(a.rotation.transpose() * b.rotation))
}
