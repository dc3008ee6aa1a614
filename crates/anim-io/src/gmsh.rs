//! Gmsh `.msh` reader, ASCII format versions 2.2 and 4.1: nodes, 4-node tetrahedra and 3-node
//! triangles, with their physical tags.
//!
//! Nothing is changed silently:
//! - node `i` of the output is the `i`-th node in the file and [`GmshMesh::node_tags`] keeps its
//!   Gmsh tag; elements refer to nodes by tag in the file and by 0-based position here;
//! - duplicate nodes (same coordinates, different tags) are kept, and so are duplicate elements
//!   (version 2 writes an element once per physical group it belongs to);
//! - elements of other types (points, lines, quadrangles, hexahedra, second-order elements) are
//!   not converted: [`GmshMesh::skipped`] counts them by Gmsh element type;
//! - binary files, and format versions other than 2.x and 4.1, are refused with a message saying
//!   how to re-export (`gmsh -format msh22` or `msh41`, ASCII).
//!
//! Sections other than `$MeshFormat`, `$PhysicalNames`, `$Entities`, `$Nodes` and `$Elements`
//! (`$Periodic`, `$NodeData`, ...) are skipped to their `$End` line.

use crate::IoError;
use crate::text::{Lines, Tokens, capacity, read_text};
use anim_core::mesh::{TetMesh, TriMesh};
use std::collections::HashMap;
use std::path::Path;

/// Gmsh element type of a 3-node triangle.
pub const TRIANGLE: u32 = 2;
/// Gmsh element type of a 4-node tetrahedron.
pub const TETRAHEDRON: u32 = 4;

/// A named physical group (`$PhysicalNames`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PhysicalName {
    /// Dimension of the group (0 to 3).
    pub dim: i64,
    /// The physical tag elements carry.
    pub tag: i64,
    /// The name, without quotes.
    pub name: String,
}

/// Elements of a type this reader does not convert, and how many there were.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SkippedElements {
    /// The Gmsh element type number (1 = line, 3 = quadrangle, 11 = 10-node tetrahedron, 15 =
    /// point, ...).
    pub element_type: u32,
    /// How many such elements the file had.
    pub count: usize,
}

/// What a `.msh` file holds.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct GmshMesh {
    /// The format version as written in the file (`2.2`, `4.1`).
    pub version: String,
    /// Node coordinates in file order.
    pub positions: Vec<[f64; 3]>,
    /// The Gmsh tag of each node.
    pub node_tags: Vec<u64>,
    /// 4-node tetrahedra, 0-based, in file order.
    pub tets: Vec<[usize; 4]>,
    /// Physical tag of each tetrahedron (0 when it has none).
    pub tet_physical: Vec<i64>,
    /// 3-node triangles, 0-based, in file order.
    pub triangles: Vec<[usize; 3]>,
    /// Physical tag of each triangle (0 when it has none).
    pub triangle_physical: Vec<i64>,
    /// The `$PhysicalNames` section.
    pub physical_names: Vec<PhysicalName>,
    /// Elements of other types, by type, in increasing type order.
    pub skipped: Vec<SkippedElements>,
}

impl GmshMesh {
    /// The nodes and tetrahedra.
    pub fn tet_mesh(&self) -> TetMesh {
        TetMesh { positions: self.positions.clone(), tets: self.tets.clone() }
    }

    /// The nodes and triangles.
    pub fn tri_mesh(&self) -> TriMesh {
        TriMesh { positions: self.positions.clone(), triangles: self.triangles.clone() }
    }

    /// The skipped element types that are volume elements (hexahedra, prisms, pyramids,
    /// higher-order tetrahedra), which a caller expecting a tetrahedral mesh must not ignore.
    pub fn skipped_volume_elements(&self) -> Vec<SkippedElements> {
        self.skipped.iter().copied().filter(|s| element_dim(s.element_type) != Some(0..=2)).collect()
    }
}

