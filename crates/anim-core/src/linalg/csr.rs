//! Compressed sparse row (CSR) matrices.
//!
//! # Storage
//!
//! An `nrows x ncols` matrix with `nnz` stored entries is held in three arrays:
//!
//! - `row_ptr` (length `nrows + 1`, `row_ptr[0] = 0`, non-decreasing, `row_ptr[nrows] = nnz`):
//!   the entries of row `i` occupy positions `row_ptr[i] .. row_ptr[i + 1]`;
//! - `col_idx` (length `nnz`): the column of each entry, strictly increasing within a row (sorted,
//!   no duplicates);
//! - `values` (length `nnz`): the value of each entry.
//!
//! This is the layout of Saad, *Iterative Methods for Sparse Linear Systems* (2nd ed., 2003),
//! section 3.4. Stored entries may be explicit zeros: the pattern is kept as assembled, so that a
//! solver that caches work per pattern (the symbolic Cholesky of [`super::direct`]) sees the same
//! pattern from one time step to the next.
//!
//! # Products
//!
//! [`CsrMatrix::mul_vec`] computes `y_i = sum_k a_{i, col_idx[k]} x_{col_idx[k]}` row by row, each
//! sum accumulated sequentially in storage order. Large matrices (more than
//! [`PARALLEL_ROW_THRESHOLD`] rows) split the rows into chunks handled by rayon tasks; because
//! every row is still summed by one task in the same order, the result is bitwise identical for
//! any thread count and to the serial path.
//!
//! # faer interop
//!
//! [`CsrMatrix::to_faer`] / [`CsrMatrix::from_faer`] convert to and from faer's compressed sparse
//! columns, [`CsrMatrix::to_faer_row`] / [`CsrMatrix::from_faer_row`] to and from its compressed
//! sparse rows.

use crate::par::prelude::*;
#[cfg(feature = "faer")]
use faer::sparse::{SparseColMat, SparseRowMat, SymbolicSparseColMat, SymbolicSparseRowMat};

use super::LinearOperator;

/// Matrices with more rows than this use rayon in [`CsrMatrix::mul_vec`].
pub const PARALLEL_ROW_THRESHOLD: usize = 4096;

/// Rows per rayon task in the parallel paths.
pub(crate) const ROW_CHUNK: usize = 1024;

/// A structural defect found by [`CsrMatrix::try_from_parts`].
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum CsrError {
    /// `row_ptr` does not have `nrows + 1` entries.
    #[error("row_ptr has length {found}, expected nrows + 1 = {expected}")]
    RowPtrLength {
        /// `nrows + 1`.
        expected: usize,
        /// Actual length.
        found: usize,
    },
    /// `row_ptr[0]` is not zero.
    #[error("row_ptr[0] = {found}, expected 0")]
    RowPtrStart {
        /// The value found.
        found: usize,
    },
    /// `row_ptr[row + 1] < row_ptr[row]`.
    #[error("row_ptr decreases at row {row}: row_ptr[{row}] = {start} > row_ptr[{row} + 1] = {end}")]
    RowPtrDecreasing {
        /// The row whose range is reversed.
        row: usize,
        /// `row_ptr[row]`.
        start: usize,
        /// `row_ptr[row + 1]`.
        end: usize,
    },
    /// `row_ptr[nrows]`, `col_idx.len()` and `values.len()` disagree.
    #[error(
        "entry counts disagree: row_ptr[nrows] = {row_ptr_end}, col_idx has {col_idx_len}, values has {values_len}"
    )]
    LengthMismatch {
        /// `row_ptr[nrows]`.
        row_ptr_end: usize,
        /// `col_idx.len()`.
        col_idx_len: usize,
        /// `values.len()`.
        values_len: usize,
    },
    /// A column index is `>= ncols`.
    #[error("entry {entry} of row {row} has column {col} >= ncols = {ncols}")]
    ColumnOutOfRange {
        /// Row of the entry.
        row: usize,
        /// Position of the entry in `col_idx`.
        entry: usize,
        /// Its column.
        col: usize,
        /// Number of columns.
        ncols: usize,
    },
    /// Columns of a row are not strictly increasing (unsorted or duplicated).
    #[error(
        "entry {entry} of row {row} has column {col}, not greater than the previous column {previous} (columns must be sorted without duplicates)"
    )]
    ColumnsNotIncreasing {
        /// Row of the entry.
        row: usize,
        /// Position of the entry in `col_idx`.
        entry: usize,
        /// Its column.
        col: usize,
        /// The column of the entry before it.
        previous: usize,
    },
}

