//! Quadratic (10-node) tetrahedra for quasi-static solves: the element that does not lock where
//! linear tetrahedra do (bending-dominated beams, nearly incompressible materials such as Cook's
//! membrane with `nu = 0.4999`).
//!
//! Shape functions in barycentric coordinates `L0..L3`: corners `N_a = L_a (2 L_a - 1)`, edge
//! `(a, b)` nodes `N_ab = 4 L_a L_b` (node order of [`TET10_EDGES`]). The deformation gradient
//! varies over the element, `F(X) = sum_a x_a grad N_a(X)^T`, and the energy is integrated with
//! the 4-point rule exact for quadratics (Keast; points `(b, b, b)`, `(a, b, b)`, ... with
//! `a = 0.5854101966249685`, `b = 0.1381966011250105`, weights `1/24`):
//!
//! ```text
//! E_e = sum_q w_q |det J_q| psi(F_q),   dE_e/dx_a = sum_q w_q |det J_q| P(F_q) grad N_a(X_q)
//! ```
//!
//! Edge nodes sit at the midpoints of straight edges (affine elements), so `J` is constant per
//! element. Equilibrium is found by the same Newton minimisation as the linear body
//! ([`newton::minimize`]).

use crate::assembly::Assembly;
use crate::element::add_stiffness;
use crate::error::FemError;
use crate::generate::{TET10_EDGES, Tet10Mesh};
use crate::material::Material;
use crate::mesh::{TetMesh, validate};
use crate::newton::{self, ElasticBody, NewtonData, NewtonInfo, NewtonSettings, Potential};
use crate::sim::LinearSolverChoice;
use anim_core::linalg::{IterativeParams, LinearSolver};
use anim_material::nalgebra::{Matrix3, Vector3};
use std::collections::HashSet;

const QA: f64 = 0.585_410_196_624_968_5;
const QB: f64 = 0.138_196_601_125_010_5;
/// Barycentric coordinates `(L1, L2, L3)` of the four quadrature points.
const POINTS: [[f64; 3]; 4] = [[QB, QB, QB], [QA, QB, QB], [QB, QA, QB], [QB, QB, QA]];
const WEIGHT: f64 = 1.0 / 24.0;

