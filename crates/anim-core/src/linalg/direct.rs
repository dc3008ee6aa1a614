//! Sparse direct solves by Cholesky `L L^T` and `L D L^T` factorisation (faer), one path for both.
//!
//! # Method
//!
//! A symmetric positive definite (SPD) matrix factors as `P A P^T = L L^T`, `L` lower triangular
//! with a positive diagonal and `P` a fill-reducing permutation (approximate minimum degree);
//! then `A x = b` is two triangular solves, `L y = P b` and `L^T (P x) = y` (Davis, *Direct
//! Methods for Sparse Linear Systems*, SIAM 2006, chapter 4). The work splits into
//!
//! - a **symbolic** phase that depends only on the sparsity pattern: ordering, elimination tree,
//!   the pattern of `L` (and, for large fill, its supernodes);
//! - a **numeric** phase that computes the values of `L`.
//!
//! In an implicit integrator the pattern of the system matrix is fixed while its values change
//! each step, so [`SparseDirect`] keeps the symbolic factorisation and reuses it while the
//! pattern (`row_ptr`, `col_idx`) is unchanged, redoing only the numeric phase on each solve. The
//! factor values, faer's workspace and the residual vector are kept between solves too.
//!
//! The symbolic phase is the same for both factorisations; the numeric phase is the
//! [`Factorization`] kind: [`Llt`] ([`SparseCholesky`], symmetric positive definite) or [`Ldlt`]
//! ([`SparseLdlt`], symmetric and possibly indefinite, the Newton matrix without the positive
//! semi-definite projection). `L D L^T` does no pivoting (faer's simplicial/supernodal
//! factorisation), so a zero pivot fails.
//!
//! # Input
//!
//! The full symmetric matrix is stored; faer reads only the entries `a_ij` with `j <= i` (the
//! lower triangle including the diagonal), the upper triangle being assumed to mirror it. The
//! reported residual `||b - A x|| / ||b||` is computed with the full stored matrix, so an upper
//! triangle that does not mirror the lower one shows up there. The factorisation runs
//! sequentially (`Par::Seq`), so results do not depend on the thread count.
//!
//! # Failure
//!
//! For Cholesky, a diagonal entry that is missing, `<= 0` or NaN is reported before factoring as
//! [`SolveError::BadPivot`] (an SPD matrix has a positive diagonal). A non-positive (Cholesky) or
//! zero (`L D L^T`) pivot found by the elimination is reported as [`SolveError::Factorization`]
//! with faer's message, as are faer's allocation/index errors. A non-finite residual after the solve is
//! [`SolveError::NonFinite`].

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::cholesky::ldlt::factor::LdltRegularization;
use faer::linalg::cholesky::llt::factor::LltRegularization;
use faer::sparse::linalg::cholesky::{
    CholeskySymbolicParams, SymbolicCholesky, SymmetricOrdering, factorize_symbolic_cholesky,
};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Par, Side};

use super::{CsrMatrix, LinearSolver, SolveError, SolveInfo, SystemMatrix, norm};

mod sealed {
    pub trait Sealed {}
}

/// The numeric phase of a [`SparseDirect`] solver: which factorisation it computes from the
/// shared symbolic one, and how it names itself. Implemented by [`Llt`] and [`Ldlt`] only.
pub trait Factorization: sealed::Sealed {
    /// The solver's name ([`LinearSolver::name`]).
    const NAME: &'static str;
    /// The factorisation's name in error messages.
    const LABEL: &'static str;
    /// The solver type's name in `Debug` output.
    const TYPE_NAME: &'static str;

    /// Checks done before factoring (none by default).
    ///
    /// # Errors
    /// A [`SolveError`] naming the problem.
    fn check(_a: &CsrMatrix) -> Result<(), SolveError> {
        Ok(())
    }

    /// faer's scratch space for the numeric factorisation.
    fn numeric_scratch(symbolic: &SymbolicCholesky<usize>) -> StackReq;

