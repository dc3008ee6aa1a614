//! Energies, momentum and centre of mass of a tree: the conserved quantities the simulations
//! report (Featherstone section 2.13).
//!
//! ```text
//! T = ½ Σᵢ vᵢ · Iᵢ vᵢ = ½ vᵀ H(q) v        V = -Σᵢ mᵢ g · cᵢ        h = Σᵢ ⁰Xᵢ* Iᵢ vᵢ
//! ```
//!
//! with `cᵢ` the world centre of mass of body `i` and `h` the spatial momentum in the world frame
//! about the world origin: its linear part is the total linear momentum, its angular part the
//! total angular momentum about the origin. Without gravity, joint forces or damping (a free
//! floating tree), `h` is conserved; with only gravity, `T + V` is.

use anim_core::glam::DVec3;

use crate::data::Data;
use crate::dynamics::check::{check_q, check_v};
use crate::dynamics::subspace::joint_motion_of;
use crate::kinematics::{forward_kinematics, local_placement};
use crate::model::Model;
use crate::spatial::{Force, Motion};

/// The kinetic energy `½ vᵀ H(q) v`, summed body by body. Writes `data.joint_placements` and
/// `data.body_velocities`.
///
/// # Panics
/// When `q`, `v` or `data` does not match `model`.
#[track_caller]
pub fn kinetic_energy(model: &Model, data: &mut Data, q: &[f64], v: &[f64]) -> f64 {
    check_q(model, data, q);
    check_v(model, "v", v);
    let mut t = 0.0;
    data.body_velocities[0] = Motion::ZERO;
    for (i, joint) in model.joints().iter().enumerate().skip(1) {
        let m = local_placement(joint, q);
        data.joint_placements[i] = m;
        let vel = data.body_velocities[joint.parent].inverse_transform(&m) + joint_motion_of(joint, v);
        data.body_velocities[i] = vel;
        t += data.body_inertias[i].kinetic_energy(&vel);
    }
    t
}

/// The gravitational potential energy `-Σ mᵢ g · cᵢ` (zero at the world origin; Pinocchio's
/// `computePotentialEnergy`). Runs [`forward_kinematics`].
///
/// # Panics
/// When `q` or `data` does not match `model`.
#[track_caller]
pub fn potential_energy(model: &Model, data: &mut Data, q: &[f64]) -> f64 {
    check_q(model, data, q);
    forward_kinematics(model, data, q);
    let g = model.gravity();
    let mut v = 0.0;
    for (i, inertia) in model.inertias().iter().enumerate().skip(1) {
        v -= inertia.mass * g.dot(data.world_placements[i].transform_point(inertia.com));
    }
    v
}

/// The spatial momentum of the whole tree in the world frame about the world origin:
/// `(total linear momentum, total angular momentum about the origin)`. Runs
/// [`forward_kinematics`] and writes `data.body_velocities`.
///
/// # Panics
/// When `q`, `v` or `data` does not match `model`.
#[track_caller]
pub fn spatial_momentum(model: &Model, data: &mut Data, q: &[f64], v: &[f64]) -> Force {
    check_v(model, "v", v);
    let _ = kinetic_energy(model, data, q, v);
    forward_kinematics(model, data, q);
    let mut h = Force::ZERO;
    for i in 1..model.njoints() {
        let local = data.body_inertias[i].mul_motion(&data.body_velocities[i]);
        h += local.transform(&data.world_placements[i]);
    }
    h
}

/// The centre of mass of every body below the universe, in the world frame (the origin for a
/// massless tree). Runs [`forward_kinematics`].
///
/// # Panics
/// When `q` or `data` does not match `model`.
#[track_caller]
pub fn center_of_mass(model: &Model, data: &mut Data, q: &[f64]) -> DVec3 {
    check_q(model, data, q);
    forward_kinematics(model, data, q);
    let (mut m, mut mc) = (0.0, DVec3::ZERO);
    for (i, inertia) in model.inertias().iter().enumerate().skip(1) {
        m += inertia.mass;
        mc += data.world_placements[i].transform_point(inertia.com) * inertia.mass;
    }
    if m > 0.0 { mc / m } else { DVec3::ZERO }
}
