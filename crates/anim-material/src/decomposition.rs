//! Determinant, cofactor matrix, and the rotation-variant SVD and polar decomposition in 2D
//! and 3D on nalgebra matrices.
//!
//! # Rotation-variant SVD
//!
//! [`svd`] returns `F = U diag(sigma) V^T` with `U`, `V` **proper rotations** (`det = +1`) and
//! `sigma_0 >= ... >= |sigma_{D-1}|`; only the last singular value may be negative, and it is
//! when `det F < 0`. An inverted element thus keeps the rotation `R = U V^T` and shows its
//! inversion as a negative last singular value (Irving, Teran & Fedkiw, *Invertible finite
//! elements for robust simulation of large deformation*, SCA 2004). The corotated and fixed
//! corotated models are evaluated on this decomposition.
//!
//! - 3D: the one-sided Jacobi kernel of `anim_core::linalg::svd` ([`anim_core::linalg::svd3_real`]).
//! - 2D: closed form. Writing `F = [[a, b], [c, d]]` as a similarity plus a reflection part,
//!   `E = (a + d)/2`, `H = (c - b)/2`, `F' = (a - d)/2`, `G = (c + b)/2`, `Q = |(E, H)|`,
//!   `R = |(F', G)|`, `a_1 = atan2(G, F')`, `a_2 = atan2(H, E)`, one has exactly
//!   `F = Rot(phi) diag(Q + R, Q - R) Rot(theta)^T` with `phi = (a_1 + a_2)/2`,
//!   `theta = (a_1 - a_2)/2`. `Q + R >= |Q - R|` always, and `Q - R < 0` exactly when
//!   `det F = Q^2 - R^2 < 0`. No trigonometric function is evaluated: with `z_1 = exp(i a_1) =
//!   (F' + i G)/R` and `z_2 = exp(i a_2) = (E + i H)/Q`, `exp(i phi)` is a square root of
//!   `z_1 z_2` (taken without cancellation) and `exp(i theta) = z_1 exp(-i phi)`. Coincident
//!   singular values (`R = 0`), a zero similarity part (`Q = 0`) and the zero matrix take
//!   `z = 1` (the `atan2(0, 0) = 0` convention) and give a valid pair of rotations.

use crate::{Mat, Scalar};
use nalgebra::SVector;
use num_traits::Float;

/// Compile-time check that the dimension is supported.
macro_rules! assert_dim {
    ($d:expr) => {
        const { assert!($d == 2 || $d == 3, "anim-material models are defined for D = 2 and D = 3") }
    };
}
pub(crate) use assert_dim;

/// A rotation-variant singular value decomposition `F = u diag(sigma) v^T`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Svd<T: Scalar, const D: usize> {
    /// Left singular vectors (columns), a proper rotation.
    pub u: Mat<T, D>,
    /// Singular values, decreasing in magnitude; only the last may be negative.
    pub sigma: SVector<T, D>,
    /// Right singular vectors (columns), a proper rotation.
    pub v: Mat<T, D>,
}

impl<T: Scalar, const D: usize> Svd<T, D> {
    /// The rotation `R = U V^T` of the polar decomposition.
    #[must_use]
    pub fn rotation(&self) -> Mat<T, D> {
        self.u * self.v.transpose()
    }
}

/// Rotation-variant SVD of a 2x2 matrix in closed form (see the [module docs](self)).
#[must_use]
pub fn svd2<T: Scalar>(f: &Mat<T, 2>) -> Svd<T, 2> {
    let half = T::of(0.5);
    let (zero, one) = (T::zero(), T::one());
    let (a, b, c, d) = (f[(0, 0)], f[(0, 1)], f[(1, 0)], f[(1, 1)]);
    let e = (a + d) * half;
    let h = (c - b) * half;
    let fp = (a - d) * half;
    let g = (c + b) * half;
    let q = Float::hypot(e, h);
    let r = Float::hypot(fp, g);
    // z1 = exp(i a_1), z2 = exp(i a_2); atan2(0, 0) = 0 gives 1 for a zero part.
    let (c1, s1) = if r > zero { (fp / r, g / r) } else { (one, zero) };
    let (c2, s2) = if q > zero { (e / q, h / q) } else { (one, zero) };
    // exp(i phi) = sqrt(z1 z2), phi = (a_1 + a_2)/2 up to pi, which flips U and V together.
    let (x, y) = (c1 * c2 - s1 * s2, s1 * c2 + c1 * s2);
    let (cp, sp) = unit_sqrt(x, y);
    // exp(i theta) = z1 exp(-i phi), theta = a_1 - phi.
    let (ct, st) = (c1 * cp + s1 * sp, s1 * cp - c1 * sp);
    Svd {
        u: Mat::<T, 2>::new(cp, -sp, sp, cp),
        sigma: SVector::<T, 2>::new(q + r, q - r),
        v: Mat::<T, 2>::new(ct, -st, st, ct),
    }
}

/// A square root of the unit complex number `x + i y`, computed without cancellation:
/// `(sqrt((1 + x)/2), y / (2 c))` for `x >= 0`, else `(|y| / (2 s), sign(y) sqrt((1 - x)/2))`.
#[inline]
fn unit_sqrt<T: Scalar>(x: T, y: T) -> (T, T) {
    let half = T::of(0.5);
    if x >= T::zero() {
        let c = Float::sqrt((T::one() + x) * half);
        (c, y * half / c)
    } else {
        let s = Float::sqrt((T::one() - x) * half);
        let s = if y < T::zero() { -s } else { s };
        (y * half / s, s)
    }
}

