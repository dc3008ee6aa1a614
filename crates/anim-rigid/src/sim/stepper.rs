//! The Lie-group steppers of [`RigidIntegrator`] and the [`RigidSimulation`] that runs them.
//! See [`crate::sim`] for the methods and their equations.

use anim_core::diagnostics::{Component, Element, Field, NonFinite, check_finite};
use anim_core::solver::{Solver, StepReport};

use crate::config;
use crate::dense::SquareMatrix;
use crate::model::Model;
use crate::sim::error::SimError;
use crate::sim::free_body::FreeBody;
use crate::sim::params::SimParams;
use crate::sim::state::RigidState;
use crate::sim::system::ArticulatedSystem;

/// The time steppers of [`RigidSimulation`] (see the table in [`crate::sim`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "kebab-case"))]
pub enum RigidIntegrator {
    /// `q₁ = q₀ ⊕ h v₀`, `v₁ = v₀ + h a(q₀, v₀)`: first order, energy grows.
    ExplicitEuler,
    /// `v₁ = v₀ + h a(q₀, v₀)`, `q₁ = q₀ ⊕ h v₁`: first order (symplectic Euler; symplectic
    /// only when the mass matrix is constant).
    SymplecticEuler,
    /// The commutator-free Lie-group RK4 (CF4): fourth order, classical RK4 on Euclidean trees.
    Rk4,
    /// The implicit midpoint rule on the manifold, solved by simplified Newton: second order,
    /// symmetric.
    ImplicitMidpoint,
    /// One free rigid body: the midpoint rule on the body angular momentum with a Cayley rotation
    /// step; conserves energy and angular momentum to rounding.
    FreeBodyMidpoint,
}

impl RigidIntegrator {
    /// Every stepper, in a fixed order.
    pub const ALL: [RigidIntegrator; 5] = [
        RigidIntegrator::ExplicitEuler,
        RigidIntegrator::SymplecticEuler,
        RigidIntegrator::Rk4,
        RigidIntegrator::ImplicitMidpoint,
        RigidIntegrator::FreeBodyMidpoint,
    ];

    /// Short name ("rk4", "implicit-midpoint", ...).
    #[must_use]
    pub const fn label(&self) -> &'static str {
        match self {
            RigidIntegrator::ExplicitEuler => "explicit-euler",
            RigidIntegrator::SymplecticEuler => "symplectic-euler",
            RigidIntegrator::Rk4 => "rk4",
            RigidIntegrator::ImplicitMidpoint => "implicit-midpoint",
            RigidIntegrator::FreeBodyMidpoint => "free-body-midpoint",
        }
    }

    /// Order of accuracy.
    #[must_use]
    pub const fn order(&self) -> u32 {
        match self {
            RigidIntegrator::ExplicitEuler | RigidIntegrator::SymplecticEuler => 1,
            RigidIntegrator::ImplicitMidpoint | RigidIntegrator::FreeBodyMidpoint => 2,
            RigidIntegrator::Rk4 => 4,
        }
    }

    /// The stepper by its [`label`](Self::label).
    #[must_use]
    pub fn from_label(label: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|i| i.label() == label)
    }
}

/// Scratch of the steppers, sized once.
#[derive(Debug, Clone, Default)]
struct Scratch {
    q: [Vec<f64>; 3],
    v: [Vec<f64>; 4],
    a: [Vec<f64>; 4],
    dq: Vec<f64>,
    q_new: Vec<f64>,
    v_new: Vec<f64>,
    r: Vec<f64>,
    r2: Vec<f64>,
    w: Vec<f64>,
    jac: SquareMatrix,
    pivots: Vec<usize>,
    /// Whether `jac` holds a factorised Newton matrix from an earlier step.
    jac_valid: bool,
    /// The step size `jac` was formed with.
    jac_h: f64,
    /// The Newton matrix and pivots as they were before the current step refactorised them,
    /// restored when the step fails (the matrix is part of the memory).
    jac_saved: SquareMatrix,
    pivots_saved: Vec<usize>,
    /// Whether `jac_saved` holds this step's starting matrix.
    saved: bool,
}

