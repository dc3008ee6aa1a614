//! Boundary conditions and contact: pinned degrees of freedom, kinematic vertex groups that follow
//! a prescribed motion, and rigid obstacles (a half-space ground or any plane, a sphere, an
//! axis-aligned box, a capsule: anim-core's shared collider
//! [`Shape`](anim_core::geometry::Shape); or a closed triangle mesh sampled on anim-core's
//! [`DistanceField`]), each with a Coulomb friction coefficient `mu >= 0` given when it is added
//! to a model ([`FemModel::add_obstacle_with_friction`](crate::model::FemModel::add_obstacle_with_friction),
//! [`FemModel::add_mesh_obstacle`](crate::model::FemModel::add_mesh_obstacle);
//! `mu = 0`, the default of `add_obstacle`, is frictionless). Both kinds are a [`Collider`] to
//! the contact code, which sees only `(phi, grad phi)` at a vertex.
//!
//! Contact is handled per integrator: the explicit step projects penetrating vertices back to the
//! obstacle surface and removes their approaching normal velocity; the implicit step adds the
//! penalty energy `kappa/2 max(-phi(x), 0)^2` (`phi` the signed distance, [`obstacle_distance`]
//! for a shape, the field's trilinear interpolant for a mesh) to the incremental potential, so
//! Newton's line search sees it: its gradient is `-kappa max(-phi, 0) grad phi` (for a shape
//! `grad phi = n`, the outward unit normal; for a mesh the interpolant's gradient, of about unit
//! length, so that the gradient is exactly the energy's) and its Hessian is taken as
//! `kappa grad phi grad phi^T` where `phi < 0`, the Gauss-Newton part, which drops the curvature
//! term `-kappa phi grad grad phi` (zero for a plane and inside a box, where `phi` is linear;
//! positive semi-definite or not for a sphere, a capsule or a mesh, so it is left out). Friction
//! is velocity-level Coulomb in the explicit step and IPC's lagged, smoothed friction potential
//! in the implicit one ([`crate::friction`]). Contact is vertex against obstacle only: no
//! self-collision, no body-body contact.
//!
//! A mesh obstacle's field covers the mesh's bounds widened by a margin; a vertex outside the
//! field's lattice is far outside the mesh and not in contact.

use anim_core::glam::DVec3;
use anim_core::surface::DistanceField;
use anim_material::nalgebra::{Rotation3, Unit, Vector3};
use serde::{Deserialize, Serialize};

/// How a kinematic vertex group moves: its vertex positions at time `t` are a function of their
/// positions `X` at time 0.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Motion {
    /// Held at the initial positions.
    Fixed,
    /// `x(t) = X + t v`.
    Translate {
        /// Velocity.
        velocity: [f64; 3],
    },
    /// `x(t) = c + R(omega t) (X - c)`, a rotation about the axis through `center`.
    Rotate {
        /// A point on the axis.
        center: [f64; 3],
        /// Axis direction (normalised on use).
        axis: [f64; 3],
        /// Angular velocity (rad/s), right-handed about `axis`.
        angular_velocity: f64,
    },
}

impl Motion {
    /// Position at time `t` of a vertex that was at `x0` at time 0.
    #[must_use]
    pub fn position(&self, x0: [f64; 3], t: f64) -> [f64; 3] {
        match *self {
            Motion::Fixed => x0,
            Motion::Translate { velocity } => {
                [x0[0] + t * velocity[0], x0[1] + t * velocity[1], x0[2] + t * velocity[2]]
            }
            Motion::Rotate { center, axis, angular_velocity } => {
                let a = Vector3::from(axis);
                if !(a.norm() > 0.0) {
                    return x0;
                }
                let r = Rotation3::from_axis_angle(&Unit::new_normalize(a), angular_velocity * t);
                let c = Vector3::from(center);
                let p = c + r * (Vector3::from(x0) - c);
                [p[0], p[1], p[2]]
            }
        }
    }
}

/// A group of vertices moving with a prescribed [`Motion`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct KinematicGroup {
    /// The vertices.
    pub vertices: Vec<usize>,
    /// Their motion.
    pub motion: Motion,
    /// Their positions at time 0.
    pub initial: Vec<[f64; 3]>,
}

