//! Colliders: planes, spheres, axis-aligned boxes and capsules ([`Collider`]), and closed
//! triangle meshes sampled on anim-core's signed distance field ([`MeshCollider`]), as penalty
//! forces with their Jacobians.
//!
//! # Why penalty forces
//!
//! anim-core's integrators advance a [`MechanicalSystem`](anim_core::integrate::MechanicalSystem):
//! a force `f(t, x, v)` and its Jacobians. They own the state, check it for NaN and commit it
//! atomically; nothing outside the integrator may teleport a particle in the middle of a step
//! (multistep methods would notice and restart, and a projection would break the convergence
//! order and the no-allocation, state-unchanged-on-error invariants). So contact is a force:
//! the collider pushes a particle back in proportion to its penetration, and the implicit methods
//! see that force's Jacobian like any spring's.
//!
//! # The force
//!
//! For a collider with signed distance `phi(x)` (positive outside) and outward normal
//! `n(x) = grad phi` ([`Shape::signed_distance`]), and thickness `t` ([`Collider::thickness`],
//! usually 0), the penetration is `p = max(0, t - phi(x))`. Inside a box `-phi` is the distance
//! to the nearest face and `n` that face's normal; inside a capsule the distance to its surface
//! along the line from the nearest axis point. While `p > 0` the particle feels
//!
//! ```text
//! f = e(p) [ n  -  tau_n (n . v) n  -  tau_t (v - (n . v) n) ]
//! ```
//!
//! - `e(p) n`: the elastic penalty force. With stiffness `k_c` ([`Collider::stiffness`]) and
//!   smoothing width `delta` ([`Collider::smoothing`]), `e(p) = k_c p^2 / (2 delta)` for
//!   `p < delta` and `k_c (p - delta/2)` beyond: the stiffness `e'(p)` ramps from 0 to `k_c` over
//!   `delta`, so the force is C1 and its Jacobian continuous. With `delta = 0` it is the plain
//!   penalty `k_c p`, whose Jacobian jumps from 0 to `k_c` at first touch: Newton's method then
//!   tends to cycle between "outside" and "deep inside" when `h^2 k_c / m` is large (a jelly
//!   cube at `k_c = 1e5`, `h = 0.01` fails without smoothing and converges with
//!   `delta = 1 mm`). The energy `E(p) = int_0^p e` (`k_c p^3 / (6 delta)`, then
//!   `k_c (p^2/2 - delta p/2 + delta^2/6)`) is counted in the network's energy.
//! - `-e(p) tau_n v_n n`: normal damping ([`Collider::damping`] `tau_n`, in s/m), proportional to
//!   the elastic force (Hunt and Crossley's form), so it vanishes continuously when contact
//!   starts and ends; relative to the elastic force it is `tau_n v_n` (0.1 s/m damps 10% of it at
//!   1 m/s).
//! - `-e(p) tau_t v_t`: viscous friction ([`Collider::friction`] `tau_t`, in s/m):
//!   `|f_t| = tau_t |v_t| e(p)`, Coulomb friction whose coefficient grows linearly with slip speed
//!   (`mu = tau_t |v_t|`). It stops sliding without the non-smooth stick/slip switch of exact
//!   Coulomb friction, which Newton's method and a symmetric Jacobian cannot represent.
//!
//! For a mesh ([`MeshCollider`]) `phi` is a sampled field whose gradient is not exactly of unit
//! length, and the whole bracket is multiplied by `|grad phi|`: the elastic force is then the
//! exact negative gradient `-dE/dx = e(p) grad phi` of the energy `E(p)` that the network
//! counts (for a shape `|grad phi| = 1`).
//!
//! # The Jacobians
//!
//! `D = df/dv = -e(p) [tau_n n n^T + tau_t (I - n n^T)]` is exact, symmetric and negative
//! semi-definite. The exact `K = df/dx = -e'(p) g n^T + e(p) (dg/dn)(dn/dx)` (with
//! `g = n + (tau_t - tau_n)(n . v) n - tau_t v` the bracket above) has three parts: the normal
//! stiffness `-e'(p) (1 - tau_n v_n) n n^T`, the friction coupling `e'(p) tau_t v_t n^T` (not
//! symmetric), and the curvature term `e(p) (dg/dn)(dn/dx)` where the normal turns as the particle
//! slides: `dn/dx = (I - n n^T) / |x - c|` in a sphere (and a capsule's end caps, `c` the end,
//! and beside a box's corner within the thickness, `c` the corner), `(I - n n^T - a a^T) / r`
//! beside a capsule's axis (`a` the unit axis, `r` the distance to it) and beside a box's edge
//! within the thickness, zero in a plane and inside a box or beside its faces (its normal is
//! constant on each face's side of the inner ridges, where it jumps). For a mesh, `phi` is the
//! field's trilinear interpolant, `n` its normalised gradient, and the elastic force is the
//! energy's exact negative gradient `e(p) |grad phi| n` (`|grad phi|` is 1 for a shape, about
//! 1 for a field): with `a = e(p) |grad phi|`, `K = g (grad a)^T + a (dg/dn)(dn/dx)`,
//! `grad a = -e'(p) |grad phi|^2 n + e(p) H n` and `a dn/dx = e(p) (I - n n^T) H`, `H` the
//! field's Hessian. In the default
//! [`JacobianMode::Definite`](crate::JacobianMode::Definite) only the normal stiffness is kept,
//! with `1 - tau_n v_n` clamped at 0 (times `|grad phi|^2` for a mesh): symmetric and negative semi-definite, as conjugate gradients
//! and Cholesky need, while the force itself is unchanged (Newton converges to the same step, a
//! little more slowly while particles slide). [`JacobianMode::Exact`](crate::JacobianMode::Exact)
//! keeps every term (finite differences check it).
//!
//! # Choosing the stiffness
//!
//! A particle of mass `m` resting on a collider sinks by `p = m g / k_c + delta / 2`, and its
//! contact frequency is `sqrt(k_c / m)`: explicit methods need `dt` below about `sqrt(m / k_c)`,
//! implicit methods do not. `delta` of a millimetre or so (well below the spring lengths) makes
//! implicit steps robust.