/// Dimension range of a Gmsh element type: `Some(0..=2)` for points, lines and surface elements,
/// `None` for volume elements and types this table does not know.
fn element_dim(t: u32) -> Option<std::ops::RangeInclusive<u8>> {
    match t {
        1..=3 | 8..=10 | 15 | 16 | 20..=28 => Some(0..=2),
        _ => None,
    }
}

/// Reads a `.msh` file.
pub fn read_gmsh(path: impl AsRef<Path>) -> Result<GmshMesh, IoError> {
    let (text, name) = read_text(path.as_ref())?;
    parse_gmsh(&text, &name)
}

#[derive(Clone, Copy, PartialEq)]
enum Version {
    V2,
    V41,
}

struct Parser<'a> {
    lines: Lines<'a>,
    len: usize,
    version: Version,
    mesh: GmshMesh,
    tag_index: HashMap<u64, usize>,
    /// (dimension, entity tag) -> first physical tag, version 4.
    entity_physical: HashMap<(i64, i64), i64>,
    skipped: HashMap<u32, usize>,
    have_nodes: bool,
    have_elements: bool,
}

/// Parses `.msh` text; `file` names it in errors.
pub fn parse_gmsh(text: &str, file: &str) -> Result<GmshMesh, IoError> {
    let mut lines = Lines::new(text, file, None);
    let t = lines.expect("$MeshFormat")?;
    if t.text != "$MeshFormat" {
        return Err(
            t.err(format!("expected $MeshFormat, found `{}` (not a Gmsh 2.x/4.x file)", short(t.text)))
        );
    }
    let mut t = lines.expect("the format line (version file-type data-size)")?;
    let version_text = t.next_str().unwrap_or_default().to_string();
    let version = if version_text == "4.1" {
        Version::V41
    } else if version_text.split('.').next() == Some("2") {
        Version::V2
    } else {
        return Err(t.err(format!(
            "format version {version_text} is not supported; re-export as version 4.1 or 2.2 (gmsh -format msh41)"
        )));
    };
    let file_type = t.i64("file type")?;
    if file_type != 0 {
        return Err(t.err("binary .msh files are not supported; re-export as ASCII (gmsh -bin 0)"));
    }
    t.usize("data size")?;
    t.end()?;
    let mut p = Parser {
        len: text.len(),
        lines,
        version,
        mesh: GmshMesh { version: version_text, ..Default::default() },
        tag_index: HashMap::new(),
        entity_physical: HashMap::new(),
        skipped: HashMap::new(),
        have_nodes: false,
        have_elements: false,
    };
    p.end_section("MeshFormat")?;
    while let Some((line, text)) = p.lines.next_content() {
        let Some(name) = text.strip_prefix('$') else {
            return Err(p
                .lines
                .err_at(line, format!("expected a section header ($Name), found `{}`", short(text))));
        };
        match name {
            "PhysicalNames" => p.physical_names()?,
            "Entities" if p.version == Version::V41 => p.entities()?,
            "Nodes" => p.nodes(line)?,
            "Elements" => p.elements(line)?,
            "MeshFormat" => return Err(p.lines.err_at(line, "a second $MeshFormat section")),
            n if n.starts_with("End") => {
                return Err(p.lines.err_at(line, format!("`{text}` without its section")));
            }
            _ => {
                p.skip_section(name, line)?;
                continue;
            }
        }
        p.end_section(name)?;
    }
    if !p.have_nodes {
        return Err(p.lines.err_at(p.lines.line, "no $Nodes section"));
    }
    if !p.have_elements {
        return Err(p.lines.err_at(p.lines.line, "no $Elements section"));
    }
    let mut skipped: Vec<SkippedElements> =
        p.skipped.into_iter().map(|(element_type, count)| SkippedElements { element_type, count }).collect();
    skipped.sort_by_key(|s| s.element_type);
    p.mesh.skipped = skipped;
    Ok(p.mesh)
}

fn short(s: &str) -> String {
    if s.chars().count() > 40 {
        format!("{}...", s.chars().take(40).collect::<String>())
    } else {
        s.to_string()
    }
}

