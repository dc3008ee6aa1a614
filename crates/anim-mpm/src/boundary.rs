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

/// How a grid velocity is constrained at an obstacle. In a scene file: `"sticky"`, `"slip"`,
/// `{ separate = { friction = 0.3 } }` or `"separate-frictionless"`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case", deny_unknown_fields)]
pub enum Boundary {
    /// No relative motion at all.
    Sticky,
    /// No relative normal motion; free tangential motion.
    Slip,
    /// No approaching normal motion, with Coulomb friction coefficient `friction` (0 = none).
    Separate {
        /// Coulomb friction coefficient (>= 0); default 0.
        #[serde(default)]
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

/// The shape of an analytic collider: anim-core's shared [`Shape`]
/// (in `D` dimensions; the trailing components of 3-vectors are ignored in 2D), re-exported here.
/// MPM handles planes, boxes and spheres (disks in 2D); a capsule is refused when the simulation
/// is built. The shape is converted to `f32` once then, the precision of the grid.
pub use anim_core::geometry::Shape;

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

    /// Checks collider `index` in `dim` dimensions and converts its shape to the grid's `f32`.
    ///
    /// anim-core's [`Shape::check_in`] checks the shape; this only checks that the conversion to
    /// `f32` keeps it valid (finite values, positive sizes still > 0, a plane normal that still
    /// normalises), and normalises the plane normal once, in `f32` as the grid uses it.
    pub(crate) fn compile(&self, index: usize, dim: usize) -> Result<GridCollider, MpmError> {
        let bad = |reason: String| MpmError::BadCollider { index, reason };
        let finite = |v: &[f32]| v.iter().take(dim).all(|c| c.is_finite());
        if !finite(&self.velocity) {
            return Err(bad("non-finite velocity".into()));
        }
        self.shape.check_in(dim).map_err(bad)?;
        let f = |v: [f64; 3]| v.map(|c| c as f32);
        let positive = |v: &[f32]| v.iter().take(dim).all(|c| *c > 0.0 && c.is_finite());
        let shape = match self.shape {
            Shape::Plane { point, normal } => {
                let (point, normal) = (f(point), f(normal));
                if !finite(&point) || !finite(&normal) {
                    return Err(bad(format!(
                        "plane point {point:?} and normal {normal:?} must be finite in f32"
                    )));
                }
                let unit = match dim {
                    1 => unit_normal::<1>(normal),
                    2 => unit_normal::<2>(normal),
                    _ => unit_normal::<3>(normal),
                };
                let normal = unit.ok_or_else(|| {
                    bad(format!(
                        "plane normal {normal:?} does not normalise in f32 (its length is zero or \
                         overflows)"
                    ))
                })?;
                GridShape::Plane { point, normal }
            }
            Shape::Box { center, half_extents } => {
                let (center, half) = (f(center), f(half_extents));
                if !finite(&center) || !positive(&half) {
                    return Err(bad(format!(
                        "box centre {center:?} must be finite and half extents {half:?} finite and > 0 in f32"
                    )));
                }
                GridShape::Box { center, half }
            }
            Shape::Sphere { center, radius } => {
                let (center, radius) = (f(center), radius as f32);
                if !finite(&center) || !positive(&[radius]) {
                    return Err(bad(format!(
                        "sphere centre {center:?} must be finite and radius {radius} finite and > 0 in f32"
                    )));
                }
                GridShape::Sphere { center, radius }
            }
            Shape::Capsule { .. } => {
                return Err(bad(
                    "a capsule collider has no MPM grid boundary (planes, boxes and spheres only)".into(),
                ));
            }
        };
        self.boundary.validate("collider friction")?;
        Ok(GridCollider { shape, velocity: self.velocity, boundary: self.boundary })
    }
}

/// The first `D` components of a plane normal normalised in `f32` (the others zero), or `None`
/// if their `f32` length is zero or not finite.
fn unit_normal<const D: usize>(normal: [f32; 3]) -> Option<[f32; 3]> {
    let v = Vector::<D>::from_fn(|i, _| normal[i]);
    let len = v.norm();
    if !(len > 0.0 && len.is_finite()) {
        return None;
    }
    let n = v.normalize();
    Some(std::array::from_fn(|i| if i < D { n[i] } else { 0.0 }))
}

/// A collider's shape in `f32`, as the grid kernels use it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum GridShape {
    /// The half-space behind a plane through `point` with outward unit normal `normal` (unit in
    /// its first `D` components, normalised when the collider is compiled).
    Plane { point: [f32; 3], normal: [f32; 3] },
    /// A solid axis-aligned box.
    Box { center: [f32; 3], half: [f32; 3] },
    /// A solid sphere (a disk in 2D).
    Sphere { center: [f32; 3], radius: f32 },
}