impl Scratch {
    fn new(nq: usize, nv: usize) -> Self {
        let zq = || vec![0.0; nq];
        let zv = || vec![0.0; nv];
        Self {
            q: [zq(), zq(), zq()],
            v: [zv(), zv(), zv(), zv()],
            a: [zv(), zv(), zv(), zv()],
            dq: zv(),
            q_new: zq(),
            v_new: zv(),
            r: zv(),
            r2: zv(),
            w: zv(),
            jac: SquareMatrix::zeros(nv),
            pivots: vec![0; nv],
            jac_valid: false,
            jac_h: 0.0,
            jac_saved: SquareMatrix::zeros(nv),
            pivots_saved: vec![0; nv],
            saved: false,
        }
    }
}

/// A tree (or one free body) with its forces and a Lie-group stepper: anim-core's
/// [`Solver`] for rigid bodies. Owns the model and every buffer; [`step`](Solver::step) does not
/// allocate.
///
/// ```
/// use anim_core::solver::Solver;
/// use anim_rigid::sim::{RigidIntegrator, RigidSimulation, SimParams};
/// use anim_rigid::{parse_urdf, UrdfOptions};
///
/// let urdf = r#"<robot name="p"><link name="base"/>
///   <link name="rod"><inertial><origin xyz="1 0 0"/><mass value="1"/>
///     <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
///   <joint name="hinge" type="continuous"><parent link="base"/><child link="rod"/>
///     <axis xyz="0 1 0"/></joint></robot>"#;
/// let model = parse_urdf(urdf, &UrdfOptions::default())?;
/// let mut sim = RigidSimulation::new(model, SimParams::default(), RigidIntegrator::ImplicitMidpoint)?;
/// let mut state = sim.initial_state(vec![0.0], vec![0.0])?;
/// let e0 = sim.energy(&state); // 0: at rest, at the height of the hinge
/// for _ in 0..1000 {
///     let report = sim.step(&mut state, 1e-3)?;
///     assert!(report.energy.is_some());
/// }
/// // It swung down and keeps its energy to within 1e-5 of the scale m g l = 9.81 J.
/// assert!(state.q[0] > 0.5);
/// assert!((sim.energy(&state) - e0).abs() < 1e-5 * 9.81);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone)]
pub struct RigidSimulation {
    system: ArticulatedSystem,
    integrator: RigidIntegrator,
    free_body: Option<FreeBody>,
    steps: u64,
    scratch: Scratch,
}

impl RigidSimulation {
    /// A simulation of `model` with the forces of `params`, stepped by `integrator`.
    ///
    /// # Errors
    /// [`SimError::BadParameter`] for bad parameters; [`SimError::Unsupported`] for
    /// [`RigidIntegrator::FreeBodyMidpoint`] on anything but one free body without torques.
    pub fn new(model: Model, params: SimParams, integrator: RigidIntegrator) -> Result<Self, SimError> {
        let free_body = match integrator {
            RigidIntegrator::FreeBodyMidpoint => Some(FreeBody::of(&model, &params)?),
            _ => None,
        };
        let scratch = Scratch::new(model.nq(), model.nv());
        let system = ArticulatedSystem::new(model, params)?;
        Ok(Self { system, integrator, free_body, steps: 0, scratch })
    }

    /// The system (model, data, forces).
    #[must_use]
    pub fn system(&self) -> &ArticulatedSystem {
        &self.system
    }

    /// The system, mutable (to change forces between steps).
    pub fn system_mut(&mut self) -> &mut ArticulatedSystem {
        &mut self.system
    }

    /// The model.
    #[must_use]
    pub fn model(&self) -> &Model {
        self.system.model()
    }

    /// The stepper.
    #[must_use]
    pub fn integrator(&self) -> RigidIntegrator {
        self.integrator
    }

    /// Steps taken so far.
    #[must_use]
    pub fn steps(&self) -> u64 {
        self.steps
    }

    /// What the simulation carries from one step to the next, for checkpoints: the step count
    /// and the implicit steppers' factorised Newton matrix, which is reused while it still
    /// converges (a resumed run that refactorised would take other Newton iterates).
    #[cfg(feature = "serde")]
    #[must_use]
    pub fn memory(&self) -> serde_json::Value {
        let s = &self.scratch;
        let jacobian =
            s.jac_valid.then(|| serde_json::json!({ "h": s.jac_h, "lu": s.jac, "pivots": s.pivots }));
        serde_json::json!({ "steps": self.steps, "newton_matrix": jacobian })
    }

