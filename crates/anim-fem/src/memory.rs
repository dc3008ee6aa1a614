//! The memory an `fem` scene will take, estimated from its mesh's counts before the model is
//! built, so the `fem` kind refuses a preset resolution, a mesh file or an OBJ `cell` the
//! machine cannot hold (anim-core's [`MemoryNeed`]) instead of aborting halfway through.
//!
//! The parts, per item (sizes of the buffers of `model`, `assembly`,
//! `newton` and `sim`):
//!
//! | part | bytes | what |
//! | --- | --- | --- |
//! | nodes | 600 | positions, masses, loads and flags, the state, the step's and Newton's vectors, a contact block |
//! | frame points, written points | 48, 330 | the frame a view fills (position and velocity, `f64`) and what a run holds to write it (anim-core's `FRAME_POINT_BYTES`, `WRITTEN_POINT_BYTES`) |
//! | elements | 1,752 (tet4), 10,532 (tet10) | the element's 12x12 (30x30) stiffness and its force buffers, `Dm^-1`, volume, shape gradients (quadrature data), the assembly's gather lists and, while it is made, its sorted block pairs; its corners in the view's context |
//! | matrix blocks | 960 | a 3x3 block of the pattern: six matrices share it (the consistent mass and its pinned copy, the stiffness, the stiffness at the step's start, the Newton matrix, the template), 144 B each, and its gather entries |
//! | factor blocks | 144 | a 3x3 block of the Cholesky or LDLT factor of backward Euler's Newton matrix (anim-core's [`cholesky_factor_blocks`], constant 10: faer's factor measured 9 to 10 times `N sqrt(a b)` blocks on cubes of 12^3 to 36^3 cells and beams of 3 to 10 across) |
//!
//! A tet4 mesh has a block per node and two per edge; a tet10 mesh about 26 per node (counted
//! on Kuhn lattices of 6^3 to 12^3 cubes and 4 x 4 x 40).

use crate::model::ElementOrder;
use crate::scenes;
use crate::sim::{LinearSolverChoice, TimeIntegrator};
use anim_core::scene::{BuildError, MemoryNeed, cholesky_factor_blocks};

/// The fill constant of a factor over tetrahedra six to a cube (see the module's table).
const FILL: f64 = 10.0;

/// The counts of a tetrahedral mesh that set its scene's memory.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeshSize {
    /// Corner vertices.
    pub vertices: f64,
    /// Tetrahedra.
    pub elements: f64,
    /// Edges (the extra nodes of 10-node elements, and two matrix blocks each for linear ones).
    pub edges: f64,
    /// The vertices along each side of the box the mesh fills, for the factor's fill; `None`
    /// for a mesh of unknown shape, counted as a cube.
    pub sides: Option<[f64; 3]>,
}

impl MeshSize {
    /// The box of `cells` cubes, six tetrahedra each (Kuhn's, as [`crate::generate::box_mesh`]
    /// lays them): exact counts, in `f64` so no size overflows.
    #[must_use]
    pub fn lattice(cells: [f64; 3]) -> Self {
        let [a, b, c] = cells;
        let axis = a * (b + 1.0) * (c + 1.0) + (a + 1.0) * b * (c + 1.0) + (a + 1.0) * (b + 1.0) * c;
        let faces = a * b * (c + 1.0) + a * (b + 1.0) * c + (a + 1.0) * b * c;
        Self {
            vertices: (a + 1.0) * (b + 1.0) * (c + 1.0),
            elements: 6.0 * a * b * c,
            edges: axis + faces + a * b * c,
            sides: Some([a + 1.0, b + 1.0, c + 1.0]),
        }
    }

    /// A mesh of `vertices` and `elements` of unknown shape: its edges from Euler's relation
    /// for a solid (`V - E + F - T = 1` with about two faces per tetrahedron: `E = V + T`).
    #[must_use]
    pub fn mesh(vertices: f64, elements: f64) -> Self {
        Self { vertices, elements, edges: vertices + elements, sides: None }
    }

    /// This mesh and `other` in one scene (their shape unknown).
    #[must_use]
    pub fn and(self, other: Self) -> Self {
        let sides = match (self.elements, other.elements) {
            (_, 0.0) => self.sides,
            (0.0, _) => other.sides,
            _ => None,
        };
        Self {
            vertices: self.vertices + other.vertices,
            elements: self.elements + other.elements,
            edges: self.edges + other.edges,
            sides,
        }
    }

