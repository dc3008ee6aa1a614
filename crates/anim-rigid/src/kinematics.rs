//! Forward kinematics by joint-frame composition (Pinocchio's `forwardKinematics`).
//!
//! One sweep from the root: `parent_M_i = placement_i · X_J(q_i)` and
//! `world_M_i = world_M_parent · parent_M_i`; frames follow as `world_M_f = world_M_i · i_M_f`.
//! The product-of-exponentials forms of the same map are in [`crate::poe`]; the tests check
//! that all three agree.

use anim_core::glam::{DMat3, DVec3};
use anim_core::lie::Se3;

use crate::data::Data;
use crate::model::{Axis, FrameIndex, Joint, JointIndex, JointType, Model};

/// `placement · X_J(q)`, specialised per joint type (one sine/cosine and two column
/// combinations for an axis-aligned revolute joint instead of a full 3x3 product), for the
/// dynamics passes: the angle's sine and cosine come from [`crate::sincos`], within an ulp of the
/// standard library's. Forward kinematics and the Jacobians ([`local_placement`]) keep the
/// standard library's values, which the analytic inverse kinematics reproduces exactly.
#[inline(always)]
pub(crate) fn joint_placement(placement: &Se3, kind: &JointType, q: &[f64]) -> Se3 {
    placement_with::<true>(placement, kind, q)
}

/// `placement · X_J(q)`, the sine and cosine from [`crate::sincos`] when `FAST`, from the
/// standard library otherwise.
#[inline(always)]
fn placement_with<const FAST: bool>(placement: &Se3, kind: &JointType, q: &[f64]) -> Se3 {
    let r = &placement.rotation;
    match kind {
        JointType::Revolute(axis) => {
            let (s, c) = if FAST { crate::sincos::sin_cos(q[0]) } else { q[0].sin_cos() };
            let rotation = match axis {
                // R · Rx(θ): columns (x, c y + s z, -s y + c z).
                Axis::X => {
                    DMat3::from_cols(r.x_axis, r.y_axis * c + r.z_axis * s, r.z_axis * c - r.y_axis * s)
                }
                // R · Ry(θ): columns (c x - s z, y, s x + c z).
                Axis::Y => {
                    DMat3::from_cols(r.x_axis * c - r.z_axis * s, r.y_axis, r.x_axis * s + r.z_axis * c)
                }
                // R · Rz(θ): columns (c x + s y, -s x + c y, z).
                Axis::Z => {
                    DMat3::from_cols(r.x_axis * c + r.y_axis * s, r.y_axis * c - r.x_axis * s, r.z_axis)
                }
                Axis::Unaligned(_) => *r * axis.rotation(q[0]),
            };
            Se3::new(rotation, placement.translation)
        }
        JointType::Prismatic(axis) => Se3::new(*r, placement.translation + *r * (axis.vector() * q[0])),
        JointType::Fixed => *placement,
        JointType::Spherical | JointType::Free | JointType::Planar(_) => *placement * kind.transform(q),
    }
}

/// `parent_M_i(q)` of `joint`: its own entries of `q`, or for a coupled joint
/// ([`crate::model::Mimic`]) `multiplier · q_master + offset`.
#[inline(always)]
pub(crate) fn local_placement(joint: &Joint, q: &[f64]) -> Se3 {
    match &joint.mimic {
        None => placement_with::<false>(
            &joint.placement,
            &joint.kind,
            &q[joint.idx_q..joint.idx_q + joint.kind.nq()],
        ),
        Some(m) => placement_with::<false>(&joint.placement, &joint.kind, &[m.position(q[joint.idx_q])]),
    }
}

#[track_caller]
fn check_sizes(model: &Model, data: &Data, q: &[f64]) {
    assert_eq!(q.len(), model.nq(), "q has length {}, the model nq = {}", q.len(), model.nq());
    assert!(data.fits(model), "this Data was not made for this Model (Data::new(&model))");
}

/// Forward kinematics: fills `data.joint_placements` and `data.world_placements` for the
/// configuration `q` (length `nq`).
///
/// # Panics
/// When `q` or `data` does not match `model`.
#[track_caller]
pub fn forward_kinematics(model: &Model, data: &mut Data, q: &[f64]) {
    check_sizes(model, data, q);
    for (i, joint) in model.joints().iter().enumerate().skip(1) {
        let local = local_placement(joint, q);
        let world = data.world_placements[joint.parent] * local;
        data.joint_placements[i] = local;
        data.world_placements[i] = world;
    }
}

/// `data.frame_placements` from `data.world_placements` (run [`forward_kinematics`] first).
///
/// # Panics
/// When `data` does not match `model`.
#[track_caller]
pub fn update_frame_placements(model: &Model, data: &mut Data) {
    assert!(data.fits(model), "this Data was not made for this Model (Data::new(&model))");
    for (f, frame) in model.frames().iter().enumerate() {
        data.frame_placements[f] = data.world_placements[frame.parent_joint] * frame.placement;
    }
}

/// [`forward_kinematics`] followed by [`update_frame_placements`].
///
/// # Panics
/// When `q` or `data` does not match `model`.
#[track_caller]
pub fn frames_forward_kinematics(model: &Model, data: &mut Data, q: &[f64]) {
    forward_kinematics(model, data, q);
    update_frame_placements(model, data);
}

/// The world placement of frame `frame`, from `data.world_placements` (run
/// [`forward_kinematics`] first); also stored in `data.frame_placements[frame]`.
///
/// # Panics
/// When `frame` or `data` does not match `model`.
#[track_caller]
pub fn update_frame_placement(model: &Model, data: &mut Data, frame: FrameIndex) -> Se3 {
    let f = model.frame(frame);
    let placement = data.world_placements[f.parent_joint] * f.placement;
    data.frame_placements[frame] = placement;
    placement
}

/// The world placement of joint `joint` alone, computed along its support without touching a
/// [`Data`] (for one-off queries; a full sweep is [`forward_kinematics`]).
///
/// # Panics
/// When `q` does not match `model` or `joint` is out of range.
#[must_use]
#[track_caller]
pub fn joint_world_placement(model: &Model, q: &[f64], joint: JointIndex) -> Se3 {
    assert_eq!(q.len(), model.nq(), "q has length {}, the model nq = {}", q.len(), model.nq());
    let mut g = Se3::IDENTITY;
    for i in model.support(joint) {
        g *= local_placement(model.joint(i), q);
    }
    g
}

/// The world position of the point `p` given in frame `frame` (after [`forward_kinematics`]).
///
/// # Panics
/// When `frame` is out of range.
#[must_use]
#[track_caller]
pub fn frame_point(model: &Model, data: &Data, frame: FrameIndex, p: DVec3) -> DVec3 {
    let f = model.frame(frame);
    (data.world_placements[f.parent_joint] * f.placement).transform_point(p)
}
