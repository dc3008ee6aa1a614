//! The simulation: the seed's PBD loop (section 3) and XPBD loop (section 3.1) over a
//! [`PbdModel`], with three constraint solvers, substepping, and a guard that stops a step which
//! produced a non-finite value or blew up, naming the step, the particle and the constraint.
//!
//! # The loop
//!
//! One step of `dt` is `substeps` substeps of `h = dt / substeps`, each the seed's loop body:
//!
//! ```text
//! (5)  forall vertices i:  v_i <- v_i + h w_i f_ext(x_i)            gravity, wind, user forces
//! (6)  dampVelocities(v_1..v_N)                                       Müller et al. 2007, 3.5
//! (7)  forall vertices i:  p_i <- x_i + h v_i
//! (8)  forall vertices i:  generateCollisionConstraints(x_i -> p_i)   contacts, see collide
//! (9)  loop solverIterations times
//! (10)     projectConstraints(C_1..C_{M+M_coll}, p_1..p_N)            see project
//! (11) endloop
//! (12) forall vertices i:  v_i <- (p_i - x_i) / h;  x_i <- p_i
//! (16) velocityUpdate(v_1..v_N)                                       restitution
//! ```
//!
//! XPBD (seed 3.1) is the same loop with `lambda <- 0` before the iterations (line 4 of its
//! algorithm) and equations 17/18 in the projection; its prediction
//! `x~ = x^n + h v^n + h^2 M^-1 f_ext` is lines (5) and (7) together. Choosing many substeps with
//! one iteration each is the "small steps" scheme of Macklin et al. 2019.
//!
//! # Solvers
//!
//! - [`SolverKind::GaussSeidel`]: the seed's sequential sweep, constraints in model order, then
//!   the contacts. Fastest convergence per iteration; one thread.
//! - [`SolverKind::ColoredGaussSeidel`]: the constraints are coloured once (greedy, in model
//!   order) so that no two of a colour share a movable particle; colours are swept in order, the
//!   constraints of a colour independently. It is Gauss-Seidel in another order: the same
//!   convergence, and faster than the model order on one thread, because consecutive
//!   projections no longer wait for each other's results. A colour of at least 65,536
//!   constraints per thread is swept in parallel, in two phases (corrections from the colour's
//!   start positions, then applied over disjoint particle ranges); on the 2-core machine this was
//!   measured slower than the sequential sweep at every cloth size tried, hence the threshold.
//! - [`SolverKind::Jacobi`]: every constraint is projected from the same positions (in parallel),
//!   its correction and multiplier increment scaled by `omega / n_j`, `n_j` the largest number of
//!   constraints meeting at one of its movable particles, and each particle adds its corrections in
//!   a fixed order (Jacobi with averaging, Macklin et al. 2014, eq. 11, in a form that keeps
//!   XPBD's `x` and `lambda` consistent). Slowest convergence; kept for comparison and for
//!   hardware without fast sequential sweeps. Contacts form a second group, projected after the
//!   internal constraints in every iteration.
//!
//! Every result is bitwise identical for any number of rayon threads: parallel loops write
//! disjoint data and every sum runs in one fixed order.
//!
//! # Failures
//!
//! A step is computed in the solver's own buffers and copied into the caller's state only when it
//! succeeded: on error the state is unchanged, and so is the simulation's memory (step count,
//! external forces, pending body targets: [`PbdSimulation::memory`]). After each step every
//! position and velocity is checked ([`PbdError::NonFinite`], whose message begins with
//! `anim-pbd: step N:` and names the particle, the component `x`/`y`/`z`, the value, the
//! particle's last finite position or velocity, and the first constraint whose update was not
//! finite, or else the first constraint at that particle), and the largest stretch
//! `|x_i - x_j| / l` over the distance constraints is compared with
//! [`PbdParams::max_stretch`] ([`PbdError::Diverged`]).

use crate::collide::{Contact, Pose};
use crate::constraint::{ConstraintFunction, load};
use crate::model::PbdModel;
use crate::project::{
    Buffered, CONTACT_ID, Compiled, Ctx, Direct, Kernel, colour, compile, project, project_contact, value,
};
use anim_core::glam::{DMat3, DVec3};
use anim_core::integrate::State;
use anim_core::solver::{Solver, StepReport};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::ops::Range;
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

/// PBD (stiffness `k`) or XPBD (compliance `alpha`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Method {
    /// Position based dynamics with the seed's stiffness `k` in `[0, 1]` (seed 3).
    Pbd,
    /// Extended PBD with compliance and multipliers (seed 3.1): stiffness independent of the
    /// iteration count and time step. The default.
    #[default]
    Xpbd,
}

/// How the constraints are swept in each iteration.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum SolverKind {
    /// Sequential Gauss-Seidel in model order, as the seed. The default.
    #[default]
    GaussSeidel,
    /// Graph-coloured Gauss-Seidel, parallel within a colour.
    ColoredGaussSeidel,
    /// Jacobi with averaging, parallel.
    Jacobi,
}

impl SolverKind {
    /// Every kind.
    pub const ALL: [SolverKind; 3] =
        [SolverKind::GaussSeidel, SolverKind::ColoredGaussSeidel, SolverKind::Jacobi];

    /// Short name for reports.
    #[must_use]
    pub fn label(self) -> &'static str {
        match self {
            SolverKind::GaussSeidel => "gauss-seidel",
            SolverKind::ColoredGaussSeidel => "colored-gauss-seidel",
            SolverKind::Jacobi => "jacobi",
        }
    }
}

