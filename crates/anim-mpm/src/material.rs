//! Materials: what a particle is made of and the Kirchhoff stress `tau = P F^T` it exerts.
//!
//! | material | elastic part | plasticity ([`plasticity`](crate::plasticity)) |
//! | --- | --- | --- |
//! | [`Material::Elastic`] | shared [`FixedCorotated`] or [`NeoHookean`] (`anim-material`) | none |
//! | [`Material::Snow`] | shared [`FixedCorotated`] on `F_E`, Lamé parameters hardened by `exp(xi (1 - J_P))` | singular values of `F_E` clamped to `[1 - theta_c, 1 + theta_s]` (Stomakhin et al. 2013) |
//! | [`Material::Fluid`] | weakly compressible: `p(J) = K/gamma (J^-gamma - 1)`, `tau = -p J I` | `F` reset to `J^(1/d) I` (no shear memory) |
//! | [`Material::Sand`] | Hencky (St. Venant-Kirchhoff in log strain, [`hencky`]): `tau = U (2 mu eps + lambda tr(eps) I) U^T` | Drucker-Prager return map with hardening (Klár et al. 2016) |
//!
//! The MLS-MPM momentum (Hu et al. 2018) needs `V_p^0 P(F_p) F_p^T`, the Kirchhoff stress times
//! the rest volume, and APIC's grid force `f_i = -sum_p V_p^0 P F_p^T grad w_ip` needs the same
//! product, so this module computes exactly that (`kirchhoff`).

use crate::hencky;
use crate::{Mat, MpmError};
use anim_material::{FixedCorotated, Hyperelastic, Lame, NeoHookean};
use serde::{Deserialize, Serialize};

/// The hyperelastic model of an elastic body (both from `anim-material`); `"fixed-corotated"`
/// or `"neo-hookean"` in scene files.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ElasticModel {
    /// Fixed corotated (Stomakhin et al. 2012), the MPM standard; the default.
    #[default]
    FixedCorotated,
    /// Compressible Neo-Hookean (undefined for `det F <= 0`).
    NeoHookean,
}

/// An elastic body (jelly).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Elastic {
    /// Energy model; default fixed corotated.
    pub model: ElasticModel,
    /// Young's modulus `E` (Pa); default `1e4`.
    pub young: f64,
    /// Poisson's ratio; default `0.2`.
    pub poisson: f64,
    /// Rest density (kg / m^D); default `1000`.
    pub density: f64,
}

impl Default for Elastic {
    fn default() -> Self {
        Self { model: ElasticModel::FixedCorotated, young: 1e4, poisson: 0.2, density: 1000.0 }
    }
}

/// Snow (Stomakhin et al. 2013).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Snow {
    /// Young's modulus `E_0`; default `1e4`.
    pub young: f64,
    /// Poisson's ratio; default `0.2`.
    pub poisson: f64,
    /// Critical compression `theta_c`; default `2.5e-2`.
    pub theta_c: f64,
    /// Critical stretch `theta_s`; default `7.5e-3`.
    pub theta_s: f64,
    /// Hardening coefficient `xi`; default `10`.
    pub hardening: f64,
    /// Rest density; default `400`.
    pub density: f64,
}

impl Default for Snow {
    fn default() -> Self {
        Self { young: 1e4, poisson: 0.2, theta_c: 2.5e-2, theta_s: 7.5e-3, hardening: 10.0, density: 400.0 }
    }
}

/// A weakly compressible fluid with the `J`-based equation of state
/// `p(J) = K / gamma (J^-gamma - 1)` (bulk modulus `K` at rest for every `gamma`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Fluid {
    /// Bulk modulus `K` (Pa); default `1e4`.
    pub bulk: f64,
    /// Exponent `gamma`; default `1` (then `tau = K (J - 1) I`, the `mpm88` fluid); 7 is Tait's.
    pub gamma: f64,
    /// Rest density; default `1000`.
    pub density: f64,
}

impl Default for Fluid {
    fn default() -> Self {
        Self { bulk: 1e4, gamma: 1.0, density: 1000.0 }
    }
}

