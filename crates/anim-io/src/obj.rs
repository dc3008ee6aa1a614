//! Wavefront OBJ: a reader for triangle meshes (cloth and obstacle input) and a writer for
//! triangle meshes and polylines (Blender, Houdini, MeshLab, any DCC tool).
//!
//! Reader: `v` positions, `f` faces (`i`, `i/t`, `i//n`, `i/t/n`; negative indices count back
//! from the last vertex defined so far), `l` polylines (split into segments). Indices are
//! converted from OBJ's 1-based to 0-based, and nothing else changes: vertices keep their file
//! order, unreferenced and duplicate vertices are kept. Faces with more than three vertices are
//! fan-triangulated (`(0, k, k + 1)`, exact for convex polygons) or rejected, as the caller
//! chooses; [`ObjMesh::triangulated_polygons`] counts them. `v x y z r g b` vertex colours are
//! read past; `v x y z w` with `w != 1` is refused (rational vertices). Texture coordinates,
//! normals, groups, materials and smoothing statements do not change the geometry and are skipped,
//! as are the free-form curve statements.
//!
//! Why not `tobj`: it is well kept, but its errors carry no line number, and it re-numbers
//! vertices per object in first-use order and drops unreferenced ones, which would silently break
//! the vertex numbering that pins and attachments refer to.

use crate::IoError;
use crate::data::Real;
use crate::text::{Lines, Tokens, read_text};
use anim_core::mesh::TriMesh;
use std::fmt::Write as _;
use std::path::Path;

/// What to do with faces of more than three vertices.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum Polygons {
    /// Split into a fan of triangles `(v0, vk, vk+1)` (exact for convex polygons).
    #[default]
    Triangulate,
    /// Refuse the file, naming the line.
    Reject,
}

/// What an OBJ file holds, 0-based.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ObjMesh {
    /// Vertex positions in file order.
    pub positions: Vec<[f64; 3]>,
    /// Triangles (faces, and the fan triangles of larger polygons), in file order.
    pub triangles: Vec<[usize; 3]>,
    /// Line segments of `l` statements, in file order.
    pub lines: Vec<[usize; 2]>,
    /// Faces of more than three vertices that were fan-triangulated.
    pub triangulated_polygons: usize,
}

impl ObjMesh {
    /// The positions and triangles as a [`TriMesh`] (lines are not part of it).
    pub fn into_tri_mesh(self) -> TriMesh {
        TriMesh { positions: self.positions, triangles: self.triangles }
    }
}

/// Reads an OBJ file.
pub fn read_obj(path: impl AsRef<Path>, polygons: Polygons) -> Result<ObjMesh, IoError> {
    let (text, name) = read_text(path.as_ref())?;
    parse_obj(&text, &name, polygons)
}

/// Parses OBJ text; `file` names it in errors.
pub fn parse_obj(text: &str, file: &str, polygons: Polygons) -> Result<ObjMesh, IoError> {
    let mut lines = Lines::new(text, file, Some('#'));
    let mut mesh = ObjMesh::default();
    // Positive indices may refer to vertices defined later; they are checked at the end.
    let mut pending: Vec<(usize, usize)> = Vec::new(); // (line, largest 0-based index on it)
    let mut corners: Vec<usize> = Vec::new();
    while let Some((line, text)) = lines.next_content() {
        let mut t = Tokens::new(text, line, file);
        let Some(keyword) = t.next_str() else { continue };
        match keyword {
            "v" => {
                let p = t.xyz("vertex coordinate")?;
                let rest: Vec<&str> = std::iter::from_fn(|| t.next_str()).collect();
                match rest.len() {
                    0 | 3 => {}
                    1 => {
                        let w: f64 =
                            rest[0].parse().map_err(|_| t.err(format!("bad weight `{}`", rest[0])))?;
                        if w != 1.0 {
                            return Err(
                                t.err(format!("vertex weight w = {} (only w = 1 is supported)", rest[0]))
                            );
                        }
                    }
                    n => return Err(t.err(format!("vertex with {} values (expected 3, 4 or 6)", n + 3))),
                }
                mesh.positions.push(p);
            }
            "f" | "l" => {
                corners.clear();
                while let Some(tok) = t.next_str() {
                    corners.push(vertex_index(&t, tok, mesh.positions.len())?);
                }
                if let Some(&max) = corners.iter().max()
                    && max >= mesh.positions.len()
                {
                    pending.push((line, max));
                }
                if keyword == "l" {
                    if corners.len() < 2 {
                        return Err(t.err(format!("line with {} vertices (needs at least 2)", corners.len())));
                    }
                    mesh.lines.extend(corners.windows(2).map(|w| [w[0], w[1]]));
                } else {
                    match corners.len() {
                        0..=2 => {
                            return Err(
                                t.err(format!("face with {} vertices (needs at least 3)", corners.len()))
                            );
                        }
                        3 => mesh.triangles.push([corners[0], corners[1], corners[2]]),
                        n => {
                            if polygons == Polygons::Reject {
                                return Err(
                                    t.err(format!("face with {n} vertices; only triangles are accepted"))
                                );
                            }
                            mesh.triangulated_polygons += 1;
                            for k in 1..n - 1 {
                                mesh.triangles.push([corners[0], corners[k], corners[k + 1]]);
                            }
                        }
                    }
                }
            }
            _ => {} // vt, vn, vp, o, g, s, usemtl, mtllib, p, curves: no effect on the geometry
        }
    }
    let n = mesh.positions.len();
    if let Some(&(line, max)) = pending.iter().find(|(_, max)| *max >= n) {
        return Err(lines.err_at(line, format!("vertex index {} but the file has {n} vertices", max + 1)));
    }
    Ok(mesh)
}