    /// Factors `mat` into `l_values` and overwrites `x` (holding `b`) with the solution.
    ///
    /// # Errors
    /// [`SolveError::Factorization`] with faer's message.
    fn factor_and_solve(
        symbolic: &SymbolicCholesky<usize>,
        l_values: &mut [f64],
        mat: SparseColMatRef<'_, usize, f64>,
        workspace: &mut MemBuffer,
        x: &mut [f64],
    ) -> Result<(), SolveError>;
}

/// Cholesky `L L^T`, for symmetric positive definite matrices; rejects a diagonal entry that is
/// missing, `<= 0` or NaN as [`SolveError::BadPivot`] before factoring.
#[derive(Debug, Clone, Copy)]
pub struct Llt;

/// `L D L^T` without pivoting, for symmetric matrices that need not be positive definite.
#[derive(Debug, Clone, Copy)]
pub struct Ldlt;

impl sealed::Sealed for Llt {}
impl sealed::Sealed for Ldlt {}

impl Factorization for Llt {
    const NAME: &'static str = "cholesky";
    const LABEL: &'static str = "Cholesky";
    const TYPE_NAME: &'static str = "SparseCholesky";

    fn check(a: &CsrMatrix) -> Result<(), SolveError> {
        for row in 0..a.nrows() {
            let d = a.get(row, row).unwrap_or(0.0);
            if !(d > 0.0) {
                return Err(SolveError::BadPivot { row, value: d });
            }
        }
        Ok(())
    }

    fn numeric_scratch(symbolic: &SymbolicCholesky<usize>) -> StackReq {
        symbolic.factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default())
    }

    fn factor_and_solve(
        symbolic: &SymbolicCholesky<usize>,
        l_values: &mut [f64],
        mat: SparseColMatRef<'_, usize, f64>,
        workspace: &mut MemBuffer,
        x: &mut [f64],
    ) -> Result<(), SolveError> {
        let n = x.len();
        let llt = symbolic
            .factorize_numeric_llt::<f64>(
                l_values,
                mat,
                Side::Upper,
                LltRegularization::default(),
                Par::Seq,
                MemStack::new(workspace),
                Default::default(),
            )
            .map_err(|e| SolveError::Factorization(format!("numeric Cholesky (matrix not SPD?): {e}")))?;
        llt.solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(x, n, 1),
            Par::Seq,
            MemStack::new(workspace),
        );
        Ok(())
    }
}

impl Factorization for Ldlt {
    const NAME: &'static str = "ldlt";
    const LABEL: &'static str = "LDLT";
    const TYPE_NAME: &'static str = "SparseLdlt";

    fn numeric_scratch(symbolic: &SymbolicCholesky<usize>) -> StackReq {
        symbolic.factorize_numeric_ldlt_scratch::<f64>(Par::Seq, Default::default())
    }

    fn factor_and_solve(
        symbolic: &SymbolicCholesky<usize>,
        l_values: &mut [f64],
        mat: SparseColMatRef<'_, usize, f64>,
        workspace: &mut MemBuffer,
        x: &mut [f64],
    ) -> Result<(), SolveError> {
        let n = x.len();
        let ldlt = symbolic
            .factorize_numeric_ldlt::<f64>(
                l_values,
                mat,
                Side::Upper,
                LdltRegularization::default(),
                Par::Seq,
                MemStack::new(workspace),
                Default::default(),
            )
            .map_err(|e| SolveError::Factorization(format!("numeric LDLT: {e}")))?;
        ldlt.solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(x, n, 1),
            Par::Seq,
            MemStack::new(workspace),
        );
        Ok(())
    }
}

/// Sparse Cholesky (`L L^T`) solver with a cached symbolic factorisation.
pub type SparseCholesky = SparseDirect<Llt>;

/// Sparse `L D L^T` solver with a cached symbolic factorisation.
pub type SparseLdlt = SparseDirect<Ldlt>;

