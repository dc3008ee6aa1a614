//! The classical fourth-order Runge-Kutta method, the high-order reference.

use super::{IntegrateError, Integrator, SecondOrderSystem, State, StepInfo, check_inputs, commit, fit};

/// Classical RK4 on the first-order system `(x, v)' = (v, a(t, x, v))`.
///
/// Fourth order, four acceleration evaluations per step, not symplectic (its energy error drifts
/// slowly, as `O(t h^4)`). Used as the converged reference in work-precision studies.
#[derive(Debug, Clone, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Rk4 {
    steps: u64,
    #[cfg_attr(feature = "serde", serde(skip))]
    k: [Vec<f64>; 4],
    #[cfg_attr(feature = "serde", serde(skip))]
    x_tmp: Vec<f64>,
    #[cfg_attr(feature = "serde", serde(skip))]
    v_tmp: Vec<f64>,
    #[cfg_attr(feature = "serde", serde(skip))]
    x_new: Vec<f64>,
    #[cfg_attr(feature = "serde", serde(skip))]
    v_new: Vec<f64>,
}

impl Rk4 {
    /// An integrator with scratch for `dof` degrees of freedom.
    #[must_use]
    pub fn new(dof: usize) -> Self {
        let z = || vec![0.0; dof];
        Self { steps: 0, k: [z(), z(), z(), z()], x_tmp: z(), v_tmp: z(), x_new: z(), v_new: z() }
    }
}

impl<S: SecondOrderSystem + ?Sized> Integrator<S> for Rk4 {
    super::serde_memory!("rk4");

    fn name(&self) -> &'static str {
        "rk4"
    }

    fn step(&mut self, system: &mut S, state: &mut State, dt: f64) -> Result<StepInfo, IntegrateError> {
        let n = system.dof();
        check_inputs(n, state, dt)?;
        for k in &mut self.k {
            fit(k, n);
        }
        fit(&mut self.x_tmp, n);
        fit(&mut self.v_tmp, n);
        fit(&mut self.x_new, n);
        fit(&mut self.v_new, n);
        let (t, x, v) = (state.t, &state.x, &state.v);
        let h = dt;
        // Stage velocities are v, v + h/2 k1, v + h/2 k2, v + h k3; stage positions follow from them.
        system.acceleration(t, x, v, &mut self.k[0]);
        for i in 0..n {
            self.x_tmp[i] = x[i] + 0.5 * h * v[i];
            self.v_tmp[i] = v[i] + 0.5 * h * self.k[0][i];
        }
        system.acceleration(t + 0.5 * h, &self.x_tmp, &self.v_tmp, &mut self.k[1]);
        for i in 0..n {
            // x stage 3 uses the stage-2 velocity v + h/2 k1.
            self.x_tmp[i] = x[i] + 0.5 * h * (v[i] + 0.5 * h * self.k[0][i]);
            self.v_tmp[i] = v[i] + 0.5 * h * self.k[1][i];
        }
        system.acceleration(t + 0.5 * h, &self.x_tmp, &self.v_tmp, &mut self.k[2]);
        for i in 0..n {
            self.x_tmp[i] = x[i] + h * (v[i] + 0.5 * h * self.k[1][i]);
            self.v_tmp[i] = v[i] + h * self.k[2][i];
        }
        system.acceleration(t + h, &self.x_tmp, &self.v_tmp, &mut self.k[3]);
        for i in 0..n {
            let (k1, k2, k3, k4) = (self.k[0][i], self.k[1][i], self.k[2][i], self.k[3][i]);
            // Position slopes: v, v + h/2 k1, v + h/2 k2, v + h k3.
            self.x_new[i] = x[i] + h * v[i] + h * h / 6.0 * (k1 + k2 + k3);
            self.v_new[i] = v[i] + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
        }
        commit(self.steps, state, &mut self.x_new, &mut self.v_new, dt)?;
        self.steps += 1;
        Ok(StepInfo { evaluations: 4, ..StepInfo::default() })
    }

    fn order(&self) -> u32 {
        4
    }

    fn symplectic(&self) -> bool {
        false
    }
}
