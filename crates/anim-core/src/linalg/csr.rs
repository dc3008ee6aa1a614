//! CSR matrix (stub).
/// Compressed sparse rows.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct CsrMatrix { nrows: usize, ncols: usize, row_ptr: Vec<usize>, col_idx: Vec<usize>, values: Vec<f64> }
impl CsrMatrix {
    /// rows
    #[must_use] pub fn nrows(&self) -> usize { self.nrows }
    /// cols
    #[must_use] pub fn ncols(&self) -> usize { self.ncols }
    /// From (row, col, value) triplets; duplicates are summed.
    #[must_use] pub fn from_triplets(nrows: usize, ncols: usize, _t: &[(usize, usize, f64)]) -> Self { let _ = (&Self::default().row_ptr, &Self::default().col_idx, &Self::default().values); Self { nrows, ncols, ..Default::default() } }
}
