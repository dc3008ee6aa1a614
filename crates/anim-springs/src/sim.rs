//! A network with its integrator, as anim-core's [`Solver`]: steps, reports, and stops a run that
//! blows up before it produces NaN.
//!
//! An explicit method stepped beyond `dt ~ c sqrt(m / k)` grows an oscillation
//! geometrically: springs stretch to many times their rest length long before any value becomes
//! infinite. After every step [`SpringSimulation`] measures the largest stretch ratio
//! `|x_i - x_j| / l` ([`SpringNetwork::max_stretch`]); above the bound (default
//! [`DEFAULT_MAX_STRETCH`]) it restores the state from before the step and returns
//! [`SpringError::Diverged`] naming the step, the spring, its particles and the ratio. A NaN or
//! infinity that still appears (a stiffness so large that the force overflows, say) is caught by
//! the integrator before it touches the state and reported as [`SpringError::NonFinite`]: its
//! message begins with `anim-springs: step N:` and names the particle, the component `x`/`y`/`z`,
//! the value and the particle's whole last finite position or velocity. Either way the caller's
//! state is the last good one; after a non-finite step the integrator's memory is unchanged too.

use crate::network::SpringNetwork;
use anim_core::diagnostics::{Field, NonFinite};
use anim_core::integrate::{IntegrateError, Integrator, IntegratorKind, NewtonParams, State, StepInfo};
use anim_core::linalg::LinearSolverKind;
use anim_core::solver::{Solver, StepReport};

/// Default bound on `|x_i - x_j| / l` before a run counts as diverged.
pub const DEFAULT_MAX_STRETCH: f64 = 10.0;

/// A failed step of a [`SpringSimulation`]. The state is unchanged when one is returned.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SpringError {
    /// A checkpointed memory that does not belong to this simulation.
    #[error("checkpoint does not fit this simulation: {0}")]
    Checkpoint(String),
    /// The integrator parameters are invalid (a beta outside `[0, 1]`).
    #[error("invalid integrator: {0}")]
    BadIntegrator(String),
    /// A position, velocity or force became NaN or infinite; the step was not taken. The report
    /// names the particle (`element.index`), its component and its last finite value.
    #[error(transparent)]
    NonFinite(NonFinite),
    /// The integrator failed (Newton or linear solver failure, bad `dt`).
    #[error("step {step}: {source}")]
    Integrate {
        /// Step index (0-based count of completed steps).
        step: u64,
        /// The integrator's error (boxed: the error type stays small).
        source: Box<IntegrateError>,
    },
    /// A spring stretched beyond the bound: the run is diverging. The step was undone.
    #[error(
        "diverged at step {step}: spring {spring} (particles {i} and {j}) stretched to {ratio:.3e} times its rest length (bound {bound}); the step was undone"
    )]
    Diverged {
        /// Step index (0-based count of completed steps).
        step: u64,
        /// Spring index.
        spring: usize,
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

/// Copies `from` into `to` reusing `to`'s buffers (the derived `State::clone_from` would allocate).
fn copy_state(to: &mut State, from: &State) {
    to.t = from.t;
    to.x.clone_from(&from.x);
    to.v.clone_from(&from.v);
}

/// A [`SpringNetwork`] with its integrator and a divergence guard.
pub struct SpringSimulation {
    network: SpringNetwork,
    integrator: Box<dyn Integrator<SpringNetwork> + Send>,
    kind: IntegratorKind,
    linear: LinearSolverKind,
    max_stretch: f64,
    steps: u64,
    backup: State,
    last: StepInfo,
}

impl std::fmt::Debug for SpringSimulation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SpringSimulation")
            .field("integrator", &self.kind.label())
            .field("linear_solver", &self.linear)
            .field("particles", &self.network.num_particles())
            .field("springs", &self.network.num_springs())
            .field("steps", &self.steps)
            .finish()
    }
}

impl SpringSimulation {
    /// Couples `network` with the integrator `kind`; implicit kinds use `newton` and `linear`.
    ///
    /// # Errors
    /// [`SpringError::BadIntegrator`] for a beta-blend `beta` outside `[0, 1]`.
    pub fn new(
        network: SpringNetwork,
        kind: IntegratorKind,
        newton: NewtonParams,
        linear: LinearSolverKind,
    ) -> Result<Self, SpringError> {
        kind.validate().map_err(SpringError::BadIntegrator)?;
        use anim_core::integrate::SecondOrderSystem;
        let dof = network.dof();
        let integrator = kind.build_with::<SpringNetwork>(dof, newton, linear);
        Ok(Self {
            network,
            integrator,
            kind,
            linear,
            max_stretch: DEFAULT_MAX_STRETCH,
            steps: 0,
            backup: State::new(vec![0.0; dof], vec![0.0; dof]),
            last: StepInfo::default(),
        })
    }