/// Solver settings. Every field's default is in its doc.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
#[non_exhaustive]
pub struct PbdParams {
    /// PBD or XPBD. Default [`Method::Xpbd`].
    pub method: Method,
    /// Constraint sweep. Default [`SolverKind::GaussSeidel`].
    pub solver: SolverKind,
    /// Solver iterations per substep (`>= 1`). Default 10.
    pub iterations: usize,
    /// Substeps per step (`>= 1`). Default 1.
    pub substeps: usize,
    /// Müller et al.'s velocity damping `k_damping` in `[0, 1]` (line 6): the velocities'
    /// deviation from the rigid motion of all free particles is reduced by this fraction every
    /// substep. Default 0.
    pub velocity_damping: f64,
    /// Use `k' = 1 - (1 - k)^(1/iterations)` in PBD (Müller et al. 2007, 3.3). Default `true`.
    pub stiffness_correction: bool,
    /// Jacobi relaxation `omega` in `(0, 2]`. Default 1.
    pub jacobi_relaxation: f64,
    /// A step after which a distance constraint is stretched beyond this multiple of its rest
    /// length fails with [`PbdError::Diverged`] (`f64::INFINITY` disables the guard). Default 100.
    pub max_stretch: f64,
    /// Speculative contact margin (m, >= 0): line (8) also generates a contact for a particle
    /// whose predicted position is within `thickness + margin + |p - x|` of a collider, so that
    /// internal constraints cannot push it through the surface during the iterations unseen
    /// (an inactive contact costs one test per iteration). Default `0.005`.
    pub contact_margin: f64,
}

impl Default for PbdParams {
    fn default() -> Self {
        Self {
            method: Method::Xpbd,
            solver: SolverKind::GaussSeidel,
            iterations: 10,
            substeps: 1,
            velocity_damping: 0.0,
            stiffness_correction: true,
            jacobi_relaxation: 1.0,
            max_stretch: 100.0,
            contact_margin: 0.005,
        }
    }
}

impl PbdParams {
    /// Settings with the given method, solver, iterations and substeps; the rest default.
    #[must_use]
    pub fn new(method: Method, solver: SolverKind, iterations: usize, substeps: usize) -> Self {
        Self { method, solver, iterations, substeps, ..Self::default() }
    }

    fn validate(&self) -> Result<(), PbdError> {
        let bad = |name, requirement, value: String| Err(PbdError::BadParameter { name, requirement, value });
        if self.iterations == 0 {
            return bad("iterations", "must be at least 1", self.iterations.to_string());
        }
        if self.substeps == 0 {
            return bad("substeps", "must be at least 1", self.substeps.to_string());
        }
        if !(0.0..=1.0).contains(&self.velocity_damping) {
            return bad("velocity_damping", "must lie in [0, 1]", self.velocity_damping.to_string());
        }
        if !(self.jacobi_relaxation > 0.0 && self.jacobi_relaxation <= 2.0) {
            return bad("jacobi_relaxation", "must lie in (0, 2]", self.jacobi_relaxation.to_string());
        }
        if !(self.contact_margin >= 0.0 && self.contact_margin.is_finite()) {
            return bad("contact_margin", "must be non-negative and finite", self.contact_margin.to_string());
        }
        if !(self.max_stretch > 1.0) {
            return bad("max_stretch", "must exceed 1", self.max_stretch.to_string());
        }
        Ok(())
    }
}

/// A failed step or bad settings. The state is unchanged when a step returns one.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum PbdError {
    /// A checkpointed memory that does not belong to this simulation.
    #[error("checkpoint does not fit this simulation: {0}")]
    Checkpoint(String),
    /// A solver setting is out of range.
    #[error("{name} {requirement}, got {value}")]
    BadParameter {
        /// The setting.
        name: &'static str,
        /// What it must satisfy.
        requirement: &'static str,
        /// The value given.
        value: String,
    },
    /// The time step is not positive and finite.
    #[error("time step must be positive and finite, got {dt}")]
    BadTimeStep {
        /// The value given.
        dt: f64,
    },
    /// A position or velocity became NaN or infinite. The step was undone.
    #[error(
        "anim-pbd: step {step}: non-finite {field} of particle {particle}{} (value {value}); last finite {field} of particle {particle}: {last_finite:?}; {}; the step was undone",
        match component { Some(c) => format!(", component {}", ["x", "y", "z"][(*c).min(2)]), None => String::new() },
        match constraint { Some((c, kind)) => format!("constraint {c} ({kind}) produced it"), None => "no constraint involved (external force or input)".to_string() }
    )]
    NonFinite {
        /// Step index (0-based count of completed steps).
        step: u64,
        /// "position" or "velocity".
        field: &'static str,
        /// First offending particle.
        particle: usize,
        /// Its first offending component (0, 1, 2 for `x`, `y`, `z`); `None` when a constraint's
        /// update was not finite and was skipped, leaving the particle finite.
        component: Option<usize>,
        /// The offending value (NaN when the update was skipped, see `component`).
        value: f64,
        /// The particle's position or velocity (as `field` says) before the step.
        last_finite: [f64; 3],
        /// The first constraint whose update was not finite (or else the first constraint at that
        /// particle), with its kind.
        constraint: Option<(usize, &'static str)>,
    },
    /// A distance constraint stretched beyond the bound: the run is diverging. The step was undone.
    #[error(
        "diverged at step {step}: constraint {constraint} (distance, particles {i} and {j}) stretched to {ratio:.3e} times its rest length (bound {bound}); the step was undone"
    )]
    Diverged {
        /// Step index.
        step: u64,
        /// Constraint index.
        constraint: usize,
        /// Its first particle.
        i: usize,
        /// Its second particle.
        j: usize,
        /// `|x_i - x_j| / l` after the step.
        ratio: f64,
        /// The bound.
        bound: f64,
    },
}

/// What a step did (the fast path's report).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct StepInfo {
    /// Substeps taken.
    pub substeps: usize,
    /// Iterations per substep.
    pub iterations: usize,
    /// Contacts generated in the last substep.
    pub contacts: usize,
}

