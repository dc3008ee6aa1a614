//! Geometric Jacobians and their time derivatives.
//!
//! Column `k` of the world Jacobian is the spatial twist (at the world origin, linear part
//! first) that a unit rate of velocity entry `k` gives the body, `J_k = Ad(world_M_i) S_k`
//! ([`JointType::motion_subspace_column`]). For a frame `f` carried by joint `i`, only the
//! columns of `i`'s support are nonzero, and the three [`ReferenceFrame`]s read the same motion
//! differently:
//!
//! ```text
//! WORLD                 J_W   = [Ad(world_M_j) S_j]_{j ∈ support(i)}      twist at the world origin
//! LOCAL                 J_L   = Ad(world_M_f)⁻¹ J_W                        twist in frame f
//! LOCAL_WORLD_ALIGNED   J_LWA = [[I, -p̂], [0, I]] J_W,  p = origin of f    velocity of f's origin, world axes
//! ```
//!
//! Rows are ordered linear first (`v_x, v_y, v_z, ω_x, ω_y, ω_z`), as in Pinocchio, so
//! `J_LWA v` is `(ṗ, ω)` of the frame, `J_L v` its body twist, and the matrices compare entry by
//! entry with Pinocchio's `getFrameJacobian` (`WORLD`, `LOCAL`, `LOCAL_WORLD_ALIGNED`).
//!
//! # Time derivatives
//!
//! With `V_i` the spatial velocity of body `i` (world frame), `d/dt Ad(world_M_i) S = [V_i, J_k]`
//! (the Lie bracket, [`Twist::bracket`]), which [`compute_joint_jacobians_time_variation`]
//! evaluates in the same sweep as the velocities. The frame versions follow by the product rule:
//! `J̇_L = Ad(world_M_f)⁻¹ (J̇_W - [V_f, J_W])` and
//! `J̇_LWA = [[I, -p̂], [0, I]] J̇_W - [[0, ṗ̂], [0, 0]] J_W`. Cost: one extra sweep, about the
//! cost of the Jacobian itself.
//!
//! # Coupled joints
//!
//! A coupled joint ([`crate::model::Mimic`]) owns no column of `v`: [`Data::jacobian`] holds its
//! own world motion times its multiplier in an extra column ([`crate::model::Mimic::column`],
//! after the `nv` columns; Pinocchio's extended Jacobian, whose mimic columns are scaled the
//! same way), and the joint and frame Jacobians add it to the master's column when the joint is
//! in the support:
//! `J[:, master] = Σ_{j ∈ support, j drives master} multiplier_j · Ad(world_M_j) S_j`.

use anim_core::lie::{Se3, Twist};

use crate::data::Data;
use crate::kinematics::local_placement;
use crate::model::{FrameIndex, JointIndex, JointType, Model};

pub use crate::matrix6x::Jacobian;

/// In which frame a Jacobian (or velocity) is expressed. Pinocchio's `ReferenceFrame`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum ReferenceFrame {
    /// Spatial twist: world axes, reference point the world origin.
    World,
    /// Body twist: the frame's own axes and origin.
    Local,
    /// Velocity of the frame's origin with world axes (`ṗ` and `ω` in world coordinates).
    LocalWorldAligned,
}

/// The world columns of joint `joint` at the placement `world_m_i`, written into `out`.
#[inline(always)]
pub(crate) fn world_columns(kind: &JointType, world_m_i: &Se3, out: &mut [Twist]) {
    let r = &world_m_i.rotation;
    let t = world_m_i.translation;
    match kind {
        JointType::Revolute(axis) => {
            let w = match axis {
                crate::model::Axis::X => r.x_axis,
                crate::model::Axis::Y => r.y_axis,
                crate::model::Axis::Z => r.z_axis,
                crate::model::Axis::Unaligned(a) => *r * *a,
            };
            out[0] = Twist::new(t.cross(w), w);
        }
        JointType::Prismatic(axis) => out[0] = Twist::new(*r * axis.vector(), anim_core::glam::DVec3::ZERO),
        JointType::Fixed => {}
        JointType::Spherical | JointType::Free | JointType::Planar(_) => {
            for (k, o) in out.iter_mut().enumerate() {
                *o = world_m_i.adjoint(kind.motion_subspace_column(k));
            }
        }
    }
}