/// A sparse matrix in compressed sparse row format (see the [module docs](self)).
///
/// Invariants: `row_ptr.len() == nrows + 1`, `row_ptr[0] == 0`, `row_ptr` non-decreasing,
/// `row_ptr[nrows] == col_idx.len() == values.len()`, and within each row the columns are strictly
/// increasing and `< ncols`.
#[derive(Debug, Clone, PartialEq)]
pub struct CsrMatrix {
    nrows: usize,
    ncols: usize,
    row_ptr: Vec<usize>,
    col_idx: Vec<usize>,
    values: Vec<f64>,
}

impl Default for CsrMatrix {
    /// The empty `0 x 0` matrix.
    fn default() -> Self {
        Self { nrows: 0, ncols: 0, row_ptr: vec![0], col_idx: Vec::new(), values: Vec::new() }
    }
}

impl CsrMatrix {
    /// Builds a matrix from `(row, col, value)` triplets in any order; duplicates are summed (in
    /// the order they appear in `triplets`). Explicit zeros are kept as stored entries.
    ///
    /// # Panics
    /// If a row index is `>= nrows` or a column index is `>= ncols`.
    #[must_use]
    #[track_caller]
    pub fn from_triplets(nrows: usize, ncols: usize, triplets: &[(usize, usize, f64)]) -> Self {
        // Counting sort by row (stable, so duplicates keep their input order).
        let mut counts = vec![0usize; nrows + 1];
        for (k, &(r, c, _)) in triplets.iter().enumerate() {
            assert!(
                r < nrows && c < ncols,
                "CsrMatrix::from_triplets: triplet {k} has index ({r}, {c}) outside the {nrows} x {ncols} matrix"
            );
            counts[r + 1] += 1;
        }
        for i in 0..nrows {
            counts[i + 1] += counts[i];
        }
        let mut next = counts.clone();
        let mut bucket: Vec<(usize, f64)> = vec![(0, 0.0); triplets.len()];
        for &(r, c, v) in triplets {
            bucket[next[r]] = (c, v);
            next[r] += 1;
        }
        // Sort each row by column (stable) and merge duplicates.
        let mut row_ptr = Vec::with_capacity(nrows + 1);
        let mut col_idx = Vec::with_capacity(triplets.len());
        let mut values = Vec::with_capacity(triplets.len());
        row_ptr.push(0);
        for i in 0..nrows {
            let row = &mut bucket[counts[i]..counts[i + 1]];
            row.sort_by_key(|&(c, _)| c);
            let row_start = col_idx.len();
            for &(c, v) in row.iter() {
                if col_idx.len() > row_start && col_idx.last() == Some(&c) {
                    if let Some(last) = values.last_mut() {
                        *last += v;
                    }
                } else {
                    col_idx.push(c);
                    values.push(v);
                }
            }
            row_ptr.push(col_idx.len());
        }
        Self { nrows, ncols, row_ptr, col_idx, values }
    }

