//! Newton's method on the incremental potential, with a backtracking line search.
//!
//! Backward Euler solves `M (x - x_n - dt v_n) / dt^2 = f_e(x) + f_d + f_ext` with
//! `v = (x - x_n) / dt`. Its solution minimises the **incremental potential**
//!
//! ```text
//! E(x) = 1/(2 dt^2) (x - x_hat)^T M (x - x_hat) + sum_e W_e psi(F_e(x)) - f_ext . x
//!        + gamma/(2 dt) (x - x_n)^T K_n (x - x_n) + sum_i kappa/2 min(phi(x_i), 0)^2
//!        + sum_contacts mu lambda f0(|T^T (x_i - x_n,i)|),
//! x_hat = x_n + dt v_n,
//! ```
//!
//! whose gradient is minus the backward Euler residual (the last sum is the lagged friction
//! potential of [`crate::friction`]). The Rayleigh damping force
//! `f_d = -gamma K v` uses here the stiffness `K_n = K(x_n)` at the start of the step (rather
//! than the stiffness at the current iterate); with `K_n` frozen, damping is a quadratic potential and
//! the whole step is a minimisation, so a line search on `E` is well defined and every accepted
//! iterate decreases it. Each Newton iteration solves
//!
//! ```text
//! (M / dt^2 + K(x_k) + gamma/dt K_n + contact) dx = -grad E(x_k)
//! ```
//!
//! (the usual `[(1 + gamma/dt) K + M/dt^2] dx = ...` with `K_n` in the damping term), then
//! halves the step until the Armijo condition `E(x + a dx) <= E(x) + 1e-4 a grad E . dx` holds.
//! With `dP/dF` projected to positive semi-definite per element (anim-material's `dpdf_psd`) the matrix
//! is positive definite and `dx` a descent direction. A quasi-static solve is the same
//! minimisation without the inertia and damping terms.
//!
//! Degrees of freedom marked fixed keep their value: their rows and columns of the matrix are
//! replaced by the identity and their gradient entries by zero.

use crate::boundary::Colliders;
use crate::error::FemError;
use crate::friction::FrictionContact;
use anim_core::linalg::{CsrMatrix, LinearSolver, SystemMatrix, dot};
use rayon::prelude::*;

use crate::assembly::Assembly;

/// Elements per rayon task in element loops.
const ELEMENT_CHUNK: usize = 256;

/// A body made of elements whose energy, gradient and Hessian can be evaluated one element at a
/// time (linear and quadratic tetrahedra).
pub trait ElasticBody: Sync {
    /// Number of elements.
    fn elements(&self) -> usize;
    /// Nodes per element.
    fn per_element(&self) -> usize;
    /// The element's energy `W psi(F)` (summed over quadrature points) at the positions `x`
    /// (flat, 3 per node). When `grad` is given it receives `d energy / d x_e` (3 per element
    /// node); when `hess` is given it receives the element Hessian (row-major, `(3n)^2`), with
    /// `dP/dF` projected to positive semi-definite first when `project` is set.
    fn element(
        &self,
        e: usize,
        x: &[f64],
        grad: Option<&mut [f64]>,
        hess: Option<&mut [f64]>,
        project: bool,
    ) -> f64;
    /// `det F` of the element (the smallest over its quadrature points), for error messages.
    fn det_f(&self, e: usize, x: &[f64]) -> f64;
}

/// The terms of the potential besides the elastic energy.
pub struct Potential<'a> {
    /// `1/dt^2` and `x_hat` for the inertia term (absent in a quasi-static solve).
    pub inertia: Option<(f64, &'a [f64])>,
    /// Lumped (per node) masses, used when `consistent_mass` is `None`.
    pub lumped_mass: &'a [f64],
    /// Consistent mass matrix (same pattern as the stiffness).
    pub consistent_mass: Option<&'a CsrMatrix>,
    /// `gamma/dt` and `x_n` for the Rayleigh damping term (with `K_n` in the scratch data).
    pub damping: Option<(f64, &'a [f64])>,
    /// External force (gravity and nodal loads), constant over the step.
    pub external: &'a [f64],
    /// Obstacles (shapes and meshes; their friction coefficients are not read here).
    pub obstacles: Colliders<'a>,
    /// Penalty stiffness.
    pub contact_stiffness: f64,
    /// Lagged friction contacts of the step (empty: frictionless), see [`crate::friction`].
    pub friction: &'a [FrictionContact],
    /// Fixed degrees of freedom.
    pub fixed: &'a [bool],
    /// Project `dP/dF` to positive semi-definite.
    pub project: bool,
}

/// Stopping rule.
#[derive(Debug, Clone, Copy)]
pub struct NewtonSettings {
    /// Converged when `||a dx||_inf <= tolerance` (length units).
    pub tolerance: f64,
    /// Iteration cap.
    pub max_iterations: usize,
    /// Step counter for error messages.
    pub step: u64,
}

/// What a minimisation did.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct NewtonInfo {
    /// Newton iterations.
    pub iterations: usize,
    /// Linear-solver iterations summed over Newton iterations.
    pub linear_iterations: usize,
    /// Infinity norm of the last accepted update.
    pub last_update: f64,
    /// Final value of the potential.
    pub energy: f64,
}