/// Items per rayon task (small in unit tests, so that they exercise the parallel paths).
const CHUNK: usize = if cfg!(test) { 16 } else { 256 };
/// Loops shorter than this run on the calling thread.
const PARALLEL_MIN: usize = if cfg!(test) { 64 } else { 2048 };
/// A colour is swept in parallel (two phases) only with at least this many constraints per
/// thread. Measured on the 2-core development machine, the two-phase sweep on 2 threads was
/// slower than the sequential colour-order sweep at every size tried (benchmark cloth 100^2,
/// 200^2, 300^2: 4.7 vs 3.0, 24 vs 13, 82 vs 35 ms per step): the corrections' second pass
/// costs more than the second core gains. Unit tests use a small value to exercise the path.
const COLOUR_PARALLEL_MIN: usize = if cfg!(test) { 64 } else { 1 << 16 };

/// The solver's scratch, sized once from the model.
#[derive(Debug)]
struct Data {
    x: Vec<DVec3>,
    v: Vec<DVec3>,
    p: Vec<DVec3>,
    compiled: Vec<Compiled>,
    lambda: Vec<f64>,
    /// Ranges of `compiled` swept in sequence (one for Gauss-Seidel and Jacobi, one per colour).
    groups: Vec<Range<usize>>,
    /// Per colour: whether it holds a global volume (then it is swept sequentially).
    group_has_volume: Vec<bool>,
    /// Per colour: `(particle, constraint, slot)` written by the colour, sorted by particle.
    touched: Vec<Vec<(u32, u32, u32)>>,
    /// Buffered corrections per constraint (coloured and Jacobi sweeps).
    corr: Vec<[DVec3; 4]>,
    scratch: Vec<Mutex<Vec<DVec3>>>,
    /// Copies of the volume meshes' buffered corrections (Jacobi gather).
    volume_corr: Vec<Vec<DVec3>>,
    contacts: Vec<Contact>,
    contact_groups: Vec<Range<usize>>,
    pose_start: Vec<Pose>,
    pose_end: Vec<Pose>,
    pose_sub: Vec<Pose>,
    pose_sub_prev: Vec<Pose>,
    tri_force: Vec<DVec3>,
    ext: Vec<DVec3>,
    bad: AtomicUsize,
}

/// A [`PbdModel`] with its solver: anim-core's [`Solver`] for PBD and XPBD.
#[derive(Debug)]
pub struct PbdSimulation {
    model: PbdModel,
    params: PbdParams,
    data: Data,
    steps: u64,
    targets: Vec<Option<Pose>>,
    forces: Vec<DVec3>,
}

/// Copies `from` into `to` reusing `to`'s buffers.
fn copy_vec3(to: &mut [DVec3], from: &[f64]) {
    for (i, t) in to.iter_mut().enumerate() {
        *t = load(from, i);
    }
}

impl PbdSimulation {
    /// Couples `model` with a solver.
    ///
    /// # Errors
    /// [`PbdError::BadParameter`] for settings out of range.
    pub fn new(model: PbdModel, params: PbdParams) -> Result<Self, PbdError> {
        params.validate()?;
        let n = model.num_particles();
        let nb = model.bodies.len();
        let nc = model.colliders.len();
        let scratch =
            model.volume_meshes.iter().map(|m| Mutex::new(vec![DVec3::ZERO; m.vertices.len()])).collect();
        let data = Data {
            x: vec![DVec3::ZERO; n],
            v: vec![DVec3::ZERO; n],
            p: vec![DVec3::ZERO; n],
            compiled: Vec::new(),
            lambda: Vec::new(),
            groups: Vec::new(),
            group_has_volume: Vec::new(),
            touched: Vec::new(),
            corr: Vec::new(),
            scratch,
            volume_corr: model.volume_meshes.iter().map(|m| vec![DVec3::ZERO; m.vertices.len()]).collect(),
            contacts: Vec::with_capacity(n * nc),
            contact_groups: Vec::with_capacity(nc),
            pose_start: vec![Pose::IDENTITY; nb],
            pose_end: vec![Pose::IDENTITY; nb],
            pose_sub: vec![Pose::IDENTITY; nb],
            pose_sub_prev: vec![Pose::IDENTITY; nb],
            tri_force: vec![DVec3::ZERO; if model.wind.is_some() { model.triangles.len() } else { 0 }],
            ext: vec![DVec3::ZERO; n],
            bad: AtomicUsize::new(usize::MAX),
        };
        let mut sim =
            Self { model, params, data, steps: 0, targets: vec![None; nb], forces: vec![DVec3::ZERO; n] };
        for (b, body) in sim.model.bodies.iter().enumerate() {
            sim.data.pose_sub[b] = body.pose_at(0.0);
        }
        sim.compile();
        Ok(sim)
    }

