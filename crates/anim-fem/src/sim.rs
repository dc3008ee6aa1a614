//! Time stepping and quasi-static solves of a [`FemModel`].
//!
//! - **Symplectic (semi-implicit) Euler** on the forces of Sifakis & Barbič 2012:
//!   `v_{n+1} = v_n + dt M^-1 (f_e(x_n) + f_d + f_ext)`, `x_{n+1} = x_n + dt v_{n+1}`, with the
//!   elastic forces from the batch algorithm (Sifakis & Barbič 2012, Algorithm 1) and the Rayleigh damping
//!   force `f_d = -gamma K(x_n) v_n` evaluated matrix-free per element. Contact projects
//!   penetrating vertices to the obstacle surface and removes their approaching normal velocity,
//!   then applies velocity-level Coulomb friction ([`crate::friction`]).
//!   With consistent mass, `M a = f` is solved by Jacobi-preconditioned conjugate gradients.
//! - **Backward Euler** by Newton's method on the incremental potential with a
//!   backtracking line search ([`newton`]), the stiffness assembled in parallel in
//!   a fixed order, and a choice of linear solver ([`LinearSolverChoice`]).
//!
//! Both steps, the quasi-static solve and the reports work on linear and 10-node bodies alike:
//! element loops go through the model ([`FemModel::element_forces`], the
//! [`ElasticBody`] implementation), and the masses, loads and boundary
//! conditions are per node.
//!
//! The explicit step is written here rather than through anim-core's `MechanicalSystem`
//! integrators because contact projection and kinematic vertices act on positions after the
//! update, and the implicit step because anim-core's backward Euler has no line search on an
//! energy and assumes a diagonal mass.
//!
//! Both steps leave the state (and the step count, the simulation's memory) unchanged when they
//! fail, and report NaN or infinity as [`FemError::NonFiniteState`] (the vertex, its component,
//! the value and the vertex's last finite position or velocity) or
//! [`FemError::NonFiniteElement`] (the element and its `det F`), with messages that begin with
//! `anim-fem: step N:`.

use crate::error::{FemError, StateField};
use crate::friction::{self, FrictionContact};
use crate::ldlt::SparseLdlt;
use crate::model::{FemModel, MassKind};
use crate::newton::{self, ElasticBody, NewtonData, NewtonInfo, NewtonSettings, Potential};
use anim_core::integrate::State;
use anim_core::linalg::{
    CsrMatrix, IterativeParams, LinearSolver, LinearSolverKind, SparseCholesky, SystemMatrix,
};
use anim_core::solver::{Solver, StepReport};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Elements per rayon task in the explicit force loop.
const ELEMENT_CHUNK: usize = 256;

/// The time integrator.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum TimeIntegrator {
    /// Symplectic (semi-implicit) Euler: explicit, conditionally stable (`dt` below the
    /// element's wave-crossing time).
    SymplecticEuler,
    /// Backward Euler by Newton on the incremental potential: unconditionally stable,
    /// dissipative.
    BackwardEuler,
}

impl TimeIntegrator {
    /// Name for reports.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            TimeIntegrator::SymplecticEuler => "symplectic-euler",
            TimeIntegrator::BackwardEuler => "backward-euler",
        }
    }
}

/// The linear solver inside Newton.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum LinearSolverChoice {
    /// Sparse Cholesky (faer, anim-core): needs a positive definite matrix (keep
    /// `project_psd` on).
    Cholesky,
    /// Sparse `L D L^T` (faer): symmetric indefinite allowed (no pivoting).
    Ldlt,
    /// Jacobi-preconditioned conjugate gradients on the assembled matrix (anim-core).
    JacobiPcg,
}

impl LinearSolverChoice {
    /// Every choice, in a fixed order.
    pub const ALL: [LinearSolverChoice; 3] =
        [LinearSolverChoice::Cholesky, LinearSolverChoice::Ldlt, LinearSolverChoice::JacobiPcg];

