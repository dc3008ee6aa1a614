//! The configuration manifold: neutral configuration, `integrate` (`q ⊕ v dt`) and
//! `difference` (`q₁ ⊖ q₀`), normalisation, limits and random samples.
//!
//! Revolute and prismatic entries live in `R` and move by addition (no wrapping of angles, as in
//! Pinocchio for bounded revolute joints). A spherical joint's unit quaternion `q_J` moves by
//! right multiplication with the exponential of the local angular velocity, and a free joint's
//! placement `M = (R(q_J), t)` by the SE(3) exponential of the local twist:
//!
//! ```text
//! spherical:  R(q ⊕ ω)  = R(q) exp(ω̂)                  ω ∈ R³ in the child frame
//! free:       M(q ⊕ ξ)  = M(q) exp(ξ̂)                  ξ = (v, ω) in the child frame
//! difference: q₁ ⊖ q₀   = log(R₀ᵀ R₁)  or  log(M₀⁻¹ M₁)
//! ```
//!
//! so `integrate(q₀, difference(q₀, q₁), 1) = q₁` (for rotation angles below `π`), and finite
//! differences of forward kinematics along `v` match the Jacobian times `v`. These are
//! Pinocchio's `integrate`/`difference` for `SpecialOrthogonalOperationTpl<3>` and
//! `SpecialEuclideanOperationTpl<3>`. The quaternion is the representation in `q` (not
//! exponential coordinates) because it has no singularity and is what Pinocchio and URDF tools
//! exchange; its sign is free (`q` and `-q` are the same rotation).

use anim_core::glam::{DQuat, DVec3};
use anim_core::lie::{Twist, so3};

use crate::model::{JointType, Model};

/// The neutral configuration: zero for revolute and prismatic joints, the identity quaternion
/// `(0, 0, 0, 1)` for spherical and free joints (zero translation).
#[must_use]
pub fn neutral(model: &Model) -> Vec<f64> {
    let mut q = vec![0.0; model.nq()];
    for j in model.joints() {
        match j.kind {
            JointType::Spherical => q[j.idx_q + 3] = 1.0,
            JointType::Free => q[j.idx_q + 6] = 1.0,
            _ => {}
        }
    }
    q
}

/// The unit quaternion `exp(ω/2)` of the rotation vector `w` (accurate at small angles).
#[must_use]
pub(crate) fn quat_exp(w: DVec3) -> DQuat {
    let theta2 = w.length_squared();
    let theta = theta2.sqrt();
    let (s, c) = if theta < 1e-4 {
        // sin(θ/2)/θ = 1/2 - θ²/48 + θ⁴/3840, cos(θ/2) = 1 - θ²/8 + θ⁴/384.
        (0.5 - theta2 / 48.0 + theta2 * theta2 / 3840.0, 1.0 - theta2 / 8.0 + theta2 * theta2 / 384.0)
    } else {
        let half = 0.5 * theta;
        (half.sin() / theta, half.cos())
    };
    DQuat::from_xyzw(w.x * s, w.y * s, w.z * s, c)
}

/// The rotation vector of the unit quaternion `q`, with angle in `[0, π]` (the sign of `q` is
/// chosen so that `w >= 0`).
#[must_use]
pub(crate) fn quat_log(q: DQuat) -> DVec3 {
    let (v, w) =
        if q.w < 0.0 { (-DVec3::new(q.x, q.y, q.z), -q.w) } else { (DVec3::new(q.x, q.y, q.z), q.w) };
    let s = v.length();
    // θ = 2 atan2(s, w); factor = θ / s, with the series 2/w (1 - s²/(3w²)) near s = 0.
    let factor = if s < 1e-8 { 2.0 / w * (1.0 - s * s / (3.0 * w * w)) } else { 2.0 * s.atan2(w) / s };
    v * factor
}

fn read_quat(q: &[f64]) -> DQuat {
    DQuat::from_xyzw(q[0], q[1], q[2], q[3])
}

fn write_quat(q: &mut [f64], r: DQuat) {
    q[0] = r.x;
    q[1] = r.y;
    q[2] = r.z;
    q[3] = r.w;
}

