//! # anim-rigid
//!
//! Articulated rigid bodies: kinematic-tree models loaded from URDF, forward kinematics by
//! joint-frame composition and by the product of exponentials, geometric Jacobians and their time
//! derivatives, inverse kinematics by the Paden-Kahan subproblems and by damped least squares
//! (Murray, Li & Sastry 1994; Lynch & Park 2017); and dynamics: spatial (Plücker) vector algebra, inverse
//! dynamics by RNEA, the mass matrix by CRBA, forward dynamics by ABA and by a sparse Cholesky
//! factorisation, energies and momentum, contact-free simulation of trees and free bodies with
//! Lie-group time steppers (Featherstone 2008). Built on anim-core's [`lie`](anim_core::lie) and
//! [`integrate`](anim_core::integrate) modules.
//!
//! ## Model, Data, configuration (Pinocchio's split)
//!
//! - [`Model`]: joints in topological order (parent index below the child's; joint `0` is the
//!   universe), each with a [`JointType`] (revolute, prismatic, fixed, spherical, free, planar), an axis,
//!   limits and a placement [`Se3`](anim_core::lie::Se3) in its parent's frame; the [`Inertia`]
//!   of the body each joint carries; named [`Frame`]s (joints, links, merged fixed joints, tool
//!   points); gravity. Built by [`ModelBuilder`] or [`load_urdf`]; never changed by an algorithm.
//! - [`Data`]: every buffer an algorithm writes (placements, Jacobians, velocities, torques, the
//!   mass matrix and its factor, articulated inertias), made once per model and reused; no
//!   algorithm allocates.
//! - The configuration `q` (length `nq`) and velocity `v` (length `nv`): spherical and free
//!   joints store a unit quaternion `(x, y, z, w)` in `q` and an angular velocity in `v`, so
//!   `nq ≠ nv`; a planar joint stores `(x, y, θ)` and moves on SE(2); [`config::integrate`] and [`config::difference`] move on that manifold. A
//!   revolute joint without limits (URDF `continuous`) stores its angle, where Pinocchio stores
//!   `(cos θ, sin θ)`: [`pinocchio::to_pinocchio`] and [`pinocchio::from_pinocchio`] convert `q`
//!   (`v` is the same in both).
//!
//! Algorithms are free functions `algorithm(&model, &mut data, inputs)`. Those of the crate root
//! are the unchecked hot path: a slice of the wrong length panics, a NaN flows into the result.
//! [`checked`] has the same functions returning a [`checked::InputError`] for a wrong length, a
//! non-finite entry (naming the joint), a zero quaternion, an index past the end or a `Data` of
//! another model; use it where the input comes from outside.
//!
//!
//! | function | computes | equation |
//! | --- | --- | --- |
//! | [`forward_kinematics`] | `world_M_i` of every joint | `world_M_i = world_M_λ(i) · M_i · X_J(q_i)` |
//! | [`update_frame_placements`] | `world_M_f` of every frame | `world_M_f = world_M_i · i_M_f` |
//! | [`PoeChain::forward_space`], [`PoeChain::forward_body`] | the same by the product of exponentials | `e^{Ŝ₁θ₁}···e^{Ŝₙθₙ} M = M e^{B̂₁θ₁}···e^{B̂ₙθₙ}` |
//! | [`compute_joint_jacobians`] | the world Jacobian of every joint | column `Ad(world_M_i) S_k` |
//! | [`frame_jacobian`] | a frame's Jacobian in [`ReferenceFrame::World`], `Local` or `LocalWorldAligned` | `J_L = Ad(world_M_f)⁻¹ J_W`, `J_LWA = [[I, -p̂], [0, I]] J_W` |
//! | [`compute_joint_jacobians_time_variation`], [`frame_jacobian_time_variation`] | `dJ/dt` along `v` | `d/dt Ad(world_M_i) S = [V_i, J_k]` |
//! | [`AnalyticIk`] | all (up to 8) IK solutions of 6R arms | Paden-Kahan subproblems ([`paden_kahan`]) |
//! | [`NumericalIk`] | IK for any chain | Levenberg-Marquardt on `log(T⁻¹T*)` with limits and a null-space objective |
//! | [`rnea`] | inverse dynamics `τ = ID(q, v, v̇)` | `τ = H(q) v̇ + C(q, v)` (Featherstone 2008), Newton-Euler passes |
//! | [`nonlinear_effects`], [`gravity_torques`] | the bias `C(q, v)` and gravity `g(q)` terms | `C = ID(q, v, 0)`, `g = ID(q, 0, 0)` |
//! | [`crba`] | the mass matrix `H(q)` | `H_ij = S_iᵀ Iᶜ_i S_j`, composite rigid bodies |
//! | [`aba`] | forward dynamics `v̇ = FD(q, v, τ)` in `O(n)` | articulated-body inertias |
//! | [`forward_dynamics_cholesky`] | `v̇ = H⁻¹ (τ - C)` | sparse `LᵀDL` of `H` ([`factor_mass_matrix`]) |
//! | [`kinetic_energy`], [`potential_energy`], [`spatial_momentum`], [`center_of_mass`] | conserved quantities | `½ vᵀ H v`, `-Σ m g·c`, `Σ Iᵢ vᵢ` |
//!
//! Twists and spatial vectors are ordered **linear first** (`(v, ω)`, `(f, n)`, as in
//! Murray-Li-Sastry and Pinocchio; Featherstone writes them angular first, see
//! [`spatial`]), and Jacobian rows likewise, so results compare entry by entry with Pinocchio.
//! The dynamics are explained with their equations in [`dynamics`]; [`spatial`] types motions
//! ([`Motion`]) and forces ([`Force`]) apart so that they cannot be added by mistake.
//!
//! ## Simulation
//!
//! [`sim`] steps trees with applied torques, joint damping and penalty joint limits:
//! [`sim::ArticulatedSystem`] is an anim-core
//! [`SecondOrderSystem`](anim_core::integrate::SecondOrderSystem) (acceleration by ABA) for
//! every explicit anim-core integrator on revolute/prismatic trees, and
//! [`sim::RigidSimulation`] an anim-core [`Solver`](anim_core::solver::Solver) with Lie-group
//! steppers for any tree (symplectic and explicit Euler, the commutator-free RK4, the implicit
//! midpoint rule, and an energy- and momentum-conserving midpoint rule for free bodies).
//! A step that produces a NaN or infinity returns [`sim::SimError::NonFinite`], whose message
//! begins with `anim-rigid: step N:` and names the joint, the coordinate within it, the value and
//! the joint's last finite `q` or `v`; the state and the simulation's memory are left as they
//! were before the step.
//! [`scenes`] has a swinging Panda, a 32-link pendulum chain and a spinning T-handle showing the
//! Dzhanibekov flip, ready for the command line.
//!
//! [`KIND`] registers them as the `rigid` scene kind of anim-core's
//! [`scene`](anim_core::scene) contracts, with the presets `panda`, `chain` and `t-handle` (see
//! [`kind`]): built from the scene-file parameters [`kind::RigidParams`], stepped, checkpointed
//! and drawn as the end points of their segments by [`kind::RigidSegments`]. A scene file can
//! bring its own robot instead of a preset: [`robot::RobotSpec`] reads a URDF file and sets the
//! base, locked joints, initial state, damping, PD servos ([`sim::Servo`]) and a torque
//! schedule.
//!
//! ## Accuracy, measured
//!
//! Kinematics, against Pinocchio 4.1 on the Franka Panda (7 DoF, fingers locked) and the UR5, 50
//! random configurations each (`tests/pinocchio.rs`, `cargo xtask conformance`): every frame
//! placement, every WORLD/LOCAL/LOCAL_WORLD_ALIGNED Jacobian and the Jacobian time variations
//! agree to `1.3e-15` (tolerance `1e-12`). The Paden-Kahan subproblems recover `10⁵` random
//! solvable instances each to below `1e-13`; the analytic IK solutions reproduce their targets
//! to `1e-11` or better; the numerical IK reaches `1e-10` on 99.7% of random reachable Panda
//! targets from the mid-range configuration (about 150 µs per solve, restarts included).
//!
//! Dynamics, against Pinocchio 4.1 on the Panda, the UR5, a generated 32-joint chain
//! (`testdata/chain32.urdf`) and the Panda on a free-flyer base, 50 random `(q, v, a, τ)` each
//! (`tests/pinocchio_dynamics.rs`): RNEA, CRBA, `C(q, v)` and `g(q)` agree to `6e-15` relative,
//! ABA to `1.1e-12` on the floating Panda and `1.5e-13` on the fixed bases, kinetic and
//! potential energies to `7e-15` (tolerance `1e-9`). `H q̈ + C = τ` closes to `2.4e-13`, ABA
//! inverts RNEA to `5.5e-12` and agrees with the Cholesky forward dynamics to `7.4e-13`. A
//! torque-free T-handle stepped `10⁵` times by the free-body midpoint rule keeps its energy and
//! angular momentum to `7.4e-12` and `3.7e-12` relative, and flips with the period of Euler's
//! top to `3e-7`. Against `H⁻¹ (τ - C)` solved with 40-digit refinement on iCub, TIAGo and the
//! human model (`tests/aba_accuracy.rs`), the joint-frame [`aba_local`] errs `1.1e-10`,
//! `3.9e-16` and `8.8e-14` (Pinocchio's `LOCAL`: `1.1e-10`, `2.3e-16`, `1.6e-13`) and the
//! world-frame [`aba_world`], which [`aba`] is, `3.8e-9`, `1.9e-11` and `1.3e-12`.
//!
//! ## Speed, measured
//!
//! Against Pinocchio 4.1's C++ (`g++ -O3 -march=native`, its faster convention for CRBA and ABA)
//! on the same 2-core machine, `cargo xtask bench --peers`, ours / theirs: RNEA 0.53 (Panda,
//! 380 ns), 0.54 (UR5), 0.50 (32-joint chain, 1.8 µs); CRBA 0.99 (Panda, 345 ns), 0.99 (UR5),
//! 0.89 (chain, 2.5 µs); ABA 0.53 (Panda, 724 ns), 0.55 (UR5), 0.52 (chain, 3.4 µs). Nothing
//! allocates after `Data` is built (`tests/no_alloc.rs`).
//!
//! ## What is not here
//!
//! Skinning, collision and contact are other modules or issues; external forces on bodies are
//! not an input of the dynamics yet. URDF `mimic` couplings and meshes are not modelled (see
//! [`urdf`]).
//!
//! ## Example
//!
//! ```
//! use anim_rigid::{Data, NumericalIk, IkParams, ReferenceFrame, Jacobian, UrdfOptions};
//! use anim_rigid::{compute_joint_jacobians, frame_jacobian, frames_forward_kinematics, parse_urdf};
//!
//! // A planar two-link arm: shoulder and elbow about z, links of 1 m along x.
//! let urdf = r#"<robot name="arm">
//!   <link name="base"/><link name="upper"/><link name="fore"/><link name="tip"/>
//!   <joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/>
//!     <axis xyz="0 0 1"/><limit lower="-3" upper="3"/></joint>
//!   <joint name="elbow" type="revolute"><parent link="upper"/><child link="fore"/>
//!     <origin xyz="1 0 0"/><axis xyz="0 0 1"/><limit lower="-3" upper="3"/></joint>
//!   <joint name="tip_joint" type="fixed"><parent link="fore"/><child link="tip"/>
//!     <origin xyz="1 0 0"/></joint>
//! </robot>"#;
//! let model = parse_urdf(urdf, &UrdfOptions::default())?;
//! let tip = model.frame_id("tip").expect("the tip frame");
//! let mut data = Data::new(&model);
//!
//! // Forward kinematics: shoulder at 90°, elbow at -90° puts the tip at (1, 1, 0).
//! let q = [std::f64::consts::FRAC_PI_2, -std::f64::consts::FRAC_PI_2];
//! frames_forward_kinematics(&model, &mut data, &q);
//! let p = data.frame_placements[tip].translation;
//! assert!((p - anim_core::glam::DVec3::new(1.0, 1.0, 0.0)).length() < 1e-15);
//!
//! // The tip's velocity (world axes) for a unit shoulder rate: ω × p = (-1, 1, 0).
//! compute_joint_jacobians(&model, &mut data, &q);
//! let mut j = Jacobian::zeros(model.nv());
//! frame_jacobian(&model, &data, tip, ReferenceFrame::LocalWorldAligned, &mut j);
//! assert!((j[(0, 0)] + 1.0).abs() < 1e-15 && (j[(1, 0)] - 1.0).abs() < 1e-15);
//!
//! // Inverse kinematics back to that pose from the zero configuration.
//! let target = data.frame_placements[tip];
//! let mut ik = NumericalIk::new(&model, tip, IkParams::default());
//! let report = ik.solve(&model, &target, &[0.3, 0.3]);
//! assert!(report.success && report.position_error < 1e-9);
//! # Ok::<(), anim_rigid::UrdfError>(())
//! ```
//!
//! `examples/panda_fk_ik.rs` does the same on the Franka Panda and the UR5 (analytic IK, all
//! eight solutions).