impl<'a> Parser<'a> {
    fn end_section(&mut self, name: &str) -> Result<(), IoError> {
        let t = self.lines.expect(&format!("$End{name}"))?;
        if t.text.strip_prefix("$End") != Some(name) {
            return Err(t.err(format!("expected $End{name}, found `{}`", short(t.text))));
        }
        Ok(())
    }

    fn skip_section(&mut self, name: &str, start: usize) -> Result<(), IoError> {
        while let Some((_, text)) = self.lines.next_content() {
            if text.strip_prefix("$End") == Some(name) {
                return Ok(());
            }
        }
        Err(self.lines.err_at(self.lines.line, format!("section ${name} (line {start}) has no $End{name}")))
    }

    fn physical_names(&mut self) -> Result<(), IoError> {
        let mut t = self.lines.expect("the number of physical names")?;
        let n = t.usize("number of physical names")?;
        t.end()?;
        for _ in 0..n {
            let mut t = self.lines.expect("a physical name")?;
            let dim = t.i64("physical dimension")?;
            let tag = t.i64("physical tag")?;
            let rest = t.text.splitn(3, char::is_whitespace).nth(2).unwrap_or("").trim();
            let name = rest
                .strip_prefix('"')
                .and_then(|r| r.strip_suffix('"'))
                .ok_or_else(|| t.err(format!("physical name `{}` is not in double quotes", short(rest))))?;
            self.mesh.physical_names.push(PhysicalName { dim, tag, name: name.to_string() });
        }
        Ok(())
    }

    fn entities(&mut self) -> Result<(), IoError> {
        let mut t = self.lines.expect("entity counts")?;
        let counts = [t.usize("points")?, t.usize("curves")?, t.usize("surfaces")?, t.usize("volumes")?];
        t.end()?;
        for (dim, &count) in counts.iter().enumerate() {
            for _ in 0..count {
                let mut t = self.lines.expect("an entity")?;
                let tag = t.i64("entity tag")?;
                let coords = if dim == 0 { 3 } else { 6 };
                for _ in 0..coords {
                    t.f64("entity bounding box")?;
                }
                let nphys = t.usize("number of physical tags")?;
                let mut first = 0;
                for k in 0..nphys {
                    let ptag = t.i64("physical tag")?;
                    if k == 0 {
                        first = ptag;
                    }
                }
                if dim > 0 {
                    let nb = t.usize("number of bounding entities")?;
                    for _ in 0..nb {
                        t.i64("bounding entity")?;
                    }
                }
                t.end()?;
                self.entity_physical.insert((dim as i64, tag), first);
            }
        }
        Ok(())
    }

    fn add_node(&mut self, t: &Tokens<'_>, tag: u64, xyz: [f64; 3]) -> Result<(), IoError> {
        let index = self.mesh.positions.len();
        if self.tag_index.insert(tag, index).is_some() {
            return Err(t.err(format!("node tag {tag} defined twice")));
        }
        self.mesh.positions.push(xyz);
        self.mesh.node_tags.push(tag);
        Ok(())
    }

