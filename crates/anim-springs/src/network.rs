//! The spring network: model, scratch data, forces, Jacobians, energy and momenta.
//!
//! A [`SpringNetwork`] is a [`SpringModel`] (particles, springs and their incidence topology, in
//! `network/model.rs`) with the scratch its kernels write. The kernels, which make the network
//! anim-core's [`SecondOrderSystem`] and
//! [`MechanicalSystem`](anim_core::integrate::MechanicalSystem), are in `network/forces.rs`. This
//! module holds the network and what is measured on it: energy, momenta and the largest stretch.
//!
//! # State layout
//!
//! A network of `N` particles has `3N` degrees of freedom in anim-core's
//! [`State`](anim_core::integrate::State): `x = [x0, y0, z0, x1, y1, z1, ...]`, `v` likewise. The
//! network never holds positions; it reads them from the state it is handed. Pinned particles
//! have inverse mass 0: the integrators keep their velocity (zero for a fixed pin).
//!
//! # Forces
//!
//! For a spring `s = (i, j)` with rest length `l`, stiffness `k` and damping `c`, let
//! `d = x_i - x_j`, `L = |d|`, `n = d / L`. The force on `i` is
//!
//! ```text
//! f_ij = -k (L - l) n  -  c ((v_i - v_j) . n) n,        f_ji = -f_ij,
//! ```
//!
//! Hooke's law plus damping along the spring (it damps stretching, not rotation).
//! Each particle also feels gravity `m g` and the penalty forces of the [colliders](crate::contact).
//!
//! **Coincident endpoints.** When `L` is below [`MIN_LENGTH`] (about `1.5e-154`, far below any
//! physical length but above the point where `d / L` would overflow), the direction `n` is taken
//! from the rest configuration (`rest_i - rest_j` normalised, or `+x` if the rest positions
//! coincide too). A zero-rest-length spring (`l = 0`) needs no direction at all: its force
//! `-k L n = -k d` is linear and its Jacobian is `-k I`. So no configuration produces a NaN.
//!
//! # Jacobians
//!
//! Per spring, `K_s = df_i/dx_i` is the 3x3 block
//!
//! ```text
//! K_s = -k [ (1 - l/L) (I - n n^T) + n n^T ]        D_s = df_i/dv_i = -c n n^T
//! ```
//!
//! and the global Jacobians have `+K_s` on the diagonal blocks `(i, i)`, `(j, j)` and `-K_s` on
//! `(i, j)`, `(j, i)` (likewise `D_s`). For a compressed spring (`L < l`) the transverse factor
//! `1 - l/L` is negative: `K_s` is indefinite and the Newton matrix `M - h^2 K` may lose
//! positive definiteness at large steps (CG and Cholesky then fail). The **definiteness fix**
//! clamps that factor at 0, `max(1 - l/L, 0)`, which makes every `K_s` negative semi-definite
//! (eigenvalues `-k` along the spring and `-k max(1 - l/L, 0)` across). It changes only the
//! Jacobian, never the force: Newton still converges to the solution of the same implicit
//! equations, at worst more slowly while springs are compressed. The `x`-derivative of the
//! damping force (`-(c/L) [n u^T P + (n . u) P]`, `u = v_i - v_j`, `P = I - n n^T`, not
//! symmetric) is also left out, as in Baraff and Witkin (1998). [`JacobianMode::Exact`] keeps
//! both, for analysis and finite-difference tests.
//!
//! # Parallel and deterministic
//!
//! A force evaluation runs two passes. (1) Per spring, in parallel, the spring force is written to
//! a per-spring buffer. (2) Per particle, in parallel, gravity, the incident spring forces (read
//! through an incidence list built once: the springs the particle is the `i` of, then those it is
//! the `j` of, each in increasing spring order) and contact forces are summed in that fixed order. Each output is written by exactly one task and each sum is taken in
//! one fixed order, so the result is bitwise identical for any number of rayon threads. The
//! Jacobian product works per particle too: `(J dx)_p = sum_s B_s (dx_p - dx_other)`, recomputed
//! from the per-spring blocks on both sides (cheaper than a second buffer, and no float atomics).
//! Energies are summed in fixed chunks whose partial sums are added in order. Below
//! [`PARALLEL_THRESHOLD`] springs or particles, the same loops run on the calling thread.
//!
//! No allocation happens in [`force`](anim_core::integrate::MechanicalSystem::force),
//! [`linearize`](anim_core::integrate::MechanicalSystem::linearize),
//! [`jacobian_apply`](anim_core::integrate::MechanicalSystem::jacobian_apply) or
//! [`energy`](anim_core::integrate::SecondOrderSystem::energy): their scratch is sized when the
//! network is built. The assembled Jacobian's sparsity pattern is built on the first call of
//! [`jacobian_assemble`](anim_core::integrate::MechanicalSystem::jacobian_assemble) and then only
//! its values are rewritten.