    /// (Re)builds the compiled constraints, the sweep order and the colouring for the settings.
    fn compile(&mut self) {
        let model = &self.model;
        let p = &self.params;
        let m = model.constraints.len();
        let mut compiled: Vec<Compiled> =
            (0..m).map(|j| compile(model, j, p.iterations, p.stiffness_correction)).collect();
        let mut groups = Vec::new();
        match p.solver {
            SolverKind::GaussSeidel | SolverKind::Jacobi => groups.push(0..m),
            SolverKind::ColoredGaussSeidel => {
                let (colours, ncol) = colour(model);
                let mut order: Vec<usize> = (0..m).collect();
                order.sort_by_key(|&j| (colours[j], j));
                compiled = order.iter().map(|&j| compiled[j]).collect();
                let mut start = 0;
                for c in 0..ncol as u32 {
                    let len = colours.iter().filter(|&&k| k == c).count();
                    groups.push(start..start + len);
                    start += len;
                }
            }
        }
        if p.solver == SolverKind::Jacobi {
            // n_i: constraints at particle i; n_j: the largest n_i over j's movable particles.
            for c in compiled.iter_mut() {
                let j = c.id as usize;
                let n_j = model
                    .constraint_particles(j)
                    .iter()
                    .filter(|&&i| model.inv_mass[i] > 0.0)
                    .map(|&i| model.inc_ptr[i + 1] - model.inc_ptr[i])
                    .max()
                    .unwrap_or(1)
                    .max(1);
                c.relax = p.jacobi_relaxation / n_j as f64;
            }
        }
        let buffered = p.solver != SolverKind::GaussSeidel;
        self.data.corr = if buffered { vec![[DVec3::ZERO; 4]; m] } else { Vec::new() };
        let is_volume = |c: &Compiled| matches!(c.kernel, Kernel::Volume { .. });
        self.data.group_has_volume =
            groups.iter().map(|r| compiled[r.clone()].iter().any(is_volume)).collect();
        self.data.touched = if p.solver == SolverKind::ColoredGaussSeidel {
            groups
                .iter()
                .map(|r| {
                    let mut t: Vec<(u32, u32, u32)> = Vec::new();
                    for ci in r.clone() {
                        let j = compiled[ci].id as usize;
                        for (slot, &i) in model.constraint_particles(j).iter().enumerate() {
                            if model.inv_mass[i] > 0.0 {
                                t.push((i as u32, ci as u32, slot as u32));
                            }
                        }
                    }
                    t.sort_unstable();
                    t
                })
                .collect()
        } else {
            Vec::new()
        };
        self.data.lambda = vec![0.0; m];
        self.data.compiled = compiled;
        self.data.groups = groups;
    }

    /// The model.
    #[must_use]
    pub fn model(&self) -> &PbdModel {
        &self.model
    }

    /// The settings.
    #[must_use]
    pub fn params(&self) -> &PbdParams {
        &self.params
    }

    /// Changes the settings between steps (recompiles the constraints and, for the coloured
    /// solver, the colouring).
    ///
    /// # Errors
    /// [`PbdError::BadParameter`]; the old settings stay in force.
    pub fn set_params(&mut self, params: PbdParams) -> Result<(), PbdError> {
        params.validate()?;
        self.params = params;
        self.compile();
        Ok(())
    }

    /// Number of colours of the coloured solver (1 for the others).
    #[must_use]
    pub fn num_groups(&self) -> usize {
        self.data.groups.len()
    }

    /// Steps completed.
    #[must_use]
    pub fn steps(&self) -> u64 {
        self.steps
    }

    /// What the simulation carries from one step to the next (step count, the external forces
    /// set with [`PbdSimulation::set_external_force`], pending body targets), for checkpoints:
    /// with the [`State`], it continues a run bit for bit.
    #[must_use]
    pub fn memory(&self) -> serde_json::Value {
        let forces: Vec<[f64; 3]> = self.forces.iter().map(|f| f.to_array()).collect();
        let targets = serde_json::to_value(&self.targets).unwrap_or(serde_json::Value::Null);
        serde_json::json!({ "steps": self.steps, "forces": forces, "targets": targets })
    }

    /// Restores what [`PbdSimulation::memory`] returned.
    ///
    /// # Errors
    /// [`PbdError::Checkpoint`] when `memory` does not fit this model (missing fields, another
    /// particle or body count).
    pub fn restore_memory(&mut self, memory: &serde_json::Value) -> Result<(), PbdError> {
        let bad = |m: &str| PbdError::Checkpoint(m.to_string());
        let steps =
            memory.get("steps").and_then(serde_json::Value::as_u64).ok_or_else(|| bad("no step count"))?;
        let forces: Vec<[f64; 3]> = memory
            .get("forces")
            .map(|f| serde_json::from_value(f.clone()))
            .ok_or_else(|| bad("no external forces"))?
            .map_err(|e| bad(&format!("external forces: {e}")))?;
        let targets: Vec<Option<Pose>> = memory
            .get("targets")
            .map(|t| serde_json::from_value(t.clone()))
            .ok_or_else(|| bad("no body targets"))?
            .map_err(|e| bad(&format!("body targets: {e}")))?;
        if forces.len() != self.forces.len() || targets.len() != self.targets.len() {
            return Err(bad(&format!(
                "{} forces and {} body targets for a model of {} particles and {} bodies",
                forces.len(),
                targets.len(),
                self.forces.len(),
                self.targets.len()
            )));
        }
        for (to, from) in self.forces.iter_mut().zip(forces) {
            *to = DVec3::from_array(from);
        }
        self.targets = targets;
        self.steps = steps;
        Ok(())
    }

    /// Sets the pose kinematic body `body` reaches at the end of the next step (it moves linearly
    /// there during the step), overriding its motion for that step.
    ///
    /// # Panics
    /// If `body` does not exist.
    #[track_caller]
    pub fn set_body_target(&mut self, body: usize, pose: Pose) {
        assert!(body < self.targets.len(), "set_body_target: body {body} does not exist");
        self.targets[body] = Some(pose);
    }

    /// Sets an external force (N) on particle `p`, applied every substep until changed.
    ///
    /// # Panics
    /// If `p` does not exist.
    #[track_caller]
    pub fn set_external_force(&mut self, p: usize, force: [f64; 3]) {
        assert!(p < self.forces.len(), "set_external_force: particle {p} does not exist");
        self.forces[p] = DVec3::from_array(force);
    }

    /// The multipliers `lambda` of the last substep, per model constraint (XPBD; PBD leaves 0).
    #[must_use]
    pub fn multipliers(&self) -> Vec<f64> {
        let mut out = vec![0.0; self.data.lambda.len()];
        for (c, l) in self.data.compiled.iter().zip(&self.data.lambda) {
            out[c.id as usize] = *l;
        }
        out
    }