use crate::geom::{MIN_LENGTH, outer};
use anim_core::glam::{DMat3, DVec3};
#[cfg(feature = "serde")]
use anim_core::scene::is_default;

/// The geometry of a collider: anim-core's shared [`Shape`], re-exported here. The penalty
/// contact handles all four: plane, sphere, axis-aligned box and capsule.
pub use anim_core::geometry::Shape;

/// How a collider's signed distance changes as a particle moves inside it: its gradient's length
/// and how the outward normal turns.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Bend {
    /// A shape's: the gradient is the unit normal, `dn/dx = curvature (I - n n^T - axis axis^T)`.
    Turn {
        /// `1 / r`: `r` the distance to a sphere's centre, a capsule's axis, or a box's nearest
        /// edge or corner (outside it, within the thickness); 0 when the normal is constant (a
        /// plane, a box's inside or beside a face, a particle at the centre or on the axis).
        curvature: f64,
        /// The unit axis of a capsule beside its cylindrical part, or of a box's edge; zero
        /// otherwise.
        axis: DVec3,
    },
    /// A distance field's ([`MeshCollider`]): the gradient is `slope n` (`slope` about 1) and
    /// its derivative the field's Hessian `H`.
    Field {
        /// `|grad phi|`.
        slope: f64,
        /// The field's Hessian `H` (symmetric).
        hessian: DMat3,
    },
}

impl Bend {
    const NONE: Bend = Bend::Turn { curvature: 0.0, axis: DVec3::ZERO };

    /// Turning about a point, as in a sphere.
    fn round(curvature: f64) -> Self {
        Bend::Turn { curvature, axis: DVec3::ZERO }
    }

    /// `|grad phi|`: 1 for a shape, about 1 for a field.
    #[inline]
    fn slope(&self) -> f64 {
        match *self {
            Bend::Turn { .. } => 1.0,
            Bend::Field { slope, .. } => slope,
        }
    }
}

/// What a collider's geometry gives the penalty law: the penetration of a point into it grown by
/// a thickness, with the outward normal and how both change ([`Bend`]).
pub(crate) trait Geometry {
    /// Penetration `p = thickness - phi(x) > 0`, outward unit normal and [`Bend`], or `None`
    /// when `x` is outside the grown geometry.
    fn probe(&self, x: DVec3, thickness: f64) -> Option<(f64, DVec3, Bend)>;

    /// Checks the geometry; a description of the problem.
    fn check(&self) -> Result<(), String>;
}

