//! Hencky elasticity: the St. Venant-Kirchhoff energy written in the logarithmic (Hencky)
//! strain, the elastic part of sand (Klár, Gast, Pradhana, Fu, Schroeder, Jiang & Teran,
//! *Drucker-Prager elastoplasticity for sand animation*, SIGGRAPH 2016).
//!
//! With the singular value decomposition `F = U diag(sigma) V^T` and the log strain
//! `eps = log sigma` (each `sigma_i` taken at least `SIGMA_MIN`):
//!
//! ```text
//! psi(F) = mu |eps|^2 + lambda/2 tr(eps)^2
//! tau    = P F^T = U diag(2 mu eps + lambda tr(eps)) U^T
//! ```
//!
//! The energy depends on `F` through its singular values only (isotropy), and the Kirchhoff
//! stress is diagonal in the left singular vectors. Sand's return map (`plasticity`) projects
//! the same log strain onto the Drucker-Prager cone.

use crate::{Mat, Vector};
use anim_material::{Lame, svd};

/// `U diag(s)`.
#[inline]
pub(crate) fn scale_columns<const D: usize>(u: &Mat<D>, s: &Vector<D>) -> Mat<D> {
    Mat::<D>::from_fn(|i, j| u[(i, j)] * s[j])
}

/// Smallest singular value treated as positive in the log strain.
pub(crate) const SIGMA_MIN: f32 = 1e-4;

/// Hencky Kirchhoff stress `tau = U diag(2 mu eps + lambda tr(eps)) U^T`, `eps = log sigma`.
pub(crate) fn hencky_kirchhoff<const D: usize>(lame: &Lame<f32>, f: &Mat<D>) -> Mat<D> {
    let s = svd(f);
    let mut eps = Vector::<D>::zeros();
    for i in 0..D {
        eps[i] = s.sigma[i].max(SIGMA_MIN).ln();
    }
    let tr = eps.sum();
    let t = eps.map(|e| 2.0 * lame.mu * e + lame.lambda * tr);
    scale_columns(&s.u, &t) * s.u.transpose()
}

/// Hencky energy density `mu |eps|^2 + lambda/2 tr(eps)^2`.
pub(crate) fn hencky_energy<const D: usize>(lame: &Lame<f32>, f: &Mat<D>) -> f32 {
    let s = svd(f);
    let mut eps = Vector::<D>::zeros();
    for i in 0..D {
        eps[i] = s.sigma[i].max(SIGMA_MIN).ln();
    }
    let tr = eps.sum();
    lame.mu * eps.norm_squared() + 0.5 * lame.lambda * tr * tr
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hencky_stress_is_energy_derivative() {
        // tau = P F^T with P = dpsi/dF; check P by central differences of psi.
        let lame = Lame { mu: 3.0f32, lambda: 2.0 };
        let f = Mat::<2>::new(1.1, 0.2, -0.1, 0.9);
        let tau = hencky_kirchhoff(&lame, &f);
        let mut p = Mat::<2>::zeros();
        let h = 1e-3f32;
        for i in 0..2 {
            for j in 0..2 {
                let mut a = f;
                let mut b = f;
                a[(i, j)] += h;
                b[(i, j)] -= h;
                p[(i, j)] = (hencky_energy(&lame, &a) - hencky_energy(&lame, &b)) / (2.0 * h);
            }
        }
        let tau_fd = p * f.transpose();
        assert!((tau - tau_fd).norm() < 2e-3 * tau.norm().max(1.0), "{tau} vs {tau_fd}");
    }
}
