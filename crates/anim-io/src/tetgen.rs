//! TetGen `.node` + `.ele` reader (tetrahedral meshes as `tetgen -p` and meshio write them).
//!
//! `.node`: `<points> 3 <attributes> <boundary markers 0|1>`, then `<index> x y z [attributes]
//! [marker]` per point. `.ele`: `<tetrahedra> 4 <attributes>`, then `<index> n0 n1 n2 n3
//! [attributes]`. `#` starts a comment. Numbering starts at 0 or 1, as the first point of the
//! `.node` file says, and must then be consecutive in both files; element corners are converted
//! to 0-based by subtracting that first index (the only change made to the data). Second-order
//! (10-node) tetrahedra and 2-D `.node` files are refused.

use crate::IoError;
use crate::text::{Lines, capacity, read_text};
use anim_core::mesh::TetMesh;
use std::path::{Path, PathBuf};

/// What a TetGen `.node`/`.ele` pair holds.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TetgenMesh {
    /// Point coordinates in file order.
    pub positions: Vec<[f64; 3]>,
    /// Tetrahedra, 0-based, in file order.
    pub tets: Vec<[usize; 4]>,
    /// The number the files give their first point and element (0 or 1).
    pub first_index: usize,
    /// Attributes per point.
    pub node_attribute_count: usize,
    /// Point attributes, `node_attribute_count` per point.
    pub node_attributes: Vec<f64>,
    /// Boundary marker of each point, when the `.node` file has them.
    pub node_markers: Option<Vec<i64>>,
    /// Attributes per tetrahedron (a region number, for `tetgen -A`).
    pub tet_attribute_count: usize,
    /// Tetrahedron attributes, `tet_attribute_count` per tetrahedron.
    pub tet_attributes: Vec<f64>,
}

impl TetgenMesh {
    /// The points and tetrahedra.
    pub fn tet_mesh(&self) -> TetMesh {
        TetMesh { positions: self.positions.clone(), tets: self.tets.clone() }
    }
}

/// Reads a `.node`/`.ele` pair. `path` may name either file or their common stem
/// (`mesh.1.node`, `mesh.1.ele` or `mesh.1`).
pub fn read_tetgen(path: impl AsRef<Path>) -> Result<TetgenMesh, IoError> {
    let path = path.as_ref();
    let stem: PathBuf = match path.extension().and_then(|e| e.to_str()) {
        Some("node") | Some("ele") => path.with_extension(""),
        _ => path.to_path_buf(),
    };
    let mut node = stem.clone().into_os_string();
    node.push(".node");
    let mut ele = stem.into_os_string();
    ele.push(".ele");
    let (node_text, node_name) = read_text(Path::new(&node))?;
    let (ele_text, ele_name) = read_text(Path::new(&ele))?;
    parse_tetgen(&node_text, &node_name, &ele_text, &ele_name)
}

