//! Plain mesh types: a triangle mesh and a tetrahedral mesh as vertex positions and 0-based
//! vertex tuples, and their validation. anim-io's readers produce them; the solver crates build
//! from them without reading any file.
//!
//! Indices are 0-based into `positions`. Readers never change data: duplicate vertices are kept,
//! element order and orientation are as in the file. Validation reports problems by element index
//! and never indexes out of bounds.

use std::fmt;

/// Relative threshold below which a triangle counts as zero-area and a tetrahedron as
/// zero-volume: `2 * area / L^2` for a triangle and `6 * |volume| / L^3` for a tetrahedron, `L`
/// the element's longest edge. Exactly degenerate elements land well below it after rounding;
/// any element a simulation can use lands far above it.
pub const DEGENERACY_TOLERANCE: f64 = 1e-12;

/// A triangle mesh: vertex positions and 0-based vertex triples.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TriMesh {
    /// Vertex positions.
    pub positions: Vec<[f64; 3]>,
    /// Triangles as 0-based indices into `positions`, counter-clockwise seen from the front.
    pub triangles: Vec<[usize; 3]>,
}

/// A tetrahedral mesh: vertex positions and 0-based vertex quadruples.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TetMesh {
    /// Vertex positions.
    pub positions: Vec<[f64; 3]>,
    /// Tetrahedra as 0-based indices into `positions`; positively oriented when
    /// `(x1 - x0) x (x2 - x0) . (x3 - x0) > 0`.
    pub tets: Vec<[usize; 4]>,
}

/// What [`TriMesh::validate`] and [`TetMesh::validate`] found. Every list holds indices in
/// increasing order; an element appears in at most one of `out_of_range`, `degenerate` and
/// `inverted`.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ValidationReport {
    /// Elements with a vertex index `>= positions.len()`.
    pub out_of_range: Vec<usize>,
    /// Vertices with a NaN or infinite coordinate.
    pub non_finite_vertices: Vec<usize>,
    /// Elements with zero area (triangles) or zero volume (tetrahedra), including elements that
    /// repeat a vertex; see [`DEGENERACY_TOLERANCE`].
    pub degenerate: Vec<usize>,
    /// Tetrahedra with negative signed volume (never set for triangles, whose orientation is a
    /// convention).
    pub inverted: Vec<usize>,
    /// Elements checked.
    pub elements: usize,
}

impl ValidationReport {
    /// True when nothing was found.
    pub fn is_ok(&self) -> bool {
        self.out_of_range.is_empty()
            && self.non_finite_vertices.is_empty()
            && self.degenerate.is_empty()
            && self.inverted.is_empty()
    }
}

fn list(f: &mut fmt::Formatter<'_>, what: &str, items: &[usize]) -> fmt::Result {
    const SHOWN: usize = 8;
    write!(f, "{} {what} (", items.len())?;
    for (i, v) in items.iter().take(SHOWN).enumerate() {
        if i > 0 {
            write!(f, ", ")?;
        }
        write!(f, "{v}")?;
    }
    if items.len() > SHOWN {
        write!(f, ", ...")?;
    }
    write!(f, ")")
}

