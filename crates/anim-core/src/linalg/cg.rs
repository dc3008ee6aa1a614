//! Conjugate gradients (stub, replaced by the implementation).
use super::{IterativeParams, LinearSolver, SolveError, SolveInfo, SystemMatrix};
/// Preconditioner choice.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Preconditioner { /// none
 Identity, /// diagonal
 Jacobi }
/// CG solver.
pub struct Cg { _p: Preconditioner, _params: IterativeParams }
impl Cg { /// new
 #[must_use] pub fn new(p: Preconditioner, params: IterativeParams) -> Self { Self { _p: p, _params: params } } }
impl LinearSolver for Cg {
    fn name(&self) -> &'static str { "cg" }
    fn needs_matrix(&self) -> bool { false }
    fn solve(&mut self, _a: SystemMatrix<'_>, _b: &[f64], _x: &mut [f64]) -> Result<SolveInfo, SolveError> { todo!() }
}
