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
//! constitutive models need (seed 5.1; Irving, Teran & Fedkiw, *Invertible finite elements for
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
//! 1. the matrix is first scaled by a power of two so its largest entry is of order one (exact;
//!    it avoids overflow and underflow of the squared norms for any scale, e.g. `1e-30` or
//!    `1e30`), and `sigma` is scaled back at the end;
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
//! The kernel is written once over [`Real`] on `[[T; 3]; 3]` arrays and exposed for
//! `glam::DMat3` ([`svd3`], [`polar`]) and `glam::Mat3` ([`svd3_f32`], [`polar_f32`]).

use glam::{DMat3, DVec3, Mat3, Vec3};

use crate::scalar::Real;

/// Cap on one-sided Jacobi sweeps (each sweep visits the 3 column pairs).
pub const MAX_SWEEPS: usize = 12;

/// A column pair counts as orthogonal when `|w_p . w_q| <= ORTHO_FACTOR * eps * |w_p| |w_q|`:
/// 3 eps bounds the rounding error of a 3-term dot product (Higham, *Accuracy and Stability of
/// Numerical Algorithms*, 2nd ed., section 3.1), so a smaller cosine cannot be resolved.
const ORTHO_FACTOR: f64 = 3.0;

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

#[inline]
fn dot3<T: Real>(a: &[T; 3], b: &[T; 3]) -> T {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[inline]
fn cross3<T: Real>(a: &[T; 3], b: &[T; 3]) -> [T; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

#[inline]
fn det3<T: Real>(m: &Cols<T>) -> T {
    dot3(&m[0], &cross3(&m[1], &m[2]))
}

#[inline]
fn scale3<T: Real>(a: &[T; 3], s: T) -> [T; 3] {
    [a[0] * s, a[1] * s, a[2] * s]
}

/// Multiplies every entry by `2^e` exactly (in two steps, so the factor itself never overflows
/// in `f32`).
fn scale_pow2<T: Real>(x: T, e: i32) -> T {
    let h1 = e / 2;
    let h2 = e - h1;
    x * T::of(2f64.powi(h1)) * T::of(2f64.powi(h2))
}

/// A unit vector orthogonal to the unit vector `u`: `u` crossed with the coordinate axis least
/// aligned with it, normalised.
fn any_orthogonal<T: Real>(u: &[T; 3]) -> [T; 3] {
    let (ax, ay, az) = (u[0].abs(), u[1].abs(), u[2].abs());
    let axis = if ax <= ay && ax <= az {
        [T::one(), T::zero(), T::zero()]
    } else if ay <= az {
        [T::zero(), T::one(), T::zero()]
    } else {
        [T::zero(), T::zero(), T::one()]
    };
    let c = cross3(u, &axis);
    let n = dot3(&c, &c).sqrt();
    scale3(&c, T::one() / n)
}

/// One-sided Jacobi on the columns of `w`, accumulating the rotations into `v`. Pairs are
/// skipped when already orthogonal to working precision or when one column is negligible
/// (norm `<= negligible`, i.e. `eps ||A||_F`: a rounding-noise column cannot be orthogonalised
/// further, and its direction is not used). Returns the number of sweeps that rotated.
fn hestenes<T: Real>(w: &mut Cols<T>, v: &mut Cols<T>, negligible: T) -> usize {
    const PAIRS: [(usize, usize); 3] = [(0, 1), (0, 2), (1, 2)];
    let tol = T::of(ORTHO_FACTOR) * T::EPS;
    let two = T::one() + T::one();
    for sweep in 0..MAX_SWEEPS {
        let mut rotated = false;
        for &(p, q) in &PAIRS {
            let alpha = dot3(&w[p], &w[p]);
            let beta = dot3(&w[q], &w[q]);
            let gamma = dot3(&w[p], &w[q]);
            let (norm_p, norm_q) = (alpha.sqrt(), beta.sqrt());
            // Written so that NaN counts as converged: it cannot be improved.
            if !(gamma.abs() > tol * norm_p * norm_q) || !(norm_p.min(norm_q) > negligible) {
                continue;
            }
            rotated = true;
            let zeta = (beta - alpha) / (two * gamma);
            let sign = if zeta >= T::zero() { T::one() } else { -T::one() };
            // hypot avoids overflowing zeta^2.
            let t = sign / (zeta.abs() + T::one().hypot(zeta));
            let c = T::one() / T::one().hypot(t);
            let s = c * t;
            for k in 0..3 {
                let (wp, wq) = (w[p][k], w[q][k]);
                w[p][k] = c * wp - s * wq;
                w[q][k] = s * wp + c * wq;
                let (vp, vq) = (v[p][k], v[q][k]);
                v[p][k] = c * vp - s * vq;
                v[q][k] = s * vp + c * vq;
            }
        }
        if !rotated {
            return sweep;
        }
    }
    MAX_SWEEPS
}

/// The SVD kernel on column arrays; also returns the number of Jacobi sweeps.
fn svd3_cols<T: Real>(a: &Cols<T>) -> (Cols<T>, [T; 3], Cols<T>, usize) {
    let (zero, one) = (T::zero(), T::one());
    let identity = [[one, zero, zero], [zero, one, zero], [zero, zero, one]];
    let finite = a.iter().flatten().all(|x| x.is_finite());
    let max_abs = a.iter().flatten().fold(zero, |m, x| m.max(x.abs()));
    if finite && max_abs == zero {
        return (identity, [zero; 3], identity, 0);
    }
    // 1. Exact power-of-two scaling to entries of order one (skipped for non-finite input).
    let exponent = if finite { max_abs.to_f64_lossless().log2().floor() as i32 } else { 0 };
    let mut w = [[zero; 3]; 3];
    for j in 0..3 {
        for i in 0..3 {
            w[j][i] = scale_pow2(a[j][i], -exponent);
        }
    }
    let mut v = identity;
    let negligible = T::EPS * w.iter().flatten().map(|x| *x * *x).sum::<T>().sqrt();
    let sweeps = hestenes(&mut w, &mut v, negligible);

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
    let u0 = scale3(&w[0], one / norms[0]);
    let proj = dot3(&u0, &w[1]);
    let perp = [w[1][0] - proj * u0[0], w[1][1] - proj * u0[1], w[1][2] - proj * u0[2]];
    let perp_norm = dot3(&perp, &perp).sqrt();
    let u1 = if perp_norm > negligible { scale3(&perp, one / perp_norm) } else { any_orthogonal(&u0) };
    let u2 = cross3(&u0, &u1);
    let mut sigma = norms;
    if dot3(&u2, &w[2]) < zero {
        sigma[2] = -sigma[2];
    }
    // 4. det V = +1 by moving a reflection onto sigma_2.
    if det3(&v) < zero {
        v[2] = scale3(&v[2], -one);
        sigma[2] = -sigma[2];
    }
    if sigma[2] == zero {
        sigma[2] = zero; // no negative zero
    }
    for s in &mut sigma {
        *s = scale_pow2(*s, exponent);
    }
    ([u0, u1, u2], sigma, v, sweeps)
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

/// SVD of a `f32` matrix, computed in `f32` (see [`svd3`]).
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

/// Polar decomposition `a = r * s` of a `f32` matrix, computed in `f32` (see [`polar`]).
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
}
