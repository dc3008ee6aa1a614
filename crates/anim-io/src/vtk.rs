//! VTK XML writers for ParaView (and VisIt, meshio, PyVista): `.vtu` unstructured grids, `.vti`
//! image data, `.pvd` time-series collections.
//!
//! Encoding: [`VtkEncoding::Base64`] (the default) writes each array inline as base64 of a
//! little-endian `UInt64` byte count followed by the little-endian values, one base64 stream per
//! array (VTK's own uncompressed "binary" layout, `header_type="UInt64"`): exact, about a third
//! larger than raw, and fast to write and read. [`VtkEncoding::Ascii`] writes shortest round-trip
//! decimal text (also exact, but larger and slower); use it to read a file by eye.
//!
//! Why hand-written: the format needed here is a few XML elements and one array layout. `vtkio`
//! (the Rust VTK crate) has had no stable release since 0.6.3 (2021; 0.7 is a release candidate),
//! pulls in nom, quick-xml and three compression libraries by default, and would still need our
//! own checks of lengths and indices. The conformance suite (`cargo xtask conformance --filter
//! io`) reads every file these writers produce back with the independent Python `meshio` package.

use crate::IoError;
use crate::data::{DataArray, Real, Values};
use std::fmt::Write as _;
use std::io::Write;
use std::path::{Path, PathBuf};

/// How arrays are stored in a VTK XML file.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum VtkEncoding {
    /// Inline base64 of `UInt64` byte count + little-endian values (exact, compact, fast).
    #[default]
    Base64,
    /// Decimal text, shortest representation that reads back to the same number (exact).
    Ascii,
}

/// A VTK cell type this writer supports.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CellKind {
    /// One point (VTK_VERTEX = 1).
    Vertex,
    /// Two points (VTK_LINE = 3): springs, rods, skeleton bones.
    Line,
    /// Three points (VTK_TRIANGLE = 5).
    Triangle,
    /// Four points (VTK_TETRA = 10).
    Tetra,
}

impl CellKind {
    /// Points per cell.
    pub fn points(self) -> usize {
        match self {
            CellKind::Vertex => 1,
            CellKind::Line => 2,
            CellKind::Triangle => 3,
            CellKind::Tetra => 4,
        }
    }

    /// The VTK cell type number.
    pub fn vtk_type(self) -> u8 {
        match self {
            CellKind::Vertex => 1,
            CellKind::Line => 3,
            CellKind::Triangle => 5,
            CellKind::Tetra => 10,
        }
    }

    fn name(self) -> &'static str {
        match self {
            CellKind::Vertex => "vertex",
            CellKind::Line => "line",
            CellKind::Triangle => "triangle",
            CellKind::Tetra => "tetrahedron",
        }
    }
}

/// A block of cells of one kind: connectivity stored flat, `kind.points()` indices per cell.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CellBlock<'a> {
    /// The cell kind.
    pub kind: CellKind,
    /// 0-based point indices, `kind.points()` per cell.
    pub connectivity: &'a [usize],
}

/// An unstructured grid (`.vtu`): points, cells of several kinds, per-point and per-cell fields.
/// Borrowing only: building one copies nothing.
///
/// Cells are numbered in the order their blocks were added; a cell field holds one tuple per cell
/// in that order.
#[derive(Debug, Clone, PartialEq)]
pub struct UnstructuredGrid<'a> {
    /// Point coordinates, 3 per point.
    pub points: Values<'a>,
    /// Cell blocks in file order.
    pub cells: Vec<CellBlock<'a>>,
    /// Per-point fields.
    pub point_data: Vec<DataArray<'a>>,
    /// Per-cell fields.
    pub cell_data: Vec<DataArray<'a>>,
    /// Fields of the whole dataset (`FieldData`, any number of tuples): what the frame is, such
    /// as the direction that points up. Written as decimal text whatever the encoding.
    pub field_data: Vec<DataArray<'a>>,
}