/// Gradients of the ten shape functions with respect to `(L1, L2, L3)` at a point.
fn reference_gradients(p: [f64; 3]) -> [[f64; 3]; 10] {
    let l = [1.0 - p[0] - p[1] - p[2], p[0], p[1], p[2]];
    let dl = [[-1.0, -1.0, -1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let mut g = [[0.0; 3]; 10];
    for a in 0..4 {
        for c in 0..3 {
            g[a][c] = (4.0 * l[a] - 1.0) * dl[a][c];
        }
    }
    for (k, [a, b]) in TET10_EDGES.iter().enumerate() {
        for c in 0..3 {
            g[4 + k][c] = 4.0 * (l[*b] * dl[*a][c] + l[*a] * dl[*b][c]);
        }
    }
    g
}

/// A body of 10-node tetrahedra with fixed coordinates and nodal loads, solved quasi-statically.
#[derive(Debug, Clone)]
pub struct QuadraticModel {
    mesh: Tet10Mesh,
    material: Material,
    weights: Vec<[f64; 4]>,
    grads: Vec<[[[f64; 3]; 10]; 4]>,
    assembly: Assembly,
    fixed: Vec<bool>,
    loads: Vec<f64>,
    boundary: Vec<[usize; 3]>,
}

impl QuadraticModel {
    /// A body from a 10-node mesh (from [`generate::quadratic`](crate::generate::quadratic)).
    ///
    /// # Errors
    /// The validation errors of the corner mesh (degenerate or inverted elements).
    pub fn new(mesh: Tet10Mesh, material: Material) -> Result<Self, FemError> {
        let corners: Vec<[usize; 4]> = mesh.elements.iter().map(|e| [e[0], e[1], e[2], e[3]]).collect();
        validate(&mesh.positions, &corners)?;
        let n = mesh.positions.len();
        let ref_grads = POINTS.map(reference_gradients);
        let mut weights = Vec::with_capacity(mesh.elements.len());
        let mut grads = Vec::with_capacity(mesh.elements.len());
        for (e, el) in mesh.elements.iter().enumerate() {
            let mut w = [0.0; 4];
            let mut g = [[[0.0; 3]; 10]; 4];
            for q in 0..4 {
                // J[i][c] = dX_i / dL_c.
                let mut j = Matrix3::zeros();
                for a in 0..10 {
                    let x = mesh.positions[el[a]];
                    for i in 0..3 {
                        for c in 0..3 {
                            j[(i, c)] += x[i] * ref_grads[q][a][c];
                        }
                    }
                }
                let det = j.determinant();
                let jinv_t = j
                    .try_inverse()
                    .ok_or(FemError::DegenerateElement { element: e, volume6: det, edge: 0.0 })?
                    .transpose();
                w[q] = WEIGHT * det.abs();
                for a in 0..10 {
                    let r = jinv_t * Vector3::from(ref_grads[q][a]);
                    g[q][a] = [r[0], r[1], r[2]];
                }
            }
            weights.push(w);
            grads.push(g);
        }
        let flat: Vec<usize> = mesh.elements.iter().flatten().copied().collect();
        let assembly = Assembly::new(n, 10, &flat);
        let boundary = TetMesh { positions: mesh.positions.clone(), tets: corners }.boundary_triangles();
        Ok(Self {
            mesh,
            material,
            weights,
            grads,
            assembly,
            fixed: vec![false; 3 * n],
            loads: vec![0.0; 3 * n],
            boundary,
        })
    }

    /// The mesh.
    #[must_use]
    pub fn mesh(&self) -> &Tet10Mesh {
        &self.mesh
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
        for (i, p) in self.mesh.positions.iter().enumerate() {
            if select(*p) {
                count += 1;
                for c in 0..3 {
                    self.fixed[3 * i + c] |= mask[c];
                }
            }
        }
        count
    }

    /// Adds the consistent nodal loads of a uniform traction `t` (force per rest area) on the
    /// boundary faces whose centroid satisfies `select`: on a 6-node triangle of area `A` the
    /// corners get 0 and the edge nodes `A t / 3` each. Returns the loaded area.
    pub fn add_traction(&mut self, select: impl Fn([f64; 3]) -> bool, t: [f64; 3]) -> f64 {
        let faces: HashSet<[usize; 3]> = self
            .boundary
            .iter()
            .map(|f| {
                let mut s = *f;
                s.sort_unstable();
                s
            })
            .collect();
        // Local faces with their edge nodes.
        const FACES: [([usize; 3], [usize; 3]); 4] =
            [([0, 1, 2], [4, 5, 6]), ([0, 1, 3], [4, 8, 7]), ([0, 2, 3], [6, 9, 7]), ([1, 2, 3], [5, 9, 8])];
        let mut area_total = 0.0;
        for el in &self.mesh.elements {
            for (corner, edge) in FACES {
                let mut key = corner.map(|c| el[c]);
                key.sort_unstable();
                if !faces.contains(&key) {
                    continue;
                }
                let p = corner.map(|c| Vector3::from(self.mesh.positions[el[c]]));
                let centroid = (p[0] + p[1] + p[2]) / 3.0;
                if !select([centroid[0], centroid[1], centroid[2]]) {
                    continue;
                }
                let area = 0.5 * (p[1] - p[0]).cross(&(p[2] - p[0])).norm();
                area_total += area;
                for e in edge {
                    for c in 0..3 {
                        self.loads[3 * el[e] + c] += area * t[c] / 3.0;
                    }
                }
            }
        }
        area_total
    }

    /// Rest positions, flat.
    #[must_use]
    pub fn rest_positions(&self) -> Vec<f64> {
        self.mesh.positions.iter().flatten().copied().collect()
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
        let mut data = NewtonData::new(&self.assembly, self.mesh.elements.len());
        let mut linear: Box<dyn LinearSolver> = solver.build(IterativeParams::new(1e-10, 100_000));
        let lumped = vec![0.0; self.nodes()];
        let mut external = vec![0.0; x.len()];
        let steps = load_steps.max(1);
        let mut total = NewtonInfo::default();
        for s in 1..=steps {
            let scale = s as f64 / steps as f64;
            for (e, l) in external.iter_mut().zip(&self.loads) {
                *e = scale * l;
            }
            let pot = Potential {
                inertia: None,
                lumped_mass: &lumped,
                consistent_mass: None,
                damping: None,
                external: &external,
                obstacles: &[],
                contact_stiffness: 0.0,
                friction: &[],
                fixed: &self.fixed,
                project,
            };
            let settings = NewtonSettings { tolerance, max_iterations: 100, step: s as u64 };
            let info = newton::minimize(self, &self.assembly, &pot, x, &mut data, linear.as_mut(), settings)?;
            total.iterations += info.iterations;
            total.linear_iterations += info.linear_iterations;
            total.last_update = info.last_update;
            total.energy = info.energy;
        }
        Ok(total)
    }

    fn deformation_gradient(&self, e: usize, q: usize, x: &[f64]) -> Matrix3<f64> {
        let el = &self.mesh.elements[e];
        let g = &self.grads[e][q];
        let mut f = Matrix3::zeros();
        for a in 0..10 {
            let v = el[a];
            for i in 0..3 {
                for j in 0..3 {
                    f[(i, j)] += x[3 * v + i] * g[a][j];
                }
            }
        }
        f
    }
}

impl ElasticBody for QuadraticModel {
    fn elements(&self) -> usize {
        self.mesh.elements.len()
    }

    fn per_element(&self) -> usize {
        10
    }

    fn element(
        &self,
        e: usize,
        x: &[f64],
        mut grad: Option<&mut [f64]>,
        mut hess: Option<&mut [f64]>,
        project: bool,
    ) -> f64 {
        let mat = &self.material;
        let mut energy = 0.0;
        if let Some(g) = grad.as_deref_mut() {
            g.fill(0.0);
        }
        for q in 0..4 {
            let f = self.deformation_gradient(e, q, x);
            let w = self.weights[e][q];
            energy += w * mat.model.energy(&mat.lame, &f);
            let grads = &self.grads[e][q];
            if let Some(g) = grad.as_deref_mut() {
                let p = mat.model.pk1(&mat.lame, &f);
                for a in 0..10 {
                    let r = p * Vector3::from(grads[a]) * w;
                    for i in 0..3 {
                        g[3 * a + i] += r[i];
                    }
                }
            }
            if let Some(h) = hess.as_deref_mut() {
                let c = mat.model.tangent_matrix(&mat.lame, &f, project);
                add_stiffness::<10>(w, grads, &c, h);
            }
        }
        energy
    }

    fn det_f(&self, e: usize, x: &[f64]) -> f64 {
        (0..4).map(|q| self.deformation_gradient(e, q, x).determinant()).fold(f64::INFINITY, f64::min)
    }
}