/// The extended column of a coupled joint: `multiplier · Ad(world_M_i) S_i` (Pinocchio's
/// `data.J` column of a `JointModelMimic`).
#[inline]
pub(crate) fn mimic_column(kind: &JointType, multiplier: f64, world_m_i: &Se3, out: &mut Twist) {
    let mut c = [Twist::ZERO];
    world_columns(kind, world_m_i, &mut c);
    *out = c[0].scale(multiplier);
}

#[track_caller]
fn check_sizes(model: &Model, data: &Data, q: &[f64]) {
    assert_eq!(q.len(), model.nq(), "q has length {}, the model nq = {}", q.len(), model.nq());
    assert!(data.fits(model), "this Data was not made for this Model (Data::new(&model))");
}

/// Forward kinematics and the world Jacobian of every joint (`data.jacobian`), in one sweep
/// (Pinocchio's `computeJointJacobians`).
///
/// # Panics
/// When `q` or `data` does not match `model`.
#[track_caller]
pub fn compute_joint_jacobians(model: &Model, data: &mut Data, q: &[f64]) {
    check_sizes(model, data, q);
    let cols = data.jacobian.columns_mut();
    for (i, joint) in model.joints().iter().enumerate().skip(1) {
        let local = local_placement(joint, q);
        let world = data.world_placements[joint.parent] * local;
        data.joint_placements[i] = local;
        data.world_placements[i] = world;
        match &joint.mimic {
            None => world_columns(&joint.kind, &world, &mut cols[joint.idx_v..joint.idx_v + joint.nv()]),
            Some(m) => mimic_column(&joint.kind, m.multiplier, &world, &mut cols[m.column]),
        }
    }
}

/// [`compute_joint_jacobians`] plus the spatial velocity of every body (`data.velocities`) and
/// the time derivative of the world Jacobian along `v` (`data.jacobian_dot`).
///
/// # Panics
/// When `q`, `v` or `data` does not match `model`.
#[track_caller]
pub fn compute_joint_jacobians_time_variation(model: &Model, data: &mut Data, q: &[f64], v: &[f64]) {
    assert_eq!(v.len(), model.nv(), "v has length {}, the model nv = {}", v.len(), model.nv());
    compute_joint_jacobians(model, data, q);
    data.velocities[0] = Twist::ZERO;
    for (i, joint) in model.joints().iter().enumerate().skip(1) {
        let mut vel = data.velocities[joint.parent];
        let range = match &joint.mimic {
            None => {
                let range = joint.idx_v..joint.idx_v + joint.nv();
                for k in range.clone() {
                    vel += data.jacobian.column(k).scale(v[k]);
                }
                range
            }
            Some(m) => {
                vel += data.jacobian.column(m.column).scale(v[joint.idx_v]);
                m.column..m.column + 1
            }
        };
        data.velocities[i] = vel;
        for k in range {
            data.jacobian_dot.columns_mut()[k] = vel.bracket(data.jacobian.column(k));
        }
    }
}

/// The Jacobian of joint `joint`'s frame in `rf`, from `data.jacobian` (run
/// [`compute_joint_jacobians`] first). Columns outside the joint's support are zero.
///
/// # Panics
/// When `out.ncols() != model.nv()` or `joint` is out of range.
#[track_caller]
pub fn joint_jacobian(model: &Model, data: &Data, joint: JointIndex, rf: ReferenceFrame, out: &mut Jacobian) {
    let placement = data.world_placements[joint];
    express(model, &data.jacobian, joint, &placement, rf, out);
}

/// The Jacobian of frame `frame` in `rf`, from `data.jacobian` and `data.world_placements` (run
/// [`compute_joint_jacobians`] first; the frame's placement is recomputed, so
/// `data.frame_placements` need not be current). Pinocchio's `getFrameJacobian`.
///
/// # Panics
/// When `out.ncols() != model.nv()` or `frame` is out of range.
#[track_caller]
pub fn frame_jacobian(model: &Model, data: &Data, frame: FrameIndex, rf: ReferenceFrame, out: &mut Jacobian) {
    let f = model.frame(frame);
    let placement = data.world_placements[f.parent_joint] * f.placement;
    express(model, &data.jacobian, f.parent_joint, &placement, rf, out);
}

