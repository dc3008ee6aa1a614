//! The finite element model: an immutable description of a body (rest mesh, precomputed
//! `Dm^-1` and `W` per element, materials, masses, loads, boundary conditions, obstacles) that
//! algorithms read and never modify.
//!
//! Every element has a material: one for the whole body ([`FemModel::new`],
//! [`FemModel::with_order`]), or one of a list per element ([`FemModel::with_materials`]), which
//! is how several bodies of different materials are one model (their meshes merged, see
//! [`bodies`](crate::bodies)). Masses, forces, stiffness and energy use each element's own material.
//!
//! A body is made of linear (4-node, [`FemModel::new`]) or quadratic (10-node,
//! [`FemModel::quadratic`], [`tet10`](crate::tet10)) tetrahedra ([`ElementOrder`]).
//! Everything else (masses, gravity, loads, pinned and kinematic nodes, obstacles, both time
//! integrators) works the same for both; the nodes of a 10-node body are its corner vertices
//! followed by its edge nodes, and [`FemModel::mesh`] holds all of them as positions with the
//! corner tetrahedra as elements (so [`FemModel::surface`] is the corner triangulation, used for
//! output).

use crate::assembly::Assembly;
use crate::boundary::{KinematicGroup, Motion, Obstacle};
use crate::element::{
    add_stiffness, deformation_gradient, force_differential, gather, gradients, nodal_forces, rest_shape,
};
use crate::error::FemError;
use crate::generate::{TET10_EDGES, Tet10Mesh};
use crate::material::Material;
use crate::mesh::{TetMesh, validate};
use crate::newton::ElasticBody;
use crate::tet10::{Tet10Elements, consistent_mass_coefficient, lumped_mass_coefficient};
use anim_core::linalg::CsrMatrix;
use anim_core::surface::DistanceField;
use anim_material::nalgebra::Matrix3;
use serde::{Deserialize, Serialize};
use std::collections::HashMap;

mod obstacles;

/// Standard gravity, z-up (m/s^2).
pub const EARTH_GRAVITY: [f64; 3] = [0.0, 0.0, -9.81];

/// How mass is distributed to the vertices.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum MassKind {
    /// Diagonal: each linear element gives a quarter of its mass `rho W` to each vertex; a
    /// 10-node element gives `rho W / 36` to each corner and `4 rho W / 27` to each edge node
    /// (HRZ lumping, see [`tet10`](crate::tet10)).
    Lumped,
    /// The consistent mass matrix of the shape functions, `M_ab = rho int N_a N_b dV I_3`:
    /// `rho W (1 + delta_ab) / 20 I_3` per linear element, the table of
    /// [`tet10`](crate::tet10) for 10-node elements.
    Consistent,
}

/// The element of a body.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum ElementOrder {
    /// Linear 4-node tetrahedra (`"tet4"`): constant strain, one point per element.
    #[default]
    #[serde(rename = "tet4")]
    Linear,
    /// Quadratic 10-node tetrahedra (`"tet10"`): linear strain, four quadrature points; no
    /// locking in bending or near incompressibility, smaller stable explicit time steps.
    #[serde(rename = "tet10")]
    Quadratic,
}

impl ElementOrder {
    /// The name used in scene files (`tet4`, `tet10`).
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            ElementOrder::Linear => "tet4",
            ElementOrder::Quadratic => "tet10",
        }
    }

    /// Nodes per element.
    #[must_use]
    pub fn nodes(self) -> usize {
        match self {
            ElementOrder::Linear => 4,
            ElementOrder::Quadratic => 10,
        }
    }
}

