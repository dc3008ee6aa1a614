//! The mass matrix of a model with coupled joints ([`crate::model::Mimic`]).
//!
//! With `G` the `nv_extended × nv` map from the model's velocity `v` to the velocity of every
//! joint taken as independent (identity rows for ordinary degrees of freedom, the row
//! `multiplier · e_master` for a coupled joint), the kinetic energy is
//! `½ vᵀ Gᵀ H_ext G v`, so the mass matrix is `H = Gᵀ H_ext G`, where `H_ext` is the mass
//! matrix of the same tree with every joint independent. This builds it without forming
//! either factor: the world form of the composite-rigid-body algorithm (Featherstone table 6.2;
//! [`crate::crba_world`]) computes each entry `H_ext[l][k] = J_l · (Iᶜ_i J_k)` of the extended
//! world Jacobian ([`crate::Data::jacobian`], whose coupled columns already carry their
//! multiplier, i.e. are columns of `J_ext G`) and adds it to the entry of the degrees of
//! freedom they drive (both triangles at once). A master and its
//! coupled joint may sit on different branches, so entries outside the tree pattern of `H`
//! appear; [`crate::Data::dof_parents`] treats such models as dense.

use anim_core::lie::Se3;

use crate::data::Data;
use crate::dense::SquareMatrix;
use crate::jacobian::{mimic_column, world_columns};
use crate::kinematics::local_placement;
use crate::model::{Joint, Model};
use crate::spatial::{Motion, SpatialInertia};

/// The extended Jacobian columns of `joint` (a coupled joint's already times its multiplier)
/// and the first reduced degree of freedom they drive.
#[inline]
fn columns(joint: &Joint) -> (usize, usize, usize) {
    match &joint.mimic {
        None => (joint.idx_v, joint.kind.nv(), joint.idx_v),
        Some(m) => (m.column, 1, joint.idx_v),
    }
}

/// `H = Gᵀ H_ext G` into `data.mass_matrix` (see the module documentation). Sizes are checked
/// by the caller.
pub(crate) fn crba_coupled<'d>(model: &Model, data: &'d mut Data, q: &[f64]) -> &'d SquareMatrix {
    let joints = model.joints();
    let inertias = model.inertias();
    data.world_placements[0] = Se3::IDENTITY;
    {
        let cols = data.jacobian.columns_mut();
        for i in 1..joints.len() {
            let joint = &joints[i];
            let m = local_placement(joint, q);
            let world = data.world_placements[joint.parent] * m;
            data.joint_placements[i] = m;
            data.world_placements[i] = world;
            data.composite_inertias[i] = SpatialInertia::from_inertia_at(&inertias[i], &world);
            match &joint.mimic {
                None => world_columns(&joint.kind, &world, &mut cols[joint.idx_v..joint.idx_v + joint.nv()]),
                Some(mm) => mimic_column(&joint.kind, mm.multiplier, &world, &mut cols[mm.column]),
            }
        }
    }
    let h = &mut data.mass_matrix;
    let nv = h.n();
    h.fill_zero();
    let values = h.as_mut_slice();
    let cols = data.jacobian.columns();
    for i in (1..joints.len()).rev() {
        let joint = &joints[i];
        let yc = data.composite_inertias[i];
        let (start, n, dof) = columns(joint);
        for a in 0..n {
            let f = yc.mul_motion(&Motion::from(cols[start + a]));
            let row = if joint.mimic.is_some() { dof } else { dof + a };
            // The joint's own block, every (a, b) pair once.
            for b in 0..n {
                let c = cols[start + b];
                let col = if joint.mimic.is_some() { dof } else { dof + b };
                values[row * nv + col] += c.v.dot(f.linear) + c.w.dot(f.angular);
            }
            // Every ancestor's columns, into both triangles.
            let mut j = joint.parent;
            while j != 0 {
                let (s2, n2, dof2) = columns(&joints[j]);
                for b in 0..n2 {
                    let c = cols[s2 + b];
                    let col = if joints[j].mimic.is_some() { dof2 } else { dof2 + b };
                    let value = c.v.dot(f.linear) + c.w.dot(f.angular);
                    values[row * nv + col] += value;
                    values[col * nv + row] += value;
                }
                j = joints[j].parent;
            }
        }
        if joint.parent != 0 {
            data.composite_inertias[joint.parent] += yc;
        }
    }
    &data.mass_matrix
}
