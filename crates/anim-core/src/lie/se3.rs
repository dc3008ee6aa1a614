//! The rigid-motion group SE(3), its Lie algebra se(3) of twists, and screws.
//!
//! A rigid motion `g = (R, t)` maps a point `q_b` of frame `b` to `q_a = R q_b + t` in frame `a`;
//! in homogeneous form `g = [[R, t], [0, 1]]`. A twist `ξ = (v, ω)` — linear
//! part **first**, angular part second, as in Murray, Li & Sastry (1994) — is the
//! element `ξ̂ = [[ω̂, v], [0, 0]]` of se(3).
//!
//! - [`Se3::exp`]: `exp(ξ̂) = [[exp(ω̂), J_l(ω) v], [0, 1]]`, where `J_l` is
//!   [`so3::left_jacobian`]. For a unit `ω` and angle `θ` this is Murray, Li & Sastry's
//!   `[[e^{ω̂θ}, (I - e^{ω̂θ})(ω × v) + ω ωᵀ v θ], [0, 1]]` ([`Se3::exp_screw`]).
//! - [`Se3::log`]: `ω = so3::log(R)`, `v = J_l(ω)⁻¹ t`; the exact inverse of `exp` for rotation
//!   angles below `π`.
//! - [`Se3::adjoint`]: `Ad_g ξ = (R v + t × R ω, R ω)`, the twist `g ξ̂ g⁻¹`; it carries twists
//!   between frames and satisfies `g exp(ξ) g⁻¹ = exp(Ad_g ξ)`.
//! - [`Twist::bracket`]: the Lie bracket `[ξ, η] = ad_ξ η = (ω₁ × v₂ - ω₂ × v₁, ω₁ × ω₂)`.
//! - [`Screw`]: the geometric reading of a twist (Chasles): an axis line, a pitch and a
//!   magnitude.

use std::ops::{Add, AddAssign, Mul, MulAssign, Neg, Sub, SubAssign};

use glam::{DMat3, DMat4, DVec3, DVec4};

use super::so3;

/// Tolerance of [`Se3::from_homogeneous`] on the bottom row and on the rotation block.
const HOMOGENEOUS_TOL: f64 = 1e-9;

/// A twist `ξ = (v, ω) ∈ R⁶`: the exponential coordinates of a rigid motion, or a rigid-body
/// velocity (linear velocity of the point at the origin `v`, angular velocity `ω`).
///
/// The order is **linear first, angular second**, everywhere: in [`to_array`](Self::to_array),
/// in [`Se3::adjoint_matrix`] and in the hat matrix `ξ̂ = [[ω̂, v], [0, 0]]`.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Twist {
    /// Linear part `v`.
    pub v: DVec3,
    /// Angular part `ω`.
    pub w: DVec3,
}

impl Default for Twist {
    /// The zero twist.
    #[inline]
    fn default() -> Self {
        Self::ZERO
    }
}

impl Twist {
    /// The zero twist (no motion).
    pub const ZERO: Self = Self::new(DVec3::ZERO, DVec3::ZERO);

    /// The twist with linear part `v` and angular part `w`.
    #[inline]
    #[must_use]
    pub const fn new(v: DVec3, w: DVec3) -> Self {
        Self { v, w }
    }

    /// The zero twist, same as [`Twist::ZERO`].
    #[inline]
    #[must_use]
    pub const fn zero() -> Self {
        Self::ZERO
    }

    /// The coordinates `[v_x, v_y, v_z, ω_x, ω_y, ω_z]` (linear first).
    #[inline]
    #[must_use]
    pub const fn to_array(&self) -> [f64; 6] {
        [self.v.x, self.v.y, self.v.z, self.w.x, self.w.y, self.w.z]
    }

    /// The twist of the coordinates `[v_x, v_y, v_z, ω_x, ω_y, ω_z]` (linear first).
    #[inline]
    #[must_use]
    pub const fn from_array(a: [f64; 6]) -> Self {
        Self::new(DVec3::new(a[0], a[1], a[2]), DVec3::new(a[3], a[4], a[5]))
    }

    /// The 4x4 matrix `ξ̂ = [[ω̂, v], [0, 0]] ∈ se(3)`.
    #[inline]
    #[must_use]
    pub fn hat(&self) -> DMat4 {
        let w = so3::hat(self.w);
        DMat4::from_cols(w.x_axis.extend(0.0), w.y_axis.extend(0.0), w.z_axis.extend(0.0), self.v.extend(0.0))
    }

    /// The inverse of [`hat`](Self::hat): `v` is the top of the last column and `ω` is
    /// [`so3::vee`] of the upper-left 3x3 block (its antisymmetric part). The bottom row is
    /// ignored.
    #[inline]
    #[must_use]
    pub fn vee(m: DMat4) -> Self {
        Self::new(m.w_axis.truncate(), so3::vee(DMat3::from_mat4(m)))
    }

    /// The twist multiplied by `s` (both parts).
    #[inline]
    #[must_use]
    pub fn scale(&self, s: f64) -> Self {
        Self::new(self.v * s, self.w * s)
    }

