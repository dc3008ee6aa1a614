//! Linear algebra shared by the implicit solvers of every crate.
//!
//! - [`LinearOperator`]: a square operator known only by its action `y = A x` (matrix-free).
//! - [`CsrMatrix`]: compressed sparse rows, built from triplets, convertible to and from faer's
//!   sparse types.
//! - Iterative solvers: conjugate gradients with an identity or Jacobi preconditioner ([`cg`]),
//!   Jacobi and Gauss-Seidel sweeps ([`stationary`]), behind the [`LinearSolver`] trait so that an
//!   implicit integrator takes any of them; sparse direct solves by faer's Cholesky and `L D L^T`,
//!   one symbolic-factorisation cache for both ([`direct`]).
//! - [`schur`]: block elimination by Schur complements.
//! - [`svd`]: 3x3 singular value and polar decompositions returning proper rotations, the
//!   building block of corotated, fixed-corotated and snow materials.
//!
//! Conventions: vectors are `&[f64]` slices; `x` passed to a solver is the initial guess and
//! receives the solution; shape mismatches are programming errors and panic with a clear message,
//! numerical failure (no convergence, a non-positive pivot) is a [`SolveError`].

pub mod cg;
pub mod csr;
#[cfg(feature = "faer")]
pub mod direct;
#[cfg(feature = "faer")]
pub mod schur;
pub mod stationary;
pub mod svd;

pub use cg::{Cg, Preconditioner};
pub use csr::{CsrError, CsrMatrix};
#[cfg(feature = "faer")]
pub use direct::{Factorization, Ldlt, Llt, SparseCholesky, SparseDirect, SparseLdlt};
#[cfg(feature = "faer")]
pub use schur::{Eliminate, schur_complement, solve_block, solve_block_diagonal_a};
pub use stationary::{GaussSeidel, Jacobi, gauss_seidel_sweep, jacobi_sweep};
pub use svd::{Svd3, polar, polar_f32, svd3, svd3_f32, svd3_real};

/// A square linear operator known by its action.
pub trait LinearOperator {
    /// Number of rows (= columns).
    fn dim(&self) -> usize;
    /// Writes `y = A x`. `x` and `y` have length [`dim`](Self::dim).
    fn apply(&self, x: &[f64], y: &mut [f64]);
    /// Writes the diagonal of `A` into `out` and returns `true`, or returns `false` when the
    /// operator cannot provide it cheaply (then Jacobi preconditioning is unavailable).
    fn diagonal(&self, out: &mut [f64]) -> bool {
        let _ = out;
        false
    }
}

/// The matrix a [`LinearSolver`] is handed: matrix-free or assembled.
#[derive(Clone, Copy)]
pub enum SystemMatrix<'a> {
    /// Known only by its action; enough for conjugate gradients.
    Operator(&'a dyn LinearOperator),
    /// Assembled; required by Jacobi, Gauss-Seidel and direct solvers.
    Csr(&'a CsrMatrix),
}

impl SystemMatrix<'_> {
    /// Number of rows.
    #[must_use]
    pub fn dim(&self) -> usize {
        match self {
            SystemMatrix::Operator(op) => op.dim(),
            SystemMatrix::Csr(m) => m.nrows(),
        }
    }
}

/// Stopping rule of an iterative solve.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields, default))]
#[non_exhaustive]
pub struct IterativeParams {
    /// Stop when `||b - A x|| <= tolerance * ||b||`. Default `1e-10`.
    pub tolerance: f64,
    /// Give up after this many iterations (sweeps for Jacobi / Gauss-Seidel). Default `1000`.
    pub max_iterations: usize,
}

impl Default for IterativeParams {
    fn default() -> Self {
        Self { tolerance: 1e-10, max_iterations: 1000 }
    }
}

impl IterativeParams {
    /// Parameters with the given tolerance and iteration cap.
    #[must_use]
    pub fn new(tolerance: f64, max_iterations: usize) -> Self {
        Self { tolerance, max_iterations }
    }
}

/// What a successful solve did.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct SolveInfo {
    /// Iterations (or sweeps) performed; 1 for a direct solve.
    pub iterations: usize,
    /// Final relative residual `||b - A x|| / ||b||` (0 when `b = 0`).
    pub relative_residual: f64,
}