/// Scratch buffers of the Newton solver, sized once for a body.
#[derive(Debug, Clone)]
pub struct NewtonData {
    elem_energy: Vec<f64>,
    elem_grad: Vec<f64>,
    elem_hess: Vec<f64>,
    /// Gradient of the potential.
    pub grad: Vec<f64>,
    dx: Vec<f64>,
    rhs: Vec<f64>,
    trial: Vec<f64>,
    tmp: Vec<f64>,
    tmp2: Vec<f64>,
    contact_hess: Vec<[f64; 9]>,
    /// Elastic stiffness `K(x)` (also used as a scratch for `K_n`).
    pub k: CsrMatrix,
    /// `K_n`, the stiffness at the start of the step (Rayleigh damping).
    pub k_n: CsrMatrix,
    /// The Newton matrix.
    pub h: CsrMatrix,
}

impl NewtonData {
    /// Buffers for `elements` elements of `per_element` nodes on `assembly`'s pattern.
    #[must_use]
    pub fn new(assembly: &Assembly, elements: usize) -> Self {
        let n = 3 * assembly.nodes();
        let ne = 3 * assembly.per_element();
        Self {
            elem_energy: vec![0.0; elements],
            elem_grad: vec![0.0; elements * ne],
            elem_hess: vec![0.0; elements * ne * ne],
            grad: vec![0.0; n],
            dx: vec![0.0; n],
            rhs: vec![0.0; n],
            trial: vec![0.0; n],
            tmp: vec![0.0; n],
            tmp2: vec![0.0; n],
            contact_hess: vec![[0.0; 9]; assembly.nodes()],
            k: assembly.matrix(),
            k_n: assembly.matrix(),
            h: assembly.matrix(),
        }
    }
}

impl NewtonData {
    /// Assembles the projected stiffness at `x` into [`k_n`](Self::k_n) (the Rayleigh damping
    /// matrix of the step).
    pub fn assemble_reference_stiffness<B: ElasticBody>(&mut self, body: &B, asm: &Assembly, x: &[f64]) {
        assemble_stiffness(body, asm, x, true, &mut self.elem_hess, &mut self.k_n);
    }
}

/// Sum of element energies at `x`, or the first element whose energy is not finite.
fn elastic_energy<B: ElasticBody>(body: &B, x: &[f64], buf: &mut [f64]) -> Result<f64, usize> {
    buf.par_chunks_mut(ELEMENT_CHUNK).enumerate().for_each(|(c, out)| {
        for (k, o) in out.iter_mut().enumerate() {
            *o = body.element(c * ELEMENT_CHUNK + k, x, None, None, false);
        }
    });
    sum_checked(buf)
}

/// Sequential sum (fixed order); `Err(index)` of the first non-finite entry.
fn sum_checked(values: &[f64]) -> Result<f64, usize> {
    let s: f64 = values.iter().sum();
    if s.is_finite() { Ok(s) } else { Err(values.iter().position(|v| !v.is_finite()).unwrap_or(0)) }
}

/// Elastic energy and its gradient (assembled into `grad`).
fn elastic_gradient<B: ElasticBody>(
    body: &B,
    asm: &Assembly,
    x: &[f64],
    data: &mut NewtonData,
) -> Result<f64, usize> {
    let ne = 3 * body.per_element();
    data.elem_energy
        .par_chunks_mut(ELEMENT_CHUNK)
        .zip(data.elem_grad.par_chunks_mut(ELEMENT_CHUNK * ne))
        .enumerate()
        .for_each(|(c, (en, gr))| {
            for (k, (o, g)) in en.iter_mut().zip(gr.chunks_mut(ne)).enumerate() {
                *o = body.element(c * ELEMENT_CHUNK + k, x, Some(g), None, false);
            }
        });
    let e = sum_checked(&data.elem_energy)?;
    asm.gather_vector(&data.elem_grad, &mut data.grad);
    Ok(e)
}