    /// The Lie bracket `[self, other] = ad_self other`, the twist of the matrix commutator
    /// `ξ̂₁ ξ̂₂ - ξ̂₂ ξ̂₁`: `(ω₁ × v₂ - ω₂ × v₁, ω₁ × ω₂)`.
    ///
    /// It is the derivative of the adjoint: `d/dt Ad_{exp(t ξ₁)} ξ₂ |_{t=0} = [ξ₁, ξ₂]`.
    #[inline]
    #[must_use]
    pub fn bracket(&self, other: Twist) -> Twist {
        Self::new(self.w.cross(other.v) - other.w.cross(self.v), self.w.cross(other.w))
    }

    /// The screw of this twist (Murray, Li & Sastry, ch. 2), or `None` for the zero twist.
    ///
    /// For `ω ≠ 0`: axis `ω/‖ω‖`, magnitude `‖ω‖`, pitch `ω·v/‖ω‖²`, and the point
    /// `ω × v/‖ω‖²` of the axis closest to the origin. For `ω = 0` (pure translation): axis
    /// `v/‖v‖`, magnitude `‖v‖`, pitch `f64::INFINITY`, point the origin.
    /// [`Screw::to_twist`] inverts it.
    #[must_use]
    pub fn to_screw(&self) -> Option<Screw> {
        let w_norm = self.w.length();
        if w_norm > 0.0 {
            let axis = self.w / w_norm;
            Some(Screw {
                axis,
                point: axis.cross(self.v) / w_norm,
                pitch: axis.dot(self.v) / w_norm,
                magnitude: w_norm,
            })
        } else {
            let v_norm = self.v.length();
            (v_norm > 0.0).then(|| Screw {
                axis: self.v / v_norm,
                point: DVec3::ZERO,
                pitch: f64::INFINITY,
                magnitude: v_norm,
            })
        }
    }
}

impl Add for Twist {
    type Output = Twist;
    #[inline]
    fn add(self, rhs: Twist) -> Twist {
        Twist::new(self.v + rhs.v, self.w + rhs.w)
    }
}

impl AddAssign for Twist {
    #[inline]
    fn add_assign(&mut self, rhs: Twist) {
        *self = *self + rhs;
    }
}

impl Sub for Twist {
    type Output = Twist;
    #[inline]
    fn sub(self, rhs: Twist) -> Twist {
        Twist::new(self.v - rhs.v, self.w - rhs.w)
    }
}

impl SubAssign for Twist {
    #[inline]
    fn sub_assign(&mut self, rhs: Twist) {
        *self = *self - rhs;
    }
}

impl Mul<f64> for Twist {
    type Output = Twist;
    #[inline]
    fn mul(self, rhs: f64) -> Twist {
        self.scale(rhs)
    }
}

impl Mul<Twist> for f64 {
    type Output = Twist;
    #[inline]
    fn mul(self, rhs: Twist) -> Twist {
        rhs.scale(self)
    }
}

impl Neg for Twist {
    type Output = Twist;
    #[inline]
    fn neg(self) -> Twist {
        Twist::new(-self.v, -self.w)
    }
}

/// A rigid motion `g = (R, t) ∈ SE(3)`: `g(q) = R q + t`, homogeneous form `[[R, t], [0, 1]]`.
///
/// `rotation` is assumed to be a rotation matrix; the constructors do not check it
/// ([`Se3::from_homogeneous`] does). Composition is `g * h` (apply `h` first).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Se3 {
    /// The rotation `R` (a proper orthonormal matrix).
    pub rotation: DMat3,
    /// The translation `t`.
    pub translation: DVec3,
}

impl Default for Se3 {
    /// The identity motion.
    #[inline]
    fn default() -> Self {
        Self::IDENTITY
    }
}

impl Se3 {
    /// The identity motion.
    pub const IDENTITY: Self = Self::new(DMat3::IDENTITY, DVec3::ZERO);

    /// The motion `q ↦ rotation q + translation`.
    #[inline]
    #[must_use]
    pub const fn new(rotation: DMat3, translation: DVec3) -> Self {
        Self { rotation, translation }
    }

    /// The pure rotation `q ↦ rotation q`.
    #[inline]
    #[must_use]
    pub const fn from_rotation(rotation: DMat3) -> Self {
        Self::new(rotation, DVec3::ZERO)
    }

    /// The pure translation `q ↦ q + translation`.
    #[inline]
    #[must_use]
    pub const fn from_translation(translation: DVec3) -> Self {
        Self::new(DMat3::IDENTITY, translation)
    }

    /// The homogeneous matrix `[[R, t], [0, 1]]`.
    #[inline]
    #[must_use]
    pub fn to_homogeneous(&self) -> DMat4 {
        DMat4::from_mat3_translation(self.rotation, self.translation)
    }

