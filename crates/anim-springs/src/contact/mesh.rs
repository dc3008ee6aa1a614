//! A collider bounded by a closed triangle mesh, sampled on anim-core's [`DistanceField`].

use anim_core::glam::DVec3;
use anim_core::surface::DistanceField;

use super::{Bend, Collider, Geometry};
use crate::geom::MIN_LENGTH;

/// A rigid, fixed obstacle bounded by a closed triangle mesh, acting on every particle through
/// the same penalty as a shape [`Collider`] (see the [module docs](super)): a [`Collider`] whose
/// `shape` is the mesh's [`DistanceField`], `phi` its trilinear interpolant and `n` its
/// normalised gradient. The energy is the shapes' `E(p)`, `p = t - phi`, and the elastic force
/// its exact negative gradient `e(p) grad phi = e(p) |grad phi| n`: the interpolant's gradient
/// is not of unit length between the nodes (up to `sqrt(3)` in principle, off by a few percent
/// beyond the exact band), and the force follows it so that the network's energy is the
/// potential of its forces. The exact Jacobian's terms in the field's Hessian `H` come from
/// `d|grad phi|/dx = H n` and `dn/dx = (I - n n^T) H / |grad phi|`.
///
/// The field must cover every point within `thickness` of the mesh: a particle outside its
/// lattice feels nothing (make it with a margin of at least the thickness, as
/// [`DistanceField::around`] and anim-core's `scene::ObstacleMesh::field`
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
pub type MeshCollider = Collider<DistanceField>;

impl MeshCollider {
    /// The mesh of `field` with the contact parameters (stiffness, damping, friction, smoothing,
    /// thickness) of `collider`.
    #[must_use]
    pub fn like(field: DistanceField, collider: &Collider) -> Self {
        let Collider { shape: _, stiffness, damping, friction, smoothing, thickness } = *collider;
        Collider { shape: field, stiffness, damping, friction, smoothing, thickness }
    }
}

impl Geometry for DistanceField {
    /// Any field: its lattice was checked when it was sampled.
    fn check(&self) -> Result<(), String> {
        Ok(())
    }

    /// Penetration `p = t - phi > 0`, outward normal and the field's slope and Hessian (see
    /// [`Bend::Field`]), or `None` outside (or outside the field's lattice). Where the field's
    /// gradient vanishes (on its medial axis) the normal is `+z` and the slope 0: no force, as
    /// the energy is stationary there.
    #[inline]
    fn probe(&self, x: DVec3, thickness: f64) -> Option<(f64, DVec3, Bend)> {
        let s = self.sample(x)?;
        let phi = s.distance - thickness;
        if phi >= 0.0 {
            return None;
        }
        let slope = s.gradient.length();
        if !(slope > MIN_LENGTH) {
            return Some((-phi, DVec3::Z, Bend::Field { slope: 0.0, hessian: s.hessian }));
        }
        Some((-phi, s.gradient / slope, Bend::Field { slope, hessian: s.hessian }))
    }
}