    /// Advances `state` by `dt` (the fast path: no energy or momenta computed).
    ///
    /// # Errors
    /// [`PbdError::BadTimeStep`], [`PbdError::NonFinite`], [`PbdError::Diverged`]; `state` is
    /// unchanged on error.
    ///
    /// # Panics
    /// If `state` does not have `3 N` positions and velocities.
    #[track_caller]
    pub fn advance(&mut self, state: &mut State, dt: f64) -> Result<StepInfo, PbdError> {
        let n = self.model.num_particles();
        assert!(state.x.len() == 3 * n && state.v.len() == 3 * n, "advance: state does not match the model");
        if !(dt > 0.0 && dt.is_finite()) {
            return Err(PbdError::BadTimeStep { dt });
        }
        copy_vec3(&mut self.data.x, &state.x);
        copy_vec3(&mut self.data.v, &state.v);
        let t0 = state.t;
        for (b, body) in self.model.bodies.iter().enumerate() {
            self.data.pose_start[b] = body.pose_at(t0);
            // A pending target is used up only by a step that succeeds.
            self.data.pose_end[b] = self.targets[b].unwrap_or_else(|| body.pose_at(t0 + dt));
        }
        let s = self.params.substeps;
        let h = dt / s as f64;
        let mut contacts = 0;
        self.data.bad.store(usize::MAX, Ordering::Relaxed);
        for k in 0..s {
            contacts = self.substep(t0 + k as f64 * h, h, k, s);
        }
        self.check(state)?;
        for (i, (x, v)) in self.data.x.iter().zip(&self.data.v).enumerate() {
            state.x[3 * i..3 * i + 3].copy_from_slice(&x.to_array());
            state.v[3 * i..3 * i + 3].copy_from_slice(&v.to_array());
        }
        state.t = t0 + dt;
        self.targets.iter_mut().for_each(|t| *t = None);
        self.steps += 1;
        Ok(StepInfo { substeps: s, iterations: self.params.iterations, contacts })
    }

    /// Runs `steps` steps of `dt`.
    ///
    /// # Errors
    /// The first failing step's error; `state` is then the state before that step.
    pub fn run(&mut self, state: &mut State, dt: f64, steps: usize) -> Result<(), PbdError> {
        for _ in 0..steps {
            self.advance(state, dt)?;
        }
        Ok(())
    }