    /// The nodes of `order` elements: the vertices, and the edges' midpoints for tet10.
    #[must_use]
    pub fn nodes(&self, order: ElementOrder) -> f64 {
        match order {
            ElementOrder::Linear => self.vertices,
            ElementOrder::Quadratic => self.vertices + self.edges,
        }
    }

    /// The 3x3 blocks of the matrix pattern: a node's own and two per edge for tet4, about 26
    /// per node for tet10.
    #[must_use]
    pub fn blocks(&self, order: ElementOrder) -> f64 {
        match order {
            ElementOrder::Linear => self.vertices + 2.0 * self.edges,
            ElementOrder::Quadratic => 26.0 * self.nodes(order),
        }
    }

    /// The memory of a simulation of this mesh of `order` elements, with a factor when
    /// `integrator` and `solver` factor the Newton matrix.
    #[must_use]
    pub fn need(
        &self,
        order: ElementOrder,
        integrator: TimeIntegrator,
        solver: LinearSolverChoice,
    ) -> MemoryNeed {
        let nodes = self.nodes(order);
        let per_element = match order {
            ElementOrder::Linear => 1752.0,
            ElementOrder::Quadratic => 10_532.0,
        };
        let mut need = MemoryNeed::new()
            .with(nodes, "nodes", 600.0)
            .with_frame_points(nodes)
            .with(self.elements, &format!("{} elements", order.name()), per_element)
            .with(self.blocks(order), "matrix blocks", 960.0);
        if integrator == TimeIntegrator::BackwardEuler && solver != LinearSolverChoice::JacobiPcg {
            // Node sides: a tet10 mesh has about twice the vertices' along each side.
            let refine = match order {
                ElementOrder::Linear => 1.0,
                ElementOrder::Quadratic => 2.0,
            };
            let sides = self.sides.map_or([nodes.cbrt(); 3], |s| s.map(|v| refine * v));
            need.add(cholesky_factor_blocks(&sides, FILL), "factor blocks", 144.0);
        }
        need
    }
}

impl MeshSize {
    /// Refuses a mesh beyond the assembly's `u32` indices (its matrix blocks, and three rows per
    /// node).
    ///
    /// # Errors
    /// [`BuildError::Invalid`] of `field` naming the count and its bound.
    pub fn check_indices(&self, field: &str, order: ElementOrder) -> Result<(), BuildError> {
        let max = f64::from(u32::MAX);
        for (what, count) in [("matrix blocks", self.blocks(order)), ("rows", 3.0 * self.nodes(order))] {
            if count > max {
                return Err(BuildError::invalid(
                    field,
                    format!("makes {count:.3e} {what}, more than the {max} the assembly indexes"),
                ));
            }
        }
        Ok(())
    }
}

/// The memory of the preset `name` at `resolution` cells across (its default when `None`) of
/// `order` elements stepped by `integrator` and `solver`; `None` for an unknown name.
#[must_use]
pub fn preset_need(
    name: &str,
    resolution: Option<usize>,
    order: ElementOrder,
    integrator: TimeIntegrator,
    solver: LinearSolverChoice,
) -> Option<MemoryNeed> {
    let n = resolution.or_else(|| scenes::resolution_default(name))?;
    Some(MeshSize::lattice(preset_cells(name, n)?).need(order, integrator, solver))
}

/// Refuses the preset `name` at `resolution` when its memory ([`preset_need`]) exceeds what is
/// available, or its mesh the assembly's indices. Unknown names pass (the kind names them).
///
/// # Errors
/// [`BuildError::Memory`] or [`BuildError::Invalid`] of `resolution`.
pub fn check_preset(
    name: &str,
    resolution: Option<usize>,
    order: ElementOrder,
    integrator: TimeIntegrator,
    solver: LinearSolverChoice,
) -> Result<(), BuildError> {
    let Some(n) = resolution.or_else(|| scenes::resolution_default(name)) else { return Ok(()) };
    let Some(cells) = preset_cells(name, n) else { return Ok(()) };
    let size = MeshSize::lattice(cells);
    size.need(order, integrator, solver).check("resolution", &format!("{n} cells across"))?;
    size.check_indices("resolution", order)
}

