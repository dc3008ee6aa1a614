//! Plasticity: the return maps applied to a particle's deformation gradient after its update
//! `F <- (I + dt grad v) F`.
//!
//! **Snow** (Stomakhin, Schroeder, Chai, Teran & Selle, *A material point method
//! for snow simulation*, SIGGRAPH 2013). With `F = F_E F_P`, the trial elastic part
//! `F_E^ = F^{n+1} (F_P^n)^-1` (in practice `(I + dt grad v) F_E^n`) is decomposed
//! `F_E^ = U diag(sigma^) V^T`, its singular values clamped to `[1 - theta_c, 1 + theta_s]`,
//! `F_E = U diag(sigma) V^T`, and the rest goes to the plastic part,
//! `F_P^{n+1} = F_E^-1 F^{n+1}`. Only `J_P = det F_P` enters the hardening `exp(xi (1 - J_P))`, so it is all
//! that is stored: `J_P^{n+1} = J_P^n prod sigma^_i / prod sigma_i`.
//!
//! **Fluid.** A weakly compressible fluid has no shear memory: after the update only
//! `J = det F` is kept, `F <- J^(1/d) I`.
//!
//! **Sand** (Klár et al. 2016, section 7.3). In log-strain space `eps = log sigma`, with
//! `eps^ = eps - tr(eps)/d` and the Drucker-Prager cone of friction coefficient
//! `alpha = sqrt(2/3) 2 sin(phi_F) / (3 - sin(phi_F))`:
//!
//! ```text
//! tr(eps) > 0 (tension)                   -> sigma = 1 (no cohesion), dq = |eps|
//! dgamma = |eps^| + (d lambda + 2 mu)/(2 mu) tr(eps) alpha <= 0  -> inside the cone, unchanged
//! otherwise                               -> eps <- eps - dgamma eps^/|eps^|, dq = dgamma
//! ```
//!
//! and the hardening state `q += dq` raises the friction angle `phi_F = h0 + (h1 q - h3) e^{-h2 q}`.
//! The elastic part of sand, in the same log strain, is [`hencky`](crate::hencky).

use crate::hencky::{SIGMA_MIN, scale_columns};
use crate::material::{Compiled, Kind};
use crate::{Mat, Vector};
use anim_material::{Lame, svd};

/// Applies the material's return map to `f` (the elastic deformation gradient) and its plastic
/// scalar.
#[inline(always)]
pub(crate) fn project<const D: usize>(m: &Compiled, f: &mut Mat<D>, plastic: &mut f32) {
    match m.kind {
        Kind::FixedCorotated | Kind::NeoHookean => {}
        Kind::Snow => snow(m.theta_c, m.theta_s, f, plastic),
        Kind::Fluid => {
            let j = anim_material::decomposition::determinant(f);
            let s = if D == 2 { j.sqrt() } else { j.cbrt() };
            *f = Mat::<D>::identity() * s;
        }
        Kind::Sand => sand(&m.lame, &m.sand, f, plastic),
    }
}

/// Snow: clamps the singular values of `F_E` to `[1 - theta_c, 1 + theta_s]` and moves the
/// excess volume change to `J_P`.
#[inline]
pub(crate) fn snow<const D: usize>(theta_c: f32, theta_s: f32, f: &mut Mat<D>, jp: &mut f32) {
    let s = svd(f);
    let mut ratio = 1.0;
    let mut sigma = s.sigma;
    for i in 0..D {
        let c = sigma[i].clamp(1.0 - theta_c, 1.0 + theta_s);
        ratio *= sigma[i] / c;
        sigma[i] = c;
    }
    *jp *= ratio;
    *f = scale_columns(&s.u, &sigma) * s.v.transpose();
}

/// The Drucker-Prager friction coefficient for the hardening state `q`.
#[inline]
fn friction_alpha(h: &[f32; 4], q: f32) -> f32 {
    let phi = (h[0] + (h[1] * q - h[3]) * (-h[2] * q).exp()).to_radians();
    let s = phi.sin();
    (2.0f32 / 3.0).sqrt() * 2.0 * s / (3.0 - s)
}

