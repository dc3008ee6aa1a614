//! The corotated models: linear elasticity in the rotated frame (Sifakis & Barbič 2012) and fixed corotated
//! (Stomakhin, Howes, Schroeder & Teran, *Energetically consistent invertible elasticity*, SCA
//! 2012).

use super::principal::{self, PrincipalEnergy, all_but, clamp_sum, other};
use crate::decomposition::svd;
use crate::{Hyperelastic, Lame, Mat, Scalar, Tangent};
use nalgebra::SVector;

/// Corotated linear elasticity (Sifakis & Barbič 2012): with the polar decomposition `F = R S`,
///
/// ```text
/// psi = mu |S - I|^2 + lambda/2 tr^2(S - I) = mu sum (sigma_i - 1)^2 + lambda/2 (sum sigma_i - d)^2,
/// P   = 2 mu (F - R) + lambda tr(R^T F - I) R.
/// ```
///
/// Rotation invariant, quadratic in the stretches (no stiffening), one SVD per evaluation.
/// `dP/dF` is the exact derivative including `dR/dF` (module [`principal`]), not the
/// "warped stiffness" `R C R^T`. Under inversion the rotation-variant SVD keeps `R` a rotation
/// and `S` indefinite; the volume term `tr(S - I)` is weak there (a fully inverted element can
/// have `tr S = d`), so the model does not reliably recover from inversion: prefer
/// [`FixedCorotated`].
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct CorotatedLinear;

/// Fixed corotated (Stomakhin et al. 2012), with `J = det F = prod sigma_i`:
///
/// ```text
/// psi = mu |F - R|^2 + lambda/2 (J - 1)^2 = mu sum (sigma_i - 1)^2 + lambda/2 (J - 1)^2,
/// P   = 2 mu (F - R) + lambda (J - 1) J F^{-T} = 2 mu (F - R) + lambda (J - 1) cof F.
/// ```
///
/// Rotation invariant and **defined for every `F`**: through `det F = 0` and under inversion the
/// volume term pushes `J` back to 1 with a finite force. One SVD per evaluation. The tangent is
/// discontinuous only where `R` is (`sigma_{d-1} = -sigma_{d-2}`, see [`principal`]). The
/// standard choice for MPM.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct FixedCorotated;

impl<T: Scalar, const D: usize> PrincipalEnergy<T, D> for CorotatedLinear {
    fn psi_hat(&self, mu: T, lambda: T, s: &SVector<T, D>) -> T {
        let mut sq = T::zero();
        let mut tr = -T::of(D as f64);
        for i in 0..D {
            sq += (s[i] - T::one()) * (s[i] - T::one());
            tr += s[i];
        }
        mu * sq + T::of(0.5) * lambda * tr * tr
    }

    fn gradient(&self, mu: T, lambda: T, s: &SVector<T, D>) -> SVector<T, D> {
        let tr = s.sum() - T::of(D as f64);
        SVector::<T, D>::from_fn(|i, _| (mu + mu) * (s[i] - T::one()) + lambda * tr)
    }

    fn hessian(&self, mu: T, lambda: T, _s: &SVector<T, D>) -> Mat<T, D> {
        Mat::<T, D>::from_fn(|i, j| if i == j { mu + mu + lambda } else { lambda })
    }

    fn twist(&self, mu: T, _lambda: T, _s: &SVector<T, D>, _i: usize, _j: usize) -> T {
        mu + mu
    }

    fn flip(&self, mu: T, lambda: T, s: &SVector<T, D>, i: usize, j: usize) -> T {
        let tr = s.sum() - T::of(D as f64);
        let two = T::of(2.0);
        two * mu + (two * lambda * tr - two * two * mu) / clamp_sum(s[i] + s[j])
    }
}

impl<T: Scalar, const D: usize> PrincipalEnergy<T, D> for FixedCorotated {
    fn psi_hat(&self, mu: T, lambda: T, s: &SVector<T, D>) -> T {
        let mut sq = T::zero();
        let mut j = T::one();
        for i in 0..D {
            sq += (s[i] - T::one()) * (s[i] - T::one());
            j *= s[i];
        }
        mu * sq + T::of(0.5) * lambda * (j - T::one()) * (j - T::one())
    }

    fn gradient(&self, mu: T, lambda: T, s: &SVector<T, D>) -> SVector<T, D> {
        let j = s.product();
        SVector::<T, D>::from_fn(|i, _| {
            (mu + mu) * (s[i] - T::one()) + lambda * (j - T::one()) * all_but(s, i)
        })
    }

    fn hessian(&self, mu: T, lambda: T, s: &SVector<T, D>) -> Mat<T, D> {
        let j = s.product();
        Mat::<T, D>::from_fn(|a, b| {
            if a == b {
                let p = all_but(s, a);
                mu + mu + lambda * p * p
            } else {
                lambda * all_but(s, a) * all_but(s, b) + lambda * (j - T::one()) * other(s, a, b)
            }
        })
    }

    fn twist(&self, mu: T, lambda: T, s: &SVector<T, D>, i: usize, j: usize) -> T {
        // (prod_{k != i} - prod_{k != j}) / (sigma_i - sigma_j) = -prod_{k != i, j}.
        mu + mu - lambda * (s.product() - T::one()) * other(s, i, j)
    }

    fn flip(&self, mu: T, lambda: T, s: &SVector<T, D>, i: usize, j: usize) -> T {
        let two = T::of(2.0);
        two * mu + lambda * (s.product() - T::one()) * other(s, i, j)
            - two * two * mu / clamp_sum(s[i] + s[j])
    }
}

macro_rules! principal_model {
    ($ty:ty) => {
        impl<T: Scalar, const D: usize> Hyperelastic<T, D> for $ty {
            fn energy(&self, lame: &Lame<T>, f: &Mat<T, D>) -> T {
                self.psi_hat(lame.mu, lame.lambda, &svd(f).sigma)
            }

            fn pk1(&self, lame: &Lame<T>, f: &Mat<T, D>) -> Mat<T, D> {
                principal::pk1(self, lame.mu, lame.lambda, f)
            }

            fn dpdf(&self, lame: &Lame<T>, f: &Mat<T, D>) -> Tangent<T, D> {
                principal::dpdf(self, lame.mu, lame.lambda, f)
            }

            fn dpdf_psd(&self, lame: &Lame<T>, f: &Mat<T, D>) -> Tangent<T, D> {
                principal::dpdf_psd(self, lame.mu, lame.lambda, f)
            }

            fn energy_pk1_dpdf(&self, lame: &Lame<T>, f: &Mat<T, D>) -> (T, Mat<T, D>, Tangent<T, D>) {
                principal::energy_pk1_dpdf(self, lame.mu, lame.lambda, f)
            }
        }
    };
}

principal_model!(CorotatedLinear);
principal_model!(FixedCorotated);