/// The cells of the preset `name` at `n` cells across (the beam and the bar ten times as long);
/// `None` for an unknown name.
#[must_use]
pub fn preset_cells(name: &str, n: usize) -> Option<[f64; 3]> {
    let n = n as f64;
    match name {
        "cantilever-beam" | "twisted-bar" => Some([10.0 * n, n, n]),
        "soft-cube-drop" => Some([n, n, n]),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_counts_are_those_of_the_meshes_the_presets_build() {
        // Exact for linear elements; the tet10 blocks (26 per node) within 15% from 3 cells
        // across (a thinner mesh has more of its nodes on the surface, with fewer neighbours).
        for (name, n, order) in [
            ("cantilever-beam", 2, ElementOrder::Linear),
            ("soft-cube-drop", 3, ElementOrder::Linear),
            ("twisted-bar", 1, ElementOrder::Linear),
            ("cantilever-beam", 3, ElementOrder::Quadratic),
            ("soft-cube-drop", 4, ElementOrder::Quadratic),
        ] {
            let scene =
                crate::scenes::by_name_with_order(name, Some(n), order).expect("known").expect("builds");
            let size = MeshSize::lattice(preset_cells(name, n).expect("known"));
            let model = &scene.model;
            assert_eq!(size.elements, model.elements() as f64, "{name}");
            assert_eq!(size.nodes(order), (scene.state.x.len() / 3) as f64, "{name} {order:?}");
            let blocks = model.assembly().matrix().nnz() as f64 / 9.0;
            match order {
                ElementOrder::Linear => assert_eq!(size.blocks(order), blocks, "{name}"),
                ElementOrder::Quadratic => {
                    let ratio = size.blocks(order) / blocks;
                    assert!(
                        (0.85..=1.15).contains(&ratio),
                        "{name}: {} against {blocks}",
                        size.blocks(order)
                    );
                }
            }
        }
    }

    #[test]
    fn a_resolution_beyond_the_memory_or_the_indices_is_refused_before_the_mesh() {
        let (be, cholesky) = (TimeIntegrator::BackwardEuler, LinearSolverChoice::Cholesky);
        let start = std::time::Instant::now();
        let e = check_preset("soft-cube-drop", Some(1_000_000_000), ElementOrder::Linear, be, cholesky)
            .expect_err("refused");
        assert!(start.elapsed().as_secs_f64() < 1.0);
        let BuildError::Memory { bytes, .. } = &e else { panic!("{e:?}") };
        assert!(*bytes > 1e30, "{bytes}");
        assert!(e.to_string().starts_with("field `resolution`: 1000000000 cells across needs about "), "{e}");
        let size = MeshSize::lattice([2000.0, 2000.0, 2000.0]);
        let e = size.check_indices("resolution", ElementOrder::Linear).expect_err("refused");
        assert!(
            e.to_string().contains("matrix blocks, more than the 4294967295 the assembly indexes"),
            "{e}"
        );
        assert!(MeshSize::lattice([100.0, 100.0, 100.0]).check_indices("r", ElementOrder::Quadratic).is_ok());
        assert!(check_preset("cantilever-beam", Some(2), ElementOrder::Quadratic, be, cholesky).is_ok());
        assert!(
            check_preset("flying-carpet", Some(1_000_000_000), ElementOrder::Linear, be, cholesky).is_ok()
        );
    }

    #[test]
    fn euler_s_relation_counts_the_edges_of_a_lattice_within_a_tenth() {
        let lattice = MeshSize::lattice([8.0, 8.0, 80.0]);
        let mesh = MeshSize::mesh(lattice.vertices, lattice.elements);
        let ratio = mesh.edges / lattice.edges;
        assert!((0.9..=1.0).contains(&ratio), "{ratio}");
    }

    #[test]
    fn the_factor_counts_only_where_backward_euler_factors() {
        let size = MeshSize::lattice([4.0, 4.0, 4.0]);
        let order = ElementOrder::Linear;
        let be = TimeIntegrator::BackwardEuler;
        let cholesky = size.need(order, be, LinearSolverChoice::Cholesky).bytes();
        let ldlt = size.need(order, be, LinearSolverChoice::Ldlt).bytes();
        let pcg = size.need(order, be, LinearSolverChoice::JacobiPcg).bytes();
        let explicit =
            size.need(order, TimeIntegrator::SymplecticEuler, LinearSolverChoice::Cholesky).bytes();
        assert_eq!(cholesky, ldlt);
        assert_eq!(pcg, explicit);
        assert_eq!(cholesky - pcg, 144.0 * cholesky_factor_blocks(&[5.0, 5.0, 5.0], FILL));
    }
}
