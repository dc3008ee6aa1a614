//! Sparse Cholesky (stub).
use super::{LinearSolver, SolveError, SolveInfo, SystemMatrix};
/// Sparse Cholesky.
#[derive(Default)]
pub struct SparseCholesky;
impl SparseCholesky { /// new
 #[must_use] pub fn new() -> Self { Self } }
impl LinearSolver for SparseCholesky {
    fn name(&self) -> &'static str { "cholesky" }
    fn needs_matrix(&self) -> bool { true }
    fn solve(&mut self, _a: SystemMatrix<'_>, _b: &[f64], _x: &mut [f64]) -> Result<SolveInfo, SolveError> { todo!() }
}