    /// Builds a matrix from its CSR arrays after checking every invariant.
    ///
    /// # Errors
    /// [`CsrError`] naming the first defective row or entry.
    pub fn try_from_parts(
        nrows: usize,
        ncols: usize,
        row_ptr: Vec<usize>,
        col_idx: Vec<usize>,
        values: Vec<f64>,
    ) -> Result<Self, CsrError> {
        if row_ptr.len() != nrows + 1 {
            return Err(CsrError::RowPtrLength { expected: nrows + 1, found: row_ptr.len() });
        }
        if row_ptr[0] != 0 {
            return Err(CsrError::RowPtrStart { found: row_ptr[0] });
        }
        for row in 0..nrows {
            if row_ptr[row + 1] < row_ptr[row] {
                return Err(CsrError::RowPtrDecreasing { row, start: row_ptr[row], end: row_ptr[row + 1] });
            }
        }
        let nnz = row_ptr[nrows];
        if col_idx.len() != nnz || values.len() != nnz {
            return Err(CsrError::LengthMismatch {
                row_ptr_end: nnz,
                col_idx_len: col_idx.len(),
                values_len: values.len(),
            });
        }
        for row in 0..nrows {
            for entry in row_ptr[row]..row_ptr[row + 1] {
                let col = col_idx[entry];
                if col >= ncols {
                    return Err(CsrError::ColumnOutOfRange { row, entry, col, ncols });
                }
                if entry > row_ptr[row] && col <= col_idx[entry - 1] {
                    return Err(CsrError::ColumnsNotIncreasing {
                        row,
                        entry,
                        col,
                        previous: col_idx[entry - 1],
                    });
                }
            }
        }
        Ok(Self { nrows, ncols, row_ptr, col_idx, values })
    }

    /// The `n x n` identity.
    #[must_use]
    pub fn identity(n: usize) -> Self {
        Self {
            nrows: n,
            ncols: n,
            row_ptr: (0..=n).collect(),
            col_idx: (0..n).collect(),
            values: vec![1.0; n],
        }
    }

    /// Number of rows.
    #[must_use]
    pub fn nrows(&self) -> usize {
        self.nrows
    }

    /// Number of columns.
    #[must_use]
    pub fn ncols(&self) -> usize {
        self.ncols
    }

    /// Number of stored entries.
    #[must_use]
    pub fn nnz(&self) -> usize {
        self.col_idx.len()
    }

    /// Row pointers (`nrows + 1` entries).
    #[must_use]
    pub fn row_ptr(&self) -> &[usize] {
        &self.row_ptr
    }

    /// Column index of each stored entry.
    #[must_use]
    pub fn col_idx(&self) -> &[usize] {
        &self.col_idx
    }

    /// Value of each stored entry.
    #[must_use]
    pub fn values(&self) -> &[f64] {
        &self.values
    }

    /// Mutable values; the pattern stays fixed (re-assembly in place).
    #[must_use]
    pub fn values_mut(&mut self) -> &mut [f64] {
        &mut self.values
    }

    /// Columns and values of row `i`.
    ///
    /// # Panics
    /// If `i >= nrows`.
    #[must_use]
    #[track_caller]
    pub fn row(&self, i: usize) -> (&[usize], &[f64]) {
        assert!(i < self.nrows, "CsrMatrix::row: row {i} out of range (nrows = {})", self.nrows);
        let range = self.row_ptr[i]..self.row_ptr[i + 1];
        (&self.col_idx[range.clone()], &self.values[range])
    }

    /// Position in [`col_idx`](Self::col_idx) / [`values`](Self::values) of entry `(r, c)`, or
    /// `None` when it is not stored (binary search within the row).
    ///
    /// # Panics
    /// If `r >= nrows`.
    #[must_use]
    #[track_caller]
    pub fn position(&self, r: usize, c: usize) -> Option<usize> {
        assert!(r < self.nrows, "CsrMatrix::position: row {r} out of range (nrows = {})", self.nrows);
        let start = self.row_ptr[r];
        let cols = &self.col_idx[start..self.row_ptr[r + 1]];
        cols.binary_search(&c).ok().map(|k| start + k)
    }