/// Sand: Hencky elasticity with Drucker-Prager plasticity and hardening (Klár, Gast, Pradhana,
/// Fu, Schroeder, Jiang & Teran, *Drucker-Prager elastoplasticity for sand animation*, SIGGRAPH
/// 2016): friction angle `phi_F = h0 + (h1 q - h3) exp(-h2 q)` degrees.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Sand {
    /// Young's modulus; default `3.537e5` (Klár et al.).
    pub young: f64,
    /// Poisson's ratio; default `0.3`.
    pub poisson: f64,
    /// Hardening parameters `h0, h1, h2, h3` (degrees, degrees, -, degrees); default
    /// `35, 9, 0.2, 10`.
    pub hardening: [f64; 4],
    /// Rest density; default `2200`.
    pub density: f64,
}

impl Default for Sand {
    fn default() -> Self {
        Self { young: 3.537e5, poisson: 0.3, hardening: [35.0, 9.0, 0.2, 10.0], density: 2200.0 }
    }
}

/// A material of the material table. In a scene file (a body's `material`) it is spelled by
/// its kind with its parameters, each defaulting to the value its doc states:
/// `{ elastic = { young = 2e4, poisson = 0.3 } }`, `{ snow = {} }`,
/// `{ fluid = { bulk = 1e5 } }`, `{ sand = { density = 1600.0 } }`; an unknown field is refused.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case", deny_unknown_fields)]
pub enum Material {
    /// Elastic body.
    Elastic(Elastic),
    /// Snow.
    Snow(Snow),
    /// Weakly compressible fluid.
    Fluid(Fluid),
    /// Sand.
    Sand(Sand),
}

impl Material {
    /// Rest density.
    #[must_use]
    pub fn density(&self) -> f64 {
        match self {
            Material::Elastic(m) => m.density,
            Material::Snow(m) => m.density,
            Material::Fluid(m) => m.density,
            Material::Sand(m) => m.density,
        }
    }

    /// Checks the parameters and converts them to the form the step uses.
    pub(crate) fn compile(&self, index: usize) -> Result<Compiled, MpmError> {
        let bad = |field: &'static str, reason: String| MpmError::BadMaterial { index, field, reason };
        let positive = |field: &'static str, v: f64| {
            if v > 0.0 && v.is_finite() {
                Ok(())
            } else {
                Err(bad(field, format!("{v} must be finite and > 0")))
            }
        };
        positive("density", self.density())?;
        let lame = |e: f64, nu: f64| {
            let l =
                Lame::<f32>::from_young_poisson(e, nu).map_err(|e| bad("young/poisson", e.to_string()))?;
            if l.mu.is_finite() && l.lambda.is_finite() {
                Ok(l)
            } else {
                Err(bad(
                    "young/poisson",
                    format!("Young's modulus {e} with Poisson's ratio {nu} overflows f32"),
                ))
            }
        };
        let mut c = Compiled {
            kind: Kind::Fluid,
            lame: Lame { mu: 0.0, lambda: 0.0 },
            theta_c: 0.0,
            theta_s: 0.0,
            xi: 0.0,
            bulk: 0.0,
            gamma: 1.0,
            sand: [0.0; 4],
            density: self.density() as f32,
        };
        match *self {
            Material::Elastic(m) => {
                c.kind = match m.model {
                    ElasticModel::FixedCorotated => Kind::FixedCorotated,
                    ElasticModel::NeoHookean => Kind::NeoHookean,
                };
                c.lame = lame(m.young, m.poisson)?;
            }
            Material::Snow(m) => {
                c.kind = Kind::Snow;
                c.lame = lame(m.young, m.poisson)?;
                if !(m.theta_c > 0.0 && m.theta_c < 1.0) {
                    return Err(bad("theta_c", format!("{} must lie in (0, 1)", m.theta_c)));
                }
                positive("theta_s", m.theta_s)?;
                if !(m.hardening >= 0.0) || !m.hardening.is_finite() {
                    return Err(bad("hardening", format!("{} must be finite and >= 0", m.hardening)));
                }
                c.theta_c = m.theta_c as f32;
                c.theta_s = m.theta_s as f32;
                c.xi = m.hardening as f32;
            }
            Material::Fluid(m) => {
                c.kind = Kind::Fluid;
                positive("bulk", m.bulk)?;
                positive("gamma", m.gamma)?;
                c.bulk = m.bulk as f32;
                c.gamma = m.gamma as f32;
            }
            Material::Sand(m) => {
                c.kind = Kind::Sand;
                c.lame = lame(m.young, m.poisson)?;
                for (i, h) in m.hardening.iter().enumerate() {
                    if !h.is_finite() || *h < 0.0 {
                        return Err(bad("hardening", format!("h{i} = {h} must be finite and >= 0")));
                    }
                }
                if m.hardening[0] >= 90.0 {
                    return Err(bad(
                        "hardening",
                        format!("h0 = {} degrees must be below 90", m.hardening[0]),
                    ));
                }
                c.sand = m.hardening.map(|h| h as f32);
            }
        }
        Ok(c)
    }
}