/// Sparse direct solver of factorisation kind `K` with a cached symbolic factorisation (see the
/// [module docs](self)).
pub struct SparseDirect<K: Factorization> {
    /// Pattern the symbolic factorisation was computed for.
    row_ptr: Vec<usize>,
    col_idx: Vec<usize>,
    symbolic: Option<SymbolicCholesky<usize>>,
    /// Values of `L` (and `D`).
    l_values: Vec<f64>,
    /// faer workspace, sized for the numeric factorisation and a one-column solve.
    workspace: MemBuffer,
    /// `A x - b`.
    residual: Vec<f64>,
    /// Number of symbolic factorisations computed so far.
    symbolic_count: usize,
    kind: std::marker::PhantomData<fn() -> K>,
}

impl<K: Factorization> std::fmt::Debug for SparseDirect<K> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct(K::TYPE_NAME)
            .field("dim", &self.row_ptr.len().saturating_sub(1))
            .field("nnz", &self.col_idx.len())
            .field("factor_len", &self.l_values.len())
            .field("symbolic_factorizations", &self.symbolic_count)
            .finish()
    }
}

impl<K: Factorization> Default for SparseDirect<K> {
    fn default() -> Self {
        Self::new()
    }
}

impl<K: Factorization> SparseDirect<K> {
    /// A solver with no cached factorisation.
    #[must_use]
    pub fn new() -> Self {
        Self {
            row_ptr: Vec::new(),
            col_idx: Vec::new(),
            symbolic: None,
            l_values: Vec::new(),
            workspace: MemBuffer::new(StackReq::EMPTY),
            residual: Vec::new(),
            symbolic_count: 0,
            kind: std::marker::PhantomData,
        }
    }

    /// How many symbolic factorisations have been computed (one per distinct pattern seen in a
    /// row); useful to check that the cache works.
    #[must_use]
    pub fn symbolic_factorizations(&self) -> usize {
        self.symbolic_count
    }

    /// Recomputes the symbolic factorisation unless the cached one has `a`'s pattern.
    fn ensure_symbolic(&mut self, a: &CsrMatrix) -> Result<(), SolveError> {
        if self.symbolic.is_some() && self.row_ptr == a.row_ptr() && self.col_idx == a.col_idx() {
            return Ok(());
        }
        self.symbolic = None;
        let n = a.nrows();
        // CSR rows of A are the CSC columns of A^T (= A for a symmetric matrix); the lower
        // triangle of A (j <= i in row i) is the upper triangle of that CSC view.
        let pattern = SymbolicSparseColMatRef::new_checked(n, n, a.row_ptr(), None, a.col_idx());
        let symbolic = factorize_symbolic_cholesky(
            pattern,
            Side::Upper,
            SymmetricOrdering::Amd,
            CholeskySymbolicParams::default(),
        )
        .map_err(|e| SolveError::Factorization(format!("symbolic {}: {e}", K::LABEL)))?;
        let req = StackReq::any_of(&[
            K::numeric_scratch(&symbolic),
            symbolic.solve_in_place_scratch::<f64>(1, Par::Seq),
        ]);
        self.workspace = MemBuffer::try_new(req)
            .map_err(|e| SolveError::Factorization(format!("{} workspace: {e}", K::LABEL)))?;
        self.l_values.clear();
        self.l_values.resize(symbolic.len_val(), 0.0);
        self.row_ptr.clear();
        self.row_ptr.extend_from_slice(a.row_ptr());
        self.col_idx.clear();
        self.col_idx.extend_from_slice(a.col_idx());
        self.symbolic = Some(symbolic);
        self.symbolic_count += 1;
        Ok(())
    }