/// Assembles the elastic stiffness at `x` into `out`.
pub fn assemble_stiffness<B: ElasticBody>(
    body: &B,
    asm: &Assembly,
    x: &[f64],
    project: bool,
    elem_hess: &mut [f64],
    out: &mut CsrMatrix,
) {
    let ne = 3 * body.per_element();
    let nn = ne * ne;
    elem_hess.par_chunks_mut(ELEMENT_CHUNK * nn).enumerate().for_each(|(c, hs)| {
        for (k, h) in hs.chunks_mut(nn).enumerate() {
            h.fill(0.0);
            body.element(c * ELEMENT_CHUNK + k, x, None, Some(h), project);
        }
    });
    asm.gather_matrix(elem_hess, out);
}

/// The penalty contact energy, adding its gradient to `grad` when given and writing its nodal
/// Hessian blocks into `hess` when given.
fn contact_terms(
    pot: &Potential<'_>,
    x: &[f64],
    mut grad: Option<&mut [f64]>,
    mut hess: Option<&mut [[f64; 9]]>,
) -> f64 {
    if pot.obstacles.is_empty() {
        return 0.0;
    }
    let k = pot.contact_stiffness;
    let mut energy = 0.0;
    for i in 0..x.len() / 3 {
        let p = [x[3 * i], x[3 * i + 1], x[3 * i + 2]];
        let mut block = [0.0; 9];
        for (o, _) in pot.obstacles.iter() {
            if let Some((e, g_o, h_o)) = o.penalty(k, p) {
                energy += e;
                if let Some(g) = grad.as_deref_mut() {
                    for c in 0..3 {
                        g[3 * i + c] += g_o[c];
                    }
                }
                for (b, h) in block.iter_mut().zip(h_o) {
                    *b += h;
                }
            }
        }
        if let Some(h) = hess.as_deref_mut() {
            h[i] = block;
        }
    }
    for contact in pot.friction {
        let i = contact.vertex;
        let p = [x[3 * i], x[3 * i + 1], x[3 * i + 2]];
        let mut g = [0.0; 3];
        let mut block = [0.0; 9];
        energy +=
            contact.potential(p, grad.is_some().then_some(&mut g), hess.is_some().then_some(&mut block));
        if let Some(gr) = grad.as_deref_mut() {
            for c in 0..3 {
                gr[3 * i + c] += g[c];
            }
        }
        if let Some(h) = hess.as_deref_mut() {
            for (hv, b) in h[i].iter_mut().zip(&block) {
                *hv += b;
            }
        }
    }
    energy
}

/// `out = M y` with the lumped or consistent mass.
fn mass_apply(pot: &Potential<'_>, y: &[f64], out: &mut [f64]) {
    match pot.consistent_mass {
        Some(m) => m.mul_vec(y, out),
        None => {
            for (i, o) in out.chunks_mut(3).enumerate() {
                let m = pot.lumped_mass[i];
                for c in 0..3 {
                    o[c] = m * y[3 * i + c];
                }
            }
        }
    }
}

/// The full potential at `x`; with `with_grad`, its gradient in `data.grad` (fixed entries 0).
fn potential<B: ElasticBody>(
    body: &B,
    asm: &Assembly,
    pot: &Potential<'_>,
    x: &[f64],
    data: &mut NewtonData,
    with_grad: bool,
) -> Result<f64, usize> {
    let mut e = if with_grad {
        elastic_gradient(body, asm, x, data)?
    } else {
        elastic_energy(body, x, &mut data.elem_energy)?
    };
    if let Some((inv_dt2, xhat)) = pot.inertia {
        for ((t, xi), hi) in data.tmp.iter_mut().zip(x).zip(xhat) {
            *t = xi - hi;
        }
        mass_apply(pot, &data.tmp, &mut data.tmp2);
        e += 0.5 * inv_dt2 * dot(&data.tmp, &data.tmp2);
        if with_grad {
            for (g, m) in data.grad.iter_mut().zip(&data.tmp2) {
                *g += inv_dt2 * m;
            }
        }
    }
    if let Some((c, xn)) = pot.damping {
        for ((t, xi), ni) in data.tmp.iter_mut().zip(x).zip(xn) {
            *t = xi - ni;
        }
        data.k_n.mul_vec(&data.tmp, &mut data.tmp2);
        e += 0.5 * c * dot(&data.tmp, &data.tmp2);
        if with_grad {
            for (g, m) in data.grad.iter_mut().zip(&data.tmp2) {
                *g += c * m;
            }
        }
    }
    e -= dot(pot.external, x);
    if with_grad {
        for (g, f) in data.grad.iter_mut().zip(pot.external) {
            *g -= f;
        }
        e += contact_terms(pot, x, Some(&mut data.grad), None);
        for (g, &fixed) in data.grad.iter_mut().zip(pot.fixed) {
            if fixed {
                *g = 0.0;
            }
        }
    } else {
        e += contact_terms(pot, x, None, None);
    }
    if e.is_finite() { Ok(e) } else { Err(0) }
}

