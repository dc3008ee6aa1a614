//! Implicit integrators solved by Newton's method: the beta-blend (backward Euler at
//! `beta = 1`) and the implicit midpoint rule.
//!
//! Both solve for the velocity change `dv = v1 - v0` from
//!
//! ```text
//! g(dv) = M dv - h f(t_e, x_e(dv), v_e(dv)) = 0,
//! x_e = x0 + alpha h v0 + gamma h dv,   v_e = v0 + eta dv,
//! ```
//!
//! and then set `v1 = v0 + dv`, `x1 = x0 + h v0 + zeta h dv`:
//!
//! | method | alpha | gamma | eta | zeta | `t_e` |
//! | --- | --- | --- | --- | --- | --- |
//! | beta-blend | beta | beta | beta | 1 | `t0 + beta h` |
//! | implicit midpoint | 1/2 | 1/4 | 1/2 | 1/2 | `t0 + h/2` |
//!
//! Each Newton iteration solves `(M - c_v D - c_x K) delta = -g` with `c_x = gamma h^2`,
//! `c_v = eta h`, `K = df/dx`, `D = df/dv`. The first iteration linearises at `(x0, v0)`, which
//! makes it exactly the linearised scheme `[I - beta h^2 M^-1 K] v1 = v0 + h M^-1 f(x0)`
//! (Baraff and Witkin's linearised backward Euler, 1998, once damping is included); later iterations linearise at the
//! current iterate. [`NewtonParams::linearized`] stops after that first iteration.
//!
//! Fixed degrees of freedom (zero inverse mass) keep `dv = 0`: their rows of the Newton matrix are
//! the identity and their right-hand side is zero, so iterative solvers never move them and the
//! assembled matrix stays symmetric.
//!
//! The line search here backtracks on the residual norm ([`NewtonParams::line_search`]); the
//! energy-based backtracking that FEM needs lives with the FEM solver, which knows its
//! incremental potential.

use super::{
    IntegrateError, Integrator, MechanicalSystem, State, StepInfo, apply, check_inputs, fit, validate,
};
use crate::diagnostics::{Field, NonFinite, check_finite};
use crate::linalg::{
    CsrMatrix, IterativeParams, LinearOperator, LinearSolver, SolveError, SystemMatrix, norm,
};

/// Newton's method inside an implicit step.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields, default))]
#[non_exhaustive]
pub struct NewtonParams {
    /// Stop when `||g|| <= tolerance * ||g_0||`, or when `||g||` is below the rounding floor of
    /// the residual, estimated as `1000 eps h (||K x0|| + ||f0||)`: near an equilibrium `||g_0||`
    /// is tiny and `tolerance * ||g_0||` would lie below what the force evaluation can resolve.
    /// Default `1e-9`.
    pub tolerance: f64,
    /// Give up (with [`IntegrateError::NewtonNotConverged`]) after this many iterations.
    /// Default `20`.
    pub max_iterations: usize,
    /// Take exactly one iteration from `(x0, v0)`: the linearised scheme (Baraff & Witkin 1998).
    /// Default `false`.
    pub linearized: bool,
    /// Backtracking line search on `||g||` from the second iteration on: the step is halved
    /// until the residual decreases by the Armijo factor `1 - 1e-4 alpha`. Keeps Newton
    /// converging where the Jacobian is approximate (definiteness fixes) or the force strongly
    /// nonlinear (contact, folding cloth). Default `true`.
    pub line_search: bool,
    /// Halvings tried by the line search before taking the best trial. Default `8`.
    pub max_halvings: usize,
    /// Stopping rule of the inner iterative linear solve. Default tolerance `1e-10`, 2000
    /// iterations.
    pub linear: IterativeParams,
}

impl Default for NewtonParams {
    fn default() -> Self {
        Self {
            tolerance: 1e-9,
            max_iterations: 20,
            linearized: false,
            line_search: true,
            max_halvings: 8,
            linear: IterativeParams::new(1e-10, 2000),
        }
    }
}

impl NewtonParams {
    /// The linearised scheme of Baraff & Witkin (1998): one Newton iteration.
    #[must_use]
    pub fn linearized() -> Self {
        Self { linearized: true, ..Self::default() }
    }

