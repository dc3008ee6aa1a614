//! Time integration of second-order systems `x'' = M^-1 f(t, x, v)`.
//!
//! Springs, FEM bodies and articulated rigid bodies are all second-order systems. This module is
//! the one place their time integrators live; no crate writes its own copy.
//!
//! # The two system traits
//!
//! - [`SecondOrderSystem`]: a system known by its acceleration `a(t, x, v)`. Enough for every
//!   explicit method. An articulated robot (acceleration by ABA) implements only this.
//! - [`MechanicalSystem`]: a system with a diagonal (lumped) mass, a force `f(t, x, v)` and the
//!   force Jacobians `K = df/dx` and `D = df/dv` (matrix-free, optionally assembled). Needed by the
//!   implicit methods, which solve `(M - c_v D - c_x K) dv = r` by Newton's method with any
//!   [`LinearSolver`](crate::linalg::LinearSolver). A zero inverse mass marks a fixed (kinematic)
//!   degree of freedom: it keeps its velocity.
//!
//! # The integrators
//!
//! | integrator | update | order | notes |
//! | --- | --- | --- | --- |
//! | [`ExplicitEuler`] | `v1 = v0 + h a(x0)`, `x1 = x0 + h v0` | 1 | energy grows on oscillators |
//! | [`SymplecticEuler`] | `v1 = v0 + h a(x0)`, `x1 = x0 + h v1` | 1 | symplectic, bounded energy error |
//! | [`BetaBlend`] | `(M - beta h^2 K) v1 = M v0 + h f(x0)` (linearised), solved by Newton on `M(v1 - v0) = h f(x0 + beta h v1)`, `x1 = x0 + h v1` | 1 | `beta = 0` is symplectic Euler, `beta = 1` backward Euler |
//! | [`PositionVerlet`] | `x1 = 2 x0 - x_-1 + h^2 a(x0)` | 2 | Stormer's form; keeps the previous position |
//! | [`Leapfrog`] | `v_{1/2} = v_{-1/2} + h a(x0)`, `x1 = x0 + h v_{1/2}` | 2 | keeps the staggered velocity |
//! | [`VelocityVerlet`] | half kick, drift, half kick | 2 | one force evaluation per step |
//! | [`ImplicitMidpoint`] | `v1 = v0 + h a((x0+x1)/2, (v0+v1)/2)`, `x1 = x0 + h (v0+v1)/2` | 2 | symplectic, implicit (Newton) |
//! | [`Rk4`] | classical Runge-Kutta | 4 | not symplectic; the high-order reference |
//!
//! The beta-blend at `beta = 1/2` is sometimes called "middle-point". In this form, where the
//! position always advances with `v1`, every `beta` gives a first-order method: `beta = 1/2`
//! evaluates the force at the midpoint of the positions but not of the velocities. The
//! second-order implicit midpoint rule is [`ImplicitMidpoint`].
//!
//! With one Newton iteration ([`NewtonParams::linearized`]) [`BetaBlend`] is exactly the
//! linearised scheme `[I - beta h^2 M^-1 K(x0)] v1 = v0 + h M^-1 f(x0)`, at `beta = 1` the
//! linearised backward Euler of Baraff & Witkin (1998): Newton starts from the point where the
//! force is evaluated at `x0`.
//!
//! # Invariants
//! - No integrator allocates in `step` after the first step of a given size.
//! - On error the state and the integrator's memory (`Integrator::memory`, feature `serde`) are left bit for bit
//!   as they were before the step (results are computed into scratch and committed only once
//!   checked).
//! - A non-finite position or velocity is reported at the step that produced it as
//!   [`IntegrateError::NonFinite`], whose message begins with `anim-core: step N:` and names the
//!   degree of freedom, the value and the last finite value; a non-finite Newton iterate or force
//!   of the implicit methods is reported the same way. Crates that drive these integrators
//!   rename the report in terms of their particles or joints
//!   ([`NonFinite::in_elements`](crate::diagnostics::NonFinite::in_elements)).
//! - The multistep methods (position Verlet, leapfrog, velocity Verlet) keep history between
//!   steps; if the caller changes the state between steps (a collision response, a reset) they
//!   notice and restart from the new state.

