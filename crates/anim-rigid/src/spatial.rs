//! Spatial (Plücker) vector algebra: motion and force 6-vectors, their transforms between
//! frames, the two cross products, rigid-body and articulated-body inertias:
//! Featherstone, *Rigid Body Dynamics Algorithms* (2008), chapter 2.
//!
//! # Two dual spaces
//!
//! A rigid body's velocity is one element of the 6-dimensional space `M⁶` of **motions**. Read at
//! a point `O` it is the pair (velocity of the body point passing through `O`, angular velocity):
//! `v_P = v_O + ω × OP`. Forces live in the dual space `F⁶`: a wrench read at `O` is
//! (resultant force, moment about `O`), and its moment about another point is
//! `n_P = n_O + f × OP`. The pairing `v · f = v_O·f + ω·n_O` is the power, the same at every
//! point. Keeping the spaces apart as two types, [`Motion`] and [`Force`], makes the algebra
//! type-checked: a motion can be added to a motion, a force to a force, and a motion paired with
//! a force, but `Motion + Force` does not compile.
//!
//! # Coordinates: linear first
//!
//! Featherstone writes Plücker coordinates **angular first**,
//! `v̂ = (ω, v_O)` and `f̂ = (n_O, f)`. This crate stores them **linear first**, `(v_O, ω)` and
//! `(f, n_O)`, like [`Twist`], the kinematics Jacobians and Pinocchio, so that every vector,
//! matrix and `q̇`-ordering compares entry for entry with Pinocchio. Featherstone's 6x6
//! matrices become ours by swapping the two 3x3 block rows and block columns; his
//! `X = [[E, 0], [-E r̂, E]]` is our `[[E, -E r̂], [0, E]]`.
//!
//! # Transforms
//!
//! A placement `g = ᴬM_B = (R, t)` (frame `B` seen from `A`) moves spatial vectors from `B`
//! coordinates to `A` coordinates:
//!
//! ```text
//! motion:  ᴬv = Ad_g ᴮv          v_A = R v_B + t × (R ω_B),   ω_A = R ω_B        Motion::transform
//! force:   ᴬf = Ad_g⁻ᵀ ᴮf        f_A = R f_B,                 n_A = R n_B + t × (R f_B)   Force::transform
//! ```
//!
//! and [`Motion::inverse_transform`], [`Force::inverse_transform`] go back (Pinocchio's `act`
//! and `actInv`). The force transform is the inverse transpose of the motion transform, which
//! is what keeps the power `v · f` frame-independent (tested).
//!
//! # Cross products
//!
//! The derivative of a motion vector `m` moving with velocity `v` is `v ×ₘ m`, of a force
//! `v ×f f` (Featherstone 2.9); in linear-first coordinates
//!
//! ```text
//! v ×ₘ m = (ω × m_v + v × m_ω,  ω × m_ω)                           Motion::cross
//! v ×f f = (ω × f,  ω × n + v × f)                                 Motion::cross_force
//! ```
//!
//! with `v ×f = -(v ×ₘ)ᵀ`, so `(v ×ₘ m) · f = -m · (v ×f f)` (tested). `v ×ₘ m` is the Lie
//! bracket of twists, [`Twist::bracket`].
//!
//! # Inertia
//!
//! A rigid body's [`SpatialInertia`] maps its velocity to its momentum `h = I v` (a force). With
//! mass `m`, centre of mass `c` and rotational inertia `Ī_O` about the frame origin,
//!
//! ```text
//! I v = (m v - h × ω,  Ī_O ω + h × v),     h = m c,     Ī_O = I_c - m ĉ ĉ
//! ```
//!
//! (Featherstone 2.62-2.63 in linear-first order). It is stored in exactly those ten numbers
//! `(m, h, Ī_O)`, so the composite inertia of several bodies expressed in one frame is a plain
//! sum (what CRBA accumulates). Transforms follow `ᴬI = Ad_g⁻ᵀ ᴮI Ad_g⁻¹`. An articulated-body
//! inertia (ABA) is a general symmetric positive semi-definite 6x6 matrix, [`ArticulatedInertia`],
//! stored as three 3x3 blocks `[[A, B], [Bᵀ, C]]`.
//!
//! ```compile_fail
//! use anim_rigid::spatial::{Force, Motion};
//! // A motion and a force live in dual spaces: adding them is a type error.
//! let _ = Motion::ZERO + Force::ZERO;
//! ```
//!
//! ```
//! use anim_core::glam::DVec3;
//! use anim_core::lie::Se3;
//! use anim_rigid::spatial::{Force, Motion, SpatialInertia};
//!
//! // A 2 kg body spinning at 3 rad/s about z, seen from a frame 1 m away: momentum and power.
//! let body = SpatialInertia::from_com(2.0, DVec3::ZERO, anim_core::glam::DMat3::IDENTITY * 0.1);
//! let v = Motion::new(DVec3::ZERO, DVec3::Z * 3.0);
//! let h: Force = body * v;
//! let g = Se3::from_translation(DVec3::X);
//! let (v_a, h_a) = (v.transform(&g), body.transform(&g) * v.transform(&g));
//! assert!((h_a.linear - h.transform(&g).linear).length() < 1e-15);
//! assert!((v_a.dot(&h_a) - v.dot(&h)).abs() < 1e-14); // 2 T = 0.9 J, the same in every frame
//! ```
//!
//! All types are plain `f64` values over glam's `DVec3`/`DMat3`, `Copy`, with no traits in the
//! interface, and every operation is `#[inline]`: the dynamics algorithms of
//! [`crate::dynamics`] are written in them and compile to straight-line code.