/// `q ⊕ v dt` written into `out`: the configuration reached from `q` by moving at constant
/// velocity `v` for `dt`. Quaternions of the result are re-normalised.
///
/// # Panics
/// When a slice length does not match the model.
#[track_caller]
pub fn integrate_into(model: &Model, q: &[f64], v: &[f64], dt: f64, out: &mut [f64]) {
    assert_eq!(q.len(), model.nq(), "q has length {}, the model nq = {}", q.len(), model.nq());
    assert_eq!(v.len(), model.nv(), "v has length {}, the model nv = {}", v.len(), model.nv());
    assert_eq!(out.len(), model.nq(), "out has length {}, the model nq = {}", out.len(), model.nq());
    for j in &model.joints()[1..] {
        let (iq, iv) = (j.idx_q, j.idx_v);
        match j.kind {
            JointType::Revolute(_) | JointType::Prismatic(_) => out[iq] = q[iq] + v[iv] * dt,
            JointType::Fixed => {}
            JointType::Spherical => {
                let w = DVec3::new(v[iv], v[iv + 1], v[iv + 2]) * dt;
                let r = (read_quat(&q[iq..iq + 4]) * quat_exp(w)).normalize();
                write_quat(&mut out[iq..iq + 4], r);
            }
            JointType::Free => {
                let lin = DVec3::new(v[iv], v[iv + 1], v[iv + 2]) * dt;
                let ang = DVec3::new(v[iv + 3], v[iv + 4], v[iv + 5]) * dt;
                let r0 = read_quat(&q[iq + 3..iq + 7]);
                let t0 = DVec3::new(q[iq], q[iq + 1], q[iq + 2]);
                let t = t0 + r0 * (so3::left_jacobian(ang) * lin);
                let r = (r0 * quat_exp(ang)).normalize();
                out[iq..iq + 3].copy_from_slice(&t.to_array());
                write_quat(&mut out[iq + 3..iq + 7], r);
            }
            JointType::Planar(_) => {
                // SE(2) exponential of the local twist (vx, vy, ω) dt.
                let phi = v[iv + 2] * dt;
                let (a, b) = se2_v(phi);
                let (lx, ly) = (v[iv] * dt, v[iv + 1] * dt);
                let (dx, dy) = (a * lx - b * ly, b * lx + a * ly);
                let (s, c) = q[iq + 2].sin_cos();
                out[iq] = q[iq] + c * dx - s * dy;
                out[iq + 1] = q[iq + 1] + s * dx + c * dy;
                out[iq + 2] = q[iq + 2] + phi;
            }
        }
    }
}

/// `q ⊕ v dt` (see [`integrate_into`]).
///
/// # Panics
/// When a slice length does not match the model.
#[must_use]
#[track_caller]
pub fn integrate(model: &Model, q: &[f64], v: &[f64], dt: f64) -> Vec<f64> {
    let mut out = vec![0.0; model.nq()];
    integrate_into(model, q, v, dt, &mut out);
    out
}

/// `q₁ ⊖ q₀` written into `out`: the velocity `v` with `integrate(q₀, v, 1) = q₁` (rotation
/// angles of the relative motion below `π`).
///
/// # Panics
/// When a slice length does not match the model.
#[track_caller]
pub fn difference_into(model: &Model, q0: &[f64], q1: &[f64], out: &mut [f64]) {
    assert_eq!(q0.len(), model.nq(), "q0 has length {}, the model nq = {}", q0.len(), model.nq());
    assert_eq!(q1.len(), model.nq(), "q1 has length {}, the model nq = {}", q1.len(), model.nq());
    assert_eq!(out.len(), model.nv(), "out has length {}, the model nv = {}", out.len(), model.nv());
    for j in &model.joints()[1..] {
        let (iq, iv) = (j.idx_q, j.idx_v);
        match j.kind {
            JointType::Revolute(_) | JointType::Prismatic(_) => out[iv] = q1[iq] - q0[iq],
            JointType::Fixed => {}
            JointType::Spherical => {
                let rel = read_quat(&q0[iq..iq + 4]).inverse() * read_quat(&q1[iq..iq + 4]);
                out[iv..iv + 3].copy_from_slice(&quat_log(rel).to_array());
            }
            JointType::Free => {
                let m0 = j.kind.transform(&q0[iq..iq + 7]);
                let m1 = j.kind.transform(&q1[iq..iq + 7]);
                let xi: Twist = (m0.inverse() * m1).log();
                out[iv..iv + 6].copy_from_slice(&xi.to_array());
            }
            JointType::Planar(_) => {
                // SE(2) logarithm of the relative motion, ω = θ₁ - θ₀ unwrapped.
                let phi = q1[iq + 2] - q0[iq + 2];
                let (s, c) = q0[iq + 2].sin_cos();
                let (px, py) = (q1[iq] - q0[iq], q1[iq + 1] - q0[iq + 1]);
                let (lx, ly) = (c * px + s * py, -s * px + c * py);
                let (a, b) = se2_v(phi);
                let d = a * a + b * b;
                out[iv] = (a * lx + b * ly) / d;
                out[iv + 1] = (-b * lx + a * ly) / d;
                out[iv + 2] = phi;
            }
        }
    }
}

