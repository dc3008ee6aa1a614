//! The Verlet family (Verlet 1967): position (Stormer) Verlet, leapfrog and velocity Verlet.
//!
//! All three are second order and symplectic, and on a force that depends only on position
//! they produce the same trajectory up to rounding: they differ in what they store between
//! steps. Position Verlet keeps the previous position, leapfrog the staggered half-step velocity,
//! velocity Verlet the acceleration at the current position. Each reports a velocity synchronised
//! with the position (second-order accurate) in [`State::v`].
//!
//! For velocity-dependent forces (damping) the acceleration is evaluated with the best velocity
//! available at that point (the half-step velocity), which keeps the methods second order in the
//! conservative part and first order in the damping.

use super::{
    History, IntegrateError, Integrator, SecondOrderSystem, State, StepInfo, check_inputs, commit, fit,
    for_chunks1, for_chunks2, validate,
};

/// Position (Stormer) Verlet: `x1 = 2 x0 - x_-1 + h^2 a(x0)`.
///
/// The first step (or the first after the state was changed from outside) starts with the Taylor
/// step `x1 = x0 + h v0 + h^2/2 a(x0)`. The reported velocity is
/// `v1 = (x1 - x0) / h + h/2 a(x0)`, second order accurate at `t1` without another force
/// evaluation.
#[derive(Debug, Clone, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct PositionVerlet {
    steps: u64,
    x_prev: Vec<f64>,
    history: History,
    #[cfg_attr(feature = "serde", serde(skip))]
    a: Vec<f64>,
    #[cfg_attr(feature = "serde", serde(skip))]
    x_new: Vec<f64>,
    #[cfg_attr(feature = "serde", serde(skip))]
    v_new: Vec<f64>,
}

impl PositionVerlet {
    /// An integrator with scratch for `dof` degrees of freedom.
    #[must_use]
    pub fn new(dof: usize) -> Self {
        Self {
            steps: 0,
            x_prev: vec![0.0; dof],
            history: History::default(),
            a: vec![0.0; dof],
            x_new: vec![0.0; dof],
            v_new: vec![0.0; dof],
        }
    }
}

impl<S: SecondOrderSystem + ?Sized> Integrator<S> for PositionVerlet {
    super::serde_memory!("position-verlet");

    fn name(&self) -> &'static str {
        "position-verlet"
    }

    fn step(&mut self, system: &mut S, state: &mut State, dt: f64) -> Result<StepInfo, IntegrateError> {
        let n = system.dof();
        check_inputs(n, state, dt)?;
        fit(&mut self.a, n);
        fit(&mut self.x_new, n);
        fit(&mut self.v_new, n);
        fit(&mut self.x_prev, n);
        system.acceleration(state.t, &state.x, &state.v, &mut self.a);
        let h2 = dt * dt;
        if self.history.matches(state) {
            for i in 0..n {
                self.x_new[i] = 2.0 * state.x[i] - self.x_prev[i] + h2 * self.a[i];
            }
        } else {
            for i in 0..n {
                self.x_new[i] = state.x[i] + dt * state.v[i] + 0.5 * h2 * self.a[i];
            }
        }
        for i in 0..n {
            self.v_new[i] = (self.x_new[i] - state.x[i]) / dt + 0.5 * dt * self.a[i];
        }
        // x_prev takes x0 only once the new state is known to be finite.
        validate(self.steps, state, &self.x_new, &self.v_new)?;
        // x_prev takes x0's buffer, the state takes x_new's, x_new keeps the old x_prev as scratch.
        std::mem::swap(&mut self.x_prev, &mut state.x);
        std::mem::swap(&mut state.x, &mut self.x_new);
        std::mem::swap(&mut state.v, &mut self.v_new);
        state.t += dt;
        self.history.record(state);
        self.steps += 1;
        Ok(StepInfo { evaluations: 1, ..StepInfo::default() })
    }

    fn reset(&mut self) {
        self.history.clear();
    }

    fn order(&self) -> u32 {
        2
    }

    fn symplectic(&self) -> bool {
        true
    }
}

/// Leapfrog: `v_{n+1/2} = v_{n-1/2} + h a(x_n)`, `x_{n+1} = x_n + h v_{n+1/2}`.
///
/// Keeps the staggered velocity between steps; the first step (or the first after an outside
/// change of the state) starts it with a half kick `v_{1/2} = v_0 + h/2 a(x_0)`. The reported
/// velocity is synchronised: `v_{n+1} = v_{n+1/2} + h/2 a(x_{n+1})`, computed from the same
/// force evaluation that the next kick uses, so a step costs one evaluation.
#[derive(Debug, Clone, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Leapfrog {
    steps: u64,
    v_half: Vec<f64>,
    history: History,
    #[cfg_attr(feature = "serde", serde(skip))]
    a: Vec<f64>,
    #[cfg_attr(feature = "serde", serde(skip))]
    x_new: Vec<f64>,
    #[cfg_attr(feature = "serde", serde(skip))]
    v_new: Vec<f64>,
    #[cfg_attr(feature = "serde", serde(skip))]
    v_half_new: Vec<f64>,
}

impl Leapfrog {
    /// An integrator with scratch for `dof` degrees of freedom.
    #[must_use]
    pub fn new(dof: usize) -> Self {
        let z = || vec![0.0; dof];
        Self {
            steps: 0,
            v_half: z(),
            history: History::default(),
            a: z(),
            x_new: z(),
            v_new: z(),
            v_half_new: z(),
        }
    }
}

impl<S: SecondOrderSystem + ?Sized> Integrator<S> for Leapfrog {
    super::serde_memory!("leapfrog");

