//! Preconditioned conjugate gradients (PCG) for symmetric positive definite systems.
//!
//! # Method
//!
//! For `A x = b` with `A` symmetric positive definite (SPD), conjugate gradients minimises the
//! energy norm of the error over the growing Krylov space `x_0 + span{r_0, A r_0, A^2 r_0, ...}`.
//! With a preconditioner `M ~ A` (SPD, cheap to invert), the textbook iteration
//! (Saad, *Iterative Methods for Sparse Linear Systems*, 2nd ed., Algorithm 9.1; Shewchuk,
//! *An Introduction to the Conjugate Gradient Method Without the Agonizing Pain*, 1994, B3) is
//!
//! ```text
//! r_0 = b - A x_0,   z_0 = M^-1 r_0,   p_0 = z_0
//! for k = 0, 1, ...
//!     alpha_k   = (r_k . z_k) / (p_k . A p_k)
//!     x_{k+1}   = x_k + alpha_k p_k
//!     r_{k+1}   = r_k - alpha_k A p_k
//!     z_{k+1}   = M^-1 r_{k+1}
//!     beta_k    = (r_{k+1} . z_{k+1}) / (r_k . z_k)
//!     p_{k+1}   = z_{k+1} + beta_k p_k
//! ```
//!
//! [`Preconditioner::Identity`] is `M = I` (plain CG); [`Preconditioner::Jacobi`] is
//! `M = diag(A)`, which removes bad row scaling (e.g. very different masses in one system).
//!
//! # Stopping and failure
//!
//! The iteration stops when `||r|| <= tolerance * ||b||` ([`IterativeParams`]). Because the
//! recursively updated residual `r_k` drifts from the true residual `b - A x_k` in floating
//! point, convergence of `r_k` is confirmed by recomputing `b - A x_k`; if the true residual is
//! still too large, the iteration restarts from it (this costs one extra product per
//! confirmation). The reported residual is always the true one.
//!
//! - `b = 0`: `x = 0` immediately, 0 iterations.
//! - `p^T A p <= 0`: [`SolveError::NotPositiveDefinite`] (`A` is not SPD).
//! - a Jacobi diagonal entry `<= 0` (or NaN): [`SolveError::BadPivot`].
//! - an operator without a diagonal under Jacobi: [`SolveError::NoDiagonal`].
//! - NaN or infinity in `b`, `x_0` or the iteration: [`SolveError::NonFinite`].
//! - `max_iterations` reached: [`SolveError::NotConverged`]; `x` holds the last iterate.
//!
//! Scratch vectors live in [`Cg`] and are resized only when the system size changes, so repeated
//! solves of one size do not allocate.

use super::{
    IterativeParams, LinearOperator, LinearSolver, SolveError, SolveInfo, SystemMatrix, axpy, dot, norm,
};

/// The preconditioner `M` of [`Cg`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Preconditioner {
    /// `M = I`: plain conjugate gradients.
    Identity,
    /// `M = diag(A)`: Jacobi (diagonal) preconditioning; needs the operator diagonal, which must
    /// be strictly positive.
    Jacobi,
}

/// Conjugate gradients with an optional Jacobi preconditioner (see the [module docs](self)).
#[derive(Debug, Clone)]
pub struct Cg {
    preconditioner: Preconditioner,
    params: IterativeParams,
    /// Ask callers for the assembled matrix instead of the matrix-free operator.
    assembled: bool,
    /// Residual `r = b - A x`.
    r: Vec<f64>,
    /// Preconditioned residual `z = M^-1 r`.
    z: Vec<f64>,
    /// Search direction.
    p: Vec<f64>,
    /// `A p` (also `A x` when recomputing the residual).
    ap: Vec<f64>,
    /// `1 / diag(A)` under Jacobi preconditioning.
    inv_diag: Vec<f64>,
    /// `b / max|b_i|`.
    b_scaled: Vec<f64>,
}

impl Cg {
    /// A solver with the given preconditioner and stopping rule.
    #[must_use]
    pub fn new(preconditioner: Preconditioner, params: IterativeParams) -> Self {
        Self {
            preconditioner,
            params,
            assembled: false,
            r: Vec::new(),
            z: Vec::new(),
            p: Vec::new(),
            ap: Vec::new(),
            inv_diag: Vec::new(),
            b_scaled: Vec::new(),
        }
    }

