//! The velocity stages of the loop: Müller et al.'s damping at line (6), the velocities from the
//! positions at lines (12)-(15), and restitution at line (16), `velocityUpdate`.
//!
//! **Damping** (Müller et al. 2007, section 3.5): with the free particles' centre of mass `x_cm`,
//! mean velocity `v_cm`, angular momentum `L = sum m_i r_i x v_i` and inertia
//! `I = sum m_i (|r_i|^2 Id - r_i r_i^T)` about `x_cm` (`r_i = x_i - x_cm`), the rigid motion is
//! `v_cm + omega x r_i` with `omega = I^-1 L`, and each velocity moves the fraction `k_damping`
//! towards it, `v_i <- v_i + k_damping (v_cm + omega x r_i - v_i)`: it damps the deformation
//! without slowing the motion of the whole.
//!
//! **Update** (lines 12-15): `v_i <- (p_i - x_i) / h`, `x_i <- p_i`.
//!
//! **Restitution** (Müller et al. 2020, eq. 34): a contact that was active in the solve and whose
//! normal velocity relative to the obstacle before the solve, `v_n^-`, approached faster than
//! `2 |g| h` leaves with `v_n = -e v_n^-`; slower contacts leave with `v_n = 0`, so resting
//! particles do not jitter.

use super::parallel::{CHUNK, PARALLEL_MIN};
use super::scratch::Data;
use crate::collide::coefficients;
use crate::model::PbdModel;
use anim_core::glam::{DMat3, DVec3};
use anim_core::par::prelude::*;

/// Line (6) with `k = k_damping`.
pub(super) fn damp_velocities(model: &PbdModel, x: &[DVec3], v: &mut [DVec3], k: f64) {
    let w = &model.inv_mass;
    let (mut m, mut xm, mut vm) = (0.0, DVec3::ZERO, DVec3::ZERO);
    for i in 0..x.len() {
        if w[i] > 0.0 {
            let mi = model.particles[i].mass;
            m += mi;
            xm += mi * x[i];
            vm += mi * v[i];
        }
    }
    if !(m > 0.0) {
        return;
    }
    xm /= m;
    vm /= m;
    let mut l = DVec3::ZERO;
    let mut inertia = DMat3::ZERO;
    for i in 0..x.len() {
        if w[i] > 0.0 {
            let mi = model.particles[i].mass;
            let r = x[i] - xm;
            l += mi * r.cross(v[i]);
            // I += m (|r|^2 Id - r r^T)
            inertia += mi * (DMat3::from_diagonal(DVec3::splat(r.length_squared())) - outer(r, r));
        }
    }
    // A line of particles has a singular inertia: regularise by a relative 1e-9 of its trace.
    let reg = 1e-9 * (inertia.x_axis.x + inertia.y_axis.y + inertia.z_axis.z) + f64::MIN_POSITIVE;
    let omega = (inertia + DMat3::from_diagonal(DVec3::splat(reg))).inverse() * l;
    if !omega.is_finite() {
        return;
    }
    for i in 0..x.len() {
        if w[i] > 0.0 {
            let dv = vm + omega.cross(x[i] - xm) - v[i];
            v[i] += k * dv;
        }
    }
}

/// Lines (12)-(15) for a substep of length `h`: `v <- (p - x) / h`, `x <- p`.
pub(super) fn update_velocities(model: &PbdModel, d: &mut Data, h: f64) {
    let n = model.num_particles();
    let parallel = anim_core::par::current_num_threads() > 1;
    let inv_h = 1.0 / h;
    if parallel && n >= PARALLEL_MIN {
        d.x.par_chunks_mut(CHUNK)
            .zip(d.v.par_chunks_mut(CHUNK))
            .zip(d.p.par_chunks(CHUNK))
            .for_each(|((x, v), p)| update(x, v, p, inv_h));
    } else {
        update(&mut d.x, &mut d.v, &d.p, inv_h);
    }
}

/// Line (16), `velocityUpdate`, for a substep of length `h`: restitution of the contacts the solve
/// used.
pub(super) fn restitution(model: &PbdModel, d: &mut Data, h: f64) {
    let inv_h = 1.0 / h;
    let gmag = model.gravity.length();
    for c in &d.contacts {
        if c.lambda > 0.0 {
            let (_, _, e) = coefficients(&model.colliders, &model.mesh_colliders, c.collider as usize);
            let i = c.particle as usize;
            let vo = c.obstacle_dx * inv_h;
            let vn = c.normal.dot(d.v[i] - vo);
            let target = if c.vn_pre < -2.0 * gmag * h { -e * c.vn_pre } else { 0.0 };
            d.v[i] += c.normal * (target.max(0.0) - vn);
        }
    }
}

/// `v <- (p - x) / h`, `x <- p` over matching chunks.
fn update(x: &mut [DVec3], v: &mut [DVec3], p: &[DVec3], inv_h: f64) {
    for ((x, v), &pn) in x.iter_mut().zip(v.iter_mut()).zip(p) {
        *v = (pn - *x) * inv_h;
        *x = pn;
    }
}

/// `a b^T`.
#[inline]
fn outer(a: DVec3, b: DVec3) -> DMat3 {
    DMat3::from_cols(a * b.x, a * b.y, a * b.z)
}
