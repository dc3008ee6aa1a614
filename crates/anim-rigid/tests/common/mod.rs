//! Shared helpers of the integration tests.
#![allow(dead_code, clippy::unwrap_used, clippy::expect_used)]

use anim_core::glam::DVec3;
use anim_core::lie::Se3;
use anim_rigid::{
    Axis, FrameKind, Inertia, JointLimits, JointType, Model, ModelBuilder, UrdfOptions, load_urdf,
};

pub fn testdata(file: &str) -> String {
    format!("{}/testdata/{file}", env!("CARGO_MANIFEST_DIR"))
}

pub fn panda() -> Model {
    let options =
        UrdfOptions::default().lock_joint("panda_finger_joint1", 0.0).lock_joint("panda_finger_joint2", 0.0);
    load_urdf(testdata("panda.urdf"), &options).unwrap()
}

pub fn panda_floating() -> Model {
    let options = UrdfOptions::default()
        .lock_joint("panda_finger_joint1", 0.0)
        .lock_joint("panda_finger_joint2", 0.0)
        .floating_base(true);
    load_urdf(testdata("panda.urdf"), &options).unwrap()
}

pub fn ur5() -> Model {
    load_urdf(testdata("ur5_robot.urdf"), &UrdfOptions::default()).unwrap()
}

pub fn puma() -> Model {
    load_urdf(testdata("puma_like.urdf"), &UrdfOptions::default()).unwrap()
}

/// A tree with every joint type: free base, unaligned revolute, spherical, prismatic, a fixed
/// joint kept as a joint, and two branches.
pub fn mixed() -> Model {
    mixed_builder().build()
}

/// [`mixed`] with a body of positive mass and a full (off-diagonal) inertia on every joint, so
/// that its mass matrix is positive definite: the dynamics test tree.
pub fn mixed_massive() -> Model {
    let mut b = mixed_builder();
    let n = b.model().njoints();
    for j in 1..n {
        let k = j as f64;
        let i_c = anim_core::glam::DMat3::from_cols(
            DVec3::new(0.05 + 0.01 * k, 0.004 * k.sin(), -0.003),
            DVec3::new(0.004 * k.sin(), 0.04 + 0.005 * k, 0.002 * k.cos()),
            DVec3::new(-0.003, 0.002 * k.cos(), 0.03 + 0.002 * k),
        );
        let placement = Se3::new(anim_core::lie::so3::exp(DVec3::new(0.2 * k, -0.1, 0.3)), DVec3::ZERO);
        b.append_body(j, &Inertia::new(0.5 + 0.3 * k, DVec3::new(0.1, -0.05 * k, 0.02), i_c), &placement)
            .unwrap();
    }
    b.build()
}

/// The 32-joint serial chain written by `testdata/make_pinocchio_dynamics_reference.py`.
pub fn chain32() -> Model {
    load_urdf(testdata("chain32.urdf"), &UrdfOptions::default()).unwrap()
}

fn mixed_builder() -> ModelBuilder {
    let mut b = ModelBuilder::new("mixed");
    let rot = anim_core::lie::so3::exp(DVec3::new(0.3, -0.2, 0.5));
    let free = b
        .add_joint(
            0,
            "base",
            JointType::Free,
            Se3::new(rot, DVec3::new(0.1, 0.2, 0.3)),
            JointLimits::UNBOUNDED,
        )
        .unwrap();
    let axis = Axis::from_vector(DVec3::new(1.0, 2.0, -0.5)).unwrap();
    let r = b
        .add_joint(
            free,
            "hinge",
            JointType::Revolute(axis),
            Se3::from_translation(DVec3::new(0.0, 0.0, 0.4)),
            JointLimits::position(-2.0, 2.0),
        )
        .unwrap();
    let ball = b
        .add_joint(
            r,
            "ball",
            JointType::Spherical,
            Se3::new(rot.transpose(), DVec3::new(0.3, 0.0, 0.1)),
            JointLimits::UNBOUNDED,
        )
        .unwrap();
    let fixed = b
        .add_joint(
            ball,
            "rigid",
            JointType::Fixed,
            Se3::from_translation(DVec3::new(0.0, 0.2, 0.0)),
            JointLimits::UNBOUNDED,
        )
        .unwrap();
    let slide_axis = Axis::from_vector(DVec3::new(0.0, 1.0, 1.0)).unwrap();
    let slide = b
        .add_joint(
            fixed,
            "slide",
            JointType::Prismatic(slide_axis),
            Se3::new(rot, DVec3::new(0.1, 0.0, 0.0)),
            JointLimits::position(-0.5, 0.5),
        )
        .unwrap();
    let branch = b
        .add_joint(
            free,
            "branch",
            JointType::Revolute(Axis::X),
            Se3::from_translation(DVec3::new(0.0, -0.3, 0.0)),
            JointLimits::UNBOUNDED,
        )
        .unwrap();
    b.add_frame("tip", FrameKind::Operational, slide, Se3::new(rot, DVec3::new(0.05, 0.1, 0.2))).unwrap();
    b.add_frame(
        "branch_tip",
        FrameKind::Operational,
        branch,
        Se3::from_translation(DVec3::new(0.2, 0.0, 0.0)),
    )
    .unwrap();
    b.append_body(slide, &Inertia::new(1.0, DVec3::X, anim_core::glam::DMat3::IDENTITY), &Se3::IDENTITY)
        .unwrap();
    b
}

pub fn se3_err(a: &Se3, b: &Se3) -> f64 {
    let r = (a.rotation - b.rotation).to_cols_array().iter().fold(0.0_f64, |m, e| m.max(e.abs()));
    r.max((a.translation - b.translation).abs().max_element())
}