    /// The same solver, asking for the assembled (CSR) matrix: the product then runs over stored
    /// entries instead of the system's matrix-free product, which pays when assembly is cheap
    /// and the product is applied many times.
    #[must_use]
    pub fn assembled(mut self) -> Self {
        self.assembled = true;
        self
    }

    /// The preconditioner.
    #[must_use]
    pub fn preconditioner(&self) -> Preconditioner {
        self.preconditioner
    }

    /// The stopping rule.
    #[must_use]
    pub fn params(&self) -> IterativeParams {
        self.params
    }

    fn resize(&mut self, n: usize) {
        if self.r.len() != n {
            self.r.resize(n, 0.0);
            self.z.resize(n, 0.0);
            self.p.resize(n, 0.0);
            self.ap.resize(n, 0.0);
        }
    }

    /// Fills `inv_diag` with `1 / diag(A)`, checking that the diagonal is positive.
    fn prepare_jacobi(&mut self, a: &dyn LinearOperator, n: usize) -> Result<(), SolveError> {
        if self.inv_diag.len() != n {
            self.inv_diag.resize(n, 0.0);
        }
        if !a.diagonal(&mut self.inv_diag) {
            return Err(SolveError::NoDiagonal);
        }
        for (row, d) in self.inv_diag.iter_mut().enumerate() {
            // `!(d > 0)` also rejects NaN.
            if !(*d > 0.0) || !d.is_finite() {
                return Err(SolveError::BadPivot { row, value: *d });
            }
            *d = 1.0 / *d;
        }
        Ok(())
    }

    /// `z = M^-1 r`.
    fn precondition(&mut self) {
        match self.preconditioner {
            Preconditioner::Identity => self.z.copy_from_slice(&self.r),
            Preconditioner::Jacobi => {
                for ((z, r), d) in self.z.iter_mut().zip(&self.r).zip(&self.inv_diag) {
                    *z = r * d;
                }
            }
        }
    }

    /// `r = b - A x`.
    fn true_residual(&mut self, a: &dyn LinearOperator, b: &[f64], x: &[f64]) {
        a.apply(x, &mut self.ap);
        for ((r, bi), ax) in self.r.iter_mut().zip(b).zip(&self.ap) {
            *r = bi - ax;
        }
    }

    /// `z = M^-1 r`, `p = z`; returns `r . z`.
    fn restart_direction(&mut self) -> f64 {
        self.precondition();
        self.p.copy_from_slice(&self.z);
        dot(&self.r, &self.z)
    }

    /// Solves with `b` and `x` scaled by `1 / max|b_i|`, so that `p^T A p` neither underflows
    /// (a right-hand side of 1e-200 is a legitimate request) nor overflows; the iteration is
    /// scale invariant, so the iterates are the same up to rounding.
    fn solve_operator(
        &mut self,
        a: &dyn LinearOperator,
        b: &[f64],
        x: &mut [f64],
    ) -> Result<SolveInfo, SolveError> {
        let n = a.dim();
        assert_eq!(b.len(), n, "Cg::solve: b.len() != dim");
        assert_eq!(x.len(), n, "Cg::solve: x.len() != dim");
        let scale = b.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        if !scale.is_finite() || b.iter().any(|v| v.is_nan()) {
            return Err(SolveError::NonFinite { iteration: 0 });
        }
        if scale == 0.0 {
            x.fill(0.0);
            return Ok(SolveInfo { iterations: 0, relative_residual: 0.0 });
        }
        let mut b_scaled = std::mem::take(&mut self.b_scaled);
        b_scaled.clear();
        b_scaled.extend(b.iter().map(|v| v / scale));
        x.iter_mut().for_each(|v| *v /= scale);
        let result = self.solve_unit(a, &b_scaled, x);
        x.iter_mut().for_each(|v| *v *= scale);
        self.b_scaled = b_scaled;
        result
    }

