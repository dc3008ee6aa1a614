//! Stable Neo-Hookean (Smith, de Goes & Kim, *Stable Neo-Hookean Flesh Simulation*, ACM TOG
//! 37(2), 2018).

use super::delta;
use super::principal::{self, PrincipalEnergy, all_but, other};
use crate::decomposition::{cofactor, cofactor_derivative, determinant};
use crate::{Hyperelastic, Lame, Mat, Scalar, Tangent};
use nalgebra::SVector;
use num_traits::Float;

/// Stable Neo-Hookean (Smith, de Goes & Kim 2018, eq. 14 with the rest-state correction), with
/// `I_C = tr(F^T F)`, `J = det F`, `cof F = dJ/dF`:
///
/// ```text
/// psi = mu'/2 (I_C - d) + lambda'/2 (J - alpha)^2 - mu'/2 log(I_C + 1) - psi_0,
/// P   = mu' (1 - 1/(I_C + 1)) F + lambda' (J - alpha) cof F,
/// dP/dF = mu' (1 - 1/(I_C + 1)) I + 2 mu'/(I_C + 1)^2 F (x) F
///         + lambda' cof F (x) cof F + lambda' (J - alpha) d(cof F)/dF.
/// ```
///
/// The user's Lamé parameters `(mu, lambda)` are reparameterised (the paper's section 3.4) so
/// that the model linearises to [`crate::LinearElastic`] with those parameters:
/// 3D `mu' = 4/3 mu`, `lambda' = lambda + 5/6 mu`; 2D `mu' = 3/2 mu`, `lambda' = lambda + 2/3 mu`.
/// `alpha = 1 + d mu' / ((d + 1) lambda')` makes `P(I) = 0`, and the constant
/// `psi_0 = lambda'/2 (1 - alpha)^2 - mu'/2 log(d + 1)` makes `psi(I) = 0`. This needs
/// `lambda' > 0`, true for every `(E, nu)` accepted by [`Lame::from_young_poisson`] and
/// [`Lame::new`].
///
/// Polynomial in `F` apart from `log(I_C + 1) >= 0`: **defined and smooth for every `F`**,
/// inverted (`J < 0`) and degenerate (`J = 0`, `F = 0`) included, with no decomposition. It
/// resists inversion with a finite force, so inverted elements recover.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct StableNeoHookean;

/// Reparameterised `(mu', lambda', alpha)`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct SnhParams<T> {
    pub mu: T,
    pub lambda: T,
    pub alpha: T,
}

impl StableNeoHookean {
    /// `(mu', lambda', alpha)` from the user's Lamé parameters in dimension `d`.
    pub(crate) fn params<T: Scalar, const D: usize>(lame: &Lame<T>) -> SnhParams<T> {
        let (mu, lambda, alpha);
        if D == 2 {
            mu = T::of(1.5) * lame.mu;
            lambda = lame.lambda + T::of(2.0 / 3.0) * lame.mu;
            alpha = T::one() + T::of(2.0 / 3.0) * mu / lambda;
        } else {
            mu = T::of(4.0 / 3.0) * lame.mu;
            lambda = lame.lambda + T::of(5.0 / 6.0) * lame.mu;
            alpha = T::one() + T::of(0.75) * mu / lambda;
        }
        SnhParams { mu, lambda, alpha }
    }
}

impl<T: Scalar, const D: usize> Hyperelastic<T, D> for StableNeoHookean {
    fn energy(&self, lame: &Lame<T>, f: &Mat<T, D>) -> T {
        let p = Self::params::<T, D>(lame);
        let half = T::of(0.5);
        let dim = T::of(D as f64);
        let ic = f.dot(f);
        let j = determinant(f);
        let rest = half * p.lambda * (T::one() - p.alpha) * (T::one() - p.alpha)
            - half * p.mu * Float::ln(dim + T::one());
        half * p.mu * (ic - dim) + half * p.lambda * (j - p.alpha) * (j - p.alpha)
            - half * p.mu * Float::ln_1p(ic)
            - rest
    }

    fn pk1(&self, lame: &Lame<T>, f: &Mat<T, D>) -> Mat<T, D> {
        let p = Self::params::<T, D>(lame);
        let ic = f.dot(f);
        let j = determinant(f);
        f * (p.mu * (T::one() - T::one() / (ic + T::one()))) + cofactor(f) * (p.lambda * (j - p.alpha))
    }

    fn dpdf(&self, lame: &Lame<T>, f: &Mat<T, D>) -> Tangent<T, D> {
        let p = Self::params::<T, D>(lame);
        let ic = f.dot(f);
        let j = determinant(f);
        let c = cofactor(f);
        let a = p.mu * (T::one() - T::one() / (ic + T::one()));
        let b = (p.mu + p.mu) / ((ic + T::one()) * (ic + T::one()));
        let g = p.lambda * (j - p.alpha);
        let mut t = Tangent::zeros();
        for k in 0..D {
            for l in 0..D {
                t.d[k][l] = Mat::<T, D>::from_fn(|i, jj| {
                    a * delta::<T>(i, k) * delta::<T>(jj, l)
                        + b * f[(k, l)] * f[(i, jj)]
                        + p.lambda * c[(k, l)] * c[(i, jj)]
                        + g * cofactor_derivative(f, i, jj, k, l)
                });
            }
        }
        t
    }