/// A tetrahedral body (see the [module docs](self)).
#[derive(Debug, Clone)]
pub struct FemModel {
    mesh: TetMesh,
    /// The 10-node elements and their quadrature data (quadratic bodies only).
    tet10: Option<Tet10Elements>,
    surface: Vec<[usize; 3]>,
    /// The materials (at least one).
    materials: Vec<Material>,
    /// The index into `materials` of each element.
    element_material: Vec<u32>,
    dm_inv: Vec<Matrix3<f64>>,
    volume: Vec<f64>,
    shape_grad: Vec<[[f64; 3]; 4]>,
    lumped_mass: Vec<f64>,
    mass_kind: MassKind,
    consistent_mass: CsrMatrix,
    /// Row sums of the consistent mass per node (quadratic bodies only: for linear elements
    /// they equal the lumped masses), the gravity weights with consistent mass.
    consistent_row_sums: Option<Vec<f64>>,
    assembly: Assembly,
    gravity: [f64; 3],
    loads: Vec<f64>,
    fixed: Vec<bool>,
    kinematic: Vec<KinematicGroup>,
    obstacles: Vec<Obstacle>,
    friction: Vec<f64>,
    mesh_obstacles: Vec<DistanceField>,
    mesh_friction: Vec<f64>,
    contact_stiffness: f64,
}

impl FemModel {
    /// A body of linear tetrahedra from a mesh and a material, with lumped mass, no gravity, no
    /// boundary conditions.
    ///
    /// Precomputes `Dm^-1` and `W` of every element (Sifakis & Barbič 2012, Algorithm 1, PRECOMPUTATION).
    ///
    /// # Errors
    /// The mesh errors of [`validate`] (degenerate or inverted rest
    /// elements named by index).
    pub fn new(mesh: TetMesh, material: Material) -> Result<Self, FemError> {
        Self::with_order(mesh, material, ElementOrder::Linear)
    }

    /// A body of 10-node tetrahedra (from [`generate::quadratic`](crate::generate::quadratic)),
    /// with HRZ-lumped mass, no gravity, no boundary conditions. Every node (corner and edge)
    /// is a degree of freedom; [`mesh`](Self::mesh) holds them all with the corner tetrahedra as
    /// elements.
    ///
    /// # Errors
    /// The mesh errors of [`validate`] on the corner tetrahedra, an edge node out of range
    /// ([`FemError::VertexOutOfRange`]) or away from its edge's midpoint
    /// ([`FemError::CurvedElement`]).
    pub fn quadratic(mesh: Tet10Mesh, material: Material) -> Result<Self, FemError> {
        let corners: Vec<[usize; 4]> = mesh.elements.iter().map(|e| [e[0], e[1], e[2], e[3]]).collect();
        validate(&mesh.positions, &corners)?;
        let tet10 = Tet10Elements::new(&mesh)?;
        let one = vec![0; corners.len()];
        Self::build(TetMesh { positions: mesh.positions, tets: corners }, Some(tet10), vec![material], one)
    }

    /// A body of `order` elements on a linear mesh: the mesh itself for
    /// [`ElementOrder::Linear`], its 10-node refinement
    /// ([`generate::quadratic`](crate::generate::quadratic)) for [`ElementOrder::Quadratic`].
    ///
    /// # Errors
    /// As [`FemModel::new`].
    pub fn with_order(mesh: TetMesh, material: Material, order: ElementOrder) -> Result<Self, FemError> {
        let one = vec![0; mesh.tets.len()];
        Self::with_materials(mesh, vec![material], one, order)
    }

    /// A body of `order` elements on a linear mesh (as [`with_order`](Self::with_order)) whose
    /// element `e` is of material `materials[element_material[e]]`. A 10-node element keeps the
    /// material of the linear element it refines.
    ///
    /// # Errors
    /// As [`FemModel::new`]; [`FemError::MaterialIndex`] for an empty `materials`, an
    /// `element_material` whose length is not the number of elements, or an index out of range.
    pub fn with_materials(
        mesh: TetMesh,
        materials: Vec<Material>,
        element_material: Vec<u32>,
        order: ElementOrder,
    ) -> Result<Self, FemError> {
        let elements = mesh.tets.len();
        if materials.is_empty() || element_material.len() != elements {
            return Err(FemError::MaterialIndex(format!(
                "{} materials and {} element materials for {elements} elements",
                materials.len(),
                element_material.len()
            )));
        }
        if let Some(e) = element_material.iter().position(|&m| m as usize >= materials.len()) {
            return Err(FemError::MaterialIndex(format!(
                "element {e} has material {}, but there are {} materials",
                element_material[e],
                materials.len()
            )));
        }
        validate(&mesh.positions, &mesh.tets)?;
        match order {
            ElementOrder::Linear => Self::build(mesh, None, materials, element_material),
            ElementOrder::Quadratic => {
                let fine = crate::generate::quadratic(&mesh);
                let tet10 = Tet10Elements::new(&fine)?;
                let corners = TetMesh { positions: fine.positions, tets: mesh.tets };
                Self::build(corners, Some(tet10), materials, element_material)
            }
        }
    }