#[cfg(feature = "cases")]
pub mod cases;
pub mod checked;
pub mod config;
pub mod data;
pub mod dense;
pub mod dynamics;
pub mod ik;
pub mod jacobian;
pub mod kind;
pub mod kinematics;
pub mod matrix6x;
pub mod model;
pub mod paden_kahan;
pub mod pinocchio;
pub mod poe;
pub mod robot;
pub mod scenes;
pub mod sim;
pub mod spatial;
pub mod urdf;

pub use checked::InputError;
pub use data::Data;
pub use dense::SquareMatrix;
pub use dynamics::{
    DynamicsError, aba, aba_local, aba_world, center_of_mass, crba, crba_local, crba_world,
    factor_mass_matrix, forward_dynamics_cholesky, gravity_torques, kinetic_energy, nonlinear_effects,
    potential_energy, rnea, solve_mass_matrix, spatial_momentum,
};
pub use ik::{AnalyticIk, AnalyticIkKind, IkError, IkParams, IkReport, IkSolution, NumericalIk};
pub use jacobian::{
    Jacobian, ReferenceFrame, compute_joint_jacobians, compute_joint_jacobians_time_variation,
    frame_jacobian, frame_jacobian_time_variation, joint_jacobian,
};
pub use kind::KIND;
pub use kinematics::{
    forward_kinematics, frame_point, frames_forward_kinematics, joint_world_placement,
    update_frame_placement, update_frame_placements,
};
pub use model::{
    Axis, DEFAULT_GRAVITY, Frame, FrameIndex, FrameKind, Inertia, Joint, JointIndex, JointLimits, JointType,
    Mimic, Model, ModelBuilder, ModelError,
};
pub use poe::PoeChain;
pub use spatial::{ArticulatedInertia, Force, Motion, SpatialInertia};
pub use urdf::{UrdfCause, UrdfError, UrdfOptions, load_urdf, parse_urdf};
