//! The per-query workspace of a [`Model`]: every buffer an algorithm writes, sized once.

use anim_core::lie::{Se3, Twist};

use crate::dense::SquareMatrix;
use crate::matrix6x::Jacobian;
use crate::model::Model;
use crate::spatial::{ArticulatedInertia, Force, Motion, SpatialInertia};

/// Marks "no parent degree of freedom" in [`Data::dof_parents`].
pub const NO_PARENT: usize = usize::MAX;

/// Results and scratch of the kinematics and dynamics algorithms for one [`Model`] (Pinocchio's
/// `Data`).
///
/// Made once with [`Data::new`] and reused for any number of queries: no algorithm allocates.
/// Which fields are valid depends on what ran last:
///
/// | field | written by |
/// | --- | --- |
/// | `joint_placements` | [`forward_kinematics`](crate::forward_kinematics) and every dynamics algorithm |
/// | `world_placements` | [`forward_kinematics`](crate::forward_kinematics), Jacobians, [`crba_world`](crate::crba_world), [`aba`](crate::aba), [`potential_energy`](crate::potential_energy), [`spatial_momentum`](crate::spatial_momentum), [`center_of_mass`](crate::center_of_mass) |
/// | `frame_placements` | [`update_frame_placements`](crate::update_frame_placements), [`frames_forward_kinematics`](crate::frames_forward_kinematics) |
/// | `jacobian` | [`compute_joint_jacobians`](crate::compute_joint_jacobians), [`crba_world`](crate::crba_world), [`aba`](crate::aba) |
/// | `velocities` | [`compute_joint_jacobians_time_variation`](crate::compute_joint_jacobians_time_variation), [`aba`](crate::aba) |
/// | `jacobian_dot` | [`compute_joint_jacobians_time_variation`](crate::compute_joint_jacobians_time_variation) |
/// | `tau`, `body_velocities`, `body_accelerations`, `body_forces` | [`rnea`](crate::rnea) (and `tau` by [`nonlinear_effects`](crate::nonlinear_effects), [`gravity_torques`](crate::gravity_torques)); `body_velocities` also by [`kinetic_energy`](crate::kinetic_energy) and [`spatial_momentum`](crate::spatial_momentum) |
/// | `nle` | [`nonlinear_effects`](crate::nonlinear_effects), [`forward_dynamics_cholesky`](crate::forward_dynamics_cholesky) |
/// | `gravity_torques` | [`gravity_torques`](crate::gravity_torques) |
/// | `mass_matrix`, `composite_inertias` | [`crba`](crate::crba), [`forward_dynamics_cholesky`](crate::forward_dynamics_cholesky) |
/// | `mass_matrix_factor` | [`factor_mass_matrix`](crate::factor_mass_matrix), [`forward_dynamics_cholesky`](crate::forward_dynamics_cholesky) |
/// | `ddq`, `articulated_inertias`, `articulated_forces`, `world_accelerations` | [`aba`](crate::aba) (`ddq` also by [`forward_dynamics_cholesky`](crate::forward_dynamics_cholesky)) |
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
    /// With coupled joints it has [`Model::nv_extended`] columns: each coupled joint's own
    /// motion follows the `nv` columns ([`crate::model::Mimic::column`]).
    pub jacobian: Jacobian,
    /// Time derivative of [`jacobian`](Self::jacobian) along the velocity last given to
    /// [`compute_joint_jacobians_time_variation`](crate::compute_joint_jacobians_time_variation).
    pub jacobian_dot: Jacobian,
    /// Spatial velocity of every joint's body, in the world frame at the world origin.
    pub velocities: Vec<Twist>,
    /// Joint torques (length `nv`): the result of [`rnea`](crate::rnea).
    pub tau: Vec<f64>,
    /// The bias term `C(q, v) = RNEA(q, v, 0)`, gravity included (length `nv`).
    pub nle: Vec<f64>,
    /// The gravity term `g(q) = RNEA(q, 0, 0)` (length `nv`).
    pub gravity_torques: Vec<f64>,
    /// Joint accelerations `q̈` (length `nv`): the result of [`aba`](crate::aba).
    pub ddq: Vec<f64>,
    /// The joint-space mass matrix `H(q)`, `nv x nv`, both triangles filled.
    pub mass_matrix: SquareMatrix,
    /// The `Lᵀ D L` factor of `H` (Featherstone's LTDL): `D` on the diagonal, `L` (unit, with
    /// the sparsity of the tree) below it; the upper triangle is `H`'s.
    pub mass_matrix_factor: SquareMatrix,
    /// Spatial velocity of every body in its own joint frame (RNEA's forward pass).
    pub body_velocities: Vec<Motion>,
    /// Spatial acceleration of every body in its own joint frame, **minus gravity** (the root is
    /// given the acceleration `-g`, Featherstone's gravity trick).
    pub body_accelerations: Vec<Motion>,
    /// Spatial force transmitted across each joint to its body, in the joint frame (RNEA's
    /// backward pass: the body's own `I a + v ×f I v` plus its children's).
    pub body_forces: Vec<Force>,
    /// Composite-rigid-body inertia of every subtree (CRBA): in the world frame after
    /// [`crba_world`](crate::dynamics::crba_world), in the joint's own frame after
    /// [`crba_local`](crate::dynamics::crba_local).
    pub composite_inertias: Vec<SpatialInertia>,
    /// Articulated-body inertia `Iᴬ` of every subtree, world frame (ABA).
    pub articulated_inertias: Vec<ArticulatedInertia>,
    /// Articulated-body bias force `pᴬ` of every subtree, world frame (ABA).
    pub articulated_forces: Vec<Force>,
    /// Spatial acceleration of every body in the world frame **minus gravity** (ABA's last pass).
    pub world_accelerations: Vec<Motion>,
    /// The parent of each degree of freedom in the tree of degrees of freedom (the previous
    /// degree of freedom of the same joint, or the last one of the nearest moving ancestor;
    /// [`NO_PARENT`] at a root): the sparsity pattern of `H` and of its factor. With coupled
    /// joints ([`Model::mimic_joints`]) `H` is treated as dense: degree of freedom `k`'s parent
    /// is `k - 1`.
    pub dof_parents: Vec<usize>,
    /// Mean number of degrees of freedom from each degree of freedom to the root (itself
    /// included): chooses between the two forms of CRBA.
    pub(crate) mean_dof_depth: f64,
    /// The model's body inertias in Featherstone's form, each in its joint frame (constant;
    /// computed once here so RNEA does not convert them at every call).
    pub(crate) body_inertias: Vec<SpatialInertia>,
    /// ABA: `U = Iᴬ S` per degree of freedom.
    pub(crate) aba_u: Vec<Force>,
    /// ABA: row of `D⁻¹ = (Sᵀ Iᴬ S)⁻¹` per degree of freedom (its joint's block, padded).
    pub(crate) aba_dinv: Vec<[f64; 6]>,
    /// ABA: `u = τ - Sᵀ pᴬ` per degree of freedom.
    pub(crate) aba_uu: Vec<f64>,
    /// ABA: velocity-product acceleration `c = v ×ₘ (S q̇)` of every body, world frame.
    pub(crate) aba_bias: Vec<Motion>,
    /// Scratch of length `nv` (right-hand sides).
    pub(crate) scratch: Vec<f64>,
}

