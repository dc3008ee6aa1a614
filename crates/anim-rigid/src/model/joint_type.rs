//! The kinds of joint and their motion: [`Axis`] and [`JointType`] (`nq`, `nv`, the joint
//! transform `X_J(q)` and the motion subspace `S`). Part of [`crate::model`], which re-exports
//! them.

use anim_core::glam::{DMat3, DQuat, DVec3};
use anim_core::lie::{Se3, Twist};

/// The direction of a revolute or prismatic joint, in the joint's own frame.
///
/// The coordinate axes get their own variants so that forward kinematics can use the cheap
/// rotation `[[c, -s, 0], [s, c, 0], [0, 0, 1]]` instead of Rodrigues' formula (Pinocchio does
/// the same with `JointModelRZ` and friends).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Axis {
    /// `+x`.
    X,
    /// `+y`.
    Y,
    /// `+z`.
    Z,
    /// Any other unit vector.
    Unaligned(DVec3),
}

impl Axis {
    /// The axis along `v`, normalised, or `None` when `v` is zero or not finite. A vector that
    /// is exactly `+x`, `+y` or `+z` after normalisation becomes [`Axis::X`], [`Axis::Y`] or
    /// [`Axis::Z`].
    #[must_use]
    pub fn from_vector(v: DVec3) -> Option<Self> {
        let n = v.length();
        if !n.is_finite() || n == 0.0 {
            return None;
        }
        let u = v / n;
        Some(if u == DVec3::X {
            Axis::X
        } else if u == DVec3::Y {
            Axis::Y
        } else if u == DVec3::Z {
            Axis::Z
        } else {
            Axis::Unaligned(u)
        })
    }

    /// The unit vector of the axis.
    #[inline]
    #[must_use]
    pub fn vector(&self) -> DVec3 {
        match *self {
            Axis::X => DVec3::X,
            Axis::Y => DVec3::Y,
            Axis::Z => DVec3::Z,
            Axis::Unaligned(u) => u,
        }
    }

    /// Two unit vectors `(e₁, e₂)` spanning the plane normal to this axis, with `e₁ × e₂` the
    /// axis: `(y, z)` for `+x`, `(z, x)` for `+y`, `(x, y)` for `+z` (Pinocchio's planar joint),
    /// and for any other `n`, `e₁ = n × c / |n × c|` with `c` the coordinate axis least aligned
    /// with `n` (the first of them on a tie), `e₂ = n × e₁`.
    #[must_use]
    pub fn plane_basis(&self) -> (DVec3, DVec3) {
        match *self {
            Axis::X => (DVec3::Y, DVec3::Z),
            Axis::Y => (DVec3::Z, DVec3::X),
            Axis::Z => (DVec3::X, DVec3::Y),
            Axis::Unaligned(n) => {
                let a = n.abs();
                let c = if a.x <= a.y && a.x <= a.z {
                    DVec3::X
                } else if a.y <= a.z {
                    DVec3::Y
                } else {
                    DVec3::Z
                };
                let e1 = n.cross(c).normalize();
                (e1, n.cross(e1))
            }
        }
    }

    /// The rotation by `angle` about this axis.
    #[inline]
    #[must_use]
    pub fn rotation(&self, angle: f64) -> DMat3 {
        let (s, c) = angle.sin_cos();
        match *self {
            Axis::X => DMat3::from_cols(DVec3::X, DVec3::new(0.0, c, s), DVec3::new(0.0, -s, c)),
            Axis::Y => DMat3::from_cols(DVec3::new(c, 0.0, -s), DVec3::Y, DVec3::new(s, 0.0, c)),
            Axis::Z => DMat3::from_cols(DVec3::new(c, s, 0.0), DVec3::new(-s, c, 0.0), DVec3::Z),
            Axis::Unaligned(u) => {
                // R = c I + s û + (1 - c) u uᵀ (Rodrigues with ‖u‖ = 1).
                let t = 1.0 - c;
                let (x, y, z) = (u.x, u.y, u.z);
                DMat3::from_cols(
                    DVec3::new(c + t * x * x, t * x * y + s * z, t * x * z - s * y),
                    DVec3::new(t * x * y - s * z, c + t * y * y, t * y * z + s * x),
                    DVec3::new(t * x * z + s * y, t * y * z - s * x, c + t * z * z),
                )
            }
        }
    }
}

/// The kind of a joint and its axis.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum JointType {
    /// Rotation about an axis through the joint origin (URDF `revolute` and `continuous`).
    Revolute(Axis),
    /// Translation along an axis (URDF `prismatic`).
    Prismatic(Axis),
    /// No motion (URDF `fixed`, or a locked joint). Only present when fixed joints are not
    /// merged into their parent; the universe is also of this type.
    Fixed,
    /// A ball joint: any rotation about the joint origin, `q` a unit quaternion `(x, y, z, w)`.
    Spherical,
    /// A free (floating) joint: any rigid motion, `q = (x, y, z, qx, qy, qz, qw)`.
    Free,
    /// A planar joint (URDF `planar`): translations in the plane normal to the axis and the
    /// rotation about it, `q = (x, y, θ)` with the translation `x e₁ + y e₂`
    /// ([`Axis::plane_basis`]), `v = (vx, vy, ω)` in the joint (child) frame. Pinocchio's
    /// `JointModelPlanar` (normal `+z`) stores `(x, y, cos θ, sin θ)`; see [`crate::pinocchio`].
    Planar(Axis),
}

