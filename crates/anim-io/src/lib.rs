#![doc = include_str!("../README.md")]

#[cfg(feature = "cases")]
pub mod cases;
pub mod checkpoint;
mod data;
mod error;
pub mod frames;
pub mod gmsh;
#[cfg(feature = "output")]
pub mod metrics;
pub mod obj;
pub mod ply;
#[cfg(feature = "output")]
pub mod preview;
#[cfg(feature = "surface")]
pub mod surface;
pub mod tetgen;
mod text;
#[cfg(feature = "output")]
pub mod viewer;
pub mod vtk;

pub use anim_core::mesh::{DEGENERACY_TOLERANCE, TetMesh, TriMesh, ValidationReport};
pub use checkpoint::{
    CheckpointHeader, CheckpointProblem, parse_checkpoint, read_checkpoint, write_atomic, write_checkpoint,
};
pub use data::{DataArray, Element, Real, Values};
pub use error::IoError;
pub use frames::{FrameFormat, FrameSequence, FrameWriter};
pub use vtk::{ImageData, UnstructuredGrid, VtkEncoding};

use std::path::Path;

fn extension(path: &Path) -> String {
    path.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase()
}

/// Reads a tetrahedral mesh by extension (`.msh` for Gmsh; `.node` or `.ele` for a TetGen pair)
/// and validates it: any out-of-range index, degenerate or inverted tetrahedron or non-finite
/// coordinate is an [`IoError::InvalidMesh`]. A Gmsh file whose volume elements are not all
/// 4-node tetrahedra is refused rather than read partially.
pub fn read_tet_mesh(path: impl AsRef<Path>) -> Result<TetMesh, IoError> {
    let path = path.as_ref();
    let file = path.display().to_string();
    let mesh = match extension(path).as_str() {
        "msh" => {
            let m = gmsh::read_gmsh(path)?;
            let skipped = m.skipped_volume_elements();
            if !skipped.is_empty() {
                let kinds: Vec<String> =
                    skipped.iter().map(|s| format!("{} of Gmsh type {}", s.count, s.element_type)).collect();
                return Err(IoError::data(
                    &file,
                    format!("volume elements other than 4-node tetrahedra: {}", kinds.join(", ")),
                ));
            }
            m.tet_mesh()
        }
        "node" | "ele" => tetgen::read_tetgen(path)?.tet_mesh(),
        other => {
            return Err(IoError::data(
                &file,
                format!("unknown tetrahedral mesh extension `{other}` (msh, node, ele)"),
            ));
        }
    };
    if mesh.tets.is_empty() {
        return Err(IoError::data(&file, "no tetrahedra"));
    }
    let report = mesh.validate();
    if report.is_ok() { Ok(mesh) } else { Err(IoError::InvalidMesh { file, report: Box::new(report) }) }
}

/// Reads a triangle mesh by extension (`.obj`, polygons fan-triangulated; `.msh`, its 3-node
/// triangles) and validates it: out-of-range indices, zero-area triangles and non-finite
/// coordinates are an [`IoError::InvalidMesh`].
pub fn read_tri_mesh(path: impl AsRef<Path>) -> Result<TriMesh, IoError> {
    let path = path.as_ref();
    let file = path.display().to_string();
    let mesh = match extension(path).as_str() {
        "obj" => obj::read_obj(path, obj::Polygons::Triangulate)?.into_tri_mesh(),
        "msh" => gmsh::read_gmsh(path)?.tri_mesh(),
        other => {
            return Err(IoError::data(
                &file,
                format!("unknown triangle mesh extension `{other}` (obj, msh)"),
            ));
        }
    };
    if mesh.triangles.is_empty() {
        return Err(IoError::data(&file, "no triangles"));
    }
    let report = mesh.validate();
    if report.is_ok() { Ok(mesh) } else { Err(IoError::InvalidMesh { file, report: Box::new(report) }) }
}
