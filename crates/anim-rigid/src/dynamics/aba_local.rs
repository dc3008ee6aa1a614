//! The articulated-body algorithm in joint frames: Featherstone's table 7.1 as written, every
//! spatial quantity of body `i` in its own joint frame and the articulated inertias carried to
//! the parent through the joint placement (Pinocchio's default `LOCAL` convention). See
//! [`crate::dynamics`] for the equations and [`super::aba_world`] for the world-frame form.
//!
//! Why a second form: in the world frame the articulated inertia of a body far from the origin
//! holds moments `m |t|²` beside its own rotational inertia, and the `Iᴬ - U D⁻¹ Uᵀ` updates
//! cancel most of them, so the rounding error grows with the square of the distance to the world
//! origin over the body's radius of gyration. In its own joint frame each articulated inertia is
//! about a point on its joint axis, and the lever arms stay the length of one link.

use anim_core::glam::DVec3;

use crate::data::Data;
use crate::dynamics::aba::{eliminate_joint, invert_spd};
use crate::dynamics::check::{check_q, check_v};
use crate::dynamics::subspace::{axis_dot, joint_motion};
use crate::kinematics::joint_placement;
use crate::model::{Axis, JointType, Model};
use crate::spatial::{ArticulatedInertia, Force, Motion};

/// `Iᴬ S` for a one-degree-of-freedom joint (revolute or prismatic): a column pick of the 6x6
/// matrix for a coordinate axis.
#[inline(always)]
fn inertia_times_axis(ia: &ArticulatedInertia, kind: &JointType) -> Force {
    match kind {
        // S = (0, a): (B a, C a).
        JointType::Revolute(axis) => match axis {
            Axis::X => Force::new(ia.b.x_axis, ia.c.x_axis),
            Axis::Y => Force::new(ia.b.y_axis, ia.c.y_axis),
            Axis::Z => Force::new(ia.b.z_axis, ia.c.z_axis),
            Axis::Unaligned(a) => Force::new(ia.b * *a, ia.c * *a),
        },
        // S = (a, 0): (A a, Bᵀ a).
        JointType::Prismatic(axis) => {
            let a = axis.vector();
            Force::new(ia.a * a, ia.b.transpose() * a)
        }
        _ => ia.mul_motion(&Motion::from(kind.motion_subspace_column(0))),
    }
}

/// `Sᵀ f` for a one-degree-of-freedom joint.
#[inline(always)]
fn project_axis(kind: &JointType, f: &Force) -> f64 {
    match kind {
        JointType::Revolute(axis) => axis_dot(axis, f.angular),
        JointType::Prismatic(axis) => axis_dot(axis, f.linear),
        _ => Motion::from(kind.motion_subspace_column(0)).dot(f),
    }
}

