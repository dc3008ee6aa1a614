//! The constitutive models a body can use (from `anim-material`), chosen at run time.
//!
//! The models themselves live in `anim-material` (shared with the material point method); this
//! module names them with [`MaterialModel`], dispatches to them, and bundles a model with its
//! parameters ([`Material`]).

use crate::error::FemError;
use anim_material::nalgebra::{Matrix3, SMatrix};
use anim_material::{
    CorotatedLinear, FixedCorotated, Hyperelastic, Lame, LinearElastic, NeoHookean, StVenantKirchhoff,
    StableNeoHookean, Tangent,
};
use serde::{Deserialize, Serialize};

/// The hyperelastic energy density of a body.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum MaterialModel {
    /// Linear (small-strain) elasticity: not rotation invariant, for small displacements only.
    Linear,
    /// Saint Venant-Kirchhoff: Green strain, softens and collapses under compression.
    StVenantKirchhoff,
    /// Corotated linear elasticity (rotation from the polar decomposition, frozen in `dP/dF`).
    CorotatedLinear,
    /// Compressible Neo-Hookean with `ln J`: undefined for inverted elements (`det F <= 0`).
    NeoHookean,
    /// Fixed corotated (Stomakhin et al. 2012): defined under inversion.
    FixedCorotated,
    /// Stable Neo-Hookean (Smith, de Goes & Kim 2018): defined under inversion.
    StableNeoHookean,
}

impl MaterialModel {
    /// Every model, in a fixed order.
    pub const ALL: [MaterialModel; 6] = [
        MaterialModel::Linear,
        MaterialModel::StVenantKirchhoff,
        MaterialModel::CorotatedLinear,
        MaterialModel::NeoHookean,
        MaterialModel::FixedCorotated,
        MaterialModel::StableNeoHookean,
    ];

    /// The name used in scene files and reports.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            MaterialModel::Linear => "linear",
            MaterialModel::StVenantKirchhoff => "st-venant-kirchhoff",
            MaterialModel::CorotatedLinear => "corotated-linear",
            MaterialModel::NeoHookean => "neo-hookean",
            MaterialModel::FixedCorotated => "fixed-corotated",
            MaterialModel::StableNeoHookean => "stable-neo-hookean",
        }
    }

    /// Energy density `psi(F)`.
    #[inline]
    #[must_use]
    pub fn energy(self, lame: &Lame<f64>, f: &Matrix3<f64>) -> f64 {
        match self {
            MaterialModel::Linear => LinearElastic.energy(lame, f),
            MaterialModel::StVenantKirchhoff => StVenantKirchhoff.energy(lame, f),
            MaterialModel::CorotatedLinear => CorotatedLinear.energy(lame, f),
            MaterialModel::NeoHookean => NeoHookean.energy(lame, f),
            MaterialModel::FixedCorotated => FixedCorotated.energy(lame, f),
            MaterialModel::StableNeoHookean => StableNeoHookean.energy(lame, f),
        }
    }

    /// First Piola-Kirchhoff stress `P(F)`.
    #[inline]
    #[must_use]
    pub fn pk1(self, lame: &Lame<f64>, f: &Matrix3<f64>) -> Matrix3<f64> {
        match self {
            MaterialModel::Linear => LinearElastic.pk1(lame, f),
            MaterialModel::StVenantKirchhoff => StVenantKirchhoff.pk1(lame, f),
            MaterialModel::CorotatedLinear => CorotatedLinear.pk1(lame, f),
            MaterialModel::NeoHookean => NeoHookean.pk1(lame, f),
            MaterialModel::FixedCorotated => FixedCorotated.pk1(lame, f),
            MaterialModel::StableNeoHookean => StableNeoHookean.pk1(lame, f),
        }
    }

    /// The stress derivative `dP/dF`.
    #[inline]
    #[must_use]
    pub fn dpdf(self, lame: &Lame<f64>, f: &Matrix3<f64>) -> Tangent<f64, 3> {
        match self {
            MaterialModel::Linear => LinearElastic.dpdf(lame, f),
            MaterialModel::StVenantKirchhoff => StVenantKirchhoff.dpdf(lame, f),
            MaterialModel::CorotatedLinear => CorotatedLinear.dpdf(lame, f),
            MaterialModel::NeoHookean => NeoHookean.dpdf(lame, f),
            MaterialModel::FixedCorotated => FixedCorotated.dpdf(lame, f),
            MaterialModel::StableNeoHookean => StableNeoHookean.dpdf(lame, f),
        }
    }

    /// The 9 x 9 tangent on column-major `vec(F)`, projected to positive semi-definite when
    /// `project` is set. A tangent that is already positive definite (a 9 x 9 Cholesky
    /// factorisation succeeds, the common case near rest) is returned as is, which skips the
    /// eigendecomposition of the projection; the result is the same.
    #[inline]
    #[must_use]
    pub fn tangent_matrix(self, lame: &Lame<f64>, f: &Matrix3<f64>, project: bool) -> SMatrix<f64, 9, 9> {
        let c = self.dpdf(lame, f).to_matrix();
        if !project || c.cholesky().is_some() {
            return c;
        }
        self.dpdf_psd(lame, f).to_matrix()
    }

    /// `dP/dF` projected to positive semi-definite (anim-material's projection: analytic where
    /// the model's eigensystem is known, eigenvalue clamping otherwise).
    #[inline]
    #[must_use]
    pub fn dpdf_psd(self, lame: &Lame<f64>, f: &Matrix3<f64>) -> Tangent<f64, 3> {
        match self {
            MaterialModel::Linear => LinearElastic.dpdf_psd(lame, f),
            MaterialModel::StVenantKirchhoff => StVenantKirchhoff.dpdf_psd(lame, f),
            MaterialModel::CorotatedLinear => CorotatedLinear.dpdf_psd(lame, f),
            MaterialModel::NeoHookean => NeoHookean.dpdf_psd(lame, f),
            MaterialModel::FixedCorotated => FixedCorotated.dpdf_psd(lame, f),
            MaterialModel::StableNeoHookean => StableNeoHookean.dpdf_psd(lame, f),
        }
    }
}

/// A model with its parameters.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Material {
    /// The energy density.
    pub model: MaterialModel,
    /// Lamé parameters.
    pub lame: Lame<f64>,
    /// Mass density (per unit rest volume).
    pub density: f64,
}

impl Material {
    /// A material from Young's modulus `young`, Poisson's ratio `poisson` and `density`.
    ///
    /// # Errors
    /// [`FemError::Material`] for `E <= 0` or `nu` outside `(-1, 0.5)`;
    /// [`FemError::BadParameter`] for a density that is not finite and positive.
    pub fn new(model: MaterialModel, young: f64, poisson: f64, density: f64) -> Result<Self, FemError> {
        let lame = Lame::from_young_poisson(young, poisson)?;
        if !(density > 0.0) || !density.is_finite() {
            return Err(FemError::BadParameter {
                name: "density",
                value: density,
                reason: "must be finite and > 0",
            });
        }
        Ok(Self { model, lame, density })
    }
}