    fn solve_csr(&mut self, a: &CsrMatrix, b: &[f64], x: &mut [f64]) -> Result<SolveInfo, SolveError> {
        let n = a.nrows();
        let name = K::TYPE_NAME;
        assert_eq!(n, a.ncols(), "{name}: the matrix must be square ({} x {})", n, a.ncols());
        assert_eq!(b.len(), n, "{name}: b.len() != nrows");
        assert_eq!(x.len(), n, "{name}: x.len() != nrows");
        let b_norm = norm(b);
        if !b_norm.is_finite() {
            return Err(SolveError::NonFinite { iteration: 0 });
        }
        K::check(a)?;
        if n == 0 {
            return Ok(SolveInfo { iterations: 1, relative_residual: 0.0 });
        }
        self.ensure_symbolic(a)?;
        let Some(symbolic) = self.symbolic.as_ref() else {
            return Err(SolveError::Factorization("symbolic factorisation missing".into()));
        };
        let pattern = SymbolicSparseColMatRef::new_checked(n, n, a.row_ptr(), None, a.col_idx());
        let mat = SparseColMatRef::new(pattern, a.values());
        x.copy_from_slice(b);
        K::factor_and_solve(symbolic, &mut self.l_values, mat, &mut self.workspace, x)?;
        if self.residual.len() != n {
            self.residual.resize(n, 0.0);
        }
        a.mul_vec(x, &mut self.residual);
        for (r, bi) in self.residual.iter_mut().zip(b) {
            *r -= bi;
        }
        let r_norm = norm(&self.residual);
        if !r_norm.is_finite() {
            return Err(SolveError::NonFinite { iteration: 1 });
        }
        let relative_residual = if b_norm == 0.0 { 0.0 } else { r_norm / b_norm };
        Ok(SolveInfo { iterations: 1, relative_residual })
    }
}