/// A checked [`Collider`] in `f32`, built once per simulation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct GridCollider {
    shape: GridShape,
    velocity: [f32; 3],
    pub(crate) boundary: Boundary,
}

impl GridCollider {
    /// Signed distance and outward normal at `x`, time `t`.
    #[inline]
    pub(crate) fn sdf<const D: usize>(&self, x: &Vector<D>, t: f32) -> (f32, Vector<D>) {
        let shift = Vector::<D>::from_fn(|i, _| self.velocity[i] * t);
        let y = x - shift;
        match self.shape {
            GridShape::Plane { point, normal } => {
                let n = Vector::<D>::from_fn(|i, _| normal[i]);
                let p = Vector::<D>::from_fn(|i, _| point[i]);
                ((y - p).dot(&n), n)
            }
            GridShape::Sphere { center, radius } => {
                let d = y - Vector::<D>::from_fn(|i, _| center[i]);
                let r = d.norm();
                let n =
                    if r > 0.0 { d / r } else { Vector::<D>::from_fn(|i, _| if i == 0 { 1.0 } else { 0.0 }) };
                (r - radius, n)
            }
            GridShape::Box { center, half } => {
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
        let compile = |c: Collider, dim| c.compile(0, dim).expect("valid");
        let sphere =
            Collider::fixed(Shape::Sphere { center: [1.0, 1.0, 0.0], radius: 0.5 }, Boundary::Sticky);
        let (phi, n) = compile(sphere, 2).sdf(&Vector::<2>::new(2.0, 1.0), 0.0);
        assert!((phi - 0.5).abs() < 1e-6 && (n - Vector::<2>::new(1.0, 0.0)).norm() < 1e-6);
        let moving = Collider { velocity: [1.0, 0.0, 0.0], ..sphere };
        let (phi, _) = compile(moving, 2).sdf(&Vector::<2>::new(2.0, 1.0), 1.0);
        assert!((phi + 0.5).abs() < 1e-6);
        let bx = compile(
            Collider::fixed(Shape::Box { center: [0.0; 3], half_extents: [1.0, 2.0, 3.0] }, Boundary::Slip),
            3,
        );
        let (phi, n) = bx.sdf(&Vector::<3>::new(0.5, 1.8, 0.0), 0.0);
        assert!((phi + 0.2).abs() < 1e-6 && (n - Vector::<3>::new(0.0, 1.0, 0.0)).norm() < 1e-6);
        let (phi, _) = bx.sdf(&Vector::<3>::new(4.0, 6.0, 0.0), 0.0);
        assert!((phi - 5.0).abs() < 1e-5);
        let plane = compile(
            Collider::fixed(Shape::Plane { point: [0.0, 0.1, 0.0], normal: [0.0, 2.0, 0.0] }, Boundary::Slip),
            3,
        );
        let (phi, n) = plane.sdf(&Vector::<3>::new(0.3, 0.0, 0.2), 0.0);
        assert!((phi + 0.1).abs() < 1e-6 && (n - Vector::<3>::new(0.0, 1.0, 0.0)).norm() < 1e-6);
    }

    #[test]
    fn invalid_and_unsupported_shapes_are_refused_by_index() {
        let capsule = Shape::Capsule { a: [0.2; 3], b: [0.4; 3], radius: 0.1 };
        let err = Collider::fixed(capsule, Boundary::Slip).compile(3, 3).unwrap_err();
        assert!(
            matches!(&err, MpmError::BadCollider { index: 3, reason } if reason.contains("capsule")),
            "{err}"
        );
        // Zero in the first two components: a plane in 3-D, none in 2-D.
        let plane =
            Collider::fixed(Shape::Plane { point: [0.0; 3], normal: [0.0, 0.0, 1.0] }, Boundary::Slip);
        assert!(plane.compile(0, 3).is_ok());
        assert!(matches!(plane.compile(1, 2), Err(MpmError::BadCollider { index: 1, .. })));
        let huge = Collider::fixed(Shape::Sphere { center: [0.5; 3], radius: 1e300 }, Boundary::Slip);
        assert!(matches!(huge.compile(0, 2), Err(MpmError::BadCollider { index: 0, .. })));
    }

    #[test]
    fn f32_conversion_refuses_only_what_it_breaks() {
        let refused = |shape: Shape, dim| {
            let err = Collider::fixed(shape, Boundary::Slip).compile(2, dim).unwrap_err();
            assert!(matches!(err, MpmError::BadCollider { index: 2, .. }), "{err}");
            let text = err.to_string();
            assert!(text.starts_with("collider 2: ") && text.contains(shape.name()), "{text}");
            text
        };
        // A short normal anim-core accepts is a plane here too, with a unit normal.
        let short =
            Collider::fixed(Shape::Plane { point: [0.0; 3], normal: [0.0, 1e-7, 0.0] }, Boundary::Slip);
        let (phi, n) = short.compile(0, 2).expect("valid").sdf(&Vector::<2>::new(0.2, -0.25), 0.0);
        assert!((phi + 0.25).abs() < 1e-7 && n == Vector::<2>::new(0.0, 1.0), "{phi} {n}");
        let (phi, n) = short.compile(0, 3).expect("valid").sdf(&Vector::<3>::new(0.2, -0.25, 0.1), 0.0);
        assert!((phi + 0.25).abs() < 1e-7 && n == Vector::<3>::new(0.0, 1.0, 0.0), "{phi} {n}");
        // A normal whose f32 square overflows, positive sizes that round to zero in f32.
        let e = refused(Shape::Plane { point: [0.0; 3], normal: [1e20, 0.0, 0.0] }, 3);
        assert!(e.contains("does not normalise in f32"), "{e}");
        let e = refused(Shape::Plane { point: [1e40, 0.0, 0.0], normal: [1.0, 0.0, 0.0] }, 2);
        assert!(e.contains("finite in f32"), "{e}");
        let e = refused(Shape::Sphere { center: [0.5; 3], radius: 1e-50 }, 2);
        assert!(e.contains("radius 0"), "{e}");
        let e = refused(Shape::Box { center: [0.5; 3], half_extents: [0.1, 1e-50, 0.1] }, 3);
        assert!(e.contains("half extents"), "{e}");
    }

    #[test]
    fn plane_normal_is_normalised_once_as_the_grid_did() {
        let normal = [0.37f64, 1.13, 0.21];
        let shape = Shape::Plane { point: [0.0, 0.3, 0.0], normal };
        let c = Collider::fixed(shape, Boundary::Slip);
        let (_, n2) = c.compile(0, 2).expect("valid").sdf(&Vector::<2>::new(0.1, 0.2), 0.0);
        assert_eq!(n2, Vector::<2>::new(normal[0] as f32, normal[1] as f32).normalize());
        let (_, n3) = c.compile(0, 3).expect("valid").sdf(&Vector::<3>::new(0.1, 0.2, 0.3), 0.0);
        assert_eq!(n3, Vector::<3>::from_fn(|i, _| normal[i] as f32).normalize());
    }
}
