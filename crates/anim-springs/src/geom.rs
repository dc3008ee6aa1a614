//! Vector geometry shared by the springs and the colliders: the shortest length that still has a
//! direction, and the outer product `a b^T` from which both build their 3x3 Jacobian blocks.
//!
//! A direction `d / |d|` is only taken when `|d|` exceeds [`MIN_LENGTH`],
//! `sqrt(f64::MIN_POSITIVE)`: below it `d / |d|` can overflow or lose every significant bit, so a
//! spring falls back to its rest direction and a particle at a sphere's centre is pushed out
//! along `+z`.

use anim_core::glam::{DMat3, DVec3};

/// Below this length a spring's direction is taken from its rest configuration.
pub const MIN_LENGTH: f64 = 1.491_668_146_240_041_3e-154; // sqrt(f64::MIN_POSITIVE)

/// `a b^T`.
#[inline]
pub(crate) fn outer(a: DVec3, b: DVec3) -> DMat3 {
    DMat3::from_cols(a * b.x, a * b.y, a * b.z)
}
