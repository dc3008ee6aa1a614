//! Block elimination by Schur complements.
//!
//! # Method
//!
//! For the block system
//!
//! ```text
//! M [x; y] = [a; b],    M = [[A, B], [C, D]],   A: n x n, B: n x m, C: m x n, D: m x m
//! ```
//!
//! one block is eliminated and the smaller system in the other unknown is solved:
//!
//! - eliminating `D` (needs `D` invertible): the Schur complement of `D` is `A - B D^-1 C` and
//!   `(A - B D^-1 C) x = a - B D^-1 b`, then `y = D^-1 (b - C x)`;
//! - eliminating `A` (needs `A` invertible): the Schur complement of `A` is `D - C A^-1 B` and
//!   `(D - C A^-1 B) y = b - C A^-1 a`, then `x = A^-1 (a - B y)`.
//!
//! These are the identities `M L = [[A - B D^-1 C, B D^-1], [0, I]]` with
//! `L = [[I, 0], [-D^-1 C, D^-1]]`, and `T M = [[I, A^-1 B], [0, D - C A^-1 B]]` with
//! `T = [[A^-1, 0], [-C A^-1, I]]` (Zhang (ed.), *The Schur Complement and Its
//! Applications*, Springer 2005, chapter 1). `M` is invertible iff the eliminated block and its
//! Schur complement both are.
//!
//! The dense functions ([`schur_complement`], [`solve_block`]) factor the eliminated block and the
//! complement with faer's LU with partial pivoting, sequentially. [`solve_block_diagonal_a`] is the
//! common case of a diagonal `A` (a lumped mass matrix, as in XPBD's
//! `[[M, -J^T], [J, alpha~]] [dx; dlambda] = [..]`): `A^-1` is a division per row and
//! `D - C A^-1 B` is assembled directly from the sparse `B` and `C`.
//!
//! # Singularity
//!
//! A `k x k` matrix `X` is declared singular to working precision when its reciprocal condition
//! number in the 1-norm, `rcond = 1 / (||X||_1 ||X^-1||_1)`, is at most `k * eps` (or `X^-1` is
//! not finite); the result is [`SolveError::Singular`] naming the block. `X^-1` is formed from the
//! LU factors for this test (`2 k^3` extra flops, the same order as the factorisation); a test on
//! the pivots alone is not reliable (an exactly singular matrix can yield LU pivots far above
//! `k * eps * ||X||` from rounding). For a diagonal `A`, `rcond = min |a_i| / max |a_i|` exactly.
//! Non-finite input is [`SolveError::NonFinite`]. Shape mismatches panic.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::lu::partial_pivoting::{factor, solve};
use faer::perm::PermRef;
use faer::{Conj, Mat, MatMut, MatRef, Par};

use super::{CsrMatrix, SolveError};

/// Which diagonal block [`schur_complement`] / [`solve_block`] eliminates.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Eliminate {
    /// Eliminate `A`: the complement is `D - C A^-1 B` (solve for `y` first).
    A,
    /// Eliminate `D`: the complement is `A - B D^-1 C` (solve for `x` first).
    D,
}

/// A dense LU factorisation with partial pivoting, `P X = L U`, checked for singularity.
struct DenseLu {
    lu: Mat<f64>,
    fwd: Vec<usize>,
    inv: Vec<usize>,
}

/// `max_j sum_i |x_ij|`, or NaN if an entry is not finite.
fn norm_1(x: MatRef<'_, f64>) -> f64 {
    let mut best = 0.0f64;
    for j in 0..x.ncols() {
        let mut s = 0.0;
        for i in 0..x.nrows() {
            s += x[(i, j)].abs();
        }
        if !s.is_finite() {
            return f64::NAN;
        }
        best = best.max(s);
    }
    best
}