mod forces;
mod model;

use crate::contact::MeshCollider;
use crate::error::{BuildError, InputError};
pub use crate::geom::MIN_LENGTH;
pub use model::{MAX_PARTICLES, MAX_SPRINGS, Particle, Spring, SpringKind, SpringModel};

use anim_core::glam::{DMat3, DVec3};
use anim_core::integrate::SecondOrderSystem;
use anim_core::linalg::CsrMatrix;
use anim_core::par::prelude::*;
use std::sync::OnceLock;
use std::sync::atomic::AtomicUsize;

/// Loops over more springs (or particles) than this run on the rayon pool.
pub const PARALLEL_THRESHOLD: usize = 2048;

/// Items per rayon task and per energy partial sum (fixed, so results do not depend on threads).
const CHUNK: usize = 512;

/// Which force Jacobian [`linearize`](anim_core::integrate::MechanicalSystem::linearize) computes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "kebab-case"))]
pub enum JacobianMode {
    /// The definiteness fix (compressed springs' transverse stiffness clamped at 0, a sphere's
    /// curvature term and the position-derivatives of damping dropped): symmetric and negative
    /// semi-definite, as conjugate gradients and Cholesky need. The default.
    #[default]
    Definite,
    /// The exact derivatives of the force: indefinite for compressed springs and non-symmetric
    /// with damping. For analysis, finite-difference tests and solvers that do not need
    /// symmetry (Jacobi, Gauss-Seidel).
    Exact,
}

/// The spring with the largest stretch ratio (see [`SpringNetwork::max_stretch`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stretch {
    /// Spring index.
    pub spring: usize,
    /// `|x_i - x_j| / l` (or divided by the network's mean rest length for `l = 0`).
    pub ratio: f64,
}

/// The sparsity pattern of the assembled Jacobian and where each block goes.
#[derive(Debug)]
struct Pattern {
    matrix: CsrMatrix,
    /// `row_ptr[3 p]` for every particle, and nnz at the end.
    block_start: Vec<usize>,
    /// Block columns of block row `p`.
    nblocks: Vec<usize>,
    /// Slot of the diagonal block within block row `p`.
    diag_slot: Vec<usize>,
    /// Slot of the incidence's other particle within its block row.
    inc_slot: Vec<usize>,
}

/// Scratch sized once from the model.
#[derive(Debug)]
struct SpringData {
    spring_force: Vec<DVec3>,
    /// Per spring at the last linearisation: `[n_x, n_y, n_z, alpha, beta, c]` with the definite
    /// `K_s = alpha I + beta n n^T` and `D_s = -c n n^T`.
    lin: Vec<[f64; 6]>,
    /// Per spring exact `K_s` (only in [`JacobianMode::Exact`]; empty otherwise).
    k_exact: Vec<DMat3>,
    contact_k: Vec<DMat3>,
    contact_d: Vec<DMat3>,
    partials: Vec<f64>,
    mode: JacobianMode,
    pattern: OnceLock<Option<Pattern>>,
    /// Address of the column indices of the matrix last checked to hold our pattern: a matrix's
    /// pattern cannot change in place (only its values can), so the same live allocation still
    /// holds it and the full comparison is skipped.
    checked_pattern: AtomicUsize,
}

