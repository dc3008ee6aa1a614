//! A collider from a closed triangle mesh: anim-core's [`DistanceField`] of the surface gives the
//! signed distance and the outward normal where a shape would give them analytically; the
//! contact model is the shapes' ([`crate::collide`]).

use super::Collider;
use anim_core::glam::DVec3;
use anim_core::surface::DistanceField;

/// A collider whose geometry is a closed triangle mesh, sampled as a signed distance field
/// ([`DistanceField`], e.g. from anim-core's `scene::ObstacleMesh::field`
/// or [`DistanceField::around`]), on an optional kinematic body: a [`Collider`] whose `shape`
/// is the field, with the same contact parameters, setters and checks as a shape's.
///
/// A particle gets a contact as against a shape: the field's interpolated distance `phi(p)` and
/// its normalised gradient `n` stand for the shape's signed distance and outward normal, and the
/// closest surface point is `q = p - phi n`. Unlike a shape's, the contact is continuous: a
/// particle that moves farther over the substep than its distance to the surface has its path
/// followed through the field, and the contact is taken where the path first comes within the
/// thickness (see [`crate::collide`]), so that a surface thinner than the motion is not crossed. Where the field has no value (the
/// point lies outside its lattice) the particle is far outside the obstacle and gets no contact;
/// so does a point where the interpolated gradient vanishes. The field is solid: a particle deep
/// inside is pushed out along the gradient, which points away from the surface everywhere in the
/// lattice. A lattice should extend past the surface by more than the thickness plus the
/// [`contact_margin`](crate::PbdParams::contact_margin) so that no contact is cut off at its
/// border; anim-core's `scene::ObstacleMesh::field` with that margin does.
///
/// Accuracy: the field is the exact distance to the triangles at its nodes near the surface,
/// trilinear between them; on a smooth surface the interpolated distance is within about
/// `h^2 / 8` times the sum of the principal curvatures of the true one (`h` the lattice
/// spacing), and a sharp edge is rounded over about a spacing. A flat face is exact.
///
/// ```
/// use anim_core::solver::Solver;
/// use anim_core::surface::{ClosedSurface, DistanceField, icosphere};
/// use anim_pbd::{EARTH_GRAVITY, Method, MeshCollider, PbdBuilder, PbdParams, PbdSimulation, SolverKind};
///
/// // A mesh sphere of radius 0.3 m centred at the origin (1280 triangles).
/// let (positions, triangles) = icosphere(3);
/// let positions = positions.iter().map(|p| p.map(|c| 0.3 * c)).collect();
/// let ball = ClosedSurface::new(positions, triangles)?;
/// let field = DistanceField::around(&ball, 0.01, 0.05)?;
///
/// // A particle dropped on top of it rests at the surface plus the thickness.
/// let mut b = PbdBuilder::new();
/// b.gravity(EARTH_GRAVITY);
/// b.particle([0.0, 0.0, 0.5], 0.1);
/// b.mesh_collider(MeshCollider::new(field).with_thickness(0.01).with_friction(0.5, 0.5));
/// let model = b.build()?;
/// let mut state = model.rest_state();
/// let mut sim = PbdSimulation::new(model, PbdParams::new(Method::Xpbd, SolverKind::GaussSeidel, 5, 2))?;
/// for _ in 0..60 {
///     sim.step(&mut state, 1.0 / 60.0)?;
/// }
/// assert!((state.x[2] - 0.31).abs() < 1e-3, "z = {}", state.x[2]);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub type MeshCollider = Collider<DistanceField>;

impl MeshCollider {
    /// The signed distance (m, negative inside) and outward unit normal at `local` (in the
    /// collider's frame); `None` outside the field's lattice or where its gradient vanishes.
    #[inline]
    #[must_use]
    pub fn signed_distance(&self, local: DVec3) -> Option<(f64, DVec3)> {
        let s = self.shape.sample(local)?;
        let n = s.normal();
        (n != DVec3::ZERO).then_some((s.distance, n))
    }
}