mod explicit;
mod implicit;
mod rk4;
pub mod study;
pub mod systems;
mod verlet;

pub use explicit::{ExplicitEuler, SymplecticEuler};
pub use implicit::{BetaBlend, ImplicitMidpoint, NewtonParams};
pub use rk4::Rk4;
pub use verlet::{Leapfrog, PositionVerlet, VelocityVerlet};

use crate::diagnostics::{Field, NonFinite, check_finite};
use crate::linalg::{CsrMatrix, LinearSolverKind, SolveError};

/// The integrated state of a second-order system: time, positions and velocities.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct State {
    /// Simulated time.
    pub t: f64,
    /// Generalised positions.
    pub x: Vec<f64>,
    /// Generalised velocities.
    pub v: Vec<f64>,
}

impl State {
    /// A state at time 0.
    ///
    /// # Panics
    /// If `x` and `v` differ in length.
    #[must_use]
    #[track_caller]
    pub fn new(x: Vec<f64>, v: Vec<f64>) -> Self {
        assert_eq!(x.len(), v.len(), "State::new: x and v differ in length");
        Self { t: 0.0, x, v }
    }

    /// Number of degrees of freedom.
    #[must_use]
    pub fn dof(&self) -> usize {
        self.x.len()
    }
}

/// A system `x'' = a(t, x, v)` known by its acceleration.
pub trait SecondOrderSystem {
    /// Number of degrees of freedom.
    fn dof(&self) -> usize;
    /// Writes the acceleration `a(t, x, v)`.
    fn acceleration(&mut self, t: f64, x: &[f64], v: &[f64], a: &mut [f64]);
    /// Total energy at `(t, x, v)`, where the system defines one.
    fn energy(&mut self, t: f64, x: &[f64], v: &[f64]) -> Option<f64> {
        let _ = (t, x, v);
        None
    }

    /// The parts of [`SecondOrderSystem::energy`] (kinetic, gravitational, the rest), where the
    /// system tells them apart.
    fn energy_parts(&mut self, t: f64, x: &[f64], v: &[f64]) -> Option<crate::solver::EnergyParts> {
        let _ = (t, x, v);
        None
    }
}

/// A system `M x'' = f(t, x, v)` with diagonal mass and force Jacobians: what implicit methods need.
///
/// `K = df/dx` and `D = df/dv` must be symmetric for the conjugate-gradient and Cholesky solvers
/// (conservative forces and symmetric damping give this); the implicit step matrix
/// `M - c_v D - c_x K` must be positive definite for them, which holds for small enough steps or
/// when `K` and `D` are negative semi-definite (springs with the definiteness fix, FEM with
/// projected element Hessians, Rayleigh damping).
pub trait MechanicalSystem: SecondOrderSystem {
    /// Writes the diagonal of `M^-1`; `0` marks a fixed degree of freedom (infinite mass).
    fn inverse_mass(&self, w: &mut [f64]);
    /// Writes the force `f(t, x, v)`.
    fn force(&mut self, t: f64, x: &[f64], v: &[f64], f: &mut [f64]);
    /// Evaluates and caches the Jacobians `K` and `D` at `(t, x, v)` for the calls below.
    fn linearize(&mut self, t: f64, x: &[f64], v: &[f64]);
    /// Writes `out = (c_x K + c_v D) dx` with the Jacobians of the last [`linearize`](Self::linearize).
    fn jacobian_apply(&self, c_x: f64, c_v: f64, dx: &[f64], out: &mut [f64]);
    /// Writes the diagonal of `c_x K + c_v D` and returns `true`, or `false` if unavailable
    /// (Jacobi preconditioning then fails with a clear error).
    fn jacobian_diagonal(&self, c_x: f64, c_v: f64, out: &mut [f64]) -> bool {
        let _ = (c_x, c_v, out);
        false
    }
    /// Assembles `c_x K + c_v D` into `out` and returns `true`, or `false` if the system is
    /// matrix-free only (Jacobi, Gauss-Seidel and Cholesky then fail with a clear error).
    ///
    /// A system should keep the sparsity pattern of `out` between calls and only rewrite its
    /// values, so that assembly does not allocate after the first step.
    fn jacobian_assemble(&self, c_x: f64, c_v: f64, out: &mut CsrMatrix) -> bool {
        let _ = (c_x, c_v, out);
        false
    }
}