    fn nodes(&mut self, start: usize) -> Result<(), IoError> {
        if self.have_nodes {
            return Err(self.lines.err_at(start, "a second $Nodes section"));
        }
        self.have_nodes = true;
        let mut t = self.lines.expect("the node count")?;
        match self.version {
            Version::V2 => {
                let n = t.usize("number of nodes")?;
                t.end()?;
                self.reserve(n);
                for _ in 0..n {
                    let mut t = self.lines.expect("a node (tag x y z)")?;
                    let tag = t.usize("node tag")? as u64;
                    let xyz = t.xyz("node coordinate")?;
                    t.end()?;
                    self.add_node(&t, tag, xyz)?;
                }
            }
            Version::V41 => {
                let blocks = t.usize("number of entity blocks")?;
                let n = t.usize("number of nodes")?;
                t.usize("minimum node tag")?;
                t.usize("maximum node tag")?;
                t.end()?;
                self.reserve(n);
                let mut tags = Vec::new();
                for _ in 0..blocks {
                    let mut h = self.lines.expect("a node block header")?;
                    let dim = h.usize("entity dimension")?;
                    h.i64("entity tag")?;
                    let parametric = h.usize("parametric flag")?;
                    let count = h.usize("nodes in block")?;
                    h.end()?;
                    if dim > 3 || parametric > 1 {
                        return Err(
                            h.err(format!("bad node block: dimension {dim}, parametric {parametric}"))
                        );
                    }
                    if self.mesh.positions.len().saturating_add(count) > n {
                        return Err(h.err(format!("node blocks hold more than the {n} nodes announced")));
                    }
                    tags.clear();
                    for _ in 0..count {
                        let mut t = self.lines.expect("a node tag")?;
                        tags.push((t.usize("node tag")? as u64, t.line));
                        t.end()?;
                    }
                    for &(tag, _) in &tags {
                        let mut t = self.lines.expect("node coordinates")?;
                        let xyz = t.xyz("node coordinate")?;
                        for _ in 0..dim * parametric {
                            t.f64("parametric coordinate")?;
                        }
                        t.end()?;
                        self.add_node(&t, tag, xyz)?;
                    }
                }
                if self.mesh.positions.len() != n {
                    return Err(self.lines.err_at(
                        self.lines.line,
                        format!("{} nodes in the blocks, {n} announced", self.mesh.positions.len()),
                    ));
                }
            }
        }
        Ok(())
    }

    fn reserve(&mut self, n: usize) {
        let c = capacity(n, self.len / 8);
        self.mesh.positions.reserve(c);
        self.mesh.node_tags.reserve(c);
    }

    fn node(&self, t: &Tokens<'_>, elem: u64, tag: u64) -> Result<usize, IoError> {
        self.tag_index
            .get(&tag)
            .copied()
            .ok_or_else(|| t.err(format!("element {elem} refers to node tag {tag}, not in $Nodes")))
    }

    /// Reads the node tags of one element of `kind` and stores it; `t` is past the element's tags.
    fn element(&mut self, t: &mut Tokens<'_>, elem: u64, kind: u32, physical: i64) -> Result<(), IoError> {
        match kind {
            TETRAHEDRON => {
                let mut v = [0; 4];
                for slot in &mut v {
                    let tag = t.usize("element node")? as u64;
                    *slot = self.node(t, elem, tag)?;
                }
                t.end()?;
                self.mesh.tets.push(v);
                self.mesh.tet_physical.push(physical);
            }
            TRIANGLE => {
                let mut v = [0; 3];
                for slot in &mut v {
                    let tag = t.usize("element node")? as u64;
                    *slot = self.node(t, elem, tag)?;
                }
                t.end()?;
                self.mesh.triangles.push(v);
                self.mesh.triangle_physical.push(physical);
            }
            other => *self.skipped.entry(other).or_insert(0) += 1,
        }
        Ok(())
    }