    /// Name for reports.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            LinearSolverChoice::Cholesky => "cholesky",
            LinearSolverChoice::Ldlt => "ldlt",
            LinearSolverChoice::JacobiPcg => "jacobi-pcg",
        }
    }

    /// Builds the solver; `cg` is the stopping rule of the iterative choice.
    #[must_use]
    pub fn build(self, cg: IterativeParams) -> Box<dyn LinearSolver> {
        match self {
            LinearSolverChoice::Cholesky => Box::new(SparseCholesky::new()),
            LinearSolverChoice::Ldlt => Box::new(SparseLdlt::new()),
            LinearSolverChoice::JacobiPcg => LinearSolverKind::JacobiPcgAssembled.build(cg),
        }
    }
}

/// Solver settings.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
#[non_exhaustive]
pub struct FemParams {
    /// Time integrator. Default backward Euler.
    pub integrator: TimeIntegrator,
    /// Linear solver inside Newton. Default Cholesky.
    pub linear_solver: LinearSolverChoice,
    /// Stiffness-proportional Rayleigh damping `gamma` (seconds), `f_d = -gamma K v`. Default 0.
    pub rayleigh_gamma: f64,
    /// Newton stops when the update's largest coordinate is at most this times the rest
    /// bounding-box diagonal. Default `1e-6`.
    pub newton_tolerance: f64,
    /// Newton iteration cap. Default 50.
    pub max_newton_iterations: usize,
    /// Relative residual of the conjugate-gradient solves. Default `1e-8`.
    pub cg_tolerance: f64,
    /// Iteration cap of the conjugate-gradient solves. Default 20000.
    pub cg_max_iterations: usize,
    /// Project every element's `dP/dF` to positive semi-definite (eigenvalue clamping) before
    /// assembly. Default true.
    pub project_psd: bool,
    /// Compute total energy in every step report (one more pass over the elements). Default true.
    pub report_energy: bool,
    /// Smoothing velocity `eps_v` (m/s) of the implicit friction ([`crate::friction`]): relative
    /// tangential speeds below it are treated as sticking, so a body held by static friction
    /// creeps at most at this speed. Only used with obstacles of non-zero friction. Default
    /// `1e-3` ([`friction::DEFAULT_EPS_V`]).
    pub friction_eps_v: f64,
}

impl Default for FemParams {
    fn default() -> Self {
        Self {
            integrator: TimeIntegrator::BackwardEuler,
            linear_solver: LinearSolverChoice::Cholesky,
            rayleigh_gamma: 0.0,
            newton_tolerance: 1e-6,
            max_newton_iterations: 50,
            cg_tolerance: 1e-8,
            cg_max_iterations: 20000,
            project_psd: true,
            report_energy: true,
            friction_eps_v: friction::DEFAULT_EPS_V,
        }
    }
}

impl FemParams {
    /// Default settings with the given integrator.
    #[must_use]
    pub fn new(integrator: TimeIntegrator) -> Self {
        Self { integrator, ..Self::default() }
    }

    /// With the given linear solver.
    #[must_use]
    pub fn with_linear_solver(mut self, s: LinearSolverChoice) -> Self {
        self.linear_solver = s;
        self
    }

    /// With Rayleigh damping `gamma`.
    #[must_use]
    pub fn with_rayleigh(mut self, gamma: f64) -> Self {
        self.rayleigh_gamma = gamma;
        self
    }

    /// With the Newton tolerance.
    #[must_use]
    pub fn with_newton_tolerance(mut self, tol: f64) -> Self {
        self.newton_tolerance = tol;
        self
    }

    /// With or without the positive semi-definite projection.
    #[must_use]
    pub fn with_projection(mut self, project: bool) -> Self {
        self.project_psd = project;
        self
    }

    /// With or without energy in the step reports.
    #[must_use]
    pub fn with_energy_report(mut self, report: bool) -> Self {
        self.report_energy = report;
        self
    }

    /// With the friction smoothing velocity `eps_v` (m/s).
    #[must_use]
    pub fn with_friction_eps_v(mut self, eps_v: f64) -> Self {
        self.friction_eps_v = eps_v;
        self
    }

