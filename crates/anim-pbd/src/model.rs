//! The model: particles with their masses, constraints, closed meshes of global volume
//! constraints, kinematic bodies, colliders, gravity and wind. Built once by
//! [`PbdBuilder`](crate::PbdBuilder), never changed by an algorithm.
//!
//! # State layout
//!
//! A model of `N` particles has its positions and velocities in anim-core's
//! [`State`](anim_core::integrate::State): `x = [x0, y0, z0, x1, ...]`, `v` likewise, and the
//! time `t` (which drives the kinematic bodies). The model never holds positions; it reads them
//! from the state it is handed.

use crate::collide::{BodyContact, Collider, KinematicBody, MeshCollider};
use crate::constraint::{AttachTarget, Constraint, ConstraintFunction, load};
use anim_core::glam::DVec3;
use anim_core::integrate::State;

/// A particle: PBD's vertex `i` with mass `m_i` (its position and velocity live in the
/// state). A pinned particle has inverse mass `w_i = 0`: nothing moves it.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct Particle {
    /// Mass `m_i` (kg, > 0); kept for a pinned particle's momentum and energy.
    pub mass: f64,
    /// Pinned: `w_i = 0`.
    pub pinned: bool,
}

/// A closed, consistently oriented triangle mesh whose enclosed volume a
/// [`GlobalVolume`](ConstraintFunction::GlobalVolume) constraint keeps.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct VolumeMesh {
    /// The particles of the mesh, in increasing order (the constraint's index set).
    pub vertices: Vec<usize>,
    /// Triangles as indices into `vertices`, oriented with outward normals.
    pub triangles: Vec<[u32; 3]>,
}

impl VolumeMesh {
    /// Enclosed volume `sum_t x_a . (x_b x x_c) / 6` at positions `x`.
    #[must_use]
    pub fn volume(&self, x: &[f64]) -> f64 {
        let mut v = 0.0;
        for t in &self.triangles {
            let [a, b, c] = t.map(|k| load(x, self.vertices[k as usize]));
            v += a.dot(b.cross(c));
        }
        v / 6.0
    }

    /// Writes the volume gradient per mesh vertex into `grad` and returns the volume.
    pub(crate) fn gradient(&self, p: impl Fn(usize) -> DVec3, grad: &mut [DVec3]) -> f64 {
        grad.iter_mut().for_each(|g| *g = DVec3::ZERO);
        let mut v = 0.0;
        for t in &self.triangles {
            let [ia, ib, ic] = t.map(|k| k as usize);
            let (a, b, c) = (p(self.vertices[ia]), p(self.vertices[ib]), p(self.vertices[ic]));
            let bc = b.cross(c);
            v += a.dot(bc);
            grad[ia] += bc;
            grad[ib] += c.cross(a);
            grad[ic] += a.cross(b);
        }
        for g in grad.iter_mut() {
            *g /= 6.0;
        }
        v / 6.0
    }
}

/// A body whose particles collide with the surfaces of the other contact bodies, and whose
/// surface their particles collide with ([`PbdBuilder::contact_body`](crate::PbdBuilder::contact_body)).
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct ContactBody {
    /// Its particles: model indices `particles.0 .. particles.1`.
    pub particles: (usize, usize),
    /// Its surface triangles, as model particle indices within its range.
    pub triangles: Vec<[usize; 3]>,
    /// A closed surface, oriented outward: a particle is pushed out along the outward normal
    /// (one-sided, so a particle that went inside by less than the search reach, `thickness +
    /// contact_margin` plus both sides' motion over the substep, comes back out; one that went
    /// deeper gets no contact and stays inside). Otherwise the surface is two-sided (cloth): a
    /// particle stays on the side it was on at the start of the substep.
    pub closed: bool,
}

/// A uniform wind acting on the model's triangles: each triangle of area `A` and unit normal `n`
/// moving with the mean velocity `u` of its vertices feels `f = drag A ((w - u) . n) n`, shared
/// equally by its three vertices (the usual cloth wind model; Provot 1995).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct Wind {
    /// Wind velocity `w` (m/s).
    pub velocity: [f64; 3],
    /// Drag coefficient (kg/m^3, `rho C_d / 2` for air is about 0.6).
    pub drag: f64,
    /// Relative gust amplitude: the wind speed is scaled by `1 + gust sin(2 pi 0.5 t)`.
    pub gust: f64,
}

/// A gradient as `(particle, dC/dx_particle)` pairs.
pub type SparseGradient = Vec<(usize, [f64; 3])>;