/// Assembles the Newton matrix at `x` into `data.h`.
fn newton_matrix<B: ElasticBody>(
    body: &B,
    asm: &Assembly,
    pot: &Potential<'_>,
    x: &[f64],
    data: &mut NewtonData,
) {
    assemble_stiffness(body, asm, x, pot.project, &mut data.elem_hess, &mut data.k);
    contact_terms(pot, x, None, Some(&mut data.contact_hess));
    let inv_dt2 = pot.inertia.map_or(0.0, |(c, _)| c);
    let damp = pot.damping.map_or(0.0, |(c, _)| c);
    let rows = asm.entry_rows();
    let cols = data.k.col_idx();
    let kv = data.k.values();
    let knv = data.k_n.values();
    let mv = pot.consistent_mass.map(CsrMatrix::values);
    let contact = !pot.obstacles.is_empty();
    let hv = data.h.values_mut();
    let body_fn = |(p, h): (usize, &mut f64)| {
        let r = rows[p] as usize;
        let c = cols[p];
        if pot.fixed[r] || pot.fixed[c] {
            *h = if r == c { 1.0 } else { 0.0 };
            return;
        }
        let mut v = kv[p];
        if damp != 0.0 {
            v += damp * knv[p];
        }
        if inv_dt2 != 0.0 {
            match mv {
                Some(m) => v += inv_dt2 * m[p],
                None => {
                    if r == c {
                        v += inv_dt2 * pot.lumped_mass[r / 3];
                    }
                }
            }
        }
        if contact && r / 3 == c / 3 {
            v += data.contact_hess[r / 3][3 * (r % 3) + c % 3];
        }
        *h = v;
    };
    if hv.len() >= 4096 {
        hv.par_iter_mut().enumerate().for_each(body_fn);
    } else {
        hv.iter_mut().enumerate().for_each(body_fn);
    }
}