    /// Value of entry `(r, c)`, or `None` when it is not stored.
    ///
    /// # Panics
    /// If `r >= nrows`.
    #[must_use]
    #[track_caller]
    pub fn get(&self, r: usize, c: usize) -> Option<f64> {
        self.position(r, c).map(|k| self.values[k])
    }

    /// Writes the diagonal (`0` where no entry is stored) into `out`.
    ///
    /// # Panics
    /// If `out.len() != min(nrows, ncols)`.
    #[track_caller]
    pub fn diagonal_into(&self, out: &mut [f64]) {
        let n = self.nrows.min(self.ncols);
        assert_eq!(out.len(), n, "CsrMatrix::diagonal_into: out has the wrong length");
        for (i, o) in out.iter_mut().enumerate() {
            *o = self.get(i, i).unwrap_or(0.0);
        }
    }

    /// `y = A x`.
    ///
    /// Rows are split among rayon tasks when `nrows > PARALLEL_ROW_THRESHOLD`; each row is summed
    /// sequentially in storage order by one task, so the result does not depend on the thread
    /// count.
    ///
    /// # Panics
    /// If `x.len() != ncols` or `y.len() != nrows`.
    #[track_caller]
    pub fn mul_vec(&self, x: &[f64], y: &mut [f64]) {
        assert_eq!(x.len(), self.ncols, "CsrMatrix::mul_vec: x.len() != ncols");
        assert_eq!(y.len(), self.nrows, "CsrMatrix::mul_vec: y.len() != nrows");
        if self.nrows > PARALLEL_ROW_THRESHOLD {
            y.par_chunks_mut(ROW_CHUNK).enumerate().for_each(|(chunk, ys)| {
                self.mul_rows(chunk * ROW_CHUNK, x, ys);
            });
        } else {
            self.mul_rows(0, x, y);
        }
    }

    /// `y[k] = (A x)[first_row + k]` for every `k`.
    #[inline]
    fn mul_rows(&self, first_row: usize, x: &[f64], y: &mut [f64]) {
        for (k, yi) in y.iter_mut().enumerate() {
            let i = first_row + k;
            let range = self.row_ptr[i]..self.row_ptr[i + 1];
            let mut s = 0.0;
            for (&c, &v) in self.col_idx[range.clone()].iter().zip(&self.values[range]) {
                s += v * x[c];
            }
            *yi = s;
        }
    }

    /// The transpose, as a new CSR matrix (entries of each row of the result are sorted).
    #[must_use]
    pub fn transpose(&self) -> Self {
        let mut row_ptr = vec![0usize; self.ncols + 1];
        for &c in &self.col_idx {
            row_ptr[c + 1] += 1;
        }
        for j in 0..self.ncols {
            row_ptr[j + 1] += row_ptr[j];
        }
        let mut next = row_ptr.clone();
        let mut col_idx = vec![0usize; self.nnz()];
        let mut values = vec![0.0; self.nnz()];
        // Rows are visited in increasing order, so the columns of the transpose come out sorted.
        for i in 0..self.nrows {
            for k in self.row_ptr[i]..self.row_ptr[i + 1] {
                let c = self.col_idx[k];
                col_idx[next[c]] = i;
                values[next[c]] = self.values[k];
                next[c] += 1;
            }
        }
        Self { nrows: self.ncols, ncols: self.nrows, row_ptr, col_idx, values }
    }

    /// Whether the matrix is square and `|a_ij - a_ji| <= tol` (absolute) for every stored entry,
    /// an entry missing on one side counting as zero. Any NaN makes it `false`.
    #[must_use]
    pub fn is_symmetric(&self, tol: f64) -> bool {
        if self.nrows != self.ncols {
            return false;
        }
        for i in 0..self.nrows {
            for k in self.row_ptr[i]..self.row_ptr[i + 1] {
                let j = self.col_idx[k];
                let mirror = self.get(j, i).unwrap_or(0.0);
                // Written so that NaN fails the test.
                if !((self.values[k] - mirror).abs() <= tol) {
                    return false;
                }
            }
        }
        true
    }