impl DenseLu {
    /// Factors `x`, or reports it singular (`block` names it in the error).
    fn new(x: MatRef<'_, f64>, block: &'static str) -> Result<Self, SolveError> {
        let n = x.nrows();
        let x_norm = norm_1(x);
        if !x_norm.is_finite() {
            return Err(SolveError::NonFinite { iteration: 0 });
        }
        let mut lu = x.to_owned();
        let mut fwd = vec![0usize; n];
        let mut inv = vec![0usize; n];
        let mut mem =
            MemBuffer::new(factor::lu_in_place_scratch::<usize, f64>(n, n, Par::Seq, Default::default()));
        let _ = factor::lu_in_place(
            lu.as_mut(),
            &mut fwd,
            &mut inv,
            Par::Seq,
            MemStack::new(&mut mem),
            Default::default(),
        );
        let this = Self { lu, fwd, inv };
        // Reciprocal condition number from the explicit inverse.
        let mut x_inv = Mat::<f64>::identity(n, n);
        this.solve_in_place(x_inv.as_mut());
        let inv_norm = norm_1(x_inv.as_ref());
        let rcond = if inv_norm.is_finite() && inv_norm > 0.0 { 1.0 / (x_norm * inv_norm) } else { 0.0 };
        if !(rcond > n as f64 * f64::EPSILON) {
            return Err(SolveError::Singular { block, rcond });
        }
        Ok(this)
    }

    /// Overwrites `rhs` (n x k) with `X^-1 rhs`.
    fn solve_in_place(&self, rhs: MatMut<'_, f64>) {
        let n = self.lu.nrows();
        let perm = PermRef::new_checked(&self.fwd, &self.inv, n);
        let mut mem = MemBuffer::new(solve::solve_in_place_scratch::<usize, f64>(n, rhs.ncols(), Par::Seq));
        // L and U share the factored matrix: the solves read only their own triangle.
        solve::solve_in_place_with_conj(
            self.lu.as_ref(),
            self.lu.as_ref(),
            perm,
            Conj::No,
            rhs,
            Par::Seq,
            MemStack::new(&mut mem),
        );
    }

    /// `X^-1 v` for a vector.
    fn solve_vec(&self, v: &[f64]) -> Vec<f64> {
        let mut out = v.to_vec();
        let n = out.len();
        self.solve_in_place(MatMut::from_column_major_slice_mut(&mut out, n, 1));
        out
    }
}

/// Checks block shapes; returns `(n, m)`.
#[track_caller]
fn check_blocks(
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    c: MatRef<'_, f64>,
    d: MatRef<'_, f64>,
) -> (usize, usize) {
    let n = a.nrows();
    let m = d.nrows();
    assert_eq!(a.ncols(), n, "schur: A must be square, got {} x {}", a.nrows(), a.ncols());
    assert_eq!(d.ncols(), m, "schur: D must be square, got {} x {}", d.nrows(), d.ncols());
    assert!(
        b.nrows() == n && b.ncols() == m,
        "schur: B must be {n} x {m}, got {} x {}",
        b.nrows(),
        b.ncols()
    );
    assert!(
        c.nrows() == m && c.ncols() == n,
        "schur: C must be {m} x {n}, got {} x {}",
        c.nrows(),
        c.ncols()
    );
    (n, m)
}

/// `y = X v` for a dense matrix.
fn mat_vec(x: MatRef<'_, f64>, v: &[f64]) -> Vec<f64> {
    (0..x.nrows()).map(|i| (0..x.ncols()).map(|j| x[(i, j)] * v[j]).sum()).collect()
}

/// The factored eliminated block and the complement.
fn complement(
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    c: MatRef<'_, f64>,
    d: MatRef<'_, f64>,
    which: Eliminate,
) -> Result<(DenseLu, Mat<f64>), SolveError> {
    let (pivot_block, name, left, right, other) = match which {
        // D - C A^-1 B
        Eliminate::A => (a, "A", c, b, d),
        // A - B D^-1 C
        Eliminate::D => (d, "D", b, c, a),
    };
    let lu = DenseLu::new(pivot_block, name)?;
    // inv_right = X^-1 right
    let mut inv_right = right.to_owned();
    lu.solve_in_place(inv_right.as_mut());
    let prod = left * &inv_right;
    let s = other - &prod;
    for j in 0..s.ncols() {
        for i in 0..s.nrows() {
            if !s[(i, j)].is_finite() {
                return Err(SolveError::NonFinite { iteration: 0 });
            }
        }
    }
    Ok((lu, s))
}