    /// Preconditioned CG on a right-hand side with `max|b_i| = 1`.
    fn solve_unit(
        &mut self,
        a: &dyn LinearOperator,
        b: &[f64],
        x: &mut [f64],
    ) -> Result<SolveInfo, SolveError> {
        let n = a.dim();
        let b_norm = norm(b);
        self.resize(n);
        if self.preconditioner == Preconditioner::Jacobi {
            self.prepare_jacobi(a, n)?;
        }
        let tol = self.params.tolerance;
        self.true_residual(a, b, x);
        let mut rel = norm(&self.r) / b_norm;
        if !rel.is_finite() {
            return Err(SolveError::NonFinite { iteration: 0 });
        }
        if rel <= tol {
            return Ok(SolveInfo { iterations: 0, relative_residual: rel });
        }
        let mut rz = self.restart_direction();
        for k in 1..=self.params.max_iterations {
            a.apply(&self.p, &mut self.ap);
            let curvature = dot(&self.p, &self.ap);
            if !curvature.is_finite() {
                return Err(SolveError::NonFinite { iteration: k });
            }
            if curvature <= 0.0 {
                return Err(SolveError::NotPositiveDefinite { iteration: k, curvature });
            }
            let alpha = rz / curvature;
            axpy(alpha, &self.p, x);
            axpy(-alpha, &self.ap, &mut self.r);
            rel = norm(&self.r) / b_norm;
            if !rel.is_finite() {
                return Err(SolveError::NonFinite { iteration: k });
            }
            if rel <= tol {
                // Confirm with the true residual; restart from it if the recursion drifted.
                self.true_residual(a, b, x);
                rel = norm(&self.r) / b_norm;
                if !rel.is_finite() {
                    return Err(SolveError::NonFinite { iteration: k });
                }
                if rel <= tol {
                    return Ok(SolveInfo { iterations: k, relative_residual: rel });
                }
                rz = self.restart_direction();
                continue;
            }
            self.precondition();
            let rz_new = dot(&self.r, &self.z);
            let beta = rz_new / rz;
            rz = rz_new;
            for (p, z) in self.p.iter_mut().zip(&self.z) {
                *p = z + beta * *p;
            }
        }
        // Report the true residual of the last iterate.
        self.true_residual(a, b, x);
        let relative_residual = norm(&self.r) / b_norm;
        Err(SolveError::NotConverged { iterations: self.params.max_iterations, relative_residual })
    }
}

