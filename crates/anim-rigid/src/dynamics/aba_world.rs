//! The articulated-body algorithm in the world frame: Featherstone's table 7.1 with every
//! spatial quantity in world coordinates (Pinocchio's `WORLD` convention). See
//! [`crate::dynamics`] for the equations and [`super::aba_local`] for the joint-frame form.

use anim_core::glam::DVec3;
use anim_core::lie::{Se3, Twist};

use crate::data::Data;
use crate::dynamics::aba::{eliminate_joint, invert_small};
use crate::dynamics::check::{check_q, check_v};
use crate::jacobian::world_columns;
use crate::kinematics::joint_placement;
use crate::model::Model;
use crate::spatial::{ArticulatedInertia, Motion, SpatialInertia};

/// Forward dynamics `v̇ = FD(q, v, τ)` by the articulated-body algorithm, gravity included;
/// written into `data.ddq` and returned.
///
/// Also writes `data.joint_placements`, `data.world_placements`, the world Jacobian
/// `data.jacobian`, the world body velocities `data.velocities`, the articulated inertias and
/// bias forces of every subtree (`data.articulated_inertias`, `data.articulated_forces`, world
/// frame, after the joint's own degrees of freedom are eliminated) and the body accelerations
/// minus gravity (`data.world_accelerations`).
///
/// A joint whose articulated inertia `D = Sᵀ Iᴬ S` is singular (a massless leaf body) gives
/// non-finite accelerations; the simulation layer reports them at the step that made them.
///
/// # Panics
/// When `q`, `v`, `tau` or `data` does not match `model`, or when the model has coupled (mimic)
/// joints: [`crate::forward_dynamics_cholesky`] handles those.
#[track_caller]
pub fn aba_world<'d>(model: &Model, data: &'d mut Data, q: &[f64], v: &[f64], tau: &[f64]) -> &'d [f64] {
    assert!(
        model.mimic_joints().is_empty(),
        "ABA does not handle coupled (mimic) joints; use forward_dynamics_cholesky"
    );
    check_q(model, data, q);
    check_v(model, "v", v);
    check_v(model, "tau", tau);
    let joints = model.joints();
    let inertias = model.inertias();
    let n = joints.len();
    data.world_placements[0] = Se3::IDENTITY;
    data.velocities[0] = Twist::ZERO;

    // Pass 1, root to leaves: placements, Jacobian columns, velocities, rigid inertias, biases.
    {
        let cols = data.jacobian.columns_mut();
        for i in 1..n {
            let joint = &joints[i];
            let (iv, nv) = (joint.idx_v, joint.nv());
            let m = joint_placement(&joint.placement, &joint.kind, &q[joint.idx_q..joint.idx_q + joint.nq()]);
            let world = data.world_placements[joint.parent] * m;
            data.joint_placements[i] = m;
            data.world_placements[i] = world;
            let js = &mut cols[iv..iv + nv];
            world_columns(&joint.kind, &world, js);
            let mut vj = Motion::ZERO;
            for (c, &qd) in js.iter().zip(&v[iv..iv + nv]) {
                vj += Motion::from(*c) * qd;
            }
            let parent_v = Motion::from(data.velocities[joint.parent]);
            let vel = parent_v + vj;
            data.velocities[i] = vel.into();
            data.aba_bias[i] = parent_v.cross(&vj);
            let y = SpatialInertia::from_inertia_at(&inertias[i], &world);
            data.articulated_inertias[i] = ArticulatedInertia::from(y);
            data.articulated_forces[i] = vel.cross_force(&y.mul_motion(&vel));
        }
    }

    // Pass 2, leaves to root: eliminate each joint's degrees of freedom, pass the rest up.
    let cols = data.jacobian.columns();
    for i in (1..n).rev() {
        let joint = &joints[i];
        let (iv, nv) = (joint.idx_v, joint.nv());
        let mut ia = data.articulated_inertias[i];
        let mut pa = data.articulated_forces[i];
        let c = data.aba_bias[i];
        match nv {
            0 => {}
            1 => {
                let s = Motion::from(cols[iv]);
                let u = ia.mul_motion(&s);
                let inv_d = 1.0 / s.dot(&u);
                let uu = tau[iv] - s.dot(&pa);
                ia.sub_rank_one(&u, inv_d);
                pa += ia.mul_motion(&c) + u * (uu * inv_d);
                data.aba_u[iv] = u;
                data.aba_dinv[iv][0] = inv_d;
                data.aba_uu[iv] = uu;
            }
            _ => {
                let mut s = [Motion::ZERO; 6];
                for a in 0..nv {
                    s[a] = Motion::from(cols[iv + a]);
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
                    invert_small,
                );
            }
        }
        data.articulated_inertias[i] = ia;
        data.articulated_forces[i] = pa;
        if joint.parent != 0 {
            data.articulated_inertias[joint.parent] += ia;
            data.articulated_forces[joint.parent] += pa;
        }
    }

    // Pass 3, root to leaves: accelerations.
    data.world_accelerations[0] = Motion::new(-model.gravity(), DVec3::ZERO);
    for i in 1..n {
        let joint = &joints[i];
        let (iv, nv) = (joint.idx_v, joint.nv());
        let mut acc = data.world_accelerations[joint.parent] + data.aba_bias[i];
        match nv {
            0 => {}
            1 => {
                let qdd = data.aba_dinv[iv][0] * (data.aba_uu[iv] - data.aba_u[iv].dot(&acc));
                data.ddq[iv] = qdd;
                acc += Motion::from(cols[iv]) * qdd;
            }
            _ => {
                let mut r = [0.0; 6];
                for b in 0..nv {
                    r[b] = data.aba_uu[iv + b] - data.aba_u[iv + b].dot(&acc);
                }
                let mut delta = Motion::ZERO;
                for a in 0..nv {
                    let qdd: f64 = (0..nv).map(|b| data.aba_dinv[iv + a][b] * r[b]).sum();
                    data.ddq[iv + a] = qdd;
                    delta += Motion::from(cols[iv + a]) * qdd;
                }
                acc += delta;
            }
        }
        data.world_accelerations[i] = acc;
    }
    &data.ddq
}