    fn check(&self) -> Result<(), FemError> {
        let bad = |name, value, reason| Err(FemError::BadParameter { name, value, reason });
        if !(self.rayleigh_gamma >= 0.0) || !self.rayleigh_gamma.is_finite() {
            return bad("rayleigh_gamma", self.rayleigh_gamma, "must be finite and >= 0");
        }
        if !(self.newton_tolerance > 0.0) || !self.newton_tolerance.is_finite() {
            return bad("newton_tolerance", self.newton_tolerance, "must be finite and > 0");
        }
        if self.max_newton_iterations == 0 {
            return bad("max_newton_iterations", 0.0, "must be >= 1");
        }
        if !(self.cg_tolerance > 0.0) {
            return bad("cg_tolerance", self.cg_tolerance, "must be > 0");
        }
        if !(self.friction_eps_v > 0.0) || !self.friction_eps_v.is_finite() {
            return bad("friction_eps_v", self.friction_eps_v, "must be finite and > 0");
        }
        Ok(())
    }
}

/// A finite element simulation: the model, the settings and every scratch buffer.
pub struct FemSimulation {
    model: FemModel,
    params: FemParams,
    data: NewtonData,
    solver: Box<dyn LinearSolver>,
    mass_solver: Box<dyn LinearSolver>,
    /// The consistent mass with fixed rows and columns replaced by the identity.
    mass_fixed: CsrMatrix,
    elem_forces: Vec<f64>,
    force: Vec<f64>,
    external: Vec<f64>,
    acc: Vec<f64>,
    xn: Vec<f64>,
    xhat: Vec<f64>,
    saved_x: Vec<f64>,
    saved_v: Vec<f64>,
    /// Lagged friction contacts of the implicit step (capacity: vertices x frictional obstacles).
    friction_contacts: Vec<FrictionContact>,
    tolerance: f64,
    steps: u64,
}

impl std::fmt::Debug for FemSimulation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("FemSimulation")
            .field("vertices", &self.model.vertices())
            .field("elements", &self.model.elements())
            .field("params", &self.params)
            .field("steps", &self.steps)
            .finish()
    }
}

impl FemSimulation {
    /// A simulation of `model` with `params`.
    ///
    /// # Errors
    /// [`FemError::BadParameter`] for invalid settings.
    pub fn new(model: FemModel, params: FemParams) -> Result<Self, FemError> {
        params.check()?;
        let n = 3 * model.vertices();
        let data = NewtonData::new(model.assembly(), model.elements());
        let cg = IterativeParams::new(params.cg_tolerance, params.cg_max_iterations);
        let solver = params.linear_solver.build(cg);
        let mut mass_fixed = model.consistent_mass().clone();
        {
            let fixed = model.fixed();
            let rows = model.assembly().entry_rows().to_vec();
            let cols = mass_fixed.col_idx().to_vec();
            for (p, v) in mass_fixed.values_mut().iter_mut().enumerate() {
                let (r, c) = (rows[p] as usize, cols[p]);
                if fixed[r] || fixed[c] {
                    *v = if r == c { 1.0 } else { 0.0 };
                }
            }
        }
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for p in &model.mesh().positions {
            for c in 0..3 {
                lo[c] = lo[c].min(p[c]);
                hi[c] = hi[c].max(p[c]);
            }
        }
        let diag = ((hi[0] - lo[0]).powi(2) + (hi[1] - lo[1]).powi(2) + (hi[2] - lo[2]).powi(2)).sqrt();
        Ok(Self {
            tolerance: params.newton_tolerance * diag,
            data,
            solver,
            mass_solver: LinearSolverKind::JacobiPcgAssembled.build(IterativeParams::new(1e-12, 1000)),
            mass_fixed,
            elem_forces: vec![0.0; 3 * model.order().nodes() * model.elements()],
            force: vec![0.0; n],
            external: vec![0.0; n],
            acc: vec![0.0; n],
            xn: vec![0.0; n],
            xhat: vec![0.0; n],
            saved_x: vec![0.0; n],
            saved_v: vec![0.0; n],
            friction_contacts: Vec::with_capacity(model.vertices() * model.colliders().frictional()),
            model,
            params,
            steps: 0,
        })
    }

    /// The model.
    #[must_use]
    pub fn model(&self) -> &FemModel {
        &self.model
    }

    /// The settings.
    #[must_use]
    pub fn params(&self) -> &FemParams {
        &self.params
    }

    /// Replaces the settings (rebuilding the linear solver).
    ///
    /// # Errors
    /// [`FemError::BadParameter`] for invalid settings.
    pub fn set_params(&mut self, params: FemParams) -> Result<(), FemError> {
        params.check()?;
        let diag = self.tolerance / self.params.newton_tolerance;
        self.solver =
            params.linear_solver.build(IterativeParams::new(params.cg_tolerance, params.cg_max_iterations));
        self.tolerance = params.newton_tolerance * diag;
        self.params = params;
        Ok(())
    }