use std::ops::{Add, AddAssign, Mul, Neg, Sub, SubAssign};

use anim_core::glam::{DMat3, DVec3};
use anim_core::lie::{Se3, Twist};

use crate::model::Inertia;

/// `a bᵀ` as a 3x3 matrix.
#[inline(always)]
fn outer(a: DVec3, b: DVec3) -> DMat3 {
    DMat3::from_cols(a * b.x, a * b.y, a * b.z)
}

/// `â b̂` for the cross-product matrices of `a` and `b` (`= b aᵀ - (a·b) I`), with each diagonal
/// entry summed from the two other coordinates (`-(a_y b_y + a_z b_z)`, ...) rather than as
/// `b_x a_x - a·b`, which cancels when `a` lies near a coordinate axis (a centre of mass on a
/// joint axis).
#[inline(always)]
fn hat_hat(a: DVec3, b: DVec3) -> DMat3 {
    let (xx, yy, zz) = (a.x * b.x, a.y * b.y, a.z * b.z);
    DMat3::from_cols(
        DVec3::new(-(yy + zz), b.y * a.x, b.z * a.x),
        DVec3::new(b.x * a.y, -(xx + zz), b.z * a.y),
        DVec3::new(b.x * a.z, b.y * a.z, -(xx + yy)),
    )
}

/// `R S Rᵀ` for a rotation `R` and a symmetric `S`, as its upper triangle
/// `[x00, x01, x02, x11, x12, x22]`, in 36 multiplications instead of 54.
///
/// Split `S = s₂₂ I + M + N` with `M` zero in its last row (rows `m₀ = (s₀₀ - s₂₂, s₀₁, 2 s₀₂)`,
/// `m₁ = (s₀₁, s₁₁ - s₂₂, 2 s₁₂)`) and `N = n̂` skew, `n = (s₁₂, -s₀₂, 0)`. Then
/// `R (s₂₂ I) Rᵀ = s₂₂ I`, `R M Rᵀ = c₀ (R m₀)ᵀ + c₁ (R m₁)ᵀ` with `c_k` the columns of `R`, and
/// `R n̂ Rᵀ = (R n)^`; the result is symmetric, so only its upper triangle is evaluated.
#[inline(always)]
fn rotate_symmetric(r: &DMat3, s: &DMat3) -> [f64; 6] {
    let (s00, s01, s02) = (s.x_axis.x, s.y_axis.x, s.z_axis.x);
    let (s11, s12, s22) = (s.y_axis.y, s.z_axis.y, s.z_axis.z);
    let (c0, c1) = (r.x_axis, r.y_axis);
    let y0 = *r * DVec3::new(s00 - s22, s01, 2.0 * s02);
    let y1 = *r * DVec3::new(s01, s11 - s22, 2.0 * s12);
    let w = c0 * s12 - c1 * s02;
    [
        c0.x * y0.x + c1.x * y1.x + s22,
        c0.x * y0.y + c1.x * y1.y - w.z,
        c0.x * y0.z + c1.x * y1.z + w.y,
        c0.y * y0.y + c1.y * y1.y + s22,
        c0.y * y0.z + c1.y * y1.z - w.x,
        c0.z * y0.z + c1.z * y1.z + s22,
    ]
}

/// A spatial motion vector (a rigid-body velocity or acceleration), **linear part first**:
/// `(v_O, ω)`, the velocity of the body point at the frame origin `O` and the angular velocity.
///
/// The same quantity as a [`Twist`] (conversions are free), typed apart from [`Force`].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Motion {
    /// Linear part `v_O`.
    pub linear: DVec3,
    /// Angular part `ω`.
    pub angular: DVec3,
}

impl Motion {
    /// The zero motion.
    pub const ZERO: Self = Self::new(DVec3::ZERO, DVec3::ZERO);

    /// The motion `(linear, angular)`.
    #[inline]
    #[must_use]
    pub const fn new(linear: DVec3, angular: DVec3) -> Self {
        Self { linear, angular }
    }

    /// The coordinates `[v_x, v_y, v_z, ω_x, ω_y, ω_z]`.
    #[inline]
    #[must_use]
    pub const fn to_array(&self) -> [f64; 6] {
        [self.linear.x, self.linear.y, self.linear.z, self.angular.x, self.angular.y, self.angular.z]
    }

    /// The motion of the coordinates `[v_x, v_y, v_z, ω_x, ω_y, ω_z]`.
    #[inline]
    #[must_use]
    pub const fn from_array(a: [f64; 6]) -> Self {
        Self::new(DVec3::new(a[0], a[1], a[2]), DVec3::new(a[3], a[4], a[5]))
    }

    /// The power `v · f = v_O · f + ω · n_O` of force `f` on this motion.
    #[inline]
    #[must_use]
    pub fn dot(&self, f: &Force) -> f64 {
        self.linear.dot(f.linear) + self.angular.dot(f.angular)
    }

