//! St. Venant-Kirchhoff (Sifakis & Barbič 2012).

use super::delta;
use crate::{Hyperelastic, Lame, Mat, Scalar, Tangent};

/// St. Venant-Kirchhoff: linear elasticity on the Green strain `E = (F^T F - I)/2`:
///
/// ```text
/// psi = mu E:E + lambda/2 tr^2(E),   P = F S,  S = 2 mu E + lambda tr(E) I,
/// dP/dF_kl = E_kl S + F dS_kl,       dS_kl = mu (F^T E_kl + E_lk F) + lambda F_kl I.
/// ```
///
/// Rotation invariant and polynomial (cheap, no decomposition), but it **softens under
/// compression**: the energy of a uniform compression `F = s I` peaks at `s^2 = 1/3` (3D, nu = 0)
/// and falls back to zero as `s -> 0`, so an element pushed far enough collapses and inverts
/// with no resistance. Use for moderate strains without strong compression.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct StVenantKirchhoff;

impl StVenantKirchhoff {
    /// Green strain and the second Piola-Kirchhoff stress `S`.
    fn strain_stress<T: Scalar, const D: usize>(lame: &Lame<T>, f: &Mat<T, D>) -> (Mat<T, D>, Mat<T, D>) {
        let c = f.transpose() * f;
        let e = Mat::<T, D>::from_fn(|i, j| T::of(0.5) * (c[(i, j)] - delta::<T>(i, j)));
        let tr = e.trace();
        let mut s = e * (lame.mu + lame.mu);
        for i in 0..D {
            s[(i, i)] += lame.lambda * tr;
        }
        (e, s)
    }
}

impl<T: Scalar, const D: usize> Hyperelastic<T, D> for StVenantKirchhoff {
    fn energy(&self, lame: &Lame<T>, f: &Mat<T, D>) -> T {
        let (e, _) = Self::strain_stress(lame, f);
        let tr = e.trace();
        lame.mu * e.dot(&e) + T::of(0.5) * lame.lambda * tr * tr
    }

    fn pk1(&self, lame: &Lame<T>, f: &Mat<T, D>) -> Mat<T, D> {
        let (_, s) = Self::strain_stress(lame, f);
        f * s
    }

    fn dpdf(&self, lame: &Lame<T>, f: &Mat<T, D>) -> Tangent<T, D> {
        let (_, s) = Self::strain_stress(lame, f);
        let fft = f * f.transpose();
        let mut t = Tangent::zeros();
        for k in 0..D {
            for l in 0..D {
                t.d[k][l] = Mat::<T, D>::from_fn(|i, j| {
                    delta::<T>(i, k) * s[(l, j)]
                        + lame.mu * (fft[(i, k)] * delta::<T>(l, j) + f[(i, l)] * f[(k, j)])
                        + lame.lambda * f[(k, l)] * f[(i, j)]
                });
            }
        }
        t
    }
}