    /// The motion of a homogeneous matrix, or `None` unless its bottom row is `(0, 0, 0, 1)` and
    /// its upper-left block is a rotation, both within `1e-9` (see [`so3::is_rotation`]), and its
    /// translation is finite. The block and translation are taken as they are (not
    /// re-orthonormalised).
    #[must_use]
    pub fn from_homogeneous(m: DMat4) -> Option<Self> {
        let bottom = m.row(3) - DVec4::W;
        let rotation = DMat3::from_mat4(m);
        let translation = m.w_axis.truncate();
        let bottom_ok = bottom.abs().max_element() <= HOMOGENEOUS_TOL;
        (bottom_ok && so3::is_rotation(rotation, HOMOGENEOUS_TOL) && translation.is_finite())
            .then(|| Self::new(rotation, translation))
    }

    /// The inverse motion `(Rᵀ, -Rᵀ t)`.
    #[inline]
    #[must_use]
    pub fn inverse(&self) -> Self {
        let rt = self.rotation.transpose();
        Self::new(rt, -(rt * self.translation))
    }

    /// The composition `self ∘ rhs` (apply `rhs` first): `(R₁ R₂, R₁ t₂ + t₁)`. Same as
    /// `self * rhs`.
    #[inline]
    #[must_use]
    pub fn compose(&self, rhs: &Se3) -> Self {
        Self::new(self.rotation * rhs.rotation, self.rotation * rhs.translation + self.translation)
    }

    /// The image of the point `p`: `R p + t`.
    #[inline]
    #[must_use]
    pub fn transform_point(&self, p: DVec3) -> DVec3 {
        self.rotation * p + self.translation
    }

    /// The image of the free vector `d` (a difference of points): `R d`.
    #[inline]
    #[must_use]
    pub fn transform_vector(&self, d: DVec3) -> DVec3 {
        self.rotation * d
    }

    /// The exponential map `se(3) → SE(3)`: `exp(ξ̂) = [[exp(ω̂), J_l(ω) v], [0, 1]]`.
    ///
    /// Valid for any `‖ω‖` (including `0`, a pure translation by `v`). With `ω` a unit vector
    /// and `ξ` scaled by `θ`, this is Murray, Li & Sastry's
    /// `[[e^{ω̂θ}, (I - e^{ω̂θ})(ω × v) + ω ωᵀ v θ], [0, 1]]`.
    #[inline]
    #[must_use]
    pub fn exp(xi: Twist) -> Self {
        Self::new(so3::exp(xi.w), so3::left_jacobian(xi.w) * xi.v)
    }

    /// `exp(θ ξ̂)`: the motion generated by moving along the screw of `xi` for time `theta`.
    #[inline]
    #[must_use]
    pub fn exp_screw(xi: Twist, theta: f64) -> Self {
        Self::exp(xi.scale(theta))
    }

    /// The logarithm `SE(3) → se(3)`: `ω = so3::log(R)` (so `‖ω‖ ∈ [0, π]`) and
    /// `v = J_l(ω)⁻¹ t`.
    ///
    /// `Se3::exp(g.log()) == g` always (to rounding); `Se3::exp(xi).log() == xi` whenever
    /// `‖xi.w‖ < π`. At a rotation angle of exactly `π` the sign of `ω` is arbitrary, as in
    /// [`so3::log`].
    #[inline]
    #[must_use]
    pub fn log(&self) -> Twist {
        let w = so3::log(self.rotation);
        Twist::new(so3::left_jacobian_inv(w) * self.translation, w)
    }

    /// The 6x6 adjoint matrix (row-major, twists in `(v, ω)` order):
    /// `Ad_g = [[R, t̂ R], [0, R]]`, so that `Ad_g ξ = ` [`adjoint`](Self::adjoint)`(ξ)`.
    #[must_use]
    pub fn adjoint_matrix(&self) -> [[f64; 6]; 6] {
        let r = self.rotation;
        let tr = so3::hat(self.translation) * r;
        let mut m = [[0.0; 6]; 6];
        for i in 0..3 {
            for j in 0..3 {
                // DMat3::col(j)[i] is the entry in row i, column j.
                m[i][j] = r.col(j)[i];
                m[i][j + 3] = tr.col(j)[i];
                m[i + 3][j + 3] = r.col(j)[i];
            }
        }
        m
    }

    /// The adjoint action `Ad_g ξ = (R v + t × (R ω), R ω)`, the twist of `g ξ̂ g⁻¹`.
    ///
    /// If `ξ` is a body twist expressed in frame `b` and `self = g_ab`, the result is the same
    /// motion expressed in frame `a`; `g exp(ξ) g⁻¹ = exp(Ad_g ξ)`.
    #[inline]
    #[must_use]
    pub fn adjoint(&self, xi: Twist) -> Twist {
        let rw = self.rotation * xi.w;
        Twist::new(self.rotation * xi.v + self.translation.cross(rw), rw)
    }

    /// The inverse adjoint action `Ad_g⁻¹ ξ = Ad_{g⁻¹} ξ = (Rᵀ (v - t × ω), Rᵀ ω)`.
    #[inline]
    #[must_use]
    pub fn adjoint_inv(&self, xi: Twist) -> Twist {
        let rt = self.rotation.transpose();
        Twist::new(rt * (xi.v - self.translation.cross(xi.w)), rt * xi.w)
    }
}