    /// Full Newton with the given tolerance.
    #[must_use]
    pub fn with_tolerance(tolerance: f64) -> Self {
        Self { tolerance, ..Self::default() }
    }
}

/// Coefficients of the implicit scheme (see the module documentation).
#[derive(Debug, Clone, Copy)]
struct Scheme {
    alpha: f64,
    gamma: f64,
    eta: f64,
    zeta: f64,
    time: f64,
}

/// The Newton matrix `M - c_v D - c_x K` (identity on fixed rows), matrix-free.
struct NewtonOperator<'a, S: ?Sized> {
    system: &'a S,
    w: &'a [f64],
    c_x: f64,
    c_v: f64,
    diagonal: Option<&'a [f64]>,
}

impl<S: MechanicalSystem + ?Sized> LinearOperator for NewtonOperator<'_, S> {
    fn dim(&self) -> usize {
        self.w.len()
    }

    fn apply(&self, x: &[f64], y: &mut [f64]) {
        self.system.jacobian_apply(self.c_x, self.c_v, x, y);
        for i in 0..self.w.len() {
            let wi = self.w[i];
            y[i] = if wi > 0.0 { x[i] / wi - y[i] } else { x[i] };
        }
    }

    fn diagonal(&self, out: &mut [f64]) -> bool {
        match self.diagonal {
            Some(d) => {
                out.copy_from_slice(d);
                true
            }
            None => false,
        }
    }
}

/// Scratch and the assembled Newton matrix, shared by both implicit methods.
#[derive(Default)]
struct NewtonCore {
    steps: u64,
    w: Vec<f64>,
    f: Vec<f64>,
    dv: Vec<f64>,
    delta: Vec<f64>,
    dv_trial: Vec<f64>,
    rhs: Vec<f64>,
    tmp: Vec<f64>,
    x_e: Vec<f64>,
    v_e: Vec<f64>,
    x_new: Vec<f64>,
    v_new: Vec<f64>,
    diag: Vec<f64>,
    jac: CsrMatrix,
    newton_matrix: CsrMatrix,
    pattern_row_ptr: Vec<usize>,
    pattern_col_idx: Vec<usize>,
    jac_to_newton: Vec<usize>,
    diag_pos: Vec<usize>,
}

impl NewtonCore {
    /// The only state kept between steps is the step count (every solve starts from zero).
    #[cfg(feature = "serde")]
    fn memory(&self, method: &'static str) -> serde_json::Value {
        serde_json::json!({ "method": method, "memory": { "steps": self.steps } })
    }

    #[cfg(feature = "serde")]
    fn restore_memory(
        &mut self,
        method: &'static str,
        memory: &serde_json::Value,
    ) -> Result<(), IntegrateError> {
        let memory = super::memory_of(method, memory)?;
        let steps = memory.get("steps").and_then(serde_json::Value::as_u64).ok_or_else(|| {
            IntegrateError::Memory { method, cause: format!("expected {{\"steps\": <count>}}, got {memory}") }
        })?;
        self.steps = steps;
        Ok(())
    }

    fn resize(&mut self, n: usize) {
        for b in [
            &mut self.w,
            &mut self.f,
            &mut self.dv,
            &mut self.delta,
            &mut self.dv_trial,
            &mut self.rhs,
            &mut self.tmp,
            &mut self.x_e,
            &mut self.v_e,
            &mut self.x_new,
            &mut self.v_new,
            &mut self.diag,
        ] {
            fit(b, n);
        }
    }