/// `q₁ ⊖ q₀` (see [`difference_into`]).
///
/// # Panics
/// When a slice length does not match the model.
#[must_use]
#[track_caller]
pub fn difference(model: &Model, q0: &[f64], q1: &[f64]) -> Vec<f64> {
    let mut out = vec![0.0; model.nv()];
    difference_into(model, q0, q1, &mut out);
    out
}

/// Re-normalises every quaternion of `q` (a zero quaternion becomes the identity).
///
/// # Panics
/// When `q.len() != model.nq()`.
#[track_caller]
pub fn normalize(model: &Model, q: &mut [f64]) {
    assert_eq!(q.len(), model.nq(), "q has length {}, the model nq = {}", q.len(), model.nq());
    for j in model.joints() {
        let start = match j.kind {
            JointType::Spherical => j.idx_q,
            JointType::Free => j.idx_q + 3,
            _ => continue,
        };
        let r = read_quat(&q[start..start + 4]);
        let n = r.length();
        let r = if n > 0.0 && n.is_finite() { r / n } else { DQuat::IDENTITY };
        write_quat(&mut q[start..start + 4], r);
    }
}

/// Clamps every one-degree-of-freedom entry of `q` into its limits and re-normalises the
/// quaternions (the projection onto the feasible set used by inverse kinematics).
///
/// # Panics
/// When `q.len() != model.nq()`.
#[track_caller]
pub fn clamp_to_limits(model: &Model, q: &mut [f64]) {
    normalize(model, q);
    for j in &model.joints()[1..] {
        if j.nq() == 1 {
            q[j.idx_q] = q[j.idx_q].clamp(j.limits.lower, j.limits.upper);
        }
    }
}

/// Whether every one-degree-of-freedom entry of `q` lies within its limits (to `tol`).
///
/// # Panics
/// When `q.len() != model.nq()`.
#[must_use]
#[track_caller]
pub fn within_limits(model: &Model, q: &[f64], tol: f64) -> bool {
    assert_eq!(q.len(), model.nq(), "q has length {}, the model nq = {}", q.len(), model.nq());
    model.joints()[1..].iter().filter(|j| j.nq() == 1).all(|j| {
        let x = q[j.idx_q];
        x >= j.limits.lower - tol && x <= j.limits.upper + tol
    })
}

/// A random configuration drawn with `uniform`, a source of independent samples in `[0, 1)`:
/// uniform within the limits of bounded joints, in `[-π, π]` for unbounded revolute joints, in
/// `[-1, 1]` (m) for unbounded prismatic joints and free and planar translations, in `[-π, π]`
/// for planar angles, and uniform over
/// rotations (Shoemake's method) for quaternions.
#[must_use]
pub fn random_configuration(model: &Model, uniform: &mut impl FnMut() -> f64) -> Vec<f64> {
    let mut q = neutral(model);
    let rand_quat = |u: &mut dyn FnMut() -> f64| {
        let (u1, u2, u3) = (u(), u(), u());
        let (a, b) = ((1.0 - u1).sqrt(), u1.sqrt());
        let tau = 2.0 * std::f64::consts::PI;
        DQuat::from_xyzw(
            a * (tau * u2).sin(),
            a * (tau * u2).cos(),
            b * (tau * u3).sin(),
            b * (tau * u3).cos(),
        )
    };
    // A coupled joint has no entry of its own (it would redraw its master's).
    for j in model.joints()[1..].iter().filter(|j| j.mimic.is_none()) {
        let iq = j.idx_q;
        match j.kind {
            JointType::Revolute(_) | JointType::Prismatic(_) => {
                let (lo, hi) = if j.limits.is_bounded() {
                    (j.limits.lower, j.limits.upper)
                } else if matches!(j.kind, JointType::Revolute(_)) {
                    (-std::f64::consts::PI, std::f64::consts::PI)
                } else {
                    (-1.0, 1.0)
                };
                q[iq] = lo + (hi - lo) * uniform();
            }
            JointType::Fixed => {}
            JointType::Spherical => write_quat(&mut q[iq..iq + 4], rand_quat(uniform)),
            JointType::Free => {
                for k in 0..3 {
                    q[iq + k] = 2.0 * uniform() - 1.0;
                }
                write_quat(&mut q[iq + 3..iq + 7], rand_quat(uniform));
            }
            JointType::Planar(_) => {
                q[iq] = 2.0 * uniform() - 1.0;
                q[iq + 1] = 2.0 * uniform() - 1.0;
                q[iq + 2] = std::f64::consts::PI * (2.0 * uniform() - 1.0);
            }
        }
    }
    q
}