/// A rigid, fixed obstacle acting on every particle through a penalty force (see the
/// [module docs](self)). The geometry is a [`Shape`] (the default, `Collider`) or the signed
/// distance field of a closed triangle mesh ([`MeshCollider`], `Collider<DistanceField>`); the
/// penalty parameters, their setters and their checks are the same for both.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct Collider<G = Shape> {
    /// The geometry: a [`Shape`], or a mesh's [`DistanceField`](anim_core::surface::DistanceField).
    pub shape: G,
    /// Penalty stiffness `k_c` (N/m, > 0).
    pub stiffness: f64,
    /// Normal damping `tau_n` (s/m, >= 0): the damping force is `tau_n |v_n|` times the elastic one.
    pub damping: f64,
    /// Friction `tau_t` (s/m, >= 0): the friction force is `tau_t |v_t|` times the elastic normal one.
    pub friction: f64,
    /// Width `delta` (m, >= 0) of the zone where the penalty stiffness ramps up from 0 to `k_c`;
    /// 0 gives the plain penalty `k_c p`.
    #[cfg_attr(feature = "serde", serde(default))]
    pub smoothing: f64,
    /// Distance `t` (m, >= 0) outside the geometry at which particles are held: the penalty acts
    /// on `phi - t`, the signed distance to the geometry grown by `t` (a plane moved out along its
    /// normal, a sphere's or capsule's radius plus `t`, a box with its edges and corners rounded
    /// to radius `t`, a mesh offset by `t`). A cloth's thickness: its triangles then lie clear of
    /// a curved obstacle instead of cutting its surface between their vertices. Default 0.
    #[cfg_attr(feature = "serde", serde(default, skip_serializing_if = "is_default"))]
    pub thickness: f64,
}

impl<G> Collider<G> {
    /// The geometry `shape` with penalty stiffness `stiffness`, no damping, friction, smoothing
    /// or thickness (add them with the `with_` methods).
    #[must_use]
    pub fn new(shape: G, stiffness: f64) -> Self {
        Self { shape, stiffness, damping: 0.0, friction: 0.0, smoothing: 0.0, thickness: 0.0 }
    }

    /// Sets the normal damping `tau_n` (s/m).
    #[must_use]
    pub fn with_damping(mut self, tau_n: f64) -> Self {
        self.damping = tau_n;
        self
    }

    /// Sets the friction `tau_t` (s/m).
    #[must_use]
    pub fn with_friction(mut self, tau_t: f64) -> Self {
        self.friction = tau_t;
        self
    }

    /// Sets the smoothing width `delta` (m).
    #[must_use]
    pub fn with_smoothing(mut self, delta: f64) -> Self {
        self.smoothing = delta;
        self
    }

    /// Sets the thickness `t` (m) at which particles are held outside the geometry.
    #[must_use]
    pub fn with_thickness(mut self, t: f64) -> Self {
        self.thickness = t;
        self
    }

    /// The penalty law of the collider's parameters.
    #[inline]
    pub(crate) fn law(&self) -> Law {
        Law {
            stiffness: self.stiffness,
            damping: self.damping,
            friction: self.friction,
            smoothing: self.smoothing,
        }
    }
}

// Every method here is crate-private: the trait bound is the crate's own business.
#[allow(private_bounds)]
impl<G: Geometry> Collider<G> {
    /// Checks the parameters and the geometry; returns a description of the first problem (a
    /// shape's names the shape).
    pub(crate) fn check(&self) -> Result<(), String> {
        self.law().check(self.thickness)?;
        self.shape.check()
    }

    /// Penetration `p > 0` of the geometry grown by the thickness, outward normal and how the
    /// normal turns (see [`Bend`]), or `None` when the particle is outside.
    #[inline]
    pub(crate) fn probe(&self, x: DVec3) -> Option<(f64, DVec3, Bend)> {
        self.shape.probe(x, self.thickness)
    }

    /// Force on a particle at `(x, v)`.
    #[inline]
    pub(crate) fn force(&self, x: DVec3, v: DVec3) -> DVec3 {
        self.law().force(self.probe(x), v)
    }

    /// Penalty energy `E(p)`.
    #[inline]
    pub(crate) fn energy(&self, x: DVec3) -> f64 {
        self.law().energy(self.probe(x))
    }

    /// Adds the Jacobians `df/dx` (definite or exact) and `df/dv` at `(x, v)` to `k` and `d`.
    #[inline]
    pub(crate) fn jacobians(&self, x: DVec3, v: DVec3, exact: bool, k: &mut DMat3, d: &mut DMat3) {
        self.law().jacobians(self.probe(x), v, exact, k, d);
    }
}