    /// The body from a validated mesh (corner tetrahedra), the 10-node data if quadratic, and
    /// the materials with each element's index into them (checked by the caller).
    fn build(
        mesh: TetMesh,
        tet10: Option<Tet10Elements>,
        materials: Vec<Material>,
        element_material: Vec<u32>,
    ) -> Result<Self, FemError> {
        let n = mesh.positions.len();
        let m = mesh.tets.len();
        let mut dm_inv = Vec::with_capacity(m);
        let mut volume = Vec::with_capacity(m);
        let mut shape_grad = Vec::with_capacity(m);
        let mut lumped_mass = vec![0.0; n];
        for (e, t) in mesh.tets.iter().enumerate() {
            let rest = t.map(|v| mesh.positions[v]);
            let (inv, w) = rest_shape(rest).ok_or(FemError::DegenerateElement {
                element: e,
                volume6: 0.0,
                edge: 0.0,
            })?;
            dm_inv.push(inv);
            volume.push(w);
            shape_grad.push(gradients(&inv));
            if tet10.is_none() {
                let density = materials[element_material[e] as usize].density;
                for &v in t {
                    lumped_mass[v] += 0.25 * density * w;
                }
            }
        }
        let (assembly, consistent_mass, consistent_row_sums) = match &tet10 {
            None => {
                let flat: Vec<usize> = mesh.tets.iter().flatten().copied().collect();
                let assembly = Assembly::new(n, 4, &flat);
                // Consistent mass: per-element 12 x 12 blocks rho W / 20 (1 + delta_ab) I_3.
                let mut blocks = vec![0.0; m * 144];
                for e in 0..m {
                    let c = materials[element_material[e] as usize].density * volume[e] / 20.0;
                    for a in 0..4 {
                        for b in 0..4 {
                            let v = if a == b { 2.0 * c } else { c };
                            for i in 0..3 {
                                blocks[e * 144 + (3 * a + i) * 12 + 3 * b + i] = v;
                            }
                        }
                    }
                }
                let mut consistent_mass = assembly.matrix();
                assembly.gather_matrix(&blocks, &mut consistent_mass);
                (assembly, consistent_mass, None)
            }
            Some(q) => {
                let flat: Vec<usize> = q.elements.iter().flatten().copied().collect();
                let assembly = Assembly::new(n, 10, &flat);
                let coef: [[f64; 10]; 10] =
                    std::array::from_fn(|a| std::array::from_fn(|b| consistent_mass_coefficient(a, b)));
                let lumped: [f64; 10] = std::array::from_fn(lumped_mass_coefficient);
                let mut row_sums = vec![0.0; n];
                let mut blocks = vec![0.0; m * 900];
                for (e, el) in q.elements.iter().enumerate() {
                    let c = materials[element_material[e] as usize].density * volume[e];
                    for a in 0..10 {
                        lumped_mass[el[a]] += c * lumped[a];
                        row_sums[el[a]] += c * coef[a].iter().sum::<f64>();
                        for b in 0..10 {
                            for i in 0..3 {
                                blocks[e * 900 + (3 * a + i) * 30 + 3 * b + i] = c * coef[a][b];
                            }
                        }
                    }
                }
                let mut consistent_mass = assembly.matrix();
                assembly.gather_matrix(&blocks, &mut consistent_mass);
                (assembly, consistent_mass, Some(row_sums))
            }
        };
        let surface = mesh.boundary_triangles();
        Ok(Self {
            mesh,
            tet10,
            surface,
            materials,
            element_material,
            dm_inv,
            volume,
            shape_grad,
            lumped_mass,
            mass_kind: MassKind::Lumped,
            consistent_mass,
            consistent_row_sums,
            assembly,
            gravity: [0.0; 3],
            loads: vec![0.0; 3 * n],
            fixed: vec![false; 3 * n],
            kinematic: Vec::new(),
            obstacles: Vec::new(),
            friction: Vec::new(),
            mesh_obstacles: Vec::new(),
            mesh_friction: Vec::new(),
            contact_stiffness: 0.0,
        })
    }

