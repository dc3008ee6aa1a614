//! Lie groups of rigid motion: rotations SO(3) and rigid motions SE(3), with their algebras,
//! exponential and logarithm maps, Jacobians, adjoints and screws
//! (Murray, Li & Sastry 1994; Lynch & Park, *Modern Robotics*, 2017); the conventions follow Murray, Li & Sastry, *A Mathematical Introduction to Robotic
//! Manipulation* (1994), chapter 2.
//!
//! # Rotations: [`so3`]
//!
//! A rotation is a matrix `R` with `RᵀR = I`, `det R = +1`. Spinning a body about the unit axis
//! `ω` at unit rate moves a point by `q' = ω × q = ω̂ q`, where `ω̂ =` [`so3::hat`]`(ω)` is the
//! skew-symmetric cross-product matrix; so `q(θ) = e^{ω̂θ} q(0)`. Because `ω̂³ = -ω̂`, the series
//! of the exponential collapses to Rodrigues' formula
//!
//! ```text
//! R = e^{ω̂θ} = I + sin θ ω̂ + (1 - cos θ) ω̂²        (‖ω‖ = 1)
//! ```
//!
//! [`so3::exp`] takes the rotation vector `w = ωθ` directly. The inverse, [`so3::log`], reads
//! `cos θ = (tr R - 1)/2` and `sin θ ω = vee(R) = (r₃₂ - r₂₃, r₁₃ - r₃₁, r₂₁ - r₁₂)/2`. Dividing by `sin θ` fails at `θ = 0`
//! and `θ = π`, so the implementation takes `θ = atan2(sin θ, cos θ)`, uses a Taylor series near
//! `0` and reads the axis from the symmetric part `(R + Rᵀ)/2 - cos θ I = (1 - cos θ) ω ωᵀ` near
//! `π`; `exp(log R) = R` holds to about `1e-15` at every angle.
//!
//! # Rigid motions: [`Se3`]
//!
//! `g = (R, t)` maps `q ↦ R q + t`; in homogeneous coordinates `g = [[R, t], [0, 1]]`. A point
//! turning at unit rate about the line through `q` with direction `ω` has velocity
//! `ω × (p - q)`, i.e. `p̄' = ξ̂ p̄` with the twist `ξ̂ = [[ω̂, v], [0, 0]]`, `v = -ω × q`. Twist
//! coordinates are **`ξ = (v, ω)`, linear part first** ([`Twist`]). The exponential is
//!
//! ```text
//! e^{ξ̂θ} = [[e^{ω̂θ}, (I - e^{ω̂θ})(ω × v) + ω ωᵀ v θ], [0, 1]]     (‖ω‖ = 1)
//!        = [[exp(ŵ),  J_l(w) v θ],                      [0, 1]]     (w = ωθ, any ‖w‖)
//! ```
//!
//! where `J_l(w) = I + ((1 - cos θ)/θ²) ŵ + ((θ - sin θ)/θ³) ŵ²` is the left Jacobian of SO(3)
//! ([`so3::left_jacobian`]); [`Se3::log`] inverts it with [`so3::left_jacobian_inv`]. The adjoint
//! `Ad_g ξ = (R v + t × R ω, R ω)` moves twists between frames (`g e^{ξ̂} g⁻¹ = e^{(Ad_g ξ)^}`),
//! and every twist with `ω ≠ 0` is a [`Screw`]: rotation about an axis line with a pitch.
//!
//! # What this module is not for
//!
//! - Not a general Lie-group framework: no traits, only the two groups rigid bodies need,
//!   as concrete `f64` types over glam's `DVec3`/`DMat3`/`DMat4`.
//! - No quaternions (use `glam::DQuat`), Euler angles, or interpolation and splines on SE(3).
//! - No checking on the hot path: functions assume their `DMat3` is a rotation; validate input
//!   with [`so3::is_rotation`] or [`Se3::from_homogeneous`].
//! - Rigid-body velocities, wrenches, spatial inertia and dynamics live in `anim-rigid`; this
//!   module only supplies the group operations they are built on.
//!
//! ```
//! use anim_core::glam::DVec3;
//! use anim_core::lie::{Se3, Twist, so3};
//!
//! // A quarter turn about z through the point (1, 0, 0): v = -ω × q.
//! let w = DVec3::Z;
//! let q = DVec3::X;
//! let xi = Twist::new(-w.cross(q), w);
//! let g = Se3::exp_screw(xi, std::f64::consts::FRAC_PI_2);
//! assert!((g.transform_point(DVec3::ZERO) - DVec3::new(1.0, -1.0, 0.0)).length() < 1e-15);
//! assert!((g.log() - xi.scale(std::f64::consts::FRAC_PI_2)).to_array().iter().all(|e| e.abs() < 1e-15));
//! assert!((so3::log(g.rotation) - w * std::f64::consts::FRAC_PI_2).length() < 1e-15);
//! ```

pub mod se3;
pub mod so3;

pub use se3::{Screw, Se3, Twist};