    /// The motion cross product `self ×ₘ m = (ω × m_v + v × m_ω, ω × m_ω)`: the rate of change of
    /// `m` when it moves with velocity `self` (Featherstone's `crm`, the Lie bracket).
    #[inline]
    #[must_use]
    pub fn cross(&self, m: &Motion) -> Motion {
        Motion::new(
            self.angular.cross(m.linear) + self.linear.cross(m.angular),
            self.angular.cross(m.angular),
        )
    }

    /// The force cross product `self ×f f = (ω × f, ω × n + v × f)`: the rate of change of a
    /// force `f` moving with velocity `self` (Featherstone's `crf`, `= -(self ×ₘ)ᵀ`).
    #[inline]
    #[must_use]
    pub fn cross_force(&self, f: &Force) -> Force {
        Force::new(self.angular.cross(f.linear), self.angular.cross(f.angular) + self.linear.cross(f.linear))
    }

    /// This motion, given in frame `B`, expressed in frame `A` with `g = ᴬM_B`:
    /// `Ad_g v = (R v + t × R ω, R ω)` (Pinocchio's `g.act(v)`).
    #[inline]
    #[must_use]
    pub fn transform(&self, g: &Se3) -> Motion {
        let w = g.rotation * self.angular;
        Motion::new(g.rotation * self.linear + g.translation.cross(w), w)
    }

    /// This motion, given in frame `A`, expressed in frame `B` with `g = ᴬM_B`:
    /// `Ad_g⁻¹ v = (Rᵀ (v - t × ω), Rᵀ ω)` (Pinocchio's `g.actInv(v)`).
    #[inline]
    #[must_use]
    pub fn inverse_transform(&self, g: &Se3) -> Motion {
        let lin = self.linear - g.translation.cross(self.angular);
        Motion::new(g.rotation.transpose() * lin, g.rotation.transpose() * self.angular)
    }

    /// The motion scaled by `s`.
    #[inline]
    #[must_use]
    pub fn scale(&self, s: f64) -> Motion {
        Motion::new(self.linear * s, self.angular * s)
    }

    /// Whether every coordinate is finite.
    #[inline]
    #[must_use]
    pub fn is_finite(&self) -> bool {
        self.linear.is_finite() && self.angular.is_finite()
    }

    /// The 6x6 matrix of [`transform`](Self::transform) (row-major, linear first):
    /// `Ad_g = [[R, t̂ R], [0, R]]`.
    #[must_use]
    pub fn transform_matrix(g: &Se3) -> [[f64; 6]; 6] {
        g.adjoint_matrix()
    }

    /// The 6x6 matrix of `m ↦ self ×ₘ m` (row-major): `[[ω̂, v̂], [0, ω̂]]`.
    #[must_use]
    pub fn cross_matrix(&self) -> [[f64; 6]; 6] {
        let (w, v) = (anim_core::lie::so3::hat(self.angular), anim_core::lie::so3::hat(self.linear));
        let mut m = [[0.0; 6]; 6];
        for i in 0..3 {
            for j in 0..3 {
                m[i][j] = w.col(j)[i];
                m[i][j + 3] = v.col(j)[i];
                m[i + 3][j + 3] = w.col(j)[i];
            }
        }
        m
    }
}

impl From<Twist> for Motion {
    #[inline]
    fn from(t: Twist) -> Self {
        Motion::new(t.v, t.w)
    }
}

impl From<Motion> for Twist {
    #[inline]
    fn from(m: Motion) -> Self {
        Twist::new(m.linear, m.angular)
    }
}

/// A spatial force vector (a wrench or a momentum), **linear part first**: `(f, n_O)`, the
/// resultant force and the moment about the frame origin `O`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Force {
    /// Linear part `f` (the resultant).
    pub linear: DVec3,
    /// Angular part `n_O` (the moment about the origin).
    pub angular: DVec3,
}

impl Force {
    /// The zero force.
    pub const ZERO: Self = Self::new(DVec3::ZERO, DVec3::ZERO);

    /// The force `(linear, angular)`.
    #[inline]
    #[must_use]
    pub const fn new(linear: DVec3, angular: DVec3) -> Self {
        Self { linear, angular }
    }

    /// The coordinates `[f_x, f_y, f_z, n_x, n_y, n_z]`.
    #[inline]
    #[must_use]
    pub const fn to_array(&self) -> [f64; 6] {
        [self.linear.x, self.linear.y, self.linear.z, self.angular.x, self.angular.y, self.angular.z]
    }

    /// The force of the coordinates `[f_x, f_y, f_z, n_x, n_y, n_z]`.
    #[inline]
    #[must_use]
    pub const fn from_array(a: [f64; 6]) -> Self {
        Self::new(DVec3::new(a[0], a[1], a[2]), DVec3::new(a[3], a[4], a[5]))
    }

    /// The power `f · v` of this force on motion `v`.
    #[inline]
    #[must_use]
    pub fn dot(&self, v: &Motion) -> f64 {
        v.dot(self)
    }