/// The Schur complement of the eliminated block of `M = [[A, B], [C, D]]`: `D - C A^-1 B` for
/// [`Eliminate::A`], `A - B D^-1 C` for [`Eliminate::D`].
///
/// # Errors
/// [`SolveError::Singular`] when the eliminated block is singular to working precision,
/// [`SolveError::NonFinite`] on NaN or infinite input.
///
/// # Panics
/// If the block shapes are inconsistent (`A: n x n`, `B: n x m`, `C: m x n`, `D: m x m`).
#[track_caller]
pub fn schur_complement(
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    c: MatRef<'_, f64>,
    d: MatRef<'_, f64>,
    which: Eliminate,
) -> Result<Mat<f64>, SolveError> {
    check_blocks(a, b, c, d);
    complement(a, b, c, d, which).map(|(_, s)| s)
}

/// Solves `[[A, B], [C, D]] [x; y] = [rhs_a; rhs_b]` by eliminating the chosen block; returns
/// `(x, y)`.
///
/// # Errors
/// [`SolveError::Singular`] when the eliminated block or its Schur complement is singular to
/// working precision, [`SolveError::NonFinite`] on NaN or infinite input.
///
/// # Panics
/// If the block shapes are inconsistent or `rhs_a.len() != n`, `rhs_b.len() != m`.
#[track_caller]
pub fn solve_block(
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    c: MatRef<'_, f64>,
    d: MatRef<'_, f64>,
    rhs_a: &[f64],
    rhs_b: &[f64],
    which: Eliminate,
) -> Result<(Vec<f64>, Vec<f64>), SolveError> {
    let (n, m) = check_blocks(a, b, c, d);
    assert_eq!(rhs_a.len(), n, "solve_block: rhs_a.len() != n");
    assert_eq!(rhs_b.len(), m, "solve_block: rhs_b.len() != m");
    if rhs_a.iter().chain(rhs_b).any(|v| !v.is_finite()) {
        return Err(SolveError::NonFinite { iteration: 0 });
    }
    let (lu, s) = complement(a, b, c, d, which)?;
    let s_lu = DenseLu::new(s.as_ref(), "Schur complement")?;
    match which {
        Eliminate::A => {
            // (D - C A^-1 B) y = b - C A^-1 a;  x = A^-1 (a - B y)
            let inv_a_rhs = lu.solve_vec(rhs_a);
            let c_part = mat_vec(c, &inv_a_rhs);
            let reduced: Vec<f64> = rhs_b.iter().zip(&c_part).map(|(bi, ci)| bi - ci).collect();
            let y = s_lu.solve_vec(&reduced);
            let by = mat_vec(b, &y);
            let top: Vec<f64> = rhs_a.iter().zip(&by).map(|(ai, bi)| ai - bi).collect();
            Ok((lu.solve_vec(&top), y))
        }
        Eliminate::D => {
            // (A - B D^-1 C) x = a - B D^-1 b;  y = D^-1 (b - C x)
            let inv_d_rhs = lu.solve_vec(rhs_b);
            let b_part = mat_vec(b, &inv_d_rhs);
            let reduced: Vec<f64> = rhs_a.iter().zip(&b_part).map(|(ai, bi)| ai - bi).collect();
            let x = s_lu.solve_vec(&reduced);
            let cx = mat_vec(c, &x);
            let bottom: Vec<f64> = rhs_b.iter().zip(&cx).map(|(bi, ci)| bi - ci).collect();
            Ok((x, lu.solve_vec(&bottom)))
        }
    }
}