    /// Chooses lumped or consistent mass (default lumped).
    #[must_use]
    pub fn with_mass(mut self, kind: MassKind) -> Self {
        self.mass_kind = kind;
        self
    }

    /// Sets the gravitational acceleration (default zero).
    #[must_use]
    pub fn with_gravity(mut self, g: [f64; 3]) -> Self {
        self.gravity = g;
        self
    }

    fn check_vertex(&self, what: &str, vertex: usize) -> Result<(), FemError> {
        if vertex >= self.vertices() {
            return Err(FemError::BoundaryVertexOutOfRange {
                what: what.to_string(),
                vertex,
                vertices: self.vertices(),
            });
        }
        Ok(())
    }

    /// Pins the given coordinates (`mask[c]` for x, y, z) of a vertex: they keep their value.
    ///
    /// # Errors
    /// [`FemError::BoundaryVertexOutOfRange`].
    pub fn pin(&mut self, vertex: usize, mask: [bool; 3]) -> Result<(), FemError> {
        self.check_vertex("pinned vertex", vertex)?;
        for c in 0..3 {
            self.fixed[3 * vertex + c] |= mask[c];
        }
        Ok(())
    }

    /// Pins every coordinate of the given vertices.
    ///
    /// # Errors
    /// [`FemError::BoundaryVertexOutOfRange`].
    pub fn pin_vertices(&mut self, vertices: &[usize]) -> Result<(), FemError> {
        for &v in vertices {
            self.pin(v, [true; 3])?;
        }
        Ok(())
    }

    /// Makes the given vertices follow `motion`, starting from their rest positions at `t = 0`.
    ///
    /// # Errors
    /// [`FemError::BoundaryVertexOutOfRange`].
    pub fn add_kinematic(&mut self, vertices: &[usize], motion: Motion) -> Result<(), FemError> {
        let what = format!("kinematic group {}", self.kinematic.len());
        for &v in vertices {
            self.check_vertex(&what, v)?;
        }
        for &v in vertices {
            self.fixed[3 * v..3 * v + 3].fill(true);
        }
        let initial = vertices.iter().map(|&v| self.mesh.positions[v]).collect();
        self.kinematic.push(KinematicGroup { vertices: vertices.to_vec(), motion, initial });
        Ok(())
    }

    /// Adds a constant force on a vertex.
    ///
    /// # Errors
    /// [`FemError::BoundaryVertexOutOfRange`], or [`FemError::BadParameter`] for a non-finite
    /// force.
    pub fn add_nodal_force(&mut self, vertex: usize, force: [f64; 3]) -> Result<(), FemError> {
        self.check_vertex("nodal force", vertex)?;
        for c in 0..3 {
            if !force[c].is_finite() {
                return Err(FemError::BadParameter {
                    name: "nodal force",
                    value: force[c],
                    reason: "must be finite",
                });
            }
            self.loads[3 * vertex + c] += force[c];
        }
        Ok(())
    }

    /// The vertices whose rest position satisfies `select`.
    #[must_use]
    pub fn vertices_where(&self, select: impl Fn([f64; 3]) -> bool) -> Vec<usize> {
        (0..self.vertices()).filter(|&i| select(self.mesh.positions[i])).collect()
    }