    /// This force, given in frame `B`, expressed in frame `A` with `g = ᴬM_B`:
    /// `Ad_g⁻ᵀ f = (R f, R n + t × R f)` (Pinocchio's `g.act(f)`).
    #[inline]
    #[must_use]
    pub fn transform(&self, g: &Se3) -> Force {
        let f = g.rotation * self.linear;
        Force::new(f, g.rotation * self.angular + g.translation.cross(f))
    }

    /// This force, given in frame `A`, expressed in frame `B` with `g = ᴬM_B`:
    /// `Ad_gᵀ f = (Rᵀ f, Rᵀ (n - t × f))` (Pinocchio's `g.actInv(f)`).
    #[inline]
    #[must_use]
    pub fn inverse_transform(&self, g: &Se3) -> Force {
        let n = self.angular - g.translation.cross(self.linear);
        Force::new(g.rotation.transpose() * self.linear, g.rotation.transpose() * n)
    }

    /// The force scaled by `s`.
    #[inline]
    #[must_use]
    pub fn scale(&self, s: f64) -> Force {
        Force::new(self.linear * s, self.angular * s)
    }

    /// Whether every coordinate is finite.
    #[inline]
    #[must_use]
    pub fn is_finite(&self) -> bool {
        self.linear.is_finite() && self.angular.is_finite()
    }

    /// The 6x6 matrix of [`transform`](Self::transform) (row-major, linear first):
    /// `Ad_g⁻ᵀ = [[R, 0], [t̂ R, R]]`.
    #[must_use]
    pub fn transform_matrix(g: &Se3) -> [[f64; 6]; 6] {
        let m = g.adjoint_matrix();
        let mut out = [[0.0; 6]; 6];
        // Ad_g⁻ᵀ = [[R, 0], [t̂R, R]]: the transpose of Ad_g with the off-diagonal block moved.
        for i in 0..3 {
            for j in 0..3 {
                out[i][j] = m[i][j];
                out[i + 3][j + 3] = m[i + 3][j + 3];
                out[i + 3][j] = m[i][j + 3];
            }
        }
        out
    }
}

macro_rules! vector_ops {
    ($t:ident) => {
        impl Add for $t {
            type Output = $t;
            #[inline]
            fn add(self, rhs: $t) -> $t {
                $t::new(self.linear + rhs.linear, self.angular + rhs.angular)
            }
        }
        impl AddAssign for $t {
            #[inline]
            fn add_assign(&mut self, rhs: $t) {
                self.linear += rhs.linear;
                self.angular += rhs.angular;
            }
        }
        impl Sub for $t {
            type Output = $t;
            #[inline]
            fn sub(self, rhs: $t) -> $t {
                $t::new(self.linear - rhs.linear, self.angular - rhs.angular)
            }
        }
        impl SubAssign for $t {
            #[inline]
            fn sub_assign(&mut self, rhs: $t) {
                self.linear -= rhs.linear;
                self.angular -= rhs.angular;
            }
        }
        impl Neg for $t {
            type Output = $t;
            #[inline]
            fn neg(self) -> $t {
                $t::new(-self.linear, -self.angular)
            }
        }
        impl Mul<f64> for $t {
            type Output = $t;
            #[inline]
            fn mul(self, s: f64) -> $t {
                self.scale(s)
            }
        }
        impl Mul<$t> for f64 {
            type Output = $t;
            #[inline]
            fn mul(self, v: $t) -> $t {
                v.scale(self)
            }
        }
    };
}

vector_ops!(Motion);
vector_ops!(Force);

/// The spatial inertia of a rigid body about a frame's origin, in Featherstone's ten numbers:
/// mass `m`, first moment of mass `h = m c` and rotational inertia `Ī_O` about the origin
/// (not about the centre of mass), all in that frame's axes.
///
/// `I v = (m v_O - h × ω, Ī_O ω + h × v_O)`; composite bodies in one frame add entry by entry
/// ([`Add`]); [`transform`](Self::transform) moves the inertia to another frame. Converts from
/// and to the model's [`Inertia`] (mass, centre of mass, inertia about the centre of mass).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct SpatialInertia {
    /// Mass `m` (kg).
    pub mass: f64,
    /// First moment of mass `h = m c` (kg·m), `c` the centre of mass.
    pub first_moment: DVec3,
    /// Rotational inertia about the frame origin, `Ī_O = I_c + m (‖c‖² I - c cᵀ)` (kg·m²).
    pub rotational: DMat3,
}

impl Default for SpatialInertia {
    fn default() -> Self {
        Self::ZERO
    }
}

impl SpatialInertia {
    /// No mass.
    pub const ZERO: Self = Self { mass: 0.0, first_moment: DVec3::ZERO, rotational: DMat3::ZERO };

    /// The inertia of mass `mass` with centre of mass `com` and rotational inertia
    /// `rotational_com` about the centre of mass (parallel-axis theorem to the origin).
    #[inline]
    #[must_use]
    pub fn from_com(mass: f64, com: DVec3, rotational_com: DMat3) -> Self {
        let h = com * mass;
        Self { mass, first_moment: h, rotational: rotational_com - hat_hat(com, h) }
    }