    /// One substep of length `h` starting at time `t` (substep `k` of `s`); returns the number of
    /// contacts.
    fn substep(&mut self, t: f64, h: f64, k: usize, s: usize) -> usize {
        let model = &self.model;
        let d = &mut self.data;
        let n = model.num_particles();
        for b in 0..model.bodies.len() {
            d.pose_sub_prev[b] = d.pose_start[b].lerp(&d.pose_end[b], k as f64 / s as f64);
            d.pose_sub[b] = d.pose_start[b].lerp(&d.pose_end[b], (k + 1) as f64 / s as f64);
        }
        // (5) external forces: gravity, user forces, wind.
        let wind = model.wind.is_some();
        if let Some(wnd) = model.wind {
            let speed = 1.0 + wnd.gust * (std::f64::consts::TAU * 0.5 * t).sin();
            let wv = DVec3::from_array(wnd.velocity) * speed;
            let (x, v) = (&d.x, &d.v);
            let tri = &model.triangles;
            for_each_chunk(&mut d.tri_force, |first, out| {
                for (m, f) in out.iter_mut().enumerate() {
                    let [a, b, c] = tri[first + m];
                    let nrm = (x[b] - x[a]).cross(x[c] - x[a]);
                    let twice = nrm.length();
                    *f = if twice > 0.0 {
                        let nh = nrm / twice;
                        let u = (v[a] + v[b] + v[c]) / 3.0;
                        nh * (wnd.drag * 0.5 * twice * (wv - u).dot(nh))
                    } else {
                        DVec3::ZERO
                    };
                }
            });
            let tf = &d.tri_force;
            for_each_chunk(&mut d.ext, |first, out| {
                for (m, e) in out.iter_mut().enumerate() {
                    let i = first + m;
                    let mut f = DVec3::ZERO;
                    for &tk in &model.tri_inc[model.tri_ptr[i]..model.tri_ptr[i + 1]] {
                        f += tf[tk as usize];
                    }
                    *e = f / 3.0;
                }
            });
        }
        let g = model.gravity;
        let (w, forces, ext) = (&model.inv_mass, &self.forces, &d.ext);
        for_each_chunk(&mut d.v, |first, out| {
            for (m, v) in out.iter_mut().enumerate() {
                let i = first + m;
                if w[i] > 0.0 {
                    let f = if wind { forces[i] + ext[i] } else { forces[i] };
                    *v += h * (g + w[i] * f);
                }
            }
        });
        // (6) dampVelocities.
        if self.params.velocity_damping > 0.0 {
            damp_velocities(model, &d.x, &mut d.v, self.params.velocity_damping);
        }
        // (7) p <- x + h v.
        {
            let (x, v) = (&d.x, &d.v);
            for_each_chunk(&mut d.p, |first, out| {
                for (m, p) in out.iter_mut().enumerate() {
                    let i = first + m;
                    *p = x[i] + h * v[i];
                }
            });
        }
        // (8) generateCollisionConstraints, collider by collider (each particle at most once per
        // collider, so each collider's contacts form one colour).
        d.contacts.clear();
        d.contact_groups.clear();
        let gmag = g.length();
        let margin = self.params.contact_margin;
        for (ci, col) in model.colliders.iter().enumerate() {
            let start = d.contacts.len();
            let (pose, prev) = match col.body {
                Some(b) => (d.pose_sub[b], d.pose_sub_prev[b]),
                None => (Pose::IDENTITY, Pose::IDENTITY),
            };
            for i in 0..n {
                if w[i] == 0.0 {
                    continue;
                }
                let p = d.p[i];
                let local = pose.inverse_apply(p);
                let (phi, nl) = col.shape.signed_distance(local);
                if !(phi < col.thickness + margin + (p - d.x[i]).length()) {
                    continue;
                }
                let normal = pose.rotation * nl;
                let q = p - normal * phi;
                let ql = pose.inverse_apply(q);
                let obstacle_dx = q - prev.apply(ql);
                let vn_pre = normal.dot(d.v[i] - obstacle_dx / h);
                d.contacts.push(Contact {
                    particle: i as u32,
                    collider: ci as u32,
                    normal,
                    offset: normal.dot(q) + col.thickness,
                    obstacle_dx,
                    vn_pre,
                    lambda: 0.0,
                    dx: DVec3::ZERO,
                });
            }
            d.contact_groups.push(start..d.contacts.len());
        }
        // (9)-(11) the iterations.
        d.lambda.iter_mut().for_each(|l| *l = 0.0);
        let xpbd = self.params.method == Method::Xpbd;
        let ctx = Ctx {
            w,
            x: &d.x,
            xpbd,
            h,
            inv_h2: 1.0 / (h * h),
            poses: &d.pose_sub,
            meshes: &model.volume_meshes,
            scratch: &d.scratch,
            colliders: &model.colliders,
            bad: &d.bad,
        };
        let parallel = rayon::current_num_threads() > 1;
        for _ in 0..self.params.iterations {
            match self.params.solver {
                SolverKind::GaussSeidel => {
                    let mut acc = Direct(&mut d.p);
                    for (c, l) in d.compiled.iter().zip(d.lambda.iter_mut()) {
                        project(&ctx, c, l, &mut acc);
                    }
                    for c in d.contacts.iter_mut() {
                        let dx = project_contact(&ctx, c, d.p[c.particle as usize]);
                        d.p[c.particle as usize] += dx;
                    }
                }
                SolverKind::ColoredGaussSeidel => {
                    for (g, r) in d.groups.iter().enumerate() {
                        let cs = &d.compiled[r.clone()];
                        let ls = &mut d.lambda[r.clone()];
                        let threads = rayon::current_num_threads();
                        if parallel && cs.len() >= COLOUR_PARALLEL_MIN * threads && !d.group_has_volume[g] {
                            // Two phases: corrections from the colour's start positions, then
                            // applied over disjoint particle ranges.
                            let pos: &[DVec3] = &d.p;
                            let corr = &mut d.corr[r.clone()];
                            let chunk = cs.len().div_ceil(2 * rayon::current_num_threads()).max(CHUNK);
                            cs.par_chunks(chunk)
                                .zip(ls.par_chunks_mut(chunk))
                                .zip(corr.par_chunks_mut(chunk))
                                .for_each(|((cs, ls), out)| {
                                    for ((c, l), o) in cs.iter().zip(ls.iter_mut()).zip(out.iter_mut()) {
                                        *o = [DVec3::ZERO; 4];
                                        project(&ctx, c, l, &mut Buffered { pos, out: o });
                                    }
                                });
                            let t = &d.touched[g];
                            let leaf = t.len().div_ceil(2 * rayon::current_num_threads()).max(4 * CHUNK);
                            apply_sorted(&mut d.p, 0, t, &d.corr, leaf);
                        } else {
                            let mut acc = Direct(&mut d.p);
                            for (c, l) in cs.iter().zip(ls.iter_mut()) {
                                project(&ctx, c, l, &mut acc);
                            }
                        }
                    }
                    project_contact_groups(&ctx, &mut d.contacts, &d.contact_groups, &mut d.p, parallel);
                }
                SolverKind::Jacobi => {
                    let pos: &[DVec3] = &d.p;
                    let work = |(c, (l, o)): (&Compiled, (&mut f64, &mut [DVec3; 4]))| {
                        *o = [DVec3::ZERO; 4];
                        project(&ctx, c, l, &mut Buffered { pos, out: o });
                    };
                    let cs = &d.compiled;
                    if parallel && cs.len() >= PARALLEL_MIN {
                        cs.par_iter()
                            .zip(d.lambda.par_iter_mut().zip(d.corr.par_iter_mut()))
                            .with_min_len(CHUNK)
                            .for_each(work);
                    } else {
                        cs.iter().zip(d.lambda.iter_mut().zip(d.corr.iter_mut())).for_each(work);
                    }
                    for (m, out) in d.scratch.iter().zip(d.volume_corr.iter_mut()) {
                        out.copy_from_slice(&m.lock().unwrap_or_else(std::sync::PoisonError::into_inner));
                    }
                    // Gather per particle in the fixed incidence order.
                    let (corr, vcorr) = (&d.corr, &d.volume_corr);
                    let gather = |i: usize| -> DVec3 {
                        let mut s = DVec3::ZERO;
                        for &(c, slot) in &model.inc[model.inc_ptr[i]..model.inc_ptr[i + 1]] {
                            s += match model.constraints[c as usize].function {
                                ConstraintFunction::GlobalVolume { mesh, .. } => vcorr[mesh][slot as usize],
                                _ => corr[c as usize][slot as usize],
                            };
                        }
                        s
                    };
                    for_each_chunk(&mut d.p, |first, out| {
                        for (m, p) in out.iter_mut().enumerate() {
                            let i = first + m;
                            if w[i] > 0.0 {
                                *p += gather(i);
                            }
                        }
                    });
                    project_contact_groups(&ctx, &mut d.contacts, &d.contact_groups, &mut d.p, parallel);
                }
            }
        }
        // (12)-(15) v <- (p - x) / h, x <- p.
        let inv_h = 1.0 / h;
        if parallel && n >= PARALLEL_MIN {
            d.x.par_chunks_mut(CHUNK)
                .zip(d.v.par_chunks_mut(CHUNK))
                .zip(d.p.par_chunks(CHUNK))
                .for_each(|((x, v), p)| update(x, v, p, inv_h));
        } else {
            update(&mut d.x, &mut d.v, &d.p, inv_h);
        }
        // (16) velocityUpdate: restitution.
        for c in &d.contacts {
            if c.lambda > 0.0 {
                let col = &model.colliders[c.collider as usize];
                let i = c.particle as usize;
                let vo = c.obstacle_dx * inv_h;
                let vn = c.normal.dot(d.v[i] - vo);
                let target = if c.vn_pre < -2.0 * gmag * h { -col.restitution * c.vn_pre } else { 0.0 };
                d.v[i] += c.normal * (target.max(0.0) - vn);
            }
        }
        d.contacts.len()
    }