    /// Dense copy, row by row (for tests and debugging).
    #[must_use]
    pub fn to_dense(&self) -> Vec<Vec<f64>> {
        let mut out = vec![vec![0.0; self.ncols]; self.nrows];
        for (i, row) in out.iter_mut().enumerate() {
            let (cols, vals) = self.row(i);
            for (&c, &v) in cols.iter().zip(vals) {
                row[c] = v;
            }
        }
        out
    }
}

/// Conversions to and from faer's sparse matrices (feature `faer`).
#[cfg(feature = "faer")]
impl CsrMatrix {
    /// Converts to faer's compressed sparse columns (same entries, explicit zeros included).
    #[must_use]
    pub fn to_faer(&self) -> SparseColMat<usize, f64> {
        // The CSR arrays of A^T are the CSC arrays of A.
        let t = self.transpose();
        let symbolic = SymbolicSparseColMat::new_checked(self.nrows, self.ncols, t.row_ptr, None, t.col_idx);
        SparseColMat::new(symbolic, t.values)
    }

    /// Converts from faer's compressed sparse columns (any valid faer matrix: unsorted or
    /// non-compressed columns are accepted; duplicates, if present, are summed).
    #[must_use]
    pub fn from_faer(m: &SparseColMat<usize, f64>) -> Self {
        let triplets: Vec<(usize, usize, f64)> =
            m.as_ref().triplet_iter().map(|t| (t.row, t.col, *t.val)).collect();
        Self::from_triplets(m.nrows(), m.ncols(), &triplets)
    }

    /// Converts to faer's compressed sparse rows (a copy of the same arrays).
    #[must_use]
    pub fn to_faer_row(&self) -> SparseRowMat<usize, f64> {
        let symbolic = SymbolicSparseRowMat::new_checked(
            self.nrows,
            self.ncols,
            self.row_ptr.clone(),
            None,
            self.col_idx.clone(),
        );
        SparseRowMat::new(symbolic, self.values.clone())
    }

    /// Converts from faer's compressed sparse rows (duplicates, if present, are summed).
    #[must_use]
    pub fn from_faer_row(m: &SparseRowMat<usize, f64>) -> Self {
        let triplets: Vec<(usize, usize, f64)> =
            m.as_ref().triplet_iter().map(|t| (t.row, t.col, *t.val)).collect();
        Self::from_triplets(m.nrows(), m.ncols(), &triplets)
    }
}

impl LinearOperator for CsrMatrix {
    /// Number of rows.
    ///
    /// # Panics
    /// If the matrix is not square.
    fn dim(&self) -> usize {
        assert_eq!(
            self.nrows, self.ncols,
            "CsrMatrix as LinearOperator: the matrix must be square ({} x {})",
            self.nrows, self.ncols
        );
        self.nrows
    }

    fn apply(&self, x: &[f64], y: &mut [f64]) {
        assert_eq!(
            self.nrows, self.ncols,
            "CsrMatrix as LinearOperator: the matrix must be square ({} x {})",
            self.nrows, self.ncols
        );
        self.mul_vec(x, y);
    }