/// Minimises the potential from the initial guess `x` (fixed entries already at their values).
///
/// # Errors
/// [`FemError::NonFiniteElement`] when the initial guess has an element with non-finite energy,
/// [`FemError::LinearSolve`], [`FemError::LineSearch`] or [`FemError::NewtonNotConverged`].
pub fn minimize<B: ElasticBody>(
    body: &B,
    asm: &Assembly,
    pot: &Potential<'_>,
    x: &mut [f64],
    data: &mut NewtonData,
    solver: &mut dyn LinearSolver,
    settings: NewtonSettings,
) -> Result<NewtonInfo, FemError> {
    let step = settings.step;
    let non_finite = |element: usize, x: &[f64]| FemError::NonFiniteElement {
        step,
        element,
        det_f: body.det_f(element, x),
    };
    let mut energy = potential(body, asm, pot, x, data, true).map_err(|e| non_finite(e, x))?;
    let mut info = NewtonInfo::default();
    for iteration in 0..settings.max_iterations {
        newton_matrix(body, asm, pot, x, data);
        for (r, g) in data.rhs.iter_mut().zip(&data.grad) {
            *r = -g;
        }
        data.dx.fill(0.0);
        let solve = solver
            .solve(SystemMatrix::Csr(&data.h), &data.rhs, &mut data.dx)
            .map_err(|source| FemError::LinearSolve { step, iteration, source })?;
        info.linear_iterations += solve.iterations;
        info.iterations = iteration + 1;
        let update = data.dx.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let slope = dot(&data.grad, &data.dx);
        let mut alpha = 1.0;
        let mut halvings = 0;
        loop {
            for ((t, xi), d) in data.trial.iter_mut().zip(x.iter()).zip(&data.dx) {
                *t = xi + alpha * d;
            }
            let trial = std::mem::take(&mut data.trial);
            let e_trial = potential(body, asm, pot, &trial, data, false).unwrap_or(f64::INFINITY);
            data.trial = trial;
            // Within the tolerance the full step is taken: the energy then differs from the
            // current one only by rounding.
            if e_trial <= energy + 1e-4 * alpha * slope || alpha * update <= settings.tolerance {
                break;
            }
            alpha *= 0.5;
            halvings += 1;
            if halvings > 40 {
                return Err(FemError::LineSearch { step, iteration, halvings });
            }
        }
        x.copy_from_slice(&data.trial);
        energy = potential(body, asm, pot, x, data, true).map_err(|e| non_finite(e, x))?;
        info.last_update = alpha * update;
        info.energy = energy;
        if alpha * update <= settings.tolerance {
            return Ok(info);
        }
    }
    Err(FemError::NewtonNotConverged {
        step,
        iterations: settings.max_iterations,
        update: info.last_update,
        tolerance: settings.tolerance,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::boundary::Obstacle;
    use crate::friction::lagged_contacts;
    use crate::generate::box_mesh;
    use crate::material::{Material, MaterialModel};
    use crate::model::FemModel;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// The assembled potential of a step with inertia, penalty contact on a tilted plane and
    /// lagged friction (four contact vertices, tangential displacements on both sides of the
    /// smoothing threshold): its gradient against central differences of the energy, and the
    /// Newton matrix (no PSD projection, so the exact Hessian: the friction Hessian is PSD
    /// without clamping) against central differences of the gradient, column by column.
    #[test]
    fn potential_with_friction_matches_finite_differences() {
        let mesh = box_mesh([0.0; 3], [0.1; 3], [1, 1, 1]).unwrap();
        let material = Material::new(MaterialModel::StableNeoHookean, 1e5, 0.3, 1000.0).unwrap();
        let mut model = FemModel::new(mesh, material).unwrap();
        let theta = 0.3_f64;
        let (s, c) = theta.sin_cos();
        let plane = Obstacle::Plane { point: [0.04 * s, 0.0, 0.04 * c], normal: [s, 0.0, c] };
        model.add_obstacle_with_friction(plane, 1e4, 0.4).unwrap();
        let xn = model.rest_positions();
        let n = xn.len();
        let fixed = vec![false; n];
        let threshold = 1.5e-3;
        let mut contacts = Vec::new();
        lagged_contacts(model.colliders(), 1e4, threshold, &xn, &fixed, &mut contacts);
        assert_eq!(contacts.len(), 4, "the four bottom vertices penetrate at x_n");
        let dt = 0.01;
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let xhat: Vec<f64> = xn.iter().map(|v| v + 1e-3 * rng.random_range(-1.0..1.0)).collect();
        let external = vec![0.0; n];
        let pot = Potential {
            inertia: Some((1.0 / (dt * dt), &xhat)),
            lumped_mass: model.lumped_mass(),
            consistent_mass: None,
            damping: None,
            external: &external,
            obstacles: model.colliders(),
            contact_stiffness: model.contact_stiffness(),
            friction: &contacts,
            fixed: &fixed,
            project: false,
        };
        let asm = model.assembly();
        let mut data = NewtonData::new(asm, model.elements());
        let x: Vec<f64> = xn.iter().map(|v| v + 2.5e-3 * rng.random_range(-1.0..1.0)).collect();
        let ys: Vec<f64> = contacts
            .iter()
            .map(|c| {
                let d: Vec<f64> = (0..3).map(|k| x[3 * c.vertex + k] - c.start[k]).collect();
                c.basis.iter().map(|t| (t[0] * d[0] + t[1] * d[1] + t[2] * d[2]).powi(2)).sum::<f64>().sqrt()
            })
            .collect();
        assert!(
            ys.iter().any(|&y| y < threshold) && ys.iter().any(|&y| y > threshold),
            "both friction regimes: {ys:?}"
        );
        potential(&model, asm, &pot, &x, &mut data, true).unwrap();
        let grad = data.grad.clone();
        newton_matrix(&model, asm, &pot, &x, &mut data);
        let h_scale = data.h.values().iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let g_scale = grad.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let step = 1e-7;
        let mut xp = x.clone();
        let mut unit = vec![0.0; n];
        let mut column = vec![0.0; n];
        for d in 0..n {
            xp[d] = x[d] + step;
            let ep = potential(&model, asm, &pot, &xp, &mut data, true).unwrap();
            let gp = data.grad.clone();
            xp[d] = x[d] - step;
            let em = potential(&model, asm, &pot, &xp, &mut data, true).unwrap();
            let gm = data.grad.clone();
            xp[d] = x[d];
            let fd = (ep - em) / (2.0 * step);
            assert!((fd - grad[d]).abs() <= 1e-6 * g_scale, "gradient {d}: {fd} vs {}", grad[d]);
            unit[d] = 1.0;
            data.h.mul_vec(&unit, &mut column);
            unit[d] = 0.0;
            for r in 0..n {
                let fdh = (gp[r] - gm[r]) / (2.0 * step);
                assert!(
                    (fdh - column[r]).abs() <= 1e-6 * h_scale,
                    "hessian ({r}, {d}): {fdh} vs {}",
                    column[r]
                );
            }
        }
    }
}
