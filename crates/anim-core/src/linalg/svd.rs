//! 3x3 singular value decomposition with proper rotations, and the polar decomposition.
//!
//! # What is returned
//!
//! For any real 3x3 `A`, [`svd3`] returns `A = U diag(sigma) V^T` with
//!
//! - `U`, `V` **proper rotations** (orthogonal, `det = +1`);
//! - `sigma_0 >= sigma_1 >= |sigma_2|`, only `sigma_2` possibly negative: when `det A < 0` the
//!   reflection is moved onto the smallest singular value.
//!
//! This "rotation variant" of the SVD is what the corotated, fixed-corotated and snow
//! constitutive models need (Irving, Teran & Fedkiw, *Invertible finite elements for
//! robust simulation of large deformation*, SCA 2004, section 5; Stomakhin et al., *A material
//! point method for snow simulation*, SIGGRAPH 2013): an inverted element keeps a rotation `U V^T`
//! and shows its inversion as a negative `sigma_2`.
//!
//! [`polar`] returns `A = R S` with `R = U V^T` a rotation and `S = V diag(sigma) V^T` symmetric
//! (positive semi-definite when `det A >= 0`).
//!
//! # Method: one-sided Jacobi (Hestenes)
//!
//! Right-multiplying `A` by plane rotations `J_pq` makes its columns mutually orthogonal:
//! `W = A V` with `V = J_1 J_2 ...`; then `||w_i||` are the singular values and `w_i / ||w_i||`
//! the left singular vectors (Hestenes, *Inversion of matrices by biorthogonalization*, J. SIAM
//! 1958; Demmel & Veselic, *Jacobi's method is more accurate than QR*, SIMAX 1992). For the pair
//! of columns `(p, q)` with `alpha = |w_p|^2`, `beta = |w_q|^2`, `gamma = w_p . w_q`, the rotation
//!
//! ```text
//! zeta = (beta - alpha) / (2 gamma),  t = sign(zeta) / (|zeta| + sqrt(1 + zeta^2)),
//! c = 1 / sqrt(1 + t^2),  s = c t,    w_p <- c w_p - s w_q,  w_q <- s w_p + c w_q
//! ```
//!
//! zeroes `gamma`. Sweeps over the pairs (0,1), (0,2), (1,2) repeat until every pair is
//! orthogonal to working precision, `|gamma| <= 3 eps |w_p| |w_q|` (3 eps bounds the rounding of
//! a 3-term dot product), or has a negligible column, `min(|w_p|, |w_q|) <= eps ||A||_F` (a
//! rounding-noise column, e.g. of a rank-deficient `A`, cannot be orthogonalised further and
//! contributes at most `eps ||A||_F` to the reconstruction). The convergence test is thus
//! relative to the columns and to `||A||`; at most [`MAX_SWEEPS`] sweeps are made (convergence is
//! quadratic; 3-5 sweeps are typical).
//!
//! Then:
//!
//! 1. only when its largest entry lies outside `[2^-170, 2^240]` is the matrix scaled by a power
//!    of two to entries of order one (exact; it avoids overflow and underflow of the squared
//!    norms for any scale, e.g. `1e-300` or `1e300`), and `sigma` is scaled back at the end;
//!    inside that range no intermediate can overflow or lose precision to underflow, and the
//!    result is bitwise the one the scaled computation would give (every operation commutes
//!    with exact power-of-two scaling);
//! 2. columns are sorted by decreasing norm (the same permutation is applied to `V`);
//! 3. `U` is built by Gram-Schmidt: `u_0 = w_0 / |w_0|`, `u_1` = the normalised part of `w_1`
//!    orthogonal to `u_0` (any unit vector orthogonal to `u_0` when that part is below
//!    `eps ||A||_F`, which handles rank 1 and zero columns), `u_2 = u_0 x u_1`, so `det U = +1` by
//!    construction; `sigma_i = |w_i|`, with `sigma_2` taking the sign of `u_2 . w_2`;
//! 4. if `det V < 0`, `v_2` and `sigma_2` are negated, which leaves `U diag(sigma) V^T` unchanged.
//!
//! Steps 3-4 put any reflection of `A` on `sigma_2`. The zero matrix gives `U = V = I`,
//! `sigma = 0`. Non-finite input does not panic; the output is then non-finite.
//!
//! The kernel runs in `f64` on `[[f64; 3]; 3]` arrays. `f32` input ([`svd3_f32`], [`polar_f32`],
//! [`svd3_real`] with `T = f32`) is widened exactly, iterated only to `f32` precision (`eps =
//! f32::EPSILON` in the tests above) and rounded back: the whole `f32` range then needs no
//! scaling, and scalar `f64` arithmetic costs the same as `f32`. It is exposed for
//! `glam::DMat3` ([`svd3`], [`polar`]), `glam::Mat3` ([`svd3_f32`], [`polar_f32`]) and any
//! [`Real`] ([`svd3_real`]).

use glam::{DMat3, DVec3, Mat3, Vec3};

use crate::scalar::Real;

/// Cap on one-sided Jacobi sweeps (each sweep visits the 3 column pairs).
pub const MAX_SWEEPS: usize = 12;

