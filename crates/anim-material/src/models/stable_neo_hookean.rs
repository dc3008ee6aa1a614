//! Stable Neo-Hookean (Smith, de Goes & Kim, *Stable Neo-Hookean Flesh Simulation*, ACM TOG
//! 37(2), 2018).

use super::delta;
use crate::decomposition::{cofactor, cofactor_derivative, determinant};
use crate::{Hyperelastic, Lame, Mat, Scalar, Tangent};
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
}