    /// Rebuilds the Newton matrix's pattern (the Jacobian's plus the diagonal) when the
    /// Jacobian's pattern changed; allocation happens only then.
    fn sync_pattern(&mut self) {
        let same = self.pattern_row_ptr.as_slice() == self.jac.row_ptr()
            && self.pattern_col_idx.as_slice() == self.jac.col_idx()
            && self.newton_matrix.nrows() == self.jac.nrows();
        if same {
            return;
        }
        let n = self.jac.nrows();
        let mut triplets = Vec::with_capacity(self.jac.nnz() + n);
        for r in 0..n {
            for &c in &self.jac.col_idx()[self.jac.row_ptr()[r]..self.jac.row_ptr()[r + 1]] {
                triplets.push((r, c, 0.0));
            }
            triplets.push((r, r, 0.0));
        }
        self.newton_matrix = CsrMatrix::from_triplets(n, n, &triplets);
        self.jac_to_newton.clear();
        for r in 0..n {
            for &c in &self.jac.col_idx()[self.jac.row_ptr()[r]..self.jac.row_ptr()[r + 1]] {
                let p = self.newton_matrix.position(r, c).unwrap_or_else(|| unreachable!("entry in pattern"));
                self.jac_to_newton.push(p);
            }
        }
        self.diag_pos.clear();
        for r in 0..n {
            let p = self.newton_matrix.position(r, r).unwrap_or_else(|| unreachable!("diagonal in pattern"));
            self.diag_pos.push(p);
        }
        self.pattern_row_ptr.clear();
        self.pattern_row_ptr.extend_from_slice(self.jac.row_ptr());
        self.pattern_col_idx.clear();
        self.pattern_col_idx.extend_from_slice(self.jac.col_idx());
    }

    /// Writes `M - J` into the assembled Newton matrix (fixed rows and columns decoupled).
    fn fill_newton_matrix(&mut self) {
        self.sync_pattern();
        let values = self.newton_matrix.values_mut();
        values.iter_mut().for_each(|v| *v = 0.0);
        let n = self.jac.nrows();
        let (row_ptr, col_idx, jac_values) = (self.jac.row_ptr(), self.jac.col_idx(), self.jac.values());
        for r in 0..n {
            if self.w[r] == 0.0 {
                continue;
            }
            for k in row_ptr[r]..row_ptr[r + 1] {
                if self.w[col_idx[k]] == 0.0 {
                    continue;
                }
                values[self.jac_to_newton[k]] -= jac_values[k];
            }
        }
        for r in 0..n {
            values[self.diag_pos[r]] += if self.w[r] > 0.0 { 1.0 / self.w[r] } else { 1.0 };
        }
    }

    /// Solves the Newton system `S delta = rhs` for the current linearisation.
    fn solve_linear<S: MechanicalSystem + ?Sized>(
        &mut self,
        system: &S,
        solver: &mut dyn LinearSolver,
        c_x: f64,
        c_v: f64,
    ) -> Result<usize, SolveError> {
        self.delta.iter_mut().for_each(|d| *d = 0.0);
        let info = if solver.needs_matrix() {
            if !system.jacobian_assemble(c_x, c_v, &mut self.jac) {
                return Err(SolveError::NeedsMatrix { solver: solver.name() });
            }
            self.fill_newton_matrix();
            solver.solve(SystemMatrix::Csr(&self.newton_matrix), &self.rhs, &mut self.delta)?
        } else {
            let has_diag = system.jacobian_diagonal(c_x, c_v, &mut self.diag);
            if has_diag {
                for i in 0..self.w.len() {
                    self.diag[i] = if self.w[i] > 0.0 { 1.0 / self.w[i] - self.diag[i] } else { 1.0 };
                }
            }
            let op = NewtonOperator {
                system,
                w: &self.w,
                c_x,
                c_v,
                diagonal: has_diag.then_some(self.diag.as_slice()),
            };
            solver.solve(SystemMatrix::Operator(&op), &self.rhs, &mut self.delta)?
        };
        Ok(info.iterations)
    }