    /// Restores what [`RigidSimulation::memory`] returned.
    ///
    /// # Errors
    /// [`SimError::Checkpoint`] when `memory` is malformed or its Newton matrix does not fit the
    /// model.
    #[cfg(feature = "serde")]
    pub fn restore_memory(&mut self, memory: &serde_json::Value) -> Result<(), SimError> {
        let bad = |m: String| SimError::Checkpoint(m);
        let steps = memory
            .get("steps")
            .and_then(serde_json::Value::as_u64)
            .ok_or_else(|| bad("no step count".into()))?;
        let jacobian = memory.get("newton_matrix").ok_or_else(|| bad("no Newton matrix entry".into()))?;
        if jacobian.is_null() {
            self.scratch.jac_valid = false;
        } else {
            let h = jacobian
                .get("h")
                .and_then(serde_json::Value::as_f64)
                .ok_or_else(|| bad("no step size".into()))?;
            let lu: SquareMatrix = jacobian
                .get("lu")
                .map(|v| serde_json::from_value(v.clone()))
                .ok_or_else(|| bad("no factorised matrix".into()))?
                .map_err(|e| bad(format!("Newton matrix: {e}")))?;
            let pivots: Vec<usize> = jacobian
                .get("pivots")
                .map(|v| serde_json::from_value(v.clone()))
                .ok_or_else(|| bad("no pivots".into()))?
                .map_err(|e| bad(format!("pivots: {e}")))?;
            if lu.n() != self.scratch.jac.n()
                || lu.as_slice().len() != lu.n() * lu.n()
                || pivots.len() != self.scratch.pivots.len()
                || pivots.iter().any(|&p| p >= lu.n())
            {
                return Err(bad(format!(
                    "Newton matrix of size {} for a model with {} velocity unknowns",
                    lu.n(),
                    self.scratch.jac.n()
                )));
            }
            self.scratch.jac = lu;
            self.scratch.pivots = pivots;
            self.scratch.jac_h = h;
            self.scratch.jac_valid = true;
        }
        self.steps = steps;
        Ok(())
    }

    /// A checked initial state: lengths match the model, entries are finite, quaternions are
    /// normalised.
    ///
    /// # Errors
    /// [`SimError::StateMismatch`] for wrong lengths, [`SimError::BadParameter`] for non-finite
    /// entries or a zero quaternion.
    pub fn initial_state(&self, q: Vec<f64>, v: Vec<f64>) -> Result<RigidState, SimError> {
        let model = self.model();
        if q.len() != model.nq() || v.len() != model.nv() {
            return Err(SimError::StateMismatch { q: q.len(), v: v.len(), nq: model.nq(), nv: model.nv() });
        }
        if let Some(x) = q.iter().chain(&v).find(|x| !x.is_finite()) {
            return Err(SimError::BadParameter {
                name: "initial state",
                value: x.to_string(),
                requirement: "entries must be finite",
            });
        }
        let mut q = q;
        for j in model.joints() {
            let start = match j.kind {
                crate::model::JointType::Spherical => j.idx_q,
                crate::model::JointType::Free => j.idx_q + 3,
                _ => continue,
            };
            if q[start..start + 4].iter().all(|x| *x == 0.0) {
                return Err(SimError::BadParameter {
                    name: "initial state",
                    value: format!("zero quaternion of joint '{}'", j.name),
                    requirement: "quaternions must be nonzero",
                });
            }
        }
        config::normalize(model, &mut q);
        Ok(RigidState::new(q, v))
    }

    /// The total energy of `state` ([`Energy::total`](crate::sim::Energy::total)).
    ///
    /// # Panics
    /// When the state does not match the model.
    #[must_use]
    #[track_caller]
    pub fn energy(&mut self, state: &RigidState) -> f64 {
        self.system.energy_of(&state.q, &state.v).total()
    }