    fn diagonal(&self, out: &mut [f64]) -> bool {
        self.diagonal_into(out);
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    #[cfg(feature = "faer")]
    use faer::{Accum, Mat, Par};
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn random_triplets(
        rng: &mut ChaCha8Rng,
        nrows: usize,
        ncols: usize,
        count: usize,
    ) -> Vec<(usize, usize, f64)> {
        (0..count)
            .map(|_| (rng.random_range(0..nrows), rng.random_range(0..ncols), rng.random_range(-1.0..1.0)))
            .collect()
    }

    /// Dense reference assembled directly from triplets.
    fn dense_from_triplets(nrows: usize, ncols: usize, t: &[(usize, usize, f64)]) -> Vec<Vec<f64>> {
        let mut d = vec![vec![0.0; ncols]; nrows];
        for &(r, c, v) in t {
            d[r][c] += v;
        }
        d
    }

    fn assert_invariants(m: &CsrMatrix) {
        let rebuilt = CsrMatrix::try_from_parts(
            m.nrows(),
            m.ncols(),
            m.row_ptr().to_vec(),
            m.col_idx().to_vec(),
            m.values().to_vec(),
        );
        assert_eq!(rebuilt.as_ref(), Ok(m));
    }

    #[test]
    fn from_triplets_sorts_and_sums_duplicates() {
        let t = [(1, 2, 1.0), (0, 1, 2.0), (1, 0, 3.0), (1, 2, 4.0), (0, 1, -2.0), (2, 2, 0.0)];
        let m = CsrMatrix::from_triplets(3, 3, &t);
        assert_eq!(m.row_ptr(), &[0, 1, 3, 4]);
        assert_eq!(m.col_idx(), &[1, 0, 2, 2]);
        assert_eq!(m.values(), &[0.0, 3.0, 5.0, 0.0]);
        assert_eq!(m.nnz(), 4);
        assert_eq!(m.get(1, 2), Some(5.0));
        assert_eq!(m.get(2, 2), Some(0.0), "explicit zeros are kept");
        assert_eq!(m.get(2, 0), None);
        assert_eq!(m.position(1, 2), Some(2));
        assert_eq!(m.position(0, 0), None);
        assert_eq!(m.row(1), (&[0usize, 2][..], &[3.0, 5.0][..]));
        assert_invariants(&m);
    }

    #[test]
    fn from_triplets_matches_dense_reference() {
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        for &(nr, nc, count) in &[(7, 5, 30), (20, 20, 150), (1, 9, 12), (9, 1, 12), (4, 4, 0)] {
            let t = random_triplets(&mut rng, nr, nc, count);
            let m = CsrMatrix::from_triplets(nr, nc, &t);
            assert_invariants(&m);
            let d = dense_from_triplets(nr, nc, &t);
            let md = m.to_dense();
            for i in 0..nr {
                for j in 0..nc {
                    assert!((md[i][j] - d[i][j]).abs() <= 1e-14, "({i}, {j})");
                }
            }
        }
    }

    #[test]
    #[should_panic(expected = "outside the 3 x 3 matrix")]
    fn from_triplets_rejects_out_of_range() {
        let _ = CsrMatrix::from_triplets(3, 3, &[(0, 0, 1.0), (1, 3, 1.0)]);
    }

    #[test]
    fn try_from_parts_reports_defects() {
        let ok = CsrMatrix::try_from_parts(2, 3, vec![0, 2, 3], vec![0, 2, 1], vec![1.0, 2.0, 3.0]);
        assert!(ok.is_ok());
        assert_eq!(
            CsrMatrix::try_from_parts(2, 3, vec![0, 2], vec![0, 2], vec![1.0, 2.0]),
            Err(CsrError::RowPtrLength { expected: 3, found: 2 })
        );
        assert_eq!(
            CsrMatrix::try_from_parts(2, 3, vec![1, 2, 3], vec![0, 2, 1], vec![1.0, 2.0, 3.0]),
            Err(CsrError::RowPtrStart { found: 1 })
        );
        assert_eq!(
            CsrMatrix::try_from_parts(2, 3, vec![0, 2, 1], vec![0, 2], vec![1.0, 2.0]),
            Err(CsrError::RowPtrDecreasing { row: 1, start: 2, end: 1 })
        );
        assert_eq!(
            CsrMatrix::try_from_parts(2, 3, vec![0, 2, 3], vec![0, 2, 1], vec![1.0, 2.0]),
            Err(CsrError::LengthMismatch { row_ptr_end: 3, col_idx_len: 3, values_len: 2 })
        );
        assert_eq!(
            CsrMatrix::try_from_parts(2, 3, vec![0, 2, 3], vec![0, 3, 1], vec![1.0, 2.0, 3.0]),
            Err(CsrError::ColumnOutOfRange { row: 0, entry: 1, col: 3, ncols: 3 })
        );
        assert_eq!(
            CsrMatrix::try_from_parts(2, 3, vec![0, 1, 3], vec![0, 2, 2], vec![1.0, 2.0, 3.0]),
            Err(CsrError::ColumnsNotIncreasing { row: 1, entry: 2, col: 2, previous: 2 })
        );
        assert_eq!(
            CsrMatrix::try_from_parts(2, 3, vec![0, 1, 3], vec![0, 2, 1], vec![1.0, 2.0, 3.0]),
            Err(CsrError::ColumnsNotIncreasing { row: 1, entry: 2, col: 1, previous: 2 })
        );
    }

    #[test]
    fn identity_and_diagonal() {
        let i = CsrMatrix::identity(4);
        assert_invariants(&i);
        let mut x = [1.0, -2.0, 3.5, 0.25];
        let mut y = [0.0; 4];
        i.mul_vec(&x, &mut y);
        assert_eq!(y, x);
        let m = CsrMatrix::from_triplets(3, 3, &[(0, 0, 2.0), (0, 1, 1.0), (2, 2, -4.0)]);
        m.diagonal_into(&mut x[..3]);
        assert_eq!(&x[..3], &[2.0, 0.0, -4.0]);
        let mut d = [9.0; 3];
        assert!(LinearOperator::diagonal(&m, &mut d));
        assert_eq!(d, [2.0, 0.0, -4.0]);
        assert_eq!(CsrMatrix::default().nnz(), 0);
        assert_invariants(&CsrMatrix::default());
    }

    #[test]
    fn mul_vec_matches_dense_product() {
        let mut rng = ChaCha8Rng::seed_from_u64(2);
        let (nr, nc) = (13, 9);
        let t = random_triplets(&mut rng, nr, nc, 60);
        let m = CsrMatrix::from_triplets(nr, nc, &t);
        let d = dense_from_triplets(nr, nc, &t);
        let x: Vec<f64> = (0..nc).map(|_| rng.random_range(-1.0..1.0)).collect();
        let mut y = vec![0.0; nr];
        m.mul_vec(&x, &mut y);
        for i in 0..nr {
            let reference: f64 = (0..nc).map(|j| d[i][j] * x[j]).sum();
            assert!((y[i] - reference).abs() <= 1e-13, "row {i}: {} vs {reference}", y[i]);
        }
    }

    /// The parallel path (nrows > threshold) must equal the sequential row sums bit for bit, for
    /// any thread count.
    #[test]
    fn mul_vec_parallel_is_bitwise_deterministic() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let n = 3 * PARALLEL_ROW_THRESHOLD + 17;
        let t = random_triplets(&mut rng, n, n, 12 * n);
        let m = CsrMatrix::from_triplets(n, n, &t);
        let x: Vec<f64> = (0..n).map(|_| rng.random_range(-1.0..1.0)).collect();
        // Serial reference written independently: each row summed in storage order.
        let mut reference = vec![0.0; n];
        for (i, r) in reference.iter_mut().enumerate() {
            let (cols, vals) = m.row(i);
            let mut s = 0.0;
            for (&c, &v) in cols.iter().zip(vals) {
                s += v * x[c];
            }
            *r = s;
        }
        for threads in [1, 2, 3] {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("thread pool");
            let mut y = vec![0.0; n];
            pool.install(|| m.mul_vec(&x, &mut y));
            assert!(y.iter().zip(&reference).all(|(a, b)| a.to_bits() == b.to_bits()), "{threads} threads");
        }
    }