    /// The inertia of the body `inertia` (mass, centre of mass, inertia about the centre of mass,
    /// all in a frame `B`), expressed in frame `A` with `g = ᴬM_B = (R, t)`: the same as
    /// `SpatialInertia::from(inertia).transform(g)`, computed from the centre-of-mass form in
    /// fewer operations (`c' = R c + t`, `Ī' = R I_c Rᵀ + m (|c'|² I - c' c'ᵀ)`, the symmetric
    /// product evaluated once per entry). The dynamics algorithms move every body to the world
    /// frame with it.
    #[inline]
    #[must_use]
    pub fn from_inertia_at(inertia: &Inertia, g: &Se3) -> SpatialInertia {
        let m = inertia.mass;
        let c = g.transform_point(inertia.com);
        let [s00, s01, s02, s11, s12, s22] = rotate_symmetric(&g.rotation, &inertia.rotational);
        let h = c * m;
        // m (|c|² I - c cᵀ), each diagonal entry from the two other coordinates (no cancellation).
        let (xx, yy, zz) = (h.x * c.x, h.y * c.y, h.z * c.z);
        let rotational = DMat3::from_cols(
            DVec3::new(s00 + (yy + zz), s01 - h.y * c.x, s02 - h.z * c.x),
            DVec3::new(s01 - h.x * c.y, s11 + (xx + zz), s12 - h.z * c.y),
            DVec3::new(s02 - h.x * c.z, s12 - h.y * c.z, s22 + (xx + yy)),
        );
        SpatialInertia { mass: m, first_moment: h, rotational }
    }

    /// The centre of mass `h / m` (the origin for a massless body).
    #[inline]
    #[must_use]
    pub fn com(&self) -> DVec3 {
        if self.mass > 0.0 { self.first_moment / self.mass } else { DVec3::ZERO }
    }

    /// The rotational inertia about the centre of mass, `Ī_O + m ĉ ĉ`.
    #[inline]
    #[must_use]
    pub fn rotational_about_com(&self) -> DMat3 {
        self.rotational + hat_hat(self.com(), self.first_moment)
    }

    /// The model's [`Inertia`] (mass, centre of mass, inertia about the centre of mass).
    #[must_use]
    pub fn to_inertia(&self) -> Inertia {
        Inertia::new(self.mass, self.com(), self.rotational_about_com())
    }

    /// The momentum `I v = (m v - h × ω, Ī ω + h × v)`.
    #[inline]
    #[must_use]
    pub fn mul_motion(&self, v: &Motion) -> Force {
        Force::new(
            v.linear * self.mass - self.first_moment.cross(v.angular),
            self.rotational * v.angular + self.first_moment.cross(v.linear),
        )
    }

    /// The kinetic energy `½ v · I v` of the body moving with velocity `v`.
    #[inline]
    #[must_use]
    pub fn kinetic_energy(&self, v: &Motion) -> f64 {
        0.5 * v.dot(&self.mul_motion(v))
    }

    /// This inertia, given in frame `B`, expressed in frame `A` with `g = ᴬM_B = (R, t)`:
    /// `h' = R h + m t`, `Ī' = R Ī Rᵀ - (ŷ t̂ + t̂ ŷ) - m t̂ t̂` with `y = R h`.
    #[inline]
    #[must_use]
    pub fn transform(&self, g: &Se3) -> SpatialInertia {
        let t = g.translation;
        let y = g.rotation * self.first_moment;
        let [r00, r01, r02, r11, r12, r22] = rotate_symmetric(&g.rotation, &self.rotational);
        // ŷ t̂ + t̂ ŷ + m t̂ t̂ = t zᵀ + z tᵀ - 2 (t·z) I with z = y + m t / 2 (â b̂ = b aᵀ - (a·b) I).
        let z = y + t * (0.5 * self.mass);
        let d = 2.0 * t.dot(z);
        let (a, b) = (t * z.x, t * z.y);
        let c = t * z.z;
        // S_ij = t_i z_j + z_i t_j: column j of t zᵀ is t z_j.
        let rotational = DMat3::from_cols(
            DVec3::new(r00 - 2.0 * a.x + d, r01 - a.y - b.x, r02 - a.z - c.x),
            DVec3::new(r01 - a.y - b.x, r11 - 2.0 * b.y + d, r12 - b.z - c.y),
            DVec3::new(r02 - a.z - c.x, r12 - b.z - c.y, r22 - 2.0 * c.z + d),
        );
        SpatialInertia { mass: self.mass, first_moment: y + t * self.mass, rotational }
    }

    /// This inertia, given in frame `A`, expressed in frame `B` with `g = ᴬM_B` (the inverse
    /// of [`transform`](Self::transform)).
    #[inline]
    #[must_use]
    pub fn inverse_transform(&self, g: &Se3) -> SpatialInertia {
        self.transform(&g.inverse())
    }

    /// The 6x6 matrix (row-major, linear first): `[[m I, -ĥ], [ĥ, Ī]]`.
    #[must_use]
    pub fn to_matrix(&self) -> [[f64; 6]; 6] {
        ArticulatedInertia::from(*self).to_matrix()
    }
}

impl From<Inertia> for SpatialInertia {
    #[inline]
    fn from(i: Inertia) -> Self {
        SpatialInertia::from_com(i.mass, i.com, i.rotational)
    }
}