    /// The post-step checks (see the module docs).
    fn check(&self, state: &State) -> Result<(), PbdError> {
        let d = &self.data;
        let step = self.steps;
        let bad_x = d.x.iter().position(|p| !p.is_finite());
        let bad_v = d.v.iter().position(|p| !p.is_finite());
        let flagged = d.bad.load(Ordering::Relaxed);
        if bad_x.is_some() || bad_v.is_some() || flagged != usize::MAX {
            let (field, particle, after, old) = match (bad_x, bad_v) {
                (Some(p), _) => ("position", p, Some(d.x[p]), &state.x),
                (None, Some(p)) => ("velocity", p, Some(d.v[p]), &state.v),
                // A skipped non-finite update left the state finite: name the constraint's first particle.
                (None, None) => ("position", self.first_particle(flagged), None, &state.x),
            };
            let component = after.and_then(|a| a.to_array().iter().position(|c| !c.is_finite()));
            let value = match (after, component) {
                (Some(a), Some(c)) => a[c],
                _ => f64::NAN,
            };
            let constraint = if flagged < self.model.constraints.len() && flagged != CONTACT_ID as usize {
                Some(flagged)
            } else {
                self.model.incident(particle).next()
            };
            return Err(PbdError::NonFinite {
                step,
                field,
                particle,
                component,
                value,
                last_finite: load(old, particle).to_array(),
                constraint: constraint.map(|c| (c, self.model.constraints[c].function.name())),
            });
        }
        if self.params.max_stretch.is_finite() {
            let mut worst: Option<(f64, usize, usize, usize)> = None;
            for (j, c) in self.model.constraints.iter().enumerate() {
                if let ConstraintFunction::Distance { particles: [a, b], rest_length } = c.function
                    && rest_length > 0.0
                {
                    let r = (d.x[a] - d.x[b]).length() / rest_length;
                    if r > self.params.max_stretch && worst.is_none_or(|w| r > w.0) {
                        worst = Some((r, j, a, b));
                    }
                }
            }
            if let Some((ratio, constraint, i, j)) = worst {
                return Err(PbdError::Diverged {
                    step,
                    constraint,
                    i,
                    j,
                    ratio,
                    bound: self.params.max_stretch,
                });
            }
        }
        Ok(())
    }

    fn first_particle(&self, flagged: usize) -> usize {
        if flagged < self.model.constraints.len() {
            self.model.constraint_particles(flagged).first().copied().unwrap_or(0)
        } else {
            0
        }
    }

    /// The largest constraint violation at positions `x`: `|C|` for equalities, `max(-C, 0)` for
    /// inequalities, over the model's constraints (kinematic bodies where the last step left them).
    ///
    /// # Panics
    /// If `x` has the wrong length.
    #[must_use]
    pub fn max_violation(&self, x: &[f64]) -> f64 {
        assert_eq!(x.len(), 3 * self.model.num_particles(), "max_violation: wrong length");
        let mut worst = 0.0f64;
        for c in &self.data.compiled {
            let v = value(c, |i| load(x, i), &self.data.pose_sub, &self.model.volume_meshes);
            let e = if c.inequality { (-v).max(0.0) } else { v.abs() };
            worst = worst.max(e);
        }
        worst
    }

    /// XPBD's residual after the last step, `max_j |C_j + alpha~_j lambda_j|` with
    /// `alpha~ = alpha / h^2` (equation 18's numerator at convergence), at positions `x`; the PBD
    /// residual `max |C_j|` of the rigid (`k = 1`) constraints in PBD mode.
    ///
    /// # Panics
    /// If `x` has the wrong length.
    #[must_use]
    pub fn residual(&self, x: &[f64], h: f64) -> f64 {
        assert_eq!(x.len(), 3 * self.model.num_particles(), "residual: wrong length");
        let xpbd = self.params.method == Method::Xpbd;
        let inv_h2 = 1.0 / (h * h);
        let mut worst = 0.0f64;
        for (c, l) in self.data.compiled.iter().zip(&self.data.lambda) {
            if !xpbd && c.k < 1.0 {
                continue;
            }
            let v = value(c, |i| load(x, i), &self.data.pose_sub, &self.model.volume_meshes);
            let r = if xpbd { v + c.alpha * inv_h2 * l } else { v };
            let e = if c.inequality && (v >= 0.0 && (!xpbd || *l == 0.0)) { 0.0 } else { r.abs() };
            worst = worst.max(e);
        }
        worst
    }

    /// Elastic energy `sum (1/2) C_j^2 / alpha_j` of the compliant constraints (XPBD's potential;
    /// rigid constraints contribute nothing), kinematic bodies where the last step left them.
    ///
    /// # Panics
    /// If `x` has the wrong length.
    #[must_use]
    pub fn elastic_energy(&self, x: &[f64]) -> f64 {
        assert_eq!(x.len(), 3 * self.model.num_particles(), "elastic_energy: wrong length");
        let mut e = 0.0;
        for c in &self.data.compiled {
            if c.alpha > 0.0 {
                let v = value(c, |i| load(x, i), &self.data.pose_sub, &self.model.volume_meshes);
                if !(c.inequality && v >= 0.0) {
                    e += 0.5 * v * v / c.alpha;
                }
            }
        }
        e
    }
}

