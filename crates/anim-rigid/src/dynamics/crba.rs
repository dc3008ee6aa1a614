//! The composite-rigid-body algorithm: the joint-space mass matrix `H(q)` (Featherstone table
//! 6.2), in two forms that compute the same matrix. See [`crate::dynamics`] for the equations.
//!
//! - [`crba_world`]: every body's inertia moved to the world once, composite inertias summed
//!   there, and each entry one 6-vector dot product `H_lk = J_l · (Iᶜ J_k)` with the world
//!   Jacobian. Per joint it pays a placement composition and a world inertia; per entry only the
//!   dot product.
//! - [`crba_local`]: Featherstone's table 6.2 verbatim, in joint frames: `F = Iᶜ_i S_i` is read
//!   off the composite inertia (axis-aligned joints pick a column), and `F` is carried up the
//!   tree by one force transform per ancestor, `H_ij = S_jᵀ F` again a single component. No
//!   world placements, but a transform per entry.
//!
//! The world form wins on deep trees (a 32-joint chain: 528 entries), the local form on short
//! arms (the Panda: 28 entries for 7 bodies); [`crba`] picks by the mean depth of the degrees of
//! freedom (see [`Data::dof_parents`]).

use anim_core::glam::DVec3;
use anim_core::lie::Se3;

use crate::data::{Data, NO_PARENT};
use crate::dense::SquareMatrix;
use crate::dynamics::check::check_q;
use crate::dynamics::crba_mimic::crba_coupled;
use crate::dynamics::subspace::axis_dot;
use crate::jacobian::world_columns;
use crate::kinematics::joint_placement;
use crate::model::{Axis, JointType, Model};
use crate::spatial::{Force, Motion, SpatialInertia};

/// The joint-space mass matrix `H(q)` (both triangles), written into `data.mass_matrix` and
/// returned: [`crba_local`] when the degrees of freedom are on average at most
/// [`LOCAL_DEPTH`] deep, [`crba_world`] otherwise (the same matrix to rounding).
///
/// `H` is symmetric positive definite when every moving body has positive mass and a
/// non-degenerate inertia; `H[(i, j)] = 0` when neither degree of freedom supports the other.
///
/// # Panics
/// When `q` or `data` does not match `model`.
///
/// A model with coupled joints ([`Model::mimic_joints`]) takes a third form, `H = Gᵀ H_ext G`
/// (see the coupled-joint section of [`crate::dynamics`]); so do [`crba_local`] and
/// [`crba_world`] when given one.
#[track_caller]
pub fn crba<'d>(model: &Model, data: &'d mut Data, q: &[f64]) -> &'d SquareMatrix {
    check_q(model, data, q);
    if !model.mimic_joints().is_empty() {
        return crba_coupled(model, data, q);
    }
    if data.mean_dof_depth <= LOCAL_DEPTH { crba_local(model, data, q) } else { crba_world(model, data, q) }
}

/// Mean depth of the degrees of freedom up to which [`crba`] takes the local form: measured on
/// the Panda (mean depth 4), the UR5 (3.5) and chains of 8 to 32 joints.
pub const LOCAL_DEPTH: f64 = 6.0;

/// `-(h × a)` for an axis (exact for the coordinate axes: no multiplication by zero).
#[inline(always)]
fn minus_cross_axis(h: DVec3, axis: &Axis) -> DVec3 {
    match axis {
        Axis::X => DVec3::new(0.0, -h.z, h.y),
        Axis::Y => DVec3::new(h.z, 0.0, -h.x),
        Axis::Z => DVec3::new(-h.y, h.x, 0.0),
        Axis::Unaligned(a) => a.cross(h),
    }
}

/// `M a` for an axis (a column of `M` for the coordinate axes).
#[inline(always)]
fn mat_axis(m: &anim_core::glam::DMat3, axis: &Axis) -> DVec3 {
    match axis {
        Axis::X => m.x_axis,
        Axis::Y => m.y_axis,
        Axis::Z => m.z_axis,
        Axis::Unaligned(a) => *m * *a,
    }
}

/// `I S_k`: the force a unit rate of degree of freedom `k` of the joint needs from inertia `I`
/// (in the joint frame).
#[inline(always)]
fn inertia_subspace(kind: &JointType, k: usize, inertia: &SpatialInertia) -> Force {
    match kind {
        // I (0, a) = (-h × a, Ī a).
        JointType::Revolute(axis) => {
            Force::new(minus_cross_axis(inertia.first_moment, axis), mat_axis(&inertia.rotational, axis))
        }
        // I (a, 0) = (m a, h × a).
        JointType::Prismatic(axis) => {
            Force::new(axis.vector() * inertia.mass, -minus_cross_axis(inertia.first_moment, axis))
        }
        _ => inertia.mul_motion(&Motion::from(kind.motion_subspace_column(k))),
    }
}

/// `S_kᵀ f` for degree of freedom `k` of the joint.
#[inline(always)]
fn project(kind: &JointType, k: usize, f: &Force) -> f64 {
    match kind {
        JointType::Revolute(axis) => axis_dot(axis, f.angular),
        JointType::Prismatic(axis) => axis_dot(axis, f.linear),
        JointType::Fixed => 0.0,
        JointType::Spherical => f.angular[k],
        JointType::Planar(_) => {
            let s = kind.motion_subspace_column(k);
            s.v.dot(f.linear) + s.w.dot(f.angular)
        }
        JointType::Free => {
            if k < 3 {
                f.linear[k]
            } else {
                f.angular[k - 3]
            }
        }
    }
}

