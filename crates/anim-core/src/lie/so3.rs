//! The rotation group SO(3) and its Lie algebra so(3).
//!
//! A rotation is a [`DMat3`] `R` with `RᵀR = I` and `det R = +1`; an element of so(3) is a
//! skew-symmetric matrix `ŵ`, written here by its *rotation vector* `w ∈ R³` (axis times angle,
//! also called exponential coordinates); Murray, Li & Sastry (1994), chapter 2.
//!
//! | function | maps | formula |
//! | --- | --- | --- |
//! | [`hat`] | `R³ → so(3)` | `hat(w) b = w × b` |
//! | [`vee`] | `R³ˣ³ → R³` | inverse of `hat` on the antisymmetric part `(M - Mᵀ)/2` |
//! | [`exp`] | `so(3) → SO(3)` | `R = I + (sin θ/θ) ŵ + ((1 - cos θ)/θ²) ŵ²`, `θ = ‖w‖` |
//! | [`exp_axis_angle`] | unit axis, angle `→ SO(3)` | `R = I + sin θ ω̂ + (1 - cos θ) ω̂²` |
//! | [`log`] | `SO(3) → so(3)` | `θ = atan2(‖vee R‖, (tr R - 1)/2) ∈ [0, π]` |
//! | [`left_jacobian`] | `so(3) → R³ˣ³` | `J_l = I + ((1 - cos θ)/θ²) ŵ + ((θ - sin θ)/θ³) ŵ²` |
//! | [`left_jacobian_inv`] | `so(3) → R³ˣ³` | `J_l⁻¹ = I - ŵ/2 + ((1 - (θ/2) cot(θ/2))/θ²) ŵ²` |
//!
//! Every coefficient that is `0/0` at `θ = 0` switches to its Taylor series below
//! `θ = 1e-3`; the series are carried far enough that the truncation error is below `1e-20`, so
//! there is no accuracy seam at the switch.

use glam::{DMat3, DVec3};

/// Below this angle (radians) the `0/0` coefficients are evaluated by their Taylor series.
const TAYLOR_ANGLE: f64 = 1e-3;

/// Above this angle [`log`] reads the axis from the symmetric part of `R` instead of the
/// antisymmetric part, because `sin θ` (the size of the antisymmetric part) goes to zero at `π`.
/// `cos(2π/3) = -1/2`: at the switch both readings lose at most a factor two of precision.
const LOG_SYMMETRIC_COS: f64 = -0.5;

/// The skew-symmetric (cross-product) matrix of `w`: `hat(w) * b == w.cross(b)`.
///
/// ```text
///          ⎡  0   -w_z   w_y ⎤
/// hat(w) = ⎢ w_z    0   -w_x ⎥
///          ⎣-w_y   w_x    0  ⎦
/// ```
#[inline]
#[must_use]
pub fn hat(w: DVec3) -> DMat3 {
    DMat3::from_cols(DVec3::new(0.0, w.z, -w.y), DVec3::new(-w.z, 0.0, w.x), DVec3::new(w.y, -w.x, 0.0))
}

/// The vector of the antisymmetric part of `m`: `vee(m) = w` with `hat(w) = (m - mᵀ)/2`.
///
/// This is the inverse of [`hat`] (`vee(hat(w)) == w` exactly) and ignores any symmetric part of
/// `m`, so `vee(R)` of a rotation by `θ` about the unit axis `ω` is `sin θ · ω`.
#[inline]
#[must_use]
pub fn vee(m: DMat3) -> DVec3 {
    // m_ij is m.col(j)[i]; w = (m_32 - m_23, m_13 - m_31, m_21 - m_12) / 2 (1-based indices).
    0.5 * DVec3::new(m.y_axis.z - m.z_axis.y, m.z_axis.x - m.x_axis.z, m.x_axis.y - m.y_axis.x)
}

/// `c I + a hat(w) + b w wᵀ`, the shape shared by the exponential and both Jacobians
/// (it uses `ŵ² = w wᵀ - ‖w‖² I` to fold the `ŵ²` term into the identity term).
#[inline]
fn identity_hat_outer(c: f64, a: f64, b: f64, w: DVec3) -> DMat3 {
    let aw = a * w;
    let bw = b * w;
    DMat3::from_cols(
        DVec3::new(c + bw.x * w.x, bw.y * w.x + aw.z, bw.z * w.x - aw.y),
        DVec3::new(bw.x * w.y - aw.z, c + bw.y * w.y, bw.z * w.y + aw.x),
        DVec3::new(bw.x * w.z + aw.y, bw.y * w.z - aw.x, c + bw.z * w.z),
    )
}

