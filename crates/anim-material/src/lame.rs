//! Lamé parameters and their validation.
//!
//! `mu = E / (2 (1 + nu))`, `lambda = E nu / ((1 + nu)(1 - 2 nu))`: the shear modulus and the first
//! Lamé parameter of isotropic linear elasticity, from Young's modulus `E` and Poisson's ratio `nu`.
//! Every model of this crate takes them per call, so a caller can scale them per element or per
//! particle ([`Lame::scaled`], MPM snow hardening).

use crate::Scalar;

/// Bad material parameters.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MaterialError {
    /// Young's modulus must be finite and positive.
    #[error("Young's modulus E = {0} must be finite and > 0")]
    YoungModulus(f64),
    /// Poisson's ratio must lie in the open interval (-1, 0.5).
    #[error("Poisson's ratio nu = {0} must lie in (-1, 0.5)")]
    PoissonRatio(f64),
    /// The shear modulus must be finite and positive.
    #[error("shear modulus mu = {0} must be finite and > 0")]
    ShearModulus(f64),
    /// The first Lamé parameter must be finite and keep the bulk modulus `lambda + 2 mu / 3`
    /// positive.
    #[error("first Lamé parameter lambda = {lambda} must be finite and > -2 mu / 3 (mu = {mu})")]
    FirstLame {
        /// The rejected `lambda`.
        lambda: f64,
        /// The shear modulus it was checked against.
        mu: f64,
    },
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
    /// Lamé parameters from Young's modulus `e` and Poisson's ratio `nu`.
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

    /// Lamé parameters given directly, validated: `mu` finite and positive, `lambda` finite with
    /// a positive bulk modulus `lambda + 2 mu / 3` (the range that `(E, nu)` with `E > 0`,
    /// `-1 < nu < 0.5` maps onto).
    ///
    /// # Errors
    /// [`MaterialError::ShearModulus`] or [`MaterialError::FirstLame`] naming the bad value.
    pub fn new(mu: f64, lambda: f64) -> Result<Self, MaterialError> {
        if !(mu > 0.0) || !mu.is_finite() {
            return Err(MaterialError::ShearModulus(mu));
        }
        if !lambda.is_finite() || !(lambda + 2.0 * mu / 3.0 > 0.0) {
            return Err(MaterialError::FirstLame { lambda, mu });
        }
        Ok(Self { mu: T::of(mu), lambda: T::of(lambda) })
    }

    /// Both parameters multiplied by `s` (MPM snow hardening `exp(xi (1 - J_P))`).
    #[must_use]
    pub fn scaled(self, s: T) -> Self {
        Self { mu: self.mu * s, lambda: self.lambda * s }
    }

    /// Young's modulus `E = mu (3 lambda + 2 mu) / (lambda + mu)`.
    #[must_use]
    pub fn young(&self) -> T {
        self.mu * (T::of(3.0) * self.lambda + T::of(2.0) * self.mu) / (self.lambda + self.mu)
    }

    /// Poisson's ratio `nu = lambda / (2 (lambda + mu))`.
    #[must_use]
    pub fn poisson(&self) -> T {
        self.lambda / (T::of(2.0) * (self.lambda + self.mu))
    }
}
