//! Forward kinematics by the product of exponentials (Murray, Li & Sastry ch. 3.2).
//!
//! For the chain of joints `1..n` that carries a frame, take every joint at the neutral
//! configuration: its world placement `M_i⁰`, its *space screw* `S_i = Ad(M_i⁰) S_i^local`
//! (a twist in the world frame: for a revolute joint `(-ω × q, ω)` with `ω` its world axis and
//! `q` a point on it) and the frame's *home* placement `M = world_M_f(q⁰)`. Then
//!
//! ```text
//! space form:  world_M_f(θ) = e^{Ŝ₁θ₁} e^{Ŝ₂θ₂} ··· e^{Ŝₙθₙ} M
//! body form:   world_M_f(θ) = M e^{B̂₁θ₁} e^{B̂₂θ₂} ··· e^{B̂ₙθₙ},     B_i = Ad(M⁻¹) S_i
//! ```
//!
//! and the Jacobians are, column by column,
//!
//! ```text
//! space (= WORLD):  J_s,i = Ad(e^{Ŝ₁θ₁} ··· e^{Ŝ_{i-1}θ_{i-1}}) S_i
//! body  (= LOCAL):  J_b,i = Ad(e^{B̂_{i+1}θ_{i+1}} ··· e^{B̂ₙθₙ})⁻¹ B_i
//! ```
//!
//! A spherical or free joint has no single screw; its factor is the conjugated joint motion
//! `M_i⁰ X_J(q_i) (M_i⁰)⁻¹` (space form) or `(M⁻¹M_i⁰) X_J(q_i) (M⁻¹M_i⁰)⁻¹` (body form), which
//! is exactly what `e^{Ŝθ}` is for a one-degree-of-freedom joint; its columns are
//! `Ad(factors up to and including i) Ad(M_i⁰) S_k^local` and the body analogue.
//!
//! A coupled joint ([`crate::model::Mimic`]) at `multiplier · θ_master + offset` is the factor
//! `e^{Ŝ (multiplier θ_master)}` about its neutral placement (which includes the offset), and
//! its column, times the multiplier, adds to its master's.
//!
//! This is the formulation the analytic inverse kinematics (Paden-Kahan) works in; joint-frame
//! composition ([`crate::forward_kinematics`]) is the fast path. The tests check that both forms
//! agree with it to rounding.

use anim_core::lie::{Se3, Twist};

use crate::config::neutral;
use crate::data::Data;
use crate::jacobian::Jacobian;
use crate::kinematics::frames_forward_kinematics;
use crate::model::{FrameIndex, JointIndex, JointType, Model};

/// One joint of a [`PoeChain`].
#[derive(Debug, Clone, PartialEq)]
struct PoeJoint {
    joint: JointIndex,
    kind: JointType,
    idx_q: usize,
    idx_v: usize,
    /// `1`, or the multiplier of a coupled joint ([`crate::model::Mimic`]): the joint turns by
    /// `scale · q[idx_q]` from its neutral placement (which includes the coupling's offset).
    scale: f64,
    /// World placement at the neutral configuration.
    zero: Se3,
    /// `M⁻¹ M_i⁰`.
    zero_in_home: Se3,
    /// Space screws `Ad(M_i⁰) S_k^local`, one per velocity entry.
    space: Vec<Twist>,
    /// Body screws `Ad(M⁻¹ M_i⁰) S_k^local`.
    body: Vec<Twist>,
}

impl PoeJoint {
    fn space_factor(&self, q: &[f64]) -> Se3 {
        let qi = &q[self.idx_q..self.idx_q + self.kind.nq()];
        match self.kind {
            JointType::Revolute(_) | JointType::Prismatic(_) => {
                Se3::exp_screw(self.space[0], self.scale * qi[0])
            }
            _ => self.zero * self.kind.transform(qi) * self.zero.inverse(),
        }
    }

    fn body_factor(&self, q: &[f64]) -> Se3 {
        let qi = &q[self.idx_q..self.idx_q + self.kind.nq()];
        match self.kind {
            JointType::Revolute(_) | JointType::Prismatic(_) => {
                Se3::exp_screw(self.body[0], self.scale * qi[0])
            }
            _ => self.zero_in_home * self.kind.transform(qi) * self.zero_in_home.inverse(),
        }
    }
}

/// The product-of-exponentials description of the chain carrying one frame: screws at the
/// neutral configuration and the home placement. Built once per frame; evaluating it allocates
/// nothing.
#[derive(Debug, Clone, PartialEq)]
pub struct PoeChain {
    frame: FrameIndex,
    home: Se3,
    nq: usize,
    nv: usize,
    joints: Vec<PoeJoint>,
}

