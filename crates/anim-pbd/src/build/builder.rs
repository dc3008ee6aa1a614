//! The builder itself: [`PbdBuilder`] collects particles (position, mass, pins), kinematic
//! bodies, colliders, gravity and wind, and constraints one at a time: distance, dihedral and
//! isometric bending, tetrahedral volume, the global volume of a closed mesh (a balloon: the
//! mesh keeps `pressure` times its rest volume, Müller et al. 2007, section 4.4) and attachments.
//! A constraint is recorded with its parameters and the index it will have in the model; its
//! rest value (length, angle, weights, volume) is taken from the positions when the model is
//! built, where every input is checked.
//!
//! The helpers below check the shape builders' own parameters and name the offending one.

use super::error::{BuildError, InputError};
use crate::collide::{BodyContact, Collider, KinematicBody, MeshCollider};
use crate::constraint::{AttachTarget, ConstraintParams};
use crate::model::{ContactBody, Wind};
use anim_core::glam::DVec3;

/// How mesh vertices get their mass.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "kebab-case"))]
pub enum MeshMass {
    /// Every vertex has this mass (kg).
    PerVertex(f64),
    /// Density per area (kg/m^2, triangle meshes) or per volume (kg/m^3, tet meshes), lumped:
    /// each element gives its vertices equal shares of its mass.
    Density(f64),
}

/// A constraint as recorded: its rest values are computed from the positions, and every index
/// checked, when the model is built.
#[derive(Debug, Clone)]
pub(super) enum Pending {
    Distance { i: usize, j: usize, rest: Option<f64> },
    Dihedral([usize; 4]),
    Isometric([usize; 4]),
    Tet([usize; 4]),
    Volume { mesh: usize, pressure: f64 },
    Attach { particle: usize, target: AttachTarget, distance: f64 },
}

/// Collects particles, constraints, pins, bodies, colliders, gravity and wind, then checks them
/// all in [`build`](Self::build). Gravity is zero until set.
#[derive(Debug, Clone, Default)]
pub struct PbdBuilder {
    pub(super) positions: Vec<[f64; 3]>,
    pub(super) masses: Vec<f64>,
    pub(super) pins: Vec<usize>,
    pub(super) pending: Vec<(Pending, ConstraintParams)>,
    pub(super) volume_meshes: Vec<(Vec<[usize; 3]>, usize)>,
    pub(super) colliders: Vec<Collider>,
    pub(super) mesh_colliders: Vec<MeshCollider>,
    pub(super) bodies: Vec<KinematicBody>,
    pub(super) gravity: [f64; 3],
    pub(super) wind: Option<Wind>,
    pub(super) triangles: Vec<[usize; 3]>,
    pub(super) edges: Vec<[usize; 2]>,
    pub(super) tets: Vec<[usize; 4]>,
    pub(super) contact_bodies: Vec<ContactBody>,
    pub(super) body_contact: BodyContact,
}

/// Standard gravity pointing down the z axis (m/s^2): the scenes' convention is z up.
pub const EARTH_GRAVITY: [f64; 3] = [0.0, 0.0, -9.81];

/// A [`InputError::BadParameter`] of builder `shape`.
pub(super) fn bad(
    shape: &'static str,
    name: &'static str,
    requirement: &'static str,
    value: impl ToString,
) -> BuildError {
    BuildError::Input(InputError::BadParameter { shape, name, requirement, value: value.to_string() })
}

/// `v` as a vector, or a [`InputError::BadParameter`] if it is not finite.
pub(super) fn check_vec(shape: &'static str, name: &'static str, v: [f64; 3]) -> Result<DVec3, BuildError> {
    if v.iter().all(|c| c.is_finite()) {
        Ok(DVec3::from_array(v))
    } else {
        Err(bad(shape, name, "must be finite", format!("{v:?}")))
    }
}

/// A [`InputError::BadParameter`] unless `v` is positive and finite.
pub(super) fn check_positive(shape: &'static str, name: &'static str, v: f64) -> Result<(), BuildError> {
    if v > 0.0 && v.is_finite() { Ok(()) } else { Err(bad(shape, name, "must be positive and finite", v)) }
}

/// A [`InputError::BadParameter`] unless the mass or density is positive and finite.
pub(super) fn check_mass(shape: &'static str, m: MeshMass) -> Result<(), BuildError> {
    match m {
        MeshMass::PerVertex(v) => check_positive(shape, "mass per vertex", v),
        MeshMass::Density(v) => check_positive(shape, "density", v),
    }
}

/// Sorted vertex pair.
pub(super) fn key(a: usize, b: usize) -> (usize, usize) {
    if a < b { (a, b) } else { (b, a) }
}

impl PbdBuilder {
    /// An empty builder without gravity.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    /// Number of particles added so far.
    #[must_use]
    pub fn num_particles(&self) -> usize {
        self.positions.len()
    }