    fn step<S: MechanicalSystem + ?Sized>(
        &mut self,
        scheme: Scheme,
        params: &NewtonParams,
        solver: &mut dyn LinearSolver,
        system: &mut S,
        state: &mut State,
        h: f64,
    ) -> Result<StepInfo, IntegrateError> {
        let n = system.dof();
        check_inputs(n, state, h)?;
        self.resize(n);
        system.inverse_mass(&mut self.w);
        let step = self.steps;
        let c_x = scheme.gamma * h * h;
        let c_v = scheme.eta * h;
        let t_e = state.t + scheme.time * h;
        let mut info = StepInfo::default();

        // Iteration 0: linearise at (x0, v0); rhs = h f0 + alpha h^2 K v0.
        system.force(t_e, &state.x, &state.v, &mut self.f);
        system.linearize(t_e, &state.x, &state.v);
        info.evaluations += 1;
        // Rounding floor of the residual: the force terms are about as large as K x0 and f0.
        system.jacobian_apply(1.0, 0.0, &state.x, &mut self.tmp);
        let floor = 1e3 * f64::EPSILON * h * (norm(&self.tmp) + norm(&self.f));
        system.jacobian_apply(scheme.alpha * h * h, 0.0, &state.v, &mut self.tmp);
        for i in 0..n {
            self.rhs[i] = if self.w[i] > 0.0 { h * self.f[i] + self.tmp[i] } else { 0.0 };
            self.dv[i] = 0.0;
        }
        let g0 = norm(&self.rhs);
        if !g0.is_finite() {
            // The force at the start is not finite: name its first offending degree of freedom.
            self.x_e.copy_from_slice(&state.x);
            self.v_e.copy_from_slice(&state.v);
            if let Some(e) = non_finite_iterate(step, system, state, t_e, self) {
                return Err(e);
            }
        }
        let mut residual = 0.0;
        if c_x == 0.0 && c_v == 0.0 {
            // beta = 0: the Newton matrix is M, the step is explicit (symplectic Euler).
            for i in 0..n {
                self.dv[i] = self.w[i] * self.rhs[i];
            }
        } else if g0 > 0.0 {
            // The first iteration is the linearised step from (x0, v0).
            info.linear_iterations += self
                .solve_linear(system, solver, c_x, c_v)
                .map_err(|source| IntegrateError::LinearSolve { step, newton_iteration: 0, source })?;
            self.dv.copy_from_slice(&self.delta);
            let mut iteration = 1;
            // Whether `rhs`, `x_e`, `v_e` already hold g(dv) and its evaluation point.
            let mut have_g = false;
            let mut g_norm = 0.0;
            loop {
                info.newton_iterations = iteration;
                if params.linearized {
                    break;
                }
                if !have_g {
                    g_norm = residual_at(
                        system,
                        state,
                        scheme,
                        h,
                        t_e,
                        &self.w,
                        &self.dv,
                        &mut self.x_e,
                        &mut self.v_e,
                        &mut self.f,
                        &mut self.rhs,
                    );
                    info.evaluations += 1;
                }
                residual = g_norm / g0;
                if !residual.is_finite() {
                    if let Some(e) = non_finite_iterate(step, system, state, t_e, self) {
                        return Err(e);
                    }
                    return Err(IntegrateError::NewtonNotConverged { step, iterations: iteration, residual });
                }
                if residual <= params.tolerance || g_norm <= floor {
                    break;
                }
                if iteration >= params.max_iterations {
                    return Err(IntegrateError::NewtonNotConverged { step, iterations: iteration, residual });
                }
                system.linearize(t_e, &self.x_e, &self.v_e);
                info.linear_iterations += self.solve_linear(system, solver, c_x, c_v).map_err(|source| {
                    IntegrateError::LinearSolve { step, newton_iteration: iteration, source }
                })?;
                iteration += 1;
                if !params.line_search {
                    for i in 0..n {
                        self.dv[i] += self.delta[i];
                    }
                    have_g = false;
                    continue;
                }
                // Backtracking on ||g||: halve the step until the residual decreases enough
                // (Armijo, 1e-4); if no trial does, take the best one seen.
                let (mut alpha, mut best_alpha, mut best) = (1.0, 1.0, f64::INFINITY);
                let mut accepted = false;
                for _ in 0..=params.max_halvings {
                    for i in 0..n {
                        self.dv_trial[i] = self.dv[i] + alpha * self.delta[i];
                    }
                    let t = residual_at(
                        system,
                        state,
                        scheme,
                        h,
                        t_e,
                        &self.w,
                        &self.dv_trial,
                        &mut self.x_e,
                        &mut self.v_e,
                        &mut self.f,
                        &mut self.tmp,
                    );
                    info.evaluations += 1;
                    if t <= (1.0 - 1e-4 * alpha) * g_norm {
                        g_norm = t;
                        accepted = true;
                        break;
                    }
                    if t < best {
                        (best, best_alpha) = (t, alpha);
                    }
                    alpha *= 0.5;
                }
                if !accepted {
                    for i in 0..n {
                        self.dv_trial[i] = self.dv[i] + best_alpha * self.delta[i];
                    }
                    g_norm = residual_at(
                        system,
                        state,
                        scheme,
                        h,
                        t_e,
                        &self.w,
                        &self.dv_trial,
                        &mut self.x_e,
                        &mut self.v_e,
                        &mut self.f,
                        &mut self.tmp,
                    );
                    info.evaluations += 1;
                }
                std::mem::swap(&mut self.dv, &mut self.dv_trial);
                std::mem::swap(&mut self.rhs, &mut self.tmp);
                have_g = true;
            }
        }
        info.residual = residual;
        for i in 0..n {
            self.v_new[i] = state.v[i] + self.dv[i];
            self.x_new[i] = state.x[i] + h * state.v[i] + scheme.zeta * h * self.dv[i];
        }
        validate(step, state, &self.x_new, &self.v_new)?;
        apply(state, &mut self.x_new, &mut self.v_new, h);
        self.steps += 1;
        Ok(info)
    }
}