/// What one integrator step did.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct StepInfo {
    /// Newton iterations (0 for explicit methods).
    pub newton_iterations: usize,
    /// Linear-solver iterations summed over the Newton iterations.
    pub linear_iterations: usize,
    /// Final Newton residual `||g|| / ||g_0||` (0 for explicit methods).
    pub residual: f64,
    /// Acceleration (or force) evaluations.
    pub evaluations: usize,
}

/// An integrator step that failed. The state is unchanged when one is returned.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum IntegrateError {
    /// A checkpointed integrator memory that does not belong to this method.
    #[error("integrator memory is not a memory of {method}: {cause}")]
    Memory {
        /// The method that was asked to restore it.
        method: &'static str,
        /// Why it does not fit.
        cause: String,
    },
    /// The step produced a NaN or infinity (a position, velocity, Newton iterate or force),
    /// named by step, degree of freedom, value and last finite value.
    #[error(transparent)]
    NonFinite(#[from] NonFinite),
    /// The time step is not a positive finite number.
    #[error("time step must be positive and finite, got {dt}")]
    BadTimeStep {
        /// The offending step.
        dt: f64,
    },
    /// The state does not match the system's number of degrees of freedom.
    #[error("state has {state} degrees of freedom (x: {x}, v: {v}) but the system has {system}")]
    DimensionMismatch {
        /// `x.len()`.
        x: usize,
        /// `v.len()`.
        v: usize,
        /// `x.len()` for the message.
        state: usize,
        /// `system.dof()`.
        system: usize,
    },
    /// The linear solve inside a Newton iteration failed.
    #[error("linear solve failed at step {step}, Newton iteration {newton_iteration}: {source}")]
    LinearSolve {
        /// Step index.
        step: u64,
        /// Newton iteration (0-based).
        newton_iteration: usize,
        /// The solver's error.
        source: SolveError,
    },
    /// Newton's method did not reach its tolerance.
    #[error(
        "Newton did not converge at step {step}: relative residual {residual:e} after {iterations} iterations"
    )]
    NewtonNotConverged {
        /// Step index.
        step: u64,
        /// Iterations performed.
        iterations: usize,
        /// Relative residual reached.
        residual: f64,
    },
}

/// Advances a system's [`State`] by one step.
pub trait Integrator<S: ?Sized> {
    /// Short name for reports.
    fn name(&self) -> &'static str;
    /// Advances `state` by `dt`.
    ///
    /// # Errors
    /// [`IntegrateError`]; `state` is then unchanged.
    fn step(&mut self, system: &mut S, state: &mut State, dt: f64) -> Result<StepInfo, IntegrateError>;
    /// Forgets history kept between steps (multistep methods), e.g. after teleporting the state.
    fn reset(&mut self) {}
    /// What the method carries from one step to the next (its step count and, for the
    /// multistep methods, the previous positions, the staggered velocity or the last
    /// acceleration), as a self-describing value for checkpoints. Scratch buffers are not part
    /// of it: a fresh integrator given this memory continues bit for bit like the one that
    /// produced it.
    #[cfg(feature = "serde")]
    fn memory(&self) -> serde_json::Value;
    /// Restores what [`Integrator::memory`] of the same method returned.
    ///
    /// # Errors
    /// [`IntegrateError::Memory`] when `memory` is not a memory of this method.
    #[cfg(feature = "serde")]
    fn restore_memory(&mut self, memory: &serde_json::Value) -> Result<(), IntegrateError>;
    /// Theoretical order of accuracy of the method.
    fn order(&self) -> u32;
    /// Whether the method is symplectic (bounded energy error on Hamiltonian systems).
    fn symplectic(&self) -> bool;
}