/// Parses the texts of a `.node` and an `.ele` file; the names appear in errors.
pub fn parse_tetgen(
    node_text: &str,
    node_file: &str,
    ele_text: &str,
    ele_file: &str,
) -> Result<TetgenMesh, IoError> {
    let mut mesh = TetgenMesh::default();
    let mut lines = Lines::new(node_text, node_file, Some('#'));
    let mut t = lines.expect("the .node header (points dimension attributes markers)")?;
    let n = t.usize("number of points")?;
    let dim = t.usize("dimension")?;
    if dim != 3 {
        return Err(t.err(format!("dimension {dim}: only 3-D .node files hold tetrahedral meshes")));
    }
    let nattr = t.usize("number of attributes")?;
    let markers = t.usize("boundary marker flag")?;
    if markers > 1 {
        return Err(t.err(format!("boundary marker flag {markers} (must be 0 or 1)")));
    }
    t.end()?;
    let cap = capacity(n, node_text.len() / 8);
    mesh.positions.reserve(cap);
    mesh.node_attribute_count = nattr;
    let mut node_markers = Vec::new();
    for i in 0..n {
        let mut t = lines.expect("a point")?;
        let index = t.usize("point number")?;
        if i == 0 {
            if index > 1 {
                return Err(t.err(format!("first point is numbered {index} (must be 0 or 1)")));
            }
            mesh.first_index = index;
        } else if index != mesh.first_index + i {
            return Err(t.err(format!("point numbered {index}, expected {}", mesh.first_index + i)));
        }
        mesh.positions.push(t.xyz("point coordinate")?);
        for _ in 0..nattr {
            mesh.node_attributes.push(t.f64("point attribute")?);
        }
        if markers == 1 {
            node_markers.push(t.i64("boundary marker")?);
        }
        t.end()?;
    }
    if markers == 1 {
        mesh.node_markers = Some(node_markers);
    }
    if let Some((line, _)) = lines.next_content() {
        return Err(lines.err_at(line, format!("content after the {n} points announced")));
    }

    let mut lines = Lines::new(ele_text, ele_file, Some('#'));
    let mut t = lines.expect("the .ele header (tetrahedra nodes-per-tet attributes)")?;
    let m = t.usize("number of tetrahedra")?;
    let per = t.usize("nodes per tetrahedron")?;
    if per != 4 {
        return Err(
            t.err(format!("{per} nodes per tetrahedron: only linear (4-node) tetrahedra are supported"))
        );
    }
    let tattr = t.usize("number of attributes")?;
    t.end()?;
    mesh.tets.reserve(capacity(m, ele_text.len() / 8));
    mesh.tet_attribute_count = tattr;
    for e in 0..m {
        let mut t = lines.expect("a tetrahedron")?;
        let index = t.usize("tetrahedron number")?;
        if index != mesh.first_index + e {
            return Err(t.err(format!("tetrahedron numbered {index}, expected {}", mesh.first_index + e)));
        }
        let mut v = [0; 4];
        for slot in &mut v {
            let k = t.usize("corner")?;
            *slot = k.checked_sub(mesh.first_index).filter(|&i| i < n).ok_or_else(|| {
                t.err(format!(
                    "corner {k} is not a point of {node_file} (numbered {}..={})",
                    mesh.first_index,
                    (mesh.first_index + n).saturating_sub(1)
                ))
            })?;
        }
        for _ in 0..tattr {
            mesh.tet_attributes.push(t.f64("tetrahedron attribute")?);
        }
        t.end()?;
        mesh.tets.push(v);
    }
    if let Some((line, _)) = lines.next_content() {
        return Err(lines.err_at(line, format!("content after the {m} tetrahedra announced")));
    }
    Ok(mesh)
}

#[cfg(test)]
mod tests {
    use super::*;

    const NODE: &str = "# unit tet\n4 3 0 1\n1 0 0 0 1\n2 1 0 0 1\n3 0 1 0 1\n4 0 0 1 0 # apex\n";
    const ELE: &str = "1 4 1\n1 1 2 3 4 7\n";

    #[test]
    fn one_based_pair_becomes_zero_based() {
        let m = parse_tetgen(NODE, "a.node", ELE, "a.ele").unwrap();
        assert_eq!(m.first_index, 1);
        assert_eq!(m.tets, vec![[0, 1, 2, 3]]);
        assert_eq!(m.positions[3], [0.0, 0.0, 1.0]);
        assert_eq!(m.node_markers, Some(vec![1, 1, 1, 0]));
        assert_eq!(m.tet_attributes, vec![7.0]);
        assert!(m.tet_mesh().validate().is_ok());
    }

    #[test]
    fn errors_name_file_and_line() {
        let cases = [
            (
                NODE.replace("4 3 0 1", "4 2 0 1"),
                ELE.to_string(),
                "a.node:2: dimension 2: only 3-D .node files hold tetrahedral meshes",
            ),
            (
                NODE.replace("3 0 1 0 1", "5 0 1 0 1"),
                ELE.to_string(),
                "a.node:5: point numbered 5, expected 3",
            ),
            (
                NODE.to_string(),
                ELE.replace("2 3 4 7", "2 3 5 7"),
                "a.ele:2: corner 5 is not a point of a.node (numbered 1..=4)",
            ),
            (
                NODE.to_string(),
                ELE.replace("2 3 4 7", "2 3 0 7"),
                "a.ele:2: corner 0 is not a point of a.node (numbered 1..=4)",
            ),
            (
                NODE.to_string(),
                ELE.replace("1 4 1", "1 10 1"),
                "a.ele:1: 10 nodes per tetrahedron: only linear (4-node) tetrahedra are supported",
            ),
            (
                NODE.to_string(),
                ELE.replace("1 4 1", "2 4 1"),
                "a.ele:3: unexpected end of file, expected a tetrahedron",
            ),
            (NODE.to_string(), ELE.replace(" 7\n", "\n"), "a.ele:2: missing tetrahedron attribute"),
        ];
        for (node, ele, expected) in cases {
            let e = parse_tetgen(&node, "a.node", &ele, "a.ele").unwrap_err().to_string();
            assert_eq!(e, expected);
        }
    }
}