/// The exponential map `so(3) → SO(3)`: the rotation by angle `‖w‖` about the axis `w/‖w‖`
/// (Rodrigues' formula).
///
/// `R = I + (sin θ/θ) ŵ + ((1 - cos θ)/θ²) ŵ²` with `θ = ‖w‖`. Accurate to a few ulps for
/// every `w`, including `w = 0` (exactly `I`) and tiny `‖w‖` (Taylor branch below `1e-3`).
#[inline]
#[must_use]
pub fn exp(w: DVec3) -> DMat3 {
    let theta2 = w.length_squared();
    let theta = theta2.sqrt();
    let (a, b) = if theta < TAYLOR_ANGLE {
        // sin θ/θ and (1 - cos θ)/θ², truncation error O(θ⁶/5040) < 1e-21.
        (1.0 - theta2 / 6.0 * (1.0 - theta2 / 20.0), 0.5 - theta2 / 24.0 * (1.0 - theta2 / 30.0))
    } else {
        let half_sinc = (0.5 * theta).sin() / theta;
        // 1 - cos θ = 2 sin²(θ/2) has no cancellation for small θ.
        (theta.sin() / theta, 2.0 * half_sinc * half_sinc)
    };
    identity_hat_outer(theta.cos(), a, b, w)
}

/// The rotation by `theta` radians about the **unit** vector `axis` (Rodrigues' formula):
/// `R = I + sin θ ω̂ + (1 - cos θ) ω̂²`.
///
/// Equal to [`exp`]`(axis * theta)` for a unit axis and any `theta` (negative or beyond `π` is
/// fine). A non-unit `axis` gives a matrix that is not a rotation; nothing checks for it.
#[inline]
#[must_use]
pub fn exp_axis_angle(axis: DVec3, theta: f64) -> DMat3 {
    let (sin, cos) = theta.sin_cos();
    let half = (0.5 * theta).sin();
    identity_hat_outer(cos, sin, 2.0 * half * half, axis)
}

/// The rotation angle of `r` in `[0, π]`: `atan2(‖vee r‖, (tr r - 1)/2)`.
///
/// This pairs `sin θ` (from the antisymmetric part) with `cos θ` (from the trace), which stays
/// well conditioned at every angle, unlike `acos` of the trace alone near `0` and `π`.
/// `r` is assumed to be a rotation (see [`is_rotation`]).
#[inline]
#[must_use]
pub fn angle(r: DMat3) -> f64 {
    let cos = 0.5 * (r.x_axis.x + r.y_axis.y + r.z_axis.z - 1.0);
    vee(r).length().atan2(cos)
}