    /// Sets the stretch ratio above which a step counts as diverged (default
    /// [`DEFAULT_MAX_STRETCH`]; `f64::INFINITY` disables the guard).
    #[must_use]
    pub fn with_max_stretch(mut self, bound: f64) -> Self {
        self.max_stretch = bound;
        self
    }

    /// The network.
    #[must_use]
    pub fn network(&self) -> &SpringNetwork {
        &self.network
    }

    /// The network, mutably (to change parameters between steps).
    pub fn network_mut(&mut self) -> &mut SpringNetwork {
        &mut self.network
    }

    /// The integrator kind.
    #[must_use]
    pub fn integrator_kind(&self) -> IntegratorKind {
        self.kind
    }

    /// The linear solver of implicit steps.
    #[must_use]
    pub fn linear_solver(&self) -> LinearSolverKind {
        self.linear
    }

    /// Steps completed.
    #[must_use]
    pub fn steps(&self) -> u64 {
        self.steps
    }

    /// What the integrator reported for the last successful step.
    #[must_use]
    pub fn last_step_info(&self) -> StepInfo {
        self.last
    }

    /// What the simulation carries from one step to the next (step count, the integrator's
    /// memory), for checkpoints: with the [`State`], it continues a run bit for bit.
    #[cfg(feature = "serde")]
    #[must_use]
    pub fn memory(&self) -> serde_json::Value {
        serde_json::json!({ "steps": self.steps, "integrator": self.integrator.memory() })
    }

    /// Restores what [`SpringSimulation::memory`] returned.
    ///
    /// # Errors
    /// [`SpringError::Checkpoint`] when `memory` is not a memory of this simulation's method.
    #[cfg(feature = "serde")]
    pub fn restore_memory(&mut self, memory: &serde_json::Value) -> Result<(), SpringError> {
        let steps = memory
            .get("steps")
            .and_then(serde_json::Value::as_u64)
            .ok_or_else(|| SpringError::Checkpoint("no step count".into()))?;
        let integrator =
            memory.get("integrator").ok_or_else(|| SpringError::Checkpoint("no integrator".into()))?;
        self.integrator.restore_memory(integrator).map_err(|e| SpringError::Checkpoint(e.to_string()))?;
        self.steps = steps;
        Ok(())
    }

    /// Advances by one step without computing the report's energy and momenta (the fast path).
    ///
    /// # Errors
    /// See [`SpringError`]; `state` is unchanged on error.
    pub fn advance(&mut self, state: &mut State, dt: f64) -> Result<StepInfo, SpringError> {
        let step = self.steps;
        copy_state(&mut self.backup, state);
        let info = self.integrator.step(&mut self.network, state, dt).map_err(|source| match source {
            // The integrator left `state` as it was: it holds the last finite values.
            IntegrateError::NonFinite(nf) => {
                let old: &[f64] = match nf.field {
                    Field::Position => &state.x,
                    Field::Velocity => &state.v,
                    _ => &[],
                };
                SpringError::NonFinite(NonFinite { step, ..nf }.in_elements(
                    "anim-springs",
                    "particle",
                    3,
                    old,
                ))
            }
            source => SpringError::Integrate { step, source: Box::new(source) },
        })?;
        if let Some(s) = self.network.max_stretch(&state.x)
            && !(s.ratio <= self.max_stretch)
        {
            copy_state(state, &self.backup);
            self.integrator.reset();
            let sp = self.network.springs()[s.spring];
            return Err(SpringError::Diverged {
                step,
                spring: s.spring,
                i: sp.i,
                j: sp.j,
                ratio: s.ratio,
                bound: self.max_stretch,
            });
        }
        self.steps += 1;
        self.last = info;
        Ok(info)
    }

    /// Advances `steps` steps of `dt`.
    ///
    /// # Errors
    /// The first failing step's error; `state` is then the state before that step.
    pub fn run(&mut self, state: &mut State, dt: f64, steps: usize) -> Result<(), SpringError> {
        for _ in 0..steps {
            self.advance(state, dt)?;
        }
        Ok(())
    }
}

impl Solver for SpringSimulation {
    type State = State;
    type Error = SpringError;

    fn step(&mut self, state: &mut State, dt: f64) -> Result<StepReport, SpringError> {
        let info = self.advance(state, dt)?;
        let mut report = StepReport::at_time(state.t);
        report.iterations = info.newton_iterations;
        report.residual = (info.newton_iterations > 0).then_some(info.residual);
        let parts = self.network.energy_parts(&state.x, &state.v);
        report.energy = Some(parts.total());
        report.energy_parts = Some(parts.split());
        report.linear_momentum = Some(self.network.linear_momentum(&state.v));
        report.angular_momentum = Some(self.network.angular_momentum(&state.x, &state.v));
        Ok(report)
    }
}
