//! B-spline interpolation kernels (as in APIC, Jiang et al. 2015): quadratic and cubic weights and their gradients.
//!
//! The kernels live in [`anim_core::bspline`], shared with the staggered-grid transfers of the
//! particle fluid; this module re-exports them under the name the MPM transfers use.

pub use anim_core::bspline::*;
