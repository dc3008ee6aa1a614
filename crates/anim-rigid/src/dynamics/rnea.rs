//! The recursive Newton-Euler algorithm (inverse dynamics) and the bias and gravity terms it
//! gives with zero acceleration (Featherstone table 5.1). See the module documentation of
//! [`crate::dynamics`] for the equations.

use anim_core::glam::DVec3;

use crate::data::Data;
use crate::dynamics::check::{check_q, check_v};
use crate::dynamics::subspace::{joint_motion_of, joint_project};
use crate::kinematics::local_placement;
use crate::model::Model;
use crate::spatial::Motion;

/// The RNEA passes into `data.tau`, with `v` (when `VEL`) and `a` (when `ACC`) read, zero
/// otherwise, and the root acceleration `-gravity`; with `PLACED` the joint placements already
/// in `data.joint_placements` for this `q` are used instead of being recomputed.
#[inline(always)]
fn rnea_core<const VEL: bool, const ACC: bool, const PLACED: bool>(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    v: &[f64],
    a: &[f64],
    gravity: DVec3,
) {
    let joints = model.joints();
    data.body_velocities[0] = Motion::ZERO;
    data.body_accelerations[0] = Motion::new(-gravity, DVec3::ZERO);
    for i in 1..joints.len() {
        let joint = &joints[i];
        let m = if PLACED {
            data.joint_placements[i]
        } else {
            let m = local_placement(joint, q);
            data.joint_placements[i] = m;
            m
        };
        let parent = joint.parent;
        let mut acc = data.body_accelerations[parent].inverse_transform(&m);
        let inertia = data.body_inertias[i];
        let force = if VEL {
            let vj = joint_motion_of(joint, v);
            let vel = data.body_velocities[parent].inverse_transform(&m) + vj;
            acc += vel.cross(&vj);
            if ACC {
                acc += joint_motion_of(joint, a);
            }
            data.body_velocities[i] = vel;
            inertia.mul_motion(&acc) + vel.cross_force(&inertia.mul_motion(&vel))
        } else {
            if ACC {
                acc += joint_motion_of(joint, a);
            }
            data.body_velocities[i] = Motion::ZERO;
            inertia.mul_motion(&acc)
        };
        data.body_accelerations[i] = acc;
        data.body_forces[i] = force;
    }
    for i in (1..joints.len()).rev() {
        let joint = &joints[i];
        let f = data.body_forces[i];
        if joint.mimic.is_none() {
            joint_project(&joint.kind, &f, &mut data.tau[joint.idx_v..joint.idx_v + joint.nv()]);
        }
        if joint.parent != 0 {
            let up = f.transform(&data.joint_placements[i]);
            data.body_forces[joint.parent] += up;
        }
    }
    // A coupled joint's force works through its master: τ_master += multiplier · Sᵀ f.
    for &i in model.mimic_joints() {
        let joint = &joints[i];
        if let Some(m) = &joint.mimic {
            let mut t = [0.0];
            joint_project(&joint.kind, &data.body_forces[i], &mut t);
            data.tau[joint.idx_v] += m.multiplier * t[0];
        }
    }
}

/// Inverse dynamics `τ = ID(q, v, a) = H(q) a + C(q, v)` by the recursive Newton-Euler
/// algorithm, gravity included; written into `data.tau` and returned. Also writes
/// `data.joint_placements` and the body velocities, accelerations (minus gravity) and forces in
/// their joint frames.
///
/// ```
/// use anim_rigid::{Data, rnea, parse_urdf, UrdfOptions};
///
/// // A 1 kg point mass on a 1 m massless rod hinged about y; at q = 0 the rod lies along +x,
/// // horizontal. Gravity (-z) pulls the mass down with a moment of +m g l about y, so holding
/// // it still takes τ = -m g l.
/// let urdf = r#"<robot name="p"><link name="base"/>
///   <link name="rod"><inertial><origin xyz="1 0 0"/><mass value="1"/>
///     <inertia ixx="0" iyy="0" izz="0" ixy="0" ixz="0" iyz="0"/></inertial></link>
///   <joint name="hinge" type="continuous"><parent link="base"/><child link="rod"/>
///     <axis xyz="0 1 0"/></joint></robot>"#;
/// let model = parse_urdf(urdf, &UrdfOptions::default())?;
/// let mut data = Data::new(&model);
/// let tau = rnea(&model, &mut data, &[0.0], &[0.0], &[0.0]);
/// assert!((tau[0] + 9.81).abs() < 1e-12);
/// # Ok::<(), anim_rigid::UrdfError>(())
/// ```
///
/// # Panics
/// When `q`, `v`, `a` or `data` does not match `model`.
#[track_caller]
pub fn rnea<'d>(model: &Model, data: &'d mut Data, q: &[f64], v: &[f64], a: &[f64]) -> &'d [f64] {
    check_q(model, data, q);
    check_v(model, "v", v);
    check_v(model, "a", a);
    rnea_core::<true, true, false>(model, data, q, v, a, model.gravity());
    &data.tau
}

/// The bias term `C(q, v) = RNEA(q, v, 0)` (Coriolis, centrifugal and gravity forces; Pinocchio's
/// `nonLinearEffects`), written into `data.nle` (and `data.tau`) and returned.
///
/// # Panics
/// When `q`, `v` or `data` does not match `model`.
#[track_caller]
pub fn nonlinear_effects<'d>(model: &Model, data: &'d mut Data, q: &[f64], v: &[f64]) -> &'d [f64] {
    check_q(model, data, q);
    check_v(model, "v", v);
    rnea_core::<true, false, false>(model, data, q, v, &[], model.gravity());
    data.nle.copy_from_slice(&data.tau);
    &data.nle
}

/// The gravity term `g(q) = RNEA(q, 0, 0)` (Pinocchio's `computeGeneralizedGravity`), written
/// into `data.gravity_torques` (and `data.tau`) and returned.
///
/// # Panics
/// When `q` or `data` does not match `model`.
#[track_caller]
pub fn gravity_torques<'d>(model: &Model, data: &'d mut Data, q: &[f64]) -> &'d [f64] {
    check_q(model, data, q);
    rnea_core::<false, false, false>(model, data, q, &[], &[], model.gravity());
    data.gravity_torques.copy_from_slice(&data.tau);
    &data.gravity_torques
}

/// [`nonlinear_effects`] with the joint placements that [`crba`](crate::crba) left in
/// `data.joint_placements` for the same `q` (forward dynamics through the mass matrix computes
/// them once), into `data.nle`.
pub(crate) fn nonlinear_effects_placed(model: &Model, data: &mut Data, v: &[f64]) {
    rnea_core::<true, false, true>(model, data, &[], v, &[], model.gravity());
    data.nle.copy_from_slice(&data.tau);
}