    fn check(&self, state: &RigidState, dt: f64) -> Result<(), SimError> {
        if !(dt > 0.0 && dt.is_finite()) {
            return Err(SimError::BadTimeStep { dt });
        }
        let model = self.model();
        if state.q.len() != model.nq() || state.v.len() != model.nv() {
            return Err(SimError::StateMismatch {
                q: state.q.len(),
                v: state.v.len(),
                nq: model.nq(),
                nv: model.nv(),
            });
        }
        Ok(())
    }

    /// One step into `scratch.q_new`, `scratch.v_new`; returns (iterations, residual, ABA calls).
    fn advance(&mut self, state: &RigidState, h: f64) -> Result<(usize, f64), SimError> {
        let (q0, v0) = (&state.q, &state.v);
        let sys = &mut self.system;
        let s = &mut self.scratch;
        let model_nv = v0.len();
        match self.integrator {
            RigidIntegrator::ExplicitEuler => {
                sys.acceleration_into(q0, v0, &mut s.a[0]);
                config::integrate_into(sys.model(), q0, v0, h, &mut s.q_new);
                for k in 0..model_nv {
                    s.v_new[k] = v0[k] + h * s.a[0][k];
                }
                Ok((0, 0.0))
            }
            RigidIntegrator::SymplecticEuler => {
                sys.acceleration_into(q0, v0, &mut s.a[0]);
                for k in 0..model_nv {
                    s.v_new[k] = v0[k] + h * s.a[0][k];
                }
                config::integrate_into(sys.model(), q0, &s.v_new, h, &mut s.q_new);
                Ok((0, 0.0))
            }
            RigidIntegrator::Rk4 => {
                cf4(sys, s, q0, v0, h);
                Ok((0, 0.0))
            }
            RigidIntegrator::ImplicitMidpoint => {
                let newton = (sys.params().newton_tolerance, sys.params().max_newton_iterations);
                midpoint(sys, s, q0, v0, h, newton, self.steps)
            }
            RigidIntegrator::FreeBodyMidpoint => {
                let body = self.free_body.ok_or_else(|| SimError::Unsupported {
                    integrator: "free-body-midpoint",
                    reason: "no free body".into(),
                })?;
                body.step(sys.model().gravity(), q0, v0, h, &mut s.q_new, &mut s.v_new).map_err(|e| match e {
                    SimError::NewtonNotConverged { iterations, residual, .. } => {
                        SimError::NewtonNotConverged { step: self.steps, iterations, residual }
                    }
                    other => other,
                })
            }
        }
    }
}

/// The commutator-free RK4 (CF4) step into `s.q_new`, `s.v_new`.
fn cf4(sys: &mut ArticulatedSystem, s: &mut Scratch, q0: &[f64], v0: &[f64], h: f64) {
    let nv = v0.len();
    // Stage 1 at (q0, v0).
    s.v[0].copy_from_slice(v0);
    sys.acceleration_into(q0, v0, &mut s.a[0]);
    // Stage 2: Y₂ = y₀ ⊕ ½F₁.
    config::integrate_into(sys.model(), q0, v0, 0.5 * h, &mut s.q[0]);
    for k in 0..nv {
        s.v[1][k] = v0[k] + 0.5 * h * s.a[0][k];
    }
    sys.acceleration_into(&s.q[0], &s.v[1], &mut s.a[1]);
    // Stage 3: Y₃ = y₀ ⊕ ½F₂.
    config::integrate_into(sys.model(), q0, &s.v[1], 0.5 * h, &mut s.q[1]);
    for k in 0..nv {
        s.v[2][k] = v0[k] + 0.5 * h * s.a[1][k];
    }
    sys.acceleration_into(&s.q[1], &s.v[2], &mut s.a[2]);
    // Stage 4: Y₄ = Y₂ ⊕ (F₃ - ½F₁).
    for k in 0..nv {
        s.dq[k] = s.v[2][k] - 0.5 * s.v[0][k];
        s.v[3][k] = v0[k] + h * s.a[2][k];
    }
    let [q2, _, q4] = &mut s.q;
    config::integrate_into(sys.model(), q2, &s.dq, h, q4);
    sys.acceleration_into(&s.q[2], &s.v[3], &mut s.a[3]);
    // y₁ = (y₀ ⊕ (F₁/4 + F₂/6 + F₃/6 - F₄/12)) ⊕ (-F₁/12 + F₂/6 + F₃/6 + F₄/4).
    for k in 0..nv {
        s.dq[k] = 0.25 * s.v[0][k] + (s.v[1][k] + s.v[2][k]) / 6.0 - s.v[3][k] / 12.0;
        s.v_new[k] = v0[k] + h / 6.0 * (s.a[0][k] + 2.0 * (s.a[1][k] + s.a[2][k]) + s.a[3][k]);
    }
    config::integrate_into(sys.model(), q0, &s.dq, h, &mut s.q[0]);
    for k in 0..nv {
        s.dq[k] = -s.v[0][k] / 12.0 + (s.v[1][k] + s.v[2][k]) / 6.0 + 0.25 * s.v[3][k];
    }
    config::integrate_into(sys.model(), &s.q[0], &s.dq, h, &mut s.q_new);
}

