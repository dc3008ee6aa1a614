//! The pressure solvers: [`PressureSolver`] bound to one [`Poisson`] operator, by one of the
//! four [`PressureMethod`]s.
//!
//! - Jacobi and red-black Gauss-Seidel relax `A s = b` sweep by sweep, checking the relative
//!   residual `max |b - A s| / max |b|` every few sweeps; their iteration counts grow as `n^2`
//!   with the grid size `n`.
//! - Conjugate gradients (Hestenes and Stiefel 1952) minimise the `A`-norm of the error over
//!   growing Krylov spaces, `O(n)` iterations; with a preconditioner `M ~ A^-1` each iteration
//!   applies `z = M r` and the search directions become `M`-conjugate.
//! - MGPCG takes one multigrid V-cycle as `M` (McAdams, Sifakis and Teran 2010), which makes the
//!   iteration count nearly independent of `n`.
//!
//! When no fluid cell touches air, `A` is singular with the constants as null space: the
//! right-hand side, the residuals, the preconditioned residuals and the result are projected
//! onto the zero-mean subspace, where `A` is positive definite.

use super::multigrid::{Level, v_cycle};
use super::poisson::{CellLabel, Poisson};
use super::reduce::{CHUNK, dot, max_abs};
use crate::error::FluidError;
use rayon::prelude::*;

/// The pressure solve method. Serialised by its [`PressureMethod::name`] (`"jacobi"`,
/// `"rb-gauss-seidel"`, `"cg"`, `"mgpcg"`), as scene files name it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum PressureMethod {
    /// Jacobi iteration.
    #[serde(rename = "jacobi")]
    Jacobi,
    /// Red-black Gauss-Seidel.
    #[serde(rename = "rb-gauss-seidel")]
    RedBlackGaussSeidel,
    /// Conjugate gradients.
    #[serde(rename = "cg")]
    ConjugateGradient,
    /// Multigrid-preconditioned conjugate gradients.
    #[serde(rename = "mgpcg")]
    Mgpcg,
}

impl PressureMethod {
    /// All methods, in the order of the tables.
    pub const ALL: [PressureMethod; 4] =
        [Self::Jacobi, Self::RedBlackGaussSeidel, Self::ConjugateGradient, Self::Mgpcg];

    /// A short name for tables.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Jacobi => "jacobi",
            Self::RedBlackGaussSeidel => "rb-gauss-seidel",
            Self::ConjugateGradient => "cg",
            Self::Mgpcg => "mgpcg",
        }
    }
}

/// What a solve did.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SolveInfo {
    /// Iterations (sweeps for Jacobi and Gauss-Seidel, CG iterations otherwise).
    pub iterations: usize,
    /// Final residual `max |b - A s| / max |b|` (0 for a zero right-hand side).
    pub residual: f64,
    /// Whether the tolerance was reached.
    pub converged: bool,
}

/// A pressure solver bound to one [`Poisson`] operator, with every buffer it needs.
#[derive(Debug, Clone)]
pub struct PressureSolver {
    method: PressureMethod,
    /// Relative residual tolerance `max|b - A s| / max|b|`.
    tolerance: f64,
    /// Iteration cap.
    max_iterations: usize,
    pub(super) levels: Vec<Level>,
    r: Vec<f64>,
    z: Vec<f64>,
    p: Vec<f64>,
    q: Vec<f64>,
    b: Vec<f64>,
    partials: Vec<f64>,
}

impl PressureSolver {
    /// A solver for `op` by `method`, stopping at relative residual `tolerance` or after
    /// `max_iterations` (sweeps or CG iterations). A tolerance of 0 (or `f64::MIN_POSITIVE`,
    /// which [`crate::mac::MacParams`] accepts) runs exactly `max_iterations` sweeps of Jacobi or
    /// Gauss-Seidel without residual checks, like the fixed 20 of Stam's solver.
    ///
    /// # Errors
    /// [`FluidError::BadParameter`] for a negative or non-finite tolerance or zero iterations.
    pub fn new(
        op: Poisson,
        method: PressureMethod,
        tolerance: f64,
        max_iterations: usize,
    ) -> Result<Self, FluidError> {
        crate::error::non_negative("pressure tolerance", tolerance)?;
        if max_iterations == 0 {
            return Err(FluidError::BadParameter {
                name: "pressure max_iterations",
                requirement: "must be at least 1",
                value: "0".into(),
            });
        }
        let n = op.len();
        let mut levels = Vec::new();
        if method == PressureMethod::Mgpcg {
            let mut cur = op.clone();
            while let Some(c) = cur.coarsen() {
                let m = c.len();
                levels.push(Level {
                    op: c.clone(),
                    x: vec![0.0; m],
                    b: vec![0.0; m],
                    r: vec![0.0; m],
                    tmp: vec![0.0; m],
                });
                cur = c;
            }
            levels.insert(
                0,
                Level { op, x: vec![0.0; n], b: vec![0.0; n], r: vec![0.0; n], tmp: vec![0.0; n] },
            );
        } else {
            levels.push(Level { op, x: Vec::new(), b: Vec::new(), r: Vec::new(), tmp: vec![0.0; n] });
        }
        Ok(Self {
            method,
            tolerance,
            max_iterations,
            levels,
            r: vec![0.0; n],
            z: vec![0.0; n],
            p: vec![0.0; n],
            q: vec![0.0; n],
            b: vec![0.0; n],
            partials: vec![0.0; n.div_ceil(CHUNK) + 1],
        })
    }