    /// Steps taken so far.
    #[must_use]
    pub fn steps(&self) -> u64 {
        self.steps
    }

    /// What the simulation carries from one step to the next (only the step count: every step
    /// starts its Newton solve from the state and assembles `K` afresh), for checkpoints.
    #[must_use]
    pub fn memory(&self) -> serde_json::Value {
        serde_json::json!({ "steps": self.steps })
    }

    /// Restores what [`FemSimulation::memory`] returned.
    ///
    /// # Errors
    /// [`FemError::Checkpoint`] when `memory` has no step count.
    pub fn restore_memory(&mut self, memory: &serde_json::Value) -> Result<(), FemError> {
        self.steps = memory
            .get("steps")
            .and_then(serde_json::Value::as_u64)
            .ok_or_else(|| FemError::Checkpoint("no step count".into()))?;
        Ok(())
    }

    /// The initial state: rest positions, zero velocity, `t = 0`.
    #[must_use]
    pub fn rest_state(&self) -> State {
        let x = self.model.rest_positions();
        let v = vec![0.0; x.len()];
        State { t: 0.0, x, v }
    }

    fn check_state(&self, state: &State) -> Result<(), FemError> {
        let expected = 3 * self.model.vertices();
        if state.x.len() != expected {
            return Err(FemError::StateSize { what: "position", found: state.x.len(), expected });
        }
        if state.v.len() != expected {
            return Err(FemError::StateSize { what: "velocity", found: state.v.len(), expected });
        }
        Ok(())
    }

    /// The elastic forces at `x` into `self.force` (Sifakis & Barbič 2012, Algorithm 1: per-element
    /// `H = -W P Dm^-T`, then an ordered gather), plus `-gamma K(x) v` when damping is on.
    fn elastic_forces(&mut self, x: &[f64], v: &[f64]) -> Result<(), FemError> {
        let model = &self.model;
        let gamma = self.params.rayleigh_gamma;
        let damping = if gamma > 0.0 { Some((gamma, v)) } else { None };
        let ne = 3 * model.order().nodes();
        self.elem_forces.par_chunks_mut(ne * ELEMENT_CHUNK).enumerate().for_each(|(c, out)| {
            for (k, o) in out.chunks_mut(ne).enumerate() {
                model.element_forces_damped(c * ELEMENT_CHUNK + k, x, damping, o);
            }
        });
        if let Some(p) = anim_core::diagnostics::first_non_finite(&self.elem_forces) {
            let element = p / ne;
            return Err(FemError::NonFiniteElement {
                step: self.steps,
                element,
                det_f: model.det_f(element, x),
            });
        }
        model.assembly().gather_vector(&self.elem_forces, &mut self.force);
        Ok(())
    }

    /// Writes the elastic forces at positions `x` (zero velocity) into `out`.
    ///
    /// # Errors
    /// [`FemError::NonFiniteElement`] when an element's stress is not finite.
    pub fn internal_forces(&mut self, x: &[f64], out: &mut [f64]) -> Result<(), FemError> {
        let gamma = self.params.rayleigh_gamma;
        self.params.rayleigh_gamma = 0.0;
        let r = self.elastic_forces(x, x);
        self.params.rayleigh_gamma = gamma;
        r?;
        out.copy_from_slice(&self.force);
        Ok(())
    }