/// Everything that does not change while simulating.
#[derive(Debug, Clone)]
pub struct PbdModel {
    pub(crate) particles: Vec<Particle>,
    pub(crate) inv_mass: Vec<f64>,
    pub(crate) positions: Vec<[f64; 3]>,
    pub(crate) constraints: Vec<Constraint>,
    pub(crate) volume_meshes: Vec<VolumeMesh>,
    pub(crate) colliders: Vec<Collider>,
    pub(crate) mesh_colliders: Vec<MeshCollider>,
    pub(crate) bodies: Vec<KinematicBody>,
    pub(crate) gravity: DVec3,
    pub(crate) wind: Option<Wind>,
    pub(crate) triangles: Vec<[usize; 3]>,
    pub(crate) edges: Vec<[usize; 2]>,
    pub(crate) tets: Vec<[usize; 4]>,
    pub(crate) contact_bodies: Vec<ContactBody>,
    pub(crate) body_contact: BodyContact,
    /// Constraints incident to each particle: `inc[inc_ptr[p]..inc_ptr[p + 1]]` as
    /// `(constraint, slot)` in increasing constraint order (slot: position in the index set).
    pub(crate) inc_ptr: Vec<usize>,
    pub(crate) inc: Vec<(u32, u32)>,
    /// Triangles incident to each particle (for the wind gather), in increasing order.
    pub(crate) tri_ptr: Vec<usize>,
    pub(crate) tri_inc: Vec<u32>,
}

impl PbdModel {
    /// Number of particles `N`.
    #[must_use]
    pub fn num_particles(&self) -> usize {
        self.particles.len()
    }

    /// Number of constraints `M` (not counting contacts, which are generated each step).
    #[must_use]
    pub fn num_constraints(&self) -> usize {
        self.constraints.len()
    }

    /// The particles.
    #[must_use]
    pub fn particles(&self) -> &[Particle] {
        &self.particles
    }

    /// Inverse masses `w_i = 1/m_i` (0 for pinned particles).
    #[must_use]
    pub fn inverse_masses(&self) -> &[f64] {
        &self.inv_mass
    }

    /// The positions the model was built from.
    #[must_use]
    pub fn rest_positions(&self) -> &[[f64; 3]] {
        &self.positions
    }

    /// The constraints, in the order they were added (the Gauss-Seidel order).
    #[must_use]
    pub fn constraints(&self) -> &[Constraint] {
        &self.constraints
    }

    /// The closed meshes of the global volume constraints.
    #[must_use]
    pub fn volume_meshes(&self) -> &[VolumeMesh] {
        &self.volume_meshes
    }

    /// Volume mesh `i`.
    ///
    /// # Panics
    /// If `i` is out of range.
    #[must_use]
    pub fn volume_mesh(&self, i: usize) -> &VolumeMesh {
        &self.volume_meshes[i]
    }

    /// The colliders.
    #[must_use]
    pub fn colliders(&self) -> &[Collider] {
        &self.colliders
    }

    /// The mesh colliders (their contacts are numbered after the shape colliders').
    #[must_use]
    pub fn mesh_colliders(&self) -> &[MeshCollider] {
        &self.mesh_colliders
    }

    /// The kinematic bodies.
    #[must_use]
    pub fn bodies(&self) -> &[KinematicBody] {
        &self.bodies
    }

    /// Gravity (m/s^2).
    #[must_use]
    pub fn gravity(&self) -> [f64; 3] {
        self.gravity.to_array()
    }

    /// The wind, if any.
    #[must_use]
    pub fn wind(&self) -> Option<Wind> {
        self.wind
    }

    /// Triangles for rendering (cloth, mesh and tet-mesh surfaces) and for the wind.
    #[must_use]
    pub fn triangles(&self) -> &[[usize; 3]] {
        &self.triangles
    }

    /// Line segments for rendering (ropes).
    #[must_use]
    pub fn edges(&self) -> &[[usize; 2]] {
        &self.edges
    }

    /// Tetrahedra (soft bodies), for output.
    #[must_use]
    pub fn tets(&self) -> &[[usize; 4]] {
        &self.tets
    }

    /// The contact bodies, whose particles collide with each other's surfaces.
    #[must_use]
    pub fn contact_bodies(&self) -> &[ContactBody] {
        &self.contact_bodies
    }

    /// The contact parameters between contact bodies.
    #[must_use]
    pub fn body_contact(&self) -> BodyContact {
        self.body_contact
    }

    /// The rest state: rest positions, zero velocities, `t = 0`.
    #[must_use]
    pub fn rest_state(&self) -> State {
        let x: Vec<f64> = self.positions.iter().flatten().copied().collect();
        let v = vec![0.0; x.len()];
        State::new(x, v)
    }

    /// The cardinality `n_j` of constraint `j` (the number of particles it involves).
    ///
    /// # Panics
    /// If `j` is out of range.
    #[must_use]
    pub fn cardinality(&self, j: usize) -> usize {
        match &self.constraints[j].function {
            ConstraintFunction::GlobalVolume { mesh, .. } => self.volume_meshes[*mesh].vertices.len(),
            _ => self.constraints[j].cardinality(),
        }
    }