impl<'a> UnstructuredGrid<'a> {
    /// A grid of these points and no cells.
    pub fn new<T: Real>(points: &'a [[T; 3]]) -> Self {
        UnstructuredGrid {
            points: T::values(points.as_flattened()),
            cells: Vec::new(),
            point_data: Vec::new(),
            cell_data: Vec::new(),
            field_data: Vec::new(),
        }
    }

    /// Number of points.
    pub fn num_points(&self) -> usize {
        self.points.len() / 3
    }

    /// Number of cells over all blocks (a partial trailing cell is not counted).
    pub fn num_cells(&self) -> usize {
        self.cells.iter().map(|b| b.connectivity.len() / b.kind.points()).sum()
    }

    /// Adds one vertex cell per listed point (how particles become visible as points in ParaView).
    pub fn vertices(mut self, points: &'a [usize]) -> Self {
        self.cells.push(CellBlock { kind: CellKind::Vertex, connectivity: points });
        self
    }

    /// Adds line cells.
    pub fn lines(mut self, lines: &'a [[usize; 2]]) -> Self {
        self.cells.push(CellBlock { kind: CellKind::Line, connectivity: lines.as_flattened() });
        self
    }

    /// Adds triangle cells.
    pub fn triangles(mut self, triangles: &'a [[usize; 3]]) -> Self {
        self.cells.push(CellBlock { kind: CellKind::Triangle, connectivity: triangles.as_flattened() });
        self
    }

    /// Adds tetrahedron cells.
    pub fn tetrahedra(mut self, tets: &'a [[usize; 4]]) -> Self {
        self.cells.push(CellBlock { kind: CellKind::Tetra, connectivity: tets.as_flattened() });
        self
    }

    /// Adds a per-point field (one tuple per point).
    pub fn point_field(mut self, field: DataArray<'a>) -> Self {
        self.point_data.push(field);
        self
    }

    /// Adds a per-cell field (one tuple per cell, cells in block order).
    pub fn cell_field(mut self, field: DataArray<'a>) -> Self {
        self.cell_data.push(field);
        self
    }

    /// Adds a field of the whole dataset ([`UnstructuredGrid::field_data`]).
    pub fn field_data(mut self, field: DataArray<'a>) -> Self {
        self.field_data.push(field);
        self
    }

    /// Checks lengths, indices and names; the message names the offending field or cell.
    pub fn check(&self) -> Result<(), String> {
        if !self.points.len().is_multiple_of(3) {
            return Err(format!("{} point coordinates, not a multiple of 3", self.points.len()));
        }
        let n = self.num_points();
        let mut first_cell = 0;
        for block in &self.cells {
            let k = block.kind.points();
            if block.connectivity.len() % k != 0 {
                return Err(format!(
                    "a {} block has {} indices, not a multiple of {k}",
                    block.kind.name(),
                    block.connectivity.len()
                ));
            }
            if let Some(pos) = block.connectivity.iter().position(|&i| i >= n) {
                return Err(format!(
                    "{} {} (cell {}) refers to point {}, but there are {n} points",
                    block.kind.name(),
                    pos / k,
                    first_cell + pos / k,
                    block.connectivity[pos]
                ));
            }
            first_cell += block.connectivity.len() / k;
        }
        check_fields(&self.point_data, n, "points")?;
        check_fields(&self.cell_data, self.num_cells(), "cells")?;
        check_field_data(&self.field_data)
    }

    /// Writes the grid as a `.vtu` file.
    pub fn write(&self, path: impl AsRef<Path>, encoding: VtkEncoding) -> Result<(), IoError> {
        let path = path.as_ref();
        self.check().map_err(|e| IoError::data(path.display(), e))?;
        write_file(path, &self.to_xml(encoding))
    }

