//! Jacobi and Gauss-Seidel (stub).
use super::{IterativeParams, LinearSolver, SolveError, SolveInfo, SystemMatrix};
/// Jacobi.
pub struct Jacobi { _params: IterativeParams }
impl Jacobi { /// new
 #[must_use] pub fn new(params: IterativeParams) -> Self { Self { _params: params } } }
impl LinearSolver for Jacobi {
    fn name(&self) -> &'static str { "jacobi" }
    fn needs_matrix(&self) -> bool { true }
    fn solve(&mut self, _a: SystemMatrix<'_>, _b: &[f64], _x: &mut [f64]) -> Result<SolveInfo, SolveError> { todo!() }
}
/// Gauss-Seidel.
pub struct GaussSeidel { _params: IterativeParams }
impl GaussSeidel { /// new
 #[must_use] pub fn new(params: IterativeParams) -> Self { Self { _params: params } } }
impl LinearSolver for GaussSeidel {
    fn name(&self) -> &'static str { "gauss-seidel" }
    fn needs_matrix(&self) -> bool { true }
    fn solve(&mut self, _a: SystemMatrix<'_>, _b: &[f64], _x: &mut [f64]) -> Result<SolveInfo, SolveError> { todo!() }
}