    /// The index set of constraint `j`.
    ///
    /// # Panics
    /// If `j` is out of range.
    #[must_use]
    pub fn constraint_particles(&self, j: usize) -> &[usize] {
        match &self.constraints[j].function {
            ConstraintFunction::GlobalVolume { mesh, .. } => &self.volume_meshes[*mesh].vertices,
            _ => self.constraints[j].particles(),
        }
    }

    /// Constraints incident to particle `p`, in increasing order.
    pub fn incident(&self, p: usize) -> impl Iterator<Item = usize> + '_ {
        self.inc[self.inc_ptr[p]..self.inc_ptr[p + 1]].iter().map(|&(c, _)| c as usize)
    }

    /// World position of an attachment target at time `t`.
    #[must_use]
    pub fn target_at(&self, target: &AttachTarget, t: f64) -> [f64; 3] {
        match *target {
            AttachTarget::Point(p) => p,
            AttachTarget::Body { body, local } => {
                self.bodies[body].pose_at(t).apply(DVec3::from_array(local)).to_array()
            }
        }
    }

    /// `C_j(x)` and its gradient as `(particle, dC/dx_particle)` pairs, at positions `x` and time
    /// `t` (for attachments to moving bodies); `None` where the gradient is undefined (see
    /// [`constraint`](crate::constraint)). Allocates: for analysis and tests, not for solvers.
    ///
    /// # Panics
    /// If `j` is out of range or `x` has the wrong length.
    #[must_use]
    pub fn evaluate(&self, j: usize, x: &[f64], t: f64) -> Option<(f64, SparseGradient)> {
        assert_eq!(x.len(), 3 * self.num_particles(), "evaluate: wrong length of x");
        let c = &self.constraints[j];
        match &c.function {
            ConstraintFunction::GlobalVolume { mesh, rest_volume, pressure } => {
                let m = &self.volume_meshes[*mesh];
                let mut grad = vec![DVec3::ZERO; m.vertices.len()];
                let v = m.gradient(|i| load(x, i), &mut grad);
                let pairs = m.vertices.iter().zip(&grad).map(|(&p, g)| (p, g.to_array())).collect();
                Some((v - pressure * rest_volume, pairs))
            }
            ConstraintFunction::Attachment { target, .. } => {
                let t = DVec3::from_array(self.target_at(target, t));
                let (value, g) = c.evaluate(x, t)?;
                Some((value, c.particles().iter().zip(g).map(|(&p, g)| (p, g.to_array())).collect()))
            }
            _ => {
                let (value, g) = c.evaluate(x, DVec3::ZERO)?;
                Some((value, c.particles().iter().zip(g).map(|(&p, g)| (p, g.to_array())).collect()))
            }
        }
    }

    /// Linear momentum `sum m_i v_i` of the particles.
    ///
    /// # Panics
    /// If `v` has the wrong length.
    #[must_use]
    pub fn linear_momentum(&self, v: &[f64]) -> [f64; 3] {
        assert_eq!(v.len(), 3 * self.num_particles(), "linear_momentum: wrong length");
        let mut p = DVec3::ZERO;
        for (i, part) in self.particles.iter().enumerate() {
            p += part.mass * load(v, i);
        }
        p.to_array()
    }

    /// Angular momentum `sum m_i x_i x v_i` about the origin.
    ///
    /// # Panics
    /// If `x` or `v` has the wrong length.
    #[must_use]
    pub fn angular_momentum(&self, x: &[f64], v: &[f64]) -> [f64; 3] {
        assert!(x.len() == 3 * self.num_particles() && v.len() == x.len(), "angular_momentum: wrong length");
        let mut l = DVec3::ZERO;
        for (i, part) in self.particles.iter().enumerate() {
            l += part.mass * load(x, i).cross(load(v, i));
        }
        l.to_array()
    }

    /// Kinetic plus gravitational energy `sum m_i (|v_i|^2 / 2 - g . x_i)`.
    ///
    /// # Panics
    /// If `x` or `v` has the wrong length.
    #[must_use]
    pub fn kinetic_and_gravity_energy(&self, x: &[f64], v: &[f64]) -> f64 {
        let (kinetic, gravity) = self.kinetic_and_gravity_parts(x, v);
        kinetic + gravity
    }

    /// Kinetic and gravitational energy apart: `(sum m |v|^2 / 2, -sum m g . x)`.
    ///
    /// # Panics
    /// If `x` or `v` is not 3 per particle.
    #[must_use]
    pub fn kinetic_and_gravity_parts(&self, x: &[f64], v: &[f64]) -> (f64, f64) {
        assert!(x.len() == 3 * self.num_particles() && v.len() == x.len(), "energy: wrong length");
        let (mut kinetic, mut gravity) = (0.0, 0.0);
        for (i, part) in self.particles.iter().enumerate() {
            kinetic += part.mass * 0.5 * load(v, i).length_squared();
            gravity -= part.mass * self.gravity.dot(load(x, i));
        }
        (kinetic, gravity)
    }
}