    /// The analytic projection (Smith, de Goes & Kim, *Analytic eigensystems for isotropic
    /// distortion energies*, 2019): with `F = U diag(sigma) V^T` (rotation-variant SVD), the
    /// `d^2` eigenpairs of `dP/dF` are the twist and flip modes of each pair `(i, j)` (eigenvalues
    /// `a -+ lambda' (J - alpha) sigma_k`, see the [`PrincipalEnergy`] impl) and the `d` scaling
    /// modes of the `d x d` Hessian of `psi` in the singular values. The negative ones are set to
    /// zero and the tensor rebuilt, which equals [`Tangent::project_psd`] without the `d^2 x d^2`
    /// eigensolve.
    fn dpdf_psd(&self, lame: &Lame<T>, f: &Mat<T, D>) -> Tangent<T, D> {
        let p = Self::params::<T, D>(lame);
        principal::dpdf_psd(self, p.mu, p.lambda, f)
    }
}

/// The energy in the signed singular values, for the analytic eigensystem of `dP/dF` (module
/// [`principal`]). `mu` and `lambda` here are the reparameterised `(mu', lambda')`, `alpha` is
/// recomputed from them; with `I_C = sum sigma_i^2`, `J = prod sigma_i`,
/// `a = mu' (1 - 1/(I_C + 1))` and `sigma_k` the third singular value (`1` in 2D):
///
/// ```text
/// psi_i      = a sigma_i + lambda' (J - alpha) prod_{m != i} sigma_m,
/// psi_ij     = a delta_ij + 2 mu'/(I_C + 1)^2 sigma_i sigma_j
///              + lambda' prod_{m != i} sigma_m prod_{m != j} sigma_m + lambda' (J - alpha) sigma_k [i != j],
/// twist_ij   = (psi_i - psi_j)/(sigma_i - sigma_j) = a - lambda' (J - alpha) sigma_k,
/// flip_ij    = (psi_i + psi_j)/(sigma_i + sigma_j) = a + lambda' (J - alpha) sigma_k.
/// ```
///
/// Twist and flip are polynomial in `sigma` with the divisions carried out, so unlike the
/// corotated models there is no singular denominator: repeated singular values, `sigma_i =
/// -sigma_j` and `F = 0` all give the exact eigenvalues.
impl<T: Scalar, const D: usize> PrincipalEnergy<T, D> for StableNeoHookean {
    fn psi_hat(&self, mu: T, lambda: T, s: &SVector<T, D>) -> T {
        let alpha = snh_alpha::<T, D>(mu, lambda);
        let half = T::of(0.5);
        let dim = T::of(D as f64);
        let ic = s.dot(s);
        let j = s.product();
        let rest =
            half * lambda * (T::one() - alpha) * (T::one() - alpha) - half * mu * Float::ln(dim + T::one());
        half * mu * (ic - dim) + half * lambda * (j - alpha) * (j - alpha)
            - half * mu * Float::ln_1p(ic)
            - rest
    }

    fn gradient(&self, mu: T, lambda: T, s: &SVector<T, D>) -> SVector<T, D> {
        let alpha = snh_alpha::<T, D>(mu, lambda);
        let ic = s.dot(s);
        let a = mu * (T::one() - T::one() / (ic + T::one()));
        let g = lambda * (s.product() - alpha);
        SVector::<T, D>::from_fn(|i, _| a * s[i] + g * all_but(s, i))
    }

    fn hessian(&self, mu: T, lambda: T, s: &SVector<T, D>) -> Mat<T, D> {
        let alpha = snh_alpha::<T, D>(mu, lambda);
        let ic = s.dot(s);
        let a = mu * (T::one() - T::one() / (ic + T::one()));
        let b = (mu + mu) / ((ic + T::one()) * (ic + T::one()));
        let g = lambda * (s.product() - alpha);
        Mat::<T, D>::from_fn(|i, j| {
            let common = b * s[i] * s[j] + lambda * all_but(s, i) * all_but(s, j);
            if i == j { a + common } else { common + g * other(s, i, j) }
        })
    }

    fn twist(&self, mu: T, lambda: T, s: &SVector<T, D>, i: usize, j: usize) -> T {
        let alpha = snh_alpha::<T, D>(mu, lambda);
        let ic = s.dot(s);
        mu * (T::one() - T::one() / (ic + T::one())) - lambda * (s.product() - alpha) * other(s, i, j)
    }

    fn flip(&self, mu: T, lambda: T, s: &SVector<T, D>, i: usize, j: usize) -> T {
        let alpha = snh_alpha::<T, D>(mu, lambda);
        let ic = s.dot(s);
        mu * (T::one() - T::one() / (ic + T::one())) + lambda * (s.product() - alpha) * other(s, i, j)
    }
}

/// `alpha = 1 + d mu' / ((d + 1) lambda')`, as in [`StableNeoHookean::params`].
#[inline]
fn snh_alpha<T: Scalar, const D: usize>(mu: T, lambda: T) -> T {
    let c = if D == 2 { T::of(2.0 / 3.0) } else { T::of(0.75) };
    T::one() + c * mu / lambda
}