    /// The triangles recorded so far (model indices): those of [`triangle`](Self::triangle), the
    /// triangle meshes' and the tetrahedral meshes' boundary faces, in the order they came.
    #[cfg(feature = "serde")]
    pub(crate) fn recorded_triangles(&self) -> &[[usize; 3]] {
        &self.triangles
    }

    /// Number of constraints added so far (the index the next one gets).
    #[must_use]
    pub fn num_constraints(&self) -> usize {
        self.pending.len()
    }

    /// Sets gravity (m/s^2), e.g. [`EARTH_GRAVITY`].
    pub fn gravity(&mut self, g: [f64; 3]) -> &mut Self {
        self.gravity = g;
        self
    }

    /// Sets a wind acting on the model's triangles.
    pub fn wind(&mut self, wind: Wind) -> &mut Self {
        self.wind = Some(wind);
        self
    }

    /// Adds a particle and returns its index.
    pub fn particle(&mut self, position: [f64; 3], mass: f64) -> usize {
        self.positions.push(position);
        self.masses.push(mass);
        self.positions.len() - 1
    }

    /// Pins particle `p` (inverse mass 0).
    pub fn pin(&mut self, p: usize) -> &mut Self {
        self.pins.push(p);
        self
    }

    /// Adds a kinematic body and returns its index.
    pub fn body(&mut self, body: KinematicBody) -> usize {
        self.bodies.push(body);
        self.bodies.len() - 1
    }

    /// Adds a collider and returns its index.
    pub fn collider(&mut self, c: Collider) -> usize {
        self.colliders.push(c);
        self.colliders.len() - 1
    }

    /// Adds a collider whose geometry is a closed triangle mesh's signed distance field
    /// ([`MeshCollider`]) and returns its index among the mesh colliders.
    pub fn mesh_collider(&mut self, c: MeshCollider) -> usize {
        self.mesh_colliders.push(c);
        self.mesh_colliders.len() - 1
    }

    /// Records a triangle for rendering and wind (it adds no constraint).
    pub fn triangle(&mut self, t: [usize; 3]) -> &mut Self {
        self.triangles.push(t);
        self
    }

    /// Records a line segment for rendering (it adds no constraint).
    pub fn edge(&mut self, e: [usize; 2]) -> &mut Self {
        self.edges.push(e);
        self
    }

    fn push(&mut self, c: Pending, params: ConstraintParams) -> usize {
        self.pending.push((c, params));
        self.pending.len() - 1
    }

    /// A distance constraint whose rest length is the particles' current distance; returns the
    /// constraint index.
    pub fn distance(&mut self, i: usize, j: usize, params: ConstraintParams) -> usize {
        self.push(Pending::Distance { i, j, rest: None }, params)
    }

    /// A distance constraint with an explicit rest length (0 joins the particles).
    pub fn distance_with_rest(&mut self, i: usize, j: usize, rest: f64, params: ConstraintParams) -> usize {
        self.push(Pending::Distance { i, j, rest: Some(rest) }, params)
    }

    /// A dihedral bending constraint on `[p0, p1, p2, p3]` (edge `p2, p3`; `p0`, `p1` opposite),
    /// rest angle from the current positions.
    pub fn dihedral(&mut self, particles: [usize; 4], params: ConstraintParams) -> usize {
        self.push(Pending::Dihedral(particles), params)
    }

    /// An isometric bending constraint on `[p0, p1, p2, p3]` (edge `p2, p3`), weights from the
    /// current positions.
    pub fn isometric_bending(&mut self, particles: [usize; 4], params: ConstraintParams) -> usize {
        self.push(Pending::Isometric(particles), params)
    }

    /// A tetrahedral volume constraint, rest volume from the current positions.
    pub fn tet_volume(&mut self, particles: [usize; 4], params: ConstraintParams) -> usize {
        self.push(Pending::Tet(particles), params)
    }

    /// A global volume constraint on the closed, outward-oriented triangle mesh `triangles`
    /// (particle indices), keeping `pressure` times its current volume.
    pub fn global_volume(
        &mut self,
        triangles: &[[usize; 3]],
        pressure: f64,
        params: ConstraintParams,
    ) -> usize {
        let c = self.pending.len();
        self.volume_meshes.push((triangles.to_vec(), c));
        let mesh = self.volume_meshes.len() - 1;
        self.push(Pending::Volume { mesh, pressure }, params)
    }

    /// Attaches particle `p` to a target (within `distance`, 0 to pin it there).
    pub fn attach(
        &mut self,
        p: usize,
        target: AttachTarget,
        distance: f64,
        params: ConstraintParams,
    ) -> usize {
        self.push(Pending::Attach { particle: p, target, distance }, params)
    }
}