/// A linear solve that failed numerically or was handed the wrong kind of matrix.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SolveError {
    /// The iteration cap was reached before the tolerance.
    #[error("no convergence after {iterations} iterations (relative residual {relative_residual:e})")]
    NotConverged {
        /// Iterations performed.
        iterations: usize,
        /// Relative residual reached.
        relative_residual: f64,
    },
    /// Conjugate gradients met a direction of non-positive curvature: the matrix is not SPD.
    #[error("matrix is not positive definite (p^T A p = {curvature:e} at iteration {iteration})")]
    NotPositiveDefinite {
        /// Iteration at which it was detected.
        iteration: usize,
        /// The offending curvature.
        curvature: f64,
    },
    /// An unusable diagonal entry: zero or non-finite for Jacobi and Gauss-Seidel sweeps,
    /// non-positive (or NaN) for the Jacobi preconditioner and the sparse Cholesky solve.
    #[error("zero or non-positive pivot {value:e} at row {row}")]
    BadPivot {
        /// Row of the pivot.
        row: usize,
        /// Its value.
        value: f64,
    },
    /// The solver needs an assembled matrix but was handed a matrix-free operator.
    #[error("{solver} needs an assembled matrix; this system provides only a matrix-free operator")]
    NeedsMatrix {
        /// Name of the solver.
        solver: &'static str,
    },
    /// The preconditioner needs the operator's diagonal, which it does not provide.
    #[error("Jacobi preconditioning needs the operator diagonal, which this operator does not provide")]
    NoDiagonal,
    /// Non-finite values appeared in the iteration.
    #[error("non-finite value in the solve at iteration {iteration}")]
    NonFinite {
        /// Iteration at which it was detected.
        iteration: usize,
    },
    /// The solver was compiled out: this build of anim-core lacks the feature it needs.
    #[error("{solver} is not available: anim-core was built without its `{feature}` feature")]
    Unavailable {
        /// Name of the solver.
        solver: &'static str,
        /// The feature that provides it.
        feature: &'static str,
    },
    /// A factorisation failed (faer's error, as text).
    #[error("factorisation failed: {0}")]
    Factorization(String),
    /// A dense block is singular to working precision: its reciprocal condition number
    /// `1 / (||X||_1 ||X^-1||_1)` is at most `k * eps` for a `k x k` block (see [`schur`]).
    #[error("{block} is singular to working precision (reciprocal condition number {rcond:e})")]
    Singular {
        /// Which block ("A", "D", "Schur complement").
        block: &'static str,
        /// Its reciprocal condition number in the 1-norm (0 when the inverse is not finite).
        rcond: f64,
    },
}

/// A linear solver an implicit integrator can be handed.
///
/// Implementations keep their scratch vectors between calls: after the first solve of a given
/// size, `solve` does not allocate (direct solvers re-factor into their existing storage where
/// faer allows).
pub trait LinearSolver: Send {
    /// Short name for reports ("cg", "jacobi-pcg", "jacobi-pcg-assembled", "jacobi",
    /// "gauss-seidel", "cholesky").
    fn name(&self) -> &'static str;
    /// Whether this solver needs [`SystemMatrix::Csr`].
    fn needs_matrix(&self) -> bool;
    /// Solves `A x = b`; `x` holds the initial guess on entry and the solution on return.
    ///
    /// # Errors
    /// [`SolveError`] when the solve fails; `x` then holds the last iterate.
    fn solve(&mut self, a: SystemMatrix<'_>, b: &[f64], x: &mut [f64]) -> Result<SolveInfo, SolveError>;
}

/// The linear solvers by name, for scene files and sweeps.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "kebab-case"))]
pub enum LinearSolverKind {
    /// Conjugate gradients, matrix-free.
    Cg,
    /// Jacobi-preconditioned conjugate gradients, matrix-free (needs the operator diagonal).
    JacobiPcg,
    /// Jacobi-preconditioned conjugate gradients on the assembled matrix.
    JacobiPcgAssembled,
    /// Jacobi sweeps on the assembled matrix.
    Jacobi,
    /// Gauss-Seidel sweeps on the assembled matrix.
    GaussSeidel,
    /// Sparse Cholesky (faer) on the assembled matrix; needs the `faer` feature.
    Cholesky,
}

impl LinearSolverKind {
    /// Every kind, in a fixed order.
    pub const ALL: [LinearSolverKind; 6] = [
        LinearSolverKind::Cg,
        LinearSolverKind::JacobiPcg,
        LinearSolverKind::JacobiPcgAssembled,
        LinearSolverKind::Jacobi,
        LinearSolverKind::GaussSeidel,
        LinearSolverKind::Cholesky,
    ];