/// A mass-spring network: the [`SpringModel`] and its scratch, implementing anim-core's
/// [`SecondOrderSystem`] and [`MechanicalSystem`](anim_core::integrate::MechanicalSystem) (see the
/// [module docs](self)).
///
/// Built by [`NetworkBuilder`](crate::NetworkBuilder).
#[derive(Debug)]
pub struct SpringNetwork {
    model: SpringModel,
    data: SpringData,
}

impl Clone for SpringNetwork {
    fn clone(&self) -> Self {
        Self { model: self.model.clone(), data: SpringData::new(&self.model, self.data.mode) }
    }
}

#[inline]
fn load(x: &[f64], p: usize) -> DVec3 {
    DVec3::new(x[3 * p], x[3 * p + 1], x[3 * p + 2])
}

#[inline]
fn chunks(n: usize) -> usize {
    n.div_ceil(CHUNK)
}

impl SpringData {
    fn new(model: &SpringModel, mode: JacobianMode) -> Self {
        let (n, m) = (model.particles.len(), model.springs.len());
        let contact = if model.has_contact() { n } else { 0 };
        Self {
            spring_force: vec![DVec3::ZERO; m],
            lin: vec![[0.0; 6]; m],
            k_exact: if mode == JacobianMode::Exact { vec![DMat3::ZERO; m] } else { Vec::new() },
            contact_k: vec![DMat3::ZERO; contact],
            contact_d: vec![DMat3::ZERO; contact],
            partials: vec![0.0; chunks(m)],
            mode,
            pattern: OnceLock::new(),
            checked_pattern: AtomicUsize::new(0),
        }
    }
}

/// Runs `f(first_index, chunk)` over `out` in chunks of `chunk` items, in parallel when `parallel`.
#[inline]
fn for_chunks<T: Send>(out: &mut [T], chunk: usize, parallel: bool, f: impl Fn(usize, &mut [T]) + Sync) {
    if parallel {
        out.par_chunks_mut(chunk).enumerate().for_each(|(c, s)| f(c * chunk, s));
    } else {
        out.chunks_mut(chunk).enumerate().for_each(|(c, s)| f(c * chunk, s));
    }
}

impl SpringNetwork {
    /// Wraps a checked model (see [`NetworkBuilder`](crate::NetworkBuilder)).
    pub(crate) fn from_model(model: SpringModel) -> Self {
        let data = SpringData::new(&model, JacobianMode::Definite);
        Self { model, data }
    }

    /// Adds mesh colliders to a built network (as
    /// [`NetworkBuilder::mesh_collider`](crate::NetworkBuilder::mesh_collider) does before the
    /// build); the scratch data is made anew, in the network's Jacobian mode.
    ///
    /// # Errors
    /// [`BuildError::BadMeshCollider`] for bad
    /// contact parameters, numbered after the mesh colliders already there; nothing is added
    /// then.
    pub fn add_mesh_colliders(&mut self, meshes: Vec<MeshCollider>) -> Result<(), BuildError> {
        let first = self.model.mesh_colliders.len();
        for (k, c) in meshes.iter().enumerate() {
            c.check().map_err(|reason| BuildError::BadMeshCollider { collider: first + k, reason })?;
        }
        self.model.mesh_colliders.extend(meshes);
        self.data = SpringData::new(&self.model, self.data.mode);
        Ok(())
    }

    /// The model (particles, springs, colliders, topology).
    #[must_use]
    pub fn model(&self) -> &SpringModel {
        &self.model
    }

    /// Number of particles.
    #[must_use]
    pub fn num_particles(&self) -> usize {
        self.model.particles.len()
    }

    /// Number of springs.
    #[must_use]
    pub fn num_springs(&self) -> usize {
        self.model.springs.len()
    }

    /// The springs (edges for output: `(i, j)` and their kind).
    #[must_use]
    pub fn springs(&self) -> &[Spring] {
        &self.model.springs
    }

    /// The particles.
    #[must_use]
    pub fn particles(&self) -> &[Particle] {
        &self.model.particles
    }

