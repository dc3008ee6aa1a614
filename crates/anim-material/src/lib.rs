//! # anim-material
//!
//! Hyperelastic material models (Sifakis & Barbič 2012; Stomakhin et al. 2012; Smith et al. 2018) shared by the finite element crate (`anim-fem`)
//! and the material point method crate (`anim-mpm`). This crate holds the constitutive laws only:
//! no meshes, no grids, no solvers, so MPM uses the models without pulling in FEM's solvers.
//!
//! Every model is a unit struct implementing [`Hyperelastic`], written once, generic over the
//! scalar `T` (`f32` for MPM particles, `f64` for FEM) and the dimension `D` (2 or 3; other
//! dimensions are a compile-time error), on `nalgebra` fixed-size matrices. Each gives the energy
//! density `psi(F)` per unit rest volume, the first Piola-Kirchhoff stress `P(F) = dpsi/dF` and its
//! derivative `dP/dF`, all analytic and checked against finite differences.
//!
//! ## Which model to pick
//!
//! | model | rotation invariant | `det F <= 0` | compression | `pk1` / `dpdf`, 3D f64 |
//! |---|---|---|---|---|
//! | [`LinearElastic`] | no (ghost forces under rotation) | finite, meaningless | linear | 6 / 67 ns, constant `dP/dF` |
//! | [`StVenantKirchhoff`] | yes | finite, collapses | **softens**: no resistance to strong compression | 20 / 200 ns |
//! | [`CorotatedLinear`] | yes | finite, weak recovery | linear in stretches | 1.6 / 2.3 us (one SVD) |
//! | [`NeoHookean`] | yes | **undefined** (`log J`): `+inf` energy, NaN stress | stiffens, `psi -> inf` as `J -> 0` | 35 / 170 ns |
//! | [`FixedCorotated`] | yes | **defined**, recovers | linear in stretches, `(J-1)^2` volume | 1.8 / 2.3 us (one SVD) |
//! | [`StableNeoHookean`] | yes | **defined**, recovers, smooth | Neo-Hookean-like | 22 / 260 ns (no SVD) |
//!
//! Times are medians per evaluation from `cargo bench -p anim-benches --bench material` (1024
//! random `F`, one core of the shared development machine; compare them as ratios). The two
//! SVD models are dominated by the 3x3 one-sided Jacobi SVD; in 2D the closed-form SVD makes
//! them ~75 ns per `pk1`.
//!
//! - Small deformations only, fastest: [`LinearElastic`].
//! - FEM with large deformation and possibly inverted elements: [`StableNeoHookean`] (smooth
//!   everywhere, no SVD, matches linear elasticity at rest through its Lamé reparameterisation).
//! - FEM where elements never invert and a barrier against inversion is wanted: [`NeoHookean`]
//!   (the solver must treat a non-finite energy as "step too long").
//! - MPM: [`FixedCorotated`] (the snow model of Stomakhin et al. 2013 builds on it).
//! - Locking: all these models are compressible; with `nu -> 0.5` (`lambda >> mu`) linear
//!   tetrahedra lock whatever the model, since the volume term dominates. The `lambda` terms are
//!   `tr^2(eps)` (linear, St. Venant-Kirchhoff, corotated), `log^2 J` (Neo-Hookean) and
//!   `(J - alpha)^2` (fixed corotated, stable Neo-Hookean).
//!
//! For Newton solvers, [`Hyperelastic::dpdf_psd`] gives the positive semi-definite projection of
//! `dP/dF` (analytic eigensystem for the corotated models and stable Neo-Hookean, clamped
//! eigendecomposition of the `D^2 x D^2` matrix otherwise; see [`Tangent::project_psd`]).
//!
//! ## Contract
//!
//! - [`Lame`] holds the Lamé parameters `(mu, lambda)`; [`Lame::from_young_poisson`] rejects
//!   `E <= 0`, `nu` outside `(-1, 0.5)` and non-finite input with a [`MaterialError`].
//! - [`Hyperelastic`] gives the energy density `psi(F)`, the first Piola-Kirchhoff stress
//!   `P(F) = dpsi/dF` and its derivative `dP/dF`, all analytic. The Lamé parameters are passed per
//!   call so that a caller can scale them per element or per particle (MPM snow hardening).
//! - Every model has `psi(I) = 0` and `P(I) = 0`, and linearises at `F = I` to [`LinearElastic`]
//!   with the same Lamé parameters.
//! - No model panics: non-finite `F` gives non-finite output, which the caller detects
//!   (`anim_core::diagnostics`).
//!
//! ## Example
//!
//! ```
//! use anim_material::{FixedCorotated, Hyperelastic, Lame, Mat, NeoHookean, StableNeoHookean};
//!
//! let lame = Lame::<f64>::from_young_poisson(1e5, 0.3)?;
//! // A stretch of 10% along x.
//! let f = Mat::<f64, 3>::new(1.1, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0);
//! let p = Hyperelastic::<f64, 3>::pk1(&StableNeoHookean, &lame, &f);
//! assert!(p[(0, 0)] > 0.0); // tension
//! // An inverted element (reflection): fixed corotated and stable Neo-Hookean push back with a
//! // finite force; Neo-Hookean is undefined there.
//! let inverted = Mat::<f64, 3>::new(-1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0);
//! assert!(FixedCorotated.pk1(&lame, &inverted).iter().all(|x| x.is_finite()));
//! assert!(StableNeoHookean.energy(&lame, &inverted).is_finite());
//! assert!(NeoHookean.energy(&lame, &inverted).is_infinite());
//! // Newton: the stress derivative, projected to be positive semi-definite.
//! let h = FixedCorotated.dpdf_psd(&lame, &f).to_matrix();
//! assert!(h.symmetric_eigenvalues().iter().all(|&e| e >= -1e-9 * h.norm()));
//! # Ok::<(), anim_material::MaterialError>(())
//! ```

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