/// A rigid obstacle's geometry: anim-core's shared [`Shape`](anim_core::geometry::Shape),
/// re-exported under this name (its friction coefficient is stored by the model, see
/// [`FemModel::obstacle_friction`](crate::model::FemModel::obstacle_friction)). FEM contact
/// handles all four shapes: planes, spheres, axis-aligned boxes and capsules.
pub use anim_core::geometry::Shape as Obstacle;

/// Signed distance `phi(x)` (negative inside) of an obstacle and the unit outward normal
/// `grad phi`.
///
/// A plane is evaluated as `n . x - n . point` with `n` the normalised normal (for the ground
/// `z >= h`, exactly `z - h`). A box and a capsule are
/// [`Shape::signed_distance`](anim_core::geometry::Shape::signed_distance): inside a box, the
/// distance to and the normal of the nearest face; outside, the distance to the nearest point
/// of the box (a face, edge or corner), whose normal turns continuously around edges and
/// corners; for a capsule, the distance to its axis segment minus the radius.
#[inline]
#[must_use]
pub fn obstacle_distance(obstacle: &Obstacle, x: [f64; 3]) -> (f64, [f64; 3]) {
    match *obstacle {
        Obstacle::Plane { point, normal } => {
            let l = (normal[0] * normal[0] + normal[1] * normal[1] + normal[2] * normal[2]).sqrt();
            let n = [normal[0] / l, normal[1] / l, normal[2] / l];
            let offset = n[0] * point[0] + n[1] * point[1] + n[2] * point[2];
            (n[0] * x[0] + n[1] * x[1] + n[2] * x[2] - offset, n)
        }
        Obstacle::Sphere { center, radius } => {
            let d = [x[0] - center[0], x[1] - center[1], x[2] - center[2]];
            let r = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            if r > 0.0 { (r - radius, [d[0] / r, d[1] / r, d[2] / r]) } else { (-radius, [0.0, 0.0, 1.0]) }
        }
        Obstacle::Box { .. } | Obstacle::Capsule { .. } => {
            let (phi, n) = obstacle.signed_distance(anim_core::glam::DVec3::from_array(x));
            (phi, n.to_array())
        }
    }
}

/// The penalty contact of a vertex at `x` with `obstacle` at stiffness `k`: `None` outside
/// (`phi >= 0`); inside, the energy `k/2 phi^2`, its gradient `k phi n` (that is,
/// `-k max(-phi, 0) n`) and the Gauss-Newton Hessian `k n n^T` (row-major 3 x 3), with `phi` and
/// `n` of [`obstacle_distance`].
#[inline]
#[must_use]
pub fn penalty(obstacle: &Obstacle, k: f64, x: [f64; 3]) -> Option<(f64, [f64; 3], [f64; 9])> {
    let (phi, n) = obstacle_distance(obstacle, x);
    penalty_of(phi, n, k)
}

/// The penalty of a vertex at signed distance `phi` with distance gradient `g` (see [`penalty`]).
#[inline]
fn penalty_of(phi: f64, g: [f64; 3], k: f64) -> Option<(f64, [f64; 3], [f64; 9])> {
    if phi < 0.0 {
        let grad = [k * phi * g[0], k * phi * g[1], k * phi * g[2]];
        let hess = std::array::from_fn(|i| k * g[i / 3] * g[i % 3]);
        Some((0.5 * k * phi * phi, grad, hess))
    } else {
        None
    }
}

