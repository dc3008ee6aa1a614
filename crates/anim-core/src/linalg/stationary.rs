//! Stationary iterations: Jacobi and Gauss-Seidel sweeps on an assembled matrix.
//!
//! # Method
//!
//! Split `A = D + L + U` (diagonal, strictly lower, strictly upper). A stationary iteration
//! repeats a fixed update `x <- G x + c` (Saad, *Iterative Methods for Sparse Linear Systems*,
//! 2nd ed., section 4.1):
//!
//! ```text
//! Jacobi:        x_i^{k+1} = ( b_i - sum_{j != i} a_ij x_j^k ) / a_ii          (G = -D^-1 (L + U))
//! Gauss-Seidel:  x_i^{k+1} = ( b_i - sum_{j < i} a_ij x_j^{k+1}
//!                                  - sum_{j > i} a_ij x_j^k ) / a_ii           (G = -(D + L)^-1 U)
//! ```
//!
//! Both converge for any initial guess iff the spectral radius `rho(G) < 1`, which holds when `A`
//! is strictly (or irreducibly) diagonally dominant; Gauss-Seidel also converges for every SPD
//! `A`. For consistently ordered matrices such as the 1D/2D Poisson matrices,
//! `rho(G_GS) = rho(G_J)^2` (Young's theorem), so Gauss-Seidel needs about half as many sweeps.
//! Their main use in simulation is as smoothers (a few sweeps, e.g. in multigrid or Stam's stable
//! fluids diffusion/projection); [`jacobi_sweep`] and [`gauss_seidel_sweep`] are public for that.
//!
//! Jacobi updates every row from the old iterate, so rows are independent: for more than
//! [`PARALLEL_ROW_THRESHOLD`] rows they are split among rayon tasks, with bitwise identical
//! results for any thread count. Gauss-Seidel is inherently sequential (forward sweep, in place).
//!
//! # Stopping and failure
//!
//! The solvers ([`Jacobi`], [`GaussSeidel`]) check the true relative residual
//! `||b - A x|| / ||b||` after **every** sweep (one extra matrix-vector product per sweep) and stop
//! once it is `<= tolerance`. `b = 0` gives `x = 0` immediately. A zero (or missing, or
//! non-finite) diagonal entry is [`SolveError::BadPivot`]; a non-finite residual is
//! [`SolveError::NonFinite`]; the sweep cap is [`SolveError::NotConverged`] with `x` holding the
//! last sweep. Both need [`SystemMatrix::Csr`]; a matrix-free operator gives
//! [`SolveError::NeedsMatrix`].

use crate::par::prelude::*;

use super::csr::{PARALLEL_ROW_THRESHOLD, ROW_CHUNK};
use super::{CsrMatrix, IterativeParams, LinearSolver, SolveError, SolveInfo, SystemMatrix, norm};

/// Checks that `a` is square and the vectors have its size.
#[track_caller]
fn check_shapes(what: &str, a: &CsrMatrix, b: &[f64], x: &[f64]) {
    assert_eq!(a.nrows(), a.ncols(), "{what}: the matrix must be square ({} x {})", a.nrows(), a.ncols());
    assert_eq!(b.len(), a.nrows(), "{what}: b.len() != nrows");
    assert_eq!(x.len(), a.nrows(), "{what}: x.len() != nrows");
}

/// Whether `d` is unusable as a pivot of a stationary sweep.
#[inline]
fn bad_pivot(d: f64) -> bool {
    d == 0.0 || !d.is_finite()
}

/// Jacobi rows `first_row ..` into `x_new`; returns the first row with a bad pivot.
fn jacobi_rows(
    a: &CsrMatrix,
    b: &[f64],
    x_old: &[f64],
    first_row: usize,
    x_new: &mut [f64],
) -> Option<(usize, f64)> {
    let (row_ptr, col_idx, values) = (a.row_ptr(), a.col_idx(), a.values());
    for (k, xi) in x_new.iter_mut().enumerate() {
        let i = first_row + k;
        let mut s = b[i];
        let mut diag = 0.0;
        for e in row_ptr[i]..row_ptr[i + 1] {
            let j = col_idx[e];
            if j == i {
                diag = values[e];
            } else {
                s -= values[e] * x_old[j];
            }
        }
        if bad_pivot(diag) {
            return Some((i, diag));
        }
        *xi = s / diag;
    }
    None
}

