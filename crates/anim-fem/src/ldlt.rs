//! Sparse `L D L^T` factorisation (faer), the direct solver for symmetric matrices that need not
//! be positive definite (Newton without the positive semi-definite projection).
//!
//! It is anim-core's [`SparseLdlt`], re-exported here: the same
//! cached symbolic factorisation as anim-core's sparse Cholesky, computed once per sparsity pattern
//! and reused; each solve redoes only the numeric phase, sequentially (`Par::Seq`), so results do
//! not depend on the thread count. No pivoting is done, so a zero pivot fails; a non-finite
//! solution is reported as [`SolveError::NonFinite`](anim_core::linalg::SolveError::NonFinite).

pub use anim_core::linalg::SparseLdlt;