impl LinearSolver for Cg {
    fn name(&self) -> &'static str {
        match (self.preconditioner, self.assembled) {
            (Preconditioner::Identity, false) => "cg",
            (Preconditioner::Jacobi, false) => "jacobi-pcg",
            (Preconditioner::Identity, true) => "cg-assembled",
            (Preconditioner::Jacobi, true) => "jacobi-pcg-assembled",
        }
    }

    fn needs_matrix(&self) -> bool {
        self.assembled
    }

    fn solve(&mut self, a: SystemMatrix<'_>, b: &[f64], x: &mut [f64]) -> Result<SolveInfo, SolveError> {
        match a {
            SystemMatrix::Operator(op) => self.solve_operator(op, b, x),
            SystemMatrix::Csr(m) => self.solve_operator(m, b, x),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linalg::CsrMatrix;
    use faer::Mat;
    use faer::prelude::Solve;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// 2D Poisson (5-point Laplacian, Dirichlet) on an `m x m` grid, scaled rows optional.
    fn poisson_2d(m: usize) -> CsrMatrix {
        let idx = |i: usize, j: usize| i * m + j;
        let mut t = Vec::new();
        for i in 0..m {
            for j in 0..m {
                t.push((idx(i, j), idx(i, j), 4.0));
                if i > 0 {
                    t.push((idx(i, j), idx(i - 1, j), -1.0));
                }
                if i + 1 < m {
                    t.push((idx(i, j), idx(i + 1, j), -1.0));
                }
                if j > 0 {
                    t.push((idx(i, j), idx(i, j - 1), -1.0));
                }
                if j + 1 < m {
                    t.push((idx(i, j), idx(i, j + 1), -1.0));
                }
            }
        }
        CsrMatrix::from_triplets(m * m, m * m, &t)
    }

    /// Random sparse SPD matrix `B^T B + D` with a widely varying diagonal `D`.
    fn random_spd(rng: &mut ChaCha8Rng, n: usize, spread: f64) -> CsrMatrix {
        let mut bt = Vec::new();
        for i in 0..n {
            for _ in 0..3 {
                bt.push((i, rng.random_range(0..n), rng.random_range(-1.0..1.0)));
            }
        }
        let b = CsrMatrix::from_triplets(n, n, &bt).to_dense();
        let mut t = Vec::new();
        for i in 0..n {
            for j in 0..n {
                let v: f64 = (0..n).map(|k| b[k][i] * b[k][j]).sum();
                if v != 0.0 {
                    t.push((i, j, v));
                }
            }
            let scale = spread.powf(rng.random_range(0.0..1.0));
            t.push((i, i, scale));
        }
        CsrMatrix::from_triplets(n, n, &t)
    }

    /// Independent reference: faer's dense LU.
    fn dense_solve(a: &CsrMatrix, b: &[f64]) -> Vec<f64> {
        let d = a.to_dense();
        let n = b.len();
        let m = Mat::<f64>::from_fn(n, n, |i, j| d[i][j]);
        let rhs = Mat::<f64>::from_fn(n, 1, |i, _| b[i]);
        let x = m.partial_piv_lu().solve(&rhs);
        (0..n).map(|i| x[(i, 0)]).collect()
    }

    fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
        a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max)
    }

    /// An operator that hides its diagonal (matrix-free).
    struct NoDiag<'a>(&'a CsrMatrix);
    impl LinearOperator for NoDiag<'_> {
        fn dim(&self) -> usize {
            self.0.nrows()
        }
        fn apply(&self, x: &[f64], y: &mut [f64]) {
            self.0.mul_vec(x, y);
        }
    }

    #[test]
    fn cg_matches_dense_solve() {
        let mut rng = ChaCha8Rng::seed_from_u64(10);
        for (a, tol) in [(poisson_2d(12), 1e-12), (random_spd(&mut rng, 60, 10.0), 1e-12)] {
            let n = a.nrows();
            let b: Vec<f64> = (0..n).map(|_| rng.random_range(-1.0..1.0)).collect();
            let reference = dense_solve(&a, &b);
            for pre in [Preconditioner::Identity, Preconditioner::Jacobi] {
                let mut cg = Cg::new(pre, IterativeParams::new(tol, 10 * n));
                let mut x = vec![0.0; n];
                let info = cg.solve(SystemMatrix::Csr(&a), &b, &mut x).expect("converges");
                assert!(info.relative_residual <= tol);
                assert!(info.iterations > 0 && info.iterations <= 10 * n);
                let ref_norm = norm(&reference);
                assert!(
                    max_abs_diff(&x, &reference) <= 1e-9 * ref_norm,
                    "{pre:?}: error {}",
                    max_abs_diff(&x, &reference)
                );
                // The reported residual is the true one.
                let mut ax = vec![0.0; n];
                a.mul_vec(&x, &mut ax);
                let r: Vec<f64> = b.iter().zip(&ax).map(|(b, ax)| b - ax).collect();
                assert!((norm(&r) / norm(&b) - info.relative_residual).abs() <= 1e-15);
            }
        }
    }

    #[test]
    fn operator_and_csr_paths_agree_bitwise() {
        let a = poisson_2d(9);
        let n = a.nrows();
        let b: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin()).collect();
        let mut x1 = vec![0.0; n];
        let mut x2 = vec![0.0; n];
        let mut cg = Cg::new(Preconditioner::Jacobi, IterativeParams::default());
        let i1 = cg.solve(SystemMatrix::Csr(&a), &b, &mut x1).expect("converges");
        let i2 = cg.solve(SystemMatrix::Operator(&a), &b, &mut x2).expect("converges");
        assert_eq!(i1, i2);
        assert!(x1.iter().zip(&x2).all(|(a, b)| a.to_bits() == b.to_bits()));
    }

    #[test]
    fn jacobi_preconditioning_helps_badly_scaled_systems() {
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let a = random_spd(&mut rng, 80, 1e6);
        let n = a.nrows();
        let b: Vec<f64> = (0..n).map(|_| rng.random_range(-1.0..1.0)).collect();
        let params = IterativeParams::new(1e-10, 10_000);
        let mut plain = Cg::new(Preconditioner::Identity, params);
        let mut pcg = Cg::new(Preconditioner::Jacobi, params);
        let mut x = vec![0.0; n];
        let it_plain = plain.solve(SystemMatrix::Csr(&a), &b, &mut x).expect("cg").iterations;
        x.fill(0.0);
        let it_pcg = pcg.solve(SystemMatrix::Csr(&a), &b, &mut x).expect("pcg").iterations;
        assert!(it_pcg < it_plain, "pcg {it_pcg} vs cg {it_plain}");
        assert_eq!(plain.name(), "cg");
        assert_eq!(pcg.name(), "jacobi-pcg");
        assert!(!pcg.needs_matrix());
    }

    #[test]
    fn zero_rhs_gives_zero_immediately() {
        let a = poisson_2d(4);
        let mut x = vec![3.0; 16];
        let mut cg = Cg::new(Preconditioner::Identity, IterativeParams::default());
        let info = cg.solve(SystemMatrix::Csr(&a), &[0.0; 16], &mut x).expect("trivial");
        assert_eq!(info, SolveInfo { iterations: 0, relative_residual: 0.0 });
        assert!(x.iter().all(|&v| v == 0.0));
    }

    #[test]
    fn exact_initial_guess_takes_no_iteration() {
        let a = CsrMatrix::from_triplets(2, 2, &[(0, 0, 2.0), (1, 1, 4.0)]);
        let mut x = vec![0.5, 0.25];
        let mut cg = Cg::new(Preconditioner::Identity, IterativeParams::default());
        let info = cg.solve(SystemMatrix::Csr(&a), &[1.0, 1.0], &mut x).expect("exact");
        assert_eq!(info.iterations, 0);
        assert_eq!(x, vec![0.5, 0.25]);
    }

    #[test]
    fn indefinite_matrix_is_reported() {
        let a = CsrMatrix::from_triplets(2, 2, &[(0, 0, 1.0), (1, 1, -1.0)]);
        let mut cg = Cg::new(Preconditioner::Identity, IterativeParams::default());
        let mut x = vec![0.0; 2];
        let err = cg.solve(SystemMatrix::Csr(&a), &[0.0, 1.0], &mut x).unwrap_err();
        assert_eq!(err, SolveError::NotPositiveDefinite { iteration: 1, curvature: -1.0 });
    }

    #[test]
    fn jacobi_rejects_non_positive_diagonal() {
        let a = CsrMatrix::from_triplets(3, 3, &[(0, 0, 1.0), (1, 1, -2.0), (2, 2, 1.0)]);
        let mut cg = Cg::new(Preconditioner::Jacobi, IterativeParams::default());
        let mut x = vec![0.0; 3];
        let err = cg.solve(SystemMatrix::Csr(&a), &[1.0; 3], &mut x).unwrap_err();
        assert_eq!(err, SolveError::BadPivot { row: 1, value: -2.0 });
        // A missing diagonal entry is a zero pivot.
        let a = CsrMatrix::from_triplets(2, 2, &[(0, 0, 1.0), (1, 0, 0.5)]);
        let err = cg.solve(SystemMatrix::Csr(&a), &[1.0; 2], &mut x[..2]).unwrap_err();
        assert_eq!(err, SolveError::BadPivot { row: 1, value: 0.0 });
    }

    #[test]
    fn jacobi_needs_diagonal() {
        let a = poisson_2d(3);
        let op = NoDiag(&a);
        let mut x = vec![0.0; 9];
        let mut pcg = Cg::new(Preconditioner::Jacobi, IterativeParams::default());
        assert_eq!(pcg.solve(SystemMatrix::Operator(&op), &[1.0; 9], &mut x), Err(SolveError::NoDiagonal));
        // Plain CG does not need it.
        let mut cg = Cg::new(Preconditioner::Identity, IterativeParams::default());
        assert!(cg.solve(SystemMatrix::Operator(&op), &[1.0; 9], &mut x).is_ok());
    }

    #[test]
    fn non_finite_values_are_reported() {
        let a = poisson_2d(3);
        let mut cg = Cg::new(Preconditioner::Identity, IterativeParams::default());
        let mut b = vec![1.0; 9];
        b[4] = f64::NAN;
        let mut x = vec![0.0; 9];
        assert_eq!(cg.solve(SystemMatrix::Csr(&a), &b, &mut x), Err(SolveError::NonFinite { iteration: 0 }));
        let mut x = vec![0.0; 9];
        x[2] = f64::INFINITY;
        assert_eq!(
            cg.solve(SystemMatrix::Csr(&a), &[1.0; 9], &mut x),
            Err(SolveError::NonFinite { iteration: 0 })
        );
        // NaN in the matrix shows in the first residual (NaN * 0 = NaN).
        let mut bad = a.clone();
        let k = bad.position(4, 5).expect("stored");
        bad.values_mut()[k] = f64::NAN;
        let mut x = vec![0.0; 9];
        assert_eq!(
            cg.solve(SystemMatrix::Csr(&bad), &[1.0; 9], &mut x),
            Err(SolveError::NonFinite { iteration: 0 })
        );
        // Overflow inside the iteration: b is scaled to unit size, p = (1, 1),
        // p^T A p = 2 * 1e308 = inf.
        let huge = CsrMatrix::from_triplets(2, 2, &[(0, 0, 1e308), (1, 1, 1e308)]);
        let mut x = vec![0.0; 2];
        assert_eq!(
            cg.solve(SystemMatrix::Csr(&huge), &[1e60, 1e60], &mut x),
            Err(SolveError::NonFinite { iteration: 1 })
        );
    }

    #[test]
    fn not_converged_keeps_last_iterate() {
        let a = poisson_2d(10);
        let n = a.nrows();
        let b = vec![1.0; n];
        let mut cg = Cg::new(Preconditioner::Identity, IterativeParams::new(1e-12, 3));
        let mut x = vec![0.0; n];
        let err = cg.solve(SystemMatrix::Csr(&a), &b, &mut x).unwrap_err();
        let SolveError::NotConverged { iterations, relative_residual } = err else {
            panic!("expected NotConverged, got {err:?}");
        };
        assert_eq!(iterations, 3);
        // x is the third iterate: progress was made, and the residual reported is its own.
        let mut ax = vec![0.0; n];
        a.mul_vec(&x, &mut ax);
        let r: Vec<f64> = b.iter().zip(&ax).map(|(b, ax)| b - ax).collect();
        let rel = norm(&r) / norm(&b);
        assert!(rel < 1.0 && rel > 1e-12);
        assert!((rel - relative_residual).abs() <= 1e-15);
        // Continuing from that iterate converges.
        let mut cg = Cg::new(Preconditioner::Identity, IterativeParams::new(1e-12, 1000));
        assert!(cg.solve(SystemMatrix::Csr(&a), &b, &mut x).is_ok());
    }

    #[test]
    fn scratch_is_reused_between_solves() {
        let a = poisson_2d(6);
        let n = a.nrows();
        let mut cg = Cg::new(Preconditioner::Jacobi, IterativeParams::default());
        let mut x = vec![0.0; n];
        cg.solve(SystemMatrix::Csr(&a), &vec![1.0; n], &mut x).expect("converges");
        let ptrs = [cg.r.as_ptr(), cg.z.as_ptr(), cg.p.as_ptr(), cg.ap.as_ptr(), cg.inv_diag.as_ptr()];
        x.fill(0.0);
        cg.solve(SystemMatrix::Csr(&a), &vec![2.0; n], &mut x).expect("converges");
        let after = [cg.r.as_ptr(), cg.z.as_ptr(), cg.p.as_ptr(), cg.ap.as_ptr(), cg.inv_diag.as_ptr()];
        assert_eq!(ptrs, after);
    }

    #[test]
    fn tiny_and_huge_right_hand_sides_solve_like_unit_ones() {
        // Regression: a backward-Euler step of a decayed stiff oscillator hands CG b ~ 1e-200,
        // where p^T A p underflowed to 0 and was reported as "not positive definite".
        let a = poisson_2d(6);
        let n = a.nrows();
        let b: Vec<f64> = (0..n).map(|i| 1.0 + (i % 5) as f64).collect();
        let mut x_unit = vec![0.0; n];
        let mut solver = Cg::new(Preconditioner::Jacobi, IterativeParams::new(1e-12, 500));
        solver.solve(SystemMatrix::Csr(&a), &b, &mut x_unit).unwrap();
        for scale in [1e-200, 1e-300, 1e200] {
            let bs: Vec<f64> = b.iter().map(|v| v * scale).collect();
            let mut x = vec![0.0; n];
            let info = solver.solve(SystemMatrix::Csr(&a), &bs, &mut x).unwrap();
            assert!(info.relative_residual <= 1e-12, "scale {scale}: {info:?}");
            for (xi, ui) in x.iter().zip(&x_unit) {
                assert!((xi / scale - ui).abs() <= 1e-9 * ui.abs(), "scale {scale}: {} vs {ui}", xi / scale);
            }
        }
    }
}
