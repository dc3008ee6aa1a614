//! A collider bounded by a closed triangle mesh, sampled on anim-core's [`DistanceField`].

use anim_core::glam::{DMat3, DVec3};
use anim_core::surface::DistanceField;

use super::{Bend, Collider, Law};
use crate::geom::{MIN_LENGTH, outer};

/// A rigid, fixed obstacle bounded by a closed triangle mesh, acting on every particle through
/// the same penalty force as a [`Collider`] (see the [module docs](super)), with `phi` the
/// signed distance of the mesh's [`DistanceField`] (trilinear between its nodes) and `n` its
/// normalised gradient. The exact Jacobian's curvature term uses the field's Hessian `H`:
/// `dn/dx = (I - n n^T) H / |grad phi|`.
///
/// The field must cover every point within `thickness` of the mesh: a particle outside its
/// lattice feels nothing (make it with a margin of at least the thickness, as
/// [`DistanceField::around`] and [`ObstacleMesh::field`](anim_core::scene::ObstacleMesh::field)
/// take).
///
/// ```
/// use anim_core::surface::{ClosedSurface, DistanceField, icosphere};
/// use anim_springs::{Collider, MeshCollider, NetworkBuilder, EARTH_GRAVITY};
///
/// // A ball of radius 0.5 m (an icosphere of 1280 triangles) sampled every 2 cm.
/// let (p, t) = icosphere(3);
/// let ball = ClosedSurface::new(p.iter().map(|v| v.map(|c| 0.5 * c)).collect(), t)?;
/// let field = DistanceField::around(&ball, 0.02, 0.05)?;
/// // The contact parameters of a shape collider, on the mesh.
/// let like = Collider::ground(0.0, 1e3).with_damping(0.5).with_friction(1.0).with_smoothing(1e-3);
/// let mut b = NetworkBuilder::new();
/// b.gravity(EARTH_GRAVITY);
/// b.particle([0.0, 0.0, 0.52], 0.01);
/// b.mesh_collider(MeshCollider::like(field, &like));
/// let net = b.build()?;
/// assert_eq!(net.model().mesh_colliders().len(), 1);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone)]
pub struct MeshCollider {
    /// The signed distance of the placed mesh (negative inside).
    pub field: DistanceField,
    /// Penalty stiffness `k_c` (N/m, > 0).
    pub stiffness: f64,
    /// Normal damping `tau_n` (s/m, >= 0).
    pub damping: f64,
    /// Friction `tau_t` (s/m, >= 0).
    pub friction: f64,
    /// Width `delta` (m, >= 0) of the zone where the penalty stiffness ramps up.
    pub smoothing: f64,
    /// Distance `t` (m, >= 0) outside the mesh at which particles are held: the penalty acts on
    /// `phi - t`.
    pub thickness: f64,
}

impl MeshCollider {
    /// The mesh of `field` with penalty stiffness `stiffness`, no damping, friction, smoothing
    /// or thickness (add them with the `with_` methods).
    #[must_use]
    pub fn new(field: DistanceField, stiffness: f64) -> Self {
        Self { field, stiffness, damping: 0.0, friction: 0.0, smoothing: 0.0, thickness: 0.0 }
    }

    /// The mesh of `field` with the contact parameters (stiffness, damping, friction, smoothing,
    /// thickness) of `collider`.
    #[must_use]
    pub fn like(field: DistanceField, collider: &Collider) -> Self {
        Self {
            field,
            stiffness: collider.stiffness,
            damping: collider.damping,
            friction: collider.friction,
            smoothing: collider.smoothing,
            thickness: collider.thickness,
        }
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

    /// Sets the thickness `t` (m) at which particles are held outside the mesh.
    #[must_use]
    pub fn with_thickness(mut self, t: f64) -> Self {
        self.thickness = t;
        self
    }

    /// Checks the parameters; returns a description of the first problem.
    pub(crate) fn check(&self) -> Result<(), String> {
        self.law().check(self.thickness)
    }

    #[inline]
    pub(super) fn law(&self) -> Law {
        Law {
            stiffness: self.stiffness,
            damping: self.damping,
            friction: self.friction,
            smoothing: self.smoothing,
        }
    }

    /// Penetration `p = t - phi > 0`, outward normal and how the distance changes (see
    /// [`Bend::Field`]), or `None` outside (or outside the field's lattice). Where the
    /// field's gradient vanishes (on its medial axis) the push is along `+z`, without
    /// derivatives.
    #[inline]
    pub(crate) fn probe(&self, x: DVec3) -> Option<(f64, DVec3, Bend)> {
        let s = self.field.sample(x)?;
        let phi = s.distance - self.thickness;
        if phi >= 0.0 {
            return None;
        }
        let slope = s.gradient.length();
        if !(slope > MIN_LENGTH) {
            return Some((-phi, DVec3::Z, Bend::Field { slope: 0.0, dn_dx: DMat3::ZERO }));
        }
        let n = s.gradient / slope;
        let dn_dx = (DMat3::IDENTITY - outer(n, n)) * s.hessian * (1.0 / slope);
        Some((-phi, n, Bend::Field { slope, dn_dx }))
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