    /// The `.vtu` document as text (after [`check`](Self::check) has passed).
    fn to_xml(&self, encoding: VtkEncoding) -> String {
        let mut out = String::with_capacity(64 + self.points.len() * 12);
        header(&mut out, "UnstructuredGrid");
        out.push_str("<UnstructuredGrid>\n");
        field_data(&mut out, &self.field_data);
        let _ = writeln!(
            out,
            "<Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">",
            self.num_points(),
            self.num_cells()
        );
        fields(&mut out, "PointData", &self.point_data, encoding);
        fields(&mut out, "CellData", &self.cell_data, encoding);
        out.push_str("<Points>\n");
        data_array(&mut out, None, 3, &self.points, encoding);
        out.push_str("</Points>\n<Cells>\n");
        let total: usize = self.cells.iter().map(|b| b.connectivity.len()).sum();
        let mut conn = Vec::with_capacity(total);
        let mut offsets = Vec::with_capacity(self.num_cells());
        let mut types = Vec::with_capacity(self.num_cells());
        let mut end = 0i64;
        for block in &self.cells {
            let k = block.kind.points();
            conn.extend(block.connectivity.iter().map(|&i| i as i64));
            for _ in 0..block.connectivity.len() / k {
                end += k as i64;
                offsets.push(end);
                types.push(block.kind.vtk_type());
            }
        }
        int_array(&mut out, "connectivity", "Int64", &conn, encoding);
        int_array(&mut out, "offsets", "Int64", &offsets, encoding);
        let types: Vec<i64> = types.into_iter().map(i64::from).collect();
        int_array(&mut out, "types", "UInt8", &types, encoding);
        out.push_str("</Cells>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n");
        out
    }
}

fn check_fields(fields: &[DataArray<'_>], n: usize, per: &str) -> Result<(), String> {
    for (i, f) in fields.iter().enumerate() {
        f.check(n, per)?;
        if fields[..i].iter().any(|g| g.name == f.name) {
            return Err(format!("two {per} fields are named `{}`", f.name));
        }
    }
    Ok(())
}

/// A regular grid (`.vti`): `dims` points along x, y, z (1 along z for a 2-D grid), point `(i, j,
/// k)` at `origin + (i, j, k) * spacing`, x varying fastest in every field.
#[derive(Debug, Clone, PartialEq)]
pub struct ImageData<'a> {
    /// Points along each axis (at least 1).
    pub dims: [usize; 3],
    /// Position of point (0, 0, 0).
    pub origin: [f64; 3],
    /// Distance between neighbouring points along each axis.
    pub spacing: [f64; 3],
    /// Per-point fields (`dims[0] * dims[1] * dims[2]` tuples).
    pub point_data: Vec<DataArray<'a>>,
    /// Per-cell fields (one tuple per cell: the product of `dims[i] - 1` over the axes with
    /// more than one point).
    pub cell_data: Vec<DataArray<'a>>,
    /// Fields of the whole dataset, as [`UnstructuredGrid::field_data`].
    pub field_data: Vec<DataArray<'a>>,
}

impl<'a> ImageData<'a> {
    /// A grid of `dims` points.
    pub fn new(dims: [usize; 3], origin: [f64; 3], spacing: [f64; 3]) -> Self {
        ImageData {
            dims,
            origin,
            spacing,
            point_data: Vec::new(),
            cell_data: Vec::new(),
            field_data: Vec::new(),
        }
    }

    /// A 2-D grid of `cells[0] x cells[1]` cells of size `spacing` with its corner at `origin`
    /// (the layout of a cell-centred fluid grid): `(cells[0] + 1) x (cells[1] + 1) x 1` points.
    pub fn from_cells_2d(cells: [usize; 2], origin: [f64; 2], spacing: [f64; 2]) -> Self {
        Self::new([cells[0] + 1, cells[1] + 1, 1], [origin[0], origin[1], 0.0], [spacing[0], spacing[1], 1.0])
    }

    /// A 3-D grid of `cells` cells of size `spacing` with its corner at `origin`.
    pub fn from_cells_3d(cells: [usize; 3], origin: [f64; 3], spacing: [f64; 3]) -> Self {
        Self::new(cells.map(|c| c + 1), origin, spacing)
    }

    /// Number of points.
    pub fn num_points(&self) -> usize {
        self.dims.iter().product()
    }

    /// Number of cells (axes with one point are flat and do not multiply).
    pub fn num_cells(&self) -> usize {
        if self.dims.contains(&0) || self.dims == [1, 1, 1] {
            return 0;
        }
        self.dims.iter().map(|&d| if d > 1 { d - 1 } else { 1 }).product()
    }

