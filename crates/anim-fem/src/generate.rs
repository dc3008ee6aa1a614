//! Built-in mesh generators: a tetrahedralised box (beam, cube, bar) at any resolution, a graded
//! beam, Cook's membrane slab, and the quadratic (10-node) refinement of a linear mesh.
//!
//! Boxes are split into hexahedral cells and every cell into six tetrahedra around its main
//! diagonal (Kuhn / Freudenthal subdivision); all cells use the same split, so neighbouring
//! cells share their face diagonals and the mesh is conforming. Every element is positively
//! oriented.

use crate::error::FemError;
use crate::mesh::{TetMesh, signed_volume6, validate};
use std::collections::HashMap;

/// The six Kuhn tetrahedra of the unit cube: cube corner `k` is `(k & 1, (k >> 1) & 1, k >> 2)`;
/// each tetrahedron follows a monotone path from corner 0 to corner 7.
const KUHN: [[usize; 4]; 6] =
    [[0, 1, 3, 7], [0, 1, 5, 7], [0, 2, 3, 7], [0, 2, 6, 7], [0, 4, 5, 7], [0, 4, 6, 7]];

/// A structured mesh of `n[0] x n[1] x n[2]` cells on the unit cube, mapped by `map` to the
/// physical domain. Vertex `(i, j, k)` has index `i + (n0 + 1) (j + (n1 + 1) k)`.
///
/// # Errors
/// [`FemError::BadParameter`] for a zero cell count; the validation errors of
/// [`validate`] when `map` folds or collapses cells.
pub fn mapped_grid(n: [usize; 3], map: impl Fn([f64; 3]) -> [f64; 3]) -> Result<TetMesh, FemError> {
    for (axis, &c) in n.iter().enumerate() {
        if c == 0 {
            return Err(FemError::BadParameter {
                name: ["cells_x", "cells_y", "cells_z"][axis],
                value: 0.0,
                reason: "must be at least 1",
            });
        }
    }
    let [nx, ny, nz] = n;
    let id = |i: usize, j: usize, k: usize| i + (nx + 1) * (j + (ny + 1) * k);
    let mut positions = Vec::with_capacity((nx + 1) * (ny + 1) * (nz + 1));
    for k in 0..=nz {
        for j in 0..=ny {
            for i in 0..=nx {
                positions.push(map([i as f64 / nx as f64, j as f64 / ny as f64, k as f64 / nz as f64]));
            }
        }
    }
    let mut tets = Vec::with_capacity(6 * nx * ny * nz);
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                let corner = |c: usize| id(i + (c & 1), j + ((c >> 1) & 1), k + (c >> 2));
                for t in KUHN {
                    let mut tet = t.map(corner);
                    let p = tet.map(|v| positions[v]);
                    if signed_volume6(p[0], p[1], p[2], p[3]) < 0.0 {
                        tet.swap(2, 3);
                    }
                    tets.push(tet);
                }
            }
        }
    }
    validate(&positions, &tets)?;
    Ok(TetMesh { positions, tets })
}

/// An axis-aligned box `[origin, origin + size]` with `cells` hexahedral cells per axis, six
/// tetrahedra per cell.
///
/// # Errors
/// [`FemError::BadParameter`] for a non-positive or non-finite size or a zero cell count.
pub fn box_mesh(origin: [f64; 3], size: [f64; 3], cells: [usize; 3]) -> Result<TetMesh, FemError> {
    for (axis, &s) in size.iter().enumerate() {
        if !(s > 0.0) || !s.is_finite() {
            return Err(FemError::BadParameter {
                name: ["size_x", "size_y", "size_z"][axis],
                value: s,
                reason: "must be finite and > 0",
            });
        }
    }
    mapped_grid(cells, |u| {
        [origin[0] + size[0] * u[0], origin[1] + size[1] * u[1], origin[2] + size[2] * u[2]]
    })
}

/// A box whose cell length along x grows geometrically so that the last cell is `ratio` times
/// longer than the first (a graded mesh).
///
/// # Errors
/// As [`box_mesh`]; `ratio` must be finite and > 0.
pub fn graded_box(
    origin: [f64; 3],
    size: [f64; 3],
    cells: [usize; 3],
    ratio: f64,
) -> Result<TetMesh, FemError> {
    if !(ratio > 0.0) || !ratio.is_finite() {
        return Err(FemError::BadParameter { name: "ratio", value: ratio, reason: "must be finite and > 0" });
    }
    let uniform = box_mesh(origin, size, cells)?;
    let nx = cells[0];
    if nx < 2 || ratio == 1.0 {
        return Ok(uniform);
    }
    // Cell k has length proportional to q^k with q^(nx - 1) = ratio.
    let q = ratio.powf(1.0 / (nx as f64 - 1.0));
    let total = (q.powi(nx as i32) - 1.0) / (q - 1.0);
    mapped_grid(cells, |u| {
        let s = u[0] * nx as f64;
        let x = (q.powf(s) - 1.0) / (q - 1.0) / total;
        [origin[0] + size[0] * x, origin[1] + size[1] * u[1], origin[2] + size[2] * u[2]]
    })
}

/// Cook's membrane as a slab one cell thick: the trapezoid `(0,0), (48,44), (48,60), (0,44)` (mm)
/// in the x-y plane, `cells x cells` quadrilaterals mapped bilinearly, extruded to
/// `z in [0, thickness]`.
///
/// # Errors
/// [`FemError::BadParameter`] for zero cells or a non-positive thickness.
pub fn cook_membrane(cells: usize, thickness: f64) -> Result<TetMesh, FemError> {
    if !(thickness > 0.0) || !thickness.is_finite() {
        return Err(FemError::BadParameter {
            name: "thickness",
            value: thickness,
            reason: "must be finite and > 0",
        });
    }
    mapped_grid([cells, cells, 1], |u| {
        let (s, t) = (u[0], u[1]);
        // Bottom edge (0,0)-(48,44), top edge (0,44)-(48,60).
        let bottom = [48.0 * s, 44.0 * s];
        let top = [48.0 * s, 44.0 + 16.0 * s];
        [bottom[0] + t * (top[0] - bottom[0]), bottom[1] + t * (top[1] - bottom[1]), thickness * u[2]]
    })
}

