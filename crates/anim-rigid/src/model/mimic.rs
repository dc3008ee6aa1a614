//! Coupled joints: a joint whose position follows another's (URDF `<mimic>`, Pinocchio's
//! `JointModelMimic`), and how [`ModelBuilder`] adds one.

use anim_core::lie::Se3;

use super::{JointIndex, JointLimits, JointType, ModelBuilder, ModelError};

/// How a coupled joint follows its master (Pinocchio's `JointModelMimic`): its position is
/// `q = multiplier · q_master + offset`, its velocity `multiplier · v_master`, and the force it
/// transmits adds `multiplier · Sᵀ f` to the master's generalised force (the virtual-work
/// dual of the same map).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Mimic {
    /// The joint it follows (a one-degree-of-freedom joint that is not itself coupled, with a
    /// lower index).
    pub master: JointIndex,
    /// Slope of the coupling (finite).
    pub multiplier: f64,
    /// Offset of the coupling (rad or m, finite).
    pub offset: f64,
    /// The column of [`crate::Data::jacobian`] that holds this joint's own world motion
    /// (columns `nv..`, one per coupled joint in joint order; Pinocchio's extended columns).
    pub column: usize,
}

impl Mimic {
    /// The position of the coupled joint when its master is at `q_master`.
    #[inline(always)]
    #[must_use]
    pub fn position(&self, q_master: f64) -> f64 {
        self.multiplier * q_master + self.offset
    }
}

impl ModelBuilder {
    /// Adds joint `name` like [`add_joint`](Self::add_joint), coupled to joint `master`: its
    /// position is `multiplier · q_master + offset` and it owns no entry of `q` or `v`
    /// ([`Mimic`]; Pinocchio's `JointModelMimic`). Its `limits` are kept on the joint but add
    /// nothing to [`Model::lower_limits`](super::Model::lower_limits).
    ///
    /// # Errors
    /// As [`add_joint`](Self::add_joint), and [`ModelError::BadMimic`] when `kind` is not
    /// revolute or prismatic, `master` does not exist yet, is not a revolute or prismatic joint,
    /// is itself coupled (Pinocchio refuses chains too), or `multiplier`, `offset` are not
    /// finite.
    #[allow(clippy::too_many_arguments)]
    pub fn add_mimic_joint(
        &mut self,
        parent: JointIndex,
        name: &str,
        kind: JointType,
        placement: Se3,
        limits: JointLimits,
        master: JointIndex,
        multiplier: f64,
        offset: f64,
    ) -> Result<JointIndex, ModelError> {
        let bad = |master: String, reason: &str| ModelError::BadMimic {
            joint: name.into(),
            master,
            reason: reason.into(),
        };
        let Some(m) = self.model.joints.get(master).filter(|_| master != 0) else {
            return Err(bad(format!("#{master}"), "no such joint before it"));
        };
        let one_dof = |k: &JointType| matches!(k, JointType::Revolute(_) | JointType::Prismatic(_));
        if !one_dof(&kind) {
            return Err(bad(m.name.clone(), "only revolute and prismatic joints can be coupled"));
        }
        if !one_dof(&m.kind) {
            return Err(bad(m.name.clone(), "the master is not a revolute or prismatic joint"));
        }
        if m.mimic.is_some() {
            return Err(bad(
                m.name.clone(),
                "the master is itself coupled (chains of mimic joints are not supported)",
            ));
        }
        if !multiplier.is_finite() || !offset.is_finite() {
            return Err(bad(
                m.name.clone(),
                &format!("multiplier {multiplier} and offset {offset} must be finite"),
            ));
        }
        let (idx_q, idx_v) = (m.idx_q, m.idx_v);
        // Validate name, placement and limits exactly as an ordinary joint.
        let (nq, nv) = (self.model.nq, self.model.nv);
        let (nlower, nupper) = (self.model.lower.len(), self.model.upper.len());
        let index = self.add_joint(parent, name, kind, placement, limits)?;
        let model = &mut self.model;
        model.nq = nq;
        model.nv = nv;
        model.lower.truncate(nlower);
        model.upper.truncate(nupper);
        let j = &mut model.joints[index];
        j.idx_q = idx_q;
        j.idx_v = idx_v;
        j.mimic = Some(Mimic { master, multiplier, offset, column: 0 });
        model.mimic_joints.push(index);
        Ok(index)
    }
}