impl Mul for Se3 {
    type Output = Se3;
    /// Composition: `(g * h)(q) = g(h(q))`.
    #[inline]
    fn mul(self, rhs: Se3) -> Se3 {
        self.compose(&rhs)
    }
}

impl MulAssign for Se3 {
    /// `g *= h` sets `g` to `g * h`.
    #[inline]
    fn mul_assign(&mut self, rhs: Se3) {
        *self = self.compose(&rhs);
    }
}

/// A screw motion (Chasles): rotation by `magnitude` radians about the line through `point` with
/// direction `axis`, together with translation by `pitch · magnitude` along `axis`.
///
/// A pure translation has `pitch == f64::INFINITY`: it moves by `magnitude` along `axis`
/// (`point` is then the origin and carries no meaning). Convert with [`Screw::to_twist`] and
/// [`Twist::to_screw`]; `Se3::exp(screw.to_twist())` is the motion. Note that JSON cannot
/// represent an infinite pitch (serde_json writes `null`), so pure-translation screws do not
/// round-trip through JSON; store the twist instead.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Screw {
    /// Unit direction of the axis (for a pure translation: the direction of translation).
    pub axis: DVec3,
    /// The point of the axis closest to the origin (the origin for a pure translation).
    pub point: DVec3,
    /// Translation per radian of rotation; `f64::INFINITY` for a pure translation.
    pub pitch: f64,
    /// Rotation angle in radians, or the translation distance for a pure translation.
    pub magnitude: f64,
}

impl Screw {
    /// The twist of this screw: `ω = M a`, `v = -ω × q + h ω` (axis `a`, point `q`, pitch `h`,
    /// magnitude `M`); for an infinite pitch `ω = 0`, `v = M a`.
    #[inline]
    #[must_use]
    pub fn to_twist(&self) -> Twist {
        if self.pitch.is_infinite() {
            Twist::new(self.axis * self.magnitude, DVec3::ZERO)
        } else {
            let w = self.axis * self.magnitude;
            Twist::new(self.point.cross(w) + self.pitch * w, w)
        }
    }