/// The integrators by name, for scene files, sweeps and the command line.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "kebab-case", deny_unknown_fields))]
pub enum IntegratorKind {
    /// [`ExplicitEuler`].
    ExplicitEuler,
    /// [`SymplecticEuler`].
    SymplecticEuler,
    /// [`BetaBlend`] with `beta = 1`.
    BackwardEuler,
    /// [`BetaBlend`] with the given `beta` in `[0, 1]`.
    BetaBlend {
        /// Blend factor.
        beta: f64,
    },
    /// [`PositionVerlet`].
    PositionVerlet,
    /// [`Leapfrog`].
    Leapfrog,
    /// [`VelocityVerlet`].
    VelocityVerlet,
    /// [`ImplicitMidpoint`].
    ImplicitMidpoint,
    /// [`Rk4`].
    Rk4,
}

impl IntegratorKind {
    /// Every kind: explicit Euler, the beta-blend at 0, 1/2 and 1, the Verlet family, midpoint and RK4.
    pub const ALL: [IntegratorKind; 10] = [
        IntegratorKind::ExplicitEuler,
        IntegratorKind::SymplecticEuler,
        IntegratorKind::BackwardEuler,
        IntegratorKind::BetaBlend { beta: 0.0 },
        IntegratorKind::BetaBlend { beta: 0.5 },
        IntegratorKind::PositionVerlet,
        IntegratorKind::Leapfrog,
        IntegratorKind::VelocityVerlet,
        IntegratorKind::ImplicitMidpoint,
        IntegratorKind::Rk4,
    ];

    /// A display label ("beta-blend(0.5)", "rk4", ...).
    #[must_use]
    pub fn label(&self) -> String {
        match self {
            IntegratorKind::ExplicitEuler => "explicit-euler".into(),
            IntegratorKind::SymplecticEuler => "symplectic-euler".into(),
            IntegratorKind::BackwardEuler => "backward-euler".into(),
            IntegratorKind::BetaBlend { beta } => format!("beta-blend({beta})"),
            IntegratorKind::PositionVerlet => "position-verlet".into(),
            IntegratorKind::Leapfrog => "leapfrog".into(),
            IntegratorKind::VelocityVerlet => "velocity-verlet".into(),
            IntegratorKind::ImplicitMidpoint => "implicit-midpoint".into(),
            IntegratorKind::Rk4 => "rk4".into(),
        }
    }

    /// Theoretical order of accuracy (1 for the Euler family and every beta-blend, 2 for the
    /// Verlet family and implicit midpoint, 4 for RK4).
    #[must_use]
    pub fn order(&self) -> u32 {
        match self {
            IntegratorKind::PositionVerlet
            | IntegratorKind::Leapfrog
            | IntegratorKind::VelocityVerlet
            | IntegratorKind::ImplicitMidpoint => 2,
            IntegratorKind::Rk4 => 4,
            IntegratorKind::ExplicitEuler
            | IntegratorKind::SymplecticEuler
            | IntegratorKind::BackwardEuler
            | IntegratorKind::BetaBlend { .. } => 1,
        }
    }

    /// Whether the method is symplectic (symplectic Euler, the Verlet family, implicit midpoint,
    /// and the beta-blend at `beta = 0`, which is symplectic Euler).
    #[must_use]
    pub fn is_symplectic(&self) -> bool {
        match self {
            IntegratorKind::SymplecticEuler
            | IntegratorKind::PositionVerlet
            | IntegratorKind::Leapfrog
            | IntegratorKind::VelocityVerlet
            | IntegratorKind::ImplicitMidpoint => true,
            IntegratorKind::BetaBlend { beta } => *beta == 0.0,
            IntegratorKind::ExplicitEuler | IntegratorKind::BackwardEuler | IntegratorKind::Rk4 => false,
        }
    }

