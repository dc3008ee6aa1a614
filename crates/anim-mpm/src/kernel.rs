//! B-spline interpolation kernels (seed 5.3.1): quadratic and cubic weights and their gradients.
//!
//! The kernels live in [`anim_core::bspline`], shared with the staggered-grid transfers of the
//! particle fluid; this module re-exports them under the name the MPM transfers use.

pub use anim_core::bspline::*;