/// The logarithm `SO(3) → so(3)`: the rotation vector `w` with `exp(w) == r` and `‖w‖ ∈ [0, π]`.
///
/// The angle comes from [`angle`]. The axis is read in one of three ways:
/// - `θ < 1e-3`: `w = vee(r) · θ/sin θ` with the Taylor series of `θ/sin θ` (no division by a
///   vanishing `sin θ`; `log(I)` is exactly zero);
/// - `cos θ ≥ -1/2`: `w = vee(r) · θ/sin θ`, since `vee(r) = sin θ · ω`;
/// - `cos θ < -1/2` (near `π`, where `sin θ → 0`): from the symmetric part
///   `B = (r + rᵀ)/2 - cos θ I = (1 - cos θ) ω ωᵀ`, whose column with the largest diagonal entry is
///   a multiple of `ω`; it is normalised and its sign chosen so that `ω · vee(r) ≥ 0`.
///
/// At exactly `θ = π` the sign of `w` is arbitrary (both signs give `r`). `r` is assumed to be a
/// rotation; a matrix far from one (see [`is_rotation`]) gives a meaningless result, and NaN
/// entries give NaN.
#[must_use]
pub fn log(r: DMat3) -> DVec3 {
    let sin_axis = vee(r);
    let sin = sin_axis.length();
    let cos = 0.5 * (r.x_axis.x + r.y_axis.y + r.z_axis.z - 1.0);
    let theta = sin.atan2(cos);
    if theta < TAYLOR_ANGLE {
        // θ/sin θ = 1 + θ²/6 + 7θ⁴/360 + O(θ⁶), truncation error < 1e-20.
        let theta2 = theta * theta;
        return sin_axis * (1.0 + theta2 / 6.0 * (1.0 + theta2 * 7.0 / 60.0));
    }
    if cos >= LOG_SYMMETRIC_COS {
        return sin_axis * (theta / sin);
    }
    // Near π: B = (r + rᵀ)/2 - cos θ I = (1 - cos θ) ω ωᵀ.
    let diag = DVec3::new(r.x_axis.x, r.y_axis.y, r.z_axis.z) - DVec3::splat(cos);
    let k = if diag.x >= diag.y && diag.x >= diag.z {
        0
    } else if diag.y >= diag.z {
        1
    } else {
        2
    };
    // Column k of B: (r_ik + r_ki)/2 - cos θ δ_ik = (1 - cos θ) ω_k ω_i.
    let column = 0.5 * (r.col(k) + r.row(k)) - cos * DMat3::IDENTITY.col(k);
    let mut axis = column.normalize();
    if axis.dot(sin_axis) < 0.0 {
        axis = -axis;
    }
    axis * theta
}

/// The left Jacobian of SO(3): `exp(w + δ) ≈ exp(J_l(w) δ) exp(w)` for small `δ`.
///
/// `J_l(w) = Σ_k ŵᵏ/(k+1)! = I + ((1 - cos θ)/θ²) ŵ + ((θ - sin θ)/θ³) ŵ²`, `θ = ‖w‖`.
/// It is also the `V` matrix of SE(3): the translation of `exp` of a twist `(v, w)` is
/// `J_l(w) v` (see [`Se3::exp`](super::Se3::exp)). Taylor branch below `θ = 1e-3`.
#[inline]
#[must_use]
pub fn left_jacobian(w: DVec3) -> DMat3 {
    let theta2 = w.length_squared();
    let theta = theta2.sqrt();
    // J = (sin θ/θ) I + ((1 - cos θ)/θ²) ŵ + ((θ - sin θ)/θ³) w wᵀ.
    let (a, b, c) = if theta < TAYLOR_ANGLE {
        (
            1.0 - theta2 / 6.0 * (1.0 - theta2 / 20.0),
            0.5 - theta2 / 24.0 * (1.0 - theta2 / 30.0),
            1.0 / 6.0 - theta2 / 120.0 * (1.0 - theta2 / 42.0),
        )
    } else {
        let sin = theta.sin();
        let half_sinc = (0.5 * theta).sin() / theta;
        (sin / theta, 2.0 * half_sinc * half_sinc, (theta - sin) / (theta2 * theta))
    };
    identity_hat_outer(a, b, c, w)
}

/// The inverse of [`left_jacobian`]:
/// `J_l⁻¹(w) = I - ŵ/2 + ((1 - (θ/2) cot(θ/2))/θ²) ŵ²`, `θ = ‖w‖`.
///
/// Defined for `‖w‖ < 2π` (`J_l` is singular at `θ = 2π`); the rotation vectors returned by
/// [`log`] have `‖w‖ ≤ π`, where it is well conditioned. Taylor branch below `θ = 1e-3`.
#[inline]
#[must_use]
pub fn left_jacobian_inv(w: DVec3) -> DMat3 {
    let theta2 = w.length_squared();
    let theta = theta2.sqrt();
    // J⁻¹ = (θ/2) cot(θ/2) I - ŵ/2 + ((1 - (θ/2) cot(θ/2))/θ²) w wᵀ.
    let (a, c) = if theta < TAYLOR_ANGLE {
        // (1 - x cot x)/θ² with x = θ/2: 1/12 + θ²/720 + θ⁴/30240 + ..., truncation < 1e-21.
        let c = 1.0 / 12.0 + theta2 / 720.0 * (1.0 + theta2 / 42.0);
        (1.0 - c * theta2, c)
    } else {
        let half = 0.5 * theta;
        let half_cot = half * half.cos() / half.sin();
        (half_cot, (1.0 - half_cot) / theta2)
    };
    identity_hat_outer(a, -0.5, c, w)
}