/// The implicit-midpoint residual `r(w) = w - v₀ - h a(q₀ ⊕ ½h v̄, v̄)`, `v̄ = (v₀ + w)/2`, into
/// `out`; `qm` and `vbar` are scratch.
fn midpoint_residual(
    sys: &mut ArticulatedSystem,
    q0: &[f64],
    v0: &[f64],
    w: &[f64],
    h: f64,
    qm: &mut [f64],
    vbar: &mut [f64],
    acc: &mut [f64],
    out: &mut [f64],
) {
    for k in 0..v0.len() {
        vbar[k] = 0.5 * (v0[k] + w[k]);
    }
    config::integrate_into(sys.model(), q0, vbar, 0.5 * h, qm);
    sys.acceleration_into(qm, vbar, acc);
    for k in 0..v0.len() {
        out[k] = w[k] - v0[k] - h * acc[k];
    }
}

fn max_abs(x: &[f64]) -> f64 {
    x.iter().fold(0.0_f64, |m, v| m.max(v.abs()))
}

/// The implicit midpoint step by simplified Newton (see [`crate::sim`]).
fn midpoint(
    sys: &mut ArticulatedSystem,
    s: &mut Scratch,
    q0: &[f64],
    v0: &[f64],
    h: f64,
    (newton_tolerance, max_newton_iterations): (f64, usize),
    step: u64,
) -> Result<(usize, f64), SimError> {
    let nv = v0.len();
    // Explicit Euler predictor.
    sys.acceleration_into(q0, v0, &mut s.a[0]);
    for k in 0..nv {
        s.w[k] = v0[k] + h * s.a[0][k];
    }
    // The residual is a velocity change of size h |a|: measure it against that scale too.
    let tol = newton_tolerance * (1.0 + max_abs(v0) + h * max_abs(&s.a[0]));
    if s.jac_h != h {
        s.jac_valid = false;
    }
    let [qm, ..] = &mut s.q;
    let [vbar, v_pert, trial, _] = &mut s.v;
    let [a0, acc, ..] = &mut s.a;
    midpoint_residual(sys, q0, v0, &s.w, h, qm, vbar, acc, &mut s.r);
    let mut residual = max_abs(&s.r);
    let mut iterations = 0;
    // Whether the Jacobian was formed at an iterate of this step.
    let mut fresh = false;
    while !(residual <= tol) {
        if iterations >= max_newton_iterations {
            return Err(SimError::NewtonNotConverged { step, iterations, residual });
        }
        if !residual.is_finite() {
            return Err(non_finite_iterate(step, iterations, q0, v0, qm, &s.w, a0));
        }
        if !s.jac_valid {
            // Keep the matrix before this step first overwrites it (a copy of nv^2 entries,
            // next to the nv residual evaluations and the factorisation that follow).
            if !s.saved {
                s.jac_saved.copy_from(&s.jac);
                s.pivots_saved.copy_from_slice(&s.pivots);
                s.saved = true;
            }
            // Forward differences of the residual, column by column.
            for k in 0..nv {
                let delta = 1e-7 * (1.0 + s.w[k].abs());
                v_pert.copy_from_slice(&s.w);
                v_pert[k] += delta;
                midpoint_residual(sys, q0, v0, v_pert, h, qm, vbar, acc, &mut s.r2);
                for i in 0..nv {
                    s.jac[(i, k)] = (s.r2[i] - s.r[i]) / delta;
                }
            }
            if !s.jac.lu_factor(&mut s.pivots) {
                return Err(SimError::SingularNewtonMatrix { step });
            }
            s.jac_valid = true;
            s.jac_h = h;
            fresh = true;
        }
        s.dq.copy_from_slice(&s.r);
        s.jac.lu_solve(&s.pivots, &mut s.dq);
        for k in 0..nv {
            trial[k] = s.w[k] - s.dq[k];
        }
        midpoint_residual(sys, q0, v0, trial, h, qm, vbar, acc, &mut s.r2);
        let new_residual = max_abs(&s.r2);
        iterations += 1;
        let improved = new_residual < residual;
        if improved {
            std::mem::swap(&mut s.w, trial);
            std::mem::swap(&mut s.r, &mut s.r2);
        }
        if new_residual <= 0.25 * residual || new_residual <= tol {
            residual = new_residual;
            continue;
        }
        if fresh {
            // A Jacobian formed at this step's iterates no longer shrinks the residual: it sits
            // at the rounding floor of ABA. Accept within STAGNATION times the tolerance.
            residual = residual.min(new_residual);
            if residual <= STAGNATION * tol {
                break;
            }
            return Err(SimError::NewtonNotConverged { step, iterations, residual });
        }
        // Slow contraction with an old Jacobian: refresh it at the current iterate.
        s.jac_valid = false;
        if improved {
            residual = new_residual;
        }
    }
    for k in 0..nv {
        s.v_new[k] = s.w[k];
        s.dq[k] = 0.5 * (v0[k] + s.w[k]);
    }
    config::integrate_into(sys.model(), q0, &s.dq, h, &mut s.q_new);
    Ok((iterations, residual))
}