/// A column pair counts as orthogonal when `|w_p . w_q| <= ORTHO_FACTOR * eps * |w_p| |w_q|`:
/// 3 eps bounds the rounding error of a 3-term dot product (Higham, *Accuracy and Stability of
/// Numerical Algorithms*, 2nd ed., section 3.1), so a smaller cosine cannot be resolved.
const ORTHO_FACTOR: f64 = 3.0;

/// `2^e` for `-1022 <= e <= 1023`, built from its bits (exact).
const fn pow2(e: i32) -> f64 {
    f64::from_bits(((e + 1023) as u64) << 52)
}

/// Largest entry magnitude (`2^240`) handled without scaling. With `m` the largest entry, every
/// intermediate of the kernel is bounded by `572 m^4` (column norms squared `<= 9 m^2`, the
/// rotation's `2 r (r + |tau|)` below), which stays below `2^1023`.
const SAFE_MAX: f64 = pow2(240);

/// Smallest largest-entry magnitude (`2^-170`) handled without scaling: a pair is rotated only
/// when both columns exceed `eps ||A||_F >= eps m` and its cosine exceeds `3 eps`, so the squared
/// quantities of the rotation are at least `36 eps^6 m^4`, a normal `f64` for `m >= 2^-170` and
/// `eps = 2^-52` (and for `eps = 2^-23` when `f32` input is handled in `f64`).
const SAFE_MIN: f64 = pow2(-170);

/// A singular value decomposition `A = u * diag(sigma) * v^T` (see the [module docs](self)).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Svd3<M, V> {
    /// Left singular vectors (columns), a proper rotation.
    pub u: M,
    /// Singular values, `sigma.x >= sigma.y >= |sigma.z|`; only `sigma.z` may be negative.
    pub sigma: V,
    /// Right singular vectors (columns), a proper rotation.
    pub v: M,
}

/// A 3x3 matrix stored by columns: `m[j][i]` is row `i` of column `j` (glam's layout).
type Cols<T> = [[T; 3]; 3];