/// Rotation-variant SVD of a 3x3 matrix (one-sided Jacobi, see [`anim_core::linalg::svd`]).
#[must_use]
pub fn svd3<T: Scalar>(f: &Mat<T, 3>) -> Svd<T, 3> {
    let cols = [
        [f[(0, 0)], f[(1, 0)], f[(2, 0)]],
        [f[(0, 1)], f[(1, 1)], f[(2, 1)]],
        [f[(0, 2)], f[(1, 2)], f[(2, 2)]],
    ];
    let (u, s, v) = anim_core::linalg::svd3_real(&cols);
    Svd {
        u: Mat::<T, 3>::from_fn(|i, j| u[j][i]),
        sigma: SVector::<T, 3>::new(s[0], s[1], s[2]),
        v: Mat::<T, 3>::from_fn(|i, j| v[j][i]),
    }
}

/// Rotation-variant SVD in 2D or 3D (see the [module docs](self)).
#[must_use]
pub fn svd<T: Scalar, const D: usize>(f: &Mat<T, D>) -> Svd<T, D> {
    assert_dim!(D);
    if D == 2 {
        let s = svd2(&Mat::<T, 2>::from_fn(|i, j| f[(i, j)]));
        Svd {
            u: Mat::<T, D>::from_fn(|i, j| s.u[(i, j)]),
            sigma: SVector::<T, D>::from_fn(|i, _| s.sigma[i]),
            v: Mat::<T, D>::from_fn(|i, j| s.v[(i, j)]),
        }
    } else {
        let s = svd3(&Mat::<T, 3>::from_fn(|i, j| f[(i, j)]));
        Svd {
            u: Mat::<T, D>::from_fn(|i, j| s.u[(i, j)]),
            sigma: SVector::<T, D>::from_fn(|i, _| s.sigma[i]),
            v: Mat::<T, D>::from_fn(|i, j| s.v[(i, j)]),
        }
    }
}

/// Polar decomposition `F = R S`: `R = U V^T` a proper rotation, `S = V diag(sigma) V^T`
/// symmetric (indefinite when `det F < 0`), from the rotation-variant [`svd`].
#[must_use]
pub fn polar<T: Scalar, const D: usize>(f: &Mat<T, D>) -> (Mat<T, D>, Mat<T, D>) {
    let s = svd(f);
    let r = s.rotation();
    let vs = Mat::<T, D>::from_fn(|i, j| s.v[(i, j)] * s.sigma[j]);
    let mut sym = vs * s.v.transpose();
    // Exactly symmetric.
    for i in 0..D {
        for j in 0..i {
            let m = (sym[(i, j)] + sym[(j, i)]) * T::of(0.5);
            sym[(i, j)] = m;
            sym[(j, i)] = m;
        }
    }
    (r, sym)
}

/// The cofactor matrix `cof F = det(F) F^{-T}` (defined for every `F`, singular included):
/// `dJ/dF = cof F`.
#[inline]
#[must_use]
pub fn cofactor<T: Scalar, const D: usize>(f: &Mat<T, D>) -> Mat<T, D> {
    assert_dim!(D);
    if D == 2 {
        Mat::<T, D>::from_fn(|i, j| {
            let s = if i == j { T::one() } else { -T::one() };
            s * f[(1 - i, 1 - j)]
        })
    } else {
        Mat::<T, D>::from_fn(|i, j| {
            let (i1, i2, j1, j2) = ((i + 1) % 3, (i + 2) % 3, (j + 1) % 3, (j + 2) % 3);
            f[(i1, j1)] * f[(i2, j2)] - f[(i1, j2)] * f[(i2, j1)]
        })
    }
}

/// `det F`.
#[inline]
#[must_use]
pub fn determinant<T: Scalar, const D: usize>(f: &Mat<T, D>) -> T {
    assert_dim!(D);
    if D == 2 {
        f[(0, 0)] * f[(1, 1)] - f[(0, 1)] * f[(1, 0)]
    } else {
        let c = cofactor(f);
        f[(0, 0)] * c[(0, 0)] + f[(0, 1)] * c[(0, 1)] + f[(0, 2)] * c[(0, 2)]
    }
}

/// Sign of the permutation `(i, k, m)` of `(0, 1, 2)`, all distinct.
#[inline]
fn levi_civita3(i: usize, k: usize) -> i32 {
    if (i + 1) % 3 == k { 1 } else { -1 }
}

/// `d(cof F)_ij / dF_kl`, the second derivative of `det F`. In 3D
/// `eps_ikm eps_jln F_mn` (one term: `m`, `n` are the remaining indices), in 2D `eps_ik eps_jl`.
#[inline]
#[must_use]
pub(crate) fn cofactor_derivative<T: Scalar, const D: usize>(
    f: &Mat<T, D>,
    i: usize,
    j: usize,
    k: usize,
    l: usize,
) -> T {
    if i == k || j == l {
        return T::zero();
    }
    if D == 2 {
        // eps_01 = 1, eps_10 = -1 (i != k, j != l): the product is +1 when both pairs are ordered alike.
        if (i < k) == (j < l) { T::one() } else { -T::one() }
    } else {
        let (m, n) = (3 - i - k, 3 - j - l);
        let s = levi_civita3(i, k) * levi_civita3(j, l);
        if s > 0 { f[(m, n)] } else { -f[(m, n)] }
    }
}