/// The first non-finite value behind a non-finite midpoint residual: the velocity iterate
/// (against `v0`), the midpoint configuration (against `q0`), or the acceleration at the start.
fn non_finite_iterate(
    step: u64,
    iterations: usize,
    q0: &[f64],
    v0: &[f64],
    qm: &[f64],
    w: &[f64],
    a0: &[f64],
) -> SimError {
    let nf = check_finite(step, Field::Velocity, w, v0)
        .and_then(|()| check_finite(step, Field::Position, qm, q0))
        .and_then(|()| check_finite(step, Field::Other("acceleration"), a0, &[]));
    match nf {
        Err(nf) => SimError::NonFinite(nf),
        // Finite iterate with a non-finite residual: the forces at the midpoint overflowed.
        Ok(()) => SimError::NewtonNotConverged { step, iterations, residual: f64::NAN },
    }
}

/// Renames a report on the flat `q` or `v` in terms of the joint that owns the entry: its index,
/// the coordinate within it and its whole last finite `q` or `v` block (from `state`, which the
/// failed step left as it was).
fn name_joint(model: &Model, nf: NonFinite, state: &RigidState) -> NonFinite {
    let by_q = nf.field == Field::Position;
    let old: &[f64] = match nf.field {
        Field::Position => &state.q,
        Field::Velocity => &state.v,
        _ => &[],
    };
    for (j, joint) in model.joints().iter().enumerate() {
        let (start, len) = if by_q { (joint.idx_q, joint.nq()) } else { (joint.idx_v, joint.nv()) };
        if (start..start + len).contains(&nf.dof) {
            let element = Element {
                kind: "joint",
                index: j,
                component: Component::Dof(u32::try_from(nf.dof - start).unwrap_or(u32::MAX)),
            };
            let block = old.get(start..start + len).unwrap_or(&[]);
            return nf.at_element("anim-rigid", element, block);
        }
    }
    NonFinite { origin: "anim-rigid", ..nf }
}

/// How far above the Newton tolerance a stagnating implicit-midpoint iteration may stop: the
/// residual cannot go below the rounding error of ABA, which grows with the conditioning of the
/// tree (a whipping chain reaches a few 1e-10 where the tolerance asks for 1e-11).
const STAGNATION: f64 = 1e3;

impl Solver for RigidSimulation {
    type State = RigidState;
    type Error = SimError;

