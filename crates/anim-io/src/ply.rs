//! Binary little-endian PLY writer for Blender, Houdini, MeshLab and CloudCompare: points with
//! named per-vertex attributes, optionally triangles.
//!
//! Layout: `element vertex` with `x y z` (`float` for `f32` positions, `double` for `f64`) then
//! one property per attribute component (`float`, `double` or `int`), and, when there are
//! triangles, `element face` with `property list uchar int vertex_indices`. Blender's importer
//! reads `nx ny nz` as normals and `red green blue` (`uchar`) as colours; other attributes come in
//! as named attributes (Blender 4.1+) or are shown by MeshLab and CloudCompare.
//!
//! Why hand-written: `ply-rs`, the Rust PLY crate, was last released in 2020 and builds every
//! element as a map of dynamically typed properties (an allocation per vertex). The binary layout
//! is a text header and packed little-endian records; writing it directly is shorter than
//! adapting our arrays to that model.

use crate::IoError;
use crate::data::{DataArray, Element, Real, Values};
use std::borrow::Cow;
use std::io::Write;
use std::path::Path;

/// A PLY file to write: positions, per-vertex attributes, optional triangles. Borrowing only.
#[derive(Debug, Clone, PartialEq)]
pub struct Ply<'a> {
    positions: Values<'a>,
    /// Per-vertex attributes; a multi-component attribute is written as one property per
    /// component, named by `names`.
    attributes: Vec<(Vec<String>, DataArray<'a>)>,
    triangles: Cow<'a, [[usize; 3]]>,
    /// Header comments after `comment written by anim-io`, one line each.
    comments: Vec<String>,
}

impl<'a> Ply<'a> {
    /// A point cloud of these positions.
    pub fn new<T: Real>(positions: &'a [[T; 3]]) -> Self {
        Self::from_values(T::values(positions.as_flattened()))
    }

    /// A point cloud of flat coordinates, 3 per point.
    pub(crate) fn from_values(positions: Values<'a>) -> Self {
        Ply { positions, attributes: Vec::new(), triangles: Cow::Borrowed(&[]), comments: Vec::new() }
    }

    /// Adds a field with one property name per component.
    pub(crate) fn field(mut self, names: Vec<String>, field: DataArray<'a>) -> Self {
        self.attributes.push((names, field));
        self
    }

    /// Sets owned triangles.
    pub(crate) fn owned_triangles(mut self, triangles: Vec<[usize; 3]>) -> Self {
        self.triangles = Cow::Owned(triangles);
        self
    }

    /// Adds a scalar per-vertex property `name` (e.g. `radius`, `density`).
    pub fn attribute<T: Element>(mut self, name: &str, values: &'a [T]) -> Self {
        self.attributes.push((vec![name.to_string()], DataArray::scalars(name, values)));
        self
    }

    /// Adds a 3-vector per-vertex attribute as three properties, e.g. `["nx", "ny", "nz"]` for
    /// normals or `["vx", "vy", "vz"]` for velocity.
    pub fn vector_attribute<T: Element>(mut self, names: [&str; 3], values: &'a [[T; 3]]) -> Self {
        let names = names.iter().map(|s| s.to_string()).collect();
        self.attributes.push((names, DataArray::vectors("vector", values)));
        self
    }

    /// Adds a header line `comment {text}` (readers skip comments); `text` must fit one line.
    pub fn comment(mut self, text: &str) -> Self {
        self.comments.push(text.to_string());
        self
    }

    /// Adds triangles (0-based vertex indices).
    pub fn triangles(mut self, triangles: &'a [[usize; 3]]) -> Self {
        self.triangles = Cow::Borrowed(triangles);
        self
    }

    /// Checks lengths, names and indices.
    pub fn check(&self) -> Result<(), String> {
        if !self.positions.len().is_multiple_of(3) {
            return Err(format!("{} coordinates, not a multiple of 3", self.positions.len()));
        }
        if let Some(c) = self.comments.iter().find(|c| c.contains(['\n', '\r'])) {
            return Err(format!("comment {c:?} spans more than one line"));
        }
        let n = self.positions.len() / 3;
        let mut names: Vec<&str> = vec!["x", "y", "z"];
        for (props, field) in &self.attributes {
            field.check(n, "vertices")?;
            if props.len() != field.components {
                return Err(format!(
                    "field `{}` has {} components but {} names",
                    field.name,
                    field.components,
                    props.len()
                ));
            }
            for p in props {
                if p.is_empty() || p.contains(|c: char| c.is_whitespace()) {
                    return Err(format!("property name `{p}` is empty or has white space"));
                }
                if names.contains(&p.as_str()) {
                    return Err(format!("two properties are named `{p}`"));
                }
                names.push(p);
            }
        }
        if n > i32::MAX as usize {
            return Err(format!("{n} vertices do not fit PLY's int indices"));
        }
        if let Some((t, tri)) = self.triangles.iter().enumerate().find(|(_, t)| t.iter().any(|&i| i >= n)) {
            return Err(format!("triangle {t} {tri:?} refers to a vertex past the last ({n} vertices)"));
        }
        Ok(())
    }