#[inline(always)]
fn dot3(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[inline(always)]
fn cross3(a: &[f64; 3], b: &[f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

#[inline(always)]
fn det3(m: &Cols<f64>) -> f64 {
    dot3(&m[0], &cross3(&m[1], &m[2]))
}

#[inline(always)]
fn scale3(a: &[f64; 3], s: f64) -> [f64; 3] {
    [a[0] * s, a[1] * s, a[2] * s]
}

/// Multiplies by `2^e` exactly (in two steps, so that `|e|` up to 2044 is covered and a
/// subnormal result is rounded once).
fn scale_pow2(x: f64, e: i32) -> f64 {
    let h1 = e / 2;
    x * pow2(h1) * pow2(e - h1)
}

/// A unit vector orthogonal to the unit vector `u`: `u` crossed with the coordinate axis least
/// aligned with it, normalised.
fn any_orthogonal(u: &[f64; 3]) -> [f64; 3] {
    let (ax, ay, az) = (u[0].abs(), u[1].abs(), u[2].abs());
    let axis = if ax <= ay && ax <= az {
        [1.0, 0.0, 0.0]
    } else if ay <= az {
        [0.0, 1.0, 0.0]
    } else {
        [0.0, 0.0, 1.0]
    };
    let c = cross3(u, &axis);
    scale3(&c, 1.0 / dot3(&c, &c).sqrt())
}

/// One-sided Jacobi on the columns of `w`, accumulating the rotations into `v`. Pairs are
/// skipped when already orthogonal to working precision (`|gamma| <= tol |w_p| |w_q|`) or when
/// one column is negligible (norm `<= negligible`, i.e. `eps ||A||_F`: a rounding-noise column
/// cannot be orthogonalised further, and its direction is not used). Returns the number of
/// sweeps that rotated.
///
/// The rotation is computed without `zeta` and `hypot`: with `tau = beta - alpha`,
/// `g = 2 gamma`, `r = sqrt(tau^2 + g^2)`, the unnormalised rotation `(|tau| + r, sign(tau) g)`
/// has squared norm `2 r (r + |tau|)`, so `c = (|tau| + r) / n`, `s = sign(tau) g / n` with
/// `n = sqrt(2 r (r + |tau|))` — the same `c`, `s = c t` as the textbook formula, in two square
/// roots and one division, free of cancellation. The caller keeps the entries within
/// [`SAFE_MIN`, `SAFE_MAX`] so that nothing overflows or underflows.
#[inline(always)]
fn hestenes(w: &mut Cols<f64>, v: &mut Cols<f64>, negligible: f64, tol: f64) -> usize {
    const PAIRS: [(usize, usize); 3] = [(0, 1), (0, 2), (1, 2)];
    let (tol2, negligible2) = (tol * tol, negligible * negligible);
    for sweep in 0..MAX_SWEEPS {
        let mut rotated = false;
        for &(p, q) in &PAIRS {
            let (wp, wq) = (w[p], w[q]);
            let alpha = dot3(&wp, &wp);
            let beta = dot3(&wq, &wq);
            let gamma = dot3(&wp, &wq);
            // The tests squared (no square roots; in range by [`SAFE_MIN`], [`SAFE_MAX`]).
            // Written so that NaN counts as converged: it cannot be improved.
            if !(gamma * gamma > tol2 * alpha * beta) || !(alpha.min(beta) > negligible2) {
                continue;
            }
            rotated = true;
            let tau = beta - alpha;
            let g = 2.0 * gamma;
            let r = (tau * tau + g * g).sqrt();
            let cp = tau.abs() + r;
            let inv_n = 1.0 / (2.0 * r * cp).sqrt();
            let c = cp * inv_n;
            let s = if tau >= 0.0 { g } else { -g } * inv_n;
            let (vp, vq) = (v[p], v[q]);
            for k in 0..3 {
                w[p][k] = c * wp[k] - s * wq[k];
                w[q][k] = s * wp[k] + c * wq[k];
                v[p][k] = c * vp[k] - s * vq[k];
                v[q][k] = s * vp[k] + c * vq[k];
            }
        }
        if !rotated {
            return sweep;
        }
    }
    MAX_SWEEPS
}

/// The SVD kernel in `f64` on column arrays, converging to the precision `eps` (`f64::EPSILON`,
/// or `f32::EPSILON` for `f32` input); also returns the number of Jacobi sweeps.
fn svd3_kernel(a: &Cols<f64>, eps: f64) -> (Cols<f64>, [f64; 3], Cols<f64>, usize) {
    let identity = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let mut max_abs = 0.0f64;
    let mut in_range = true;
    for x in a.iter().flatten() {
        let y = x.abs();
        max_abs = max_abs.max(y);
        in_range &= y <= SAFE_MAX; // false for NaN
    }
    // 1. Exact power-of-two scaling to entries of order one, only when the largest entry is
    //    outside [SAFE_MIN, SAFE_MAX] (skipped for non-finite input).
    let (mut w, exponent) = if in_range && max_abs >= SAFE_MIN {
        (*a, 0)
    } else {
        let finite = a.iter().flatten().all(|x| x.is_finite());
        if finite && max_abs == 0.0 {
            return (identity, [0.0; 3], identity, 0);
        }
        let exponent = if finite { max_abs.log2().floor() as i32 } else { 0 };
        (a.map(|col| col.map(|x| scale_pow2(x, -exponent))), exponent)
    };
    let mut v = identity;
    let negligible = eps * w.iter().flatten().map(|x| x * x).sum::<f64>().sqrt();
    let sweeps = hestenes(&mut w, &mut v, negligible, ORTHO_FACTOR * eps);

    // 2. Sort columns by decreasing norm (three compare-and-swaps; NaN never swaps).
    let mut norms = [dot3(&w[0], &w[0]).sqrt(), dot3(&w[1], &w[1]).sqrt(), dot3(&w[2], &w[2]).sqrt()];
    for &(p, q) in &[(0usize, 1usize), (1, 2), (0, 1)] {
        if norms[q] > norms[p] {
            norms.swap(p, q);
            w.swap(p, q);
            v.swap(p, q);
        }
    }

    // 3. U by Gram-Schmidt and a cross product: det U = +1.
    let u0 = scale3(&w[0], 1.0 / norms[0]);
    let proj = dot3(&u0, &w[1]);
    let perp = [w[1][0] - proj * u0[0], w[1][1] - proj * u0[1], w[1][2] - proj * u0[2]];
    let perp_norm = dot3(&perp, &perp).sqrt();
    let u1 = if perp_norm > negligible { scale3(&perp, 1.0 / perp_norm) } else { any_orthogonal(&u0) };
    let u2 = cross3(&u0, &u1);
    let mut sigma = norms;
    if dot3(&u2, &w[2]) < 0.0 {
        sigma[2] = -sigma[2];
    }
    // 4. det V = +1 by moving a reflection onto sigma_2.
    if det3(&v) < 0.0 {
        v[2] = scale3(&v[2], -1.0);
        sigma[2] = -sigma[2];
    }
    if exponent != 0 {
        sigma = sigma.map(|s| scale_pow2(s, exponent));
    }
    ([u0, u1, u2], sigma, v, sweeps)
}

/// The SVD kernel for either precision on column arrays: `f32` input is widened to `f64`
/// (exactly; its whole range then needs no scaling), decomposed to `f32` precision and rounded.
fn svd3_cols<T: Real>(a: &Cols<T>) -> (Cols<T>, [T; 3], Cols<T>, usize) {
    let a64 = a.map(|col| col.map(T::to_f64_lossless));
    let (u, sigma, v, sweeps) = svd3_kernel(&a64, T::EPS.to_f64_lossless());
    let mut sigma = sigma.map(T::of);
    if sigma[2] == T::zero() {
        sigma[2] = T::zero(); // no negative zero
    }
    (u.map(|col| col.map(T::of)), sigma, v.map(|col| col.map(T::of)), sweeps)
}

/// Polar decomposition from the SVD: `R = U V^T`, `S = V diag(sigma) V^T` (exactly symmetric).
fn polar_cols<T: Real>(a: &Cols<T>) -> (Cols<T>, Cols<T>) {
    let (u, sigma, v, _) = svd3_cols(a);
    let mut r = [[T::zero(); 3]; 3];
    let mut s = [[T::zero(); 3]; 3];
    for j in 0..3 {
        for i in 0..3 {
            // (U V^T)_ij = sum_k U_ik V_jk ; column j of the result, row i.
            r[j][i] = u[0][i] * v[0][j] + u[1][i] * v[1][j] + u[2][i] * v[2][j];
        }
    }
    for j in 0..3 {
        for i in 0..=j {
            let x =
                sigma[0] * v[0][i] * v[0][j] + sigma[1] * v[1][i] * v[1][j] + sigma[2] * v[2][i] * v[2][j];
            s[j][i] = x;
            s[i][j] = x;
        }
    }
    (r, s)
}

/// The SVD kernel for either precision on column arrays (`a[j][i]` is row `i` of column `j`):
/// returns `(u, sigma, v)` in the same layout, with the conventions of [`svd3`]. This is the
/// entry point for callers that do not use glam types (e.g. nalgebra matrices in `anim-material`).
#[must_use]
pub fn svd3_real<T: Real>(a: &[[T; 3]; 3]) -> ([[T; 3]; 3], [T; 3], [[T; 3]; 3]) {
    let (u, sigma, v, _) = svd3_cols(a);
    (u, sigma, v)
}

/// SVD of a `f64` matrix: `a = u * diag(sigma) * v^T` with rotations `u`, `v` and
/// `sigma.x >= sigma.y >= |sigma.z|` (see the [module docs](self)).
#[must_use]
pub fn svd3(a: DMat3) -> Svd3<DMat3, DVec3> {
    let (u, sigma, v, _) = svd3_cols(&a.to_cols_array_2d());
    Svd3 {
        u: DMat3::from_cols_array_2d(&u),
        sigma: DVec3::from_array(sigma),
        v: DMat3::from_cols_array_2d(&v),
    }
}

/// SVD of a `f32` matrix to `f32` precision (computed in `f64` arithmetic, see [`svd3`]).
#[must_use]
pub fn svd3_f32(a: Mat3) -> Svd3<Mat3, Vec3> {
    let (u, sigma, v, _) = svd3_cols(&a.to_cols_array_2d());
    Svd3 { u: Mat3::from_cols_array_2d(&u), sigma: Vec3::from_array(sigma), v: Mat3::from_cols_array_2d(&v) }
}

/// Polar decomposition `a = r * s` of a `f64` matrix: `r` a rotation, `s` symmetric.
#[must_use]
pub fn polar(a: DMat3) -> (DMat3, DMat3) {
    let (r, s) = polar_cols(&a.to_cols_array_2d());
    (DMat3::from_cols_array_2d(&r), DMat3::from_cols_array_2d(&s))
}

/// Polar decomposition `a = r * s` of a `f32` matrix to `f32` precision (see [`polar`]).
#[must_use]
pub fn polar_f32(a: Mat3) -> (Mat3, Mat3) {
    let (r, s) = polar_cols(&a.to_cols_array_2d());
    (Mat3::from_cols_array_2d(&r), Mat3::from_cols_array_2d(&s))
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::{Mat, Side};
    use glam::DQuat;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// Test matrices per category.
    const PER_CATEGORY: usize = 2000;

    #[derive(Debug, Clone, Copy, PartialEq)]
    enum Category {
        Random,
        Rank1,
        Rank2,
        Repeated,
        Reflected,
        NearIdentity,
        Zero,
        Tiny,
        Huge,
    }

    const CATEGORIES: [Category; 9] = [
        Category::Random,
        Category::Rank1,
        Category::Rank2,
        Category::Repeated,
        Category::Reflected,
        Category::NearIdentity,
        Category::Zero,
        Category::Tiny,
        Category::Huge,
    ];

    fn rand_vec(rng: &mut ChaCha8Rng) -> DVec3 {
        DVec3::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0))
    }

    fn rand_mat(rng: &mut ChaCha8Rng) -> DMat3 {
        DMat3::from_cols(rand_vec(rng), rand_vec(rng), rand_vec(rng))
    }

    /// Uniformly random rotation from a normalised Gaussian-ish quaternion.
    fn rand_rotation(rng: &mut ChaCha8Rng) -> DMat3 {
        loop {
            let q = DQuat::from_xyzw(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
            );
            let l = q.length();
            if l > 0.1 && l <= 1.0 {
                return DMat3::from_quat(q / l);
            }
        }
    }

    fn generate(cat: Category, rng: &mut ChaCha8Rng) -> DMat3 {
        match cat {
            Category::Random => rand_mat(rng),
            Category::Rank1 => {
                let (a, b) = (rand_vec(rng), rand_vec(rng));
                DMat3::from_cols(a * b.x, a * b.y, a * b.z)
            }
            Category::Rank2 => {
                let (a1, b1, a2, b2) = (rand_vec(rng), rand_vec(rng), rand_vec(rng), rand_vec(rng));
                DMat3::from_cols(a1 * b1.x + a2 * b2.x, a1 * b1.y + a2 * b2.y, a1 * b1.z + a2 * b2.z)
            }
            Category::Repeated => {
                let s: f64 = rng.random_range(0.1..3.0);
                let t: f64 = rng.random_range(0.1..3.0);
                let diag = match rng.random_range(0..5) {
                    0 => DVec3::new(s, s, s),
                    1 => DVec3::new(s, s, t),
                    2 => DVec3::new(s, t, t),
                    3 => DVec3::new(s, s, 0.0),
                    _ => DVec3::new(s, 0.0, 0.0),
                };
                match rng.random_range(0..4) {
                    // c * identity and c * rotation exactly.
                    0 => DMat3::from_diagonal(DVec3::splat(s)),
                    1 => rand_rotation(rng) * s,
                    _ => rand_rotation(rng) * DMat3::from_diagonal(diag) * rand_rotation(rng).transpose(),
                }
            }
            Category::Reflected => {
                let mut a = rand_mat(rng);
                if a.determinant() > 0.0 {
                    a.x_axis = -a.x_axis;
                }
                match rng.random_range(0..3) {
                    0 => a,
                    1 => rand_rotation(rng) * DMat3::from_diagonal(DVec3::new(1.0, 1.0, -1.0)),
                    _ => DMat3::from_diagonal(DVec3::new(
                        -rng.random_range(0.1..2.0),
                        -rng.random_range(0.1..2.0),
                        -rng.random_range(0.1..2.0),
                    )),
                }
            }
            Category::NearIdentity => {
                let scale = [1e-3, 1e-6, 1e-10, 0.0][rng.random_range(0..4)];
                DMat3::IDENTITY + rand_mat(rng) * scale
            }
            Category::Zero => {
                if rng.random_bool(0.5) {
                    DMat3::ZERO
                } else {
                    DMat3::from_cols_array(&[-0.0; 9])
                }
            }
            Category::Tiny => rand_mat(rng) * 1e-30,
            Category::Huge => rand_mat(rng) * 1e30,
        }
    }

    fn frob(m: DMat3) -> f64 {
        m.to_cols_array().iter().map(|x| x * x).sum::<f64>().sqrt()
    }

    /// Singular values of A (ascending) from faer's self-adjoint eigenvalues of A^T A.
    fn reference_singular_values(a: DMat3) -> [f64; 3] {
        let ata = a.transpose() * a;
        let m = Mat::<f64>::from_fn(3, 3, |i, j| ata.col(j)[i]);
        let ev = m.self_adjoint_eigenvalues(Side::Lower).expect("symmetric eigenvalues");
        [ev[2].max(0.0).sqrt(), ev[1].max(0.0).sqrt(), ev[0].max(0.0).sqrt()]
    }

    #[derive(Debug, Default, Clone, Copy)]
    struct Worst {
        reconstruction: f64,
        orthogonality: f64,
        det: f64,
        sigma_vs_eigen: f64,
        sigma_checked: usize,
        null_sigma: f64,
        max_sweeps: usize,
        capped: usize,
    }

    /// Runs one precision: `svd` maps an f64 matrix to (U, sigma, V, sweeps) in f64 after a
    /// round trip through the working precision; `a_work` is A as seen in that precision.
    fn run_precision(
        label: &str,
        tol: f64,
        mut svd: impl FnMut(DMat3) -> (DMat3, DMat3, DVec3, DMat3, usize),
    ) {
        let mut rng = ChaCha8Rng::seed_from_u64(if label == "f64" { 50 } else { 51 });
        let mut total = 0usize;
        for cat in CATEGORIES {
            let mut worst = Worst::default();
            for _ in 0..PER_CATEGORY {
                let a64 = generate(cat, &mut rng);
                let (a, u, sigma, v, sweeps) = svd(a64);
                total += 1;
                worst.max_sweeps = worst.max_sweeps.max(sweeps);
                worst.capped += usize::from(sweeps >= MAX_SWEEPS);
                let norm_a = frob(a).max(f64::MIN_POSITIVE);
                let rec = frob(u * DMat3::from_diagonal(sigma) * v.transpose() - a) / norm_a;
                let ortho =
                    frob(u.transpose() * u - DMat3::IDENTITY).max(frob(v.transpose() * v - DMat3::IDENTITY));
                let det = (u.determinant() - 1.0).abs().max((v.determinant() - 1.0).abs());
                worst.reconstruction = worst.reconstruction.max(rec);
                worst.orthogonality = worst.orthogonality.max(ortho);
                worst.det = worst.det.max(det);
                assert!(
                    rec <= tol,
                    "{label} {cat:?}: reconstruction {rec:e} for {a:?} -> {u:?} {sigma:?} {v:?}"
                );
                assert!(ortho <= tol, "{label} {cat:?}: orthogonality {ortho:e} for {a:?}");
                assert!(det <= tol, "{label} {cat:?}: det error {det:e} for {a:?}");
                // Ordering: sigma0 >= sigma1 >= |sigma2|, only sigma2 may be negative.
                assert!(
                    sigma.x >= sigma.y && sigma.y >= sigma.z.abs() && sigma.y >= 0.0,
                    "{label} {cat:?}: ordering {sigma:?}"
                );
                // The sign of sigma2 is the sign of det A when det A is clearly nonzero.
                let det_a = a.determinant();
                let det_scale = sigma.x.powi(3);
                if det_a.abs() > 1e3 * tol * det_scale {
                    assert_eq!(
                        sigma.z < 0.0,
                        det_a < 0.0,
                        "{label} {cat:?}: sign of sigma2 {sigma:?}, det {det_a:e}"
                    );
                }
                if cat == Category::Zero {
                    assert_eq!(sigma, DVec3::ZERO);
                    assert_eq!((u, v), (DMat3::IDENTITY, DMat3::IDENTITY));
                }
                // Magnitudes against an independent eigen-solver (sqrt of the eigenvalues of
                // A^T A, A rescaled to unit norm so A^T A stays in range). sqrt(lambda_i) carries
                // an error ~ eps sigma_0^2 / sigma_i, so only values with sigma_i > 1e-3 sigma_0
                // are compared (all three for well-conditioned A, the nonzero ones for rank-1/2).
                let reference = reference_singular_values(a / norm_a);
                let got = [sigma.x.abs(), sigma.y.abs(), sigma.z.abs()];
                for i in 0..3 {
                    if reference[0] > 0.0 && reference[i] > 1e-3 * reference[0] {
                        let err = (got[i] / norm_a - reference[i]).abs() / reference[0];
                        worst.sigma_vs_eigen = worst.sigma_vs_eigen.max(err);
                        worst.sigma_checked += 1;
                        assert!(
                            err <= tol,
                            "{label} {cat:?}: sigma {got:?} vs reference {reference:?} (x {norm_a})"
                        );
                    }
                }
                // The singular values that are zero by construction are zero to working precision.
                let exact_rank = match cat {
                    Category::Rank1 => 1,
                    Category::Rank2 => 2,
                    _ => 3,
                };
                for i in exact_rank..3 {
                    worst.null_sigma = worst.null_sigma.max(got[i] / got[0]);
                    assert!(
                        got[i] <= tol * got[0],
                        "{label} {cat:?}: sigma {got:?} should have rank {exact_rank}"
                    );
                }
            }
            println!(
                "svd {label} {:<13} reconstruction {:.2e}  orthogonality {:.2e}  |det-1| {:.2e}  sigma-vs-eig {:.2e} ({} values)  null sigma/sigma0 {:.2e}  max sweeps {} (capped {})",
                format!("{cat:?}"),
                worst.reconstruction,
                worst.orthogonality,
                worst.det,
                worst.sigma_vs_eigen,
                worst.sigma_checked,
                worst.null_sigma,
                worst.max_sweeps,
                worst.capped,
            );
        }
        assert!(total >= 10_000);
    }

    #[test]
    fn svd3_f64_categories() {
        run_precision("f64", 1e-12, |a| {
            let (u, s, v, sweeps) = svd3_cols(&a.to_cols_array_2d());
            let out = svd3(a);
            // The public wrapper returns exactly the kernel's result.
            assert_eq!(out.u, DMat3::from_cols_array_2d(&u));
            assert_eq!(out.sigma, DVec3::from_array(s));
            assert_eq!(out.v, DMat3::from_cols_array_2d(&v));
            (a, out.u, out.sigma, out.v, sweeps)
        });
    }

    #[test]
    fn svd3_f32_categories() {
        run_precision("f32", 1e-5, |a| {
            let a32 = a.as_mat3();
            let (_, _, _, sweeps) = svd3_cols(&a32.to_cols_array_2d());
            let out = svd3_f32(a32);
            (a32.as_dmat3(), out.u.as_dmat3(), out.sigma.as_dvec3(), out.v.as_dmat3(), sweeps)
        });
    }

    #[test]
    fn special_matrices_exact_structure() {
        // Identity: U = V = I, sigma = 1.
        let s = svd3(DMat3::IDENTITY);
        assert_eq!(s.sigma, DVec3::ONE);
        assert!(frob(s.u * s.v.transpose() - DMat3::IDENTITY) <= 1e-15);
        // A pure reflection: sigma = (1, 1, -1).
        let s = svd3(DMat3::from_diagonal(DVec3::new(1.0, 1.0, -1.0)));
        assert_eq!(s.sigma, DVec3::new(1.0, 1.0, -1.0));
        // Point reflection -I (det -1): sigma = (1, 1, -1), U V^T = -(reflection) is a rotation.
        let s = svd3(-DMat3::IDENTITY);
        assert_eq!(s.sigma, DVec3::new(1.0, 1.0, -1.0));
        assert!((s.u.determinant() - 1.0).abs() <= 1e-15 && (s.v.determinant() - 1.0).abs() <= 1e-15);
        // Diagonal with unsorted entries.
        let s = svd3(DMat3::from_diagonal(DVec3::new(2.0, -5.0, 3.0)));
        assert_eq!(s.sigma, DVec3::new(5.0, 3.0, -2.0));
        // Rank 1: e0 e0^T.
        let s = svd3(DMat3::from_cols(DVec3::X, DVec3::ZERO, DVec3::ZERO));
        assert_eq!(s.sigma, DVec3::new(1.0, 0.0, 0.0));
        assert!((s.u.determinant() - 1.0).abs() <= 1e-15);
        // Extreme scales keep their exact power-of-two structure.
        for scale in [1e-300, 1e300, 2f64.powi(-1070)] {
            let s = svd3(DMat3::IDENTITY * scale);
            assert_eq!(s.sigma, DVec3::splat(scale), "{scale:e}");
        }
        let s = svd3_f32(Mat3::IDENTITY * 1e-42); // subnormal f32
        assert_eq!(s.sigma, Vec3::splat(1e-42));
        let s = svd3_f32(Mat3::IDENTITY * 3e38);
        assert_eq!(s.sigma, Vec3::splat(3e38));
    }

    #[test]
    fn non_finite_input_does_not_panic() {
        let mut a = DMat3::IDENTITY;
        a.y_axis.z = f64::NAN;
        let s = svd3(a);
        assert!(!s.sigma.is_finite() || !s.u.is_finite() || !s.v.is_finite());
        let s = svd3_f32(Mat3::IDENTITY * f32::INFINITY);
        assert!(!s.sigma.is_finite() || !s.u.is_finite());
    }

    /// Independent reference for the rotation of a matrix with det > 0:
    /// R = A (A^T A)^{-1/2}, with (A^T A)^{-1/2} from faer's symmetric eigendecomposition.
    fn reference_rotation(a: DMat3) -> DMat3 {
        let ata = a.transpose() * a;
        let m = Mat::<f64>::from_fn(3, 3, |i, j| ata.col(j)[i]);
        let evd = m.self_adjoint_eigen(Side::Lower).expect("eigen");
        let (q, l) = (evd.U(), evd.S());
        let inv_sqrt = Mat::<f64>::from_fn(3, 3, |i, j| {
            (0..3).map(|k| q[(i, k)] * q[(j, k)] / l.column_vector()[k].sqrt()).sum()
        });
        a * DMat3::from_cols_array_2d(&[
            [inv_sqrt[(0, 0)], inv_sqrt[(1, 0)], inv_sqrt[(2, 0)]],
            [inv_sqrt[(0, 1)], inv_sqrt[(1, 1)], inv_sqrt[(2, 1)]],
            [inv_sqrt[(0, 2)], inv_sqrt[(1, 2)], inv_sqrt[(2, 2)]],
        ])
    }

    #[test]
    fn polar_decomposition() {
        let mut rng = ChaCha8Rng::seed_from_u64(52);
        let mut worst = [0.0f64; 4];
        for k in 0..4000 {
            let cat = CATEGORIES[k % CATEGORIES.len()];
            let a = generate(cat, &mut rng);
            let norm_a = frob(a).max(f64::MIN_POSITIVE);
            let (r, s) = polar(a);
            let rec = frob(r * s - a) / norm_a;
            let ortho = frob(r.transpose() * r - DMat3::IDENTITY);
            assert!(rec <= 1e-12 && ortho <= 1e-12, "{cat:?}: {rec:e} {ortho:e}");
            assert!((r.determinant() - 1.0).abs() <= 1e-12);
            assert_eq!(s, s.transpose(), "S exactly symmetric");
            worst[0] = worst[0].max(rec);
            worst[1] = worst[1].max(ortho);
            // det A > 0 and well conditioned: R is unique; compare with the reference.
            let sv = reference_singular_values(a / norm_a);
            // The reference loses cond(A)^2 * eps (it squares A), hence cond <= 100 here.
            if a.determinant() > 0.0 && sv[2] / sv[0] > 1e-2 {
                let err = frob(r - reference_rotation(a / norm_a));
                assert!(err <= 1e-11, "{cat:?}: rotation differs by {err:e}");
                worst[2] = worst[2].max(err);
                // S is then positive definite: x^T S x > 0.
                let x = rand_vec(&mut rng);
                assert!(x.dot(s * x) > 0.0);
            }
            // f32 version on the same matrix.
            let a32 = a.as_mat3();
            let (r32, s32) = polar_f32(a32);
            let rec32 = frob((r32 * s32 - a32).as_dmat3()) / frob(a32.as_dmat3()).max(f64::MIN_POSITIVE);
            let ortho32 = frob((r32.transpose() * r32 - Mat3::IDENTITY).as_dmat3());
            assert!(rec32 <= 1e-5 && ortho32 <= 1e-5, "f32 {cat:?}: {rec32:e} {ortho32:e}");
            worst[3] = worst[3].max(rec32.max(ortho32));
        }
        println!(
            "polar f64 reconstruction {:.2e} orthogonality {:.2e} vs reference rotation {:.2e}; f32 worst {:.2e}",
            worst[0], worst[1], worst[2], worst[3]
        );
    }

    /// `a * b` as an unevaluated sum `hi + lo` (exact; Dekker's product via a fused multiply-add).
    fn two_prod(a: f64, b: f64) -> (f64, f64) {
        let p = a * b;
        (p, a.mul_add(b, -p))
    }

    /// `det A` to about `1e-30 |A|^3` absolute accuracy: every triple product is expanded into four
    /// exact terms and the 24 terms are summed by Neumaier's compensated summation.
    fn accurate_det(a: DMat3) -> f64 {
        let m = |i: usize, j: usize| a.col(j)[i];
        let mut terms = Vec::with_capacity(24);
        for (p, sign) in [
            ([0, 1, 2], 1.0),
            ([1, 2, 0], 1.0),
            ([2, 0, 1], 1.0),
            ([0, 2, 1], -1.0),
            ([1, 0, 2], -1.0),
            ([2, 1, 0], -1.0),
        ] {
            let (h, l) = two_prod(m(0, p[0]), m(1, p[1]));
            let (hh, hl) = two_prod(h, m(2, p[2]));
            let (lh, ll) = two_prod(l, m(2, p[2]));
            terms.extend([sign * hh, sign * hl, sign * lh, sign * ll]);
        }
        let (mut sum, mut comp) = (0.0f64, 0.0f64);
        for t in terms {
            let s = sum + t;
            comp += if sum.abs() >= t.abs() { (sum - s) + t } else { (t - s) + sum };
            sum = s;
        }
        sum + comp
    }

    /// Nearly singular matrices `R1 diag(s0, s1, s2) R2` with `|s2| ~ 1e-12 .. 1e-6` (det A ~
    /// 1e-12 and below, either sign): the smallest singular value is compared with the
    /// independent `|det A| / (sigma_0 sigma_1)` (accurate determinant, the two large values from
    /// faer's eigenvalues of `A^T A`). A backward-stable SVD gets it to `O(eps) sigma_0` absolute;
    /// `sqrt` of the eigenvalue of `A^T A` would only give `O(sqrt(eps)) sigma_0 ~ 1e-8`.
    #[test]
    fn nearly_singular_smallest_singular_value() {
        let mut rng = ChaCha8Rng::seed_from_u64(53);
        let mut worst = [0.0f64; 3];
        for _ in 0..3000 {
            let s0: f64 = rng.random_range(0.5..2.0);
            let s1: f64 = rng.random_range(0.2..1.0) * s0;
            let s2: f64 =
                10f64.powf(rng.random_range(-12.0..-6.0)) * if rng.random_bool(0.5) { 1.0 } else { -1.0 };
            let a = rand_rotation(&mut rng)
                * DMat3::from_diagonal(DVec3::new(s0, s1, s2))
                * rand_rotation(&mut rng).transpose();
            let out = svd3(a);
            let norm_a = frob(a);
            let rec = frob(out.u * DMat3::from_diagonal(out.sigma) * out.v.transpose() - a) / norm_a;
            let ortho = frob(out.u.transpose() * out.u - DMat3::IDENTITY)
                .max(frob(out.v.transpose() * out.v - DMat3::IDENTITY));
            assert!(rec <= 1e-14 && ortho <= 1e-14, "{a:?}: reconstruction {rec:e}, orthogonality {ortho:e}");
            assert!((out.u.determinant() - 1.0).abs() <= 1e-14 && (out.v.determinant() - 1.0).abs() <= 1e-14);
            let reference = reference_singular_values(a);
            let det = accurate_det(a);
            let s2_ref = det / (reference[0] * reference[1]);
            // The stored A differs from the product by rounding (~eps), so compare with the
            // reference of the stored A, not with s2.
            let err2 = (out.sigma.z - s2_ref).abs() / out.sigma.x;
            assert!(
                err2 <= 8.0 * f64::EPSILON,
                "sigma_2 {:e} vs |det|/(s0 s1) {s2_ref:e}: {err2:e}",
                out.sigma.z
            );
            assert_eq!(out.sigma.z < 0.0, det < 0.0);
            let err01 = ((out.sigma.x - reference[0]).abs() / reference[0])
                .max((out.sigma.y - reference[1]).abs() / reference[0]);
            assert!(err01 <= 1e-14, "{:?} vs {reference:?}", out.sigma);
            worst = [worst[0].max(rec.max(ortho)), worst[1].max(err2), worst[2].max(err01)];
        }
        println!(
            "nearly singular: reconstruction/orthogonality {:.2e}, |sigma_2 - det/(s0 s1)|/s0 {:.2e} (eps {:.2e}), sigma_0,1 {:.2e}",
            worst[0],
            worst[1],
            f64::EPSILON,
            worst[2]
        );
    }

    /// Matrices inside the unscaled range and the same matrices times `2^k` outside it (handled
    /// by exact power-of-two scaling) give bitwise the same `U`, `V` and `sigma * 2^k`: the fast
    /// path and the scaled path agree exactly, for f64 and f32.
    #[test]
    fn unscaled_and_scaled_paths_agree_bitwise() {
        let mut rng = ChaCha8Rng::seed_from_u64(54);
        for k in 0..900 {
            let a = generate(CATEGORIES[k % CATEGORIES.len()], &mut rng);
            if frob(a) == 0.0 || frob(a) < 1e-20 || frob(a) > 1e20 {
                continue;
            }
            let base = svd3(a);
            for e in [300, -300, 700, -700] {
                let f = 2f64.powi(e);
                let scaled = svd3(a * f);
                assert_eq!((scaled.u, scaled.v), (base.u, base.v), "{a:?} x 2^{e}");
                assert_eq!(scaled.sigma, base.sigma * f, "{a:?} x 2^{e}");
            }
            let a32 = a.as_mat3();
            let base = svd3_f32(a32);
            let scaled = svd3_f32(a32 * 2f32.powi(-60));
            assert_eq!((scaled.u, scaled.v), (base.u, base.v));
            assert_eq!(scaled.sigma, base.sigma * 2f32.powi(-60));
        }
    }
}
