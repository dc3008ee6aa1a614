//! Isotropic energies written in the singular values of `F`, and their derivatives through the
//! rotation-variant SVD.
//!
//! For `psi(F) = psi_hat(sigma)` with `F = U diag(sigma) V^T`:
//!
//! ```text
//! P(F) = U diag(dpsi_hat/dsigma_i) V^T.
//! ```
//!
//! The derivative `dP/dF` includes the terms from the rotation of `U` and `V`. In the rotated
//! frame, `dP = U A[U^T dF V] V^T`, and the tensor `A` decouples (Teran, Sifakis, Irving &
//! Fedkiw, *Robust quasistatic finite elements and flesh simulation*, SCA 2005, section 5;
//! Stomakhin et al., *Energetically consistent invertible elasticity*, SCA 2012):
//!
//! - the diagonal entries couple through the Hessian of `psi_hat`:
//!   `A[M]_ii = sum_j psi_hat_ij M_jj`;
//! - each off-diagonal pair `(M_ij, M_ji)`, `i < j`, is mapped by the 2x2 block
//!   `1/2 [[c1 + c2, c1 - c2], [c1 - c2, c1 + c2]]` with
//!   `c1 = (psi_i - psi_j) / (sigma_i - sigma_j)` (the twist, eigenvector `(1, 1)`) and
//!   `c2 = (psi_i + psi_j) / (sigma_i + sigma_j)` (the flip, eigenvector `(1, -1)`), where
//!   `psi_i = dpsi_hat/dsigma_i`.
//!
//! `c1` has a removable singularity at coincident singular values (pure rotations, uniform
//! scaling): each model gives it in closed form with the division carried out, so it is exact
//! there. `c2` is singular where `sigma_i + sigma_j = 0`, which with the rotation-variant SVD
//! happens only for an inverted `F` with `sigma_{d-1} = -sigma_{d-2}`: there the rotation `R`
//! itself is not unique and `P` is discontinuous, so no finite tangent exists; the denominator
//! is clamped to at least `sqrt(eps)` so the value stays finite.
//!
//! The eigen-decomposition of `A` is explicit (Smith, de Goes & Kim, *Analytic eigensystems for
//! isotropic distortion energies*, ACM TOG 2019): `c1` and `c2` for each pair, and the
//! eigenvalues of the `d x d` Hessian of `psi_hat`. [`crate::Hyperelastic::dpdf_psd`] of these models clamps them to zero, which
//! gives the positive semi-definite projection of `dP/dF` without a `d^2 x d^2` eigensolve.

use crate::decomposition::{Svd, assert_dim, svd};
use crate::{Mat, Scalar, Tangent};
use nalgebra::{Matrix2, Matrix3, SVector, SymmetricEigen};
use num_traits::Float;

/// An isotropic energy density written in the (signed) singular values.
pub trait PrincipalEnergy<T: Scalar, const D: usize> {
    /// `psi_hat(sigma)`.
    fn psi_hat(&self, mu: T, lambda: T, s: &SVector<T, D>) -> T;
    /// `dpsi_hat / dsigma_i`.
    fn gradient(&self, mu: T, lambda: T, s: &SVector<T, D>) -> SVector<T, D>;
    /// `d^2 psi_hat / dsigma_i dsigma_j`.
    fn hessian(&self, mu: T, lambda: T, s: &SVector<T, D>) -> Mat<T, D>;
    /// `(psi_i - psi_j) / (sigma_i - sigma_j)` in closed form (finite at `sigma_i = sigma_j`).
    fn twist(&self, mu: T, lambda: T, s: &SVector<T, D>, i: usize, j: usize) -> T;
    /// `(psi_i + psi_j) / (sigma_i + sigma_j)`, the denominator clamped by [`clamp_sum`].
    fn flip(&self, mu: T, lambda: T, s: &SVector<T, D>, i: usize, j: usize) -> T;
}

/// `sigma_i + sigma_j` clamped to at least `sqrt(eps)` (it is `>= 0` by the SVD's ordering).
#[inline]
#[must_use]
pub fn clamp_sum<T: Scalar>(sum: T) -> T {
    let floor = Float::sqrt(T::EPS);
    if sum > floor { sum } else { floor }
}

/// `P = U diag(psi_i) V^T`.
pub(crate) fn pk1<T: Scalar, const D: usize, M: PrincipalEnergy<T, D>>(
    m: &M,
    mu: T,
    lambda: T,
    f: &Mat<T, D>,
) -> Mat<T, D> {
    let s = svd(f);
    let g = m.gradient(mu, lambda, &s.sigma);
    let ug = Mat::<T, D>::from_fn(|i, j| s.u[(i, j)] * g[j]);
    ug * s.v.transpose()
}

/// The rotated-frame coefficients: the Hessian of `psi_hat` and `(c1, c2)` per pair.
struct Frame<T: Scalar, const D: usize> {
    svd: Svd<T, D>,
    hess: Mat<T, D>,
    twist: Mat<T, D>,
    flip: Mat<T, D>,
}