/// The local corner pairs of the six edge nodes of a 10-node tetrahedron, in node order 4..9
/// (the VTK `QUADRATIC_TETRA` order).
pub const TET10_EDGES: [[usize; 2]; 6] = [[0, 1], [1, 2], [0, 2], [0, 3], [1, 3], [2, 3]];

/// A quadratic (10-node) tetrahedral mesh: corner vertices first, then one node per edge.
#[derive(Debug, Clone, PartialEq)]
pub struct Tet10Mesh {
    /// Node positions: the linear mesh's vertices, then the edge midpoints.
    pub positions: Vec<[f64; 3]>,
    /// Elements: four corners, then the edge nodes in [`TET10_EDGES`] order.
    pub elements: Vec<[usize; 10]>,
    /// Number of corner (vertex) nodes; nodes from this index on are edge nodes.
    pub corners: usize,
}

/// Refines a linear mesh into 10-node tetrahedra with straight edges (edge nodes at the
/// midpoints), numbering edge nodes in the order the edges are first met.
#[must_use]
pub fn quadratic(mesh: &TetMesh) -> Tet10Mesh {
    let mut positions = mesh.positions.clone();
    let corners = positions.len();
    let mut edge_node: HashMap<(usize, usize), usize> = HashMap::new();
    let mut elements = Vec::with_capacity(mesh.tets.len());
    for t in &mesh.tets {
        let mut e = [0usize; 10];
        e[..4].copy_from_slice(t);
        for (k, [a, b]) in TET10_EDGES.iter().enumerate() {
            let (i, j) = (t[*a].min(t[*b]), t[*a].max(t[*b]));
            let node = *edge_node.entry((i, j)).or_insert_with(|| {
                let (p, q) = (positions[i], positions[j]);
                positions.push([0.5 * (p[0] + q[0]), 0.5 * (p[1] + q[1]), 0.5 * (p[2] + q[2])]);
                positions.len() - 1
            });
            e[4 + k] = node;
        }
        elements.push(e);
    }
    Tet10Mesh { positions, elements, corners }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn total_volume(m: &TetMesh) -> f64 {
        m.tets
            .iter()
            .map(|t| {
                signed_volume6(m.positions[t[0]], m.positions[t[1]], m.positions[t[2]], m.positions[t[3]])
                    / 6.0
            })
            .sum()
    }

    #[test]
    fn box_is_conforming_and_fills_its_volume() {
        let m = box_mesh([1.0, -2.0, 0.5], [2.0, 3.0, 0.5], [3, 2, 4]).unwrap();
        assert_eq!(m.positions.len(), 4 * 3 * 5);
        assert_eq!(m.tets.len(), 6 * 24);
        assert!((total_volume(&m) - 3.0).abs() < 1e-12);
        // Conforming: every interior face is shared by exactly two elements, so the boundary
        // is exactly the box surface: 2 triangles per boundary cell face.
        let faces = m.boundary_triangles().len();
        assert_eq!(faces, 2 * 2 * (3 * 2 + 2 * 4 + 3 * 4));
    }

    #[test]
    fn graded_box_has_the_requested_ratio() {
        let m = graded_box([0.0; 3], [10.0, 1.0, 1.0], [8, 1, 1], 10.0).unwrap();
        let x: Vec<f64> = (0..=8).map(|i| m.positions[i][0]).collect();
        let first = x[1] - x[0];
        let last = x[8] - x[7];
        assert!((last / first - 10.0).abs() < 1e-9, "{}", last / first);
        assert!((x[8] - 10.0).abs() < 1e-12);
        assert!((total_volume(&m) - 10.0).abs() < 1e-10);
    }

    #[test]
    fn cook_membrane_area() {
        let m = cook_membrane(4, 1.0).unwrap();
        // Trapezoid area: 48 * (44 + 16) / 2 = 1440.
        assert!((total_volume(&m) - 1440.0).abs() < 1e-9);
    }

    #[test]
    fn quadratic_mesh_shares_edge_nodes() {
        let m = box_mesh([0.0; 3], [1.0; 3], [1, 1, 1]).unwrap();
        let q = quadratic(&m);
        // A cube split into 6 Kuhn tets has 12 cube edges + 6 face diagonals + 1 main diagonal.
        assert_eq!(q.positions.len() - q.corners, 19);
        for e in &q.elements {
            for (k, [a, b]) in TET10_EDGES.iter().enumerate() {
                let (p, r, mid) = (q.positions[e[*a]], q.positions[e[*b]], q.positions[e[4 + k]]);
                for c in 0..3 {
                    assert!((mid[c] - 0.5 * (p[c] + r[c])).abs() < 1e-15);
                }
            }
        }
    }

    #[test]
    fn bad_sizes_are_named() {
        assert!(matches!(
            box_mesh([0.0; 3], [1.0, 0.0, 1.0], [1, 1, 1]),
            Err(FemError::BadParameter { name: "size_y", .. })
        ));
        assert!(matches!(
            box_mesh([0.0; 3], [1.0; 3], [1, 0, 1]),
            Err(FemError::BadParameter { name: "cells_y", .. })
        ));
    }
}