/// A rigid obstacle as the contact code sees it: a shape or a mesh's distance field.
#[derive(Debug, Clone, Copy)]
pub enum Collider<'a> {
    /// A plane, sphere, box or capsule ([`obstacle_distance`]).
    Shape(&'a Obstacle),
    /// A closed triangle mesh sampled on a [`DistanceField`] (trilinear between its nodes).
    Mesh(&'a DistanceField),
}

impl Collider<'_> {
    /// `(phi, grad phi)` at `x`: for a shape, [`obstacle_distance`] (the gradient is the unit
    /// normal); for a mesh, the field's interpolated distance and its gradient (about unit
    /// length, zero on the medial axis). `None` outside a mesh's lattice: far outside, no
    /// contact.
    #[inline]
    #[must_use]
    pub fn gradient(&self, x: [f64; 3]) -> Option<(f64, [f64; 3])> {
        match self {
            Collider::Shape(o) => Some(obstacle_distance(o, x)),
            Collider::Mesh(field) => {
                field.sample(DVec3::from_array(x)).map(|s| (s.distance, s.gradient.to_array()))
            }
        }
    }

    /// `(phi, n)` at `x`, `n` the outward unit normal (for a mesh the normalised gradient of the
    /// field, zero where the gradient vanishes); `None` outside a mesh's lattice.
    #[inline]
    #[must_use]
    pub fn distance(&self, x: [f64; 3]) -> Option<(f64, [f64; 3])> {
        match self {
            Collider::Shape(o) => Some(obstacle_distance(o, x)),
            Collider::Mesh(field) => {
                field.sample(DVec3::from_array(x)).map(|s| (s.distance, s.normal().to_array()))
            }
        }
    }

    /// The penalty contact of a vertex at `x` at stiffness `k`: `None` outside (`phi >= 0`, or
    /// outside a mesh's lattice); inside, the energy `k/2 phi^2`, its gradient `k phi g` and the
    /// Gauss-Newton Hessian `k g g^T` (row-major 3 x 3), with `(phi, g)` of
    /// [`gradient`](Self::gradient). For a shape this is [`penalty`].
    #[inline]
    #[must_use]
    pub fn penalty(&self, k: f64, x: [f64; 3]) -> Option<(f64, [f64; 3], [f64; 9])> {
        let (phi, g) = self.gradient(x)?;
        penalty_of(phi, g, k)
    }
}

/// The rigid obstacles of a model, as the contact code reads them: the shapes and the meshes,
/// each with its friction coefficient, shapes first.
#[derive(Debug, Clone, Copy, Default)]
pub struct Colliders<'a> {
    /// The shapes.
    pub shapes: &'a [Obstacle],
    /// The friction coefficient of each shape.
    pub shape_friction: &'a [f64],
    /// The meshes' distance fields.
    pub meshes: &'a [DistanceField],
    /// The friction coefficient of each mesh.
    pub mesh_friction: &'a [f64],
}

impl<'a> Colliders<'a> {
    /// Whether there is no obstacle.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.shapes.is_empty() && self.meshes.is_empty()
    }

    /// Every obstacle with its friction coefficient: the shapes, then the meshes.
    pub fn iter(&self) -> impl Iterator<Item = (Collider<'a>, f64)> + use<'a> {
        let shapes = self.shapes.iter().map(Collider::Shape).zip(self.shape_friction.iter().copied());
        let meshes = self.meshes.iter().map(Collider::Mesh).zip(self.mesh_friction.iter().copied());
        shapes.chain(meshes)
    }

    /// How many obstacles have a positive friction coefficient.
    #[must_use]
    pub fn frictional(&self) -> usize {
        self.shape_friction.iter().chain(self.mesh_friction).filter(|&&mu| mu > 0.0).count()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rotation_motion_is_a_rigid_turn() {
        let m = Motion::Rotate {
            center: [1.0, 0.0, 0.0],
            axis: [1.0, 0.0, 0.0],
            angular_velocity: std::f64::consts::PI,
        };
        let p = m.position([2.0, 1.0, 0.0], 0.5);
        assert!((p[0] - 2.0).abs() < 1e-15 && p[1].abs() < 1e-15 && (p[2] - 1.0).abs() < 1e-15, "{p:?}");
        let t = Motion::Translate { velocity: [0.0, 0.0, -2.0] }.position([1.0, 1.0, 1.0], 0.25);
        assert_eq!(t, [1.0, 1.0, 0.5]);
    }

    #[test]
    fn obstacle_distances() {
        let (d, n) = obstacle_distance(&Obstacle::ground(1.0), [3.0, 4.0, 0.5]);
        assert_eq!((d, n), (-0.5, [0.0, 0.0, 1.0]));
        let tilted = Obstacle::Plane { point: [0.0, 0.0, 2.0], normal: [0.0, 3.0, 4.0] };
        let (d, n) = obstacle_distance(&tilted, [0.0, 3.0, 6.0]);
        assert!((d - 5.0).abs() < 1e-15 && n == [0.0, 0.6, 0.8], "{d} {n:?}");
        let (d, n) = obstacle_distance(&Obstacle::Sphere { center: [0.0; 3], radius: 1.0 }, [0.0, 3.0, 0.0]);
        assert_eq!((d, n), (2.0, [0.0, 1.0, 0.0]));
    }
}
