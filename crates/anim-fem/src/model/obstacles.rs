//! The model's rigid obstacles: shapes and triangle meshes, each with a friction coefficient,
//! and the penalty stiffness they share (see [`boundary`](crate::boundary)).

use anim_core::surface::DistanceField;

use super::FemModel;
use crate::boundary::{Colliders, Obstacle};
use crate::error::FemError;

impl FemModel {
    /// Adds a frictionless obstacle with penalty stiffness `stiffness` for implicit steps (the
    /// largest stiffness given is used for all obstacles).
    ///
    /// # Errors
    /// [`FemError::BadParameter`] for a non-positive stiffness; [`FemError::BadObstacle`] for a
    /// shape that fails [`Shape::check`](anim_core::geometry::Shape::check) (a non-positive
    /// sphere radius or box half extent, a zero plane normal, a capsule whose ends coincide).
    pub fn add_obstacle(&mut self, obstacle: Obstacle, stiffness: f64) -> Result<(), FemError> {
        self.add_obstacle_with_friction(obstacle, stiffness, 0.0)
    }

    /// Adds an obstacle with penalty stiffness `stiffness` (as [`add_obstacle`](Self::add_obstacle))
    /// and Coulomb friction coefficient `friction` (`mu >= 0`; 0 is frictionless), see
    /// [`friction`](crate::friction).
    ///
    /// # Errors
    /// [`FemError::BadParameter`] for a negative or non-finite friction coefficient (named
    /// `friction`), a non-positive stiffness; [`FemError::BadObstacle`] as for `add_obstacle`.
    pub fn add_obstacle_with_friction(
        &mut self,
        obstacle: Obstacle,
        stiffness: f64,
        friction: f64,
    ) -> Result<(), FemError> {
        check_contact(stiffness, friction)?;
        let index = self.obstacles.len();
        let bad = |reason: String| FemError::BadObstacle { obstacle: index, reason };
        obstacle.check().map_err(bad)?;
        self.obstacles.push(obstacle);
        self.friction.push(friction);
        self.contact_stiffness = self.contact_stiffness.max(stiffness);
        Ok(())
    }

    /// Adds a rigid obstacle bounded by a closed triangle mesh, given as the signed distance
    /// field of the placed mesh (anim-core's [`DistanceField`], e.g. from
    /// [`DistanceField::around`] or a scene file's
    /// [`ObstacleMesh::field`](anim_core::scene::ObstacleMesh::field)), with penalty stiffness
    /// `stiffness` (as [`add_obstacle`](Self::add_obstacle): the largest given is used for all
    /// obstacles) and Coulomb friction coefficient `friction` (`>= 0`). Contact treats it as
    /// it treats a shape, with `(phi, n)` looked up in the field (see
    /// [`boundary`](crate::boundary)); vertices outside the field's lattice are not in contact.
    ///
    /// ```
    /// use anim_core::solver::Solver;
    /// use anim_core::surface::{ClosedSurface, DistanceField, icosphere};
    /// use anim_fem::generate::box_mesh;
    /// use anim_fem::material::{Material, MaterialModel};
    /// use anim_fem::model::{EARTH_GRAVITY, FemModel};
    /// use anim_fem::sim::{FemParams, FemSimulation, TimeIntegrator};
    ///
    /// // A ball of radius 0.5 m (an icosphere of 1280 triangles) sampled every 5 cm.
    /// let (p, t) = icosphere(3);
    /// let ball = ClosedSurface::new(p.iter().map(|v| v.map(|c| 0.5 * c)).collect(), t)?;
    /// let field = DistanceField::around(&ball, 0.05, 0.1)?;
    /// // A 10 cm cube falling onto its top.
    /// let mesh = box_mesh([-0.05, -0.05, 0.52], [0.1; 3], [2, 2, 2])?;
    /// let material = Material::new(MaterialModel::StableNeoHookean, 1e5, 0.3, 1000.0)?;
    /// let mut model = FemModel::new(mesh, material)?.with_gravity(EARTH_GRAVITY);
    /// model.add_mesh_obstacle(field, 1e6, 0.0)?;
    /// let mut sim = FemSimulation::new(model, FemParams::new(TimeIntegrator::BackwardEuler))?;
    /// let mut state = sim.rest_state();
    /// for _ in 0..30 {
    ///     sim.step(&mut state, 0.01)?;
    /// }
    /// let lowest = state.x.chunks(3).map(|p| p[2]).fold(f64::INFINITY, f64::min);
    /// assert!((lowest - 0.5).abs() < 0.01, "resting on the ball: {lowest}");
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    ///
    /// # Errors
    /// [`FemError::BadParameter`] for a negative or non-finite friction coefficient (named
    /// `friction`), a non-positive stiffness.
    pub fn add_mesh_obstacle(
        &mut self,
        field: DistanceField,
        stiffness: f64,
        friction: f64,
    ) -> Result<(), FemError> {
        check_contact(stiffness, friction)?;
        self.mesh_obstacles.push(field);
        self.mesh_friction.push(friction);
        self.contact_stiffness = self.contact_stiffness.max(stiffness);
        Ok(())
    }

    /// The shape obstacles.
    #[must_use]
    pub fn obstacles(&self) -> &[Obstacle] {
        &self.obstacles
    }

    /// Coulomb friction coefficient of each obstacle (same order as
    /// [`obstacles`](Self::obstacles); 0 for frictionless).
    #[must_use]
    pub fn obstacle_friction(&self) -> &[f64] {
        &self.friction
    }

    /// Penalty stiffness of the obstacles.
    #[must_use]
    pub fn contact_stiffness(&self) -> f64 {
        self.contact_stiffness
    }

    /// The mesh obstacles' distance fields, in the order added.
    #[must_use]
    pub fn mesh_obstacles(&self) -> &[DistanceField] {
        &self.mesh_obstacles
    }

    /// Coulomb friction coefficient of each mesh obstacle (same order as
    /// [`mesh_obstacles`](Self::mesh_obstacles)).
    #[must_use]
    pub fn mesh_obstacle_friction(&self) -> &[f64] {
        &self.mesh_friction
    }

    /// Every obstacle, shapes then meshes, with its friction coefficient, as contact reads them.
    #[must_use]
    pub fn colliders(&self) -> Colliders<'_> {
        Colliders {
            shapes: &self.obstacles,
            shape_friction: &self.friction,
            meshes: &self.mesh_obstacles,
            mesh_friction: &self.mesh_friction,
        }
    }
}

/// Checks a penalty stiffness (positive and finite) and a friction coefficient (`>= 0`, finite).
fn check_contact(stiffness: f64, friction: f64) -> Result<(), FemError> {
    if !(friction >= 0.0) || !friction.is_finite() {
        return Err(FemError::BadParameter {
            name: "friction",
            value: friction,
            reason: "must be finite and >= 0",
        });
    }
    if !(stiffness > 0.0) || !stiffness.is_finite() {
        return Err(FemError::BadParameter {
            name: "contact stiffness",
            value: stiffness,
            reason: "must be finite and > 0",
        });
    }
    Ok(())
}