/// Copies the support columns of `joint` from the world Jacobian `src`, expressed in `rf` for a
/// frame at `placement`; zeroes the other columns.
#[track_caller]
fn express(
    model: &Model,
    src: &Jacobian,
    joint: JointIndex,
    placement: &Se3,
    rf: ReferenceFrame,
    out: &mut Jacobian,
) {
    assert_eq!(
        out.ncols(),
        model.nv(),
        "output Jacobian has {} columns, the model nv = {}",
        out.ncols(),
        model.nv()
    );
    out.fill_zero();
    let p = placement.translation;
    let mut j = joint;
    while j != 0 {
        let jt = model.joint(j);
        for k in jt.idx_v..jt.idx_v + jt.nv() {
            let c = src.column(k);
            out.columns[k] = match rf {
                ReferenceFrame::World => c,
                ReferenceFrame::Local => placement.adjoint_inv(c),
                ReferenceFrame::LocalWorldAligned => Twist::new(c.v - p.cross(c.w), c.w),
            };
        }
        j = jt.parent;
    }
    if model.mimic_joints().is_empty() {
        return;
    }
    // Coupled joints in the support add their own column to their master's.
    let mut j = joint;
    while j != 0 {
        let jt = model.joint(j);
        if let Some(m) = &jt.mimic {
            let c = src.column(m.column);
            out.columns[jt.idx_v] += match rf {
                ReferenceFrame::World => c,
                ReferenceFrame::Local => placement.adjoint_inv(c),
                ReferenceFrame::LocalWorldAligned => Twist::new(c.v - p.cross(c.w), c.w),
            };
        }
        j = jt.parent;
    }
}

/// The time derivative of [`frame_jacobian`] along the velocity given to
/// [`compute_joint_jacobians_time_variation`] (run that first).
///
/// # Panics
/// When `out.ncols() != model.nv()` or `frame` is out of range.
#[track_caller]
pub fn frame_jacobian_time_variation(
    model: &Model,
    data: &Data,
    frame: FrameIndex,
    rf: ReferenceFrame,
    out: &mut Jacobian,
) {
    let f = model.frame(frame);
    let placement = data.world_placements[f.parent_joint] * f.placement;
    assert_eq!(
        out.ncols(),
        model.nv(),
        "output Jacobian has {} columns, the model nv = {}",
        out.ncols(),
        model.nv()
    );
    out.fill_zero();
    let vel = data.velocities[f.parent_joint];
    let p = placement.translation;
    let p_dot = vel.v + vel.w.cross(p);
    let mut j = f.parent_joint;
    while j != 0 {
        let jt = model.joint(j);
        for k in jt.idx_v..jt.idx_v + jt.nv() {
            let c = data.jacobian.column(k);
            let dc = data.jacobian_dot.column(k);
            out.columns[k] = match rf {
                ReferenceFrame::World => dc,
                ReferenceFrame::Local => placement.adjoint_inv(dc - vel.bracket(c)),
                ReferenceFrame::LocalWorldAligned => {
                    Twist::new(dc.v - p.cross(dc.w) - p_dot.cross(c.w), dc.w)
                }
            };
        }
        j = jt.parent;
    }
    if model.mimic_joints().is_empty() {
        return;
    }
    let mut j = f.parent_joint;
    while j != 0 {
        let jt = model.joint(j);
        if let Some(m) = &jt.mimic {
            let c = data.jacobian.column(m.column);
            let dc = data.jacobian_dot.column(m.column);
            out.columns[jt.idx_v] += match rf {
                ReferenceFrame::World => dc,
                ReferenceFrame::Local => placement.adjoint_inv(dc - vel.bracket(c)),
                ReferenceFrame::LocalWorldAligned => {
                    Twist::new(dc.v - p.cross(dc.w) - p_dot.cross(c.w), dc.w)
                }
            };
        }
        j = jt.parent;
    }
}