impl Collider {
    /// The ground plane `z = height` with outward normal `+z`, penalty stiffness `stiffness`, no
    /// damping, friction or smoothing (add them with the `with_` methods).
    #[must_use]
    pub fn ground(height: f64, stiffness: f64) -> Self {
        Self::new(Shape::ground(height), stiffness)
    }

    /// A solid sphere with penalty stiffness `stiffness`, no damping, friction or smoothing.
    #[must_use]
    pub fn sphere(center: [f64; 3], radius: f64, stiffness: f64) -> Self {
        Self::new(Shape::Sphere { center, radius }, stiffness)
    }

    /// A copy with a unit plane normal (called once the parameters are checked).
    pub(crate) fn normalized(mut self) -> Self {
        self.shape = self.shape.normalized();
        self
    }
}

impl Geometry for Shape {
    fn check(&self) -> Result<(), String> {
        Shape::check(self)
    }

    #[inline]
    fn probe(&self, x: DVec3, thickness: f64) -> Option<(f64, DVec3, Bend)> {
        match *self {
            Shape::Plane { point, normal } => {
                let n = DVec3::from_array(normal);
                let phi = (x - DVec3::from_array(point)).dot(n) - thickness;
                (phi < 0.0).then_some((-phi, n, Bend::NONE))
            }
            Shape::Sphere { center, radius } => {
                let radius = radius + thickness;
                let d = x - DVec3::from_array(center);
                let r = d.length();
                if r >= radius {
                    return None;
                }
                // At the exact centre the normal is undefined: push out along +z.
                if r > MIN_LENGTH {
                    Some((radius - r, d / r, Bend::round(1.0 / r)))
                } else {
                    Some((radius - r, DVec3::Z, Bend::NONE))
                }
            }
            Shape::Box { center, half_extents } => {
                let (distance, n) = self.signed_distance(x);
                let phi = distance - thickness;
                if phi >= 0.0 {
                    return None;
                }
                // Inside, the nearest face's normal: constant. Outside (within the thickness),
                // beside a face it is constant too, beside an edge it turns about the edge, beside
                // a corner about the corner.
                let q = (x - DVec3::from_array(center)).abs() - DVec3::from_array(half_extents);
                let out = q.cmpgt(DVec3::ZERO);
                let bend = match (out.bitmask().count_ones(), distance > MIN_LENGTH) {
                    (2, true) => {
                        let along = DVec3::select(out, DVec3::ZERO, DVec3::ONE);
                        Bend::Turn { curvature: 1.0 / distance, axis: along }
                    }
                    (3, true) => Bend::round(1.0 / distance),
                    _ => Bend::NONE,
                };
                Some((-phi, n, bend))
            }
            Shape::Capsule { a, b, radius } => {
                let (distance, n) = self.signed_distance(x);
                let phi = distance - thickness;
                if phi >= 0.0 {
                    return None;
                }
                // The distance to the axis; on it the normal is any perpendicular, fixed.
                let r = radius + distance;
                if !(r > MIN_LENGTH) {
                    return Some((-phi, n, Bend::NONE));
                }
                let (a, b) = (DVec3::from_array(a), DVec3::from_array(b));
                let ab = b - a;
                let t = (x - a).dot(ab) / ab.length_squared();
                let bend = if t > 0.0 && t < 1.0 {
                    Bend::Turn { curvature: 1.0 / r, axis: ab.normalize() }
                } else {
                    Bend::round(1.0 / r)
                };
                Some((-phi, n, bend))
            }
        }
    }
}

/// The penalty law shared by the shape and mesh colliders: the force, energy and Jacobians of a
/// particle given its penetration, normal and [`Bend`] (see the [module docs](self)).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Law {
    stiffness: f64,
    damping: f64,
    friction: f64,
    smoothing: f64,
}