    /// Rebinds the solver to new cell labels of the same grid: the operator and its multigrid
    /// hierarchy are rebuilt in their buffers, allocating nothing, and every buffer is cleared,
    /// so the solver is then exactly what [`PressureSolver::new`] builds for the new labels
    /// (the same solves, bit for bit).
    ///
    /// # Errors
    /// [`FluidError::BadLength`] if `labels` does not have one entry per cell; the solver is
    /// then unchanged.
    pub fn relabel(&mut self, labels: &[CellLabel]) -> Result<(), FluidError> {
        self.levels[0].op.relabel(labels)?;
        for l in 1..self.levels.len() {
            let (fine, coarse) = self.levels.split_at_mut(l);
            let (fine, coarse) = (&fine[l - 1].op, &mut coarse[0].op);
            fine.coarse_labels(coarse.dims, &mut coarse.labels);
            coarse.assemble();
        }
        for lv in &mut self.levels {
            for v in [&mut lv.x, &mut lv.b, &mut lv.r, &mut lv.tmp] {
                v.fill(0.0);
            }
        }
        for v in [&mut self.r, &mut self.z, &mut self.p, &mut self.q, &mut self.b, &mut self.partials] {
            v.fill(0.0);
        }
        Ok(())
    }

    /// The operator.
    #[must_use]
    pub fn operator(&self) -> &Poisson {
        &self.levels[0].op
    }

    /// The method.
    #[must_use]
    pub fn method(&self) -> PressureMethod {
        self.method
    }

    /// Number of multigrid levels (1 unless MGPCG).
    #[must_use]
    pub fn levels(&self) -> usize {
        self.levels.len()
    }

    /// Changes the tolerance and iteration cap.
    ///
    /// # Errors
    /// As [`PressureSolver::new`].
    pub fn set_tolerance(&mut self, tolerance: f64, max_iterations: usize) -> Result<(), FluidError> {
        crate::error::non_negative("pressure tolerance", tolerance)?;
        if max_iterations == 0 {
            return Err(FluidError::BadParameter {
                name: "pressure max_iterations",
                requirement: "must be at least 1",
                value: "0".into(),
            });
        }
        self.tolerance = tolerance;
        self.max_iterations = max_iterations;
        Ok(())
    }

    /// Solves `A s = rhs` for `s`, starting from the given `s` (non-fluid entries are set to 0).
    ///
    /// # Panics
    /// If `rhs` or `s` does not have one entry per cell (a programming error).
    #[track_caller]
    pub fn solve(&mut self, rhs: &[f64], s: &mut [f64]) -> SolveInfo {
        let n = self.levels[0].op.len();
        assert!(rhs.len() == n && s.len() == n, "pressure solve: arrays must have one entry per cell");
        // Right-hand side restricted to fluid cells, projected onto the range when singular.
        {
            let op = &self.levels[0].op;
            self.b
                .par_iter_mut()
                .zip(rhs.par_iter())
                .zip(op.diag.par_iter())
                .with_min_len(crate::grain::ENTRIES)
                .for_each(|((b, &r), &d)| {
                    *b = if d > 0.0 { r } else { 0.0 };
                });
            s.par_iter_mut().zip(op.diag.par_iter()).with_min_len(crate::grain::ENTRIES).for_each(
                |(x, &d)| {
                    if d <= 0.0 {
                        *x = 0.0;
                    }
                },
            );
            if op.singular {
                op.remove_mean(&mut self.b, &mut self.partials);
            }
        }
        let bnorm = max_abs(&self.b, &mut self.partials);
        if bnorm == 0.0 {
            s.fill(0.0);
            return SolveInfo { iterations: 0, residual: 0.0, converged: true };
        }
        match self.method {
            PressureMethod::Jacobi | PressureMethod::RedBlackGaussSeidel => self.relax(s, bnorm),
            PressureMethod::ConjugateGradient | PressureMethod::Mgpcg => self.pcg(s, bnorm),
        }
    }

