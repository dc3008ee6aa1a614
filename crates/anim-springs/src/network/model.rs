//! The model of a spring network: particles, springs and the topology the kernels walk.
//!
//! A [`SpringModel`] never changes during a simulation (only gravity may be reset between steps).
//! Besides the particles and springs as the builder checked them, it holds compact copies for the
//! memory-bound kernels: each spring's two particle indices as `u32` and its `[l, k, c]`, and the
//! **incidence list**, built once by a counting sort: for every particle, first the springs it is
//! the `i` of, then those it is the `j` of, each group in increasing spring order. Every
//! per-particle sum of the force and Jacobian kernels runs in that fixed order, which is what
//! makes them independent of the thread count.

use crate::contact::{Collider, MeshCollider};
use anim_core::glam::DVec3;

/// A particle's parameters; its position and velocity live in the state.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct Particle {
    /// Mass (kg, > 0). A pinned particle keeps its mass for the kinetic energy and momentum.
    pub mass: f64,
    /// A pinned particle does not respond to forces (inverse mass 0).
    pub pinned: bool,
}

/// What a spring stands for; used by renderers and reports, not by the physics.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "kebab-case"))]
pub enum SpringKind {
    /// Along a grid line or a mesh edge: the visible structure.
    Structural,
    /// Across a face (cloth quad diagonals, lattice face and body diagonals).
    Shear,
    /// Skipping a particle, or across a mesh edge: resists bending.
    Bending,
    /// Added by hand.
    Custom,
}

/// A spring between particles `i` and `j`.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct Spring {
    /// First particle.
    pub i: usize,
    /// Second particle.
    pub j: usize,
    /// Rest length `l` (m, >= 0).
    pub rest_length: f64,
    /// Stiffness `k` (N/m, > 0).
    pub stiffness: f64,
    /// Damping along the spring `c` (N s/m, >= 0).
    pub damping: f64,
    /// What the spring stands for.
    pub kind: SpringKind,
}

/// One end of a spring seen from a particle, packed in 8 bytes (the kernels are memory-bound).
#[derive(Debug, Clone, Copy)]
pub(super) struct Incidence {
    /// `spring << 1`, plus 1 if the particle is the spring's `j` (the spring force buffer holds
    /// the force on `i`, so `j` takes it with a minus sign).
    pub(super) code: u32,
    /// The particle at the other end.
    pub(super) other: u32,
}

impl Incidence {
    #[inline]
    pub(super) fn spring(self) -> usize {
        (self.code >> 1) as usize
    }

    #[inline]
    pub(super) fn other(self) -> usize {
        self.other as usize
    }
}

/// Largest number of springs (incidence codes hold `2 * spring + 1` in a `u32`).
pub const MAX_SPRINGS: usize = (u32::MAX >> 1) as usize;

/// Largest number of particles.
pub const MAX_PARTICLES: usize = u32::MAX as usize;

/// The immutable description of a network: particles, springs, gravity, colliders, topology.
#[derive(Debug, Clone)]
pub struct SpringModel {
    pub(super) particles: Vec<Particle>,
    pub(super) rest_positions: Vec<[f64; 3]>,
    pub(super) springs: Vec<Spring>,
    pub(super) triangles: Vec<[usize; 3]>,
    pub(super) gravity: DVec3,
    pub(super) colliders: Vec<Collider>,
    pub(super) mesh_colliders: Vec<MeshCollider>,
    pub(super) inv_mass: Vec<f64>,
    /// Particles of each spring (compact copy of `springs` for the kernels).
    pub(super) ends: Vec<[u32; 2]>,
    /// `[rest length, stiffness, damping]` of each spring.
    pub(super) params: Vec<[f64; 3]>,
    pub(super) inc_ptr: Vec<usize>,
    pub(super) inc_mid: Vec<usize>,
    pub(super) inc: Vec<Incidence>,
    pub(super) length_scale: f64,
}