/// Material kind, for the per-particle dispatch.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Kind {
    FixedCorotated,
    NeoHookean,
    Snow,
    Fluid,
    Sand,
}

/// A validated material in the step's precision.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Compiled {
    pub kind: Kind,
    pub lame: Lame<f32>,
    pub theta_c: f32,
    pub theta_s: f32,
    pub xi: f32,
    pub bulk: f32,
    pub gamma: f32,
    pub sand: [f32; 4],
    pub density: f32,
}

impl Compiled {
    /// Snow's hardened Lamé parameters `exp(xi (1 - J_P)) (mu_0, lambda_0)`.
    #[inline]
    pub fn hardened(&self, jp: f32) -> Lame<f32> {
        self.lame.scaled((self.xi * (1.0 - jp)).exp())
    }

    /// Fluid pressure `p(J) = K/gamma (J^-gamma - 1)`.
    #[inline]
    pub fn pressure(&self, j: f32) -> f32 {
        if self.gamma == 1.0 {
            self.bulk * (1.0 / j - 1.0)
        } else {
            self.bulk / self.gamma * (j.powf(-self.gamma) - 1.0)
        }
    }

    /// Squared speed of the fastest elastic wave, `(lambda + 2 mu) / rho` (hardened for snow;
    /// the tangent bulk modulus for fluids).
    #[inline]
    pub fn wave_speed2(&self, jp: f32, j: f32) -> f32 {
        match self.kind {
            Kind::Fluid => {
                let j = j.max(1e-3);
                let jg = if self.gamma == 1.0 { 1.0 / j } else { j.powf(-self.gamma) };
                self.bulk * jg / self.density
            }
            Kind::Snow => {
                let l = self.hardened(jp);
                (l.lambda + 2.0 * l.mu) / self.density
            }
            _ => (self.lame.lambda + 2.0 * self.lame.mu) / self.density,
        }
    }
}

/// The Kirchhoff stress `tau = P(F) F^T` of a particle (`f` is `F`, or `F_E` for snow and
/// sand; `plastic` the plastic scalar).
#[inline(always)]
pub(crate) fn kirchhoff<const D: usize>(m: &Compiled, f: &Mat<D>, plastic: f32) -> Mat<D> {
    match m.kind {
        Kind::FixedCorotated => FixedCorotated.pk1(&m.lame, f) * f.transpose(),
        Kind::NeoHookean => NeoHookean.pk1(&m.lame, f) * f.transpose(),
        Kind::Snow => FixedCorotated.pk1(&m.hardened(plastic), f) * f.transpose(),
        Kind::Fluid => {
            let j = anim_material::decomposition::determinant(f);
            Mat::<D>::identity() * (-m.pressure(j) * j)
        }
        Kind::Sand => hencky::hencky_kirchhoff(&m.lame, f),
    }
}

/// Elastic energy density `psi` per unit rest volume.
pub(crate) fn energy<const D: usize>(m: &Compiled, f: &Mat<D>, plastic: f32) -> f32 {
    match m.kind {
        Kind::FixedCorotated => FixedCorotated.energy(&m.lame, f),
        Kind::NeoHookean => NeoHookean.energy(&m.lame, f),
        Kind::Snow => FixedCorotated.energy(&m.hardened(plastic), f),
        Kind::Fluid => {
            // psi(J) = -int_1^J p(s) ds.
            let j = anim_material::decomposition::determinant(f);
            let (k, g) = (m.bulk, m.gamma);
            if g == 1.0 {
                k * ((j - 1.0) - j.ln())
            } else {
                k / g * ((j - 1.0) - (j.powf(1.0 - g) - 1.0) / (1.0 - g))
            }
        }
        Kind::Sand => hencky::hencky_energy(&m.lame, f),
    }
}
