//! A collider from a closed triangle mesh: anim-core's [`DistanceField`] of the surface gives the
//! signed distance and the outward normal where a shape would give them analytically; the
//! contact model is the shapes' ([`crate::collide`]).

use super::check_contact;
use anim_core::glam::DVec3;
use anim_core::surface::DistanceField;

/// A collider whose geometry is a closed triangle mesh, sampled as a signed distance field
/// ([`DistanceField`], e.g. from [`ObstacleMesh::field`](anim_core::scene::ObstacleMesh::field)
/// or [`DistanceField::around`]), on an optional kinematic body, with the same contact
/// parameters as a shape [`Collider`](crate::Collider).
///
/// A particle gets a contact exactly as against a shape: the field's interpolated distance
/// `phi(p)` and its normalised gradient `n` stand for the shape's signed distance and outward
/// normal, and the closest surface point is `q = p - phi n`. Where the field has no value (the
/// point lies outside its lattice) the particle is far outside the obstacle and gets no contact;
/// so does a point where the interpolated gradient vanishes. The field is solid: a particle deep
/// inside is pushed out along the gradient, which points away from the surface everywhere in the
/// lattice. A lattice should extend past the surface by more than the thickness plus the
/// [`contact_margin`](crate::PbdParams::contact_margin) so that no contact is cut off at its
/// border; [`ObstacleMesh::field`](anim_core::scene::ObstacleMesh::field) with that margin does.
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
#[derive(Debug, Clone)]
pub struct MeshCollider {
    /// The signed distance of the surface (in the body's frame when `body` is set).
    pub field: DistanceField,
    /// The kinematic body carrying it, if any.
    pub body: Option<usize>,
    /// Distance kept between particle centres and the surface (m, >= 0; a particle radius).
    pub thickness: f64,
    /// Static friction coefficient `mu_s >= 0`.
    pub static_friction: f64,
    /// Kinetic friction coefficient `mu_k >= 0`.
    pub kinetic_friction: f64,
    /// Coefficient of restitution `e` in `[0, 1]`.
    pub restitution: f64,
}

impl MeshCollider {
    /// A collider of the surface whose signed distance is `field`, fixed in world space, with no
    /// thickness, no friction and no restitution.
    #[must_use]
    pub fn new(field: DistanceField) -> Self {
        Self {
            field,
            body: None,
            thickness: 0.0,
            static_friction: 0.0,
            kinetic_friction: 0.0,
            restitution: 0.0,
        }
    }

    /// Sets the thickness.
    #[must_use]
    pub fn with_thickness(mut self, thickness: f64) -> Self {
        self.thickness = thickness;
        self
    }

    /// Sets static and kinetic friction.
    #[must_use]
    pub fn with_friction(mut self, static_friction: f64, kinetic_friction: f64) -> Self {
        self.static_friction = static_friction;
        self.kinetic_friction = kinetic_friction;
        self
    }

    /// Sets the restitution.
    #[must_use]
    pub fn with_restitution(mut self, e: f64) -> Self {
        self.restitution = e;
        self
    }

    /// Puts the collider on kinematic body `body` (the field is then in the body's frame).
    #[must_use]
    pub fn on_body(mut self, body: usize) -> Self {
        self.body = Some(body);
        self
    }

    /// The signed distance (m, negative inside) and outward unit normal at `local` (in the
    /// collider's frame); `None` outside the field's lattice or where its gradient vanishes.
    #[inline]
    #[must_use]
    pub fn signed_distance(&self, local: DVec3) -> Option<(f64, DVec3)> {
        let s = self.field.sample(local)?;
        let n = s.normal();
        (n != DVec3::ZERO).then_some((s.distance, n))
    }

    /// Checks the parameters; the reason on failure.
    pub(crate) fn validate(&self, bodies: usize) -> Result<(), String> {
        check_contact(
            self.thickness,
            self.static_friction,
            self.kinetic_friction,
            self.restitution,
            self.body,
            bodies,
        )
    }
}