    /// The name used in scene files and reports (kebab case, as serialised).
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            LinearSolverKind::Cg => "cg",
            LinearSolverKind::JacobiPcg => "jacobi-pcg",
            LinearSolverKind::JacobiPcgAssembled => "jacobi-pcg-assembled",
            LinearSolverKind::Jacobi => "jacobi",
            LinearSolverKind::GaussSeidel => "gauss-seidel",
            LinearSolverKind::Cholesky => "cholesky",
        }
    }

    /// Builds the solver with the given stopping rule (ignored by the direct solver).
    #[must_use]
    pub fn build(self, params: IterativeParams) -> Box<dyn LinearSolver> {
        match self {
            LinearSolverKind::Cg => Box::new(Cg::new(Preconditioner::Identity, params)),
            LinearSolverKind::JacobiPcg => Box::new(Cg::new(Preconditioner::Jacobi, params)),
            LinearSolverKind::JacobiPcgAssembled => {
                Box::new(Cg::new(Preconditioner::Jacobi, params).assembled())
            }
            LinearSolverKind::Jacobi => Box::new(Jacobi::new(params)),
            LinearSolverKind::GaussSeidel => Box::new(GaussSeidel::new(params)),
            #[cfg(feature = "faer")]
            LinearSolverKind::Cholesky => Box::new(SparseCholesky::new()),
            #[cfg(not(feature = "faer"))]
            LinearSolverKind::Cholesky => Box::new(Unavailable { solver: "cholesky", feature: "faer" }),
        }
    }

    /// Whether this build of anim-core can solve with this kind (`cholesky` needs the `faer`
    /// feature).
    #[must_use]
    pub fn is_available(self) -> bool {
        cfg!(feature = "faer") || self != LinearSolverKind::Cholesky
    }
}

/// A solver compiled out of this build: every solve is [`SolveError::Unavailable`].
#[cfg(not(feature = "faer"))]
struct Unavailable {
    solver: &'static str,
    feature: &'static str,
}

#[cfg(not(feature = "faer"))]
impl LinearSolver for Unavailable {
    fn name(&self) -> &'static str {
        self.solver
    }
    fn needs_matrix(&self) -> bool {
        true
    }
    fn solve(&mut self, _a: SystemMatrix<'_>, _b: &[f64], _x: &mut [f64]) -> Result<SolveInfo, SolveError> {
        Err(SolveError::Unavailable { solver: self.solver, feature: self.feature })
    }
}

/// Euclidean dot product, summed in a fixed order (results do not depend on the thread count).
#[inline]
#[must_use]
pub fn dot(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len(), "dot: length mismatch");
    // Four independent accumulators: vectorises, and the order is fixed.
    let mut acc = [0.0f64; 4];
    let chunks = a.len() / 4;
    for i in 0..chunks {
        for k in 0..4 {
            acc[k] += a[4 * i + k] * b[4 * i + k];
        }
    }
    let mut s = (acc[0] + acc[1]) + (acc[2] + acc[3]);
    for i in 4 * chunks..a.len() {
        s += a[i] * b[i];
    }
    s
}

/// Euclidean norm.
#[inline]
#[must_use]
pub fn norm(a: &[f64]) -> f64 {
    dot(a, a).sqrt()
}

/// `y += alpha * x`.
#[inline]
pub fn axpy(alpha: f64, x: &[f64], y: &mut [f64]) {
    assert_eq!(x.len(), y.len(), "axpy: length mismatch");
    for (yi, xi) in y.iter_mut().zip(x) {
        *yi += alpha * xi;
    }
}

#[cfg(test)]
mod kind_tests {
    use super::*;

    #[test]
    fn kind_names_match_serde_and_the_built_solvers() {
        for kind in LinearSolverKind::ALL {
            #[cfg(feature = "serde")]
            assert_eq!(serde_json::to_string(&kind).unwrap(), format!("\"{}\"", kind.name()));
            let solver = kind.build(IterativeParams::default());
            assert_eq!(solver.name(), kind.name());
            let assembled = matches!(
                kind,
                LinearSolverKind::JacobiPcgAssembled
                    | LinearSolverKind::Jacobi
                    | LinearSolverKind::GaussSeidel
                    | LinearSolverKind::Cholesky
            );
            assert_eq!(solver.needs_matrix(), assembled, "{kind:?}");
        }
    }
}