    /// Advances `state` by `dt`; reports the Newton iterations (implicit steppers), the total
    /// energy and the world linear and angular momentum after the step.
    fn step(&mut self, state: &mut RigidState, dt: f64) -> Result<StepReport, SimError> {
        self.check(state, dt)?;
        // The memory this step may change: the Newton matrix (saved lazily before it is
        // refactorised), its validity and step size.
        let (jac_valid, jac_h) = (self.scratch.jac_valid, self.scratch.jac_h);
        self.scratch.saved = false;
        let result = self.advance(state, dt).and_then(|r| {
            check_finite(self.steps, Field::Position, &self.scratch.q_new, &state.q)?;
            check_finite(self.steps, Field::Velocity, &self.scratch.v_new, &state.v)?;
            Ok(r)
        });
        let (iterations, residual) = match result {
            Ok(r) => r,
            Err(e) => {
                let s = &mut self.scratch;
                (s.jac_valid, s.jac_h) = (jac_valid, jac_h);
                if s.saved {
                    std::mem::swap(&mut s.jac, &mut s.jac_saved);
                    std::mem::swap(&mut s.pivots, &mut s.pivots_saved);
                    s.saved = false;
                }
                return Err(match e {
                    SimError::NonFinite(nf) => SimError::NonFinite(name_joint(self.model(), nf, state)),
                    other => other,
                });
            }
        };
        std::mem::swap(&mut state.q, &mut self.scratch.q_new);
        std::mem::swap(&mut state.v, &mut self.scratch.v_new);
        state.t += dt;
        self.steps += 1;
        let mut report = StepReport::at_time(state.t);
        report.iterations = iterations;
        report.residual =
            matches!(self.integrator, RigidIntegrator::ImplicitMidpoint | RigidIntegrator::FreeBodyMidpoint)
                .then_some(residual);
        let energy = self.system.energy_of(&state.q, &state.v);
        report.energy = Some(energy.total());
        report.energy_parts = Some(anim_core::solver::EnergyParts {
            kinetic: energy.kinetic,
            gravity: energy.gravity,
            elastic: energy.limits,
        });
        let h = self.system.momentum_of(&state.q, &state.v);
        report.linear_momentum = Some(h.linear.to_array());
        report.angular_momentum = Some(h.angular.to_array());
        Ok(report)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenes::pendulum_chain_model;

    /// A 6-link chain swung by the implicit midpoint rule, which keeps its factorised Newton
    /// matrix across steps: a run continued from `memory()` must not refactorise.
    #[cfg(feature = "serde")]
    #[test]
    fn a_run_resumed_from_memory_is_bitwise_identical() {
        let model = pendulum_chain_model(&[1.0; 6], 0.3).unwrap();
        let new =
            || RigidSimulation::new(model.clone(), SimParams::default(), RigidIntegrator::ImplicitMidpoint);
        let mut sim = new().unwrap();
        let nq = sim.model().nq();
        let q0: Vec<f64> = (0..nq).map(|i| 0.3 + 0.1 * i as f64).collect();
        let mut state = sim.initial_state(q0, vec![0.0; sim.model().nv()]).unwrap();
        for _ in 0..6 {
            sim.step(&mut state, 2e-3).unwrap();
        }
        assert!(sim.scratch.jac_valid, "the Newton matrix is kept between steps");
        let memory = serde_json::to_string(&sim.memory()).unwrap();
        let saved = serde_json::to_string(&state).unwrap();
        for _ in 0..6 {
            sim.step(&mut state, 2e-3).unwrap();
        }
        let mut resumed_sim = new().unwrap();
        resumed_sim.restore_memory(&serde_json::from_str(&memory).unwrap()).unwrap();
        let mut resumed: RigidState = serde_json::from_str(&saved).unwrap();
        for _ in 0..6 {
            resumed_sim.step(&mut resumed, 2e-3).unwrap();
        }
        let same = |a: &[f64], b: &[f64]| a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits());
        assert!(same(&state.q, &resumed.q) && same(&state.v, &resumed.v));
        assert_eq!(resumed_sim.steps(), 12);

        // A memory whose Newton matrix does not fit the model is refused.
        let other = pendulum_chain_model(&[1.0; 3], 0.3).unwrap();
        let mut small =
            RigidSimulation::new(other, SimParams::default(), RigidIntegrator::ImplicitMidpoint).unwrap();
        let e = small.restore_memory(&serde_json::from_str(&memory).unwrap()).unwrap_err();
        assert!(e.to_string().contains("Newton matrix"), "{e}");
    }