impl PoeChain {
    /// The chain from the root to frame `frame` of `model` (fixed joints are skipped: they only
    /// change the home placement).
    ///
    /// # Panics
    /// When `frame` is out of range.
    #[must_use]
    #[track_caller]
    pub fn new(model: &Model, frame: FrameIndex) -> Self {
        let mut data = Data::new(model);
        let q0 = neutral(model);
        frames_forward_kinematics(model, &mut data, &q0);
        let home = data.frame_placements[frame];
        let home_inv = home.inverse();
        let joints = model
            .support(model.frame(frame).parent_joint)
            .into_iter()
            .filter(|&j| model.joint(j).kind.nv() > 0)
            .map(|j| {
                let jt = model.joint(j);
                let zero = data.world_placements[j];
                let zero_in_home = home_inv * zero;
                let local: Vec<Twist> =
                    (0..jt.kind.nv()).map(|k| jt.kind.motion_subspace_column(k)).collect();
                PoeJoint {
                    joint: j,
                    kind: jt.kind,
                    idx_q: jt.idx_q,
                    idx_v: jt.idx_v,
                    scale: jt.mimic.map_or(1.0, |m| m.multiplier),
                    zero,
                    zero_in_home,
                    space: local.iter().map(|s| zero.adjoint(*s)).collect(),
                    body: local.iter().map(|s| zero_in_home.adjoint(*s)).collect(),
                }
            })
            .collect();
        Self { frame, home, nq: model.nq(), nv: model.nv(), joints }
    }

    /// The frame this chain ends at.
    #[must_use]
    pub fn frame(&self) -> FrameIndex {
        self.frame
    }

    /// The home placement `M` (the frame at the neutral configuration).
    #[must_use]
    pub fn home(&self) -> Se3 {
        self.home
    }

    /// The moving joints of the chain, root first.
    #[must_use]
    pub fn joints(&self) -> Vec<JointIndex> {
        self.joints.iter().map(|j| j.joint).collect()
    }

    /// The space screws `S_i` of the chain's one-degree-of-freedom joints (and every column of
    /// its multi-degree-of-freedom joints), root first.
    #[must_use]
    pub fn space_screws(&self) -> Vec<Twist> {
        self.joints.iter().flat_map(|j| j.space.iter().copied()).collect()
    }

    /// The body screws `B_i = Ad(M⁻¹) S_i`, root first.
    #[must_use]
    pub fn body_screws(&self) -> Vec<Twist> {
        self.joints.iter().flat_map(|j| j.body.iter().copied()).collect()
    }

    #[track_caller]
    fn check_q(&self, q: &[f64]) {
        assert_eq!(q.len(), self.nq, "q has length {}, the model nq = {}", q.len(), self.nq);
    }

    /// `e^{Ŝ₁θ₁} ··· e^{Ŝₙθₙ} M`.
    ///
    /// # Panics
    /// When `q.len()` is not the model's `nq`.
    #[must_use]
    #[track_caller]
    pub fn forward_space(&self, q: &[f64]) -> Se3 {
        self.check_q(q);
        self.joints.iter().fold(Se3::IDENTITY, |g, j| g * j.space_factor(q)) * self.home
    }

    /// `M e^{B̂₁θ₁} ··· e^{B̂ₙθₙ}`.
    ///
    /// # Panics
    /// When `q.len()` is not the model's `nq`.
    #[must_use]
    #[track_caller]
    pub fn forward_body(&self, q: &[f64]) -> Se3 {
        self.check_q(q);
        self.joints.iter().fold(self.home, |g, j| g * j.body_factor(q))
    }

    /// The space Jacobian (equal to the frame's [`ReferenceFrame::World`](crate::ReferenceFrame)
    /// Jacobian) by the product-of-exponentials formula; columns outside the chain are zero.
    ///
    /// # Panics
    /// When `q` or `out` does not match the model.
    #[track_caller]
    pub fn jacobian_space(&self, q: &[f64], out: &mut Jacobian) {
        self.check_q(q);
        assert_eq!(
            out.ncols(),
            self.nv,
            "output Jacobian has {} columns, the model nv = {}",
            out.ncols(),
            self.nv
        );
        out.fill_zero();
        let mut prefix = Se3::IDENTITY;
        for j in &self.joints {
            let one_dof = j.kind.nv() == 1;
            if !one_dof {
                prefix *= j.space_factor(q);
            }
            for (k, s) in j.space.iter().enumerate() {
                // `+=`: a coupled joint adds to its master's column.
                out.columns_mut()[j.idx_v + k] += prefix.adjoint(*s).scale(j.scale);
            }
            if one_dof {
                prefix *= j.space_factor(q);
            }
        }
    }

    /// The body Jacobian (equal to the frame's [`ReferenceFrame::Local`](crate::ReferenceFrame)
    /// Jacobian) by the product-of-exponentials formula; columns outside the chain are zero.
    ///
    /// # Panics
    /// When `q` or `out` does not match the model.
    #[track_caller]
    pub fn jacobian_body(&self, q: &[f64], out: &mut Jacobian) {
        self.check_q(q);
        assert_eq!(
            out.ncols(),
            self.nv,
            "output Jacobian has {} columns, the model nv = {}",
            out.ncols(),
            self.nv
        );
        out.fill_zero();
        // suffix = G_{i+1} ··· G_n (for a one-dof joint G_i commutes with its own screw, so
        // including it changes nothing; for a multi-dof joint it must be excluded).
        let mut suffix = Se3::IDENTITY;
        for j in self.joints.iter().rev() {
            let one_dof = j.kind.nv() == 1;
            if one_dof {
                suffix = j.body_factor(q) * suffix;
            }
            for (k, b) in j.body.iter().enumerate() {
                out.columns_mut()[j.idx_v + k] += suffix.adjoint_inv(*b).scale(j.scale);
            }
            if !one_dof {
                suffix = j.body_factor(q) * suffix;
            }
        }
    }
}
