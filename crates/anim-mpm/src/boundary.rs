//! Grid boundary conditions (the `BC` operator of the MLS-MPM grid update, Hu et al. 2018): on the domain walls and on
//! analytic colliders (planes, boxes, spheres), fixed or moving with a constant velocity.
//!
//! A grid node inside a collider (signed distance `phi(x_i) <= 0`) or within
//! [`wall_nodes`](crate::MpmParams::wall_nodes) nodes of a domain wall gets its velocity,
//! relative to the obstacle's velocity `v_c`, projected:
//!
//! - [`Boundary::Sticky`]: `v = v_c`;
//! - [`Boundary::Slip`]: the normal component removed, `v_rel <- v_rel - (v_rel . n) n`;
//! - [`Boundary::Separate`]: the normal component removed only when approaching
//!   (`v_rel . n < 0`), so matter can leave the obstacle; with Coulomb friction `mu`, the
//!   tangential part then shrinks by `mu |v_rel . n|` (and stops if that exceeds it).

use crate::{MpmError, Vector};
use serde::{Deserialize, Serialize};

/// How a grid velocity is constrained at an obstacle.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default)]
pub enum Boundary {
    /// No relative motion at all.
    Sticky,
    /// No relative normal motion; free tangential motion.
    Slip,
    /// No approaching normal motion, with Coulomb friction coefficient `friction` (0 = none).
    Separate {
        /// Coulomb friction coefficient (>= 0).
        friction: f32,
    },
    /// The default: separating without friction.
    #[default]
    SeparateFrictionless,
}

impl Boundary {
    /// Applies the condition to a relative velocity `v` at a surface of outward normal `n`.
    #[inline]
    pub(crate) fn apply<const D: usize>(self, v: &mut Vector<D>, n: &Vector<D>) {
        match self {
            Boundary::Sticky => *v = Vector::<D>::zeros(),
            Boundary::Slip => {
                let vn = v.dot(n);
                *v -= n * vn;
            }
            Boundary::Separate { friction } => {
                let vn = v.dot(n);
                if vn < 0.0 {
                    *v -= n * vn;
                    if friction > 0.0 {
                        let vt = v.norm();
                        let drop = -friction * vn;
                        if vt <= drop { *v = Vector::<D>::zeros() } else { *v *= 1.0 - drop / vt }
                    }
                }
            }
            Boundary::SeparateFrictionless => {
                let vn = v.dot(n);
                if vn < 0.0 {
                    *v -= n * vn;
                }
            }
        }
    }

    pub(crate) fn validate(self, what: &'static str) -> Result<(), MpmError> {
        if let Boundary::Separate { friction } = self
            && (!(friction >= 0.0) || !friction.is_finite())
        {
            return Err(MpmError::BadParameter {
                name: what,
                reason: format!("friction {friction} must be finite and >= 0"),
            });
        }
        Ok(())
    }
}

/// The shape of an analytic collider (in `D` dimensions; the trailing components of 3-vectors
/// are ignored in 2D).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum Shape {
    /// The half-space behind a plane through `point` with outward unit normal `normal`.
    Plane {
        /// A point of the plane.
        point: [f32; 3],
        /// Outward normal (normalised on use).
        normal: [f32; 3],
    },
    /// A solid axis-aligned box.
    Box {
        /// Centre.
        center: [f32; 3],
        /// Half extents (> 0).
        half: [f32; 3],
    },
    /// A solid sphere (a disk in 2D).
    Sphere {
        /// Centre.
        center: [f32; 3],
        /// Radius (> 0).
        radius: f32,
    },
}

/// An analytic obstacle: a shape moving with constant velocity, and its boundary condition.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Collider {
    /// Shape at time 0.
    pub shape: Shape,
    /// Constant translational velocity (zero for a fixed obstacle).
    pub velocity: [f32; 3],
    /// Boundary condition on its surface.
    pub boundary: Boundary,
}

impl Collider {
    /// A fixed collider.
    #[must_use]
    pub fn fixed(shape: Shape, boundary: Boundary) -> Self {
        Self { shape, velocity: [0.0; 3], boundary }
    }

    pub(crate) fn validate(&self, index: usize, dim: usize) -> Result<(), MpmError> {
        let bad = |reason: String| MpmError::BadCollider { index, reason };
        let finite = |v: &[f32]| v.iter().take(dim).all(|c| c.is_finite());
        if !finite(&self.velocity) {
            return Err(bad("non-finite velocity".into()));
        }
        match self.shape {
            Shape::Plane { point, normal } => {
                if !finite(&point) || !finite(&normal) {
                    return Err(bad("non-finite plane".into()));
                }
                if normal.iter().take(dim).map(|c| c * c).sum::<f32>() < 1e-12 {
                    return Err(bad("plane normal is zero".into()));
                }
            }
            Shape::Box { center, half } => {
                if !finite(&center) || !half.iter().take(dim).all(|h| *h > 0.0 && h.is_finite()) {
                    return Err(bad(format!("box needs a finite centre and half extents > 0, got {half:?}")));
                }
            }
            Shape::Sphere { center, radius } => {
                if !finite(&center) || !(radius > 0.0) || !radius.is_finite() {
                    return Err(bad(format!("sphere needs a finite centre and radius > 0, got {radius}")));
                }
            }
        }
        self.boundary.validate("collider friction")
    }