    /// The screw of `xi`, or `None` for the zero twist; same as [`Twist::to_screw`].
    #[inline]
    #[must_use]
    pub fn from_twist(xi: Twist) -> Option<Self> {
        xi.to_screw()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;
    use std::f64::consts::PI;

    type Mat6 = [[f64; 6]; 6];

    fn frobenius4(m: DMat4) -> f64 {
        m.to_cols_array().iter().map(|e| e * e).sum::<f64>().sqrt()
    }

    fn twist_err(a: Twist, b: Twist) -> f64 {
        (a - b).to_array().iter().map(|e| e * e).sum::<f64>().sqrt()
    }

    fn twist_norm(a: Twist) -> f64 {
        twist_err(a, Twist::ZERO)
    }

    fn random_unit(rng: &mut ChaCha8Rng) -> DVec3 {
        let z: f64 = rng.random_range(-1.0..=1.0);
        let phi: f64 = rng.random_range(0.0..(2.0 * PI));
        let r = (1.0 - z * z).max(0.0).sqrt();
        DVec3::new(r * phi.cos(), r * phi.sin(), z)
    }

    fn random_vec(rng: &mut ChaCha8Rng, scale: f64) -> DVec3 {
        DVec3::new(
            rng.random_range(-scale..scale),
            rng.random_range(-scale..scale),
            rng.random_range(-scale..scale),
        )
    }

    fn random_twist(rng: &mut ChaCha8Rng, max_angle: f64) -> Twist {
        let w = random_unit(rng) * rng.random_range(0.0..max_angle);
        Twist::new(random_vec(rng, 2.0), w)
    }

    fn random_se3(rng: &mut ChaCha8Rng) -> Se3 {
        let r = DMat3::from_axis_angle(random_unit(rng), rng.random_range(0.0..=PI));
        Se3::new(r, random_vec(rng, 3.0))
    }

    /// Independent reference: 4x4 matrix exponential by scaling and squaring with a Taylor series.
    fn expm_reference(a: DMat4) -> DMat4 {
        let mut squarings = 0;
        let mut scaled = a;
        while frobenius4(scaled) > 0.25 {
            scaled *= 0.5;
            squarings += 1;
        }
        let mut term = DMat4::IDENTITY;
        let mut sum = DMat4::IDENTITY;
        for k in 1..=25 {
            term = term * scaled * (1.0 / k as f64);
            sum += term;
        }
        for _ in 0..squarings {
            sum = sum * sum;
        }
        sum
    }

    fn mat6_mul(a: &Mat6, b: &Mat6) -> Mat6 {
        let mut c = [[0.0; 6]; 6];
        for i in 0..6 {
            for j in 0..6 {
                c[i][j] = (0..6).map(|k| a[i][k] * b[k][j]).sum();
            }
        }
        c
    }

    fn mat6_apply(a: &Mat6, xi: Twist) -> Twist {
        let x = xi.to_array();
        let mut y = [0.0; 6];
        for i in 0..6 {
            y[i] = (0..6).map(|k| a[i][k] * x[k]).sum();
        }
        Twist::from_array(y)
    }

    fn mat6_max_diff(a: &Mat6, b: &Mat6) -> f64 {
        let mut m = 0.0_f64;
        for i in 0..6 {
            for j in 0..6 {
                m = m.max((a[i][j] - b[i][j]).abs());
            }
        }
        m
    }

    #[test]
    fn twist_array_order_is_linear_then_angular() {
        let xi = Twist::new(DVec3::new(1.0, 2.0, 3.0), DVec3::new(4.0, 5.0, 6.0));
        assert_eq!(xi.to_array(), [1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
        assert_eq!(Twist::from_array(xi.to_array()), xi);
        assert_eq!(Twist::zero(), Twist::new(DVec3::ZERO, DVec3::ZERO));
        assert_eq!(Twist::default(), Twist::ZERO);
        // ξ̂ = [[ω̂, v], [0, 0]].
        let h = xi.hat();
        assert_eq!(h.w_axis, DVec4::new(1.0, 2.0, 3.0, 0.0));
        assert_eq!(h.row(3), DVec4::ZERO);
        assert_eq!(DMat3::from_mat4(h), so3::hat(xi.w));
        assert_eq!(Twist::vee(h), xi);
    }

    #[test]
    fn twist_arithmetic() {
        let a = Twist::new(DVec3::new(1.0, 2.0, 3.0), DVec3::new(4.0, 5.0, 6.0));
        let b = Twist::new(DVec3::new(-1.0, 0.5, 2.0), DVec3::new(0.0, -3.0, 1.0));
        assert_eq!(a + b, Twist::new(DVec3::new(0.0, 2.5, 5.0), DVec3::new(4.0, 2.0, 7.0)));
        assert_eq!(a - b, Twist::new(DVec3::new(2.0, 1.5, 1.0), DVec3::new(4.0, 8.0, 5.0)));
        assert_eq!(a * 2.0, Twist::new(DVec3::new(2.0, 4.0, 6.0), DVec3::new(8.0, 10.0, 12.0)));
        assert_eq!(2.0 * a, a.scale(2.0));
        assert_eq!(-a, a.scale(-1.0));
        let mut c = a;
        c += b;
        c -= b;
        assert_eq!(c, a);
    }

    #[test]
    fn bracket_is_the_matrix_commutator() {
        let mut rng = ChaCha8Rng::seed_from_u64(20);
        for _ in 0..1000 {
            let a = random_twist(&mut rng, 3.0);
            let b = random_twist(&mut rng, 3.0);
            let commutator = a.hat() * b.hat() - b.hat() * a.hat();
            assert_eq!(commutator.row(3), DVec4::ZERO);
            let err = twist_err(a.bracket(b), Twist::vee(commutator));
            assert!(err <= 1e-14, "{err:e}");
            assert!(twist_err(a.bracket(b), -b.bracket(a)) <= 1e-15);
            // Jacobi identity.
            let c = random_twist(&mut rng, 3.0);
            let jacobi = a.bracket(b.bracket(c)) + b.bracket(c.bracket(a)) + c.bracket(a.bracket(b));
            assert!(twist_norm(jacobi) <= 1e-13, "{jacobi:?}");
        }
    }

    #[test]
    fn bracket_is_the_derivative_of_the_adjoint() {
        let mut rng = ChaCha8Rng::seed_from_u64(21);
        let h = 1e-5;
        for _ in 0..200 {
            let xi = random_twist(&mut rng, 3.0);
            let eta = random_twist(&mut rng, 3.0);
            let plus = Se3::exp(xi.scale(h)).adjoint(eta);
            let minus = Se3::exp(xi.scale(-h)).adjoint(eta);
            let derivative = (plus - minus).scale(0.5 / h);
            // Central differences: truncation h² |ξ|³ |η| / 6 ≈ 1e-9, rounding ε/h ≈ 1e-11.
            let err = twist_err(derivative, xi.bracket(eta));
            assert!(err <= 1e-8, "{err:e}");
        }
    }

    #[test]
    fn exp_matches_matrix_exponential_reference() {
        let mut rng = ChaCha8Rng::seed_from_u64(22);
        let mut twists: Vec<Twist> = (0..2000).map(|_| random_twist(&mut rng, 2.0 * PI)).collect();
        for theta in [0.0, 1e-12, 1e-9, 1e-4, 1e-3 * (1.0 - 1e-12), 1e-3 * (1.0 + 1e-12), PI] {
            twists.push(Twist::new(random_vec(&mut rng, 2.0), random_unit(&mut rng) * theta));
        }
        let mut max_err = 0.0_f64;
        for xi in twists {
            let err = frobenius4(Se3::exp(xi).to_homogeneous() - expm_reference(xi.hat()));
            max_err = max_err.max(err);
            assert!(err <= 1e-13, "{xi:?}: {err:e}");
        }
        println!("se3 exp vs 4x4 scaling-and-squaring Taylor reference: max Frobenius error {max_err:e}");
    }

    #[test]
    fn exp_matches_closed_form_for_unit_axes() {
        let mut rng = ChaCha8Rng::seed_from_u64(23);
        for _ in 0..2000 {
            let w = random_unit(&mut rng);
            let v = random_vec(&mut rng, 2.0);
            let theta = rng.random_range(-2.0 * PI..2.0 * PI);
            // Murray, Li & Sastry: [[e^{ω̂θ}, (I - e^{ω̂θ})(ω × v) + ω ωᵀ v θ], [0, 1]].
            let wh = so3::hat(w);
            let r = DMat3::IDENTITY + wh * theta.sin() + wh * wh * (1.0 - theta.cos());
            let t = (DMat3::IDENTITY - r) * w.cross(v) + w * w.dot(v) * theta;
            let g = Se3::exp_screw(Twist::new(v, w), theta);
            let err = frobenius4(g.to_homogeneous() - Se3::new(r, t).to_homogeneous());
            assert!(err <= 1e-14 * (1.0 + v.length() * theta.abs()), "{err:e}");
        }
        // ω = 0: a pure translation by v θ.
        let v = DVec3::new(1.0, -2.0, 0.5);
        let g = Se3::exp_screw(Twist::new(v, DVec3::ZERO), 3.0);
        assert_eq!(g, Se3::from_translation(v * 3.0));
    }

    #[test]
    fn log_of_exp_reproduces_the_twist() {
        let mut rng = ChaCha8Rng::seed_from_u64(24);
        let mut twists: Vec<Twist> = (0..10_000).map(|_| random_twist(&mut rng, PI - 1e-6)).collect();
        for theta in [0.0, 1e-9, 1e-3, 2.0, PI - 1e-3, PI - 1e-6, PI - 1e-9] {
            twists.push(Twist::new(random_vec(&mut rng, 2.0), random_unit(&mut rng) * theta));
        }
        let mut max_err = 0.0_f64;
        for xi in twists {
            let err = twist_err(Se3::exp(xi).log(), xi) / twist_norm(xi).max(1.0);
            max_err = max_err.max(err);
            assert!(err <= 1e-12, "{xi:?}: {err:e}");
        }
        println!("se3 log(exp xi) = xi, |w| < π: max error / max(1,|xi|) {max_err:e}");
    }

    #[test]
    fn exp_of_log_reproduces_the_motion() {
        let mut rng = ChaCha8Rng::seed_from_u64(25);
        let mut motions: Vec<Se3> = (0..10_000).map(|_| random_se3(&mut rng)).collect();
        for theta in [0.0, 1e-9, 1e-6, PI - 1e-6, PI - 1e-9, PI] {
            for _ in 0..100 {
                let r = so3::exp_axis_angle(random_unit(&mut rng), theta);
                motions.push(Se3::new(r, random_vec(&mut rng, 3.0)));
            }
        }
        // Exact half turns about the coordinate axes and (1, 1, 0)/√2.
        for r in [
            DMat3::from_diagonal(DVec3::new(1.0, -1.0, -1.0)),
            DMat3::from_diagonal(DVec3::new(-1.0, 1.0, -1.0)),
            DMat3::from_diagonal(DVec3::new(-1.0, -1.0, 1.0)),
            DMat3::from_cols(DVec3::Y, DVec3::X, -DVec3::Z),
        ] {
            motions.push(Se3::new(r, DVec3::new(0.5, -1.0, 2.0)));
        }
        let mut max_err = 0.0_f64;
        for g in motions {
            let err = frobenius4(Se3::exp(g.log()).to_homogeneous() - g.to_homogeneous())
                / g.translation.length().max(1.0);
            max_err = max_err.max(err);
            assert!(err <= 1e-12, "{g:?}: {err:e}");
        }
        println!("se3 exp(log g) = g: max Frobenius error / max(1,|t|) {max_err:e}");
    }

    #[test]
    fn inverse_composes_to_identity() {
        let mut rng = ChaCha8Rng::seed_from_u64(26);
        let identity = DMat4::IDENTITY;
        for _ in 0..1000 {
            let g = random_se3(&mut rng);
            let left = (g.inverse() * g).to_homogeneous();
            let right = (g * g.inverse()).to_homogeneous();
            assert!(frobenius4(left - identity) <= 1e-14);
            assert!(frobenius4(right - identity) <= 1e-14);
            let p = random_vec(&mut rng, 5.0);
            assert!((g.inverse().transform_point(g.transform_point(p)) - p).length() <= 1e-14);
        }
        assert_eq!(Se3::IDENTITY.inverse(), Se3::IDENTITY);
        assert_eq!(Se3::default(), Se3::IDENTITY);
    }

    #[test]
    fn compose_and_transforms_match_homogeneous_matrices() {
        let mut rng = ChaCha8Rng::seed_from_u64(27);
        for _ in 0..1000 {
            let g = random_se3(&mut rng);
            let h = random_se3(&mut rng);
            let product = g.to_homogeneous() * h.to_homogeneous();
            assert!(frobenius4((g * h).to_homogeneous() - product) <= 1e-14);
            assert_eq!(g * h, g.compose(&h));
            let mut k = g;
            k *= h;
            assert_eq!(k, g * h);
            let p = random_vec(&mut rng, 5.0);
            let hp = g.to_homogeneous() * p.extend(1.0);
            assert!((g.transform_point(p) - hp.truncate()).length() <= 1e-14);
            let hv = g.to_homogeneous() * p.extend(0.0);
            assert!((g.transform_vector(p) - hv.truncate()).length() <= 1e-14);
        }
        let t = DVec3::new(1.0, 2.0, 3.0);
        assert_eq!(Se3::from_translation(t).transform_point(DVec3::ZERO), t);
        assert_eq!(Se3::from_translation(t).transform_vector(DVec3::X), DVec3::X);
        let r = so3::exp(DVec3::new(0.0, 0.0, PI / 2.0));
        assert!((Se3::from_rotation(r).transform_point(DVec3::X) - DVec3::Y).length() <= 1e-15);
    }

    #[test]
    fn homogeneous_round_trip_and_rejection() {
        let mut rng = ChaCha8Rng::seed_from_u64(28);
        for _ in 0..1000 {
            let g = random_se3(&mut rng);
            let m = g.to_homogeneous();
            assert_eq!(m.row(3), DVec4::W);
            assert_eq!(Se3::from_homogeneous(m), Some(g));
        }
        let g = random_se3(&mut rng);
        let mut bad_row = g.to_homogeneous();
        bad_row.z_axis.w = 1e-3;
        assert_eq!(Se3::from_homogeneous(bad_row), None);
        let mut bad_corner = g.to_homogeneous();
        bad_corner.w_axis.w = 2.0;
        assert_eq!(Se3::from_homogeneous(bad_corner), None);
        let scaled = Se3::new(g.rotation * 1.01, g.translation).to_homogeneous();
        assert_eq!(Se3::from_homogeneous(scaled), None);
        let reflection = DMat3::from_diagonal(DVec3::new(-1.0, 1.0, 1.0));
        let reflected = Se3::new(reflection, g.translation).to_homogeneous();
        assert_eq!(Se3::from_homogeneous(reflected), None);
        let mut nan = g.to_homogeneous();
        nan.w_axis.x = f64::NAN;
        assert_eq!(Se3::from_homogeneous(nan), None);
    }

    #[test]
    fn adjoint_conjugates_the_exponential() {
        let mut rng = ChaCha8Rng::seed_from_u64(29);
        for _ in 0..1000 {
            let g = random_se3(&mut rng);
            let xi = random_twist(&mut rng, 2.0 * PI);
            let conjugated = g * Se3::exp(xi) * g.inverse();
            let err = frobenius4(conjugated.to_homogeneous() - Se3::exp(g.adjoint(xi)).to_homogeneous());
            assert!(err <= 1e-13, "g exp(ξ) g⁻¹ vs exp(Ad_g ξ): {err:e}");
            // Ad_g ξ is the twist of the matrix g ξ̂ g⁻¹.
            let m = g.to_homogeneous() * xi.hat() * g.inverse().to_homogeneous();
            assert!(m.row(3).abs().max_element() <= 1e-15);
            let err = twist_err(g.adjoint(xi), Twist::vee(m));
            assert!(err <= 1e-13, "Ad_g ξ vs vee(g ξ̂ g⁻¹): {err:e}");
        }
    }

    #[test]
    fn adjoint_matrix_matches_adjoint_and_composes() {
        let mut rng = ChaCha8Rng::seed_from_u64(30);
        for _ in 0..1000 {
            let g = random_se3(&mut rng);
            let h = random_se3(&mut rng);
            let xi = random_twist(&mut rng, 3.0);
            let ad_g = g.adjoint_matrix();
            assert!(twist_err(mat6_apply(&ad_g, xi), g.adjoint(xi)) <= 1e-13);
            let ad_gh = (g * h).adjoint_matrix();
            let product = mat6_mul(&ad_g, &h.adjoint_matrix());
            assert!(mat6_max_diff(&ad_gh, &product) <= 1e-13, "Ad_gh != Ad_g Ad_h");
            assert!(twist_err((g * h).adjoint(xi), g.adjoint(h.adjoint(xi))) <= 1e-13);
            // The inverse action.
            assert!(twist_err(g.adjoint_inv(g.adjoint(xi)), xi) <= 1e-13);
            assert!(twist_err(g.adjoint_inv(xi), g.inverse().adjoint(xi)) <= 1e-13);
        }
        // The block layout [[R, t̂R], [0, R]] on a pure translation: Ad (0, ω) = (t × ω, ω).
        let g = Se3::from_translation(DVec3::new(1.0, 0.0, 0.0));
        let m = g.adjoint_matrix();
        let xi = Twist::new(DVec3::ZERO, DVec3::Z);
        assert_eq!(mat6_apply(&m, xi), Twist::new(DVec3::new(0.0, -1.0, 0.0), DVec3::Z));
        assert_eq!(m[3][0], 0.0);
        assert_eq!(m[0][0], 1.0);
    }

    #[test]
    fn screw_round_trips_with_twist() {
        let mut rng = ChaCha8Rng::seed_from_u64(31);
        for _ in 0..1000 {
            let xi =
                Twist::new(random_vec(&mut rng, 2.0), random_unit(&mut rng) * rng.random_range(0.1..3.0));
            let Some(screw) = xi.to_screw() else {
                panic!("no screw for the nonzero twist {xi:?}");
            };
            assert!((screw.axis.length() - 1.0).abs() <= 1e-15);
            assert!(screw.point.dot(screw.axis).abs() <= 1e-14, "point is closest to origin");
            assert!((screw.magnitude - xi.w.length()).abs() <= 1e-15);
            assert!(twist_err(screw.to_twist(), xi) <= 1e-14);
            assert_eq!(Screw::from_twist(xi), Some(screw));
            let Some(back) = screw.to_twist().to_screw() else {
                panic!("no screw for the nonzero twist {:?}", screw.to_twist());
            };
            assert!((back.pitch - screw.pitch).abs() <= 1e-14);
            assert!((back.point - screw.point).length() <= 1e-14);
        }
    }

    #[test]
    fn screw_motion_moves_its_axis_along_itself() {
        // A revolute/helical twist: a point q on the axis, pitch h. Moving along the screw
        // by θ translates every point of the axis by h θ along it and rotates the rest about it.
        let axis = DVec3::new(1.0, 2.0, 2.0) / 3.0;
        let point = DVec3::new(2.0, -1.0, 0.0); // point · axis = 0
        let screw = Screw { axis, point, pitch: 0.25, magnitude: 1.0 };
        let theta = 1.3;
        let g = Se3::exp_screw(screw.to_twist(), theta);
        for s in [-2.0, 0.0, 1.5] {
            let on_axis = point + s * axis;
            let moved = g.transform_point(on_axis);
            assert!((moved - (on_axis + 0.25 * theta * axis)).length() <= 1e-14);
        }
        assert!((so3::log(g.rotation) - axis * theta).length() <= 1e-14);
        // Zero pitch: v = -ω × q, a pure rotation about the line.
        let revolute = Twist::new(-axis.cross(point), axis);
        assert!(twist_err(revolute, Screw { pitch: 0.0, ..screw }.to_twist()) <= 1e-15);
    }

    #[test]
    fn pure_translation_and_zero_twist() {
        let v = DVec3::new(0.0, 3.0, 4.0);
        let xi = Twist::new(v, DVec3::ZERO);
        let Some(screw) = xi.to_screw() else {
            panic!("no screw for a pure translation");
        };
        assert_eq!(screw.pitch, f64::INFINITY);
        assert_eq!(screw.magnitude, 5.0);
        assert_eq!(screw.axis, DVec3::new(0.0, 0.6, 0.8));
        assert_eq!(screw.point, DVec3::ZERO);
        assert!(twist_err(screw.to_twist(), xi) <= 1e-15);
        assert_eq!(Se3::exp(screw.to_twist()).translation, screw.to_twist().v);
        assert_eq!(Twist::ZERO.to_screw(), None);
        assert_eq!(Screw::from_twist(Twist::zero()), None);
    }

    /// serde_json (without its `float_roundtrip` feature) parses floats to within an ulp, not
    /// always exactly, so the values are compared to 1e-15 relative; the field layout is exact.
    #[cfg(feature = "serde")]
    #[test]
    fn serde_round_trip() -> Result<(), serde_json::Error> {
        let xi = Twist::new(DVec3::new(0.1, -2.0, 3.5), DVec3::new(1.0, 0.25, -0.5));
        let g = Se3::exp(xi);
        let Some(screw) = xi.to_screw() else {
            panic!("no screw for the nonzero twist {xi:?}");
        };
        let json = serde_json::to_string(&xi)?;
        assert!(json.starts_with(r#"{"v":["#) && json.contains(r#"],"w":["#), "{json}");
        let back: Twist = serde_json::from_str(&json)?;
        assert!(twist_err(back, xi) <= 1e-15 * twist_norm(xi));
        let back: Se3 = serde_json::from_str(&serde_json::to_string(&g)?)?;
        let g_norm = frobenius4(g.to_homogeneous());
        assert!(frobenius4(back.to_homogeneous() - g.to_homogeneous()) <= 1e-15 * g_norm);
        let back: Screw = serde_json::from_str(&serde_json::to_string(&screw)?)?;
        assert!((back.axis - screw.axis).length() <= 1e-15);
        assert!((back.point - screw.point).length() <= 1e-15 * screw.point.length());
        assert!((back.pitch - screw.pitch).abs() <= 1e-15 * screw.pitch.abs());
        assert!((back.magnitude - screw.magnitude).abs() <= 1e-15 * screw.magnitude);
        Ok(())
    }
}