    /// Whether the method needs a [`MechanicalSystem`] (force Jacobians).
    #[must_use]
    pub fn is_implicit(&self) -> bool {
        matches!(
            self,
            IntegratorKind::BackwardEuler
                | IntegratorKind::BetaBlend { .. }
                | IntegratorKind::ImplicitMidpoint
        )
    }

    /// Builds the integrator for a system with `dof` degrees of freedom; implicit methods use
    /// Newton with a Jacobi-preconditioned CG solve. See [`build_with`](Self::build_with).
    #[must_use]
    pub fn build<S: MechanicalSystem + ?Sized>(self, dof: usize) -> Box<dyn Integrator<S> + Send> {
        self.build_with(dof, NewtonParams::default(), LinearSolverKind::JacobiPcg)
    }

    /// Builds the integrator with the given Newton parameters and linear solver (both ignored by
    /// explicit methods).
    ///
    /// # Panics
    /// If a beta-blend `beta` lies outside `[0, 1]` (validate user input with
    /// [`validate`](Self::validate) first).
    #[must_use]
    pub fn build_with<S: MechanicalSystem + ?Sized>(
        self,
        dof: usize,
        newton: NewtonParams,
        linear: LinearSolverKind,
    ) -> Box<dyn Integrator<S> + Send> {
        match self {
            IntegratorKind::BackwardEuler => {
                Box::new(BetaBlend::new(1.0, newton, linear.build(newton.linear), dof))
            }
            IntegratorKind::BetaBlend { beta } => {
                Box::new(BetaBlend::new(beta, newton, linear.build(newton.linear), dof))
            }
            IntegratorKind::ImplicitMidpoint => {
                Box::new(ImplicitMidpoint::new(newton, linear.build(newton.linear), dof))
            }
            explicit => explicit.build_explicit(dof).unwrap_or_else(|| unreachable!("explicit kind")),
        }
    }

    /// Builds an explicit integrator for any [`SecondOrderSystem`]; `None` for implicit kinds.
    #[must_use]
    pub fn build_explicit<S: SecondOrderSystem + ?Sized>(
        self,
        dof: usize,
    ) -> Option<Box<dyn Integrator<S> + Send>> {
        Some(match self {
            IntegratorKind::ExplicitEuler => Box::new(ExplicitEuler::new(dof)),
            IntegratorKind::SymplecticEuler => Box::new(SymplecticEuler::new(dof)),
            IntegratorKind::PositionVerlet => Box::new(PositionVerlet::new(dof)),
            IntegratorKind::Leapfrog => Box::new(Leapfrog::new(dof)),
            IntegratorKind::VelocityVerlet => Box::new(VelocityVerlet::new(dof)),
            IntegratorKind::Rk4 => Box::new(Rk4::new(dof)),
            IntegratorKind::BackwardEuler
            | IntegratorKind::BetaBlend { .. }
            | IntegratorKind::ImplicitMidpoint => {
                return None;
            }
        })
    }

    /// Checks parameters given by a user (a beta outside `[0, 1]` or not finite).
    ///
    /// # Errors
    /// A message naming the bad value.
    pub fn validate(&self) -> Result<(), String> {
        match self {
            IntegratorKind::BetaBlend { beta } if !(0.0..=1.0).contains(beta) => {
                Err(format!("beta must lie in [0, 1], got {beta}"))
            }
            _ => Ok(()),
        }
    }
}

/// Checks `dt` and the state's shape against the system.
pub(crate) fn check_inputs(dof: usize, state: &State, dt: f64) -> Result<(), IntegrateError> {
    if !(dt > 0.0 && dt.is_finite()) {
        return Err(IntegrateError::BadTimeStep { dt });
    }
    if state.x.len() != dof || state.v.len() != dof {
        return Err(IntegrateError::DimensionMismatch {
            x: state.x.len(),
            v: state.v.len(),
            state: state.x.len(),
            system: dof,
        });
    }
    Ok(())
}