impl fmt::Display for ValidationReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.is_ok() {
            return write!(f, "{} elements, no problems", self.elements);
        }
        let mut first = true;
        for (what, items) in [
            ("elements with out-of-range vertex indices", &self.out_of_range),
            ("vertices with non-finite coordinates", &self.non_finite_vertices),
            ("degenerate (zero-area or zero-volume) elements", &self.degenerate),
            ("inverted tetrahedra", &self.inverted),
        ] {
            if items.is_empty() {
                continue;
            }
            if !first {
                write!(f, "; ")?;
            }
            first = false;
            list(f, what, items)?;
        }
        Ok(())
    }
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Six times the signed volume of the tetrahedron `p` (anim-io depends on no crate of the
/// workspace; anim-core's `geometry::tet_signed_volume6` is the same triple product, its terms in
/// another order).
fn volume6([a, b, c, d]: [[f64; 3]; 4]) -> f64 {
    dot(cross(sub(b, a), sub(c, a)), sub(d, a))
}

fn norm2(a: [f64; 3]) -> f64 {
    dot(a, a)
}

fn non_finite(positions: &[[f64; 3]]) -> Vec<usize> {
    positions.iter().enumerate().filter(|(_, p)| !p.iter().all(|c| c.is_finite())).map(|(i, _)| i).collect()
}

fn has_repeat(ix: &[usize]) -> bool {
    (0..ix.len()).any(|i| (i + 1..ix.len()).any(|j| ix[i] == ix[j]))
}

impl TriMesh {
    /// Checks every triangle: indices in range, non-zero area; and every vertex: finite.
    pub fn validate(&self) -> ValidationReport {
        let mut r = ValidationReport {
            non_finite_vertices: non_finite(&self.positions),
            elements: self.triangles.len(),
            ..Default::default()
        };
        let n = self.positions.len();
        for (e, t) in self.triangles.iter().enumerate() {
            if t.iter().any(|&i| i >= n) {
                r.out_of_range.push(e);
                continue;
            }
            if has_repeat(t) {
                r.degenerate.push(e);
                continue;
            }
            let [a, b, c] = t.map(|i| self.positions[i]);
            let (ab, ac, bc) = (sub(b, a), sub(c, a), sub(c, b));
            let l2 = norm2(ab).max(norm2(ac)).max(norm2(bc));
            let twice_area = norm2(cross(ab, ac)).sqrt();
            // NaN-aware: a NaN area counts as degenerate only through non_finite_vertices.
            if twice_area <= DEGENERACY_TOLERANCE * l2 {
                r.degenerate.push(e);
            }
        }
        r
    }

    /// Area-weighted vertex normals (unit length; zero for vertices of no non-degenerate
    /// triangle). Triangles with an out-of-range index are skipped.
    pub fn vertex_normals(&self) -> Vec<[f64; 3]> {
        let mut normals = vec![[0.0; 3]; self.positions.len()];
        let n = self.positions.len();
        for t in &self.triangles {
            if t.iter().any(|&i| i >= n) {
                continue;
            }
            let [a, b, c] = t.map(|i| self.positions[i]);
            let w = cross(sub(b, a), sub(c, a));
            for &i in t {
                for k in 0..3 {
                    normals[i][k] += w[k];
                }
            }
        }
        for v in &mut normals {
            let l = norm2(*v).sqrt();
            if l > 0.0 {
                *v = v.map(|c| c / l);
            }
        }
        normals
    }
}

impl TetMesh {
    /// Six times the signed volume of tetrahedron `e`, or `None` when `e` is out of range or it
    /// names a vertex that does not exist.
    pub fn signed_volume6(&self, e: usize) -> Option<f64> {
        let t = self.tets.get(e)?;
        Some(volume6([
            *self.positions.get(t[0])?,
            *self.positions.get(t[1])?,
            *self.positions.get(t[2])?,
            *self.positions.get(t[3])?,
        ]))
    }

    /// Checks every tetrahedron: indices in range, non-zero volume, positive orientation; and
    /// every vertex: finite.
    pub fn validate(&self) -> ValidationReport {
        let mut r = ValidationReport {
            non_finite_vertices: non_finite(&self.positions),
            elements: self.tets.len(),
            ..Default::default()
        };
        let n = self.positions.len();
        for (e, t) in self.tets.iter().enumerate() {
            if t.iter().any(|&i| i >= n) {
                r.out_of_range.push(e);
                continue;
            }
            if has_repeat(t) {
                r.degenerate.push(e);
                continue;
            }
            let p = t.map(|i| self.positions[i]);
            let mut l2: f64 = 0.0;
            for i in 0..4 {
                for j in i + 1..4 {
                    l2 = l2.max(norm2(sub(p[j], p[i])));
                }
            }
            let v6 = volume6(p);
            if v6.abs() <= DEGENERACY_TOLERANCE * l2 * l2.sqrt() {
                r.degenerate.push(e);
            } else if v6 < 0.0 {
                r.inverted.push(e);
            }
        }
        r
    }

    /// The boundary triangles (faces that belong to exactly one tetrahedron), oriented outward
    /// for positively oriented tetrahedra, in a deterministic order (see
    /// [`boundary_triangles`]). Tetrahedra with an out-of-range index are skipped.
    #[must_use]
    pub fn boundary_triangles(&self) -> Vec<[usize; 3]> {
        boundary_triangles(&self.tets, self.positions.len())
    }
}

/// The boundary triangles of the tetrahedra `tets` over `n` points: the faces that belong to
/// exactly one tetrahedron, oriented outward for positively oriented tetrahedra. A tetrahedron
/// with an index `>= n` is skipped.
///
/// The faces of a tetrahedron `(a, b, c, d)` are taken as `(a, c, b)`, `(a, b, d)`, `(a, d, c)`,
/// `(b, c, d)` (outward when the tetrahedron is positive); a face is kept with the orientation
/// of the tetrahedron that listed it, and the faces come out in the order in which their sorted
/// vertex triples were first met.
///
/// ```
/// // Two tetrahedra sharing the face (1, 2, 3): 6 boundary faces of the 8.
/// let faces = anim_core::mesh::boundary_triangles(&[[0, 1, 2, 3], [1, 2, 3, 4]], 5);
/// assert_eq!(faces.len(), 6);
/// assert!(!faces.iter().any(|f| { let mut k = *f; k.sort_unstable(); k == [1, 2, 3] }));
/// ```
#[must_use]
pub fn boundary_triangles(tets: &[[usize; 4]], n: usize) -> Vec<[usize; 3]> {
    use std::collections::HashMap;
    let mut count: HashMap<[usize; 3], (usize, [usize; 3])> = HashMap::new();
    let mut order = Vec::new();
    for t in tets {
        if t.iter().any(|&i| i >= n) {
            continue;
        }
        let [a, b, c, d] = *t;
        for f in [[a, c, b], [a, b, d], [a, d, c], [b, c, d]] {
            let mut key = f;
            key.sort_unstable();
            let entry = count.entry(key).or_insert_with(|| {
                order.push(key);
                (0, f)
            });
            entry.0 += 1;
        }
    }
    order.iter().filter_map(|k| count.get(k)).filter(|(c, _)| *c == 1).map(|(_, f)| *f).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit_tet() -> TetMesh {
        TetMesh {
            positions: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            tets: vec![[0, 1, 2, 3]],
        }
    }

    #[test]
    fn tet_checks_name_each_problem_by_index() {
        let mut m = unit_tet();
        m.positions.push([1.0, 1.0, 0.0]); // coplanar with 0, 1, 2
        m.tets.push([0, 2, 1, 3]); // inverted
        m.tets.push([0, 1, 2, 4]); // flat
        m.tets.push([0, 1, 2, 7]); // out of range
        m.tets.push([0, 1, 1, 3]); // repeated vertex
        let r = m.validate();
        assert_eq!(r.out_of_range, vec![3]);
        assert_eq!(r.degenerate, vec![2, 4]);
        assert_eq!(r.inverted, vec![1]);
        assert!(r.non_finite_vertices.is_empty());
        assert!(!r.is_ok());
        assert_eq!(m.signed_volume6(0), Some(1.0));
        assert_eq!(m.signed_volume6(3), None);
        assert_eq!(m.signed_volume6(9), None);
        let text = r.to_string();
        assert!(text.contains("1 elements with out-of-range vertex indices (3)"), "{text}");
        assert!(text.contains("1 inverted tetrahedra (1)"), "{text}");
    }

    #[test]
    fn a_tiny_but_valid_tet_is_not_degenerate() {
        let mut m = unit_tet();
        for p in &mut m.positions {
            *p = p.map(|c| c * 1e-9);
        }
        assert!(m.validate().is_ok());
        // Nearly flat: height 1e-6 of the edge length is still a valid element.
        m.positions[3] = [0.0, 0.0, 1e-6];
        assert!(m.validate().is_ok(), "{}", m.validate());
        m.positions[3] = [0.3e-9, 0.3e-9, 0.0];
        assert_eq!(m.validate().degenerate, vec![0]);
    }

    #[test]
    fn triangle_checks() {
        let m = TriMesh {
            positions: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 1.0, f64::NAN]],
            triangles: vec![[0, 1, 2], [0, 1, 5], [0, 0, 1], [0, 2, 1]],
        };
        let r = m.validate();
        assert_eq!(r.out_of_range, vec![1]);
        assert_eq!(r.degenerate, vec![0, 2, 3]);
        assert_eq!(r.non_finite_vertices, vec![3]);
        assert!(r.inverted.is_empty());
    }

    #[test]
    fn boundary_of_two_tets_has_six_outward_faces() {
        let mut m = unit_tet();
        m.positions.push([1.0, 1.0, 1.0]);
        m.tets.push([1, 2, 3, 4]); // shares face (1, 2, 3), positively oriented
        assert!(m.validate().is_ok(), "{}", m.validate());
        let faces = m.boundary_triangles();
        assert_eq!(faces.len(), 6);
        // Every face normal points away from the centroid of its mesh.
        let c = [0.4, 0.4, 0.4];
        for f in faces {
            let [a, b, d] = f.map(|i| m.positions[i]);
            let n = cross(sub(b, a), sub(d, a));
            assert!(dot(n, sub(a, c)) > 0.0, "face {f:?} points inward");
        }
    }

    #[test]
    fn vertex_normals_of_a_flat_square_point_up() {
        let m = TriMesh {
            positions: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]],
            triangles: vec![[0, 1, 2], [0, 2, 3]],
        };
        for n in m.vertex_normals() {
            assert_eq!(n, [0.0, 0.0, 1.0]);
        }
    }
}
