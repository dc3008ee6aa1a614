//! Rigid-body dynamics of kinematic trees: inverse dynamics (RNEA), the joint-space mass matrix
//! (CRBA), forward dynamics (ABA, and `H⁻¹ (τ - C)` through a sparse `LᵀDL` factorisation),
//! energies and momentum: Featherstone, *Rigid Body Dynamics Algorithms*
//! (2008), chapters 5-7; the spatial algebra is [`crate::spatial`].
//!
//! # The equation of motion
//!
//! A tree of rigid bodies with configuration `q` and velocity `v = q̇` (for spherical and free
//! joints, the angular velocity in the joint frame, see [`crate::model`]) obeys
//!
//! ```text
//! τ = H(q) v̇ + C(q, v)
//! ```
//!
//! where `τ` are the joint forces, `H(q)` the symmetric positive-definite joint-space mass
//! matrix, and `C(q, v) = c(q, v) + g(q)` the bias: Coriolis and centrifugal forces plus the
//! gravity term. Featherstone names the two problems `v̇ = FD(model, q, v, τ)` and
//! `τ = ID(model, q, v, v̇)`:
//!
//! | function | computes | cost | Featherstone |
//! | --- | --- | --- | --- |
//! | [`rnea`] | `τ = ID(q, v, v̇)` | `O(n)` | ch. 5, table 5.1 |
//! | [`nonlinear_effects`] | `C(q, v) = ID(q, v, 0)` | `O(n)` | 5.3 |
//! | [`gravity_torques`] | `g(q) = ID(q, 0, 0)` | `O(n)` | 5.3 |
//! | [`crba`] ([`crba_local`], [`crba_world`]) | `H(q)` | `O(n d)` | ch. 6, table 6.2 |
//! | [`aba`] ([`aba_local`], [`aba_world`]) | `v̇ = FD(q, v, τ)` | `O(n)` | ch. 7, table 7.1 |
//! | [`factor_mass_matrix`], [`solve_mass_matrix`] | `H = Lᵀ D L`, `H⁻¹ b` with no fill-in | `O(n d²)` | 6.5, table 6.3 |
//! | [`forward_dynamics_cholesky`] | `v̇ = H⁻¹ (τ - C)` | `O(n d²)` | 6.1 |
//! | [`forward_dynamics`] | `v̇ = FD(q, v, τ)`: the faster of the two above for the tree | | |
//! | [`kinetic_energy`], [`potential_energy`], [`spatial_momentum`], [`center_of_mass`] | `½ vᵀ H v`, `-Σ mᵢ g·cᵢ`, `Σ Iᵢ vᵢ`, `Σ mᵢ cᵢ / M` | `O(n)` | 2.13 |
//!
//! (`n` bodies, `d` the depth of the tree.) Every function is `algorithm(&model, &mut data, ...)`
//! and writes its result into [`Data`](crate::Data); none allocates.
//!
//! # RNEA: recursive Newton-Euler
//!
//! A forward pass computes each body's velocity and acceleration from its parent's, in the body's
//! own joint frame (`ⁱX_λ = Ad(λM_i)⁻¹`, `S_i` the joint's motion subspace, constant in that frame
//! for every joint type here, so the joint's own bias acceleration `c_J` vanishes):
//!
//! ```text
//! v_i = ⁱX_λ v_λ + S_i q̇_i
//! a_i = ⁱX_λ a_λ + S_i q̈_i + v_i ×ₘ S_i q̇_i          a_0 = -g  (gravity as a base acceleration)
//! f_i = I_i a_i + v_i ×f I_i v_i
//! ```
//!
//! and a backward pass projects and accumulates: `τ_i = S_iᵀ f_i`, `f_λ += ᵡX*_i f_i`. Giving the
//! root the acceleration `-g` instead of applying `m_i g` to every body is Featherstone's trick:
//! the same result, one term fewer per body.
//!
//! # CRBA: composite rigid bodies
//!
//! `H_ij = S_iᵀ Iᶜ_i S_j` for `j` in the support of `i`, where `Iᶜ_i` is the inertia of the whole
//! subtree below joint `i` as one rigid body. Two forms compute it:
//!
//! - in joint frames ([`crba_local`], Featherstone's table 6.2, Pinocchio's default): the
//!   composite inertias accumulate through the joint placements, `Iᶜ_λ += ᵡX*_i Iᶜ_i ⁱX_λ`, the
//!   force `F = Iᶜ_i S_i` is a column of `Iᶜ_i` for an axis-aligned joint, and it is carried up
//!   to every ancestor `j` by one force transform each, `H_ij = S_jᵀ F` one of its components;
//! - in the **world frame** ([`crba_world`], Pinocchio's `WORLD` convention): each body's inertia
//!   is moved to the world once, the composite inertias are plain sums
//!   ([`SpatialInertia`](crate::spatial::SpatialInertia) adds entry by entry), and each entry is
//!   one 6-vector dot product `H_lk = J_l · (Iᶜ_i J_k)` with the world Jacobian columns
//!   `J_k = Ad(⁰M_i) S_k`.
//!
//! The local form costs a transform per entry and the world form a placement composition per
//! body: the first is faster on robot arms (the Panda, the UR5), the second on deep chains
//! (32 joints: 528 entries); [`crba`] picks by the mean depth of the degrees of freedom. Only the
//! lower triangle is computed; it is mirrored.
//!
//! # ABA: articulated bodies
//!
//! Three passes, in two forms. In joint frames ([`aba_local`], Featherstone's table 7.1,
//! Pinocchio's default `LOCAL` convention), with `ⁱX_λ = Ad(λM_i)⁻¹` and `S_i` constant:
//!
//! ```text
//! 1. v_i = ⁱX_λ v_λ + S_i q̇_i,   c_i = v_i ×ₘ S_i q̇_i,   Iᴬ_i = I_i,   pᴬ_i = v_i ×f I_i v_i
//! 2. (leaves to root)  U_i = Iᴬ_i S_i,  D_i = S_iᵀ U_i,  u_i = τ_i - S_iᵀ pᴬ_i
//!    Iᵃ_i = Iᴬ_i - U_i D_i⁻¹ U_iᵀ,   Iᴬ_λ += ᵡX*_i Iᵃ_i ⁱX_λ,   pᴬ_λ += ᵡX*_i (pᴬ_i + Iᵃ_i c_i + U_i D_i⁻¹ u_i)
//! 3. (root to leaves)  a'_i = ⁱX_λ a_λ + c_i,  q̈_i = D_i⁻¹ (u_i - U_iᵀ a'_i),  a_i = a'_i + S_i q̈_i
//! ```
//!
//! In the **world frame** ([`aba_world`], Pinocchio's `WORLD` convention) the same passes use the
//! world Jacobian columns `J_i = Ad(⁰M_i) S_i` in place of `S_i`, and no transform at all: the
//! articulated inertias of siblings and parent are in the same frame and simply add
//! (`c_i = v_λ ×ₘ J_i q̇_i`, `Iᴬ_λ += Iᵃ_i`). `a_0 = -g` in both. `D_i` is a scalar for revolute
//! and prismatic joints and a symmetric positive-definite block for spherical, planar and free
//! joints; for a free joint `U_i D_i⁻¹ = 1` exactly and `q̈ = D⁻¹ u - a'` (as Pinocchio does).
//!
//! The world form saves the 6x6 transform per joint and costs one placement composition and the
//! Jacobian columns; the local form is the accurate one. In world coordinates a body at distance
//! `r` from the origin has moments `m r²` in its inertia, which the eliminations
//! `Iᴬ - U D⁻¹ Uᵀ` mostly cancel, so rounding errors grow with `r²` over the squared radius of
//! gyration; in joint frames the lever arms stay one link long. Against `H⁻¹ (τ - C)` solved with
//! multiple-precision refinement (`tests/aba_accuracy.rs`, 20 samples per model, errors relative
//! to the largest acceleration; Pinocchio 4.1's own two conventions on the same samples):
//!
//! | model (fixed base) | `aba_local` | `aba_world` | Pinocchio `LOCAL` | Pinocchio `WORLD` |
//! | --- | --- | --- | --- | --- |
//! | iCub (32 DoF) | 1.1e-10 | 3.8e-9 | 1.1e-10 | 9.5e-9 |
//! | TIAGo, no hand (12 DoF) | 3.9e-16 | 1.9e-11 | 2.3e-16 | 3.1e-11 |
//! | human (36 DoF) | 8.8e-14 | 1.3e-12 | 1.6e-13 | 3.3e-12 |
//!
//! and on free-flyer bases 4.2e-10 / 1.4e-6 / 4.2e-10 / 8.5e-7 (iCub), 2.5e-16 / 1.9e-11 /
//! 2.5e-16 / 4.2e-11 (TIAGo), 3.3e-13 / 2.1e-9 / 5.1e-15 / 4.1e-7 (human: one sample with the
//! hip's three joints near gimbal lock, where ours is 60 times Pinocchio's). Both forms sum the
//! parallel-axis term `m (|c|² I - c cᵀ)` with each diagonal entry from the two other
//! coordinates, without which a centre of mass near a joint axis (iCub's head) cost a factor 15.
//!
//! [`aba`] is [`aba_world`]: the joint-frame form costs a 6x6 transform of `Iᴬ` per joint and is
//! not within 10% of the world form's time everywhere. Per call, `aba_local / aba_world`, median
//! (range) of five interleaved rounds of `cargo xtask bench --peers --filter rigid` on a shared
//! 2-core machine: Panda 1.00 (0.90-1.18), UR5 1.07 (0.99-1.18), 32-joint chain 1.13
//! (1.03-1.43), iCub 1.08 (0.87-1.30), TIAGo 1.00 (0.71-1.27), human 1.16 (1.04-1.37). Both
//! forms took 0.39-0.56 of Pinocchio's time in the same convention in that run.
//!
//! # The Cholesky cross-check
//!
//! `H` has the sparsity of the tree: `H_ij = 0` unless one of `i`, `j` supports the other.
//! Featherstone's `LᵀDL` factorisation (table 6.3) eliminates from the leaves, so the factor has
//! exactly that sparsity and no fill-in; for a chain it is a dense `LDLᵀ` in reversed order.
//! [`forward_dynamics_cholesky`] solves `H v̇ = τ - C` with it: a second, independent forward
//! dynamics that ABA is tested against. It computes the joint placements once, in CRBA, and the
//! bias forces reuse them. On shallow arms it is also the faster one: CRBA's few entries,
//! the bias forces and a factorisation with little to eliminate cost less than ABA's 6x6
//! articulated inertias, so [`forward_dynamics`] takes it when the degrees of freedom are on
//! average at most [`CHOLESKY_DEPTH`] deep and ABA otherwise.
//!
//! # Coupled joints
//!
//! A joint coupled to another ([`crate::model::Mimic`], URDF `<mimic>` with
//! [`crate::urdf::UrdfOptions::couple_mimic_joints`]) moves by `multiplier · v_master`; the
//! model's `v` has no entry for it. With `G` the map from `v` to the velocities of the same
//! tree with every joint independent, RNEA adds `multiplier · Sᵀ f` of the coupled joint to the
//! master's torque (`τ = Gᵀ τ_ext`), CRBA returns `H = Gᵀ H_ext G` (which has entries between
//! branches, so the factorisation treats it as dense), and the energies follow the coupled
//! motion. [`aba`] has no such coupling and refuses these models; [`forward_dynamics_cholesky`]
//! solves `H v̇ = τ - C` for them, as Pinocchio does with its mimic joints.
//!
//! # Conventions
//!
//! Spatial vectors are linear first (see [`crate::spatial`]); gravity is the model's
//! ([`Model::gravity`](crate::Model::gravity), default `(0, 0, -9.81)`), and `τ`, `v`, `v̇`
//! have Pinocchio's layout, so every result compares entry for entry with Pinocchio's `rnea`,
//! `crba`, `aba` and `nonLinearEffects` (`tests/pinocchio_dynamics.rs`). External forces on
//! bodies and contact are not modelled here.

mod aba;
mod aba_local;
mod aba_world;
mod check;
mod cholesky;
mod crba;
mod crba_mimic;
mod energy;
mod forward;
mod rnea;
mod subspace;

pub use aba::aba;
pub use aba_local::aba_local;
pub use aba_world::aba_world;
pub use cholesky::{DynamicsError, factor_mass_matrix, forward_dynamics_cholesky, solve_mass_matrix};
pub use crba::{LOCAL_DEPTH, crba, crba_local, crba_world};
pub use energy::{center_of_mass, kinetic_energy, potential_energy, spatial_momentum};
pub use forward::{CHOLESKY_DEPTH, forward_dynamics};
pub use rnea::{gravity_torques, nonlinear_effects, rnea};