    #[test]
    fn transpose_and_symmetry() {
        let mut rng = ChaCha8Rng::seed_from_u64(4);
        let t = random_triplets(&mut rng, 6, 8, 25);
        let m = CsrMatrix::from_triplets(6, 8, &t);
        let mt = m.transpose();
        assert_invariants(&mt);
        let (d, dt) = (m.to_dense(), mt.to_dense());
        for i in 0..6 {
            for j in 0..8 {
                assert_eq!(d[i][j], dt[j][i]);
            }
        }
        assert!(!m.is_symmetric(1e-12), "non-square");
        // A + A^T is symmetric; perturbing one entry breaks it.
        let mut sym_t = random_triplets(&mut rng, 7, 7, 20);
        let mirrored: Vec<_> = sym_t.iter().map(|&(r, c, v)| (c, r, v)).collect();
        sym_t.extend(mirrored);
        let mut s = CsrMatrix::from_triplets(7, 7, &sym_t);
        assert!(s.is_symmetric(1e-15));
        let k = s.col_idx().iter().enumerate().position(|(k, &c)| {
            let row = s.row_ptr().partition_point(|&p| p <= k) - 1;
            row != c
        });
        let k = k.expect("an off-diagonal entry");
        s.values_mut()[k] += 1e-6;
        assert!(s.is_symmetric(1e-5));
        assert!(!s.is_symmetric(1e-7));
        s.values_mut()[k] = f64::NAN;
        assert!(!s.is_symmetric(1.0));
    }