    /// Writes the file.
    pub fn write(&self, path: impl AsRef<Path>) -> Result<(), IoError> {
        let path = path.as_ref();
        self.check().map_err(|e| IoError::data(path.display(), e))?;
        let file = std::fs::File::create(path).map_err(|e| IoError::io(path, e))?;
        let mut w = std::io::BufWriter::new(file);
        w.write_all(&self.bytes()).and_then(|_| w.flush()).map_err(|e| IoError::io(path, e))
    }

    /// The whole file in memory, after the same checks as [`write`](Self::write).
    pub fn to_bytes(&self) -> Result<Vec<u8>, IoError> {
        self.check().map_err(|e| IoError::data("PLY", e))?;
        Ok(self.bytes())
    }

    /// The file's bytes; [`check`](Self::check) must have passed.
    fn bytes(&self) -> Vec<u8> {
        let n = self.positions.len() / 3;
        let mut header = String::from("ply\nformat binary_little_endian 1.0\ncomment written by anim-io\n");
        for c in &self.comments {
            header.push_str(&format!("comment {c}\n"));
        }
        header.push_str(&format!("element vertex {n}\n"));
        for axis in ["x", "y", "z"] {
            header.push_str(&format!("property {} {axis}\n", ply_type(&self.positions)));
        }
        for (props, field) in &self.attributes {
            for p in props {
                header.push_str(&format!("property {} {p}\n", ply_type(&field.values)));
            }
        }
        if !self.triangles.is_empty() {
            header.push_str(&format!(
                "element face {}\nproperty list uchar int vertex_indices\n",
                self.triangles.len()
            ));
        }
        header.push_str("end_header\n");
        let record: usize = 3 * self.positions.size()
            + self.attributes.iter().map(|(_, f)| f.components * f.values.size()).sum::<usize>();
        let mut out = Vec::with_capacity(header.len() + n * record + self.triangles.len() * 13);
        out.extend_from_slice(header.as_bytes());
        for i in 0..n {
            self.positions.extend_le(3 * i..3 * i + 3, &mut out);
            for (_, f) in &self.attributes {
                let c = f.components;
                f.values.extend_le(c * i..c * i + c, &mut out);
            }
        }
        for t in self.triangles.iter() {
            out.push(3);
            for &i in t {
                // In range by check(): n <= i32::MAX.
                out.extend_from_slice(&(i as i32).to_le_bytes());
            }
        }
        out
    }
}

fn ply_type(v: &Values<'_>) -> &'static str {
    match v {
        Values::F32(_) => "float",
        Values::F64(_) => "double",
        Values::I32(_) => "int",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn header_and_records_are_exact() {
        let p = [[1.0f32, 2.0, 3.0], [4.0, 5.0, 6.0], [7.0, 8.0, 9.0]];
        let r = [0.5f64, 0.25, 0.125];
        let bytes = Ply::new(&p).attribute("radius", &r).triangles(&[[0, 1, 2]]).to_bytes().unwrap();
        let header = "ply\nformat binary_little_endian 1.0\ncomment written by anim-io\nelement vertex 3\n\
                      property float x\nproperty float y\nproperty float z\nproperty double radius\n\
                      element face 1\nproperty list uchar int vertex_indices\nend_header\n";
        assert_eq!(&bytes[..header.len()], header.as_bytes());
        let body = &bytes[header.len()..];
        assert_eq!(body.len(), 3 * (12 + 8) + 13);
        assert_eq!(&body[0..4], &1.0f32.to_le_bytes());
        assert_eq!(&body[12..20], &0.5f64.to_le_bytes());
        assert_eq!(&body[20..24], &4.0f32.to_le_bytes());
        assert_eq!(&body[60..], &[3, 0, 0, 0, 0, 1, 0, 0, 0, 2, 0, 0, 0]);
    }

    #[test]
    fn bad_input_is_refused_with_a_reason() {
        let p = [[0.0f64; 3]; 2];
        let e = Ply::new(&p).triangles(&[[0, 1, 2]]).check().unwrap_err();
        assert!(e.contains("triangle 0 [0, 1, 2]"), "{e}");
        let e = Ply::new(&p).attribute("x", &[1.0f64, 2.0]).check().unwrap_err();
        assert!(e.contains("two properties are named `x`"), "{e}");
        let e = Ply::new(&p).attribute("r", &[1.0f64]).check().unwrap_err();
        assert!(e.contains("1 tuples but there are 2 vertices"), "{e}");
        assert!(Ply::new(&p).attribute("r", &[1.0f64]).to_bytes().is_err());
    }
}