/// Solves `[[diag(a_diag), B], [C, D]] [x; y] = [rhs_a; rhs_b]` by eliminating the diagonal
/// block: forms `S = D - C diag(a_diag)^-1 B` densely from the sparse `B` and `C`, solves
/// `S y = rhs_b - C diag(a_diag)^-1 rhs_a`, then `x = diag(a_diag)^-1 (rhs_a - B y)`. Returns
/// `(x, y)`.
///
/// # Errors
/// [`SolveError::Singular`] when `min |a_i| / max |a_i| <= n * eps` (block "A"), or when `S` is singular to working precision (block "Schur complement");
/// [`SolveError::NonFinite`] on NaN or infinite input.
///
/// # Panics
/// If `B` is not `n x m`, `C` not `m x n`, `D` not `m x m` (`n = a_diag.len()`), or the
/// right-hand sides have the wrong lengths.
#[track_caller]
pub fn solve_block_diagonal_a(
    a_diag: &[f64],
    b: &CsrMatrix,
    c: &CsrMatrix,
    d: MatRef<'_, f64>,
    rhs_a: &[f64],
    rhs_b: &[f64],
) -> Result<(Vec<f64>, Vec<f64>), SolveError> {
    let n = a_diag.len();
    let m = d.nrows();
    assert_eq!(d.ncols(), m, "solve_block_diagonal_a: D must be square, got {} x {}", d.nrows(), d.ncols());
    assert!(
        b.nrows() == n && b.ncols() == m,
        "solve_block_diagonal_a: B must be {n} x {m}, got {} x {}",
        b.nrows(),
        b.ncols()
    );
    assert!(
        c.nrows() == m && c.ncols() == n,
        "solve_block_diagonal_a: C must be {m} x {n}, got {} x {}",
        c.nrows(),
        c.ncols()
    );
    assert_eq!(rhs_a.len(), n, "solve_block_diagonal_a: rhs_a.len() != n");
    assert_eq!(rhs_b.len(), m, "solve_block_diagonal_a: rhs_b.len() != m");
    let all_finite =
        a_diag.iter().chain(rhs_a).chain(rhs_b).chain(b.values()).chain(c.values()).all(|v| v.is_finite());
    if !all_finite {
        return Err(SolveError::NonFinite { iteration: 0 });
    }
    let max_abs = a_diag.iter().fold(0.0f64, |acc, v| acc.max(v.abs()));
    let min_abs = a_diag.iter().fold(f64::INFINITY, |acc, v| acc.min(v.abs()));
    if n > 0 {
        let rcond = if max_abs > 0.0 { min_abs / max_abs } else { 0.0 };
        if !(rcond > n as f64 * f64::EPSILON) {
            return Err(SolveError::Singular { block: "A", rcond });
        }
    }
    // S = D - C A^-1 B: row r of C times rows of B scaled by 1 / a_k.
    let mut s = d.to_owned();
    for r in 0..m {
        let (c_cols, c_vals) = c.row(r);
        for (&k, &c_rk) in c_cols.iter().zip(c_vals) {
            let w = c_rk / a_diag[k];
            let (b_cols, b_vals) = b.row(k);
            for (&j, &b_kj) in b_cols.iter().zip(b_vals) {
                s[(r, j)] -= w * b_kj;
            }
        }
    }
    let s_lu = DenseLu::new(s.as_ref(), "Schur complement")?;
    // y = S^-1 (rhs_b - C A^-1 rhs_a)
    let inv_a_rhs: Vec<f64> = rhs_a.iter().zip(a_diag).map(|(r, a)| r / a).collect();
    let mut reduced = vec![0.0; m];
    c.mul_vec(&inv_a_rhs, &mut reduced);
    for (v, bi) in reduced.iter_mut().zip(rhs_b) {
        *v = bi - *v;
    }
    let y = s_lu.solve_vec(&reduced);
    // x = A^-1 (rhs_a - B y)
    let mut by = vec![0.0; n];
    b.mul_vec(&y, &mut by);
    let x: Vec<f64> = rhs_a.iter().zip(&by).zip(a_diag).map(|((r, by), a)| (r - by) / a).collect();
    Ok((x, y))
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::prelude::Solve;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn random_mat(rng: &mut ChaCha8Rng, r: usize, c: usize) -> Mat<f64> {
        Mat::from_fn(r, c, |_, _| rng.random_range(-1.0..1.0))
    }

    /// Well conditioned: random plus a dominant diagonal.
    fn random_square(rng: &mut ChaCha8Rng, n: usize) -> Mat<f64> {
        let mut m = random_mat(rng, n, n);
        for i in 0..n {
            m[(i, i)] += if rng.random_bool(0.5) { 1.0 } else { -1.0 } * (n as f64 + 1.0);
        }
        m
    }

    /// Reference: faer's dense LU of the assembled `[[A, B], [C, D]]`.
    fn assembled_solve(
        a: &Mat<f64>,
        b: &Mat<f64>,
        c: &Mat<f64>,
        d: &Mat<f64>,
        ra: &[f64],
        rb: &[f64],
    ) -> (Vec<f64>, Vec<f64>) {
        let (n, m) = (a.nrows(), d.nrows());
        let full = Mat::<f64>::from_fn(n + m, n + m, |i, j| match (i < n, j < n) {
            (true, true) => a[(i, j)],
            (true, false) => b[(i, j - n)],
            (false, true) => c[(i - n, j)],
            (false, false) => d[(i - n, j - n)],
        });
        let rhs = Mat::<f64>::from_fn(n + m, 1, |i, _| if i < n { ra[i] } else { rb[i - n] });
        let sol = full.partial_piv_lu().solve(&rhs);
        ((0..n).map(|i| sol[(i, 0)]).collect(), (n..n + m).map(|i| sol[(i, 0)]).collect())
    }

    fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
        a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max)
    }

    fn dense_from_csr(m: &CsrMatrix) -> Mat<f64> {
        let d = m.to_dense();
        Mat::from_fn(m.nrows(), m.ncols(), |i, j| d[i][j])
    }

    #[test]
    fn both_eliminations_match_assembled_lu() {
        let mut rng = ChaCha8Rng::seed_from_u64(40);
        for &(n, m) in &[(1, 1), (3, 2), (2, 5), (8, 8), (12, 4)] {
            for _ in 0..5 {
                let a = random_square(&mut rng, n);
                let d = random_square(&mut rng, m);
                let b = random_mat(&mut rng, n, m);
                let c = random_mat(&mut rng, m, n);
                let ra: Vec<f64> = (0..n).map(|_| rng.random_range(-1.0..1.0)).collect();
                let rb: Vec<f64> = (0..m).map(|_| rng.random_range(-1.0..1.0)).collect();
                let (xr, yr) = assembled_solve(&a, &b, &c, &d, &ra, &rb);
                let mut results = Vec::new();
                for which in [Eliminate::A, Eliminate::D] {
                    let (x, y) = solve_block(a.as_ref(), b.as_ref(), c.as_ref(), d.as_ref(), &ra, &rb, which)
                        .expect("well conditioned");
                    assert!(max_abs_diff(&x, &xr) <= 1e-12, "{which:?} ({n}, {m}) x");
                    assert!(max_abs_diff(&y, &yr) <= 1e-12, "{which:?} ({n}, {m}) y");
                    results.push((x, y));
                }
                assert!(max_abs_diff(&results[0].0, &results[1].0) <= 1e-12);
                assert!(max_abs_diff(&results[0].1, &results[1].1) <= 1e-12);
            }
        }
    }

    /// The complements against the definitions written with explicit dense inverses.
    #[test]
    fn schur_complement_matches_definition() {
        let mut rng = ChaCha8Rng::seed_from_u64(41);
        let (n, m) = (4, 3);
        let a = random_square(&mut rng, n);
        let d = random_square(&mut rng, m);
        let b = random_mat(&mut rng, n, m);
        let c = random_mat(&mut rng, m, n);
        let inv = |x: &Mat<f64>| x.partial_piv_lu().solve(Mat::<f64>::identity(x.nrows(), x.nrows()));
        let sa_ref = &d - &c * inv(&a) * &b;
        let sd_ref = &a - &b * inv(&d) * &c;
        let sa = schur_complement(a.as_ref(), b.as_ref(), c.as_ref(), d.as_ref(), Eliminate::A)
            .expect("A invertible");
        let sd = schur_complement(a.as_ref(), b.as_ref(), c.as_ref(), d.as_ref(), Eliminate::D)
            .expect("D invertible");
        assert_eq!((sa.nrows(), sa.ncols(), sd.nrows(), sd.ncols()), (m, m, n, n));
        for i in 0..m {
            for j in 0..m {
                assert!((sa[(i, j)] - sa_ref[(i, j)]).abs() <= 1e-13);
            }
        }
        for i in 0..n {
            for j in 0..n {
                assert!((sd[(i, j)] - sd_ref[(i, j)]).abs() <= 1e-13);
            }
        }
    }

    #[test]
    fn singular_blocks_are_errors() {
        let mut rng = ChaCha8Rng::seed_from_u64(42);
        let (n, m) = (4, 3);
        let a = random_square(&mut rng, n);
        let b = random_mat(&mut rng, n, m);
        let c = random_mat(&mut rng, m, n);
        // Exactly rank-deficient D: third row = first + second.
        let mut d = random_square(&mut rng, m);
        for j in 0..m {
            d[(2, j)] = d[(0, j)] + d[(1, j)];
        }
        let err = schur_complement(a.as_ref(), b.as_ref(), c.as_ref(), d.as_ref(), Eliminate::D).unwrap_err();
        assert!(matches!(err, SolveError::Singular { block: "D", .. }), "{err:?}");
        // Many random rank-deficient D = X Y^T (rank m - 1) must all be caught.
        for _ in 0..200 {
            let x = random_mat(&mut rng, m, m - 1);
            let y = random_mat(&mut rng, m, m - 1);
            let d = &x * y.transpose();
            let err = solve_block(
                a.as_ref(),
                b.as_ref(),
                c.as_ref(),
                d.as_ref(),
                &[1.0; 4],
                &[1.0; 3],
                Eliminate::D,
            )
            .unwrap_err();
            assert!(matches!(err, SolveError::Singular { block: "D", .. }), "{err:?}");
        }
        // Exactly singular blocks of several sizes: dyadic entries, so that the dependent row
        // s * row_p + t * row_q is computed without rounding.
        for k in [2usize, 3, 5, 10, 30] {
            for _ in 0..50 {
                let mut x =
                    Mat::<f64>::from_fn(k, k, |_, _| rng.random_range(-1024i32..=1024) as f64 / 1024.0);
                let (p, q) = (0, 1);
                let r = k - 1; // row 1 itself when k = 2
                let (sp, sq) =
                    (rng.random_range(-4i32..=4) as f64 / 4.0, rng.random_range(-4i32..=4) as f64 / 4.0);
                for j in 0..k {
                    x[(r, j)] = if r == q { sp * x[(p, j)] } else { sp * x[(p, j)] + sq * x[(q, j)] };
                }
                let bk = random_mat(&mut rng, 2, k);
                let ck = random_mat(&mut rng, k, 2);
                let a2 = random_square(&mut rng, 2);
                let err = schur_complement(a2.as_ref(), bk.as_ref(), ck.as_ref(), x.as_ref(), Eliminate::D)
                    .unwrap_err();
                assert!(matches!(err, SolveError::Singular { block: "D", .. }), "k = {k}: {err:?}");
            }
        }
        // An ill-conditioned but invertible block (cond = 1e9) is accepted and solved to the
        // accuracy its condition allows (relative error ~ cond * eps).
        let mut ill = Mat::<f64>::identity(m, m);
        ill[(1, 1)] = 1e-9;
        let rb = [1.0, 1e-9, -1.0];
        let (x_ill, y_ill) =
            solve_block(a.as_ref(), b.as_ref(), c.as_ref(), ill.as_ref(), &[1.0; 4], &rb, Eliminate::D)
                .expect("ill-conditioned but invertible");
        let (xr, yr) = assembled_solve(&a, &b, &c, &ill, &[1.0; 4], &rb);
        let scale = xr.iter().chain(&yr).fold(0.0f64, |s, v| s.max(v.abs()));
        assert!(max_abs_diff(&x_ill, &xr).max(max_abs_diff(&y_ill, &yr)) <= 1e9 * 1e-15 * scale);
        // A zero block.
        let z = Mat::<f64>::zeros(n, n);
        let err =
            solve_block(z.as_ref(), b.as_ref(), c.as_ref(), d.as_ref(), &[1.0; 4], &[1.0; 3], Eliminate::A)
                .unwrap_err();
        assert_eq!(err, SolveError::Singular { block: "A", rcond: 0.0 });
        // Invertible blocks but singular M: the complement is reported. With A = I, B = I, C = I,
        // D = I the complement D - C A^-1 B is 0.
        let i3 = Mat::<f64>::identity(3, 3);
        let err = solve_block(
            i3.as_ref(),
            i3.as_ref(),
            i3.as_ref(),
            i3.as_ref(),
            &[1.0; 3],
            &[1.0; 3],
            Eliminate::A,
        )
        .unwrap_err();
        assert!(matches!(err, SolveError::Singular { block: "Schur complement", .. }), "{err:?}");
        // NaN input.
        let mut nan = a.clone();
        nan[(1, 1)] = f64::NAN;
        let err =
            solve_block(nan.as_ref(), b.as_ref(), c.as_ref(), d.as_ref(), &[1.0; 4], &[1.0; 3], Eliminate::A)
                .unwrap_err();
        assert_eq!(err, SolveError::NonFinite { iteration: 0 });
    }

    #[test]
    #[should_panic(expected = "B must be 2 x 3")]
    fn shape_mismatch_panics() {
        let a = Mat::<f64>::identity(2, 2);
        let b = Mat::<f64>::zeros(3, 3);
        let c = Mat::<f64>::zeros(3, 2);
        let d = Mat::<f64>::identity(3, 3);
        let _ = schur_complement(a.as_ref(), b.as_ref(), c.as_ref(), d.as_ref(), Eliminate::A);
    }

    /// XPBD-shaped system [[M, -J^T], [J, alpha]] with a lumped mass: against the assembled LU
    /// and against the dense elimination.
    #[test]
    fn diagonal_a_matches_assembled_lu() {
        let mut rng = ChaCha8Rng::seed_from_u64(43);
        for &(n, m) in &[(6, 2), (30, 10), (9, 9)] {
            let masses: Vec<f64> = (0..n).map(|_| rng.random_range(0.1..10.0)).collect();
            let mut jt = Vec::new();
            for r in 0..m {
                for _ in 0..4 {
                    jt.push((r, rng.random_range(0..n), rng.random_range(-1.0..1.0)));
                }
            }
            let j = CsrMatrix::from_triplets(m, n, &jt);
            let minus_jt = {
                let t = j.transpose();
                let neg: Vec<(usize, usize, f64)> = (0..t.nrows())
                    .flat_map(|r| {
                        let (cols, vals) = t.row(r);
                        cols.iter().zip(vals).map(move |(&c, &v)| (r, c, -v)).collect::<Vec<_>>()
                    })
                    .collect();
                CsrMatrix::from_triplets(n, m, &neg)
            };
            let alpha =
                Mat::<f64>::from_fn(m, m, |i, k| if i == k { rng.random_range(1e-3..1e-1) } else { 0.0 });
            let ra: Vec<f64> = (0..n).map(|_| rng.random_range(-1.0..1.0)).collect();
            let rb: Vec<f64> = (0..m).map(|_| rng.random_range(-1.0..1.0)).collect();
            let (x, y) =
                solve_block_diagonal_a(&masses, &minus_jt, &j, alpha.as_ref(), &ra, &rb).expect("solvable");
            let a_dense = Mat::<f64>::from_fn(n, n, |i, k| if i == k { masses[i] } else { 0.0 });
            let (bd, cd) = (dense_from_csr(&minus_jt), dense_from_csr(&j));
            let (xr, yr) = assembled_solve(&a_dense, &bd, &cd, &alpha, &ra, &rb);
            let scale = xr.iter().chain(&yr).fold(1.0f64, |s, v| s.max(v.abs()));
            assert!(max_abs_diff(&x, &xr) <= 1e-11 * scale, "({n}, {m}) x");
            assert!(max_abs_diff(&y, &yr) <= 1e-11 * scale, "({n}, {m}) y");
            let (x2, y2) = solve_block(
                a_dense.as_ref(),
                bd.as_ref(),
                cd.as_ref(),
                alpha.as_ref(),
                &ra,
                &rb,
                Eliminate::A,
            )
            .expect("solvable");
            assert!(max_abs_diff(&x, &x2) <= 1e-11 * scale && max_abs_diff(&y, &y2) <= 1e-11 * scale);
        }
    }

    #[test]
    fn diagonal_a_singular_cases() {
        let b = CsrMatrix::from_triplets(3, 1, &[(0, 0, 1.0)]);
        let c = CsrMatrix::from_triplets(1, 3, &[(0, 0, 1.0)]);
        let d = Mat::<f64>::zeros(1, 1);
        let err =
            solve_block_diagonal_a(&[1.0, 0.0, 2.0], &b, &c, d.as_ref(), &[1.0; 3], &[1.0]).unwrap_err();
        assert_eq!(err, SolveError::Singular { block: "A", rcond: 0.0 });
        // S = 0 - 1 * 1 / 1 + 1 = 0 with D = [1].
        let d1 = Mat::<f64>::from_fn(1, 1, |_, _| 1.0);
        let err =
            solve_block_diagonal_a(&[1.0, 1.0, 1.0], &b, &c, d1.as_ref(), &[1.0; 3], &[1.0]).unwrap_err();
        assert!(matches!(err, SolveError::Singular { block: "Schur complement", .. }), "{err:?}");
    }
}