    /// Adds the consistent nodal loads of a uniform traction `t` (force per rest area) on the
    /// boundary triangles whose centroid satisfies `select`: each vertex of a triangle of area
    /// `A` gets `A t / 3` (linear elements); on the 6-node face of a 10-node element the corners
    /// get 0 and the three edge nodes `A t / 3` each. Returns the loaded area.
    pub fn add_traction(&mut self, select: impl Fn([f64; 3]) -> bool, t: [f64; 3]) -> f64 {
        let edge_nodes: HashMap<(usize, usize), usize> = match &self.tet10 {
            None => HashMap::new(),
            Some(q) => q
                .elements
                .iter()
                .flat_map(|el| {
                    TET10_EDGES
                        .iter()
                        .enumerate()
                        .map(|(k, [a, b])| ((el[*a].min(el[*b]), el[*a].max(el[*b])), el[4 + k]))
                })
                .collect(),
        };
        let mut total = 0.0;
        for tri in &self.surface {
            let p = tri.map(|v| self.mesh.positions[v]);
            let centroid = [0, 1, 2].map(|c| (p[0][c] + p[1][c] + p[2][c]) / 3.0);
            if !select(centroid) {
                continue;
            }
            let u = [0, 1, 2].map(|c| p[1][c] - p[0][c]);
            let v = [0, 1, 2].map(|c| p[2][c] - p[0][c]);
            let n = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]];
            let area = 0.5 * (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            total += area;
            let loaded = if self.tet10.is_some() {
                [(0, 1), (1, 2), (0, 2)].map(|(a, b)| {
                    let (i, j) = (tri[a].min(tri[b]), tri[a].max(tri[b]));
                    edge_nodes.get(&(i, j)).copied()
                })
            } else {
                tri.map(Some)
            };
            for vtx in loaded.into_iter().flatten() {
                for c in 0..3 {
                    self.loads[3 * vtx + c] += area * t[c] / 3.0;
                }
            }
        }
        total
    }

    /// The rest mesh: every node's position (for a 10-node body, the corners then the edge
    /// nodes) and the (corner) tetrahedra.
    #[must_use]
    pub fn mesh(&self) -> &TetMesh {
        &self.mesh
    }

    /// The element order.
    #[must_use]
    pub fn order(&self) -> ElementOrder {
        if self.tet10.is_some() { ElementOrder::Quadratic } else { ElementOrder::Linear }
    }

    /// The node indices of a 10-node body's elements (four corners, then the edge nodes in
    /// [`TET10_EDGES`] order); `None` for a linear body.
    #[must_use]
    pub fn quadratic_elements(&self) -> Option<&[[usize; 10]]> {
        self.tet10.as_ref().map(|q| q.elements.as_slice())
    }

    /// Number of vertices (nodes: corners and, for 10-node elements, edge nodes).
    #[must_use]
    pub fn vertices(&self) -> usize {
        self.mesh.positions.len()
    }

    /// Number of tetrahedra.
    #[must_use]
    pub fn elements(&self) -> usize {
        self.mesh.tets.len()
    }

    /// The boundary surface triangles (outward), for output.
    #[must_use]
    pub fn surface(&self) -> &[[usize; 3]] {
        &self.surface
    }

    /// The material of element 0: the body's material when it has one
    /// ([`FemModel::new`], [`FemModel::with_order`]); see [`materials`](Self::materials) and
    /// [`element_material`](Self::element_material) for bodies of several.
    #[must_use]
    pub fn material(&self) -> &Material {
        &self.materials[0]
    }

    /// The materials of the elements (one for a single-material body).
    #[must_use]
    pub fn materials(&self) -> &[Material] {
        &self.materials
    }

    /// The index into [`materials`](Self::materials) of each element's material.
    #[must_use]
    pub fn element_material(&self) -> &[u32] {
        &self.element_material
    }

    /// The material of element `e`.
    #[inline]
    #[must_use]
    pub fn material_of(&self, e: usize) -> &Material {
        &self.materials[self.element_material[e] as usize]
    }

    /// `Dm^-1` per element (of the corner tetrahedron for 10-node elements).
    #[must_use]
    pub fn dm_inv(&self) -> &[Matrix3<f64>] {
        &self.dm_inv
    }

    /// Rest volume `W` per element.
    #[must_use]
    pub fn rest_volume(&self) -> &[f64] {
        &self.volume
    }

    /// Lumped vertex masses (HRZ lumping for 10-node elements).
    #[must_use]
    pub fn lumped_mass(&self) -> &[f64] {
        &self.lumped_mass
    }

    /// The mass distribution.
    #[must_use]
    pub fn mass_kind(&self) -> MassKind {
        self.mass_kind
    }

    /// The consistent mass matrix (on the stiffness pattern).
    #[must_use]
    pub fn consistent_mass(&self) -> &CsrMatrix {
        &self.consistent_mass
    }

    /// The assembly pattern.
    #[must_use]
    pub fn assembly(&self) -> &Assembly {
        &self.assembly
    }

    /// Gravity.
    #[must_use]
    pub fn gravity(&self) -> [f64; 3] {
        self.gravity
    }

    /// Which coordinates are fixed (pinned or kinematic), 3 per vertex.
    #[must_use]
    pub fn fixed(&self) -> &[bool] {
        &self.fixed
    }

    /// Kinematic groups.
    #[must_use]
    pub fn kinematic(&self) -> &[KinematicGroup] {
        &self.kinematic
    }

    /// The rest positions, flat (`[x0, y0, z0, x1, ...]`).
    #[must_use]
    pub fn rest_positions(&self) -> Vec<f64> {
        self.mesh.positions.iter().flatten().copied().collect()
    }

    /// Writes the external force: `m_i g` plus the nodal loads, times `scale`. The gravity
    /// weights `m_i` are the lumped masses, or with consistent mass on a 10-node body the row
    /// sums of `M` (`rho int N_i dV`, negative at the corners), so that `M^-1 f` is exactly `g`
    /// for a free body with either mass.
    pub fn external_force(&self, scale: f64, out: &mut [f64]) {
        let weights = match (&self.consistent_row_sums, self.mass_kind) {
            (Some(rows), MassKind::Consistent) => rows,
            _ => &self.lumped_mass,
        };
        for (i, o) in out.chunks_mut(3).enumerate() {
            for c in 0..3 {
                o[c] = scale * (weights[i] * self.gravity[c] + self.loads[3 * i + c]);
            }
        }
    }

    /// Writes the kinematic targets at time `t` into `x` (other entries untouched).
    pub fn apply_kinematic(&self, t: f64, x: &mut [f64]) {
        for g in &self.kinematic {
            for (&v, &x0) in g.vertices.iter().zip(&g.initial) {
                let p = g.motion.position(x0, t);
                x[3 * v..3 * v + 3].copy_from_slice(&p);
            }
        }
    }

    /// Total elastic energy `sum_e W_e psi(F_e)` at positions `x`.
    #[must_use]
    pub fn elastic_energy(&self, x: &[f64]) -> f64 {
        (0..self.elements()).map(|e| self.element(e, x, None, None, false)).sum()
    }

    /// The deformation gradient of element `e` at positions `x` (for a 10-node element, at its
    /// centroid, where the corner shape functions have zero gradient and edge node `(a, b)` has
    /// `grad L_a + grad L_b`).
    #[must_use]
    pub fn deformation_gradient(&self, e: usize, x: &[f64]) -> Matrix3<f64> {
        match &self.tet10 {
            None => deformation_gradient(&gather(x, &self.mesh.tets[e]), &self.dm_inv[e]),
            Some(q) => {
                let b = &self.shape_grad[e];
                let el = &q.elements[e];
                let mut f = Matrix3::zeros();
                for (k, [a, c]) in TET10_EDGES.iter().enumerate() {
                    let v = el[4 + k];
                    for i in 0..3 {
                        for j in 0..3 {
                            f[(i, j)] += x[3 * v + i] * (b[*a][j] + b[*c][j]);
                        }
                    }
                }
                f
            }
        }
    }

    /// A strain measure per node, for pictures: at each node the largest, over the elements
    /// around it, of the Frobenius norm of the Green-Lagrange strain `E = (F^T F - I) / 2` at
    /// the element's [`FemModel::deformation_gradient`]. 0 at rest, `|E|` of a uniform stretch
    /// everywhere under one; dimensionless. `out` is overwritten, one value per node.
    pub fn nodal_strain(&self, x: &[f64], out: &mut Vec<f64>) {
        out.clear();
        out.resize(self.vertices(), 0.0);
        for e in 0..self.elements() {
            let f = self.deformation_gradient(e, x);
            let strain = 0.5 * (f.transpose() * f - Matrix3::identity()).norm();
            let nodes: &[usize] = match &self.tet10 {
                None => &self.mesh.tets[e],
                Some(q) => &q.elements[e],
            };
            for &v in nodes {
                out[v] = out[v].max(strain);
            }
        }
    }

    /// The elastic nodal forces of element `e` into `out` (3 per element node, `3 x 4` or
    /// `3 x 10` values): Sifakis & Barbič's `H = -W P(F) Dm^-T`, `f_4 = -(f_1 + f_2 + f_3)` for linear
    /// elements, `-sum_q w_q P(F_q) grad N_a(X_q)` for 10-node elements.
    #[inline]
    pub fn element_forces(&self, e: usize, x: &[f64], out: &mut [f64]) {
        self.element_forces_damped(e, x, None, out);
    }

    /// The elastic forces of element `e` plus, with `damping = Some((gamma, v))`, the Rayleigh
    /// damping forces `-gamma K_e(x) v` (matrix-free).
    #[inline]
    pub(crate) fn element_forces_damped(
        &self,
        e: usize,
        x: &[f64],
        damping: Option<(f64, &[f64])>,
        out: &mut [f64],
    ) {
        if let Some(q) = &self.tet10 {
            q.forces(self.material_of(e), e, x, damping, out);
            return;
        }
        let fd = self.deformation_gradient(e, x);
        let mat = self.material_of(e);
        let p = mat.model.pk1(&mat.lame, &fd);
        let mut f = nodal_forces(self.volume[e], &p, &self.dm_inv[e]);
        if let Some((gamma, v)) = damping {
            let tangent = mat.model.dpdf(&mat.lame, &fd);
            let u = gather(v, &self.mesh.tets[e]);
            let d = force_differential(self.volume[e], &self.dm_inv[e], &tangent, &u);
            for a in 0..4 {
                for i in 0..3 {
                    f[a][i] += gamma * d[a][i];
                }
            }
        }
        for a in 0..4 {
            out[3 * a..3 * a + 3].copy_from_slice(&f[a]);
        }
    }
}