/// Forward dynamics `v̇ = FD(q, v, τ)` by the articulated-body algorithm in joint frames,
/// gravity included; written into `data.ddq` and returned. The same result as
/// [`aba_world`](super::aba_world) up to rounding, with errors that do not grow with the
/// bodies' distance from the world origin (see the module documentation of
/// [`crate::dynamics`]).
///
/// Also writes `data.joint_placements`, the body velocities
/// `data.body_velocities` and accelerations minus gravity `data.body_accelerations` (each in its
/// joint frame, as [`rnea`](crate::rnea) writes them), and the articulated inertias and bias
/// forces of every subtree (`data.articulated_inertias`, `data.articulated_forces`) **in the
/// joint's own frame**, after the joint's degrees of freedom are eliminated. Unlike
/// [`aba_world`](super::aba_world) it does not write `data.world_placements`, `data.jacobian`,
/// `data.velocities` or `data.world_accelerations`.
///
/// A joint whose articulated inertia `D = Sᵀ Iᴬ S` is singular (a massless leaf body) gives
/// non-finite accelerations.
///
/// # Panics
/// When `q`, `v`, `tau` or `data` does not match `model`, or when the model has coupled (mimic)
/// joints: [`crate::forward_dynamics_cholesky`] handles those.
#[track_caller]
pub fn aba_local<'d>(model: &Model, data: &'d mut Data, q: &[f64], v: &[f64], tau: &[f64]) -> &'d [f64] {
    assert!(
        model.mimic_joints().is_empty(),
        "ABA does not handle coupled (mimic) joints; use forward_dynamics_cholesky"
    );
    check_q(model, data, q);
    check_v(model, "v", v);
    check_v(model, "tau", tau);
    let joints = model.joints();
    let n = joints.len();
    data.body_velocities[0] = Motion::ZERO;

    // Pass 1, root to leaves: joint placements, velocities, velocity-product accelerations, rigid
    // inertias and bias forces, all in the body's joint frame.
    for i in 1..n {
        let joint = &joints[i];
        let (iq, iv) = (joint.idx_q, joint.idx_v);
        let m = joint_placement(&joint.placement, &joint.kind, &q[iq..iq + joint.nq()]);
        data.joint_placements[i] = m;
        let vj = joint_motion(&joint.kind, &v[iv..iv + joint.nv()]);
        let vel = data.body_velocities[joint.parent].inverse_transform(&m) + vj;
        data.body_velocities[i] = vel;
        data.aba_bias[i] = vel.cross(&vj);
        let y = data.body_inertias[i];
        data.articulated_inertias[i] = ArticulatedInertia::from(y);
        data.articulated_forces[i] = vel.cross_force(&y.mul_motion(&vel));
    }

    // Pass 2, leaves to root: eliminate each joint's degrees of freedom, carry the rest to the
    // parent's frame.
    for i in (1..n).rev() {
        let joint = &joints[i];
        let (iv, nv) = (joint.idx_v, joint.nv());
        let mut ia = data.articulated_inertias[i];
        let mut pa = data.articulated_forces[i];
        let c = data.aba_bias[i];
        match nv {
            0 => {}
            1 => {
                let u = inertia_times_axis(&ia, &joint.kind);
                let inv_d = 1.0 / project_axis(&joint.kind, &u);
                let uu = tau[iv] - project_axis(&joint.kind, &pa);
                ia.sub_rank_one(&u, inv_d);
                pa += ia.mul_motion(&c) + u * (uu * inv_d);
                data.aba_u[iv] = u;
                data.aba_dinv[iv][0] = inv_d;
                data.aba_uu[iv] = uu;
            }
            6 if matches!(joint.kind, JointType::Free) => {
                // S = 1: U = Iᴬ, D = Iᴬ, U D⁻¹ = 1 exactly, nothing of the subtree's inertia
                // passes the joint and the force it transmits is τ (as Pinocchio does).
                let mut d = [[0.0; 6]; 6];
                for (a, row) in d.iter_mut().enumerate() {
                    let col = ia.mul_motion(&Motion::from(joint.kind.motion_subspace_column(a))).to_array();
                    row.copy_from_slice(&col);
                    data.aba_u[iv + a] = Force::from_array(col);
                }
                let mut uu = [0.0; 6];
                uu.copy_from_slice(&tau[iv..iv + 6]);
                let p = pa.to_array();
                for (x, pk) in uu.iter_mut().zip(p) {
                    *x -= pk;
                }
                data.aba_uu[iv..iv + 6].copy_from_slice(&uu);
                data.aba_dinv[iv..iv + 6].copy_from_slice(&invert_spd(&d, 6));
                ia = ArticulatedInertia::ZERO;
                pa += Force::from_array(uu);
            }
            _ => {
                let mut s = [Motion::ZERO; 6];
                for a in 0..nv {
                    s[a] = Motion::from(joint.kind.motion_subspace_column(a));
                }
                eliminate_joint(
                    &mut ia,
                    &mut pa,
                    &c,
                    &s[..nv],
                    &tau[iv..iv + nv],
                    &mut data.aba_u[iv..iv + nv],
                    &mut data.aba_dinv[iv..iv + nv],
                    &mut data.aba_uu[iv..iv + nv],
                    invert_spd,
                );
            }
        }
        data.articulated_inertias[i] = ia;
        data.articulated_forces[i] = pa;
        if joint.parent != 0 {
            let m = &data.joint_placements[i];
            let up = ia.transform(m);
            data.articulated_inertias[joint.parent] += up;
            data.articulated_forces[joint.parent] += pa.transform(m);
        }
    }

    // Pass 3, root to leaves: accelerations in joint frames.
    data.body_accelerations[0] = Motion::new(-model.gravity(), DVec3::ZERO);
    for i in 1..n {
        let joint = &joints[i];
        let (iv, nv) = (joint.idx_v, joint.nv());
        let mut acc = data.body_accelerations[joint.parent].inverse_transform(&data.joint_placements[i])
            + data.aba_bias[i];
        match nv {
            0 => {}
            1 => {
                let qdd = data.aba_dinv[iv][0] * (data.aba_uu[iv] - data.aba_u[iv].dot(&acc));
                data.ddq[iv] = qdd;
                acc += joint_motion(&joint.kind, &[qdd]);
            }
            6 if matches!(joint.kind, JointType::Free) => {
                // q̈ = D⁻¹ u - (U D⁻¹)ᵀ a' with U D⁻¹ = 1, and a = a' + q̈.
                let a = acc.to_array();
                for k in 0..6 {
                    let row = &data.aba_dinv[iv + k];
                    let x: f64 = (0..6).map(|b| row[b] * data.aba_uu[iv + b]).sum();
                    data.ddq[iv + k] = x - a[k];
                }
                acc += joint_motion(&joint.kind, &data.ddq[iv..iv + 6]);
            }
            _ => {
                let mut r = [0.0; 6];
                for b in 0..nv {
                    r[b] = data.aba_uu[iv + b] - data.aba_u[iv + b].dot(&acc);
                }
                for a in 0..nv {
                    data.ddq[iv + a] = (0..nv).map(|b| data.aba_dinv[iv + a][b] * r[b]).sum();
                }
                acc += joint_motion(&joint.kind, &data.ddq[iv..iv + nv]);
            }
        }
        data.body_accelerations[i] = acc;
    }
    &data.ddq
}