    /// A torque of `f64::MAX` on a light rod (moment of inertia 0.003 kg m^2 about its hinge)
    /// gives an infinite acceleration: every stepper reports it by joint, and the state and the
    /// memory (including the implicit stepper's kept Newton matrix) are those before the step.
    #[test]
    fn an_overflowing_torque_is_reported_by_joint_and_the_step_undone() {
        let model = pendulum_chain_model(&[0.1], 0.3).unwrap();
        for integrator in [
            RigidIntegrator::ExplicitEuler,
            RigidIntegrator::SymplecticEuler,
            RigidIntegrator::Rk4,
            RigidIntegrator::ImplicitMidpoint,
        ] {
            let label = integrator.label();
            let mut sim = RigidSimulation::new(model.clone(), SimParams::default(), integrator).unwrap();
            let mut state = sim.initial_state(vec![0.4], vec![0.0]).unwrap();
            for _ in 0..10 {
                sim.step(&mut state, 1e-3).unwrap();
            }
            sim.system_mut().set_torque(&[f64::MAX]).unwrap();
            let before = state.clone();
            #[cfg(feature = "serde")]
            let memory = serde_json::to_string(&sim.memory()).unwrap();
            // A different step size makes the implicit stepper drop its kept matrix first.
            let err = sim.step(&mut state, 2e-3).unwrap_err();
            let bits = |s: &RigidState| {
                s.q.iter().chain(&s.v).chain([&s.t]).map(|x| x.to_bits()).collect::<Vec<_>>()
            };
            assert_eq!(bits(&state), bits(&before), "{label}: state changed");
            #[cfg(feature = "serde")]
            assert_eq!(serde_json::to_string(&sim.memory()).unwrap(), memory, "{label}: memory changed");
            assert_eq!(sim.steps(), 10);
            let msg = err.to_string();
            let SimError::NonFinite(nf) = err else { panic!("{label}: expected NonFinite, got {msg}") };
            assert_eq!(nf.step, 10, "{msg}");
            assert_eq!(nf.origin, "anim-rigid", "{msg}");
            assert_eq!(nf.element.kind, "joint", "{msg}");
            assert_eq!(nf.element.index, 1, "{msg}");
            assert_eq!(nf.element.component, Component::Dof(0), "{msg}");
            let old = if nf.field == Field::Position { &before.q } else { &before.v };
            assert_eq!(*nf.last_finite_element, **old, "{msg}");
            assert!(msg.starts_with("anim-rigid: step 10: non-finite "), "{msg}");
            assert!(msg.contains("of joint 1, coordinate 0"), "{msg}");
        }
    }

    /// A step of the implicit midpoint rule that refactorises its kept Newton matrix and then
    /// fails (here: one Newton iteration allowed) restores that matrix bit for bit.
    #[test]
    fn a_failed_implicit_step_restores_the_kept_newton_matrix() {
        let model = pendulum_chain_model(&[1.0; 3], 0.3).unwrap();
        let mut sim =
            RigidSimulation::new(model, SimParams::default(), RigidIntegrator::ImplicitMidpoint).unwrap();
        let mut state = sim.initial_state(vec![0.5, 0.3, 0.1], vec![0.0; 3]).unwrap();
        for _ in 0..10 {
            sim.step(&mut state, 1e-3).unwrap();
        }
        assert!(sim.scratch.jac_valid);
        let params = SimParams { max_newton_iterations: 1, ..sim.system().params().clone() };
        sim.system_mut().set_params(params).unwrap();
        let before = state.clone();
        #[cfg(feature = "serde")]
        let memory = serde_json::to_string(&sim.memory()).unwrap();
        let err = sim.step(&mut state, 5e-2).unwrap_err();
        assert!(matches!(err, SimError::NewtonNotConverged { step: 10, .. }), "{err}");
        assert!(sim.scratch.jac_h == 1e-3 && sim.scratch.jac_valid);
        #[cfg(feature = "serde")]
        assert_eq!(serde_json::to_string(&sim.memory()).unwrap(), memory, "the kept matrix changed");
        assert_eq!(state, before);
    }
}