    fn name(&self) -> &'static str {
        "leapfrog"
    }

    fn step(&mut self, system: &mut S, state: &mut State, dt: f64) -> Result<StepInfo, IntegrateError> {
        let n = system.dof();
        check_inputs(n, state, dt)?;
        for b in [&mut self.a, &mut self.x_new, &mut self.v_new, &mut self.v_half, &mut self.v_half_new] {
            fit(b, n);
        }
        let mut evaluations = 0;
        // The staggered velocity of this step: the kept one, or (on a restart) a half kick from
        // the state, built in `v_half_new` so that a failed step leaves `v_half` as it was.
        let restart = !self.history.matches(state);
        if restart {
            system.acceleration(state.t, &state.x, &state.v, &mut self.a);
            evaluations += 1;
            for i in 0..n {
                self.v_half_new[i] = state.v[i] + 0.5 * dt * self.a[i];
            }
        }
        let v_half: &[f64] = if restart { &self.v_half_new } else { &self.v_half };
        for i in 0..n {
            self.x_new[i] = state.x[i] + dt * v_half[i];
        }
        system.acceleration(state.t + dt, &self.x_new, v_half, &mut self.a);
        evaluations += 1;
        // v_new first: on a restart v_half_new is also the start velocity, updated in place.
        for i in 0..n {
            self.v_new[i] = v_half[i] + 0.5 * dt * self.a[i];
        }
        if restart {
            for i in 0..n {
                self.v_half_new[i] += dt * self.a[i];
            }
        } else {
            for i in 0..n {
                self.v_half_new[i] = self.v_half[i] + dt * self.a[i];
            }
        }
        commit(self.steps, state, &mut self.x_new, &mut self.v_new, dt)?;
        std::mem::swap(&mut self.v_half, &mut self.v_half_new);
        self.history.record(state);
        self.steps += 1;
        Ok(StepInfo { evaluations, ..StepInfo::default() })
    }

    fn reset(&mut self) {
        self.history.clear();
    }

    fn order(&self) -> u32 {
        2
    }

    fn symplectic(&self) -> bool {
        true
    }
}

/// Velocity Verlet: `v_{1/2} = v0 + h/2 a(x0)`, `x1 = x0 + h v_{1/2}`,
/// `v1 = v_{1/2} + h/2 a(x1)`.
///
/// Keeps `a(x1)` for the next step's first half kick, so a step costs one evaluation (two on
/// the first step or after an outside change of the state).
#[derive(Debug, Clone, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct VelocityVerlet {
    steps: u64,
    a: Vec<f64>,
    history: History,
    #[cfg_attr(feature = "serde", serde(skip))]
    a_new: Vec<f64>,
    #[cfg_attr(feature = "serde", serde(skip))]
    x_new: Vec<f64>,
    #[cfg_attr(feature = "serde", serde(skip))]
    v_new: Vec<f64>,
}

impl VelocityVerlet {
    /// An integrator with scratch for `dof` degrees of freedom.
    #[must_use]
    pub fn new(dof: usize) -> Self {
        let z = || vec![0.0; dof];
        Self { steps: 0, a: z(), history: History::default(), a_new: z(), x_new: z(), v_new: z() }
    }
}

impl<S: SecondOrderSystem + ?Sized> Integrator<S> for VelocityVerlet {
    super::serde_memory!("velocity-verlet");

    fn name(&self) -> &'static str {
        "velocity-verlet"
    }

    fn step(&mut self, system: &mut S, state: &mut State, dt: f64) -> Result<StepInfo, IntegrateError> {
        let n = system.dof();
        check_inputs(n, state, dt)?;
        for b in [&mut self.a, &mut self.a_new, &mut self.x_new, &mut self.v_new] {
            fit(b, n);
        }
        let mut evaluations = 0;
        // The acceleration at the start: the kept one, or (on a restart) evaluated into `a_new`
        // so that a failed step leaves `a` as it was.
        let restart = !self.history.matches(state);
        if restart {
            system.acceleration(state.t, &state.x, &state.v, &mut self.a_new);
            evaluations += 1;
        }
        // v_new holds the half-step velocity until the second kick.
        let a: &[f64] = if restart { &self.a_new } else { &self.a };
        first_kick(&mut self.v_new, &mut self.x_new, &state.x, &state.v, a, dt);
        system.acceleration(state.t + dt, &self.x_new, &self.v_new, &mut self.a_new);
        evaluations += 1;
        let a_new = &self.a_new;
        for_chunks1(&mut self.v_new, |o, vn| {
            for k in 0..vn.len() {
                vn[k] += 0.5 * dt * a_new[o + k];
            }
        });
        commit(self.steps, state, &mut self.x_new, &mut self.v_new, dt)?;
        std::mem::swap(&mut self.a, &mut self.a_new);
        self.history.record(state);
        self.steps += 1;
        Ok(StepInfo { evaluations, ..StepInfo::default() })
    }

    fn reset(&mut self) {
        self.history.clear();
    }

    fn order(&self) -> u32 {
        2
    }

    fn symplectic(&self) -> bool {
        true
    }
}

/// Velocity Verlet's first kick and drift, `v_half = v + dt/2 a`, `x_new = x + dt v_half`, over
/// plain slices (the start acceleration is one of two buffers; as a slice argument the loop
/// vectorises as it would on a fixed field).
#[inline]
fn first_kick(v_half: &mut [f64], x_new: &mut [f64], x: &[f64], v: &[f64], a: &[f64], dt: f64) {
    for_chunks2(v_half, x_new, |o, vn, xn| {
        let (x, v, a) = (&x[o..o + vn.len()], &v[o..o + vn.len()], &a[o..o + vn.len()]);
        for k in 0..vn.len() {
            vn[k] = v[k] + 0.5 * dt * a[k];
            xn[k] = x[k] + dt * vn[k];
        }
    });
}
