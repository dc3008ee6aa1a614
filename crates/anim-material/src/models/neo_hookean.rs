//! Compressible Neo-Hookean with the `log J` volume term (Sifakis & Barbič 2012).

use super::delta;
use crate::decomposition::{cofactor, determinant};
use crate::{Hyperelastic, Lame, Mat, Scalar, Tangent};
use num_traits::Float;

/// Compressible Neo-Hookean (Sifakis & Barbič 2012), `J = det F`:
///
/// ```text
/// psi = mu/2 (tr(F^T F) - d) - mu log J + lambda/2 log^2 J,
/// P   = mu (F - F^{-T}) + lambda log(J) F^{-T},
/// dP/dF_kl = mu E_kl + (mu - lambda log J) F^{-T} E_lk F^{-T} + lambda (F^{-T})_kl F^{-T}.
/// ```
///
/// The energy grows without bound as `J -> 0+`, which resists compression strongly (no
/// collapse, unlike St. Venant-Kirchhoff). **Undefined for `J <= 0`** (`log J`): there
/// [`Hyperelastic::energy`] returns `+inf` and [`Hyperelastic::pk1`] and [`Hyperelastic::dpdf`]
/// return matrices filled with NaN, so a caller detects an inverted element with `is_finite`
/// (or [`NeoHookean::is_defined`]) and handles it (reject the step, or switch the element to a
/// model defined under inversion such as [`crate::StableNeoHookean`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct NeoHookean;

impl NeoHookean {
    /// Whether `F` is in the model's domain, `det F > 0` (false for NaN).
    #[must_use]
    pub fn is_defined<T: Scalar, const D: usize>(f: &Mat<T, D>) -> bool {
        determinant(f) > T::zero()
    }
}

impl<T: Scalar, const D: usize> Hyperelastic<T, D> for NeoHookean {
    fn energy(&self, lame: &Lame<T>, f: &Mat<T, D>) -> T {
        let j = determinant(f);
        if !(j > T::zero()) {
            return if Float::is_nan(j) { j } else { T::infinity() };
        }
        let lj = Float::ln(j);
        T::of(0.5) * lame.mu * (f.dot(f) - T::of(D as f64)) - lame.mu * lj
            + T::of(0.5) * lame.lambda * lj * lj
    }

    fn pk1(&self, lame: &Lame<T>, f: &Mat<T, D>) -> Mat<T, D> {
        let j = determinant(f);
        if !(j > T::zero()) {
            return Mat::<T, D>::from_element(T::nan());
        }
        let g = cofactor(f) / j;
        (f - g) * lame.mu + g * (lame.lambda * Float::ln(j))
    }

    fn dpdf(&self, lame: &Lame<T>, f: &Mat<T, D>) -> Tangent<T, D> {
        let j = determinant(f);
        if !(j > T::zero()) {
            return Tangent { d: [[Mat::<T, D>::from_element(T::nan()); D]; D] };
        }
        let g = cofactor(f) / j;
        let a = lame.mu - lame.lambda * Float::ln(j);
        let mut t = Tangent::zeros();
        for k in 0..D {
            for l in 0..D {
                t.d[k][l] = Mat::<T, D>::from_fn(|i, jj| {
                    lame.mu * delta::<T>(i, k) * delta::<T>(jj, l)
                        + a * g[(i, l)] * g[(k, jj)]
                        + lame.lambda * g[(k, l)] * g[(i, jj)]
                });
            }
        }
        t
    }
}