impl Law {
    /// Checks the parameters and a thickness.
    pub(crate) fn check(&self, thickness: f64) -> Result<(), String> {
        if !(self.stiffness > 0.0 && self.stiffness.is_finite()) {
            return Err(format!("stiffness must be positive and finite, got {}", self.stiffness));
        }
        if !(self.damping >= 0.0 && self.damping.is_finite()) {
            return Err(format!("damping must be non-negative and finite, got {}", self.damping));
        }
        if !(self.friction >= 0.0 && self.friction.is_finite()) {
            return Err(format!("friction must be non-negative and finite, got {}", self.friction));
        }
        if !(self.smoothing >= 0.0 && self.smoothing.is_finite()) {
            return Err(format!("smoothing must be non-negative and finite, got {}", self.smoothing));
        }
        if !(thickness >= 0.0 && thickness.is_finite()) {
            return Err(format!("thickness must be non-negative and finite, got {thickness}"));
        }
        Ok(())
    }

    /// Elastic normal force magnitude `phi(p)`, its derivative `phi'(p)` and energy `E(p)` (see
    /// the [module docs](self)).
    #[inline]
    fn elastic(&self, p: f64) -> (f64, f64, f64) {
        let (kc, delta) = (self.stiffness, self.smoothing);
        if p >= delta {
            (kc * (p - 0.5 * delta), kc, kc * (0.5 * p * p - 0.5 * delta * p + delta * delta / 6.0))
        } else {
            (kc * p * p / (2.0 * delta), kc * p / delta, kc * p * p * p / (6.0 * delta))
        }
    }

    /// Force on a particle of velocity `v` at a probe's result: the elastic force
    /// `-dE/dx = e(p) |grad phi| n` with its damping and friction.
    #[inline]
    fn force(&self, probe: Option<(f64, DVec3, Bend)>, v: DVec3) -> DVec3 {
        match probe {
            None => DVec3::ZERO,
            Some((p, n, bend)) => {
                let push = self.elastic(p).0 * bend.slope();
                let vn = n.dot(v);
                let vt = v - vn * n;
                push * (n - self.damping * vn * n - self.friction * vt)
            }
        }
    }

    /// Penalty energy `E(p)`.
    #[inline]
    fn energy(&self, probe: Option<(f64, DVec3, Bend)>) -> f64 {
        probe.map_or(0.0, |(p, _, _)| self.elastic(p).2)
    }

    /// Adds the Jacobians `df/dx` (definite or exact) and `df/dv` at a probe's result to `k`
    /// and `d`.
    #[inline]
    fn jacobians(
        &self,
        probe: Option<(f64, DVec3, Bend)>,
        v: DVec3,
        exact: bool,
        k: &mut DMat3,
        d: &mut DMat3,
    ) {
        let Some((p, n, bend)) = probe else {
            return;
        };
        let (e, de, _) = self.elastic(p);
        // grad phi = s n, dp/dx = -s n: s = 1 for a shape, about 1 for a field. The force's
        // magnitude is a = e(p) s.
        let s = bend.slope();
        let a = e * s;
        let (tn, tt) = (self.damping, self.friction);
        let nn = outer(n, n);
        let proj = DMat3::IDENTITY - nn;
        let vn = n.dot(v);
        *d -= a * (tn * nn + tt * proj);
        if !exact {
            // The symmetric normal part of -e' s^2 g n^T (g . n = 1 - tau_n v_n), clamped to
            // stay negative semi-definite when the particle separates fast.
            *k -= (de * s * s * (1.0 - tn * vn).max(0.0)) * nn;
            return;
        }
        // f = a(x) g(n, v), g = n + (tau_t - tau_n)(n . v) n - tau_t v;
        // df/dx = g (grad a)^T + a (dg/dn) (dn/dx).
        let g = n + (tt - tn) * vn * n - tt * v;
        *k -= (de * s * s) * outer(g, n);
        let dg_dn = || DMat3::IDENTITY + (tt - tn) * (vn * DMat3::IDENTITY + outer(n, v));
        match bend {
            Bend::Turn { curvature, axis } if curvature > 0.0 => {
                // s = 1; dn/dx = curvature (I - n n^T - a a^T); a = 0 but beside a capsule's axis.
                let turn = if axis == DVec3::ZERO { proj } else { proj - outer(axis, axis) };
                *k += (e * curvature) * (dg_dn() * turn);
            }
            Bend::Field { hessian, .. } => {
                // grad a = -e' s^2 n + e H n (grad s = H n), and a dn/dx = e (I - n n^T) H.
                *k += e * (outer(g, hessian * n) + dg_dn() * proj * hessian);
            }
            Bend::Turn { .. } => {}
        }
    }
}

mod mesh;
pub use mesh::MeshCollider;

#[cfg(test)]
mod mesh_tests;
#[cfg(test)]
mod tests;