    fn explicit_step(&mut self, state: &mut State, dt: f64) -> Result<usize, FemError> {
        let x = std::mem::take(&mut state.x);
        let r = self.elastic_forces(&x, &state.v);
        state.x = x;
        r?;
        self.model.external_force(1.0, &mut self.external);
        for ((a, f), e) in self.acc.iter_mut().zip(&self.force).zip(&self.external) {
            *a = f + e;
        }
        let fixed = self.model.fixed();
        let mut iterations = 0;
        match self.model.mass_kind() {
            MassKind::Lumped => {
                for (d, a) in self.acc.iter_mut().enumerate() {
                    *a = if fixed[d] { 0.0 } else { *a / self.model.lumped_mass()[d / 3] };
                }
            }
            MassKind::Consistent => {
                for (d, a) in self.acc.iter_mut().enumerate() {
                    if fixed[d] {
                        *a = 0.0;
                    }
                }
                self.force.copy_from_slice(&self.acc);
                let info = self
                    .mass_solver
                    .solve(SystemMatrix::Csr(&self.mass_fixed), &self.force, &mut self.acc)
                    .map_err(|source| FemError::LinearSolve { step: self.steps, iteration: 0, source })?;
                iterations = info.iterations;
            }
        }
        self.xn.copy_from_slice(&state.x);
        for d in 0..state.x.len() {
            if !fixed[d] {
                state.v[d] += dt * self.acc[d];
                state.x[d] += dt * state.v[d];
            }
        }
        self.model.apply_kinematic(state.t + dt, &mut state.x);
        for d in 0..state.x.len() {
            if fixed[d] {
                state.v[d] = (state.x[d] - self.xn[d]) / dt;
            }
        }
        self.project_contacts(state, dt);
        Ok(iterations)
    }

    fn project_contacts(&self, state: &mut State, dt: f64) {
        let fixed = self.model.fixed();
        for (o, mu) in self.model.colliders().iter() {
            for i in 0..self.model.vertices() {
                if fixed[3 * i] && fixed[3 * i + 1] && fixed[3 * i + 2] {
                    continue;
                }
                let p = [state.x[3 * i], state.x[3 * i + 1], state.x[3 * i + 2]];
                let Some((phi, n)) = o.distance(p) else { continue };
                if phi < 0.0 {
                    let vn: f64 = (0..3).map(|c| state.v[3 * i + c] * n[c]).sum();
                    for c in 0..3 {
                        if !fixed[3 * i + c] {
                            state.x[3 * i + c] -= phi * n[c];
                            if vn < 0.0 {
                                state.v[3 * i + c] -= vn * n[c];
                            }
                        }
                    }
                    if vn < 0.0 && mu > 0.0 {
                        let dv = friction::coulomb_velocity(
                            &mut state.v[3 * i..3 * i + 3],
                            n,
                            -vn,
                            mu,
                            &fixed[3 * i..3 * i + 3],
                        );
                        for c in 0..3 {
                            state.x[3 * i + c] += dt * dv[c];
                        }
                    }
                }
            }
        }
    }

    fn implicit_step(&mut self, state: &mut State, dt: f64) -> Result<NewtonInfo, FemError> {
        let n = state.x.len();
        self.xn.copy_from_slice(&state.x);
        for d in 0..n {
            self.xhat[d] = state.x[d] + dt * state.v[d];
        }
        self.model.external_force(1.0, &mut self.external);
        friction::lagged_contacts(
            self.model.colliders(),
            self.model.contact_stiffness(),
            self.params.friction_eps_v * dt,
            &self.xn,
            self.model.fixed(),
            &mut self.friction_contacts,
        );
        let gamma = self.params.rayleigh_gamma;
        if gamma > 0.0 {
            self.data.assemble_reference_stiffness(&self.model, self.model.assembly(), &self.xn);
        }
        // Initial guess: the inertial predictor, fixed coordinates at their targets; fall back
        // to the current positions when the predictor inverts an element the material cannot,
        // and start from them when friction contacts are active (as IPC does: from the
        // predictor, contact vertices start deep in the sliding regime, where Newton overshoots).
        let fixed = self.model.fixed();
        let mut x = std::mem::take(&mut state.x);
        for d in 0..n {
            if !fixed[d] {
                x[d] = self.xhat[d];
            }
        }
        self.model.apply_kinematic(state.t + dt, &mut x);
        if !self.friction_contacts.is_empty() || !(self.model.elastic_energy(&x).is_finite()) {
            for d in 0..n {
                if !fixed[d] {
                    x[d] = self.xn[d];
                }
            }
        }
        let pot = Potential {
            inertia: Some((1.0 / (dt * dt), &self.xhat)),
            lumped_mass: self.model.lumped_mass(),
            consistent_mass: match self.model.mass_kind() {
                MassKind::Lumped => None,
                MassKind::Consistent => Some(self.model.consistent_mass()),
            },
            damping: if gamma > 0.0 { Some((gamma / dt, &self.xn)) } else { None },
            external: &self.external,
            obstacles: self.model.colliders(),
            contact_stiffness: self.model.contact_stiffness(),
            friction: &self.friction_contacts,
            fixed,
            project: self.params.project_psd,
        };
        let settings = NewtonSettings {
            tolerance: self.tolerance,
            max_iterations: self.params.max_newton_iterations,
            step: self.steps,
        };
        let result = newton::minimize(
            &self.model,
            self.model.assembly(),
            &pot,
            &mut x,
            &mut self.data,
            self.solver.as_mut(),
            settings,
        );
        state.x = x;
        let info = match result {
            Ok(info) => info,
            Err(e) => {
                state.x.copy_from_slice(&self.xn);
                return Err(e);
            }
        };
        for d in 0..n {
            state.v[d] = (state.x[d] - self.xn[d]) / dt;
        }
        Ok(info)
    }