/// `(sin φ / φ, (1 - cos φ) / φ)`: the SE(2) exponential moves the local translation `(x, y)`
/// to `(a x - b y, b x + a y)`. Series below `1e-4`.
fn se2_v(phi: f64) -> (f64, f64) {
    if phi.abs() < 1e-4 {
        let p2 = phi * phi;
        (1.0 - p2 / 6.0, phi / 2.0 - phi * p2 / 24.0)
    } else {
        let (s, c) = phi.sin_cos();
        (s / phi, (1.0 - c) / phi)
    }
}

/// The joint motion of the free joint `q = (t, quaternion)` as an [`Se3`].
#[cfg(test)]
fn free_placement(q: &[f64]) -> anim_core::lie::Se3 {
    JointType::Free.transform(q)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{Axis, JointLimits, ModelBuilder};
    use anim_core::lie::Se3;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn mixed_model() -> Model {
        let mut b = ModelBuilder::new("mixed");
        let f = b.add_joint(0, "free", JointType::Free, Se3::IDENTITY, JointLimits::UNBOUNDED).unwrap();
        let r = b
            .add_joint(
                f,
                "rev",
                JointType::Revolute(Axis::Y),
                Se3::from_translation(DVec3::X),
                JointLimits::position(-1.0, 1.0),
            )
            .unwrap();
        let s = b.add_joint(r, "ball", JointType::Spherical, Se3::IDENTITY, JointLimits::UNBOUNDED).unwrap();
        b.add_joint(s, "slide", JointType::Prismatic(Axis::Z), Se3::IDENTITY, JointLimits::UNBOUNDED)
            .unwrap();
        b.build()
    }

    #[test]
    fn integrate_then_difference_round_trips() {
        let model = mixed_model();
        assert_eq!((model.nq(), model.nv()), (13, 11));
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        for _ in 0..100 {
            let q0 = random_configuration(&model, &mut || rng.random::<f64>());
            let v: Vec<f64> = (0..model.nv()).map(|_| rng.random_range(-1.0..1.0)).collect();
            let q1 = integrate(&model, &q0, &v, 0.9);
            let d = difference(&model, &q0, &q1);
            for (a, b) in d.iter().zip(&v) {
                assert!((a - 0.9 * b).abs() < 1e-13, "{a} vs {}", 0.9 * b);
            }
            assert!(difference(&model, &q1, &q1).iter().all(|e| e.abs() < 1e-15));
        }
    }

    #[test]
    fn free_integration_is_the_se3_exponential() {
        let model = mixed_model();
        let mut q = neutral(&model);
        q[0..3].copy_from_slice(&[0.3, -0.2, 1.0]);
        let r0 = quat_exp(DVec3::new(0.4, 0.1, -0.7));
        q[3..7].copy_from_slice(&r0.to_array());
        let mut v = vec![0.0; model.nv()];
        v[0..6].copy_from_slice(&[0.5, -1.0, 0.2, 1.1, 0.3, -0.4]);
        let q1 = integrate(&model, &q, &v, 1.0);
        let expected =
            free_placement(&q[0..7]) * Se3::exp(Twist::from_array([0.5, -1.0, 0.2, 1.1, 0.3, -0.4]));
        let got = free_placement(&q1[0..7]);
        assert!((got.translation - expected.translation).length() < 1e-14);
        assert!((got.rotation - expected.rotation).abs_diff_eq(anim_core::glam::DMat3::ZERO, 1e-14));
    }

    #[test]
    fn quaternion_exp_log_accurate_at_small_and_large_angles() {
        for w in [
            DVec3::ZERO,
            DVec3::new(1e-9, 0.0, 2e-9),
            DVec3::new(1e-5, -3e-5, 2e-5),
            DVec3::new(0.3, 2.0, -1.0),
        ] {
            let back = quat_log(quat_exp(w));
            assert!((back - w).length() <= 1e-15 * (1.0 + w.length()) * 4.0, "{w} -> {back}");
            let r = DMat3Ext::from_quat(quat_exp(w));
            assert!((r - so3::exp(w)).abs_diff_eq(anim_core::glam::DMat3::ZERO, 1e-15));
        }
    }

    struct DMat3Ext;
    impl DMat3Ext {
        fn from_quat(q: DQuat) -> anim_core::glam::DMat3 {
            anim_core::glam::DMat3::from_quat(q)
        }
    }

    #[test]
    fn clamp_and_limits() {
        let model = mixed_model();
        let mut q = neutral(&model);
        q[7] = 3.0;
        q[3] = 2.0;
        assert!(!within_limits(&model, &q, 0.0));
        clamp_to_limits(&model, &mut q);
        assert_eq!(q[7], 1.0);
        assert!(within_limits(&model, &q, 0.0));
        let n: f64 = q[3..7].iter().map(|e| e * e).sum();
        assert!((n - 1.0).abs() < 1e-15);
    }
}
