//! The 10-node (quadratic) tetrahedron, the element that does not lock where linear tetrahedra
//! do (bending-dominated beams, nearly incompressible materials such as Cook's membrane with
//! `nu = 0.4999`): shape functions, quadrature, element energy, forces and stiffness, and mass.
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
//! Edge nodes sit at the midpoints of straight edges (affine elements, checked on
//! construction), so `J` is constant per element.
//!
//! **Mass.** The consistent mass `M_ab = rho int N_a N_b dV` has a degree-4 integrand; for an
//! affine element of volume `V` it is `rho V / 420` times (from
//! `int L0^i L1^j L2^k L3^l dV = 6 V i! j! k! l! / (i + j + k + l + 3)!`):
//!
//! | pair | coefficient |
//! | --- | --- |
//! | corner, same corner | 6 |
//! | corner, other corner | 1 |
//! | corner, edge through it | -4 |
//! | corner, edge not through it | -6 |
//! | edge, same edge | 32 |
//! | edge, edge sharing a corner | 16 |
//! | edge, opposite edge | 8 |
//!
//! ([`consistent_mass_coefficient`]). Its row sums, `-rho V / 20` at the corners and
//! `rho V / 5` at the edge nodes, make row-sum lumping useless (negative corner masses), so the
//! lumped mass is **HRZ (diagonal-scaling) lumping**: the diagonal of `M` scaled to carry the
//! element's mass, `rho V / 36` per corner and `4 rho V / 27` per edge node
//! ([`lumped_mass_coefficient`]), all positive.
//!
//! Bodies of these elements are `FemModel::quadratic` (time stepping) and `QuadraticModel`
//! (quasi-static solves).

use crate::element::add_stiffness;
use crate::error::FemError;
use crate::generate::{TET10_EDGES, Tet10Mesh};
use crate::material::Material;
use anim_material::nalgebra::{Matrix3, Vector3};

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

/// The corners of node `k` of a 10-node element (a corner twice for a corner node).
fn node_corners(k: usize) -> [usize; 2] {
    if k < 4 { [k, k] } else { TET10_EDGES[k - 4] }
}

/// `M_ab / (rho V)`: the consistent mass of nodes `a` and `b` (`0..10`, corners then the edge
/// nodes of [`TET10_EDGES`]) of an affine 10-node element of volume `V` (see the
/// [module docs](self)).
#[must_use]
pub fn consistent_mass_coefficient(a: usize, b: usize) -> f64 {
    let (ca, cb) = (node_corners(a), node_corners(b));
    let num = match (a < 4, b < 4) {
        (true, true) => {
            if a == b {
                6.0
            } else {
                1.0
            }
        }
        (true, false) | (false, true) => {
            let (corner, edge) = if a < 4 { (a, cb) } else { (b, ca) };
            if edge.contains(&corner) { -4.0 } else { -6.0 }
        }
        (false, false) => match ca.iter().filter(|c| cb.contains(c)).count() {
            2 => 32.0,
            1 => 16.0,
            _ => 8.0,
        },
    };
    num / 420.0
}

/// The HRZ lumped mass of node `a` of an affine 10-node element over `rho V`: `M_aa` scaled so
/// that the ten masses sum to one (`1/36` at a corner, `4/27` at an edge node).
#[must_use]
pub fn lumped_mass_coefficient(a: usize) -> f64 {
    let trace: f64 = (0..10).map(|k| consistent_mass_coefficient(k, k)).sum();
    consistent_mass_coefficient(a, a) / trace
}

/// Quadrature data of a mesh of 10-node tetrahedra: `|det J| w` and the shape-function gradients
/// at the four points of every element.
#[derive(Debug, Clone)]
pub(crate) struct Tet10Elements {
    pub(crate) elements: Vec<[usize; 10]>,
    weights: Vec<[f64; 4]>,
    grads: Vec<[[[f64; 3]; 10]; 4]>,
}

impl Tet10Elements {
    /// Precomputes the quadrature data. The corner elements must have been validated; checks
    /// the edge nodes (in range, at their edge's midpoint).
    pub(crate) fn new(mesh: &Tet10Mesh) -> Result<Self, FemError> {
        let n = mesh.positions.len();
        let ref_grads = POINTS.map(reference_gradients);
        let mut weights = Vec::with_capacity(mesh.elements.len());
        let mut grads = Vec::with_capacity(mesh.elements.len());
        for (e, el) in mesh.elements.iter().enumerate() {
            for &v in el {
                if v >= n {
                    return Err(FemError::VertexOutOfRange { element: e, vertex: v, vertices: n });
                }
            }
            for (k, [a, b]) in TET10_EDGES.iter().enumerate() {
                let (p, q, m) = (mesh.positions[el[*a]], mesh.positions[el[*b]], mesh.positions[el[4 + k]]);
                let edge = (0..3).map(|c| (q[c] - p[c]).powi(2)).sum::<f64>().sqrt();
                let offset = (0..3).map(|c| (m[c] - 0.5 * (p[c] + q[c])).powi(2)).sum::<f64>().sqrt();
                if !(offset <= 1e-9 * edge) {
                    return Err(FemError::CurvedElement { element: e, node: el[4 + k], offset, edge });
                }
            }
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
        Ok(Self { elements: mesh.elements.clone(), weights, grads })
    }

    /// `F` at quadrature point `q` of element `e`.
    #[inline]
    pub(crate) fn deformation_gradient(&self, e: usize, q: usize, x: &[f64]) -> Matrix3<f64> {
        let el = &self.elements[e];
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

    /// The element's energy, gradient and Hessian (see
    /// [`ElasticBody::element`](crate::newton::ElasticBody::element)).
    #[inline]
    pub(crate) fn element(
        &self,
        mat: &Material,
        e: usize,
        x: &[f64],
        mut grad: Option<&mut [f64]>,
        mut hess: Option<&mut [f64]>,
        project: bool,
    ) -> f64 {
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

    /// The elastic nodal forces `-dE_e/dx` of element `e` into `out` (30 values), plus the
    /// Rayleigh damping forces `-gamma K_e(x) v` when `damping = Some((gamma, v))`
    /// (matrix-free: `dF_q = sum_b v_b grad N_b^T`, `f_a -= gamma w_q (dP/dF)[dF_q] grad N_a`).
    #[inline]
    pub(crate) fn forces(
        &self,
        mat: &Material,
        e: usize,
        x: &[f64],
        damping: Option<(f64, &[f64])>,
        out: &mut [f64],
    ) {
        out.fill(0.0);
        for q in 0..4 {
            let f = self.deformation_gradient(e, q, x);
            let w = self.weights[e][q];
            let mut p = mat.model.pk1(&mat.lame, &f);
            if let Some((gamma, v)) = damping {
                let df = self.deformation_gradient(e, q, v);
                p += mat.model.dpdf(&mat.lame, &f).apply(&df) * gamma;
            }
            let grads = &self.grads[e][q];
            for a in 0..10 {
                let r = p * Vector3::from(grads[a]) * w;
                for i in 0..3 {
                    out[3 * a + i] -= r[i];
                }
            }
        }
    }

    /// The smallest `det F` over the element's quadrature points.
    pub(crate) fn det_f(&self, e: usize, x: &[f64]) -> f64 {
        (0..4).map(|q| self.deformation_gradient(e, q, x).determinant()).fold(f64::INFINITY, f64::min)
    }
}