    /// Triangles for rendering; may be empty (a rope).
    #[must_use]
    pub fn triangles(&self) -> &[[usize; 3]] {
        &self.model.triangles
    }

    /// The positions of a flat state vector as points, for output.
    ///
    /// # Panics
    /// If `x.len()` is not three times the number of particles.
    #[track_caller]
    pub fn positions<'a>(&self, x: &'a [f64]) -> impl ExactSizeIterator<Item = [f64; 3]> + 'a {
        assert_eq!(x.len(), self.dof(), "positions: state has the wrong length");
        x.chunks_exact(3).map(|c| [c[0], c[1], c[2]])
    }

    /// Fills `out` with the positions of a flat state vector (reusing its allocation).
    ///
    /// # Panics
    /// If `x.len()` is not three times the number of particles.
    #[track_caller]
    pub fn positions_into(&self, x: &[f64], out: &mut Vec<[f64; 3]>) {
        out.clear();
        out.extend(self.positions(x));
    }

    /// The rest positions as a flat state vector, with zero velocities (the state to start from).
    #[must_use]
    pub fn rest_state(&self) -> anim_core::integrate::State {
        let x: Vec<f64> = self.model.rest_positions.iter().flatten().copied().collect();
        let v = vec![0.0; x.len()];
        anim_core::integrate::State::new(x, v)
    }

    /// Which Jacobian [`linearize`](anim_core::integrate::MechanicalSystem::linearize) computes.
    #[must_use]
    pub fn jacobian_mode(&self) -> JacobianMode {
        self.data.mode
    }

    /// Chooses the Jacobian (definiteness fix or exact); takes effect at the next linearisation.
    pub fn set_jacobian_mode(&mut self, mode: JacobianMode) {
        self.data.mode = mode;
        let m = if mode == JacobianMode::Exact { self.model.springs.len() } else { 0 };
        self.data.k_exact.resize(m, DMat3::ZERO);
    }

    /// Changes gravity between steps.
    ///
    /// # Errors
    /// [`InputError::NonFiniteGravity`].
    pub fn set_gravity(&mut self, g: [f64; 3]) -> Result<(), BuildError> {
        if !g.iter().all(|c| c.is_finite()) {
            return Err(BuildError::Input(InputError::NonFiniteGravity { gravity: g }));
        }
        self.model.gravity = DVec3::from_array(g);
        Ok(())
    }

    /// Total mass (pinned particles included).
    #[must_use]
    pub fn total_mass(&self) -> f64 {
        self.model.particles.iter().map(|p| p.mass).sum()
    }

    /// Linear momentum `sum m_i v_i` (pinned particles included with their mass and velocity).
    ///
    /// # Panics
    /// If `v` has the wrong length.
    #[must_use]
    #[track_caller]
    pub fn linear_momentum(&self, v: &[f64]) -> [f64; 3] {
        assert_eq!(v.len(), self.dof(), "linear_momentum: wrong length");
        let mut p = DVec3::ZERO;
        for (k, part) in self.model.particles.iter().enumerate() {
            p += part.mass * load(v, k);
        }
        p.to_array()
    }

    /// Angular momentum `sum m_i x_i × v_i` about the origin.
    ///
    /// # Panics
    /// If `x` or `v` has the wrong length.
    #[must_use]
    #[track_caller]
    pub fn angular_momentum(&self, x: &[f64], v: &[f64]) -> [f64; 3] {
        assert!(x.len() == self.dof() && v.len() == self.dof(), "angular_momentum: wrong length");
        let mut l = DVec3::ZERO;
        for (k, part) in self.model.particles.iter().enumerate() {
            l += part.mass * load(x, k).cross(load(v, k));
        }
        l.to_array()
    }

    /// Energy split into kinetic, spring, gravity and contact parts (summed in a fixed order).
    ///
    /// # Panics
    /// If `x` or `v` has the wrong length.
    #[track_caller]
    pub fn energy_parts(&mut self, x: &[f64], v: &[f64]) -> EnergyParts {
        assert!(x.len() == self.dof() && v.len() == self.dof(), "energy: wrong length");
        let model = &self.model;
        let m = model.springs.len();
        let partials = &mut self.data.partials;
        for_chunks(partials, 1, m > PARALLEL_THRESHOLD, |c, out| {
            let mut e = 0.0;
            for s in c * CHUNK..((c + 1) * CHUNK).min(m) {
                let sp = &model.springs[s];
                let d = load(x, sp.i) - load(x, sp.j);
                let stretch = d.length() - sp.rest_length;
                e += 0.5 * sp.stiffness * stretch * stretch;
            }
            out[0] = e;
        });
        // Partial sums of fixed chunks, added in order: independent of the thread count.
        let spring: f64 = partials.iter().sum();
        let mut kinetic = 0.0;
        let mut gravity = 0.0;
        let mut contact = 0.0;
        // Particle sums are cheap: one pass in a fixed serial order.
        for (k, part) in model.particles.iter().enumerate() {
            let (xp, vp) = (load(x, k), load(v, k));
            kinetic += 0.5 * part.mass * vp.length_squared();
            gravity -= part.mass * model.gravity.dot(xp);
            for c in &model.colliders {
                contact += c.energy(xp);
            }
            for c in &model.mesh_colliders {
                contact += c.energy(xp);
            }
        }
        EnergyParts { kinetic, spring, gravity, contact }
    }

    /// The spring with the largest stretch ratio `|x_i - x_j| / l` at positions `x` (a
    /// zero-length spring is measured against the network's mean rest length); `None` without
    /// springs. Ties go to the lowest index, so the answer does not depend on the thread count.
    ///
    /// A ratio far above 1 (say 10) means the simulation has blown up: [`SpringSimulation`]
    /// checks it after every step.
    ///
    /// [`SpringSimulation`]: crate::SpringSimulation
    ///
    /// # Panics
    /// If `x` has the wrong length.
    #[must_use]
    #[track_caller]
    pub fn max_stretch(&self, x: &[f64]) -> Option<Stretch> {
        assert_eq!(x.len(), self.dof(), "max_stretch: wrong length");
        let model = &self.model;
        let ratio = |s: usize| {
            let sp = &model.springs[s];
            let len = (load(x, sp.i) - load(x, sp.j)).length();
            let r = len / if sp.rest_length > 0.0 { sp.rest_length } else { model.length_scale };
            // A NaN length counts as infinitely stretched.
            Stretch { spring: s, ratio: if r.is_nan() { f64::INFINITY } else { r } }
        };
        let better = |a: Stretch, b: Stretch| {
            if b.ratio > a.ratio || (b.ratio == a.ratio && b.spring < a.spring) { b } else { a }
        };
        let m = model.springs.len();
        if m == 0 {
            return None;
        }
        #[cfg(feature = "parallel")]
        let best = if m > PARALLEL_THRESHOLD {
            (0..m).into_par_iter().with_min_len(CHUNK).map(ratio).reduce(|| ratio(0), better)
        } else {
            (0..m).map(ratio).fold(ratio(0), better)
        };
        #[cfg(not(feature = "parallel"))]
        let best = { (0..m).map(ratio).fold(ratio(0), better) };
        Some(best)
    }
}

/// The energy of a network split by source (see [`SpringNetwork::energy_parts`]).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct EnergyParts {
    /// `sum m |v|^2 / 2`.
    pub kinetic: f64,
    /// `sum k (L - l)^2 / 2`.
    pub spring: f64,
    /// `-sum m g . x`.
    pub gravity: f64,
    /// `sum k_c p^2 / 2` over particles and colliders.
    pub contact: f64,
}

impl EnergyParts {
    /// The total.
    #[must_use]
    pub fn total(&self) -> f64 {
        self.kinetic + self.spring + self.gravity + self.contact
    }

    /// As the workspace's [`anim_core::solver::EnergyParts`]: springs and contact are its
    /// `elastic` part.
    #[must_use]
    pub fn split(&self) -> anim_core::solver::EnergyParts {
        anim_core::solver::EnergyParts {
            kinetic: self.kinetic,
            gravity: self.gravity,
            elastic: self.spring + self.contact,
        }
    }
}