impl<K: Factorization> LinearSolver for SparseDirect<K> {
    fn name(&self) -> &'static str {
        K::NAME
    }

    fn needs_matrix(&self) -> bool {
        true
    }

    fn solve(&mut self, a: SystemMatrix<'_>, b: &[f64], x: &mut [f64]) -> Result<SolveInfo, SolveError> {
        match a {
            SystemMatrix::Csr(m) => self.solve_csr(m, b, x),
            SystemMatrix::Operator(_) => Err(SolveError::NeedsMatrix { solver: K::NAME }),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::Mat;
    use faer::prelude::Solve;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// Random sparse SPD matrix: `B^T B + I` with a sparse random `B`.
    fn random_spd(rng: &mut ChaCha8Rng, n: usize) -> CsrMatrix {
        let mut b = vec![vec![0.0; n]; n];
        for row in b.iter_mut() {
            for _ in 0..3 {
                row[rng.random_range(0..n)] = rng.random_range(-1.0..1.0);
            }
        }
        let mut t = Vec::new();
        for i in 0..n {
            for j in 0..n {
                let v: f64 = (0..n).map(|k| b[k][i] * b[k][j]).sum();
                if v != 0.0 || i == j {
                    t.push((i, j, v + if i == j { 1.0 } else { 0.0 }));
                }
            }
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

    #[test]
    fn matches_dense_solve() {
        let mut rng = ChaCha8Rng::seed_from_u64(30);
        for n in [1, 5, 40, 150] {
            let a = random_spd(&mut rng, n);
            assert!(a.is_symmetric(1e-14));
            let b: Vec<f64> = (0..n).map(|_| rng.random_range(-1.0..1.0)).collect();
            let mut x = vec![0.0; n];
            let mut chol = SparseCholesky::new();
            let info = chol.solve(SystemMatrix::Csr(&a), &b, &mut x).expect("SPD");
            assert_eq!(info.iterations, 1);
            assert!(info.relative_residual <= 1e-13, "n = {n}: {}", info.relative_residual);
            let reference = dense_solve(&a, &b);
            assert!(max_abs_diff(&x, &reference) <= 1e-11, "n = {n}");
        }
    }

    /// A larger problem with fill (2D Poisson, 5-point, 30 x 30 grid): exercises faer's
    /// supernodal path as well as the simplicial one used for the small matrices above.
    #[test]
    fn poisson_2d_matches_dense_solve() {
        let m = 30;
        let idx = |i: usize, j: usize| i * m + j;
        let mut t = Vec::new();
        for i in 0..m {
            for j in 0..m {
                t.push((idx(i, j), idx(i, j), 4.0));
                if i > 0 {
                    t.push((idx(i, j), idx(i - 1, j), -1.0));
                    t.push((idx(i - 1, j), idx(i, j), -1.0));
                }
                if j > 0 {
                    t.push((idx(i, j), idx(i, j - 1), -1.0));
                    t.push((idx(i, j - 1), idx(i, j), -1.0));
                }
            }
        }
        let a = CsrMatrix::from_triplets(m * m, m * m, &t);
        let b: Vec<f64> = (0..m * m).map(|k| ((k * 7) % 11) as f64 - 5.0).collect();
        let mut x = vec![0.0; m * m];
        let mut chol = SparseCholesky::new();
        let info = chol.solve(SystemMatrix::Csr(&a), &b, &mut x).expect("SPD");
        assert!(info.relative_residual <= 1e-14, "{}", info.relative_residual);
        let reference = dense_solve(&a, &b);
        let scale = reference.iter().fold(0.0f64, |s, v| s.max(v.abs()));
        assert!(max_abs_diff(&x, &reference) <= 1e-12 * scale);
    }

    /// faer switches to its supernodal factorisation when the factor is dense enough (flops per
    /// factor entry > 40): a dense SPD matrix of size 160 takes that path. The upper triangle is
    /// filled with garbage to check that only the lower one is read on this path too.
    #[test]
    fn dense_spd_takes_supernodal_path() {
        use faer::sparse::linalg::cholesky::SymbolicCholeskyRaw;
        let mut rng = ChaCha8Rng::seed_from_u64(32);
        let n = 160;
        let g: Vec<Vec<f64>> =
            (0..n).map(|_| (0..n).map(|_| rng.random_range(-1.0..1.0)).collect()).collect();
        let mut full = Vec::new();
        let mut lower_only = Vec::new();
        for i in 0..n {
            for j in 0..n {
                let v: f64 =
                    (0..n).map(|k| g[k][i] * g[k][j]).sum::<f64>() + if i == j { n as f64 } else { 0.0 };
                full.push((i, j, v));
                lower_only.push((i, j, if j <= i { v } else { 1e3 }));
            }
        }
        let a = CsrMatrix::from_triplets(n, n, &full);
        let garbage = CsrMatrix::from_triplets(n, n, &lower_only);
        let b: Vec<f64> = (0..n).map(|_| rng.random_range(-1.0..1.0)).collect();
        let reference = dense_solve(&a, &b);
        let mut chol = SparseCholesky::new();
        let mut x = vec![0.0; n];
        let info = chol.solve(SystemMatrix::Csr(&a), &b, &mut x).expect("SPD");
        assert!(matches!(
            chol.symbolic.as_ref().map(SymbolicCholesky::raw),
            Some(SymbolicCholeskyRaw::Supernodal(_))
        ));
        assert!(info.relative_residual <= 1e-13);
        assert!(max_abs_diff(&x, &reference) <= 1e-12);
        // Same pattern, so the cached supernodal analysis is reused.
        chol.solve(SystemMatrix::Csr(&garbage), &b, &mut x).expect("lower triangle SPD");
        assert_eq!(chol.symbolic_factorizations(), 1);
        assert!(max_abs_diff(&x, &reference) <= 1e-12);
    }

    #[test]
    fn symbolic_factorisation_is_cached_per_pattern() {
        let mut rng = ChaCha8Rng::seed_from_u64(31);
        let mut a = random_spd(&mut rng, 60);
        let b: Vec<f64> = (0..60).map(|_| rng.random_range(-1.0..1.0)).collect();
        let mut chol = SparseCholesky::new();
        let mut x = vec![0.0; 60];
        chol.solve(SystemMatrix::Csr(&a), &b, &mut x).expect("SPD");
        assert_eq!(chol.symbolic_factorizations(), 1);
        let l_ptr = chol.l_values.as_ptr();
        // New values, same pattern: scale the diagonal up (still SPD); only numeric work.
        for i in 0..60 {
            let k = a.position(i, i).expect("diagonal stored");
            a.values_mut()[k] *= 3.0;
        }
        chol.solve(SystemMatrix::Csr(&a), &b, &mut x).expect("SPD");
        assert_eq!(chol.symbolic_factorizations(), 1);
        assert_eq!(chol.l_values.as_ptr(), l_ptr, "factor storage reused");
        assert!(max_abs_diff(&x, &dense_solve(&a, &b)) <= 1e-11, "re-factored numerically");
        // A different pattern triggers a new analysis.
        let c = random_spd(&mut rng, 60);
        chol.solve(SystemMatrix::Csr(&c), &b, &mut x).expect("SPD");
        assert_eq!(chol.symbolic_factorizations(), 2);
        assert!(max_abs_diff(&x, &dense_solve(&c, &b)) <= 1e-11);
    }

    #[test]
    fn only_the_lower_triangle_is_read() {
        // Lower triangle of [[4, 1], [1, 3]]; the upper entry is garbage.
        let a = CsrMatrix::from_triplets(2, 2, &[(0, 0, 4.0), (0, 1, 100.0), (1, 0, 1.0), (1, 1, 3.0)]);
        let mut x = [0.0; 2];
        SparseCholesky::new().solve(SystemMatrix::Csr(&a), &[1.0, 2.0], &mut x).expect("SPD lower");
        // Exact solution of [[4, 1], [1, 3]] x = [1, 2]: x = [1/11, 7/11].
        assert!((x[0] - 1.0 / 11.0).abs() <= 1e-15 && (x[1] - 7.0 / 11.0).abs() <= 1e-15);
    }

    #[test]
    fn non_spd_matrices_give_errors_not_nan() {
        let mut chol = SparseCholesky::new();
        let mut x = [0.0; 3];
        // Positive diagonal but indefinite: [[1, 2], [2, 1]] has eigenvalues 3 and -1.
        let indefinite =
            CsrMatrix::from_triplets(2, 2, &[(0, 0, 1.0), (0, 1, 2.0), (1, 0, 2.0), (1, 1, 1.0)]);
        let err = chol.solve(SystemMatrix::Csr(&indefinite), &[1.0, 1.0], &mut x[..2]).unwrap_err();
        assert!(matches!(err, SolveError::Factorization(_)), "{err:?}");
        // Negative and missing diagonal entries are reported with their row.
        let neg = CsrMatrix::from_triplets(3, 3, &[(0, 0, 2.0), (1, 1, 1.0), (2, 2, -1.0)]);
        assert_eq!(
            chol.solve(SystemMatrix::Csr(&neg), &[1.0; 3], &mut x),
            Err(SolveError::BadPivot { row: 2, value: -1.0 })
        );
        let missing = CsrMatrix::from_triplets(3, 3, &[(0, 0, 2.0), (2, 2, 1.0), (1, 2, 0.5), (2, 1, 0.5)]);
        assert_eq!(
            chol.solve(SystemMatrix::Csr(&missing), &[1.0; 3], &mut x),
            Err(SolveError::BadPivot { row: 1, value: 0.0 })
        );
        // Singular (positive semi-definite): [[1, 1], [1, 1]].
        let singular = CsrMatrix::from_triplets(2, 2, &[(0, 0, 1.0), (0, 1, 1.0), (1, 0, 1.0), (1, 1, 1.0)]);
        let err = chol.solve(SystemMatrix::Csr(&singular), &[1.0, 1.0], &mut x[..2]).unwrap_err();
        assert!(matches!(err, SolveError::Factorization(_)), "{err:?}");
        // NaN in an off-diagonal entry.
        let nan =
            CsrMatrix::from_triplets(2, 2, &[(0, 0, 1.0), (1, 0, f64::NAN), (0, 1, f64::NAN), (1, 1, 1.0)]);
        let err = chol.solve(SystemMatrix::Csr(&nan), &[1.0, 1.0], &mut x[..2]).unwrap_err();
        assert!(matches!(err, SolveError::Factorization(_) | SolveError::NonFinite { .. }), "{err:?}");
        // The solver still works afterwards.
        let ok = CsrMatrix::identity(3);
        chol.solve(SystemMatrix::Csr(&ok), &[1.0, 2.0, 3.0], &mut x).expect("identity");
        assert_eq!(x, [1.0, 2.0, 3.0]);
    }

    #[test]
    fn operator_is_rejected_and_zero_rhs() {
        let a = CsrMatrix::identity(2);
        let mut chol = SparseCholesky::new();
        let mut x = [5.0; 2];
        assert_eq!(
            chol.solve(SystemMatrix::Operator(&a), &[1.0; 2], &mut x),
            Err(SolveError::NeedsMatrix { solver: "cholesky" })
        );
        let info = chol.solve(SystemMatrix::Csr(&a), &[0.0; 2], &mut x).expect("SPD");
        assert_eq!(info, SolveInfo { iterations: 1, relative_residual: 0.0 });
        assert_eq!(x, [0.0; 2]);
        assert_eq!(chol.name(), "cholesky");
        assert!(chol.needs_matrix());
    }

    #[test]
    fn ldlt_solves_an_indefinite_symmetric_system() {
        // [[2, 1, 0], [1, -3, 1], [0, 1, 4]] is symmetric indefinite.
        let t = [(0, 0, 2.0), (0, 1, 1.0), (1, 0, 1.0), (1, 1, -3.0), (1, 2, 1.0), (2, 1, 1.0), (2, 2, 4.0)];
        let a = CsrMatrix::from_triplets(3, 3, &t);
        let x_true = [1.0, -2.0, 0.5];
        let mut b = [0.0; 3];
        a.mul_vec(&x_true, &mut b);
        let mut x = [0.0; 3];
        let mut ldlt = SparseLdlt::new();
        let info = ldlt.solve(SystemMatrix::Csr(&a), &b, &mut x).unwrap();
        assert!(info.relative_residual < 1e-14);
        for k in 0..3 {
            assert!((x[k] - x_true[k]).abs() < 1e-14);
        }
        // Cholesky refuses the same matrix; LDLT caches its symbolic factorisation the same way.
        assert!(SparseCholesky::new().solve(SystemMatrix::Csr(&a), &b, &mut x).is_err());
        ldlt.solve(SystemMatrix::Csr(&a), &b, &mut x).unwrap();
        assert_eq!(ldlt.symbolic_factorizations(), 1);
        assert_eq!(ldlt.name(), "ldlt");
        assert_eq!(
            ldlt.solve(SystemMatrix::Operator(&a), &b, &mut x),
            Err(SolveError::NeedsMatrix { solver: "ldlt" })
        );
    }

    #[test]
    fn ldlt_matches_cholesky_on_spd() {
        let mut rng = ChaCha8Rng::seed_from_u64(33);
        let a = random_spd(&mut rng, 50);
        let b: Vec<f64> = (0..50).map(|_| rng.random_range(-1.0..1.0)).collect();
        let (mut x1, mut x2) = (vec![0.0; 50], vec![0.0; 50]);
        SparseCholesky::new().solve(SystemMatrix::Csr(&a), &b, &mut x1).expect("SPD");
        SparseLdlt::new().solve(SystemMatrix::Csr(&a), &b, &mut x2).expect("SPD");
        assert!(max_abs_diff(&x1, &x2) <= 1e-12);
    }
}