/// One Jacobi sweep: `x_new_i = (b_i - sum_{j != i} a_ij x_old_j) / a_ii` for every row.
///
/// Rows are computed independently (in parallel above [`PARALLEL_ROW_THRESHOLD`] rows, with
/// results independent of the thread count). A missing diagonal entry counts as zero.
///
/// # Errors
/// [`SolveError::BadPivot`] for the lowest row whose diagonal is zero or non-finite; `x_new` is
/// then partially updated.
///
/// # Panics
/// If `a` is not square or a vector length differs from its size.
#[track_caller]
pub fn jacobi_sweep(a: &CsrMatrix, b: &[f64], x_old: &[f64], x_new: &mut [f64]) -> Result<(), SolveError> {
    check_shapes("jacobi_sweep", a, b, x_old);
    assert_eq!(x_new.len(), a.nrows(), "jacobi_sweep: x_new.len() != nrows");
    let bad = if a.nrows() > PARALLEL_ROW_THRESHOLD {
        x_new
            .par_chunks_mut(ROW_CHUNK)
            .enumerate()
            .filter_map(|(chunk, xs)| jacobi_rows(a, b, x_old, chunk * ROW_CHUNK, xs))
            .min_by_key(|&(row, _)| row)
    } else {
        jacobi_rows(a, b, x_old, 0, x_new)
    };
    match bad {
        Some((row, value)) => Err(SolveError::BadPivot { row, value }),
        None => Ok(()),
    }
}

/// One forward Gauss-Seidel sweep, in place: rows `i = 0, 1, ..., n-1` in order,
/// `x_i = (b_i - sum_{j != i} a_ij x_j) / a_ii` using the already updated `x_j` for `j < i`.
///
/// A missing diagonal entry counts as zero.
///
/// # Errors
/// [`SolveError::BadPivot`] at the first row whose diagonal is zero or non-finite; rows before it
/// have been updated.
///
/// # Panics
/// If `a` is not square or a vector length differs from its size.
#[track_caller]
pub fn gauss_seidel_sweep(a: &CsrMatrix, b: &[f64], x: &mut [f64]) -> Result<(), SolveError> {
    check_shapes("gauss_seidel_sweep", a, b, x);
    let (row_ptr, col_idx, values) = (a.row_ptr(), a.col_idx(), a.values());
    for i in 0..a.nrows() {
        let mut s = b[i];
        let mut diag = 0.0;
        for e in row_ptr[i]..row_ptr[i + 1] {
            let j = col_idx[e];
            if j == i {
                diag = values[e];
            } else {
                s -= values[e] * x[j];
            }
        }
        if bad_pivot(diag) {
            return Err(SolveError::BadPivot { row: i, value: diag });
        }
        x[i] = s / diag;
    }
    Ok(())
}

/// `||b - A x|| / b_norm`, using `scratch` for `A x`.
fn relative_residual(a: &CsrMatrix, b: &[f64], x: &[f64], b_norm: f64, scratch: &mut [f64]) -> f64 {
    a.mul_vec(x, scratch);
    for (s, bi) in scratch.iter_mut().zip(b) {
        *s = bi - *s;
    }
    norm(scratch) / b_norm
}