    fn relative_residual(&mut self, s: &[f64], bnorm: f64) -> f64 {
        let op = &self.levels[0].op;
        op.residual(&self.b, s, &mut self.r);
        if op.singular {
            op.remove_mean(&mut self.r, &mut self.partials);
        }
        max_abs(&self.r, &mut self.partials) / bnorm
    }

    fn relax(&mut self, s: &mut [f64], bnorm: f64) -> SolveInfo {
        /// Sweeps between residual checks (even: Jacobi sweeps in pairs).
        const CHECK_EVERY: usize = 10;
        let fixed = self.tolerance <= f64::MIN_POSITIVE;
        let mut it = 0;
        while it < self.max_iterations {
            let Level { op, tmp, .. } = &mut self.levels[0];
            if self.method == PressureMethod::Jacobi {
                // Two sweeps per pass, `s -> tmp -> s`, so that no copy is needed; CHECK_EVERY is
                // even, so the residual is checked after the same sweeps as one at a time.
                op.jacobi_sweep(&self.b, s, tmp);
                it += 1;
                if it == self.max_iterations {
                    s.copy_from_slice(tmp);
                    break;
                }
                op.jacobi_sweep(&self.b, tmp, s);
                it += 1;
            } else {
                op.colour_sweep(0, &self.b, s, tmp);
                op.colour_sweep(1, &self.b, s, tmp);
                it += 1;
            }
            if !fixed && it % CHECK_EVERY == 0 && self.relative_residual(s, bnorm) <= self.tolerance {
                break;
            }
        }
        let op = &self.levels[0].op;
        if op.singular {
            op.remove_mean(s, &mut self.partials);
        }
        let residual = self.relative_residual(s, bnorm);
        SolveInfo { iterations: it, residual, converged: fixed || residual <= self.tolerance }
    }

    fn precondition(&mut self) {
        if self.method == PressureMethod::Mgpcg {
            self.levels[0].b.copy_from_slice(&self.r);
            v_cycle(&mut self.levels, 0);
            self.z.copy_from_slice(&self.levels[0].x);
            let op = &self.levels[0].op;
            if op.singular {
                op.remove_mean(&mut self.z, &mut self.partials);
            }
        } else {
            self.z.copy_from_slice(&self.r);
        }
    }

    fn pcg(&mut self, s: &mut [f64], bnorm: f64) -> SolveInfo {
        self.levels[0].op.residual(&self.b, s, &mut self.r);
        if self.levels[0].op.singular {
            self.levels[0].op.remove_mean(&mut self.r, &mut self.partials);
        }
        let mut residual = max_abs(&self.r, &mut self.partials) / bnorm;
        if residual <= self.tolerance {
            return SolveInfo { iterations: 0, residual, converged: true };
        }
        self.precondition();
        self.p.copy_from_slice(&self.z);
        let mut rz = dot(&self.r, &self.z, &mut self.partials);
        let mut it = 0;
        while it < self.max_iterations {
            self.levels[0].op.apply(&self.p, &mut self.q);
            let pq = dot(&self.p, &self.q, &mut self.partials);
            if !(pq > 0.0) {
                break;
            }
            let alpha = rz / pq;
            s.par_iter_mut()
                .zip(self.p.par_iter())
                .with_min_len(crate::grain::ENTRIES)
                .for_each(|(x, &p)| *x += alpha * p);
            self.r
                .par_iter_mut()
                .zip(self.q.par_iter())
                .with_min_len(crate::grain::ENTRIES)
                .for_each(|(r, &q)| *r -= alpha * q);
            it += 1;
            residual = max_abs(&self.r, &mut self.partials) / bnorm;
            if residual <= self.tolerance {
                break;
            }
            self.precondition();
            let rz_new = dot(&self.r, &self.z, &mut self.partials);
            let beta = rz_new / rz;
            rz = rz_new;
            self.p
                .par_iter_mut()
                .zip(self.z.par_iter())
                .with_min_len(crate::grain::ENTRIES)
                .for_each(|(p, &z)| *p = z + beta * *p);
        }
        if self.levels[0].op.singular {
            self.levels[0].op.remove_mean(s, &mut self.partials);
        }
        // The recurrence residual drifts from the true one; report the true one.
        let true_residual = self.relative_residual(s, bnorm);
        SolveInfo { iterations: it, residual: true_residual, converged: residual <= self.tolerance }
    }
}
