//! The per-query workspace of a [`Model`]: every buffer an algorithm writes, sized once.

use anim_core::lie::{Se3, Twist};

use crate::jacobian::Jacobian;
use crate::model::Model;

/// Results and scratch of the kinematics algorithms for one [`Model`] (Pinocchio's `Data`).
///
/// Made once with [`Data::new`] and reused for any number of queries: no algorithm allocates.
/// Which fields are valid depends on what ran last:
///
/// | field | written by |
/// | --- | --- |
/// | `joint_placements`, `world_placements` | [`forward_kinematics`](crate::forward_kinematics) and everything that calls it |
/// | `frame_placements` | [`update_frame_placements`](crate::update_frame_placements), [`frames_forward_kinematics`](crate::frames_forward_kinematics) |
/// | `jacobian` | [`compute_joint_jacobians`](crate::compute_joint_jacobians) |
/// | `velocities`, `jacobian_dot` | [`compute_joint_jacobians_time_variation`](crate::compute_joint_jacobians_time_variation) |
///
/// Several threads can share one `&Model`, each with its own `Data`.
#[derive(Debug, Clone, PartialEq)]
pub struct Data {
    /// `parent_M_i`: placement of each joint frame in its parent joint's frame (index 0: identity).
    pub joint_placements: Vec<Se3>,
    /// `world_M_i`: placement of each joint frame in the world (index 0: identity).
    pub world_placements: Vec<Se3>,
    /// `world_M_f`: placement of each frame in the world.
    pub frame_placements: Vec<Se3>,
    /// The world (spatial) Jacobian of every joint, `6 x nv`: column `k` is the spatial twist
    /// `Ad(world_M_i) S_k` (linear part first, at the world origin) of the joint `i` owning
    /// velocity entry `k`. A joint's own Jacobian is this matrix restricted to its support.
    pub jacobian: Jacobian,
    /// Time derivative of [`jacobian`](Self::jacobian) along the velocity last given to
    /// [`compute_joint_jacobians_time_variation`](crate::compute_joint_jacobians_time_variation).
    pub jacobian_dot: Jacobian,
    /// Spatial velocity of every joint's body, in the world frame at the world origin.
    pub velocities: Vec<Twist>,
}

impl Data {
    /// A workspace sized for `model`, with identity placements and zero Jacobians.
    #[must_use]
    pub fn new(model: &Model) -> Self {
        Self {
            joint_placements: vec![Se3::IDENTITY; model.njoints()],
            world_placements: vec![Se3::IDENTITY; model.njoints()],
            frame_placements: vec![Se3::IDENTITY; model.frames().len()],
            jacobian: Jacobian::zeros(model.nv()),
            jacobian_dot: Jacobian::zeros(model.nv()),
            velocities: vec![Twist::ZERO; model.njoints()],
        }
    }

    /// Whether this workspace has the sizes of `model`.
    #[must_use]
    pub fn fits(&self, model: &Model) -> bool {
        self.joint_placements.len() == model.njoints()
            && self.world_placements.len() == model.njoints()
            && self.frame_placements.len() == model.frames().len()
            && self.jacobian.ncols() == model.nv()
            && self.jacobian_dot.ncols() == model.nv()
            && self.velocities.len() == model.njoints()
    }
}