/// Names the first non-finite entry of the Newton evaluation point `x_e`, `v_e` or of the force
/// `f` there (compared with the state, or with the force at the start of the step). Runs only on
/// the error path.
fn non_finite_iterate<S: MechanicalSystem + ?Sized>(
    step: u64,
    system: &mut S,
    state: &State,
    t_e: f64,
    core: &mut NewtonCore,
) -> Option<IntegrateError> {
    if let Err(e) = check_finite(step, Field::Position, &core.x_e, &state.x) {
        return Some(e.into());
    }
    if let Err(e) = check_finite(step, Field::Velocity, &core.v_e, &state.v) {
        return Some(e.into());
    }
    // The force at the evaluation point on a free degree of freedom (fixed rows do not enter
    // the residual), then the force at the start of the step for the last finite value.
    system.force(t_e, &core.x_e, &core.v_e, &mut core.f);
    let dof = (0..core.f.len()).find(|&i| core.w[i] > 0.0 && !core.f[i].is_finite())?;
    system.force(state.t, &state.x, &state.v, &mut core.tmp);
    Some(NonFinite::at_dof(step, Field::Force, dof, core.f[dof], core.tmp[dof]).into())
}

/// Evaluates the Newton residual `g = h f(x_e, v_e) - M dv` (zero on fixed rows) at `dv`,
/// leaving the evaluation point in `x_e`, `v_e`; returns `||g||`.
fn residual_at<S: MechanicalSystem + ?Sized>(
    system: &mut S,
    state: &State,
    scheme: Scheme,
    h: f64,
    t_e: f64,
    w: &[f64],
    dv: &[f64],
    x_e: &mut [f64],
    v_e: &mut [f64],
    f: &mut [f64],
    g: &mut [f64],
) -> f64 {
    for i in 0..dv.len() {
        x_e[i] = state.x[i] + scheme.alpha * h * state.v[i] + scheme.gamma * h * dv[i];
        v_e[i] = state.v[i] + scheme.eta * dv[i];
    }
    system.force(t_e, x_e, v_e, f);
    for i in 0..dv.len() {
        g[i] = if w[i] > 0.0 { h * f[i] - dv[i] / w[i] } else { 0.0 };
    }
    norm(g)
}

/// The beta-blend of symplectic and backward Euler: `[I - beta h^2 M^-1 K] v1 = v0 + h M^-1 f(x0)`,
/// `x1 = x0 + h v1`, solved to convergence by Newton (or linearised, see [`NewtonParams`]).
///
/// `beta = 1` is backward Euler: unconditionally stable, first order, numerically dissipative.
/// `beta = 0` is symplectic Euler (no linear solve is made). Every `beta` is first order because
/// the position always advances with `v1`; see [`ImplicitMidpoint`] for a second-order implicit
/// method.
pub struct BetaBlend {
    beta: f64,
    params: NewtonParams,
    solver: Box<dyn LinearSolver>,
    core: NewtonCore,
}