/// The sweep loop shared by both solvers; `sweep` performs one sweep in place on `x`.
fn iterate(
    params: IterativeParams,
    solver: &'static str,
    a: SystemMatrix<'_>,
    b: &[f64],
    x: &mut [f64],
    scratch: &mut Vec<f64>,
    mut sweep: impl FnMut(&CsrMatrix, &[f64], &mut [f64]) -> Result<(), SolveError>,
) -> Result<SolveInfo, SolveError> {
    let SystemMatrix::Csr(a) = a else {
        return Err(SolveError::NeedsMatrix { solver });
    };
    check_shapes(solver, a, b, x);
    let n = a.nrows();
    if scratch.len() != n {
        scratch.resize(n, 0.0);
    }
    let b_norm = norm(b);
    if !b_norm.is_finite() {
        return Err(SolveError::NonFinite { iteration: 0 });
    }
    if b_norm == 0.0 {
        x.fill(0.0);
        return Ok(SolveInfo { iterations: 0, relative_residual: 0.0 });
    }
    let mut rel = relative_residual(a, b, x, b_norm, scratch);
    if !rel.is_finite() {
        return Err(SolveError::NonFinite { iteration: 0 });
    }
    if rel <= params.tolerance {
        return Ok(SolveInfo { iterations: 0, relative_residual: rel });
    }
    for k in 1..=params.max_iterations {
        sweep(a, b, x)?;
        rel = relative_residual(a, b, x, b_norm, scratch);
        if !rel.is_finite() {
            return Err(SolveError::NonFinite { iteration: k });
        }
        if rel <= params.tolerance {
            return Ok(SolveInfo { iterations: k, relative_residual: rel });
        }
    }
    Err(SolveError::NotConverged { iterations: params.max_iterations, relative_residual: rel })
}

/// Jacobi iteration (see the [module docs](self)).
#[derive(Debug, Clone)]
pub struct Jacobi {
    params: IterativeParams,
    /// The previous iterate.
    x_old: Vec<f64>,
    /// `A x` / the residual.
    scratch: Vec<f64>,
}

impl Jacobi {
    /// A solver with the given stopping rule (`max_iterations` counts sweeps).
    #[must_use]
    pub fn new(params: IterativeParams) -> Self {
        Self { params, x_old: Vec::new(), scratch: Vec::new() }
    }
}

impl LinearSolver for Jacobi {
    fn name(&self) -> &'static str {
        "jacobi"
    }

    fn needs_matrix(&self) -> bool {
        true
    }

    fn solve(&mut self, a: SystemMatrix<'_>, b: &[f64], x: &mut [f64]) -> Result<SolveInfo, SolveError> {
        if self.x_old.len() != x.len() {
            self.x_old.resize(x.len(), 0.0);
        }
        let x_old = &mut self.x_old;
        iterate(self.params, "jacobi", a, b, x, &mut self.scratch, |a, b, x| {
            x_old.copy_from_slice(x);
            jacobi_sweep(a, b, x_old, x)
        })
    }
}

/// Gauss-Seidel iteration, forward sweeps (see the [module docs](self)).
#[derive(Debug, Clone)]
pub struct GaussSeidel {
    params: IterativeParams,
    /// `A x` / the residual.
    scratch: Vec<f64>,
}

impl GaussSeidel {
    /// A solver with the given stopping rule (`max_iterations` counts sweeps).
    #[must_use]
    pub fn new(params: IterativeParams) -> Self {
        Self { params, scratch: Vec::new() }
    }
}

