//! Tetrahedral meshes: validation of the rest configuration, reading Gmsh and TetGen files
//! (through `anim-io`, feature `files`), and the boundary surface used for output and contact.
//!
//! The mesh type is anim-core's [`TetMesh`]: vertex positions and 4-vertex elements. An element
//! `(X0, X1, X2, X3)` is positively oriented when `(X1 - X0) x (X2 - X0) . (X3 - X0) > 0`; the
//! rest configuration of every element must be positively oriented and non-degenerate, otherwise
//! [`validate`] names the first offending element.

use crate::error::FemError;
pub use anim_core::mesh::TetMesh;
#[cfg(feature = "files")]
use std::path::Path;

/// Relative degeneracy threshold: an element is degenerate when
/// `|6 V| <= DEGENERACY * (longest edge)^3` (a regular tetrahedron has `6 V / l^3 = 0.707`).
pub const DEGENERACY: f64 = 1e-12;

/// Six times the signed volume of the tetrahedron `(a, b, c, d)` (anim-core's
/// [`tet_signed_volume6`](anim_core::geometry::tet_signed_volume6)).
pub use anim_core::geometry::tet_signed_volume6 as signed_volume6;

#[inline]
fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

#[inline]
fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    let d = sub(a, b);
    (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt()
}

/// Checks that a mesh can be simulated: at least one element, finite vertices, indices in
/// range, no repeated vertex, every rest element positively oriented and non-degenerate.
///
/// # Errors
/// The first problem found, naming the element or vertex ([`FemError`]).
pub fn validate(positions: &[[f64; 3]], elements: &[[usize; 4]]) -> Result<(), FemError> {
    if elements.is_empty() {
        return Err(FemError::EmptyMesh);
    }
    for (vertex, p) in positions.iter().enumerate() {
        if !p.iter().all(|c| c.is_finite()) {
            return Err(FemError::NonFiniteVertex { vertex });
        }
    }
    let n = positions.len();
    for (element, t) in elements.iter().enumerate() {
        for (a, &vertex) in t.iter().enumerate() {
            if vertex >= n {
                return Err(FemError::VertexOutOfRange { element, vertex, vertices: n });
            }
            if t[..a].contains(&vertex) {
                return Err(FemError::RepeatedVertex { element, vertex });
            }
        }
        let p = t.map(|i| positions[i]);
        let volume6 = signed_volume6(p[0], p[1], p[2], p[3]);
        let mut edge: f64 = 0.0;
        for a in 0..4 {
            for b in a + 1..4 {
                edge = edge.max(dist(p[a], p[b]));
            }
        }
        if !(volume6.abs() > DEGENERACY * edge * edge * edge) {
            return Err(FemError::DegenerateElement { element, volume6, edge });
        }
        if volume6 < 0.0 {
            return Err(FemError::InvertedElement { element, volume6 });
        }
    }
    Ok(())
}

/// Reads a Gmsh `.msh` file (versions 2.2 and 4.1, ASCII) and keeps its 4-node tetrahedra.
///
/// # Errors
/// [`FemError::MeshInput`] when the file cannot be read or parsed (the message names the file
/// and line), or the validation errors of [`validate`].
#[cfg(feature = "files")]
pub fn read_gmsh(path: impl AsRef<Path>) -> Result<TetMesh, FemError> {
    let mesh = anim_io::gmsh::read_gmsh(path)?.tet_mesh();
    validate(&mesh.positions, &mesh.tets)?;
    Ok(mesh)
}

/// Reads a TetGen `.node`/`.ele` pair (`path` names either file or their common stem).
///
/// # Errors
/// As [`read_gmsh`].
#[cfg(feature = "files")]
pub fn read_tetgen(path: impl AsRef<Path>) -> Result<TetMesh, FemError> {
    let mesh = anim_io::tetgen::read_tetgen(path)?.tet_mesh();
    validate(&mesh.positions, &mesh.tets)?;
    Ok(mesh)
}

/// Why a mesh file is refused by a build without feature `files`.
#[cfg(not(feature = "files"))]
pub(crate) fn needs_files(path: &std::path::Path) -> String {
    format!("{}: reading mesh files needs anim-fem's `files` feature (on by default)", path.display())
}

/// The boundary triangles of a tetrahedral mesh, oriented outward, in a deterministic order.
#[must_use]
pub fn boundary_triangles(mesh: &TetMesh) -> Vec<[usize; 3]> {
    mesh.boundary_triangles()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit() -> (Vec<[f64; 3]>, Vec<[usize; 4]>) {
        (vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]], vec![[0, 1, 2, 3]])
    }

    #[test]
    fn rejects_bad_rest_elements_by_index() {
        let (p, t) = unit();
        assert!(validate(&p, &t).is_ok());
        let inverted = vec![[0, 1, 2, 3], [0, 2, 1, 3]];
        assert!(matches!(validate(&p, &inverted), Err(FemError::InvertedElement { element: 1, .. })));
        let mut flat = p.clone();
        flat[3] = [0.3, 0.3, 0.0];
        assert!(matches!(validate(&flat, &t), Err(FemError::DegenerateElement { element: 0, .. })));
        assert!(matches!(
            validate(&p, &[[0, 1, 2, 7]]),
            Err(FemError::VertexOutOfRange { element: 0, vertex: 7, .. })
        ));
        assert!(matches!(
            validate(&p, &[[0, 1, 1, 3]]),
            Err(FemError::RepeatedVertex { element: 0, vertex: 1 })
        ));
        assert!(matches!(validate(&p, &[]), Err(FemError::EmptyMesh)));
        let mut nan = p.clone();
        nan[2][1] = f64::NAN;
        assert!(matches!(validate(&nan, &t), Err(FemError::NonFiniteVertex { vertex: 2 })));
        let msg = validate(&p, &inverted).unwrap_err().to_string();
        assert!(msg.contains("element 1") && msg.contains("inverted"), "{msg}");
    }

    #[test]
    #[cfg(feature = "files")]
    fn reads_tetgen_and_gmsh_files() {
        let dir = std::env::temp_dir().join(format!("anim-fem-mesh-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let node = "4 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n3 0 0 1\n";
        let ele = "1 4 0\n0 0 1 2 3\n";
        std::fs::write(dir.join("t.node"), node).unwrap();
        std::fs::write(dir.join("t.ele"), ele).unwrap();
        let m = read_tetgen(dir.join("t")).unwrap();
        assert_eq!(m.tets, vec![[0, 1, 2, 3]]);
        // The same tetrahedron with two vertices swapped: inverted, named.
        std::fs::write(dir.join("bad.node"), node).unwrap();
        std::fs::write(dir.join("bad.ele"), "1 4 0\n0 0 2 1 3\n").unwrap();
        assert!(matches!(read_tetgen(dir.join("bad")), Err(FemError::InvertedElement { element: 0, .. })));
        let msh = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n$EndNodes\n$Elements\n1\n1 4 2 0 1 1 2 3 4\n$EndElements\n";
        std::fs::write(dir.join("t.msh"), msh).unwrap();
        let g = read_gmsh(dir.join("t.msh")).unwrap();
        assert_eq!(g.tets.len(), 1);
        assert!(matches!(read_gmsh(dir.join("missing.msh")), Err(FemError::MeshInput(_))));
        std::fs::remove_dir_all(&dir).ok();
    }
}
