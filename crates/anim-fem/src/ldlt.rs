//! Sparse `L D L^T` factorisation (faer), the direct solver for symmetric matrices that need not
//! be positive definite (Newton without the positive semi-definite projection).
//!
//! Like anim-core's sparse Cholesky, the symbolic factorisation (approximate minimum degree
//! ordering, elimination tree, pattern of `L`) is computed once per sparsity pattern and reused;
//! each solve redoes only the numeric phase, sequentially (`Par::Seq`), so results do not depend
//! on the thread count. No pivoting is done (faer's simplicial/supernodal `L D L^T`), so a zero
//! pivot fails; a non-finite solution is reported as [`SolveError::NonFinite`].

use anim_core::linalg::{CsrMatrix, LinearSolver, SolveError, SolveInfo, SystemMatrix, norm};
use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::cholesky::ldlt::factor::LdltRegularization;
use faer::sparse::linalg::cholesky::{
    CholeskySymbolicParams, SymbolicCholesky, SymmetricOrdering, factorize_symbolic_cholesky,
};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Par, Side};

/// Sparse `L D L^T` solver with a cached symbolic factorisation.
pub struct SparseLdlt {
    row_ptr: Vec<usize>,
    col_idx: Vec<usize>,
    symbolic: Option<SymbolicCholesky<usize>>,
    l_values: Vec<f64>,
    workspace: MemBuffer,
    residual: Vec<f64>,
}

impl std::fmt::Debug for SparseLdlt {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SparseLdlt").field("dim", &self.row_ptr.len().saturating_sub(1)).finish()
    }
}

impl Default for SparseLdlt {
    fn default() -> Self {
        Self::new()
    }
}

impl SparseLdlt {
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
        }
    }

    fn ensure_symbolic(&mut self, a: &CsrMatrix) -> Result<(), SolveError> {
        if self.symbolic.is_some() && self.row_ptr == a.row_ptr() && self.col_idx == a.col_idx() {
            return Ok(());
        }
        self.symbolic = None;
        let n = a.nrows();
        let pattern = SymbolicSparseColMatRef::new_checked(n, n, a.row_ptr(), None, a.col_idx());
        let symbolic = factorize_symbolic_cholesky(
            pattern,
            Side::Upper,
            SymmetricOrdering::Amd,
            CholeskySymbolicParams::default(),
        )
        .map_err(|e| SolveError::Factorization(format!("symbolic LDLT: {e}")))?;
        let req = StackReq::any_of(&[
            symbolic.factorize_numeric_ldlt_scratch::<f64>(Par::Seq, Default::default()),
            symbolic.solve_in_place_scratch::<f64>(1, Par::Seq),
        ]);
        self.workspace =
            MemBuffer::try_new(req).map_err(|e| SolveError::Factorization(format!("LDLT workspace: {e}")))?;
        self.l_values.clear();
        self.l_values.resize(symbolic.len_val(), 0.0);
        self.row_ptr.clear();
        self.row_ptr.extend_from_slice(a.row_ptr());
        self.col_idx.clear();
        self.col_idx.extend_from_slice(a.col_idx());
        self.symbolic = Some(symbolic);
        Ok(())
    }
}

impl LinearSolver for SparseLdlt {
    fn name(&self) -> &'static str {
        "ldlt"
    }

    fn needs_matrix(&self) -> bool {
        true
    }

    fn solve(&mut self, a: SystemMatrix<'_>, b: &[f64], x: &mut [f64]) -> Result<SolveInfo, SolveError> {
        let SystemMatrix::Csr(a) = a else {
            return Err(SolveError::NeedsMatrix { solver: "ldlt" });
        };
        let n = a.nrows();
        assert_eq!(b.len(), n, "SparseLdlt: b.len() != nrows");
        assert_eq!(x.len(), n, "SparseLdlt: x.len() != nrows");
        let b_norm = norm(b);
        if !b_norm.is_finite() {
            return Err(SolveError::NonFinite { iteration: 0 });
        }
        if n == 0 {
            return Ok(SolveInfo { iterations: 1, relative_residual: 0.0 });
        }
        self.ensure_symbolic(a)?;
        let Some(symbolic) = self.symbolic.as_ref() else {
            return Err(SolveError::Factorization("symbolic factorisation missing".into()));
        };
        let pattern = SymbolicSparseColMatRef::new_checked(n, n, a.row_ptr(), None, a.col_idx());
        let mat = SparseColMatRef::new(pattern, a.values());
        let ldlt = symbolic
            .factorize_numeric_ldlt::<f64>(
                &mut self.l_values,
                mat,
                Side::Upper,
                LdltRegularization::default(),
                Par::Seq,
                MemStack::new(&mut self.workspace),
                Default::default(),
            )
            .map_err(|e| SolveError::Factorization(format!("numeric LDLT: {e}")))?;
        x.copy_from_slice(b);
        ldlt.solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(x, n, 1),
            Par::Seq,
            MemStack::new(&mut self.workspace),
        );
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
        Ok(SolveInfo { iterations: 1, relative_residual: if b_norm == 0.0 { 0.0 } else { r_norm / b_norm } })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solves_an_indefinite_symmetric_system() {
        // [[2, 1, 0], [1, -3, 1], [0, 1, 4]] is symmetric indefinite.
        let t = [(0, 0, 2.0), (0, 1, 1.0), (1, 0, 1.0), (1, 1, -3.0), (1, 2, 1.0), (2, 1, 1.0), (2, 2, 4.0)];
        let a = CsrMatrix::from_triplets(3, 3, &t);
        let x_true = [1.0, -2.0, 0.5];
        let mut b = [0.0; 3];
        a.mul_vec(&x_true, &mut b);
        let mut x = [0.0; 3];
        let info = SparseLdlt::new().solve(SystemMatrix::Csr(&a), &b, &mut x).unwrap();
        assert!(info.relative_residual < 1e-14);
        for k in 0..3 {
            assert!((x[k] - x_true[k]).abs() < 1e-14);
        }
    }
}
