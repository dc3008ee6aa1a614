//! Quadratic (10-node) tetrahedra: the element that does not lock where linear tetrahedra do
//! (bending-dominated beams, nearly incompressible materials such as Cook's membrane with
//! `nu = 0.4999`), for time stepping and quasi-static solves.
//!
//! The element itself is [`tet10`](crate::tet10): shape functions `N_a = L_a (2 L_a - 1)` at the
//! corners and `N_ab = 4 L_a L_b` at the edge nodes, the 4-point rule exact for quadratics, the
//! closed-form consistent mass and its HRZ lumping ([`consistent_mass_coefficient`] and
//! [`lumped_mass_coefficient`], re-exported here).
//!
//! The dynamic body is a [`FemModel`] built with
//! [`FemModel::quadratic`](crate::model::FemModel::quadratic) (every boundary condition, load,
//! obstacle and both time integrators of the linear body); [`QuadraticModel`] is the
//! quasi-static front end the conformance cases use.

use crate::boundary::Colliders;
use crate::error::FemError;
use crate::generate::Tet10Mesh;
use crate::material::Material;
use crate::model::FemModel;
use crate::newton::{self, ElasticBody, NewtonData, NewtonInfo, NewtonSettings, Potential};
use crate::sim::LinearSolverChoice;
use anim_core::linalg::{IterativeParams, LinearSolver};

pub use crate::tet10::{consistent_mass_coefficient, lumped_mass_coefficient};

/// A body of 10-node tetrahedra with fixed coordinates and nodal loads, solved quasi-statically:
/// a [`FemModel::quadratic`] without mass, gravity or contact, with its own Newton scratch per
/// solve.
#[derive(Debug, Clone)]
pub struct QuadraticModel {
    mesh: Tet10Mesh,
    model: FemModel,
}

impl QuadraticModel {
    /// A body from a 10-node mesh (from [`generate::quadratic`](crate::generate::quadratic)).
    ///
    /// # Errors
    /// The validation errors of the corner mesh (degenerate or inverted elements), edge nodes
    /// out of range or off their edge's midpoint ([`FemError::CurvedElement`]).
    pub fn new(mesh: Tet10Mesh, material: Material) -> Result<Self, FemError> {
        let model = FemModel::quadratic(mesh.clone(), material)?;
        Ok(Self { mesh, model })
    }

    /// The mesh.
    #[must_use]
    pub fn mesh(&self) -> &Tet10Mesh {
        &self.mesh
    }

    /// The underlying body.
    #[must_use]
    pub fn model(&self) -> &FemModel {
        &self.model
    }

    /// Number of nodes.
    #[must_use]
    pub fn nodes(&self) -> usize {
        self.mesh.positions.len()
    }

    /// Fixes the coordinates `mask` of every node for which `select(X)` holds; returns how many
    /// nodes were selected.
    pub fn fix_where(&mut self, select: impl Fn([f64; 3]) -> bool, mask: [bool; 3]) -> usize {
        let mut count = 0;
        for i in self.model.vertices_where(select) {
            if self.model.pin(i, mask).is_ok() {
                count += 1;
            }
        }
        count
    }

    /// Adds the consistent nodal loads of a uniform traction `t` (force per rest area) on the
    /// boundary faces whose centroid satisfies `select`: on a 6-node triangle of area `A` the
    /// corners get 0 and the edge nodes `A t / 3` each. Returns the loaded area.
    pub fn add_traction(&mut self, select: impl Fn([f64; 3]) -> bool, t: [f64; 3]) -> f64 {
        self.model.add_traction(select, t)
    }

    /// Rest positions, flat.
    #[must_use]
    pub fn rest_positions(&self) -> Vec<f64> {
        self.model.rest_positions()
    }

    /// Static equilibrium under the nodal loads applied in `load_steps` increments; `x` holds
    /// the initial guess (fixed coordinates at their values) and receives the solution.
    /// `tolerance` bounds the last Newton update (length units).
    ///
    /// # Errors
    /// As [`newton::minimize`].
    pub fn solve_static(
        &self,
        x: &mut [f64],
        load_steps: usize,
        tolerance: f64,
        solver: LinearSolverChoice,
        project: bool,
    ) -> Result<NewtonInfo, FemError> {
        let model = &self.model;
        let mut data = NewtonData::new(model.assembly(), model.elements());
        let mut linear: Box<dyn LinearSolver> = solver.build(IterativeParams::new(1e-10, 100_000));
        let lumped = vec![0.0; self.nodes()];
        let mut external = vec![0.0; x.len()];
        let steps = load_steps.max(1);
        let mut total = NewtonInfo::default();
        for s in 1..=steps {
            model.external_force(s as f64 / steps as f64, &mut external);
            let pot = Potential {
                inertia: None,
                lumped_mass: &lumped,
                consistent_mass: None,
                damping: None,
                external: &external,
                obstacles: Colliders::default(),
                contact_stiffness: 0.0,
                friction: &[],
                fixed: model.fixed(),
                project,
            };
            let settings = NewtonSettings { tolerance, max_iterations: 100, step: s as u64 };
            let info =
                newton::minimize(model, model.assembly(), &pot, x, &mut data, linear.as_mut(), settings)?;
            total.iterations += info.iterations;
            total.linear_iterations += info.linear_iterations;
            total.last_update = info.last_update;
            total.energy = info.energy;
        }
        Ok(total)
    }
}

impl ElasticBody for QuadraticModel {
    fn elements(&self) -> usize {
        self.model.elements()
    }

    fn per_element(&self) -> usize {
        10
    }

    fn element(
        &self,
        e: usize,
        x: &[f64],
        grad: Option<&mut [f64]>,
        hess: Option<&mut [f64]>,
        project: bool,
    ) -> f64 {
        self.model.element(e, x, grad, hess, project)
    }

    fn det_f(&self, e: usize, x: &[f64]) -> f64 {
        self.model.det_f(e, x)
    }
}