    fn elements(&mut self, start: usize) -> Result<(), IoError> {
        if !self.have_nodes {
            return Err(self.lines.err_at(start, "$Elements before $Nodes"));
        }
        if self.have_elements {
            return Err(self.lines.err_at(start, "a second $Elements section"));
        }
        self.have_elements = true;
        let mut t = self.lines.expect("the element count")?;
        match self.version {
            Version::V2 => {
                let n = t.usize("number of elements")?;
                t.end()?;
                for _ in 0..n {
                    let mut t = self.lines.expect("an element")?;
                    let elem = t.usize("element number")? as u64;
                    let kind = t.usize("element type")?;
                    let kind = u32::try_from(kind).map_err(|_| t.err(format!("element type {kind}")))?;
                    let ntags = t.usize("number of tags")?;
                    let mut physical = 0;
                    for k in 0..ntags {
                        let tag = t.i64("element tag")?;
                        if k == 0 {
                            physical = tag;
                        }
                    }
                    self.element(&mut t, elem, kind, physical)?;
                }
            }
            Version::V41 => {
                let blocks = t.usize("number of entity blocks")?;
                let n = t.usize("number of elements")?;
                t.usize("minimum element tag")?;
                t.usize("maximum element tag")?;
                t.end()?;
                let mut seen = 0usize;
                for _ in 0..blocks {
                    let mut h = self.lines.expect("an element block header")?;
                    let dim = h.i64("entity dimension")?;
                    let entity = h.i64("entity tag")?;
                    let kind = h.usize("element type")?;
                    let kind = u32::try_from(kind).map_err(|_| h.err(format!("element type {kind}")))?;
                    let count = h.usize("elements in block")?;
                    h.end()?;
                    seen = seen.saturating_add(count);
                    if seen > n {
                        return Err(
                            h.err(format!("element blocks hold more than the {n} elements announced"))
                        );
                    }
                    let physical = self.entity_physical.get(&(dim, entity)).copied().unwrap_or(0);
                    for _ in 0..count {
                        let mut t = self.lines.expect("an element")?;
                        let elem = t.usize("element tag")? as u64;
                        self.element(&mut t, elem, kind, physical)?;
                    }
                }
                if seen != n {
                    return Err(self
                        .lines
                        .err_at(self.lines.line, format!("{seen} elements in the blocks, {n} announced")));
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const V2: &str = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$PhysicalNames\n1\n3 7 \"solid part\"\n$EndPhysicalNames\n\
        $Nodes\n5\n10 0 0 0\n20 1 0 0\n30 0 1 0\n40 0 0 1\n50 0 0 0\n$EndNodes\n\
        $Elements\n3\n1 15 2 0 1 10\n2 4 2 7 1 10 20 30 40\n3 2 2 5 2 10 30 20\n$EndElements\n";

    #[test]
    fn v2_tags_map_to_file_order_and_duplicates_stay() {
        let m = parse_gmsh(V2, "a.msh").unwrap();
        assert_eq!(m.version, "2.2");
        assert_eq!(m.positions.len(), 5);
        assert_eq!(m.positions[4], [0.0, 0.0, 0.0]);
        assert_eq!(m.node_tags, vec![10, 20, 30, 40, 50]);
        assert_eq!(m.tets, vec![[0, 1, 2, 3]]);
        assert_eq!(m.tet_physical, vec![7]);
        assert_eq!(m.triangles, vec![[0, 2, 1]]);
        assert_eq!(m.triangle_physical, vec![5]);
        assert_eq!(m.physical_names, vec![PhysicalName { dim: 3, tag: 7, name: "solid part".into() }]);
        assert_eq!(m.skipped, vec![SkippedElements { element_type: 15, count: 1 }]);
        assert!(m.skipped_volume_elements().is_empty());
    }

    #[test]
    fn errors_name_the_line() {
        let cases = [
            (
                V2.replace("2.2 0 8", "2.2 1 8"),
                "a.msh:2: binary .msh files are not supported; re-export as ASCII (gmsh -bin 0)",
            ),
            (
                V2.replace("2.2 0 8", "4 0 8"),
                "a.msh:2: format version 4 is not supported; re-export as version 4.1 or 2.2 (gmsh -format msh41)",
            ),
            (
                V2.replace("1 10 20 30 40", "1 10 20 30 41"),
                "a.msh:19: element 2 refers to node tag 41, not in $Nodes",
            ),
            (V2.replace("40 0 0 1", "40 0 0"), "a.msh:13: missing node coordinate"),
            (V2.replace("50 0 0 0", "10 0 0 0"), "a.msh:14: node tag 10 defined twice"),
            (V2.replace("$EndNodes", "$EndNode"), "a.msh:15: expected $EndNodes, found `$EndNode`"),
            (V2.replace("1 10 20 30 40", "1 10 20 30 40 50"), "a.msh:19: unexpected trailing `50`"),
            (V2[..V2.len() - 32].to_string(), "a.msh:20: unexpected end of file, expected an element"),
        ];
        for (text, expected) in cases {
            let e = parse_gmsh(&text, "a.msh").unwrap_err().to_string();
            assert_eq!(e, expected);
        }
    }
}