impl LinearSolver for GaussSeidel {
    fn name(&self) -> &'static str {
        "gauss-seidel"
    }

    fn needs_matrix(&self) -> bool {
        true
    }

    fn solve(&mut self, a: SystemMatrix<'_>, b: &[f64], x: &mut [f64]) -> Result<SolveInfo, SolveError> {
        iterate(self.params, "gauss-seidel", a, b, x, &mut self.scratch, gauss_seidel_sweep)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::Mat;
    use faer::prelude::Solve;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn poisson_1d(n: usize) -> CsrMatrix {
        let mut t = Vec::new();
        for i in 0..n {
            t.push((i, i, 2.0));
            if i > 0 {
                t.push((i, i - 1, -1.0));
            }
            if i + 1 < n {
                t.push((i, i + 1, -1.0));
            }
        }
        CsrMatrix::from_triplets(n, n, &t)
    }

    fn poisson_2d(m: usize) -> CsrMatrix {
        let idx = |i: usize, j: usize| i * m + j;
        let mut t = Vec::new();
        for i in 0..m {
            for j in 0..m {
                t.push((idx(i, j), idx(i, j), 4.0));
                for (di, dj) in [(-1i64, 0i64), (1, 0), (0, -1), (0, 1)] {
                    let (ni, nj) = (i as i64 + di, j as i64 + dj);
                    if ni >= 0 && nj >= 0 && (ni as usize) < m && (nj as usize) < m {
                        t.push((idx(i, j), idx(ni as usize, nj as usize), -1.0));
                    }
                }
            }
        }
        CsrMatrix::from_triplets(m * m, m * m, &t)
    }

    /// Strictly diagonally dominant, non-symmetric random matrix.
    fn diag_dominant(rng: &mut ChaCha8Rng, n: usize) -> CsrMatrix {
        let mut t = Vec::new();
        for i in 0..n {
            let mut off = 0.0;
            for _ in 0..4 {
                let j = rng.random_range(0..n);
                if j != i {
                    let v: f64 = rng.random_range(-1.0..1.0);
                    off += v.abs();
                    t.push((i, j, v));
                }
            }
            let sign = if rng.random_bool(0.5) { 1.0 } else { -1.0 };
            t.push((i, i, sign * (off * 1.5 + 0.1)));
        }
        CsrMatrix::from_triplets(n, n, &t)
    }

    fn dense_solve(a: &CsrMatrix, b: &[f64]) -> Vec<f64> {
        let d = a.to_dense();
        let n = b.len();
        let m = Mat::<f64>::from_fn(n, n, |i, j| d[i][j]);
        let x = m.partial_piv_lu().solve(&Mat::<f64>::from_fn(n, 1, |i, _| b[i]));
        (0..n).map(|i| x[(i, 0)]).collect()
    }

    fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
        a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max)
    }

    fn solvers(params: IterativeParams) -> [Box<dyn LinearSolver>; 2] {
        [Box::new(Jacobi::new(params)), Box::new(GaussSeidel::new(params))]
    }

    #[test]
    fn converge_on_diagonally_dominant_system() {
        let mut rng = ChaCha8Rng::seed_from_u64(20);
        let a = diag_dominant(&mut rng, 50);
        let b: Vec<f64> = (0..50).map(|_| rng.random_range(-1.0..1.0)).collect();
        let reference = dense_solve(&a, &b);
        for mut s in solvers(IterativeParams::new(1e-12, 500)) {
            assert!(s.needs_matrix());
            let mut x = vec![0.0; 50];
            let info = s.solve(SystemMatrix::Csr(&a), &b, &mut x).expect("converges");
            assert!(info.relative_residual <= 1e-12 && info.iterations > 1, "{}", s.name());
            assert!(max_abs_diff(&x, &reference) <= 1e-10, "{}", s.name());
        }
    }

    /// Young's theorem: on the Poisson matrices rho(GS) = rho(J)^2, so GS needs about half the
    /// sweeps. Measured on the asymptotic regime (tight tolerance), the ratio must lie in
    /// [1.5, 2.5].
    #[test]
    fn gauss_seidel_twice_as_fast_as_jacobi_on_poisson() {
        for (name, a) in [("1d", poisson_1d(30)), ("2d", poisson_2d(8))] {
            let n = a.nrows();
            let b: Vec<f64> = (0..n).map(|i| 1.0 + (i as f64).sin()).collect();
            let reference = dense_solve(&a, &b);
            let params = IterativeParams::new(1e-8, 100_000);
            let mut sweeps = [0usize; 2];
            for (k, mut s) in solvers(params).into_iter().enumerate() {
                let mut x = vec![0.0; n];
                let info = s.solve(SystemMatrix::Csr(&a), &b, &mut x).expect("converges");
                let scale = reference.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                assert!(max_abs_diff(&x, &reference) <= 1e-5 * scale, "{name} {}", s.name());
                sweeps[k] = info.iterations;
            }
            let ratio = sweeps[0] as f64 / sweeps[1] as f64;
            assert!(sweeps[1] < sweeps[0], "{name}: gs {} jacobi {}", sweeps[1], sweeps[0]);
            assert!((1.5..=2.5).contains(&ratio), "{name}: jacobi/gs sweep ratio {ratio} ({sweeps:?})");
        }
    }

    /// A = [[1, a, a], [a, 1, a], [a, a, 1]] with a = 0.8 is SPD (eigenvalues 2.6, 0.2, 0.2) but
    /// the Jacobi iteration matrix has eigenvalue -2a = -1.6: Jacobi diverges, Gauss-Seidel
    /// converges (it converges for every SPD matrix).
    #[test]
    fn jacobi_diverges_where_gauss_seidel_converges() {
        let a = 0.8;
        let m = CsrMatrix::from_triplets(
            3,
            3,
            &[
                (0, 0, 1.0),
                (0, 1, a),
                (0, 2, a),
                (1, 0, a),
                (1, 1, 1.0),
                (1, 2, a),
                (2, 0, a),
                (2, 1, a),
                (2, 2, 1.0),
            ],
        );
        let b = [1.0, 2.0, 3.0];
        let params = IterativeParams::new(1e-10, 60);
        let mut x = [0.0; 3];
        let err = Jacobi::new(params).solve(SystemMatrix::Csr(&m), &b, &mut x).unwrap_err();
        match err {
            SolveError::NotConverged { iterations, relative_residual } => {
                assert_eq!(iterations, 60);
                assert!(relative_residual > 1.0, "diverged: {relative_residual}");
            }
            other => panic!("expected NotConverged, got {other:?}"),
        }
        let mut x = [0.0; 3];
        let info = GaussSeidel::new(IterativeParams::new(1e-14, 1000))
            .solve(SystemMatrix::Csr(&m), &b, &mut x)
            .expect("GS converges for SPD");
        assert!(info.relative_residual <= 1e-14);
        // error <= cond(A) * relative residual * |x| = 13 * 1e-14 * |x|
        let reference = dense_solve(&m, &b);
        let scale = reference.iter().fold(0.0f64, |s, v| s.max(v.abs()));
        assert!(max_abs_diff(&x, &reference) <= 13.0 * 1e-14 * 2.0 * scale);
    }

    #[test]
    fn zero_diagonal_is_a_bad_pivot() {
        let a = CsrMatrix::from_triplets(3, 3, &[(0, 0, 2.0), (1, 0, 1.0), (1, 2, 1.0), (2, 2, 3.0)]);
        for mut s in solvers(IterativeParams::default()) {
            let mut x = [0.0; 3];
            assert_eq!(
                s.solve(SystemMatrix::Csr(&a), &[1.0; 3], &mut x),
                Err(SolveError::BadPivot { row: 1, value: 0.0 }),
                "{}",
                s.name()
            );
        }
        let mut x = [0.0; 3];
        assert_eq!(
            gauss_seidel_sweep(&a, &[1.0; 3], &mut x),
            Err(SolveError::BadPivot { row: 1, value: 0.0 })
        );
        assert_eq!(x[0], 0.5, "rows before the bad pivot were updated");
    }

    #[test]
    fn matrix_free_operator_is_rejected() {
        let a = poisson_1d(4);
        for mut s in solvers(IterativeParams::default()) {
            let mut x = [0.0; 4];
            let err = s.solve(SystemMatrix::Operator(&a), &[1.0; 4], &mut x).unwrap_err();
            assert_eq!(err, SolveError::NeedsMatrix { solver: s.name() });
        }
    }

    #[test]
    fn zero_rhs_and_non_finite() {
        let a = poisson_1d(5);
        for mut s in solvers(IterativeParams::default()) {
            let mut x = [1.0; 5];
            let info = s.solve(SystemMatrix::Csr(&a), &[0.0; 5], &mut x).expect("trivial");
            assert_eq!(info.iterations, 0);
            assert_eq!(x, [0.0; 5]);
            let mut b = [1.0; 5];
            b[3] = f64::INFINITY;
            assert_eq!(
                s.solve(SystemMatrix::Csr(&a), &b, &mut x),
                Err(SolveError::NonFinite { iteration: 0 })
            );
        }
    }

    /// One sweep of each, against the formulas written out densely.
    #[test]
    fn single_sweeps_match_formulas() {
        let mut rng = ChaCha8Rng::seed_from_u64(21);
        let a = diag_dominant(&mut rng, 12);
        let d = a.to_dense();
        let b: Vec<f64> = (0..12).map(|_| rng.random_range(-1.0..1.0)).collect();
        let x0: Vec<f64> = (0..12).map(|_| rng.random_range(-1.0..1.0)).collect();
        let mut xj = vec![0.0; 12];
        jacobi_sweep(&a, &b, &x0, &mut xj).expect("pivots fine");
        let mut xg = x0.clone();
        gauss_seidel_sweep(&a, &b, &mut xg).expect("pivots fine");
        let mut xg_ref = x0.clone();
        for i in 0..12 {
            let sj: f64 = (0..12).filter(|&j| j != i).map(|j| d[i][j] * x0[j]).sum();
            assert!((xj[i] - (b[i] - sj) / d[i][i]).abs() <= 1e-13);
            let sg: f64 = (0..12).filter(|&j| j != i).map(|j| d[i][j] * xg_ref[j]).sum();
            xg_ref[i] = (b[i] - sg) / d[i][i];
        }
        assert!(max_abs_diff(&xg, &xg_ref) <= 1e-13);
    }

    /// The parallel Jacobi sweep equals the serial one bit for bit, for any thread count.
    #[test]
    fn parallel_jacobi_sweep_is_deterministic() {
        let m = 70; // 4900 rows > PARALLEL_ROW_THRESHOLD
        let a = poisson_2d(m);
        assert!(a.nrows() > PARALLEL_ROW_THRESHOLD);
        let n = a.nrows();
        let b: Vec<f64> = (0..n).map(|i| (i as f64 * 0.1).cos()).collect();
        let x0: Vec<f64> = (0..n).map(|i| (i as f64 * 0.7).sin()).collect();
        let mut serial = vec![0.0; n];
        assert!(jacobi_rows(&a, &b, &x0, 0, &mut serial).is_none());
        for threads in [1, 2, 4] {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("pool");
            let mut x = vec![0.0; n];
            pool.install(|| jacobi_sweep(&a, &b, &x0, &mut x)).expect("pivots fine");
            assert!(x.iter().zip(&serial).all(|(p, q)| p.to_bits() == q.to_bits()), "{threads}");
        }
        // A bad pivot in two chunks reports the lowest row regardless of scheduling.
        let mut t: Vec<(usize, usize, f64)> = Vec::new();
        for i in 0..n {
            let (cols, vals) = a.row(i);
            for (&c, &v) in cols.iter().zip(vals) {
                let zero = c == i && (i == 3000 || i == 4500);
                t.push((i, c, if zero { 0.0 } else { v }));
            }
        }
        let bad = CsrMatrix::from_triplets(n, n, &t);
        let mut x = vec![0.0; n];
        assert_eq!(jacobi_sweep(&bad, &b, &x0, &mut x), Err(SolveError::BadPivot { row: 3000, value: 0.0 }));
    }

    #[test]
    fn scratch_is_reused_between_solves() {
        let a = poisson_1d(16);
        let mut j = Jacobi::new(IterativeParams::new(1e-6, 10_000));
        let mut x = vec![0.0; 16];
        j.solve(SystemMatrix::Csr(&a), &[1.0; 16], &mut x).expect("converges");
        let ptrs = (j.x_old.as_ptr(), j.scratch.as_ptr());
        x.fill(0.0);
        j.solve(SystemMatrix::Csr(&a), &[2.0; 16], &mut x).expect("converges");
        assert_eq!(ptrs, (j.x_old.as_ptr(), j.scratch.as_ptr()));
    }
}