impl Data {
    /// A workspace sized for `model`, with identity placements and zero Jacobians.
    #[must_use]
    pub fn new(model: &Model) -> Self {
        Self {
            joint_placements: vec![Se3::IDENTITY; model.njoints()],
            world_placements: vec![Se3::IDENTITY; model.njoints()],
            frame_placements: vec![Se3::IDENTITY; model.frames().len()],
            jacobian: Jacobian::zeros(model.nv_extended()),
            jacobian_dot: Jacobian::zeros(model.nv_extended()),
            velocities: vec![Twist::ZERO; model.njoints()],
            tau: vec![0.0; model.nv()],
            nle: vec![0.0; model.nv()],
            gravity_torques: vec![0.0; model.nv()],
            ddq: vec![0.0; model.nv()],
            mass_matrix: SquareMatrix::zeros(model.nv()),
            mass_matrix_factor: SquareMatrix::zeros(model.nv()),
            body_velocities: vec![Motion::ZERO; model.njoints()],
            body_accelerations: vec![Motion::ZERO; model.njoints()],
            body_forces: vec![Force::ZERO; model.njoints()],
            composite_inertias: vec![SpatialInertia::ZERO; model.njoints()],
            articulated_inertias: vec![ArticulatedInertia::ZERO; model.njoints()],
            articulated_forces: vec![Force::ZERO; model.njoints()],
            world_accelerations: vec![Motion::ZERO; model.njoints()],
            mean_dof_depth: mean_depth(&dof_parents(model)),
            dof_parents: dof_parents(model),
            body_inertias: model.inertias().iter().map(SpatialInertia::from).collect(),
            aba_u: vec![Force::ZERO; model.nv()],
            aba_dinv: vec![[0.0; 6]; model.nv()],
            aba_uu: vec![0.0; model.nv()],
            aba_bias: vec![Motion::ZERO; model.njoints()],
            scratch: vec![0.0; model.nv()],
        }
    }

    /// Whether this workspace has the sizes of `model`.
    #[must_use]
    pub fn fits(&self, model: &Model) -> bool {
        self.joint_placements.len() == model.njoints()
            && self.world_placements.len() == model.njoints()
            && self.frame_placements.len() == model.frames().len()
            && self.jacobian.ncols() == model.nv_extended()
            && self.jacobian_dot.ncols() == model.nv_extended()
            && self.velocities.len() == model.njoints()
            && self.tau.len() == model.nv()
            && self.mass_matrix.n() == model.nv()
            && self.body_velocities.len() == model.njoints()
            && self.dof_parents.len() == model.nv()
    }
}

/// Mean over the degrees of freedom of the length of their path to the root (1 for a root).
fn mean_depth(parents: &[usize]) -> f64 {
    if parents.is_empty() {
        return 0.0;
    }
    let mut depth = vec![0usize; parents.len()];
    for k in 0..parents.len() {
        depth[k] = if parents[k] == NO_PARENT { 1 } else { depth[parents[k]] + 1 };
    }
    depth.iter().sum::<usize>() as f64 / parents.len() as f64
}

/// The parent of each degree of freedom (see [`Data::dof_parents`]).
fn dof_parents(model: &Model) -> Vec<usize> {
    if !model.mimic_joints().is_empty() {
        // Coupling fills entries of the mass matrix between branches: treat it as dense (a
        // chain), which the factorisation and the coupled CRBA handle.
        return (0..model.nv()).map(|k| if k == 0 { NO_PARENT } else { k - 1 }).collect();
    }
    let mut parents = vec![NO_PARENT; model.nv()];
    for j in &model.joints()[1..] {
        if j.nv() == 0 {
            continue;
        }
        // The last degree of freedom of the nearest ancestor that has one.
        let mut a = j.parent;
        let mut above = NO_PARENT;
        while a != 0 {
            let pj = model.joint(a);
            if pj.nv() > 0 {
                above = pj.idx_v + pj.nv() - 1;
                break;
            }
            a = pj.parent;
        }
        parents[j.idx_v] = above;
        for k in 1..j.nv() {
            parents[j.idx_v + k] = j.idx_v + k - 1;
        }
    }
    parents
}
