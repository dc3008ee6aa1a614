//! The spring network: model, scratch data, forces, Jacobians, energy and momenta.
//!
//! # State layout
//!
//! A network of `N` particles has `3N` degrees of freedom in anim-core's
//! [`State`](anim_core::integrate::State): `x = [x0, y0, z0, x1, y1, z1, ...]`, `v` likewise. The
//! network never holds positions; it reads them from the state it is handed. Pinned particles
//! have inverse mass 0: the integrators keep their velocity (zero for a fixed pin).
//!
//! # Forces (seed section 2)
//!
//! For a spring `s = (i, j)` with rest length `l`, stiffness `k` and damping `c`, let
//! `d = x_i - x_j`, `L = |d|`, `n = d / L`. The force on `i` is
//!
//! ```text
//! f_ij = -k (L - l) n  -  c ((v_i - v_j) . n) n,        f_ji = -f_ij,
//! ```
//!
//! Hooke's law of the seed plus damping along the spring (it damps stretching, not rotation).
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

use crate::contact::{Collider, outer};
use anim_core::glam::{DMat3, DVec3};
use anim_core::integrate::{MechanicalSystem, SecondOrderSystem};
use anim_core::linalg::CsrMatrix;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::sync::OnceLock;
use std::sync::atomic::{AtomicUsize, Ordering};

/// Below this length a spring's direction is taken from its rest configuration.
pub const MIN_LENGTH: f64 = 1.491_668_146_240_041_3e-154; // sqrt(f64::MIN_POSITIVE)

/// Loops over more springs (or particles) than this run on the rayon pool.
pub const PARALLEL_THRESHOLD: usize = 2048;

/// Items per rayon task and per energy partial sum (fixed, so results do not depend on threads).
const CHUNK: usize = 512;

/// A particle's parameters; its position and velocity live in the state.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Particle {
    /// Mass (kg, > 0). A pinned particle keeps its mass for the kinetic energy and momentum.
    pub mass: f64,
    /// A pinned particle does not respond to forces (inverse mass 0).
    pub pinned: bool,
}

/// What a spring stands for; used by renderers and reports, not by the physics.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
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
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
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

/// Which force Jacobian [`linearize`](MechanicalSystem::linearize) computes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
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

/// One end of a spring seen from a particle, packed in 8 bytes (the kernels are memory-bound).
#[derive(Debug, Clone, Copy)]
struct Incidence {
    /// `spring << 1`, plus 1 if the particle is the spring's `j` (the spring force buffer holds
    /// the force on `i`, so `j` takes it with a minus sign).
    code: u32,
    /// The particle at the other end.
    other: u32,
}

impl Incidence {
    #[inline]
    fn spring(self) -> usize {
        (self.code >> 1) as usize
    }

