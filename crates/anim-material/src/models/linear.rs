//! Linear (small-strain) elasticity (Sifakis & Barbič 2012).

use super::delta;
use crate::{Hyperelastic, Lame, Mat, Scalar, Tangent};

/// Linear elasticity on the small strain `eps = (F + F^T)/2 - I`:
///
/// ```text
/// psi = mu eps:eps + lambda/2 tr^2(eps),   P = 2 mu eps + lambda tr(eps) I,
/// dP/dF_kl = mu (E_kl + E_lk) + lambda delta_kl I   (constant).
/// ```
///
/// Cheapest model and the only one with a constant tangent, but **not rotation invariant**: a
/// pure rotation `F = Q` gives nonzero stress, so large rotations produce ghost forces and volume
/// growth. Valid for small displacements only.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct LinearElastic;

impl<T: Scalar, const D: usize> Hyperelastic<T, D> for LinearElastic {
    fn energy(&self, lame: &Lame<T>, f: &Mat<T, D>) -> T {
        let eps = small_strain(f);
        let tr = eps.trace();
        lame.mu * eps.dot(&eps) + T::of(0.5) * lame.lambda * tr * tr
    }

    fn pk1(&self, lame: &Lame<T>, f: &Mat<T, D>) -> Mat<T, D> {
        let eps = small_strain(f);
        let tr = eps.trace();
        let mut p = eps * (lame.mu + lame.mu);
        for i in 0..D {
            p[(i, i)] += lame.lambda * tr;
        }
        p
    }

    fn dpdf(&self, lame: &Lame<T>, _f: &Mat<T, D>) -> Tangent<T, D> {
        let mut t = Tangent::zeros();
        for k in 0..D {
            for l in 0..D {
                t.d[k][l] = Mat::<T, D>::from_fn(|i, j| {
                    lame.mu * (delta::<T>(i, k) * delta::<T>(j, l) + delta::<T>(i, l) * delta::<T>(j, k))
                        + lame.lambda * delta::<T>(i, j) * delta::<T>(k, l)
                });
            }
        }
        t
    }
}

/// `eps = (F + F^T)/2 - I`.
fn small_strain<T: Scalar, const D: usize>(f: &Mat<T, D>) -> Mat<T, D> {
    Mat::<T, D>::from_fn(|i, j| T::of(0.5) * (f[(i, j)] + f[(j, i)]) - delta::<T>(i, j))
}
