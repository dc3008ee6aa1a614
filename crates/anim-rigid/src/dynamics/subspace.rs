//! The motion subspace `S` of a joint in its own (child) frame, as the dynamics algorithms use
//! it: the joint velocity `S q̇` and the projection `Sᵀ f` of a spatial force onto the joint's
//! degrees of freedom (Featherstone, *Rigid Body Dynamics Algorithms*, 2008, chapter 4). In its
//! own frame `S` is constant for every joint type here: one unit axis for a revolute (angular)
//! or prismatic (linear) joint, the three angular axes for a spherical joint, all six for a free
//! joint, none for a fixed joint.

use anim_core::glam::DVec3;

use crate::model::{Axis, Joint, JointType};
use crate::spatial::{Force, Motion};

/// `a · v` for an axis, reading one component when the axis is a coordinate axis.
#[inline(always)]
pub(crate) fn axis_dot(axis: &Axis, v: DVec3) -> f64 {
    match axis {
        Axis::X => v.x,
        Axis::Y => v.y,
        Axis::Z => v.z,
        Axis::Unaligned(u) => u.dot(v),
    }
}

/// The joint velocity `S q̇` in the joint (child) frame; `qd` is the joint's slice of `v`.
#[inline(always)]
pub(crate) fn joint_motion(kind: &JointType, qd: &[f64]) -> Motion {
    match kind {
        JointType::Revolute(axis) => Motion::new(DVec3::ZERO, axis.vector() * qd[0]),
        JointType::Prismatic(axis) => Motion::new(axis.vector() * qd[0], DVec3::ZERO),
        JointType::Fixed => Motion::ZERO,
        JointType::Spherical => Motion::new(DVec3::ZERO, DVec3::new(qd[0], qd[1], qd[2])),
        JointType::Free => Motion::new(DVec3::new(qd[0], qd[1], qd[2]), DVec3::new(qd[3], qd[4], qd[5])),
        JointType::Planar(axis) => {
            let (e1, e2) = axis.plane_basis();
            Motion::new(e1 * qd[0] + e2 * qd[1], axis.vector() * qd[2])
        }
    }
}

/// `Sᵀ f` written into the joint's slice `out`.
/// `S_i qd_i` of `joint` for the rates `qd` of the whole model (`v` or `v̇`): its own entries,
/// or for a coupled joint `multiplier · qd_master`.
#[inline(always)]
pub(crate) fn joint_motion_of(joint: &Joint, qd: &[f64]) -> Motion {
    match &joint.mimic {
        None => joint_motion(&joint.kind, &qd[joint.idx_v..joint.idx_v + joint.kind.nv()]),
        Some(m) => joint_motion(&joint.kind, &[m.multiplier * qd[joint.idx_v]]),
    }
}

#[inline(always)]
pub(crate) fn joint_project(kind: &JointType, f: &Force, out: &mut [f64]) {
    match kind {
        JointType::Revolute(axis) => out[0] = axis_dot(axis, f.angular),
        JointType::Prismatic(axis) => out[0] = axis_dot(axis, f.linear),
        JointType::Fixed => {}
        JointType::Spherical => out.copy_from_slice(&f.angular.to_array()),
        JointType::Free => {
            out[..3].copy_from_slice(&f.linear.to_array());
            out[3..].copy_from_slice(&f.angular.to_array());
        }
        JointType::Planar(axis) => {
            let (e1, e2) = axis.plane_basis();
            out[0] = e1.dot(f.linear);
            out[1] = e2.dot(f.linear);
            out[2] = axis_dot(axis, f.angular);
        }
    }
}