fn frame<T: Scalar, const D: usize, M: PrincipalEnergy<T, D>>(
    m: &M,
    mu: T,
    lambda: T,
    f: &Mat<T, D>,
) -> Frame<T, D> {
    let s = svd(f);
    let hess = m.hessian(mu, lambda, &s.sigma);
    let mut twist = Mat::<T, D>::zeros();
    let mut flip = Mat::<T, D>::zeros();
    for i in 0..D {
        for j in i + 1..D {
            twist[(i, j)] = m.twist(mu, lambda, &s.sigma, i, j);
            flip[(i, j)] = m.flip(mu, lambda, &s.sigma, i, j);
        }
    }
    Frame { svd: s, hess, twist, flip }
}

/// Assembles `d[k][l] = U A[U^T E_kl V] V^T` from the rotated-frame coefficients.
fn assemble<T: Scalar, const D: usize>(fr: &Frame<T, D>) -> Tangent<T, D> {
    let (u, v) = (&fr.svd.u, &fr.svd.v);
    let half = T::of(0.5);
    let mut t = Tangent::zeros();
    for k in 0..D {
        for l in 0..D {
            // M = U^T E_kl V: M_ab = U_ka V_lb.
            let m = Mat::<T, D>::from_fn(|a, b| u[(k, a)] * v[(l, b)]);
            let mut a = Mat::<T, D>::zeros();
            for i in 0..D {
                let mut x = T::zero();
                for j in 0..D {
                    x += fr.hess[(i, j)] * m[(j, j)];
                }
                a[(i, i)] = x;
                for j in i + 1..D {
                    let (c1, c2) = (fr.twist[(i, j)], fr.flip[(i, j)]);
                    let (p, q) = ((c1 + c2) * half, (c1 - c2) * half);
                    a[(i, j)] = p * m[(i, j)] + q * m[(j, i)];
                    a[(j, i)] = q * m[(i, j)] + p * m[(j, i)];
                }
            }
            t.d[k][l] = u * a * v.transpose();
        }
    }
    t
}

/// `dP/dF` with the rotation-derivative terms.
pub(crate) fn dpdf<T: Scalar, const D: usize, M: PrincipalEnergy<T, D>>(
    m: &M,
    mu: T,
    lambda: T,
    f: &Mat<T, D>,
) -> Tangent<T, D> {
    assemble(&frame(m, mu, lambda, f))
}

/// `(psi, P, dP/dF)` from one SVD.
pub(crate) fn energy_pk1_dpdf<T: Scalar, const D: usize, M: PrincipalEnergy<T, D>>(
    m: &M,
    mu: T,
    lambda: T,
    f: &Mat<T, D>,
) -> (T, Mat<T, D>, Tangent<T, D>) {
    let fr = frame(m, mu, lambda, f);
    let s = &fr.svd;
    let e = m.psi_hat(mu, lambda, &s.sigma);
    let g = m.gradient(mu, lambda, &s.sigma);
    let ug = Mat::<T, D>::from_fn(|i, j| s.u[(i, j)] * g[j]);
    (e, ug * s.v.transpose(), assemble(&fr))
}

/// The positive semi-definite projection of `dP/dF` from the analytic eigensystem: `c1`, `c2`
/// clamped at zero and the `d x d` Hessian of `psi_hat` projected.
pub(crate) fn dpdf_psd<T: Scalar, const D: usize, M: PrincipalEnergy<T, D>>(
    m: &M,
    mu: T,
    lambda: T,
    f: &Mat<T, D>,
) -> Tangent<T, D> {
    let mut fr = frame(m, mu, lambda, f);
    for i in 0..D {
        for j in i + 1..D {
            fr.twist[(i, j)] = Float::max(fr.twist[(i, j)], T::zero());
            fr.flip[(i, j)] = Float::max(fr.flip[(i, j)], T::zero());
        }
    }
    fr.hess = project_small(&fr.hess);
    assemble(&fr)
}

/// PSD projection of a symmetric 2x2 or 3x3 matrix.
fn project_small<T: Scalar, const D: usize>(h: &Mat<T, D>) -> Mat<T, D> {
    assert_dim!(D);
    if D == 2 {
        let m = Matrix2::<T>::from_fn(|i, j| h[(i, j)]);
        let mut e = SymmetricEigen::new(m);
        e.eigenvalues.iter_mut().for_each(|x| *x = Float::max(*x, T::zero()));
        let r = e.recompose();
        Mat::<T, D>::from_fn(|i, j| r[(i, j)])
    } else {
        let m = Matrix3::<T>::from_fn(|i, j| h[(i, j)]);
        let mut e = SymmetricEigen::new(m);
        e.eigenvalues.iter_mut().for_each(|x| *x = Float::max(*x, T::zero()));
        let r = e.recompose();
        Mat::<T, D>::from_fn(|i, j| r[(i, j)])
    }
}

/// The product of the singular values other than `i` and `j` (`1` in 2D, `sigma_k` in 3D).
#[inline]
pub(crate) fn other<T: Scalar, const D: usize>(s: &SVector<T, D>, i: usize, j: usize) -> T {
    if D == 2 { T::one() } else { s[3 - i - j] }
}

/// The product of the singular values other than `i`.
#[inline]
pub(crate) fn all_but<T: Scalar, const D: usize>(s: &SVector<T, D>, i: usize) -> T {
    let mut p = T::one();
    for k in 0..D {
        if k != i {
            p *= s[k];
        }
    }
    p
}
