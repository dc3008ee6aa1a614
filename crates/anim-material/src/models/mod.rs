//! The hyperelastic models (Sifakis & Barbič 2012; Stomakhin et al. 2012 for fixed corotated)
//! and the stable Neo-Hookean model (Smith et al. 2018).
//!
//! | model | energy density `psi(F)` |
//! |---|---|
//! | [`LinearElastic`] | `mu eps:eps + lambda/2 tr^2(eps)`, `eps = (F + F^T)/2 - I` |
//! | [`StVenantKirchhoff`] | `mu E:E + lambda/2 tr^2(E)`, `E = (F^T F - I)/2` |
//! | [`CorotatedLinear`] | `mu |S - I|^2 + lambda/2 tr^2(S - I)`, `F = R S` |
//! | [`NeoHookean`] | `mu/2 (tr(F^T F) - d) - mu log J + lambda/2 log^2 J` |
//! | [`FixedCorotated`] | `mu |F - R|^2 + lambda/2 (J - 1)^2` |
//! | [`StableNeoHookean`] | `mu'/2 (I_C - d) + lambda'/2 (J - alpha)^2 - mu'/2 log(I_C + 1) - psi_0` |
//!
//! The first four are invariant-based and differentiated directly; the two corotated models
//! are written in principal stretches and differentiated in the rotated frame (module
//! [`principal`]).

mod corotated;
mod linear;
mod neo_hookean;
pub mod principal;
mod stable_neo_hookean;
mod stvk;

pub use corotated::{CorotatedLinear, FixedCorotated};
pub use linear::LinearElastic;
pub use neo_hookean::NeoHookean;
pub use stable_neo_hookean::StableNeoHookean;
pub use stvk::StVenantKirchhoff;

/// `1` when `a == b`, else `0`.
#[inline]
pub(crate) fn delta<T: crate::Scalar>(a: usize, b: usize) -> T {
    if a == b { T::one() } else { T::zero() }
}