/// `a b^T`.
#[inline]
fn outer(a: DVec3, b: DVec3) -> DMat3 {
    DMat3::from_cols(a * b.x, a * b.y, a * b.z)
}

/// `v <- (p - x) / h`, `x <- p` over matching chunks.
fn update(x: &mut [DVec3], v: &mut [DVec3], p: &[DVec3], inv_h: f64) {
    for ((x, v), &pn) in x.iter_mut().zip(v.iter_mut()).zip(p) {
        *v = (pn - *x) * inv_h;
        *x = pn;
    }
}

/// Adds the buffered corrections `list = (particle, constraint, slot)` (sorted by particle, each
/// particle at most once) to `pos`, whose first element is particle `base`; splits the list and
/// the positions at a particle boundary and recurses in parallel.
fn apply_sorted(pos: &mut [DVec3], base: usize, list: &[(u32, u32, u32)], corr: &[[DVec3; 4]], leaf: usize) {
    if list.len() <= leaf {
        for &(i, c, s) in list {
            pos[i as usize - base] += corr[c as usize][s as usize];
        }
        return;
    }
    let mid = list.len() / 2;
    let split = list[mid].0 as usize;
    let (lo, hi) = pos.split_at_mut(split - base);
    rayon::join(
        || apply_sorted(lo, base, &list[..mid], corr, leaf),
        || apply_sorted(hi, split, &list[mid..], corr, leaf),
    );
}

/// Projects the contacts collider by collider; within a collider every particle appears once, so
/// its contacts run in parallel.
fn project_contact_groups(
    ctx: &Ctx<'_>,
    contacts: &mut [Contact],
    groups: &[Range<usize>],
    p: &mut [DVec3],
    parallel: bool,
) {
    for r in groups {
        let cs = &mut contacts[r.clone()];
        if parallel && cs.len() >= PARALLEL_MIN {
            let pos: &[DVec3] = p;
            cs.par_chunks_mut(CHUNK).for_each(|cs| {
                for c in cs {
                    c.dx = project_contact(ctx, c, pos[c.particle as usize]);
                }
            });
            for c in cs.iter() {
                p[c.particle as usize] += c.dx;
            }
        } else {
            for c in cs {
                let dx = project_contact(ctx, c, p[c.particle as usize]);
                p[c.particle as usize] += dx;
            }
        }
    }
}

/// Runs `f(first_index, chunk)` over `out` in chunks, in parallel for long arrays.
fn for_each_chunk<T: Send>(out: &mut [T], f: impl Fn(usize, &mut [T]) + Sync) {
    if out.len() >= PARALLEL_MIN && rayon::current_num_threads() > 1 {
        out.par_chunks_mut(CHUNK).enumerate().for_each(|(c, s)| f(c * CHUNK, s));
    } else {
        f(0, out);
    }
}

/// Müller et al. 2007, section 3.5: damp the velocities' deviation from the rigid motion of the
/// free particles (sums in a fixed order).
fn damp_velocities(model: &PbdModel, x: &[DVec3], v: &mut [DVec3], k: f64) {
    let w = &model.inv_mass;
    let (mut m, mut xm, mut vm) = (0.0, DVec3::ZERO, DVec3::ZERO);
    for i in 0..x.len() {
        if w[i] > 0.0 {
            let mi = model.particles[i].mass;
            m += mi;
            xm += mi * x[i];
            vm += mi * v[i];
        }
    }
    if !(m > 0.0) {
        return;
    }
    xm /= m;
    vm /= m;
    let mut l = DVec3::ZERO;
    let mut inertia = DMat3::ZERO;
    for i in 0..x.len() {
        if w[i] > 0.0 {
            let mi = model.particles[i].mass;
            let r = x[i] - xm;
            l += mi * r.cross(v[i]);
            // I += m (|r|^2 Id - r r^T)
            inertia += mi * (DMat3::from_diagonal(DVec3::splat(r.length_squared())) - outer(r, r));
        }
    }
    // A line of particles has a singular inertia: regularise by a relative 1e-9 of its trace.
    let reg = 1e-9 * (inertia.x_axis.x + inertia.y_axis.y + inertia.z_axis.z) + f64::MIN_POSITIVE;
    let omega = (inertia + DMat3::from_diagonal(DVec3::splat(reg))).inverse() * l;
    if !omega.is_finite() {
        return;
    }
    for i in 0..x.len() {
        if w[i] > 0.0 {
            let dv = vm + omega.cross(x[i] - xm) - v[i];
            v[i] += k * dv;
        }
    }
}

impl Solver for PbdSimulation {
    type State = State;
    type Error = PbdError;

    fn step(&mut self, state: &mut State, dt: f64) -> Result<StepReport, PbdError> {
        let info = self.advance(state, dt)?;
        let mut report = StepReport::at_time(state.t);
        report.iterations = info.iterations * info.substeps;
        let h = dt / info.substeps as f64;
        report.residual = Some(self.residual(&state.x, h));
        let elastic = if self.params.method == Method::Xpbd { self.elastic_energy(&state.x) } else { 0.0 };
        report.energy = Some(self.model.kinetic_and_gravity_energy(&state.x, &state.v) + elastic);
        report.linear_momentum = Some(self.model.linear_momentum(&state.v));
        report.angular_momentum = Some(self.model.angular_momentum(&state.x, &state.v));
        report.constraint_violation = Some(self.max_violation(&state.x));
        Ok(report)
    }
}