    #[test]
    #[cfg(feature = "faer")]
    fn faer_round_trip_and_product() {
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        for &(nr, nc, count) in &[(11, 7, 40), (30, 30, 200), (5, 5, 0)] {
            let t = random_triplets(&mut rng, nr, nc, count);
            let m = CsrMatrix::from_triplets(nr, nc, &t);
            let f = m.to_faer();
            assert_eq!((f.nrows(), f.ncols()), (nr, nc));
            assert_eq!(f.compute_nnz(), m.nnz());
            assert_eq!(CsrMatrix::from_faer(&f), m);
            let fr = m.to_faer_row();
            assert_eq!(CsrMatrix::from_faer_row(&fr), m);
            // faer built independently from the same triplets must agree entry by entry.
            let faer_triplets: Vec<faer::sparse::Triplet<usize, usize, f64>> =
                t.iter().map(|&(r, c, v)| faer::sparse::Triplet::new(r, c, v)).collect();
            let g = SparseColMat::<usize, f64>::try_new_from_triplets(nr, nc, &faer_triplets)
                .expect("valid triplets");
            let (gd, md) = (g.to_dense(), m.to_dense());
            for i in 0..nr {
                for j in 0..nc {
                    assert!((gd[(i, j)] - md[i][j]).abs() <= 1e-14);
                }
            }
            // Product against faer's own sparse x dense kernel.
            let x = Mat::<f64>::from_fn(nc, 1, |_, _| rng.random_range(-1.0..1.0));
            let mut fy = Mat::<f64>::zeros(nr, 1);
            faer::sparse::linalg::matmul::sparse_dense_matmul(
                fy.as_mut(),
                Accum::Replace,
                f.as_ref(),
                x.as_ref(),
                1.0,
                Par::Seq,
            );
            let xs: Vec<f64> = (0..nc).map(|i| x[(i, 0)]).collect();
            let mut y = vec![0.0; nr];
            m.mul_vec(&xs, &mut y);
            for i in 0..nr {
                assert!((y[i] - fy[(i, 0)]).abs() <= 1e-13, "row {i}");
            }
        }
    }

    #[test]
    #[should_panic(expected = "must be square")]
    fn operator_requires_square() {
        let m = CsrMatrix::from_triplets(2, 3, &[(0, 0, 1.0)]);
        let _ = LinearOperator::dim(&m);
    }

    #[test]
    #[should_panic(expected = "x.len() != ncols")]
    fn mul_vec_checks_lengths() {
        let m = CsrMatrix::identity(3);
        let mut y = [0.0; 3];
        m.mul_vec(&[1.0, 2.0], &mut y);
    }
}