    /// Adds a per-point field.
    pub fn point_field(mut self, field: DataArray<'a>) -> Self {
        self.point_data.push(field);
        self
    }

    /// Adds a per-cell field.
    pub fn cell_field(mut self, field: DataArray<'a>) -> Self {
        self.cell_data.push(field);
        self
    }

    /// Adds a field of the whole dataset ([`ImageData::field_data`]).
    pub fn field_data(mut self, field: DataArray<'a>) -> Self {
        self.field_data.push(field);
        self
    }

    /// Checks dimensions, spacing and field lengths.
    pub fn check(&self) -> Result<(), String> {
        if self.dims.contains(&0) {
            return Err(format!("grid dimensions {:?} contain 0", self.dims));
        }
        if !self.origin.iter().chain(&self.spacing).all(|v| v.is_finite()) {
            return Err("non-finite origin or spacing".into());
        }
        check_fields(&self.point_data, self.num_points(), "grid points")?;
        check_fields(&self.cell_data, self.num_cells(), "grid cells")?;
        check_field_data(&self.field_data)
    }

    /// Writes the grid as a `.vti` file.
    pub fn write(&self, path: impl AsRef<Path>, encoding: VtkEncoding) -> Result<(), IoError> {
        let path = path.as_ref();
        self.check().map_err(|e| IoError::data(path.display(), e))?;
        let mut out = String::new();
        header(&mut out, "ImageData");
        let [nx, ny, nz] = self.dims;
        let extent = format!("0 {} 0 {} 0 {}", nx - 1, ny - 1, nz - 1);
        let [ox, oy, oz] = self.origin;
        let [sx, sy, sz] = self.spacing;
        let _ = writeln!(
            out,
            "<ImageData WholeExtent=\"{extent}\" Origin=\"{ox:e} {oy:e} {oz:e}\" Spacing=\"{sx:e} {sy:e} {sz:e}\">"
        );
        field_data(&mut out, &self.field_data);
        let _ = writeln!(out, "<Piece Extent=\"{extent}\">");
        fields(&mut out, "PointData", &self.point_data, encoding);
        fields(&mut out, "CellData", &self.cell_data, encoding);
        out.push_str("</Piece>\n</ImageData>\n</VTKFile>\n");
        write_file(path, &out)
    }
}

/// Writes a `.pvd` collection: one `DataSet` per `(time, file)`. Give files relative to the
/// `.pvd`'s own folder (as [`FrameSequence`](crate::frames::FrameSequence) does); separators are
/// written as `/`. ParaView opens the `.pvd` as one time-varying dataset.
pub fn write_pvd(path: impl AsRef<Path>, frames: &[(f64, PathBuf)]) -> Result<(), IoError> {
    let path = path.as_ref();
    let mut out = String::from(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n<Collection>\n",
    );
    for (time, file) in frames {
        if !time.is_finite() {
            return Err(IoError::data(
                path.display(),
                format!("non-finite time {time} for {}", file.display()),
            ));
        }
        let name: Vec<String> =
            file.components().map(|c| c.as_os_str().to_string_lossy().into_owned()).collect();
        let _ = writeln!(
            out,
            "<DataSet timestep=\"{time:e}\" group=\"\" part=\"0\" file=\"{}\"/>",
            escape(&name.join("/"))
        );
    }
    out.push_str("</Collection>\n</VTKFile>\n");
    write_file(path, &out)
}

pub(crate) fn write_file(path: &Path, text: &str) -> Result<(), IoError> {
    let file = std::fs::File::create(path).map_err(|e| IoError::io(path, e))?;
    let mut w = std::io::BufWriter::new(file);
    w.write_all(text.as_bytes()).and_then(|_| w.flush()).map_err(|e| IoError::io(path, e))
}

fn header(out: &mut String, kind: &str) {
    let _ = writeln!(
        out,
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"{kind}\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">"
    );
}

