// The README, with its links to what feature `serde` adds resolved: to the items with it,
// else to the features table that says how to get them.
#![cfg_attr(feature = "serde", doc = concat!(include_str!("../README.md"), "\n[`KIND`]: KIND\n[`scene`]: anim_core::scene\n[`kind`]: kind\n[`kind::RigidParams`]: kind::RigidParams\n[`kind::RigidSegments`]: kind::RigidSegments\n"))]
#![cfg_attr(not(feature = "serde"), doc = concat!(include_str!("../README.md"), "\n[`KIND`]: #features\n[`scene`]: #features\n[`kind`]: #features\n[`kind::RigidParams`]: #features\n[`kind::RigidSegments`]: #features\n"))]

#[cfg(feature = "cases")]
pub mod cases;
pub mod checked;
pub mod config;
pub mod data;
pub mod dense;
pub mod dynamics;
pub mod ik;
pub mod jacobian;
#[cfg(feature = "serde")]
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
mod sincos;
pub mod spatial;
pub mod urdf;

pub use checked::InputError;
pub use data::Data;
pub use dense::SquareMatrix;
pub use dynamics::{
    DynamicsError, aba, aba_local, aba_world, center_of_mass, crba, crba_local, crba_world,
    factor_mass_matrix, forward_dynamics, forward_dynamics_cholesky, gravity_torques, kinetic_energy,
    nonlinear_effects, potential_energy, rnea, solve_mass_matrix, spatial_momentum,
};
pub use ik::{AnalyticIk, AnalyticIkKind, IkError, IkParams, IkReport, IkSolution, NumericalIk};
pub use jacobian::{
    Jacobian, ReferenceFrame, compute_joint_jacobians, compute_joint_jacobians_time_variation,
    frame_jacobian, frame_jacobian_time_variation, joint_jacobian,
};
#[cfg(feature = "serde")]
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

/// anim-core, the math and contracts this crate builds on: its `glam`, integrators and scene
/// traits, without a dependency of your own.
pub use anim_core;
/// The trait whose `step` advances this crate's simulations.
pub use anim_core::solver::Solver;
