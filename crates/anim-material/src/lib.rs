//! # anim-material
//!
//! Hyperelastic material models (seed section 5.1) shared by the finite element crate (`anim-fem`)
//! and the material point method crate (`anim-mpm`). This crate holds the constitutive laws only:
//! no meshes, no grids, no solvers, so MPM uses the models without pulling in FEM's solvers.
//!
//! Every model is written once, generic over the scalar `T` (`f32` for MPM particles, `f64` for
//! FEM) and the dimension `D` (2 or 3), on `nalgebra` fixed-size matrices.
//!
//! ## Contract
//!
//! - [`Lame`] holds the Lamé parameters `(mu, lambda)`; [`Lame::from_young_poisson`] rejects
//!   `E <= 0`, `nu` outside `(-1, 0.5)` and non-finite input with a [`MaterialError`].
//! - [`Hyperelastic`] gives the energy density `psi(F)`, the first Piola-Kirchhoff stress
//!   `P(F) = dpsi/dF` and its derivative `dP/dF`, all analytic. The Lamé parameters are passed per
//!   call so that a caller can scale them per element or per particle (MPM snow hardening).

#![forbid(unsafe_code)]

pub use nalgebra;

use anim_core::scalar::Real;
use nalgebra::{RealField, SMatrix};

/// A square `D x D` matrix (deformation gradients, stresses).
pub type Mat<T, const D: usize> = SMatrix<T, D, D>;

/// The scalar types the models run in: `f32` and `f64`.
pub trait Scalar: Real + RealField + Copy {}
impl<T: Real + RealField + Copy> Scalar for T {}

/// Bad material parameters.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MaterialError {
    /// Young's modulus must be finite and positive.
    #[error("Young's modulus E = {0} must be finite and > 0")]
    YoungModulus(f64),
    /// Poisson's ratio must lie in the open interval (-1, 0.5).
    #[error("Poisson's ratio nu = {0} must lie in (-1, 0.5)")]
    PoissonRatio(f64),
}

/// Lamé parameters: shear modulus `mu` and first parameter `lambda`.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Lame<T> {
    /// Shear modulus `mu = E / (2 (1 + nu))`.
    pub mu: T,
    /// First Lamé parameter `lambda = E nu / ((1 + nu)(1 - 2 nu))`.
    pub lambda: T,
}

impl<T: Scalar> Lame<T> {
    /// Lamé parameters from Young's modulus `e` and Poisson's ratio `nu` (seed 5.1).
    ///
    /// # Errors
    /// [`MaterialError`] when `e` is not finite and positive or `nu` is outside `(-1, 0.5)`.
    pub fn from_young_poisson(e: f64, nu: f64) -> Result<Self, MaterialError> {
        if !(e > 0.0) || !e.is_finite() {
            return Err(MaterialError::YoungModulus(e));
        }
        if !(nu > -1.0 && nu < 0.5) {
            return Err(MaterialError::PoissonRatio(nu));
        }
        let mu = e / (2.0 * (1.0 + nu));
        let lambda = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
        Ok(Self { mu: T::of(mu), lambda: T::of(lambda) })
    }

    /// Both parameters multiplied by `s` (MPM snow hardening `exp(xi (1 - J_P))`).
    #[must_use]
    pub fn scaled(self, s: T) -> Self {
        Self { mu: self.mu * s, lambda: self.lambda * s }
    }
}

/// A hyperelastic energy density `psi(F)` with its analytic derivatives.
///
/// `T` is the scalar, `D` the dimension (2 or 3).
pub trait Hyperelastic<T: Scalar, const D: usize>: Send + Sync {
    /// Energy density `psi(F)` per unit rest volume.
    fn energy(&self, lame: &Lame<T>, f: &Mat<T, D>) -> T;
    /// First Piola-Kirchhoff stress `P(F) = dpsi/dF`.
    fn pk1(&self, lame: &Lame<T>, f: &Mat<T, D>) -> Mat<T, D>;
    /// The stress derivative `dP/dF` (the fourth-order elasticity tensor of the model).
    fn dpdf(&self, lame: &Lame<T>, f: &Mat<T, D>) -> Tangent<T, D>;
}

/// The fourth-order tensor `dP/dF`: `d[k][l]` is the `D x D` matrix `dP/dF_kl`, so that for a
/// perturbation `dF`, `dP = sum_kl d[k][l] dF_kl`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tangent<T: Scalar, const D: usize> {
    /// `d[k][l] = dP / dF_kl`.
    pub d: [[Mat<T, D>; D]; D],
}

impl<T: Scalar, const D: usize> Tangent<T, D> {
    /// The directional derivative `dP[dF] = sum_kl d[k][l] dF_kl`.
    #[must_use]
    pub fn apply(&self, df: &Mat<T, D>) -> Mat<T, D> {
        let mut out = Mat::<T, D>::zeros();
        for k in 0..D {
            for l in 0..D {
                out += self.d[k][l] * df[(k, l)];
            }
        }
        out
    }
}

impl<T: Scalar> Tangent<T, 3> {
    /// The tensor as a 9 x 9 matrix on column-major `vec(F)` (`vec(F)[k + 3 l] = F_kl`):
    /// `vec(dP) = M vec(dF)`.
    #[must_use]
    pub fn to_matrix(&self) -> SMatrix<T, 9, 9> {
        let mut m = SMatrix::<T, 9, 9>::zeros();
        for k in 0..3 {
            for l in 0..3 {
                let col = k + 3 * l;
                for i in 0..3 {
                    for j in 0..3 {
                        m[(i + 3 * j, col)] = self.d[k][l][(i, j)];
                    }
                }
            }
        }
        m
    }
}

impl<T: Scalar> Tangent<T, 2> {
    /// The tensor as a 4 x 4 matrix on column-major `vec(F)` (`vec(F)[k + 2 l] = F_kl`):
    /// `vec(dP) = M vec(dF)`.
    #[must_use]
    pub fn to_matrix(&self) -> SMatrix<T, 4, 4> {
        let mut m = SMatrix::<T, 4, 4>::zeros();
        for k in 0..2 {
            for l in 0..2 {
                let col = k + 2 * l;
                for i in 0..2 {
                    for j in 0..2 {
                        m[(i + 2 * j, col)] = self.d[k][l][(i, j)];
                    }
                }
            }
        }
        m
    }
}