fn fields(out: &mut String, tag: &str, fields: &[DataArray<'_>], encoding: VtkEncoding) {
    if fields.is_empty() {
        return;
    }
    let _ = writeln!(out, "<{tag}>");
    for f in fields {
        data_array(out, Some(&f.name), f.components, &f.values, encoding);
    }
    let _ = writeln!(out, "</{tag}>");
}

/// Field data whose arrays hold whole tuples, named once each.
fn check_field_data(fields: &[DataArray<'_>]) -> Result<(), String> {
    for (i, f) in fields.iter().enumerate() {
        if f.components == 0 || !f.values.len().is_multiple_of(f.components) {
            return Err(format!(
                "field data `{}` has {} values, not whole tuples of {}",
                f.name,
                f.values.len(),
                f.components
            ));
        }
        if fields[..i].iter().any(|g| g.name == f.name) {
            return Err(format!("two field data arrays are named `{}`", f.name));
        }
    }
    Ok(())
}

/// The dataset's `FieldData` (VTK reads its arrays' `NumberOfTuples`), as decimal text.
fn field_data(out: &mut String, fields: &[DataArray<'_>]) {
    if fields.is_empty() {
        return;
    }
    out.push_str("<FieldData>\n");
    for f in fields {
        let components = f.components.max(1);
        let _ = writeln!(
            out,
            "<DataArray type=\"{}\" Name=\"{}\" NumberOfComponents=\"{components}\" NumberOfTuples=\"{}\" format=\"ascii\">",
            type_name(&f.values),
            escape(&f.name),
            f.values.len() / components
        );
        for i in 0..f.values.len() {
            f.values.write_text(i, out);
            out.push(if (i + 1) % components == 0 { '\n' } else { ' ' });
        }
        out.push_str("</DataArray>\n");
    }
    out.push_str("</FieldData>\n");
}

fn type_name(v: &Values<'_>) -> &'static str {
    match v {
        Values::F32(_) => "Float32",
        Values::F64(_) => "Float64",
        Values::I32(_) => "Int32",
    }
}

fn open_array(out: &mut String, name: Option<&str>, ty: &str, components: usize, encoding: VtkEncoding) {
    let format = match encoding {
        VtkEncoding::Base64 => "binary",
        VtkEncoding::Ascii => "ascii",
    };
    out.push_str("<DataArray type=\"");
    out.push_str(ty);
    if let Some(name) = name {
        out.push_str("\" Name=\"");
        out.push_str(&escape(name));
    }
    let _ = writeln!(out, "\" NumberOfComponents=\"{components}\" format=\"{format}\">");
}

fn data_array(out: &mut String, name: Option<&str>, components: usize, v: &Values<'_>, enc: VtkEncoding) {
    open_array(out, name, type_name(v), components, enc);
    match enc {
        VtkEncoding::Base64 => {
            let mut bytes = Vec::with_capacity(8 + v.len() * v.size());
            bytes.extend_from_slice(&((v.len() * v.size()) as u64).to_le_bytes());
            v.extend_le(0..v.len(), &mut bytes);
            base64(&bytes, out);
        }
        VtkEncoding::Ascii => {
            for i in 0..v.len() {
                v.write_text(i, out);
                out.push(if (i + 1) % components.max(1) == 0 { '\n' } else { ' ' });
            }
        }
    }
    out.push_str("\n</DataArray>\n");
}

fn int_array(out: &mut String, name: &str, ty: &str, v: &[i64], enc: VtkEncoding) {
    open_array(out, Some(name), ty, 1, enc);
    match enc {
        VtkEncoding::Base64 => {
            let size = if ty == "UInt8" { 1 } else { 8 };
            let mut bytes = Vec::with_capacity(8 + v.len() * size);
            bytes.extend_from_slice(&((v.len() * size) as u64).to_le_bytes());
            for &x in v {
                if size == 1 {
                    bytes.push(x as u8);
                } else {
                    bytes.extend_from_slice(&x.to_le_bytes());
                }
            }
            base64(&bytes, out);
        }
        VtkEncoding::Ascii => {
            for (i, x) in v.iter().enumerate() {
                let _ = write!(out, "{x}");
                out.push(if (i + 1) % 16 == 0 { '\n' } else { ' ' });
            }
        }
    }
    out.push_str("\n</DataArray>\n");
}

/// Escapes text for an XML attribute value.
pub(crate) fn escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            c => out.push(c),
        }
    }
    out
}

/// Standard base64 (RFC 4648, with padding) of `bytes`, appended to `out`.
pub(crate) fn base64(bytes: &[u8], out: &mut String) {
    const TABLE: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    out.reserve(bytes.len().div_ceil(3) * 4);
    let mut chunks = bytes.chunks_exact(3);
    for c in chunks.by_ref() {
        let n = (u32::from(c[0]) << 16) | (u32::from(c[1]) << 8) | u32::from(c[2]);
        for shift in [18, 12, 6, 0] {
            out.push(TABLE[(n >> shift) as usize & 63] as char);
        }
    }
    let rest = chunks.remainder();
    if !rest.is_empty() {
        let b1 = rest.get(1).copied().unwrap_or(0);
        let n = (u32::from(rest[0]) << 16) | (u32::from(b1) << 8);
        out.push(TABLE[(n >> 18) as usize & 63] as char);
        out.push(TABLE[(n >> 12) as usize & 63] as char);
        out.push(if rest.len() == 2 { TABLE[(n >> 6) as usize & 63] as char } else { '=' });
        out.push('=');
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn b64(s: &[u8]) -> String {
        let mut out = String::new();
        base64(s, &mut out);
        out
    }

    #[test]
    fn base64_matches_rfc4648_vectors() {
        for (input, expected) in [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("fooba", "Zm9vYmE="),
            ("foobar", "Zm9vYmFy"),
        ] {
            assert_eq!(b64(input.as_bytes()), expected);
        }
        assert_eq!(b64(&[0xff, 0xfe, 0xfd]), "//79");
    }

    #[test]
    fn vtu_structure_and_offsets() {
        let pts = [[0.0f64, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        let tets = [[0, 1, 2, 3]];
        let tris = [[0, 1, 2], [0, 2, 3]];
        let mass = [1.0f64, 2.0, 3.0, 4.0];
        let g = UnstructuredGrid::new(&pts)
            .triangles(&tris)
            .tetrahedra(&tets)
            .point_field(DataArray::scalars("mass", &mass));
        assert_eq!(g.num_cells(), 3);
        let xml = g.to_xml(VtkEncoding::Ascii);
        assert!(xml.contains("NumberOfPoints=\"4\" NumberOfCells=\"3\""), "{xml}");
        assert!(
            xml.contains("Name=\"offsets\" NumberOfComponents=\"1\" format=\"ascii\">\n3 6 10 \n"),
            "{xml}"
        );
        assert!(
            xml.contains("Name=\"types\" NumberOfComponents=\"1\" format=\"ascii\">\n5 5 10 \n"),
            "{xml}"
        );
        assert!(xml.contains(
            "Name=\"connectivity\" NumberOfComponents=\"1\" format=\"ascii\">\n0 1 2 0 2 3 0 1 2 3 \n"
        ));
        assert!(
            xml.contains("Name=\"mass\" NumberOfComponents=\"1\" format=\"ascii\">\n1\n2\n3\n4\n"),
            "{xml}"
        );
    }

    /// Field data is the dataset's own `FieldData` element, before the piece, with its tuple
    /// count; arrays of partial tuples or repeated names are refused.
    #[test]
    fn field_data_is_written_before_the_piece_with_its_tuple_count() {
        let pts = [[0.0f64; 3]];
        let up = [[0.0f64, 1.0, 0.0]];
        let xml =
            UnstructuredGrid::new(&pts).field_data(DataArray::vectors("up", &up)).to_xml(VtkEncoding::Base64);
        let doc = roxmltree::Document::parse(&xml).unwrap();
        let array =
            doc.descendants().find(|n| n.has_tag_name("FieldData")).unwrap().first_element_child().unwrap();
        assert_eq!(
            array.parent_element().unwrap().parent_element().unwrap().tag_name().name(),
            "UnstructuredGrid"
        );
        assert_eq!(
            (
                array.attribute("Name"),
                array.attribute("NumberOfTuples"),
                array.attribute("NumberOfComponents")
            ),
            (Some("up"), Some("1"), Some("3"))
        );
        assert_eq!(read_f64(array), [0.0, 1.0, 0.0]);
        let half = [0.0f64, 1.0];
        let e =
            UnstructuredGrid::new(&pts).field_data(DataArray::new("up", 3, &half[..])).check().unwrap_err();
        assert_eq!(e, "field data `up` has 2 values, not whole tuples of 3");
        let img = ImageData::new([2, 2, 1], [0.0; 3], [1.0; 3])
            .field_data(DataArray::vectors("up", &up))
            .field_data(DataArray::vectors("up", &up));
        assert_eq!(img.check().unwrap_err(), "two field data arrays are named `up`");
    }

    #[test]
    fn base64_array_has_byte_count_header() {
        let mut out = String::new();
        data_array(&mut out, Some("a"), 1, &Values::F64(&[1.0]), VtkEncoding::Base64);
        // 8-byte header (8 as u64 LE) then 1.0 as f64 LE: 08 00.. 00 00 00 00 00 00 00 f0 3f.
        let mut bytes = 8u64.to_le_bytes().to_vec();
        bytes.extend_from_slice(&1.0f64.to_le_bytes());
        assert!(out.contains(&b64(&bytes)), "{out}");
        assert_eq!(b64(&bytes), "CAAAAAAAAAAAAAAAAADwPw==");
    }

    #[test]
    fn checks_name_the_problem() {
        let pts = [[0.0f32; 3]; 3];
        let bad = [[0, 1, 3]];
        let e = UnstructuredGrid::new(&pts).triangles(&bad).check().unwrap_err();
        assert_eq!(e, "triangle 0 (cell 0) refers to point 3, but there are 3 points");
        let short = [1.0f32, 2.0];
        let e = UnstructuredGrid::new(&pts).point_field(DataArray::scalars("m", &short)).check().unwrap_err();
        assert_eq!(e, "field `m` has 2 tuples but there are 3 points");
        let ok = [1.0f32; 3];
        let e = UnstructuredGrid::new(&pts)
            .point_field(DataArray::scalars("m", &ok))
            .point_field(DataArray::scalars("m", &ok))
            .check()
            .unwrap_err();
        assert!(e.contains("two points fields are named `m`"), "{e}");
        let img = ImageData::from_cells_2d([4, 3], [0.0; 2], [1.0; 2]);
        assert_eq!((img.num_points(), img.num_cells()), (20, 12));
        let cells = [0.0f64; 11];
        let e = img.cell_field(DataArray::scalars("p", &cells)).check().unwrap_err();
        assert_eq!(e, "field `p` has 11 tuples but there are 12 grid cells");
    }

    /// Standard base64 decoding, for reading files back.
    fn unbase64(text: &str) -> Vec<u8> {
        const TABLE: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
        let digits: Vec<u32> = text
            .bytes()
            .filter(|b| !b.is_ascii_whitespace() && *b != b'=')
            .map(|b| TABLE.iter().position(|&t| t == b).unwrap() as u32)
            .collect();
        let mut out = Vec::new();
        for c in digits.chunks(4) {
            let n = c.iter().enumerate().fold(0u32, |n, (k, &d)| n | (d << (18 - 6 * k)));
            out.extend(n.to_be_bytes()[1..c.len()].iter().copied());
        }
        out
    }

    /// The values of a `Float64` `DataArray` element, in either encoding.
    fn read_f64(array: roxmltree::Node<'_, '_>) -> Vec<f64> {
        assert_eq!(array.attribute("type"), Some("Float64"));
        let text = array.text().unwrap_or("");
        match array.attribute("format") {
            Some("ascii") => text.split_whitespace().map(|t| t.parse().unwrap()).collect(),
            Some("binary") => {
                let bytes = unbase64(text);
                let (count, data) = bytes.split_at(8);
                assert_eq!(u64::from_le_bytes(count.try_into().unwrap()) as usize, data.len());
                data.chunks_exact(8).map(|c| f64::from_le_bytes(c.try_into().unwrap())).collect()
            }
            other => panic!("format {other:?}"),
        }
    }

    /// Writes 2-D and 3-D grids in both encodings, parses the files back with an XML parser
    /// and checks the extents, origin, spacing, field names, component counts and every value.
    #[test]
    fn vti_reads_back_with_its_extents_spacing_and_values() {
        let dir = std::env::temp_dir().join(format!("anim-io-vti-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let cases = [
            ([4usize, 3, 1], [0.25, -1.0, 0.0], [0.1, 1.0 / 3.0, 1.0]),
            ([3, 2, 5], [1.0, 2.0, 3.0], [0.5, 0.25, 0.125]),
        ];
        for (cells, origin, spacing) in cases {
            let img = if cells[2] == 1 {
                ImageData::from_cells_2d(
                    [cells[0], cells[1]],
                    [origin[0], origin[1]],
                    [spacing[0], spacing[1]],
                )
            } else {
                ImageData::from_cells_3d(cells, origin, spacing)
            };
            let n_cells = cells.iter().product::<usize>();
            let n_points = img.num_points();
            // Point extents: a 2-D grid is one point thick along z.
            let extent: Vec<f64> = img.dims.iter().flat_map(|&d| [0.0, (d - 1) as f64]).collect();
            assert_eq!(img.num_cells(), n_cells);
            let density: Vec<f64> = (0..n_cells).map(|c| (c as f64).sqrt() - 1.5).collect();
            let velocity: Vec<[f64; 3]> =
                (0..n_cells).map(|c| [c as f64, -(c as f64) / 7.0, 1e-300]).collect();
            let height: Vec<f64> = (0..n_points).map(|p| 0.1 * p as f64 + f64::EPSILON).collect();
            let img = img
                .cell_field(DataArray::scalars("density", &density))
                .cell_field(DataArray::vectors("velocity", &velocity))
                .point_field(DataArray::scalars("height", &height));
            for encoding in [VtkEncoding::Ascii, VtkEncoding::Base64] {
                let path = dir.join(format!("g{}-{encoding:?}.vti", cells[2]));
                img.write(&path, encoding).unwrap();
                let text = std::fs::read_to_string(&path).unwrap();
                let doc = roxmltree::Document::parse(&text).unwrap();
                let root = doc.root_element();
                assert_eq!(root.attribute("type"), Some("ImageData"));
                let grid = root.children().find(|n| n.has_tag_name("ImageData")).unwrap();
                let numbers = |s: Option<&str>| -> Vec<f64> {
                    s.unwrap().split_whitespace().map(|t| t.parse().unwrap()).collect()
                };
                assert_eq!(numbers(grid.attribute("WholeExtent")), extent);
                assert_eq!(numbers(grid.attribute("Origin")), origin.to_vec());
                assert_eq!(numbers(grid.attribute("Spacing")), spacing.to_vec());
                let piece = grid.children().find(|n| n.has_tag_name("Piece")).unwrap();
                assert_eq!(numbers(piece.attribute("Extent")), extent);
                let array = |section: &str, name: &str| {
                    let data = piece.children().find(|n| n.has_tag_name(section)).unwrap();
                    data.children().find(|n| n.attribute("Name") == Some(name)).unwrap()
                };
                let d = array("CellData", "density");
                assert_eq!(d.attribute("NumberOfComponents"), Some("1"));
                assert_eq!(read_f64(d), density, "{encoding:?}");
                let v = array("CellData", "velocity");
                assert_eq!(v.attribute("NumberOfComponents"), Some("3"));
                assert_eq!(read_f64(v), velocity.as_flattened(), "{encoding:?}");
                assert_eq!(read_f64(array("PointData", "height")), height, "{encoding:?}");
            }
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn escape_covers_xml_specials() {
        assert_eq!(escape("a<b>&\"c'"), "a&lt;b&gt;&amp;&quot;c&apos;");
    }
}