/// Checks new positions and velocities for non-finite values.
pub(crate) fn validate(step: u64, state: &State, x_new: &[f64], v_new: &[f64]) -> Result<(), IntegrateError> {
    check_finite(step, Field::Position, x_new, &state.x)?;
    check_finite(step, Field::Velocity, v_new, &state.v)?;
    Ok(())
}

/// Moves new positions and velocities into `state` by swapping buffers (no copy) and advances
/// its time. Afterwards `x_new` and `v_new` hold the previous state's arrays as scratch.
pub(crate) fn apply(state: &mut State, x_new: &mut Vec<f64>, v_new: &mut Vec<f64>, dt: f64) {
    std::mem::swap(&mut state.x, x_new);
    std::mem::swap(&mut state.v, v_new);
    state.t += dt;
}

/// Checks the new positions and velocities, then moves them into `state`.
pub(crate) fn commit(
    step: u64,
    state: &mut State,
    x_new: &mut Vec<f64>,
    v_new: &mut Vec<f64>,
    dt: f64,
) -> Result<(), IntegrateError> {
    validate(step, state, x_new, v_new)?;
    apply(state, x_new, v_new, dt);
    Ok(())
}

/// Degrees of freedom from which element-wise update loops run in parallel.
pub(crate) const PARALLEL_DOFS: usize = 1 << 15;
const CHUNK: usize = 1 << 13;

/// Runs `f(offset, chunk)` over chunks of one output array, in parallel for long arrays.
#[inline]
pub(crate) fn for_chunks1<F>(a: &mut [f64], f: F)
where
    F: Fn(usize, &mut [f64]) + Sync + Send,
{
    if a.len() >= PARALLEL_DOFS {
        use crate::par::prelude::*;
        a.par_chunks_mut(CHUNK).enumerate().for_each(|(c, ac)| f(c * CHUNK, ac));
    } else {
        f(0, a);
    }
}

/// Runs `f(offset, a_chunk, b_chunk)` over matching chunks of two output arrays, in parallel
/// for long arrays. The work is element-wise, so the result does not depend on the thread count.
#[inline]
pub(crate) fn for_chunks2<F>(a: &mut [f64], b: &mut [f64], f: F)
where
    F: Fn(usize, &mut [f64], &mut [f64]) + Sync + Send,
{
    assert_eq!(a.len(), b.len(), "for_chunks2: length mismatch");
    if a.len() >= PARALLEL_DOFS {
        use crate::par::prelude::*;
        a.par_chunks_mut(CHUNK)
            .zip(b.par_chunks_mut(CHUNK))
            .enumerate()
            .for_each(|(c, (ac, bc))| f(c * CHUNK, ac, bc));
    } else {
        f(0, a, b);
    }
}

/// Resizes a scratch vector (allocates only when the size changes).
#[inline]
pub(crate) fn fit(buf: &mut Vec<f64>, n: usize) {
    if buf.len() != n {
        buf.resize(n, 0.0);
    }
}

/// `Integrator::memory` and `Integrator::restore_memory` for a method whose serde form is its
/// memory (scratch fields are `#[serde(skip)]` and refilled by the next step).
macro_rules! serde_memory {
    ($name:literal) => {
        #[cfg(feature = "serde")]
        fn memory(&self) -> serde_json::Value {
            let own = serde_json::to_value(self).unwrap_or(serde_json::Value::Null);
            serde_json::json!({ "method": $name, "memory": own })
        }

        #[cfg(feature = "serde")]
        fn restore_memory(&mut self, memory: &serde_json::Value) -> Result<(), IntegrateError> {
            let own = crate::integrate::memory_of($name, memory)?;
            *self = serde::Deserialize::deserialize(own)
                .map_err(|e| IntegrateError::Memory { method: $name, cause: e.to_string() })?;
            Ok(())
        }
    };
}
pub(crate) use serde_memory;

