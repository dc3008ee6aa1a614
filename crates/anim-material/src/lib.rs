#![doc = include_str!("../README.md")]
#![forbid(unsafe_code)]

pub use nalgebra;

#[cfg(feature = "cases")]
pub mod cases;
pub mod decomposition;
mod lame;
pub mod models;
mod tangent;

pub use decomposition::{Svd, polar, svd, svd2, svd3};
pub use lame::{Lame, MaterialError};
pub use models::{
    CorotatedLinear, FixedCorotated, LinearElastic, NeoHookean, StVenantKirchhoff, StableNeoHookean,
};
pub use tangent::Tangent;

/// anim-core, the math and contracts this crate builds on: its `glam`, integrators and scene
/// traits, without a dependency of your own.
pub use anim_core;
/// The trait whose `step` advances this crate's simulations.
pub use anim_core::solver::Solver;

use anim_core::scalar::Real;
use nalgebra::{RealField, SMatrix};

/// A square `D x D` matrix (deformation gradients, stresses).
pub type Mat<T, const D: usize> = SMatrix<T, D, D>;

/// The scalar types the models run in: `f32` and `f64`.
pub trait Scalar: Real + RealField + Copy {}
impl<T: Real + RealField + Copy> Scalar for T {}

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
    /// `dP/dF` projected onto positive semi-definite tensors (for Newton's method). The default
    /// clamps the eigenvalues of the flattened tensor ([`Tangent::project_psd`]); models with a
    /// known eigensystem override it with the cheaper analytic projection.
    fn dpdf_psd(&self, lame: &Lame<T>, f: &Mat<T, D>) -> Tangent<T, D> {
        self.dpdf(lame, f).project_psd()
    }
    /// Energy, stress and stress derivative together (what a Newton iteration needs). The SVD
    /// models override it to decompose `F` once instead of three times.
    fn energy_pk1_dpdf(&self, lame: &Lame<T>, f: &Mat<T, D>) -> (T, Mat<T, D>, Tangent<T, D>) {
        (self.energy(lame, f), self.pk1(lame, f), self.dpdf(lame, f))
    }
}

#[cfg(any(test, feature = "cases"))]
mod samples;
#[cfg(test)]
mod tests;