    #[inline]
    fn other(self) -> usize {
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
    particles: Vec<Particle>,
    rest_positions: Vec<[f64; 3]>,
    springs: Vec<Spring>,
    triangles: Vec<[usize; 3]>,
    gravity: DVec3,
    colliders: Vec<Collider>,
    inv_mass: Vec<f64>,
    /// Particles of each spring (compact copy of `springs` for the kernels).
    ends: Vec<[u32; 2]>,
    /// `[rest length, stiffness, damping]` of each spring.
    params: Vec<[f64; 3]>,
    inc_ptr: Vec<usize>,
    inc_mid: Vec<usize>,
    inc: Vec<Incidence>,
    length_scale: f64,
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
/// [`SecondOrderSystem`] and [`MechanicalSystem`] (see the [module docs](self)).
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

impl SpringModel {
    /// Assembles a model from checked parts (see [`NetworkBuilder`](crate::NetworkBuilder)).
    pub(crate) fn new(
        particles: Vec<Particle>,
        rest_positions: Vec<[f64; 3]>,
        springs: Vec<Spring>,
        triangles: Vec<[usize; 3]>,
        gravity: DVec3,
        colliders: Vec<Collider>,
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
            inv_mass,
            ends,
            params,
            inc_ptr,
            inc_mid,
            inc,
            length_scale,
        }
    }

    /// The direction used when a spring's endpoints coincide.
    #[cold]
    fn fallback_direction(&self, s: usize) -> DVec3 {
        let sp = &self.springs[s];
        let d = DVec3::from_array(self.rest_positions[sp.i]) - DVec3::from_array(self.rest_positions[sp.j]);
        let len = d.length();
        if len > MIN_LENGTH && len.is_finite() { d / len } else { DVec3::X }
    }

    /// Direction and length of spring `s` at positions `x`.
    #[inline]
    fn frame(&self, s: usize, x: &[f64]) -> (DVec3, f64) {
        let [i, j] = self.ends[s];
        let d = load(x, i as usize) - load(x, j as usize);
        let len = d.length();
        if len > MIN_LENGTH { (d * (1.0 / len), len) } else { (self.fallback_direction(s), len) }
    }

    /// Force of spring `s` on its particle `i`.
    #[inline]
    fn spring_force(&self, s: usize, x: &[f64], v: &[f64]) -> DVec3 {
        let [i, j] = self.ends[s];
        let (i, j) = (i as usize, j as usize);
        let [rest, k, c] = self.params[s];
        let d = load(x, i) - load(x, j);
        let u = load(v, i) - load(v, j);
        let len = d.length();
        // One division instead of three: the kernel is bound by divisions and square roots.
        let n = if len > MIN_LENGTH { d * (1.0 / len) } else { self.fallback_direction(s) };
        if rest == 0.0 {
            // Zero rest length: f = -k d exactly, no direction needed but for the damping.
            return -k * d - c * n.dot(u) * n;
        }
        -(k * (len - rest) + c * n.dot(u)) * n
    }

    /// Linearisation of spring `s`: `[n, alpha, beta, c]` of the definite (or, for
    /// [`JacobianMode::Exact`], the undamped exact) `K_s = alpha I + beta n n^T`, and the exact
    /// `K_s` including the damping's position derivative when `exact`.
    #[inline]
    fn spring_jacobian(&self, s: usize, x: &[f64], v: &[f64], exact: bool) -> ([f64; 6], DMat3) {
        let [rest, k, c] = self.params[s];
        let (n, len) = self.frame(s, x);
        // K_s = -k [t (I - n n^T) + n n^T] = -k t I - k (1 - t) n n^T.
        let transverse = if rest == 0.0 {
            1.0
        } else {
            let t = 1.0 - rest / len.max(MIN_LENGTH);
            if exact { t } else { t.max(0.0) }
        };
        let (alpha, beta) = (-k * transverse, -k * (1.0 - transverse));
        let lin = [n.x, n.y, n.z, alpha, beta, c];
        if !exact {
            return (lin, DMat3::ZERO);
        }
        let nn = outer(n, n);
        let mut full = alpha * DMat3::IDENTITY + beta * nn;
        if c != 0.0 && len > MIN_LENGTH {
            let [i, j] = self.ends[s];
            let u = load(v, i as usize) - load(v, j as usize);
            let proj = DMat3::IDENTITY - nn;
            full -= (c / len) * (outer(n, proj * u) + n.dot(u) * proj);
        }
        (lin, full)
    }

    /// Sum of collider forces on particle `p`.
    #[inline]
    fn contact_force(&self, xp: DVec3, vp: DVec3) -> DVec3 {
        let mut f = DVec3::ZERO;
        for c in &self.colliders {
            f += c.force(xp, vp);
        }
        f
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

    /// Springs incident to particle `p` as `(spring index, other particle)`: first those whose
    /// `i` it is, then those whose `j` it is, each in increasing spring order (the fixed order
    /// of every per-particle sum).
    pub fn incident(&self, p: usize) -> impl Iterator<Item = (usize, usize)> + '_ {
        self.inc[self.inc_ptr[p]..self.inc_ptr[p + 1]].iter().map(|e| (e.spring(), e.other()))
    }
}

impl SpringData {
    fn new(model: &SpringModel, mode: JacobianMode) -> Self {
        let (n, m) = (model.particles.len(), model.springs.len());
        let contact = if model.colliders.is_empty() { 0 } else { n };
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

/// Runs `f(p, values of block row p)` for particles `lo..hi`, splitting `values` at the block-row
/// boundaries `bounds` and recursing in parallel (no allocation).
fn for_block_rows(
    values: &mut [f64],
    bounds: &[usize],
    lo: usize,
    hi: usize,
    parallel: bool,
    f: &(impl Fn(usize, &mut [f64]) + Sync),
) {
    if !parallel || hi - lo <= CHUNK {
        let mut rest = values;
        for p in lo..hi {
            let (row, tail) = rest.split_at_mut(bounds[p + 1] - bounds[p]);
            f(p, row);
            rest = tail;
        }
        return;
    }
    let mid = lo + (hi - lo) / 2;
    let (left, right) = values.split_at_mut(bounds[mid] - bounds[lo]);
    rayon::join(
        || for_block_rows(left, bounds, lo, mid, parallel, f),
        || for_block_rows(right, bounds, mid, hi, parallel, f),
    );
}

/// Adds `sign * b` to the block in `slot` of a block row whose rows are `width` entries long.
#[inline]
fn add_block(row: &mut [f64], width: usize, slot: usize, b: &DMat3, sign: f64) {
    for a in 0..3 {
        let base = a * width + 3 * slot;
        row[base] += sign * b.x_axis[a];
        row[base + 1] += sign * b.y_axis[a];
        row[base + 2] += sign * b.z_axis[a];
    }
}

impl SpringNetwork {
    /// Wraps a checked model (see [`NetworkBuilder`](crate::NetworkBuilder)).
    pub(crate) fn from_model(model: SpringModel) -> Self {
        let data = SpringData::new(&model, JacobianMode::Definite);
        Self { model, data }
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

    /// Which Jacobian [`linearize`](MechanicalSystem::linearize) computes.
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
    /// [`BuildError::NonFiniteGravity`](crate::BuildError::NonFiniteGravity).
    pub fn set_gravity(&mut self, g: [f64; 3]) -> Result<(), crate::BuildError> {
        if !g.iter().all(|c| c.is_finite()) {
            return Err(crate::BuildError::NonFiniteGravity { gravity: g });
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
        let best = if m > PARALLEL_THRESHOLD {
            (0..m).into_par_iter().with_min_len(CHUNK).map(ratio).reduce(|| ratio(0), better)
        } else {
            (0..m).map(ratio).fold(ratio(0), better)
        };
        Some(best)
    }

    fn build_pattern(&self) -> Option<Pattern> {
        let model = &self.model;
        let n = model.particles.len();
        let mut block_start = Vec::with_capacity(n + 1);
        let mut nblocks = Vec::with_capacity(n);
        let mut diag_slot = Vec::with_capacity(n);
        let mut inc_slot = vec![0usize; model.inc.len()];
        let mut row_ptr = Vec::with_capacity(3 * n + 1);
        let mut col_idx = Vec::new();
        row_ptr.push(0);
        let mut cols = Vec::new();
        for p in 0..n {
            cols.clear();
            cols.push(p);
            cols.extend(model.inc[model.inc_ptr[p]..model.inc_ptr[p + 1]].iter().map(|e| e.other()));
            cols.sort_unstable();
            cols.dedup();
            block_start.push(col_idx.len());
            nblocks.push(cols.len());
            diag_slot.push(cols.binary_search(&p).ok()?);
            for e in model.inc_ptr[p]..model.inc_ptr[p + 1] {
                inc_slot[e] = cols.binary_search(&model.inc[e].other()).ok()?;
            }
            for _ in 0..3 {
                for &q in &cols {
                    col_idx.extend_from_slice(&[3 * q, 3 * q + 1, 3 * q + 2]);
                }
                row_ptr.push(col_idx.len());
            }
        }
        block_start.push(col_idx.len());
        let values = vec![0.0; col_idx.len()];
        let matrix = CsrMatrix::try_from_parts(3 * n, 3 * n, row_ptr, col_idx, values).ok()?;
        Some(Pattern { matrix, block_start, nblocks, diag_slot, inc_slot })
    }

    /// Writes the force (or, with `accel`, the acceleration `M^-1 f`) in two passes: per-spring
    /// forces into a buffer, then a per-particle gather in a fixed order (see the module docs).
    fn evaluate(&mut self, x: &[f64], v: &[f64], out: &mut [f64], accel: bool) {
        let model = &self.model;

        let m = model.springs.len();
        for_chunks(&mut self.data.spring_force, CHUNK, m > PARALLEL_THRESHOLD, |first, out| {
            for (k, fs) in out.iter_mut().enumerate() {
                *fs = model.spring_force(first + k, x, v);
            }
        });
        let spring_force = &self.data.spring_force;
        let n = model.particles.len();
        for_chunks(out, 3 * CHUNK, n > PARALLEL_THRESHOLD, |first, out| {
            for (k, fp) in out.chunks_exact_mut(3).enumerate() {
                let p = first / 3 + k;
                // Springs pull p as their `i` with +f_s, as their `j` with -f_s.
                let mut plus = DVec3::ZERO;
                for e in &model.inc[model.inc_ptr[p]..model.inc_mid[p]] {
                    plus += spring_force[e.spring()];
                }
                let mut minus = DVec3::ZERO;
                for e in &model.inc[model.inc_mid[p]..model.inc_ptr[p + 1]] {
                    minus += spring_force[e.spring()];
                }
                let mut acc = model.particles[p].mass * model.gravity + (plus - minus);
                if !model.colliders.is_empty() {
                    acc += model.contact_force(load(x, p), load(v, p));
                }
                if accel {
                    // A pinned particle (zero inverse mass) does not accelerate, whatever the
                    // force: `0 * inf` would otherwise put a NaN on a particle that cannot move.
                    let w = model.inv_mass[p];
                    acc = if w == 0.0 { DVec3::ZERO } else { acc * w };
                }
                fp[0] = acc.x;
                fp[1] = acc.y;
                fp[2] = acc.z;
            }
        });
    }

    /// `c_x K_s + c_v D_s` for spring `s` from the last linearisation.
    #[inline]
    fn block(&self, s: usize, c_x: f64, c_v: f64) -> DMat3 {
        let [nx, ny, nz, alpha, beta, c] = self.data.lin[s];
        let nn = outer(DVec3::new(nx, ny, nz), DVec3::new(nx, ny, nz));
        if self.data.mode == JacobianMode::Exact {
            c_x * self.data.k_exact[s] - (c_v * c) * nn
        } else {
            (c_x * alpha) * DMat3::IDENTITY + (c_x * beta - c_v * c) * nn
        }
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
}

impl SecondOrderSystem for SpringNetwork {
    fn dof(&self) -> usize {
        3 * self.model.particles.len()
    }

    fn acceleration(&mut self, _t: f64, x: &[f64], v: &[f64], a: &mut [f64]) {
        self.evaluate(x, v, a, true);
    }

    fn energy(&mut self, _t: f64, x: &[f64], v: &[f64]) -> Option<f64> {
        Some(self.energy_parts(x, v).total())
    }
}

impl MechanicalSystem for SpringNetwork {
    fn inverse_mass(&self, w: &mut [f64]) {
        for (p, &wp) in self.model.inv_mass.iter().enumerate() {
            w[3 * p] = wp;
            w[3 * p + 1] = wp;
            w[3 * p + 2] = wp;
        }
    }

    fn force(&mut self, _t: f64, x: &[f64], v: &[f64], f: &mut [f64]) {
        self.evaluate(x, v, f, false);
    }

    fn linearize(&mut self, _t: f64, x: &[f64], v: &[f64]) {
        let model = &self.model;
        let mode = self.data.mode;
        let exact = mode == JacobianMode::Exact;
        let m = model.springs.len();
        let data = &mut self.data;
        if exact {
            for (s, (l, k)) in data.lin.iter_mut().zip(data.k_exact.iter_mut()).enumerate() {
                (*l, *k) = model.spring_jacobian(s, x, v, true);
            }
        } else {
            for_chunks(&mut data.lin, CHUNK, m > PARALLEL_THRESHOLD, |first, out| {
                for (k, l) in out.iter_mut().enumerate() {
                    *l = model.spring_jacobian(first + k, x, v, false).0;
                }
            });
        }
        if !model.colliders.is_empty() {
            let exact = mode == JacobianMode::Exact;
            let n = model.particles.len();
            let work = |p: usize, kc: &mut DMat3, dc: &mut DMat3| {
                *kc = DMat3::ZERO;
                *dc = DMat3::ZERO;
                for c in &model.colliders {
                    c.jacobians(load(x, p), load(v, p), exact, kc, dc);
                }
            };
            if n > PARALLEL_THRESHOLD {
                data.contact_k
                    .par_iter_mut()
                    .zip(data.contact_d.par_iter_mut())
                    .enumerate()
                    .for_each(|(p, (kc, dc))| work(p, kc, dc));
            } else {
                for (p, (kc, dc)) in data.contact_k.iter_mut().zip(data.contact_d.iter_mut()).enumerate() {
                    work(p, kc, dc);
                }
            }
        }
    }

    fn jacobian_apply(&self, c_x: f64, c_v: f64, dx: &[f64], out: &mut [f64]) {
        let model = &self.model;
        let data = &self.data;
        let n = model.particles.len();
        let contacts = !data.contact_k.is_empty();
        let exact = data.mode == JacobianMode::Exact;
        for_chunks(out, 3 * CHUNK, n > PARALLEL_THRESHOLD, |first, out| {
            for (k, op) in out.chunks_exact_mut(3).enumerate() {
                let p = first / 3 + k;
                let xp = load(dx, p);
                let mut acc = DVec3::ZERO;
                for e in &model.inc[model.inc_ptr[p]..model.inc_ptr[p + 1]] {
                    let s = e.spring();
                    let u = xp - load(dx, e.other());
                    let [nx, ny, nz, alpha, beta, c] = data.lin[s];
                    let nd = DVec3::new(nx, ny, nz);
                    if exact {
                        acc += c_x * (data.k_exact[s] * u) - (c_v * c * nd.dot(u)) * nd;
                    } else {
                        // (c_x K_s + c_v D_s) u = c_x alpha u + (c_x beta - c_v c)(n . u) n.
                        acc += (c_x * alpha) * u + ((c_x * beta - c_v * c) * nd.dot(u)) * nd;
                    }
                }
                if contacts {
                    acc += c_x * (data.contact_k[p] * xp) + c_v * (data.contact_d[p] * xp);
                }
                op[0] = acc.x;
                op[1] = acc.y;
                op[2] = acc.z;
            }
        });
    }

    fn jacobian_diagonal(&self, c_x: f64, c_v: f64, out: &mut [f64]) -> bool {
        let model = &self.model;
        let data = &self.data;
        let n = model.particles.len();
        let contacts = !data.contact_k.is_empty();
        for_chunks(out, 3 * CHUNK, n > PARALLEL_THRESHOLD, |first, out| {
            for (k, op) in out.chunks_exact_mut(3).enumerate() {
                let p = first / 3 + k;
                let mut acc = DVec3::ZERO;
                for e in &model.inc[model.inc_ptr[p]..model.inc_ptr[p + 1]] {
                    let b = self.block(e.spring(), c_x, c_v);
                    acc += DVec3::new(b.x_axis.x, b.y_axis.y, b.z_axis.z);
                }
                if contacts {
                    let b = c_x * data.contact_k[p] + c_v * data.contact_d[p];
                    acc += DVec3::new(b.x_axis.x, b.y_axis.y, b.z_axis.z);
                }
                op[0] = acc.x;
                op[1] = acc.y;
                op[2] = acc.z;
            }
        });
        true
    }

    fn jacobian_assemble(&self, c_x: f64, c_v: f64, out: &mut CsrMatrix) -> bool {
        let Some(pattern) = self.data.pattern.get_or_init(|| self.build_pattern()).as_ref() else {
            return false;
        };
        let address = out.col_idx().as_ptr() as usize;
        let same = out.nrows() == pattern.matrix.nrows()
            && out.ncols() == pattern.matrix.ncols()
            && out.row_ptr() == pattern.matrix.row_ptr()
            && (address == self.data.checked_pattern.load(Ordering::Relaxed)
                || out.col_idx() == pattern.matrix.col_idx());
        if !same {
            *out = pattern.matrix.clone();
        }
        self.data.checked_pattern.store(out.col_idx().as_ptr() as usize, Ordering::Relaxed);
        let model = &self.model;
        let data = &self.data;
        let n = model.particles.len();
        let contacts = !data.contact_k.is_empty();
        let fill = |p: usize, row: &mut [f64]| {
            row.iter_mut().for_each(|v| *v = 0.0);
            let width = 3 * pattern.nblocks[p];
            let diag = pattern.diag_slot[p];
            for e in model.inc_ptr[p]..model.inc_ptr[p + 1] {
                let b = self.block(model.inc[e].spring(), c_x, c_v);
                add_block(row, width, diag, &b, 1.0);
                add_block(row, width, pattern.inc_slot[e], &b, -1.0);
            }
            if contacts {
                let b = c_x * data.contact_k[p] + c_v * data.contact_d[p];
                add_block(row, width, diag, &b, 1.0);
            }
        };
        for_block_rows(out.values_mut(), &pattern.block_start, 0, n, n > PARALLEL_THRESHOLD, &fill);
        true
    }
}