impl BetaBlend {
    /// A beta-blend integrator for `dof` degrees of freedom with the given linear solver.
    ///
    /// # Panics
    /// If `beta` is outside `[0, 1]`.
    #[must_use]
    #[track_caller]
    pub fn new(beta: f64, params: NewtonParams, solver: Box<dyn LinearSolver>, dof: usize) -> Self {
        assert!((0.0..=1.0).contains(&beta), "BetaBlend: beta must lie in [0, 1], got {beta}");
        let mut core = NewtonCore::default();
        core.resize(dof);
        Self { beta, params, solver, core }
    }

    /// Backward Euler (`beta = 1`).
    #[must_use]
    pub fn backward_euler(params: NewtonParams, solver: Box<dyn LinearSolver>, dof: usize) -> Self {
        Self::new(1.0, params, solver, dof)
    }

    /// The blend factor.
    #[must_use]
    pub fn beta(&self) -> f64 {
        self.beta
    }
}

impl<S: MechanicalSystem + ?Sized> Integrator<S> for BetaBlend {
    #[cfg(feature = "serde")]
    fn memory(&self) -> serde_json::Value {
        self.core.memory(Integrator::<S>::name(self))
    }

    #[cfg(feature = "serde")]
    fn restore_memory(&mut self, memory: &serde_json::Value) -> Result<(), IntegrateError> {
        self.core.restore_memory(if self.beta == 1.0 { "backward-euler" } else { "beta-blend" }, memory)
    }

    fn name(&self) -> &'static str {
        if self.beta == 1.0 { "backward-euler" } else { "beta-blend" }
    }

    fn step(&mut self, system: &mut S, state: &mut State, dt: f64) -> Result<StepInfo, IntegrateError> {
        let b = self.beta;
        let scheme = Scheme { alpha: b, gamma: b, eta: b, zeta: 1.0, time: b };
        self.core.step(scheme, &self.params, self.solver.as_mut(), system, state, dt)
    }

    fn order(&self) -> u32 {
        1
    }

    fn symplectic(&self) -> bool {
        self.beta == 0.0
    }
}

/// The implicit midpoint rule: `x1 = x0 + h (v0 + v1)/2`,
/// `v1 = v0 + h a((x0 + x1)/2, (v0 + v1)/2)`, solved by Newton.
///
/// Second order, symplectic and symmetric: on a linear oscillator it conserves the energy exactly
/// (up to the Newton and linear-solve tolerances) for any step, so it is the energy-behaved implicit
/// choice for stiff conservative systems.
pub struct ImplicitMidpoint {
    params: NewtonParams,
    solver: Box<dyn LinearSolver>,
    core: NewtonCore,
}

impl ImplicitMidpoint {
    /// An implicit-midpoint integrator for `dof` degrees of freedom with the given linear solver.
    #[must_use]
    pub fn new(params: NewtonParams, solver: Box<dyn LinearSolver>, dof: usize) -> Self {
        let mut core = NewtonCore::default();
        core.resize(dof);
        Self { params, solver, core }
    }
}

impl<S: MechanicalSystem + ?Sized> Integrator<S> for ImplicitMidpoint {
    #[cfg(feature = "serde")]
    fn memory(&self) -> serde_json::Value {
        self.core.memory(Integrator::<S>::name(self))
    }

    #[cfg(feature = "serde")]
    fn restore_memory(&mut self, memory: &serde_json::Value) -> Result<(), IntegrateError> {
        self.core.restore_memory("implicit-midpoint", memory)
    }

    fn name(&self) -> &'static str {
        "implicit-midpoint"
    }

    fn step(&mut self, system: &mut S, state: &mut State, dt: f64) -> Result<StepInfo, IntegrateError> {
        let scheme = Scheme { alpha: 0.5, gamma: 0.25, eta: 0.5, zeta: 0.5, time: 0.5 };
        self.core.step(scheme, &self.params, self.solver.as_mut(), system, state, dt)
    }

    fn order(&self) -> u32 {
        2
    }

    fn symplectic(&self) -> bool {
        true
    }
}