/// Sand: the Drucker-Prager return map in log-strain space with hardening.
pub(crate) fn sand<const D: usize>(lame: &Lame<f32>, h: &[f32; 4], f: &mut Mat<D>, q: &mut f32) {
    let s = svd(f);
    let mut eps = Vector::<D>::zeros();
    for i in 0..D {
        eps[i] = s.sigma[i].max(SIGMA_MIN).ln();
    }
    let tr = eps.sum();
    let dev = eps - Vector::<D>::repeat(tr / D as f32);
    let dev_norm = dev.norm();
    let (new_eps, dq) = if tr >= 0.0 || dev_norm == 0.0 {
        (Vector::<D>::zeros(), eps.norm())
    } else {
        let alpha = friction_alpha(h, *q);
        let dgamma = dev_norm + (D as f32 * lame.lambda + 2.0 * lame.mu) / (2.0 * lame.mu) * tr * alpha;
        if dgamma <= 0.0 { (eps, 0.0) } else { (eps - dev * (dgamma / dev_norm), dgamma) }
    };
    *q += dq;
    let sigma = new_eps.map(f32::exp);
    *f = scale_columns(&s.u, &sigma) * s.v.transpose();
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::{Material, Sand, Snow};

    fn rot2(t: f32) -> Mat<2> {
        Mat::<2>::new(t.cos(), -t.sin(), t.sin(), t.cos())
    }

    #[test]
    fn snow_clamps_singular_values_and_keeps_total_volume() {
        let m = Material::Snow(Snow::default()).compile(0).expect("valid");
        // F = R1 diag(1.2, 0.5) R2: both singular values outside the band.
        let f0 = rot2(0.3) * Mat::<2>::new(1.2, 0.0, 0.0, 0.5) * rot2(-1.1);
        let mut f = f0;
        let mut jp = 0.9f32;
        snow(m.theta_c, m.theta_s, &mut f, &mut jp);
        let s = svd(&f);
        assert!((s.sigma[0] - (1.0 + m.theta_s)).abs() < 1e-6);
        assert!((s.sigma[1] - (1.0 - m.theta_c)).abs() < 1e-6);
        // det F_E * J_P is the total volume change det F0 * J_P0.
        assert!((anim_material::decomposition::determinant(&f) * jp - f0.determinant() * 0.9).abs() < 1e-5);
        // The rotation part is kept: U V^T unchanged.
        let s0 = svd(&f0);
        assert!((s.u * s.v.transpose() - s0.u * s0.v.transpose()).norm() < 1e-5);
        // Inside the band nothing changes.
        let mut g = rot2(0.2) * Mat::<2>::new(1.005, 0.0, 0.0, 0.99);
        let g0 = g;
        let mut jp2 = 1.0;
        snow(m.theta_c, m.theta_s, &mut g, &mut jp2);
        assert!((g - g0).norm() < 1e-6 && (jp2 - 1.0).abs() < 1e-6);
    }

    #[test]
    fn sand_tension_returns_to_apex_and_cone_projection_lands_on_cone() {
        let m = Material::Sand(Sand::default()).compile(0).expect("valid");
        // Tension: projected to sigma = 1.
        let mut f = Mat::<3>::from_diagonal(&Vector::<3>::new(1.1, 1.05, 1.02));
        let mut q = 0.0;
        sand(&m.lame, &m.sand, &mut f, &mut q);
        assert!((f - Mat::<3>::identity()).norm() < 1e-6);
        assert!(q > 0.0);
        // Compression with strong shear: ends exactly on the yield surface
        // |eps^| + (d lambda + 2 mu)/(2 mu) tr(eps) alpha = 0.
        let mut f = Mat::<3>::from_diagonal(&Vector::<3>::new(1.25, 0.95, 0.8));
        let mut q = 0.0;
        sand(&m.lame, &m.sand, &mut f, &mut q);
        let s = svd(&f);
        let eps = s.sigma.map(f32::ln);
        let tr = eps.sum();
        let dev = (eps - Vector::<3>::repeat(tr / 3.0)).norm();
        let alpha = friction_alpha(&m.sand, 0.0);
        let yield_fn = dev + (3.0 * m.lame.lambda + 2.0 * m.lame.mu) / (2.0 * m.lame.mu) * tr * alpha;
        assert!(yield_fn.abs() < 1e-5, "yield function {yield_fn}");
        // Volume (trace of the log strain) is kept by the deviatoric projection.
        let tr0 = 1.25f32.ln() + 0.95f32.ln() + 0.8f32.ln();
        assert!(q > 0.0, "the trial state was outside the cone");
        assert!((tr - tr0).abs() < 1e-5);
    }
}
