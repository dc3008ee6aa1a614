//! Reading triangle meshes from Wavefront OBJ text, for [`NetworkBuilder::mesh`](crate::NetworkBuilder::mesh).
//!
//! Only what a spring network needs is read: `v x y z` vertex lines and `f` face lines (vertex
//! indices 1-based or negative-relative, with optional `/vt/vn` parts, which are ignored).
//! Polygons with more than three vertices are split into a fan of triangles. Every other line
//! (normals, texture coordinates, groups, materials, comments) is skipped. Problems are
//! [`BuildError::Obj`] naming the line.

use crate::error::BuildError;

/// Vertex positions and triangles read from an OBJ file.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TriangleMesh {
    /// Vertex positions.
    pub positions: Vec<[f64; 3]>,
    /// Triangles as 0-based vertex indices.
    pub triangles: Vec<[usize; 3]>,
}

impl TriangleMesh {
    /// Parses OBJ text.
    ///
    /// # Errors
    /// [`BuildError::Obj`] for a malformed vertex or face, an index of 0 or out of range, or a
    /// face with fewer than three vertices.
    pub fn from_obj(text: &str) -> Result<Self, BuildError> {
        let mut mesh = TriangleMesh::default();
        let mut face = Vec::new();
        for (k, raw) in text.lines().enumerate() {
            let line = k + 1;
            let err = |message: String| BuildError::Obj { line, message };
            let content = raw.split('#').next().unwrap_or("");
            let mut words = content.split_whitespace();
            match words.next() {
                Some("v") => {
                    let mut p = [0.0f64; 3];
                    for c in &mut p {
                        let w = words.next().ok_or_else(|| err("vertex needs three coordinates".into()))?;
                        *c = w.parse().map_err(|_| err(format!("bad coordinate '{w}'")))?;
                        if !c.is_finite() {
                            return Err(err(format!("coordinate '{w}' is not finite")));
                        }
                    }
                    mesh.positions.push(p);
                }
                Some("f") => {
                    face.clear();
                    for w in words {
                        let idx = w.split('/').next().unwrap_or("");
                        let i: i64 = idx.parse().map_err(|_| err(format!("bad vertex index '{w}'")))?;
                        let n = mesh.positions.len() as i64;
                        let resolved = if i > 0 { i - 1 } else { n + i };
                        if i == 0 || resolved < 0 || resolved >= n {
                            return Err(err(format!(
                                "vertex index {i} is out of range ({n} vertices defined so far)"
                            )));
                        }
                        face.push(resolved as usize);
                    }
                    if face.len() < 3 {
                        return Err(err(format!("face needs at least 3 vertices, got {}", face.len())));
                    }
                    for k in 1..face.len() - 1 {
                        mesh.triangles.push([face[0], face[k], face[k + 1]]);
                    }
                }
                _ => {}
            }
        }
        Ok(mesh)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_vertices_and_fan_triangulates() {
        let m = TriangleMesh::from_obj(
            "# square\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvn 0 0 1\nf 1/1/1 2/2/1 3/3/1 -1\n",
        )
        .unwrap();
        assert_eq!(m.positions.len(), 4);
        assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3]]);
    }

    #[test]
    fn errors_name_the_line() {
        let e = TriangleMesh::from_obj("v 0 0 0\nv 1 0 0\nf 1 2 7\n").unwrap_err();
        assert!(matches!(e, BuildError::Obj { line: 3, .. }), "{e}");
        let e = TriangleMesh::from_obj("v 0 0\n").unwrap_err();
        assert!(matches!(e, BuildError::Obj { line: 1, .. }), "{e}");
        let e = TriangleMesh::from_obj("v 0 0 0\nv 1 0 0\nf 1 2\n").unwrap_err();
        assert!(e.to_string().contains("at least 3"), "{e}");
        let e = TriangleMesh::from_obj("v 0 0 x\n").unwrap_err();
        assert!(e.to_string().contains("bad coordinate"), "{e}");
    }
}
