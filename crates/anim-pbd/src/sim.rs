//! The simulation: the PBD loop (Müller et al. 2007) and XPBD loop (Macklin et al. 2016) over a
//! [`PbdModel`], with three constraint solvers, substepping, and a guard that stops a step which
//! produced a non-finite value or blew up, naming the step, the particle and the constraint.
//!
//! # The loop
//!
//! One step of `dt` is `substeps` substeps of `h = dt / substeps`, each the body of Müller et al.'s loop (Algorithm 1):
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
//! XPBD (Macklin et al. 2016) is the same loop with `lambda <- 0` before the iterations (line 4 of its
//! algorithm) and equations 17/18 in the projection; its prediction
//! `x~ = x^n + h v^n + h^2 M^-1 f_ext` is lines (5) and (7) together. Choosing many substeps with
//! one iteration each is the "small steps" scheme of Macklin et al. 2019.
//!
//! # Stages
//!
//! Each stage is a function of its own, and [`PbdSimulation`]'s substep is their sequence:
//!
//! | lines | stage | file |
//! | --- | --- | --- |
//! | (5), (7) | external forces and wind, predicted positions | `sim/predict.rs` |
//! | (6), (12)-(16) | velocity damping, velocity update, restitution | `sim/velocity.rs` |
//! | (8) | collision constraint generation | `sim/contacts.rs`, between bodies `sim/body_contacts.rs` |
//! | (9)-(11) | the constraint sweeps of the three solvers | `sim/solve.rs` |
//! | after the step | the non-finite and stretch guard, the commit | `sim/check.rs` |
//!
//! The settings are in `sim/params.rs` ([`PbdParams`], [`Method`], [`SolverKind`]), the errors in
//! `sim/error.rs` ([`PbdError`]), the buffers a step writes in `sim/scratch.rs` and the split of
//! loops over threads in `sim/parallel.rs`. Every result is bitwise identical for any number of
//! rayon threads: parallel loops write disjoint data and every sum runs in one fixed order.

mod body_contacts;
mod check;
mod colour_split;
mod contacts;
mod error;
mod parallel;
mod params;
mod predict;
mod scratch;
mod solve;
mod velocity;

pub use error::PbdError;
pub use params::{Method, PbdParams, SolverKind};

use crate::collide::Pose;
use crate::constraint::load;
use crate::model::PbdModel;
use crate::project::value;
use anim_core::glam::DVec3;
use anim_core::integrate::State;
use anim_core::solver::{Solver, StepReport};
use scratch::Data;
use std::sync::atomic::Ordering;

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
impl PbdSimulation {
    /// Couples `model` with a solver.
    ///
    /// # Errors
    /// [`PbdError::BadParameter`] for settings out of range.
    pub fn new(model: PbdModel, params: PbdParams) -> Result<Self, PbdError> {
        params.validate()?;
        let n = model.num_particles();
        let nb = model.bodies.len();
        let data = Data::new(&model);
        let mut sim =
            Self { model, params, data, steps: 0, targets: vec![None; nb], forces: vec![DVec3::ZERO; n] };
        solve::plan_sweeps(&sim.model, &sim.params, &mut sim.data);
        Ok(sim)
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
        solve::plan_sweeps(&self.model, &self.params, &mut self.data);
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
    #[cfg(feature = "serde")]
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
    #[cfg(feature = "serde")]
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
        check::load_state(&mut self.data, state);
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
        anim_core::par::on_worker(|| {
            for k in 0..s {
                contacts = self.substep(t0 + k as f64 * h, h, k, s);
            }
        });
        check::check(&self.model, &self.params, &self.data, self.steps, state)?;
        check::commit(&self.data, state, t0 + dt);
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

    /// One substep of length `h` starting at time `t` (substep `k` of `s`): the PBD loop body,
    /// stage by stage. Returns the number of contacts.
    fn substep(&mut self, t: f64, h: f64, k: usize, s: usize) -> usize {
        let (model, params, d) = (&self.model, &self.params, &mut self.data);
        predict::place_bodies(model, d, k, s);
        // (5) external forces: gravity, user forces, wind.
        predict::apply_external_forces(model, d, &self.forces, t, h);
        // (6) dampVelocities.
        if params.velocity_damping > 0.0 {
            velocity::damp_velocities(model, &d.x, &mut d.v, params.velocity_damping);
        }
        // (7) p <- x + h v.
        predict::predict_positions(d, h);
        // (8) generateCollisionConstraints.
        contacts::generate_contacts(model, d, params.contact_margin, h);
        body_contacts::generate_body_contacts(model, d, params.contact_margin);
        // (9)-(11) the solver iterations.
        solve::solve_constraints(model, params, d, h);
        // (12)-(15) v <- (p - x) / h, x <- p.
        velocity::update_velocities(model, d, h);
        // (16) velocityUpdate: restitution.
        velocity::restitution(model, d, h);
        d.contacts.len() + d.bodies.contacts.len()
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
        let (kinetic, gravity) = self.model.kinetic_and_gravity_parts(&state.x, &state.v);
        let parts = anim_core::solver::EnergyParts { kinetic, gravity, elastic };
        report.energy = Some(parts.total());
        report.energy_parts = Some(parts);
        report.linear_momentum = Some(self.model.linear_momentum(&state.v));
        report.angular_momentum = Some(self.model.angular_momentum(&state.x, &state.v));
        report.constraint_violation = Some(self.max_violation(&state.x));
        Ok(report)
    }
}