/// [`crba`] in joint frames (Featherstone table 6.2): composite inertias accumulated through the
/// joint placements, `F = Iᶜ_i S_i` carried up the tree one force transform per ancestor. Also
/// writes `data.joint_placements`.
///
/// # Panics
/// When `q` or `data` does not match `model`.
#[track_caller]
pub fn crba_local<'d>(model: &Model, data: &'d mut Data, q: &[f64]) -> &'d SquareMatrix {
    check_q(model, data, q);
    if !model.mimic_joints().is_empty() {
        return crba_coupled(model, data, q);
    }
    let joints = model.joints();
    for i in 1..joints.len() {
        let joint = &joints[i];
        data.joint_placements[i] =
            joint_placement(&joint.placement, &joint.kind, &q[joint.idx_q..joint.idx_q + joint.nq()]);
        data.composite_inertias[i] = data.body_inertias[i];
    }
    let chain = is_chain(&data.dof_parents);
    let h = &mut data.mass_matrix;
    let nv = h.n();
    if !chain {
        h.fill_zero();
    }
    let values = h.as_mut_slice();
    for i in (1..joints.len()).rev() {
        let joint = &joints[i];
        let yc = data.composite_inertias[i];
        for a in 0..joint.nv() {
            let k = joint.idx_v + a;
            let f = inertia_subspace(&joint.kind, a, &yc);
            // Row k of the lower triangle: this joint's own degrees of freedom up to k ...
            for b in 0..=a {
                values[k * nv + joint.idx_v + b] = project(&joint.kind, b, &f);
            }
            // ... then every ancestor's, carrying F up one frame at a time.
            let (mut j, mut f) = (i, f);
            while joints[j].parent != 0 {
                f = f.transform(&data.joint_placements[j]);
                j = joints[j].parent;
                let pj = &joints[j];
                for b in 0..pj.nv() {
                    values[k * nv + pj.idx_v + b] = project(&pj.kind, b, &f);
                }
            }
        }
        if joint.parent != 0 {
            let up = yc.transform(&data.joint_placements[i]);
            data.composite_inertias[joint.parent] += up;
        }
    }
    h.mirror_lower();
    &data.mass_matrix
}

/// [`crba`] in the world frame (Pinocchio's `WORLD` convention): world inertias summed into
/// composite inertias, `H_lk = J_l · (Iᶜ J_k)`. Also writes `data.joint_placements`,
/// `data.world_placements` and the world Jacobian `data.jacobian`.
///
/// # Panics
/// When `q` or `data` does not match `model`.
#[track_caller]
pub fn crba_world<'d>(model: &Model, data: &'d mut Data, q: &[f64]) -> &'d SquareMatrix {
    check_q(model, data, q);
    if !model.mimic_joints().is_empty() {
        return crba_coupled(model, data, q);
    }
    let joints = model.joints();
    let inertias = model.inertias();
    data.world_placements[0] = Se3::IDENTITY;
    {
        let cols = data.jacobian.columns_mut();
        // The previous joint's world placement, kept in registers: in a chain it is the parent,
        // and reading it back from `data` would stall on the store just made.
        let mut prev = Se3::IDENTITY;
        for i in 1..joints.len() {
            let joint = &joints[i];
            let m = joint_placement(&joint.placement, &joint.kind, &q[joint.idx_q..joint.idx_q + joint.nq()]);
            let parent = if joint.parent == i - 1 { prev } else { data.world_placements[joint.parent] };
            let world = parent * m;
            prev = world;
            data.joint_placements[i] = m;
            data.world_placements[i] = world;
            data.composite_inertias[i] = SpatialInertia::from_inertia_at(&inertias[i], &world);
            world_columns(&joint.kind, &world, &mut cols[joint.idx_v..joint.idx_v + joint.nv()]);
        }
    }
    let h = &mut data.mass_matrix;
    let nv = h.n();
    let chain = is_chain(&data.dof_parents);
    if !chain {
        // Entries between unrelated branches stay zero; a chain writes every entry itself.
        h.fill_zero();
    }
    let cols = data.jacobian.columns();
    let values = h.as_mut_slice();
    for i in (1..joints.len()).rev() {
        let joint = &joints[i];
        let yc = data.composite_inertias[i];
        for k in joint.idx_v..joint.idx_v + joint.nv() {
            let f = yc.mul_motion(&Motion::from(cols[k]));
            // Row k of the lower triangle: H[k][l] = J_l · F_k for l = k and every degree of
            // freedom above it.
            if chain {
                let row = &mut values[k * nv..=k * nv + k];
                for (h, c) in row.iter_mut().zip(&cols[..=k]) {
                    *h = c.v.dot(f.linear) + c.w.dot(f.angular);
                }
            } else {
                let mut l = k;
                while l != NO_PARENT {
                    let c = cols[l];
                    values[k * nv + l] = c.v.dot(f.linear) + c.w.dot(f.angular);
                    l = data.dof_parents[l];
                }
            }
        }
        if joint.parent != 0 {
            data.composite_inertias[joint.parent] += yc;
        }
    }
    h.mirror_lower();
    &data.mass_matrix
}

/// Whether the degrees of freedom form one chain (each one's parent is the one before it).
#[inline]
fn is_chain(parents: &[usize]) -> bool {
    parents.iter().enumerate().all(|(k, &p)| if k == 0 { p == NO_PARENT } else { p == k - 1 })
}