impl From<&Inertia> for SpatialInertia {
    #[inline]
    fn from(i: &Inertia) -> Self {
        SpatialInertia::from_com(i.mass, i.com, i.rotational)
    }
}

impl Add for SpatialInertia {
    type Output = SpatialInertia;
    /// The inertia of the two bodies rigidly joined (both in the same frame).
    #[inline]
    fn add(self, rhs: SpatialInertia) -> SpatialInertia {
        SpatialInertia {
            mass: self.mass + rhs.mass,
            first_moment: self.first_moment + rhs.first_moment,
            rotational: self.rotational + rhs.rotational,
        }
    }
}

impl AddAssign for SpatialInertia {
    #[inline]
    fn add_assign(&mut self, rhs: SpatialInertia) {
        self.mass += rhs.mass;
        self.first_moment += rhs.first_moment;
        self.rotational += rhs.rotational;
    }
}

impl Mul<Motion> for SpatialInertia {
    type Output = Force;
    /// The momentum `I v` (see [`SpatialInertia::mul_motion`]).
    #[inline]
    fn mul(self, v: Motion) -> Force {
        self.mul_motion(&v)
    }
}

/// A symmetric 6x6 inertia that need not be a single rigid body's: the articulated-body inertia
/// of ABA (Featherstone ch. 7). Linear-first blocks `[[A, B], [Bᵀ, C]]`, `A`, `C` symmetric:
/// `I v = (A v_O + B ω, Bᵀ v_O + C ω)`.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct ArticulatedInertia {
    /// Linear-linear block `A` (symmetric).
    pub a: DMat3,
    /// Linear-angular block `B`.
    pub b: DMat3,
    /// Angular-angular block `C` (symmetric).
    pub c: DMat3,
}

impl Default for ArticulatedInertia {
    fn default() -> Self {
        Self::ZERO
    }
}

impl ArticulatedInertia {
    /// The zero matrix.
    pub const ZERO: Self = Self { a: DMat3::ZERO, b: DMat3::ZERO, c: DMat3::ZERO };

    /// `I v = (A v + B ω, Bᵀ v + C ω)`.
    #[inline]
    #[must_use]
    pub fn mul_motion(&self, v: &Motion) -> Force {
        Force::new(self.a * v.linear + self.b * v.angular, self.b.transpose() * v.linear + self.c * v.angular)
    }

    /// Subtracts the symmetric rank-one term `u uᵀ / d` (ABA's `Iᴬ - U D⁻¹ Uᵀ` for a
    /// one-degree-of-freedom joint).
    #[inline]
    pub fn sub_rank_one(&mut self, u: &Force, inv_d: f64) {
        let w = u.scale(inv_d);
        self.a -= outer(w.linear, u.linear);
        self.b -= outer(w.linear, u.angular);
        self.c -= outer(w.angular, u.angular);
    }

    /// Subtracts `w uᵀ` for one term of a symmetric sum `Σ_k w_k u_kᵀ` (the caller guarantees
    /// the total is symmetric; only the `A`, `B` and `C` blocks are updated).
    #[inline]
    pub fn sub_outer(&mut self, w: &Force, u: &Force) {
        self.a -= outer(w.linear, u.linear);
        self.b -= outer(w.linear, u.angular);
        self.c -= outer(w.angular, u.angular);
    }

    /// This inertia, given in frame `B`, expressed in frame `A` with `g = ᴬM_B = (R, t)`:
    /// `Ad_g⁻ᵀ I Ad_g⁻¹`. After rotating every block by `R`,
    /// `A' = A`, `B' = B - A t̂`, `C' = C + (t̂ B)ᵀ + t̂ B'` (`= C + t̂ B - Bᵀ t̂ - t̂ A t̂`), in
    /// that order of operations (Pinocchio's `SE3actOn`), each `t̂ M` a column of cross products.
    #[inline]
    #[must_use]
    pub fn transform(&self, g: &Se3) -> ArticulatedInertia {
        let r = g.rotation;
        let rt = r.transpose();
        let t = g.translation;
        let a = r * self.a * rt;
        let b = r * self.b * rt;
        let mut c = r * self.c * rt;
        let hat = |m: &DMat3| DMat3::from_cols(t.cross(m.x_axis), t.cross(m.y_axis), t.cross(m.z_axis));
        c += hat(&b).transpose();
        let b_new = (hat(&a) + b.transpose()).transpose();
        c += hat(&b_new);
        ArticulatedInertia { a, b: b_new, c }
    }

    /// The 6x6 matrix (row-major, linear first).
    #[must_use]
    pub fn to_matrix(&self) -> [[f64; 6]; 6] {
        let mut m = [[0.0; 6]; 6];
        for i in 0..3 {
            for j in 0..3 {
                m[i][j] = self.a.col(j)[i];
                m[i][j + 3] = self.b.col(j)[i];
                m[i + 3][j] = self.b.col(i)[j];
                m[i + 3][j + 3] = self.c.col(j)[i];
            }
        }
        m
    }
}