    /// Signed distance and outward normal at `x`, time `t`.
    #[inline]
    pub(crate) fn sdf<const D: usize>(&self, x: &Vector<D>, t: f32) -> (f32, Vector<D>) {
        let shift = Vector::<D>::from_fn(|i, _| self.velocity[i] * t);
        let y = x - shift;
        match self.shape {
            Shape::Plane { point, normal } => {
                let n = Vector::<D>::from_fn(|i, _| normal[i]).normalize();
                let p = Vector::<D>::from_fn(|i, _| point[i]);
                ((y - p).dot(&n), n)
            }
            Shape::Sphere { center, radius } => {
                let d = y - Vector::<D>::from_fn(|i, _| center[i]);
                let r = d.norm();
                let n =
                    if r > 0.0 { d / r } else { Vector::<D>::from_fn(|i, _| if i == 0 { 1.0 } else { 0.0 }) };
                (r - radius, n)
            }
            Shape::Box { center, half } => {
                let q = Vector::<D>::from_fn(|i, _| (y[i] - center[i]).abs() - half[i]);
                let outside = q.map(|c| c.max(0.0));
                let out_len = outside.norm();
                let inside = q.max().min(0.0);
                let phi = out_len + inside;
                // Normal: gradient of the box distance.
                let mut n = Vector::<D>::zeros();
                if out_len > 0.0 {
                    for i in 0..D {
                        n[i] = outside[i] / out_len * (y[i] - center[i]).signum();
                    }
                } else {
                    let axis = q.argmax().0;
                    n[axis] = (y[axis] - center[axis]).signum();
                }
                (phi, n)
            }
        }
    }

    /// Velocity of the collider as a `D`-vector.
    #[inline]
    pub(crate) fn vel<const D: usize>(&self) -> Vector<D> {
        Vector::<D>::from_fn(|i, _| self.velocity[i])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn conditions_project_relative_velocity() {
        let n = Vector::<2>::new(0.0, 1.0);
        let mut v = Vector::<2>::new(1.0, -2.0);
        Boundary::Slip.apply(&mut v, &n);
        assert_eq!(v, Vector::<2>::new(1.0, 0.0));
        let mut v = Vector::<2>::new(1.0, 2.0);
        Boundary::Slip.apply(&mut v, &n);
        assert_eq!(v, Vector::<2>::new(1.0, 0.0));
        let mut v = Vector::<2>::new(1.0, 2.0);
        Boundary::SeparateFrictionless.apply(&mut v, &n);
        assert_eq!(v, Vector::<2>::new(1.0, 2.0));
        let mut v = Vector::<2>::new(1.0, -2.0);
        Boundary::Separate { friction: 0.25 }.apply(&mut v, &n);
        assert!((v - Vector::<2>::new(0.5, 0.0)).norm() < 1e-7);
        let mut v = Vector::<2>::new(1.0, -2.0);
        Boundary::Separate { friction: 1.0 }.apply(&mut v, &n);
        assert_eq!(v, Vector::<2>::zeros());
        let mut v = Vector::<2>::new(1.0, -2.0);
        Boundary::Sticky.apply(&mut v, &n);
        assert_eq!(v, Vector::<2>::zeros());
    }

    #[test]
    fn signed_distances() {
        let sphere =
            Collider::fixed(Shape::Sphere { center: [1.0, 1.0, 0.0], radius: 0.5 }, Boundary::Sticky);
        let (phi, n) = sphere.sdf(&Vector::<2>::new(2.0, 1.0), 0.0);
        assert!((phi - 0.5).abs() < 1e-6 && (n - Vector::<2>::new(1.0, 0.0)).norm() < 1e-6);
        let moving = Collider { velocity: [1.0, 0.0, 0.0], ..sphere };
        let (phi, _) = moving.sdf(&Vector::<2>::new(2.0, 1.0), 1.0);
        assert!((phi + 0.5).abs() < 1e-6);
        let bx = Collider::fixed(Shape::Box { center: [0.0; 3], half: [1.0, 2.0, 3.0] }, Boundary::Slip);
        let (phi, n) = bx.sdf(&Vector::<3>::new(0.5, 1.8, 0.0), 0.0);
        assert!((phi + 0.2).abs() < 1e-6 && (n - Vector::<3>::new(0.0, 1.0, 0.0)).norm() < 1e-6);
        let (phi, _) = bx.sdf(&Vector::<3>::new(4.0, 6.0, 0.0), 0.0);
        assert!((phi - 5.0).abs() < 1e-5);
        let plane =
            Collider::fixed(Shape::Plane { point: [0.0, 0.1, 0.0], normal: [0.0, 2.0, 0.0] }, Boundary::Slip);
        let (phi, n) = plane.sdf(&Vector::<3>::new(0.3, 0.0, 0.2), 0.0);
        assert!((phi + 0.1).abs() < 1e-6 && (n - Vector::<3>::new(0.0, 1.0, 0.0)).norm() < 1e-6);
    }
}
