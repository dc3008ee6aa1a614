//! Floating-point scalars: the [`Real`] trait implemented for `f32` and `f64`.
//!
//! Kernels that must run in both precisions (the 3x3 SVD that FEM runs in `f64` and MPM in `f32`)
//! are written once against [`Real`]. Everything else in the workspace uses concrete types.

use num_traits::Float;

/// A floating-point scalar (`f32` or `f64`).
pub trait Real:
    Float
    + num_traits::FloatConst
    + std::fmt::Debug
    + std::fmt::Display
    + Default
    + Send
    + Sync
    + std::iter::Sum
    + std::ops::AddAssign
    + std::ops::SubAssign
    + std::ops::MulAssign
    + std::ops::DivAssign
    + 'static
{
    /// Machine epsilon of the type.
    const EPS: Self;
    /// Converts from `f64`, rounding to nearest.
    fn of(x: f64) -> Self;
    /// Widens to `f64`.
    fn to_f64_lossless(self) -> f64;
}

impl Real for f32 {
    const EPS: Self = f32::EPSILON;
    #[inline]
    fn of(x: f64) -> Self {
        x as f32
    }
    #[inline]
    fn to_f64_lossless(self) -> f64 {
        f64::from(self)
    }
}

impl Real for f64 {
    const EPS: Self = f64::EPSILON;
    #[inline]
    fn of(x: f64) -> Self {
        x
    }
    #[inline]
    fn to_f64_lossless(self) -> f64 {
        self
    }
}