impl From<SpatialInertia> for ArticulatedInertia {
    /// The rigid body's 6x6 matrix `[[m I, -ĥ], [ĥ, Ī]]`.
    #[inline]
    fn from(i: SpatialInertia) -> Self {
        let h = i.first_moment;
        // -ĥ: column j is -(h × e_j) = e_j × h.
        let minus_h_hat = DMat3::from_cols(DVec3::X.cross(h), DVec3::Y.cross(h), DVec3::Z.cross(h));
        ArticulatedInertia { a: DMat3::from_diagonal(DVec3::splat(i.mass)), b: minus_h_hat, c: i.rotational }
    }
}

impl Add for ArticulatedInertia {
    type Output = ArticulatedInertia;
    #[inline]
    fn add(self, rhs: ArticulatedInertia) -> ArticulatedInertia {
        ArticulatedInertia { a: self.a + rhs.a, b: self.b + rhs.b, c: self.c + rhs.c }
    }
}

impl AddAssign for ArticulatedInertia {
    #[inline]
    fn add_assign(&mut self, rhs: ArticulatedInertia) {
        self.a += rhs.a;
        self.b += rhs.b;
        self.c += rhs.c;
    }
}

impl Mul<Motion> for ArticulatedInertia {
    type Output = Force;
    #[inline]
    fn mul(self, v: Motion) -> Force {
        self.mul_motion(&v)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use anim_core::lie::so3;

    type M6 = [[f64; 6]; 6];

    fn mat_vec(m: &M6, x: [f64; 6]) -> [f64; 6] {
        std::array::from_fn(|i| (0..6).map(|j| m[i][j] * x[j]).sum())
    }

    fn mat_mul(a: &M6, b: &M6) -> M6 {
        std::array::from_fn(|i| std::array::from_fn(|j| (0..6).map(|k| a[i][k] * b[k][j]).sum()))
    }

    fn transpose(a: &M6) -> M6 {
        std::array::from_fn(|i| std::array::from_fn(|j| a[j][i]))
    }

    fn max_diff(a: &[f64], b: &[f64]) -> f64 {
        a.iter().zip(b).fold(0.0_f64, |m, (x, y)| m.max((x - y).abs()))
    }

    fn flat(m: &M6) -> Vec<f64> {
        m.iter().flatten().copied().collect()
    }

    fn sample() -> (Se3, Motion, Motion, Force, SpatialInertia) {
        let g = Se3::new(so3::exp(DVec3::new(0.4, -1.1, 0.7)), DVec3::new(0.3, -0.8, 1.2));
        let v = Motion::new(DVec3::new(0.1, -0.4, 0.9), DVec3::new(1.3, 0.2, -0.6));
        let m = Motion::new(DVec3::new(-0.7, 0.5, 0.2), DVec3::new(0.3, -1.2, 0.8));
        let f = Force::new(DVec3::new(2.0, -1.0, 0.5), DVec3::new(-0.3, 0.9, 1.4));
        let i_c = DMat3::from_cols(
            DVec3::new(0.5, 0.02, -0.01),
            DVec3::new(0.02, 0.3, 0.04),
            DVec3::new(-0.01, 0.04, 0.2),
        );
        let inertia = SpatialInertia::from_com(2.5, DVec3::new(0.1, -0.2, 0.3), i_c);
        (g, v, m, f, inertia)
    }

    #[test]
    fn force_transform_is_the_inverse_transpose_and_power_is_invariant() {
        let (g, v, _, f, _) = sample();
        let xm = Motion::transform_matrix(&g);
        let xf = Force::transform_matrix(&g);
        // Xfᵀ Xm = I.
        let p = mat_mul(&transpose(&xf), &xm);
        let id: M6 = std::array::from_fn(|i| std::array::from_fn(|j| f64::from(u8::from(i == j))));
        assert!(max_diff(&flat(&p), &flat(&id)) < 1e-14);
        assert!(max_diff(&v.transform(&g).to_array(), &mat_vec(&xm, v.to_array())) < 1e-14);
        assert!(max_diff(&f.transform(&g).to_array(), &mat_vec(&xf, f.to_array())) < 1e-14);
        // v·f is the same in both frames; inverse transforms undo the transforms.
        assert!((v.transform(&g).dot(&f.transform(&g)) - v.dot(&f)).abs() < 1e-14);
        assert!(max_diff(&v.transform(&g).inverse_transform(&g).to_array(), &v.to_array()) < 1e-15);
        assert!(max_diff(&f.transform(&g).inverse_transform(&g).to_array(), &f.to_array()) < 1e-14);
        // The motion transform is the twist adjoint.
        let t: Twist = v.into();
        assert!(max_diff(&v.transform(&g).to_array(), &g.adjoint(t).to_array()) < 1e-15);
    }

    #[test]
    fn cross_products_are_dual_and_match_the_bracket() {
        let (g, v, m, f, _) = sample();
        // (v ×ₘ m)·f = -m·(v ×f f).
        assert!((v.cross(&m).dot(&f) + m.dot(&v.cross_force(&f))).abs() < 1e-14);
        let bracket = Twist::from(v).bracket(Twist::from(m));
        assert!(max_diff(&v.cross(&m).to_array(), &bracket.to_array()) < 1e-15);
        assert!(max_diff(&v.cross(&m).to_array(), &mat_vec(&v.cross_matrix(), m.to_array())) < 1e-15);
        // Cross products commute with transforms: X(v × m) = (Xv) × (Xm).
        let lhs = v.cross(&m).transform(&g);
        let rhs = v.transform(&g).cross(&m.transform(&g));
        assert!(max_diff(&lhs.to_array(), &rhs.to_array()) < 1e-14);
        let lhs = v.cross_force(&f).transform(&g);
        let rhs = v.transform(&g).cross_force(&f.transform(&g));
        assert!(max_diff(&lhs.to_array(), &rhs.to_array()) < 1e-14);
        // v ×f v·... : a motion is orthogonal to its own force cross product with any momentum.
        assert!(v.dot(&v.cross_force(&f)).abs() < 1e-14);
    }

    #[test]
    fn inertia_round_trips_and_transforms_like_the_matrix() {
        let (g, v, _, _, inertia) = sample();
        let back = inertia.to_inertia();
        let again = SpatialInertia::from(back);
        assert!((again.rotational - inertia.rotational).abs_diff_eq(DMat3::ZERO, 1e-15));
        assert!((back.com - DVec3::new(0.1, -0.2, 0.3)).length() < 1e-15);
        // Momentum by the 6x6 matrix.
        let h = inertia.mul_motion(&v);
        assert!(max_diff(&h.to_array(), &mat_vec(&inertia.to_matrix(), v.to_array())) < 1e-14);
        // ᴬI = Xfᵀ... : ᴬI (Xm v) = Xf (ᴮI v).
        let ia = inertia.transform(&g);
        let lhs = ia.mul_motion(&v.transform(&g));
        let rhs = h.transform(&g);
        assert!(max_diff(&lhs.to_array(), &rhs.to_array()) < 1e-13);
        // The transformed inertia is the rigidly moved body: same com in world, same I_c rotated.
        assert!((ia.com() - g.transform_point(inertia.com())).length() < 1e-14);
        let ic = g.rotation * inertia.rotational_about_com() * g.rotation.transpose();
        assert!((ia.rotational_about_com() - ic).abs_diff_eq(DMat3::ZERO, 1e-13));
        let back = ia.inverse_transform(&g);
        assert!((back.rotational - inertia.rotational).abs_diff_eq(DMat3::ZERO, 1e-13));
        // The centre-of-mass shortcut agrees with the general transform.
        let direct = SpatialInertia::from_inertia_at(&inertia.to_inertia(), &g);
        assert!((direct.rotational - ia.rotational).abs_diff_eq(DMat3::ZERO, 1e-14));
        assert!((direct.first_moment - ia.first_moment).length() < 1e-15);
        // Kinetic energy is frame independent.
        assert!((ia.kinetic_energy(&v.transform(&g)) - inertia.kinetic_energy(&v)).abs() < 1e-13);
        // Adding inertias is merging bodies.
        let other = SpatialInertia::from_com(0.7, DVec3::new(-0.4, 0.0, 0.2), DMat3::IDENTITY * 0.1);
        let merged = (inertia + other).to_inertia();
        let reference = inertia.to_inertia().merged(&other.to_inertia());
        assert!((merged.rotational - reference.rotational).abs_diff_eq(DMat3::ZERO, 1e-14));
        assert!((merged.com - reference.com).length() < 1e-15);
    }

    #[test]
    fn symmetric_rotation_matches_the_matrix_product() {
        let (g, _, _, _, inertia) = sample();
        let s = inertia.rotational;
        let full = g.rotation * s * g.rotation.transpose();
        let [x00, x01, x02, x11, x12, x22] = rotate_symmetric(&g.rotation, &s);
        let got =
            DMat3::from_cols(DVec3::new(x00, x01, x02), DVec3::new(x01, x11, x12), DVec3::new(x02, x12, x22));
        assert!((got - full).abs_diff_eq(DMat3::ZERO, 1e-15), "{got} vs {full}");
    }

    #[test]
    fn articulated_inertia_transform_matches_the_matrix_product() {
        let (g, v, m, _, inertia) = sample();
        // A general symmetric matrix: a rigid inertia minus a rank-one term.
        let mut ai = ArticulatedInertia::from(inertia);
        let u = ai.mul_motion(&m);
        ai.sub_rank_one(&u, 0.5 / m.dot(&u));
        let mat = ai.to_matrix();
        assert!(max_diff(&flat(&mat), &flat(&transpose(&mat))) < 1e-15, "symmetric");
        let x = Motion::transform_matrix(&g.inverse()); // Ad_g⁻¹
        let expected = mat_mul(&transpose(&x), &mat_mul(&mat, &x));
        let got = ai.transform(&g).to_matrix();
        assert!(max_diff(&flat(&got), &flat(&expected)) < 1e-13, "{got:?}\n{expected:?}");
        assert!(max_diff(&ai.mul_motion(&v).to_array(), &mat_vec(&mat, v.to_array())) < 1e-14);
        // For a rigid body it agrees with the SpatialInertia transform.
        let rigid = ArticulatedInertia::from(inertia).transform(&g).to_matrix();
        assert!(max_diff(&flat(&rigid), &flat(&inertia.transform(&g).to_matrix())) < 1e-13);
    }
}