/// Whether `m` is a rotation within `tol`: every entry of `mᵀm - I` and `det m - 1` are at most
/// `tol` in magnitude (and all entries are finite).
#[must_use]
pub fn is_rotation(m: DMat3, tol: f64) -> bool {
    if !m.is_finite() {
        return false;
    }
    let gram = m.transpose() * m - DMat3::IDENTITY;
    let max_gram = gram.to_cols_array().iter().fold(0.0_f64, |acc, e| acc.max(e.abs()));
    max_gram <= tol && (m.determinant() - 1.0).abs() <= tol
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;
    use std::f64::consts::PI;

    fn frobenius(m: DMat3) -> f64 {
        m.to_cols_array().iter().map(|e| e * e).sum::<f64>().sqrt()
    }

    fn random_unit(rng: &mut ChaCha8Rng) -> DVec3 {
        let z: f64 = rng.random_range(-1.0..=1.0);
        let phi: f64 = rng.random_range(0.0..(2.0 * PI));
        let r = (1.0 - z * z).max(0.0).sqrt();
        DVec3::new(r * phi.cos(), r * phi.sin(), z)
    }

    /// Independent reference: matrix exponential by scaling and squaring with a Taylor series.
    fn expm_reference(a: DMat3) -> DMat3 {
        let mut squarings = 0;
        let mut scaled = a;
        while frobenius(scaled) > 0.25 {
            scaled *= 0.5;
            squarings += 1;
        }
        let mut term = DMat3::IDENTITY;
        let mut sum = DMat3::IDENTITY;
        for k in 1..=25 {
            term = term * scaled * (1.0 / k as f64);
            sum += term;
        }
        for _ in 0..squarings {
            sum = sum * sum;
        }
        sum
    }

    /// Independent reference for the left Jacobian: Σ_k ŵᵏ/(k+1)! (fine for ‖w‖ ≤ π).
    fn left_jacobian_series(w: DVec3) -> DMat3 {
        let h = hat(w);
        let mut power = DMat3::IDENTITY;
        let mut sum = DMat3::IDENTITY;
        let mut factorial = 1.0;
        for k in 1..=40 {
            power *= h;
            factorial *= (k + 1) as f64;
            sum += power * (1.0 / factorial);
        }
        sum
    }

    /// The exact rotation by π about the unit axis `n`: 2 n nᵀ - I.
    fn rotation_by_pi(n: DVec3) -> DMat3 {
        DMat3::from_cols(2.0 * n.x * n, 2.0 * n.y * n, 2.0 * n.z * n) - DMat3::IDENTITY
    }

    #[test]
    fn hat_and_vee_are_inverse() {
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        for _ in 0..1000 {
            let w = DVec3::new(
                rng.random_range(-10.0..10.0),
                rng.random_range(-10.0..10.0),
                rng.random_range(-10.0..10.0),
            );
            assert_eq!(vee(hat(w)), w);
            let h = hat(w);
            assert_eq!(h.transpose(), -h, "hat(w) is skew-symmetric");
        }
    }

    #[test]
    fn hat_is_the_cross_product_matrix() {
        let mut rng = ChaCha8Rng::seed_from_u64(2);
        for _ in 0..1000 {
            let a = random_unit(&mut rng) * rng.random_range(0.0..5.0);
            let b = random_unit(&mut rng) * rng.random_range(0.0..5.0);
            let err = (hat(a) * b - a.cross(b)).length();
            assert!(err <= 1e-14, "hat(a) b != a x b: {err:e}");
        }
        assert_eq!(hat(DVec3::X) * DVec3::Y, DVec3::Z);
    }

    #[test]
    fn vee_reads_only_the_antisymmetric_part() {
        let w = DVec3::new(0.3, -1.2, 2.5);
        let symmetric = DMat3::from_cols(
            DVec3::new(1.0, 2.0, 3.0),
            DVec3::new(2.0, -4.0, 5.0),
            DVec3::new(3.0, 5.0, 7.0),
        );
        assert!((vee(hat(w) + symmetric) - w).length() <= 1e-15);
        // The antisymmetric part of a rotation about the unit axis n by θ is sin θ · n.
        let n = DVec3::new(2.0, -1.0, 2.0) / 3.0;
        let err = (vee(exp_axis_angle(n, 0.7)) - 0.7_f64.sin() * n).length();
        assert!(err <= 1e-15, "{err:e}");
    }

    #[test]
    fn exp_matches_matrix_exponential_reference() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let mut magnitudes: Vec<f64> = vec![
            0.0,
            1e-12,
            1e-9,
            1e-6,
            1e-4,
            TAYLOR_ANGLE * (1.0 - 1e-12),
            TAYLOR_ANGLE * (1.0 + 1e-12),
            1e-2,
            0.1,
            PI,
            2.0 * PI,
            10.0,
        ];
        magnitudes.extend((0..2000).map(|_| rng.random_range(0.0..(2.0 * PI))));
        let mut max_err = 0.0_f64;
        for &theta in &magnitudes {
            let w = random_unit(&mut rng) * theta;
            let err = frobenius(exp(w) - expm_reference(hat(w)));
            max_err = max_err.max(err);
            // The reference loses about an ulp per squaring (log2(4‖w‖) of them); glam's
            // closed form `from_axis_angle` deviates from it by the same amount.
            assert!(err <= 4e-15 * theta.max(1.0), "|w| = {theta:e}: error {err:e}");
        }
        println!("so3::exp vs scaling-and-squaring Taylor reference: max Frobenius error {max_err:e}");
    }

    #[test]
    fn exp_matches_rodrigues_formula_for_unit_axes() {
        let mut rng = ChaCha8Rng::seed_from_u64(4);
        for _ in 0..2000 {
            let axis = random_unit(&mut rng);
            let theta = rng.random_range(-2.0 * PI..2.0 * PI);
            // Rodrigues: R = I + sin θ ω̂ + (1 - cos θ) ω̂².
            let h = hat(axis);
            let rodrigues = DMat3::IDENTITY + h * theta.sin() + h * h * (1.0 - theta.cos());
            let err = frobenius(exp(axis * theta) - rodrigues);
            assert!(err <= 2e-15, "exp: {err:e}");
            let err = frobenius(exp_axis_angle(axis, theta) - rodrigues);
            assert!(err <= 2e-15, "exp_axis_angle: {err:e}");
            let err = frobenius(exp_axis_angle(axis, theta) - DMat3::from_axis_angle(axis, theta));
            assert!(err <= 2e-15, "exp_axis_angle vs glam: {err:e}");
        }
    }

    #[test]
    fn exp_near_zero_is_exact_to_rounding() {
        assert_eq!(exp(DVec3::ZERO), DMat3::IDENTITY);
        let w = DVec3::new(3.0, -4.0, 12.0) / 13.0 * 1e-9;
        // exp(w) = I + ŵ + ŵ²/2 + O(1e-27).
        let h = hat(w);
        let reference = DMat3::IDENTITY + h + h * h * 0.5;
        let err = frobenius(exp(w) - reference);
        assert!(err <= 1e-16, "{err:e}");
        // The first-order part is reproduced to relative rounding error.
        let off = vee(exp(w));
        assert!((off - w).length() <= 1e-16 * w.length(), "{off:?}");
    }

    #[test]
    fn exp_gives_rotations() {
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        for _ in 0..1000 {
            let w = random_unit(&mut rng) * rng.random_range(0.0..20.0);
            assert!(is_rotation(exp(w), 1e-14), "{w:?}");
        }
    }

    /// Random axis, angle uniform in [0, π], plus the edge angles and the π rotations.
    fn log_test_rotations() -> Vec<DMat3> {
        let mut rng = ChaCha8Rng::seed_from_u64(6);
        let mut rotations = Vec::new();
        for _ in 0..10_000 {
            let axis = random_unit(&mut rng);
            rotations.push(DMat3::from_axis_angle(axis, rng.random_range(0.0..=PI)));
        }
        for theta in [0.0, 1e-9, 1e-6, PI - 1e-6, PI - 1e-9, PI] {
            for _ in 0..200 {
                rotations.push(exp_axis_angle(random_unit(&mut rng), theta));
            }
        }
        let diagonal = DVec3::new(1.0, 1.0, 0.0) / 2.0_f64.sqrt();
        for n in [DVec3::X, DVec3::Y, DVec3::Z, -DVec3::X, diagonal] {
            rotations.push(rotation_by_pi(n));
            for theta in [PI - 1e-6, PI - 1e-9, PI] {
                rotations.push(exp_axis_angle(n, theta));
            }
        }
        rotations
    }

    #[test]
    fn exp_of_log_reproduces_the_rotation() {
        let mut max_err = 0.0_f64;
        for r in log_test_rotations() {
            let w = log(r);
            assert!(w.length() <= PI + 1e-15, "angle out of [0, π]: {}", w.length());
            let err = frobenius(exp(w) - r);
            max_err = max_err.max(err);
            assert!(err <= 1e-12, "exp(log R) != R: {err:e} for R = {r:?}");
        }
        println!("so3 exp(log R) = R over 10^4 random + edge rotations: max Frobenius error {max_err:e}");
    }

    #[test]
    fn log_of_exp_reproduces_the_rotation_vector() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let mut magnitudes: Vec<f64> = vec![
            0.0,
            1e-15,
            1e-9,
            1e-6,
            TAYLOR_ANGLE * (1.0 - 1e-12),
            TAYLOR_ANGLE * (1.0 + 1e-12),
            2.0 * PI / 3.0 - 1e-12,
            2.0 * PI / 3.0 + 1e-12,
            PI - 1e-3,
            PI - 1e-6,
            PI - 1e-9,
        ];
        magnitudes.extend((0..10_000).map(|_| rng.random_range(0.0..(PI - 1e-6))));
        let mut max_err = 0.0_f64;
        for &theta in &magnitudes {
            let w = random_unit(&mut rng) * theta;
            let err = (log(exp(w)) - w).length() / theta.max(1.0);
            max_err = max_err.max(err);
            assert!(err <= 1e-12, "|w| = {theta}: log(exp w) error {err:e}");
        }
        println!("so3 log(exp w) = w, |w| < π: max error / max(1,|w|) {max_err:e}");
    }

    #[test]
    fn log_at_exactly_pi_has_length_pi_and_reproduces_the_rotation() {
        let mut rng = ChaCha8Rng::seed_from_u64(8);
        let mut axes = vec![
            DVec3::X,
            DVec3::Y,
            DVec3::Z,
            DVec3::new(1.0, 1.0, 0.0) / 2.0_f64.sqrt(),
            DVec3::new(1.0, 1.0, 1.0) / 3.0_f64.sqrt(),
        ];
        axes.extend((0..100).map(|_| random_unit(&mut rng)));
        for n in axes {
            let r = rotation_by_pi(n);
            let w = log(r);
            assert!((w.length() - PI).abs() <= 1e-15, "|log R| = {}", w.length());
            assert!((w.normalize().dot(n).abs() - 1.0).abs() <= 1e-15, "axis {:?} vs {n:?}", w.normalize());
            let err = frobenius(exp(w) - r);
            assert!(err <= 1e-14, "{err:e}");
        }
    }

    #[test]
    fn log_near_pi_keeps_the_sign_of_the_axis() {
        let mut rng = ChaCha8Rng::seed_from_u64(9);
        for _ in 0..200 {
            let n = random_unit(&mut rng);
            for theta in [PI - 1e-4, PI - 1e-7, PI - 1e-9] {
                let w = log(exp_axis_angle(n, theta));
                assert!(w.dot(n) > 0.0, "sign flipped at θ = π - {:e}", PI - theta);
            }
        }
    }

    #[test]
    fn angle_matches_the_rotation_angle() {
        let mut rng = ChaCha8Rng::seed_from_u64(10);
        for theta in [0.0, 1e-12, 1e-6, 0.5, 2.0, PI - 1e-9, PI] {
            let r = exp_axis_angle(random_unit(&mut rng), theta);
            assert!((angle(r) - theta).abs() <= 1e-15, "θ = {theta}: {}", angle(r));
        }
        for _ in 0..1000 {
            let theta = rng.random_range(0.0..PI);
            let r = exp_axis_angle(random_unit(&mut rng), theta);
            assert!((angle(r) - theta).abs() <= 1e-14);
            assert!((angle(r) - log(r).length()).abs() <= 1e-15);
        }
    }

    #[test]
    fn left_jacobian_matches_finite_differences() {
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let h = 1e-5;
        let mut magnitudes: Vec<f64> = vec![0.0, 1e-9, 1e-4, TAYLOR_ANGLE, 0.5, PI - 1e-6];
        magnitudes.extend((0..500).map(|_| rng.random_range(0.0..PI)));
        let mut max_err = 0.0_f64;
        for &theta in &magnitudes {
            let w = random_unit(&mut rng) * theta;
            let delta = random_unit(&mut rng);
            let derivative = (exp(w + h * delta) - exp(w - h * delta)) * (0.5 / h);
            let analytic = hat(left_jacobian(w) * delta) * exp(w);
            let err = frobenius(derivative - analytic);
            max_err = max_err.max(err);
            // Central differences: truncation h²/6 · O(1) ≈ 2e-11, rounding ε/h ≈ 2e-11.
            assert!(err <= 1e-8, "|w| = {theta}: {err:e}");
        }
        println!("so3 left Jacobian vs central differences (h = 1e-5): max error {max_err:e}");
    }

    #[test]
    fn left_jacobian_matches_its_power_series() {
        let mut rng = ChaCha8Rng::seed_from_u64(12);
        let mut magnitudes: Vec<f64> =
            vec![0.0, 1e-9, 1e-5, TAYLOR_ANGLE * (1.0 - 1e-12), TAYLOR_ANGLE * (1.0 + 1e-12), 0.1, PI];
        magnitudes.extend((0..500).map(|_| rng.random_range(0.0..PI)));
        for &theta in &magnitudes {
            let w = random_unit(&mut rng) * theta;
            let err = frobenius(left_jacobian(w) - left_jacobian_series(w));
            assert!(err <= 1e-14, "|w| = {theta:e}: {err:e}");
        }
    }

    #[test]
    fn left_jacobian_inv_inverts_left_jacobian() {
        let mut rng = ChaCha8Rng::seed_from_u64(13);
        let mut magnitudes: Vec<f64> =
            vec![0.0, 1e-9, 1e-5, TAYLOR_ANGLE * (1.0 - 1e-12), TAYLOR_ANGLE * (1.0 + 1e-12), PI, 6.0];
        magnitudes.extend((0..1000).map(|_| rng.random_range(0.0..6.0)));
        let mut max_err = 0.0_f64;
        for &theta in &magnitudes {
            let w = random_unit(&mut rng) * theta;
            let err = frobenius(left_jacobian_inv(w) * left_jacobian(w) - DMat3::IDENTITY);
            let err2 = frobenius(left_jacobian(w) * left_jacobian_inv(w) - DMat3::IDENTITY);
            max_err = max_err.max(err).max(err2);
            assert!(err <= 1e-12 && err2 <= 1e-12, "|w| = {theta}: {err:e} {err2:e}");
        }
        println!("so3 J_l^-1 J_l = I for |w| <= 6: max error {max_err:e}");
        // Both sides of the Taylor switch, where a wrong series coefficient would show at
        // O(θ²) = 1e-6 and the direct formula has its worst cancellation.
        for scale in [1.0 - 1e-12, 1.0 + 1e-12] {
            let w = DVec3::new(0.6, 0.0, 0.8) * TAYLOR_ANGLE * scale;
            let err = frobenius(left_jacobian_inv(w) * left_jacobian(w) - DMat3::IDENTITY);
            assert!(err <= 1e-15, "{err:e}");
        }
    }

    #[test]
    fn is_rotation_accepts_rotations_and_rejects_the_rest() {
        let r = exp(DVec3::new(0.3, -2.0, 1.0));
        assert!(is_rotation(r, 1e-14));
        assert!(is_rotation(DMat3::IDENTITY, 0.0));
        let reflection = DMat3::from_diagonal(DVec3::new(1.0, 1.0, -1.0)) * r;
        assert!(!is_rotation(reflection, 1e-6), "det = -1");
        assert!(!is_rotation(r * 1.001, 1e-6), "scaled");
        let shear = DMat3::from_cols(DVec3::X, DVec3::new(1e-3, 1.0, 0.0), DVec3::Z);
        assert!(!is_rotation(shear * r, 1e-6), "sheared");
        assert!(is_rotation(shear * r, 1e-2), "within a loose tolerance");
        let mut nan = r;
        nan.x_axis.x = f64::NAN;
        assert!(!is_rotation(nan, 1.0));
    }
}
