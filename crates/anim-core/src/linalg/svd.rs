//! 3x3 SVD (stub).
use glam::{DMat3, DVec3, Mat3, Vec3};
/// SVD result.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Svd3<M, V> { /// U
 pub u: M, /// sigma
 pub sigma: V, /// V
 pub v: M }
/// f64 svd.
#[must_use] pub fn svd3(_a: DMat3) -> Svd3<DMat3, DVec3> { todo!() }
/// f32 svd.
#[must_use] pub fn svd3_f32(_a: Mat3) -> Svd3<Mat3, Vec3> { todo!() }
/// polar
#[must_use] pub fn polar(_a: DMat3) -> (DMat3, DMat3) { todo!() }
/// polar f32
#[must_use] pub fn polar_f32(_a: Mat3) -> (Mat3, Mat3) { todo!() }