    /// Static equilibrium under the external loads (gravity, nodal forces), applied in
    /// `load_steps` equal increments, each solved by Newton from the previous one. `x` holds
    /// the initial guess (fixed coordinates at their values) and receives the solution.
    ///
    /// # Errors
    /// As the implicit step.
    pub fn solve_static(&mut self, x: &mut [f64], load_steps: usize) -> Result<NewtonInfo, FemError> {
        let mut total = NewtonInfo::default();
        let steps = load_steps.max(1);
        for s in 1..=steps {
            self.model.external_force(s as f64 / steps as f64, &mut self.external);
            let pot = Potential {
                inertia: None,
                lumped_mass: self.model.lumped_mass(),
                consistent_mass: None,
                damping: None,
                external: &self.external,
                obstacles: self.model.colliders(),
                contact_stiffness: self.model.contact_stiffness(),
                friction: &[],
                fixed: self.model.fixed(),
                project: self.params.project_psd,
            };
            let settings = NewtonSettings {
                tolerance: self.tolerance,
                max_iterations: self.params.max_newton_iterations,
                step: s as u64,
            };
            let info = newton::minimize(
                &self.model,
                self.model.assembly(),
                &pot,
                x,
                &mut self.data,
                self.solver.as_mut(),
                settings,
            )?;
            total.iterations += info.iterations;
            total.linear_iterations += info.linear_iterations;
            total.last_update = info.last_update;
            total.energy = info.energy;
        }
        Ok(total)
    }

    /// Kinetic energy `1/2 v^T M v`.
    #[must_use]
    pub fn kinetic_energy(&self, v: &[f64]) -> f64 {
        match self.model.mass_kind() {
            MassKind::Lumped => v
                .chunks(3)
                .zip(self.model.lumped_mass())
                .map(|(vi, m)| 0.5 * m * (vi[0] * vi[0] + vi[1] * vi[1] + vi[2] * vi[2]))
                .sum(),
            MassKind::Consistent => {
                let mut mv = vec![0.0; v.len()];
                self.model.consistent_mass().mul_vec(v, &mut mv);
                0.5 * anim_core::linalg::dot(v, &mv)
            }
        }
    }

    /// Total energy: kinetic + elastic + gravitational and load potential.
    #[must_use]
    pub fn total_energy(&self, state: &State) -> f64 {
        let mut ext = vec![0.0; state.x.len()];
        self.model.external_force(1.0, &mut ext);
        self.kinetic_energy(&state.v) + self.model.elastic_energy(&state.x)
            - anim_core::linalg::dot(&ext, &state.x)
    }

    /// Total energy without allocating: uses the external force of the step just taken and
    /// the acceleration buffer as scratch.
    fn step_energy(&mut self, state: &State) -> anim_core::solver::EnergyParts {
        let kinetic = match self.model.mass_kind() {
            MassKind::Lumped => self.kinetic_energy(&state.v),
            MassKind::Consistent => {
                self.model.consistent_mass().mul_vec(&state.v, &mut self.acc);
                0.5 * anim_core::linalg::dot(&state.v, &self.acc)
            }
        };
        anim_core::solver::EnergyParts {
            kinetic,
            // The potential of the constant external load (gravity and any applied force).
            gravity: -anim_core::linalg::dot(&self.external, &state.x),
            elastic: self.model.elastic_energy(&state.x),
        }
    }