impl SpringModel {
    /// Assembles a model from checked parts (see [`NetworkBuilder`](crate::NetworkBuilder)).
    pub(crate) fn new(
        particles: Vec<Particle>,
        rest_positions: Vec<[f64; 3]>,
        springs: Vec<Spring>,
        triangles: Vec<[usize; 3]>,
        gravity: DVec3,
        colliders: Vec<Collider>,
        mesh_colliders: Vec<MeshCollider>,
    ) -> Self {
        let n = particles.len();
        let inv_mass = particles.iter().map(|p| if p.pinned { 0.0 } else { 1.0 / p.mass }).collect();
        // Incidence lists by counting sort, each in increasing spring order.
        let mut inc_ptr = vec![0usize; n + 1];
        for s in &springs {
            inc_ptr[s.i + 1] += 1;
            inc_ptr[s.j + 1] += 1;
        }
        for p in 0..n {
            inc_ptr[p + 1] += inc_ptr[p];
        }
        let mut next = inc_ptr.clone();
        // Each particle lists first the springs it is the `i` of, then those it is the `j` of,
        // each group in increasing spring order; `inc_mid[p]` is where the second group starts.
        // The builder checked the sizes against MAX_SPRINGS and MAX_PARTICLES.
        let mut inc = vec![Incidence { code: 0, other: 0 }; 2 * springs.len()];
        for (k, s) in springs.iter().enumerate() {
            inc[next[s.i]] = Incidence { code: (k as u32) << 1, other: s.j as u32 };
            next[s.i] += 1;
        }
        let inc_mid = next.clone();
        for (k, s) in springs.iter().enumerate() {
            inc[next[s.j]] = Incidence { code: ((k as u32) << 1) | 1, other: s.i as u32 };
            next[s.j] += 1;
        }
        let ends = springs.iter().map(|s| [s.i as u32, s.j as u32]).collect();
        let params = springs.iter().map(|s| [s.rest_length, s.stiffness, s.damping]).collect();
        let positive: Vec<f64> = springs.iter().map(|s| s.rest_length).filter(|l| *l > 0.0).collect();
        let length_scale =
            if positive.is_empty() { 1.0 } else { positive.iter().sum::<f64>() / positive.len() as f64 };
        Self {
            particles,
            rest_positions,
            springs,
            triangles,
            gravity,
            colliders,
            mesh_colliders,
            inv_mass,
            ends,
            params,
            inc_ptr,
            inc_mid,
            inc,
            length_scale,
        }
    }

    /// The particles.
    #[must_use]
    pub fn particles(&self) -> &[Particle] {
        &self.particles
    }

    /// The springs.
    #[must_use]
    pub fn springs(&self) -> &[Spring] {
        &self.springs
    }

    /// Triangles for rendering (cloth faces, lattice surface, mesh faces); may be empty.
    #[must_use]
    pub fn triangles(&self) -> &[[usize; 3]] {
        &self.triangles
    }

    /// The positions the network was built from.
    #[must_use]
    pub fn rest_positions(&self) -> &[[f64; 3]] {
        &self.rest_positions
    }

    /// Gravity acceleration (m/s^2).
    #[must_use]
    pub fn gravity(&self) -> [f64; 3] {
        self.gravity.to_array()
    }

    /// The colliders.
    #[must_use]
    pub fn colliders(&self) -> &[Collider] {
        &self.colliders
    }

    /// The mesh colliders.
    #[must_use]
    pub fn mesh_colliders(&self) -> &[MeshCollider] {
        &self.mesh_colliders
    }

    /// Whether any collider (shape or mesh) acts.
    #[inline]
    pub(super) fn has_contact(&self) -> bool {
        !self.colliders.is_empty() || !self.mesh_colliders.is_empty()
    }

    /// Springs incident to particle `p` as `(spring index, other particle)`: first those whose
    /// `i` it is, then those whose `j` it is, each in increasing spring order (the fixed order
    /// of every per-particle sum).
    pub fn incident(&self, p: usize) -> impl Iterator<Item = (usize, usize)> + '_ {
        self.inc[self.inc_ptr[p]..self.inc_ptr[p + 1]].iter().map(|e| (e.spring(), e.other()))
    }
}
