//! Explicit and symplectic Euler.

use super::{
    IntegrateError, Integrator, SecondOrderSystem, State, StepInfo, check_inputs, commit, fit, for_chunks2,
};

/// Explicit (forward) Euler: `v1 = v0 + h a(t0, x0, v0)`, `x1 = x0 + h v0`.
///
/// First order; on an undamped oscillator the energy grows by a factor `1 + (omega h)^2` per
/// step, so it is stable only with damping. Included as the baseline.
#[derive(Debug, Clone, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct ExplicitEuler {
    steps: u64,
    #[cfg_attr(feature = "serde", serde(skip))]
    a: Vec<f64>,
    #[cfg_attr(feature = "serde", serde(skip))]
    x_new: Vec<f64>,
    #[cfg_attr(feature = "serde", serde(skip))]
    v_new: Vec<f64>,
}

impl ExplicitEuler {
    /// An integrator with scratch for `dof` degrees of freedom.
    #[must_use]
    pub fn new(dof: usize) -> Self {
        Self { steps: 0, a: vec![0.0; dof], x_new: vec![0.0; dof], v_new: vec![0.0; dof] }
    }
}

impl<S: SecondOrderSystem + ?Sized> Integrator<S> for ExplicitEuler {
    super::serde_memory!("explicit-euler");

    fn name(&self) -> &'static str {
        "explicit-euler"
    }

    fn step(&mut self, system: &mut S, state: &mut State, dt: f64) -> Result<StepInfo, IntegrateError> {
        let n = system.dof();
        check_inputs(n, state, dt)?;
        fit(&mut self.a, n);
        fit(&mut self.x_new, n);
        fit(&mut self.v_new, n);
        system.acceleration(state.t, &state.x, &state.v, &mut self.a);
        let (x, v, a) = (&state.x, &state.v, &self.a);
        for_chunks2(&mut self.x_new, &mut self.v_new, |o, xn, vn| {
            for k in 0..xn.len() {
                xn[k] = x[o + k] + dt * v[o + k];
                vn[k] = v[o + k] + dt * a[o + k];
            }
        });
        commit(self.steps, state, &mut self.x_new, &mut self.v_new, dt)?;
        self.steps += 1;
        Ok(StepInfo { evaluations: 1, ..StepInfo::default() })
    }

    fn order(&self) -> u32 {
        1
    }

    fn symplectic(&self) -> bool {
        false
    }
}

/// Symplectic (semi-implicit) Euler: `v1 = v0 + h a(t0, x0, v0)`, `x1 = x0 + h v1`.
///
/// First order and symplectic: on a harmonic oscillator the energy error stays bounded (it
/// oscillates with amplitude `O(omega h)`) for `omega h < 2`, the stability bound behind the
/// usual explicit step bound `dt <= c sqrt(m / k)`.
#[derive(Debug, Clone, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct SymplecticEuler {
    steps: u64,
    #[cfg_attr(feature = "serde", serde(skip))]
    a: Vec<f64>,
    #[cfg_attr(feature = "serde", serde(skip))]
    x_new: Vec<f64>,
    #[cfg_attr(feature = "serde", serde(skip))]
    v_new: Vec<f64>,
}

impl SymplecticEuler {
    /// An integrator with scratch for `dof` degrees of freedom.
    #[must_use]
    pub fn new(dof: usize) -> Self {
        Self { steps: 0, a: vec![0.0; dof], x_new: vec![0.0; dof], v_new: vec![0.0; dof] }
    }
}

impl<S: SecondOrderSystem + ?Sized> Integrator<S> for SymplecticEuler {
    super::serde_memory!("symplectic-euler");

    fn name(&self) -> &'static str {
        "symplectic-euler"
    }

    fn step(&mut self, system: &mut S, state: &mut State, dt: f64) -> Result<StepInfo, IntegrateError> {
        let n = system.dof();
        check_inputs(n, state, dt)?;
        fit(&mut self.a, n);
        fit(&mut self.x_new, n);
        fit(&mut self.v_new, n);
        system.acceleration(state.t, &state.x, &state.v, &mut self.a);
        let (x, v, a) = (&state.x, &state.v, &self.a);
        for_chunks2(&mut self.v_new, &mut self.x_new, |o, vn, xn| {
            for k in 0..vn.len() {
                vn[k] = v[o + k] + dt * a[o + k];
                xn[k] = x[o + k] + dt * vn[k];
            }
        });
        commit(self.steps, state, &mut self.x_new, &mut self.v_new, dt)?;
        self.steps += 1;
        Ok(StepInfo { evaluations: 1, ..StepInfo::default() })
    }

    fn order(&self) -> u32 {
        1
    }

    fn symplectic(&self) -> bool {
        true
    }
}
