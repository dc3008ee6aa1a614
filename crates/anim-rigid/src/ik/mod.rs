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
mod pose;

pub use analytic::{AnalyticIk, AnalyticIkKind, IkError, IkSolution};
pub use numerical::{IkParams, IkReport, NumericalIk};
pub use pose::pose_error;