impl JointType {
    /// Number of configuration entries.
    #[inline]
    #[must_use]
    pub const fn nq(&self) -> usize {
        match self {
            JointType::Revolute(_) | JointType::Prismatic(_) => 1,
            JointType::Fixed => 0,
            JointType::Spherical => 4,
            JointType::Free => 7,
            JointType::Planar(_) => 3,
        }
    }

    /// Number of velocity entries (degrees of freedom).
    #[inline]
    #[must_use]
    pub const fn nv(&self) -> usize {
        match self {
            JointType::Revolute(_) | JointType::Prismatic(_) => 1,
            JointType::Fixed => 0,
            JointType::Spherical | JointType::Planar(_) => 3,
            JointType::Free => 6,
        }
    }

    /// A short name: `revolute`, `prismatic`, `fixed`, `spherical`, `free` or `planar`.
    #[must_use]
    pub const fn name(&self) -> &'static str {
        match self {
            JointType::Revolute(_) => "revolute",
            JointType::Prismatic(_) => "prismatic",
            JointType::Fixed => "fixed",
            JointType::Spherical => "spherical",
            JointType::Free => "free",
            JointType::Planar(_) => "planar",
        }
    }

    /// The joint motion `X_J(q)`: the placement of the joint's child frame in the frame the
    /// joint placement puts it at `q = neutral`. `q` is this joint's slice of the configuration
    /// (length [`nq`](Self::nq)); quaternions are assumed to be of unit length.
    #[inline]
    #[must_use]
    pub fn transform(&self, q: &[f64]) -> Se3 {
        match self {
            JointType::Revolute(axis) => Se3::from_rotation(axis.rotation(q[0])),
            JointType::Prismatic(axis) => Se3::from_translation(axis.vector() * q[0]),
            JointType::Fixed => Se3::IDENTITY,
            JointType::Spherical => Se3::from_rotation(quat_to_matrix(q[0], q[1], q[2], q[3])),
            JointType::Free => Se3::new(quat_to_matrix(q[3], q[4], q[5], q[6]), DVec3::new(q[0], q[1], q[2])),
            JointType::Planar(axis) => {
                let (e1, e2) = axis.plane_basis();
                Se3::new(axis.rotation(q[2]), e1 * q[0] + e2 * q[1])
            }
        }
    }

    /// Column `k` (`k < nv`) of the motion subspace `S`: the twist, in the joint's child frame
    /// (linear part first), produced by a unit rate of velocity entry `k`. The joint's spatial
    /// velocity is `S v_joint`; dynamics uses `S` for projections (`τ = Sᵀ f`).
    ///
    /// Revolute: `(0, a)`; prismatic: `(a, 0)`; spherical: `(0, e_k)`; free: the `k`-th unit
    /// twist (`(e_k, 0)` for `k < 3`, `(0, e_{k-3})` otherwise); planar: `(e₁, 0)`, `(e₂, 0)`,
    /// `(0, n)`.
    ///
    /// # Panics
    /// When `k >= nv`.
    #[must_use]
    #[track_caller]
    pub fn motion_subspace_column(&self, k: usize) -> Twist {
        assert!(k < self.nv(), "motion subspace column {k} of a {} joint (nv = {})", self.name(), self.nv());
        let e = |i: usize| [DVec3::X, DVec3::Y, DVec3::Z][i];
        match self {
            JointType::Revolute(axis) => Twist::new(DVec3::ZERO, axis.vector()),
            JointType::Prismatic(axis) => Twist::new(axis.vector(), DVec3::ZERO),
            JointType::Fixed => Twist::ZERO,
            JointType::Spherical => Twist::new(DVec3::ZERO, e(k)),
            JointType::Free => {
                if k < 3 {
                    Twist::new(e(k), DVec3::ZERO)
                } else {
                    Twist::new(DVec3::ZERO, e(k - 3))
                }
            }
            JointType::Planar(axis) => {
                let (e1, e2) = axis.plane_basis();
                [
                    Twist::new(e1, DVec3::ZERO),
                    Twist::new(e2, DVec3::ZERO),
                    Twist::new(DVec3::ZERO, axis.vector()),
                ][k]
            }
        }
    }
}

/// The rotation matrix of the unit quaternion `(x, y, z, w)`.
#[inline]
fn quat_to_matrix(x: f64, y: f64, z: f64, w: f64) -> DMat3 {
    DMat3::from_quat(DQuat::from_xyzw(x, y, z, w))
}