impl ElasticBody for FemModel {
    fn elements(&self) -> usize {
        self.mesh.tets.len()
    }

    fn per_element(&self) -> usize {
        self.order().nodes()
    }

    #[inline]
    fn element(
        &self,
        e: usize,
        x: &[f64],
        grad: Option<&mut [f64]>,
        hess: Option<&mut [f64]>,
        project: bool,
    ) -> f64 {
        if let Some(q) = &self.tet10 {
            return q.element(self.material_of(e), e, x, grad, hess, project);
        }
        let f = self.deformation_gradient(e, x);
        let w = self.volume[e];
        let mat = self.material_of(e);
        let energy = w * mat.model.energy(&mat.lame, &f);
        if let Some(g) = grad {
            let p = mat.model.pk1(&mat.lame, &f);
            let h = nodal_forces(w, &p, &self.dm_inv[e]);
            for a in 0..4 {
                for i in 0..3 {
                    g[3 * a + i] = -h[a][i];
                }
            }
        }
        if let Some(h) = hess {
            let c = mat.model.tangent_matrix(&mat.lame, &f, project);
            add_stiffness::<4>(w, &self.shape_grad[e], &c, h);
        }
        energy
    }

    fn det_f(&self, e: usize, x: &[f64]) -> f64 {
        match &self.tet10 {
            Some(q) => q.det_f(e, x),
            None => self.deformation_gradient(e, x).determinant(),
        }
    }
}