/// The 0-based position index of a face or line corner `i[/t[/n]]`, `count` vertices so far.
fn vertex_index(t: &Tokens<'_>, token: &str, count: usize) -> Result<usize, IoError> {
    let first = token.split('/').next().unwrap_or("");
    let i: i64 = first.parse().map_err(|_| t.err(format!("bad vertex reference `{token}`")))?;
    if i > 0 {
        Ok((i - 1) as usize)
    } else if i < 0 && i.unsigned_abs() <= count as u64 {
        Ok(count - i.unsigned_abs() as usize)
    } else {
        Err(t.err(format!(
            "vertex reference `{token}` points before the first vertex ({count} defined so far)"
        )))
    }
}

/// Writes an OBJ file: `v` lines (shortest round-trip decimals), then `f` lines for triangles and
/// `l` lines for segments, 1-based. Indices are checked first.
pub fn write_obj<T: Real + std::fmt::Display>(
    path: impl AsRef<Path>,
    positions: &[[T; 3]],
    triangles: &[[usize; 3]],
    lines: &[[usize; 2]],
) -> Result<(), IoError> {
    let path = path.as_ref();
    let text = obj_text(positions, triangles, lines, &[]).map_err(|e| IoError::data(path.display(), e))?;
    crate::vtk::write_file(path, &text)
}

/// The OBJ text of a mesh, or why it cannot be written; `comments` are lines after the first
/// (`# written by anim-io`), each written after `# `.
pub(crate) fn obj_text<T: Real + std::fmt::Display>(
    positions: &[[T; 3]],
    triangles: &[[usize; 3]],
    lines: &[[usize; 2]],
    comments: &[String],
) -> Result<String, String> {
    let n = positions.len();
    if let Some((i, t)) = triangles.iter().enumerate().find(|(_, t)| t.iter().any(|&v| v >= n)) {
        return Err(format!("triangle {i} {t:?} refers to a vertex past the last ({n} vertices)"));
    }
    if let Some((i, l)) = lines.iter().enumerate().find(|(_, l)| l.iter().any(|&v| v >= n)) {
        return Err(format!("line {i} {l:?} refers to a vertex past the last ({n} vertices)"));
    }
    let mut out = String::with_capacity(n * 40 + triangles.len() * 24);
    out.push_str("# written by anim-io\n");
    for c in comments {
        let _ = writeln!(out, "# {c}");
    }
    for p in positions {
        let _ = writeln!(out, "v {} {} {}", p[0], p[1], p[2]);
    }
    for t in triangles {
        let _ = writeln!(out, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    for l in lines {
        let _ = writeln!(out, "l {} {}", l[0] + 1, l[1] + 1);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_all_face_forms_and_relative_indices() {
        let text = "# a quad and a triangle\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0 1.0\n\
                    vt 0 0\nvn 0 0 1\nf 1/1/1 2//1 3/1 4\nf -4 -2 -1\nl 1 2 3\n";
        let m = parse_obj(text, "t.obj", Polygons::Triangulate).unwrap();
        assert_eq!(m.positions.len(), 4);
        assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3], [0, 2, 3]]);
        assert_eq!(m.lines, vec![[0, 1], [1, 2]]);
        assert_eq!(m.triangulated_polygons, 1);
        let e = parse_obj(text, "t.obj", Polygons::Reject).unwrap_err().to_string();
        assert_eq!(e, "t.obj:8: face with 4 vertices; only triangles are accepted");
    }

    #[test]
    fn errors_name_file_and_line() {
        let cases = [
            ("v 0 0 0\nv 1 0\n", "t.obj:2: missing vertex coordinate"),
            ("v 0 0 0\nv 1 0 x\n", "t.obj:2: vertex coordinate: expected a number, found `x`"),
            ("v 0 0 0\nf 1 2 5\nv 1 0 0\n", "t.obj:2: vertex index 5 but the file has 2 vertices"),
            (
                "v 0 0 0\n\nf 1 -2 1\n",
                "t.obj:3: vertex reference `-2` points before the first vertex (1 defined so far)",
            ),
            (
                "v 0 0 0\nf 0 1 1\n",
                "t.obj:2: vertex reference `0` points before the first vertex (1 defined so far)",
            ),
            ("v 0 0 0\nf 1 1\n", "t.obj:2: face with 2 vertices (needs at least 3)"),
            ("v 0 0 0 2\n", "t.obj:1: vertex weight w = 2 (only w = 1 is supported)"),
            ("v 0 0 nan\n", "t.obj:1: vertex coordinate: non-finite value `nan`"),
        ];
        for (text, expected) in cases {
            let e = parse_obj(text, "t.obj", Polygons::Triangulate).unwrap_err().to_string();
            assert_eq!(e, expected, "for {text:?}");
        }
    }

    #[test]
    fn forward_references_are_allowed() {
        let m = parse_obj("f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\n", "t.obj", Polygons::Reject).unwrap();
        assert_eq!(m.triangles, vec![[0, 1, 2]]);
    }

    #[test]
    fn writer_output_reads_back_exactly() {
        let p = [[0.1f64, -2.5e-17, 3.0e300], [1.0 / 3.0, 0.0, -0.0], [7.0, 8.0, 9.0]];
        let text = obj_text(&p, &[[0, 1, 2]], &[[2, 0]], &[]).unwrap();
        let m = parse_obj(&text, "w.obj", Polygons::Reject).unwrap();
        assert_eq!(m.positions, p.to_vec());
        assert_eq!(m.triangles, vec![[0, 1, 2]]);
        assert_eq!(m.lines, vec![[2, 0]]);
        assert!(obj_text(&p, &[[0, 1, 3]], &[], &[]).unwrap_err().contains("triangle 0"));
    }
}