    /// Linear and angular momentum (about the origin): `sum_i m_i v_i` and
    /// `sum_i x_i x m_i v_i` with lumped mass, `sum_i (M v)_i` and `sum_i x_i x (M v)_i` with
    /// consistent mass (the quantities the equations of motion conserve under internal forces).
    #[must_use]
    pub fn momentum(&self, state: &State) -> ([f64; 3], [f64; 3]) {
        let mut p = [0.0; 3];
        let mut l = [0.0; 3];
        let consistent = self.model.mass_kind() == MassKind::Consistent;
        let mass = self.model.consistent_mass();
        for (i, m) in self.model.lumped_mass().iter().enumerate() {
            let x = &state.x[3 * i..3 * i + 3];
            if consistent {
                let mut mv = [0.0; 3];
                for (c, out) in mv.iter_mut().enumerate() {
                    let (cols, vals) = mass.row(3 * i + c);
                    *out = cols.iter().zip(vals).map(|(&j, &a)| a * state.v[j]).sum();
                }
                for c in 0..3 {
                    p[c] += mv[c];
                }
                l[0] += x[1] * mv[2] - x[2] * mv[1];
                l[1] += x[2] * mv[0] - x[0] * mv[2];
                l[2] += x[0] * mv[1] - x[1] * mv[0];
            } else {
                let v = &state.v[3 * i..3 * i + 3];
                for c in 0..3 {
                    p[c] += m * v[c];
                }
                l[0] += m * (x[1] * v[2] - x[2] * v[1]);
                l[1] += m * (x[2] * v[0] - x[0] * v[2]);
                l[2] += m * (x[0] * v[1] - x[1] * v[0]);
            }
        }
        (p, l)
    }

    /// Advances `state` by `dt` and reports what the step did.
    ///
    /// # Errors
    /// [`FemError`]: bad `dt` or state size, divergence (naming the vertex or element), a failed
    /// Newton or linear solve. The state is unchanged on error.
    pub fn advance(&mut self, state: &mut State, dt: f64) -> Result<StepReport, FemError> {
        if !(dt > 0.0) || !dt.is_finite() {
            return Err(FemError::BadParameter { name: "dt", value: dt, reason: "must be finite and > 0" });
        }
        self.check_state(state)?;
        self.saved_x.copy_from_slice(&state.x);
        self.saved_v.copy_from_slice(&state.v);
        let result = match self.params.integrator {
            TimeIntegrator::SymplecticEuler => self.explicit_step(state, dt).map(|it| (0, it, None)),
            TimeIntegrator::BackwardEuler => self
                .implicit_step(state, dt)
                .map(|i| (i.iterations, i.linear_iterations, Some(i.last_update))),
        };
        let restore = |sim: &Self, state: &mut State| {
            state.x.copy_from_slice(&sim.saved_x);
            state.v.copy_from_slice(&sim.saved_v);
        };
        let (newton_iterations, linear_iterations, residual) = match result {
            Ok(r) => r,
            Err(e) => {
                restore(self, state);
                return Err(e);
            }
        };
        for field in [StateField::Position, StateField::Velocity] {
            let values = if field == StateField::Position { &state.x } else { &state.v };
            if let Some(d) = anim_core::diagnostics::first_non_finite(values) {
                let value = values[d];
                restore(self, state);
                let old = if field == StateField::Position { &state.x } else { &state.v };
                let vertex = d / 3;
                return Err(FemError::NonFiniteState {
                    step: self.steps,
                    field,
                    vertex,
                    component: d % 3,
                    value,
                    last_finite: [old[3 * vertex], old[3 * vertex + 1], old[3 * vertex + 2]],
                });
            }
        }
        state.t += dt;
        self.steps += 1;
        let (p, l) = self.momentum(state);
        let mut report = StepReport::at_time(state.t);
        report.iterations = if newton_iterations > 0 { newton_iterations } else { linear_iterations };
        report.residual = residual;
        report.energy_parts = self.params.report_energy.then(|| self.step_energy(state));
        report.energy = report.energy_parts.map(|e| e.total());
        report.linear_momentum = Some(p);
        report.angular_momentum = Some(l);
        Ok(report)
    }
}

impl Solver for FemSimulation {
    type State = State;
    type Error = FemError;

    fn step(&mut self, state: &mut State, dt: f64) -> Result<StepReport, FemError> {
        self.advance(state, dt)
    }
}