/// The `"memory"` part of a saved memory after checking that its `"method"` is `method`.
#[cfg(feature = "serde")]
pub(crate) fn memory_of<'a>(
    method: &'static str,
    saved: &'a serde_json::Value,
) -> Result<&'a serde_json::Value, IntegrateError> {
    match saved.get("method").and_then(serde_json::Value::as_str) {
        Some(m) if m == method => {
            saved.get("memory").ok_or(IntegrateError::Memory { method, cause: "no \"memory\" field".into() })
        }
        Some(other) => Err(IntegrateError::Memory { method, cause: format!("it was saved by {other}") }),
        None => Err(IntegrateError::Memory { method, cause: "no \"method\" field".into() }),
    }
}

/// A snapshot of the state a multistep method last produced, to detect outside changes.
#[derive(Debug, Clone, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub(crate) struct History {
    valid: bool,
    t: f64,
    x: Vec<f64>,
    v: Vec<f64>,
}

impl History {
    /// Whether `state` is bit for bit the state recorded last.
    pub(crate) fn matches(&self, state: &State) -> bool {
        self.valid
            && self.t.to_bits() == state.t.to_bits()
            && self.x.len() == state.x.len()
            && self.x.iter().zip(&state.x).all(|(a, b)| a.to_bits() == b.to_bits())
            && self.v.iter().zip(&state.v).all(|(a, b)| a.to_bits() == b.to_bits())
    }

    pub(crate) fn record(&mut self, state: &State) {
        fit(&mut self.x, state.x.len());
        fit(&mut self.v, state.v.len());
        self.x.copy_from_slice(&state.x);
        self.v.copy_from_slice(&state.v);
        self.t = state.t;
        self.valid = true;
    }

    pub(crate) fn clear(&mut self) {
        self.valid = false;
    }
}

#[cfg(test)]
mod tests;

/// A second-order system with its integrator, as a [`Solver`](crate::solver::Solver): the bridge
/// from this module to the workspace's common stepping interface.
pub struct Simulation<S: ?Sized> {
    integrator: Box<dyn Integrator<S> + Send>,
    system: Box<S>,
}

impl<S: SecondOrderSystem + ?Sized> Simulation<S> {
    /// Couples a system with an integrator.
    #[must_use]
    pub fn new(system: Box<S>, integrator: Box<dyn Integrator<S> + Send>) -> Self {
        Self { integrator, system }
    }

    /// The system (model).
    #[must_use]
    pub fn system(&self) -> &S {
        &self.system
    }

    /// The system, mutably (to change parameters between steps).
    pub fn system_mut(&mut self) -> &mut S {
        &mut self.system
    }

    /// The integrator's name.
    #[must_use]
    pub fn integrator_name(&self) -> &'static str {
        self.integrator.name()
    }

    /// The integrator's memory between steps, for checkpoints (see [`Integrator::memory`]).
    #[must_use]
    #[cfg(feature = "serde")]
    pub fn memory(&self) -> serde_json::Value {
        self.integrator.memory()
    }

    /// Restores the integrator's memory from a checkpoint.
    ///
    /// # Errors
    /// [`IntegrateError::Memory`] when `memory` belongs to another method.
    #[cfg(feature = "serde")]
    pub fn restore_memory(&mut self, memory: &serde_json::Value) -> Result<(), IntegrateError> {
        self.integrator.restore_memory(memory)
    }
}

impl<S: SecondOrderSystem + ?Sized> crate::solver::Solver for Simulation<S> {
    type State = State;
    type Error = IntegrateError;

    fn step(&mut self, state: &mut State, dt: f64) -> Result<crate::solver::StepReport, IntegrateError> {
        let info = self.integrator.step(&mut self.system, state, dt)?;
        let mut report = crate::solver::StepReport::at_time(state.t);
        report.iterations = info.newton_iterations;
        report.residual = (info.newton_iterations > 0).then_some(info.residual);
        report.energy = self.system.energy(state.t, &state.x, &state.v);
        report.energy_parts = self.system.energy_parts(state.t, &state.x, &state.v);
        Ok(report)
    }
}
