//! # anim-io
//!
//! Files people open and look at, and meshes people bring in. Solver crates expose their state
//! as plain arrays; this crate turns those arrays into files for the tools animators and
//! researchers already use, reads the mesh formats simulations start from, and draws previews
//! without a GPU or a display. No solver crate depends on it.
//!
//! | module | formats | opened by |
//! | --- | --- | --- |
//! | [`vtk`] | VTK XML `.vtu` (points; vertex, line, triangle, tetrahedron cells; point and cell fields), `.vti` (2-D/3-D grids), `.pvd` (time series) | ParaView, VisIt, PyVista, meshio; Blender and Houdini through their VTK importers |
//! | [`ply`] | binary little-endian `.ply`: points with named attributes, triangles | Blender, Houdini, MeshLab, CloudCompare |
//! | [`obj`] | `.obj` triangle meshes and polylines, read and written | Blender, Houdini, Maya, every DCC tool |
//! | `surface` | a closed `.obj` surface read, placed and checked closed, manifold and oriented as anim-core's `ClosedSurface` (feature `surface`: `read_closed_surface`) | the scene kinds' closed meshes: bodies, mesh obstacles, fluid sources |
//! | [`gmsh`] | Gmsh `.msh` ASCII 2.2 and 4.1, read: nodes, tetrahedra, triangles, physical tags | written by Gmsh, meshio, many meshers |
//! | [`tetgen`] | TetGen `.node` + `.ele`, read | written by TetGen, meshio |
//! | [`frames`] | numbered sequences `frame_00000.vtu ...` in any of the writers' formats | ParaView (with the `.pvd`), Blender and Houdini sequence importers |
//! | [`preview`] | PNG frames and animated GIFs from a software renderer (feature `output`, default) | any image viewer, a browser |
//! | [`viewer`] | `viewer.html` beside a run's frames: orbit, play, time slider, colour by field (three.js embedded; feature `output`, default) | any browser, from the folder, offline |
//! | [`metrics`] | CSV and JSON of per-step metrics (serde; feature `output`, default) | spreadsheets, pandas, plotting scripts |
//!
//! Readers return plain types ([`TriMesh`], [`TetMesh`], or a format's own struct that keeps
//! its extra data); indices are 0-based, and the only change from the file is the documented
//! shift from 1-based numbering. A malformed file gives [`IoError::Parse`] naming the file, the
//! line and the cause; [`TriMesh::validate`] and [`TetMesh::validate`] report out-of-range
//! indices, zero-area triangles, zero-volume and (separately) inverted tetrahedra by element
//! index. [`read_tet_mesh`] and [`read_tri_mesh`] pick the reader by extension and validate.
//!
//! Writers borrow the caller's arrays (positions and fields in `f32` or `f64`, see [`Real`] and
//! [`DataArray`]) and check lengths and indices before writing anything: a mismatch is an
//! [`IoError::InvalidData`] naming the field or cell. (Solver crates panic on mismatched lengths
//! as API misuse; writers already return `Result` for I/O, and a file that cannot be written at
//! the end of a long run should be reported, not abort it.)
//!
//! ```
//! use anim_io::{DataArray, FrameFormat, FrameWriter, UnstructuredGrid};
//! use anim_io::preview::{Camera, Canvas, Colors};
//!
//! # fn main() -> Result<(), anim_io::IoError> {
//! let dir = std::env::temp_dir().join(format!("anim-io-doc-{}", std::process::id()));
//! // Three particles falling, written as a ParaView time series and previewed as a PNG.
//! let mut frames = FrameWriter::new(&dir, FrameFormat::Vtu)?;
//! let vertices = [0, 1, 2];
//! for step in 0..3 {
//!     let t = step as f64 * 0.1;
//!     let x: Vec<[f64; 3]> = (0..3).map(|i| [i as f64, -4.9 * t * t, 0.0]).collect();
//!     let speed = vec![9.8 * t; 3];
//!     let grid = UnstructuredGrid::new(&x)
//!         .vertices(&vertices)
//!         .point_field(DataArray::scalars("speed", &speed));
//!     frames.write(t, &grid)?;
//! }
//! let pvd = frames.finish()?; // dir/frames.pvd: open it in ParaView and press play
//! assert!(pvd.is_some_and(|p| p.exists()));
//!
//! let camera = Camera::look_at([1.0, 0.0, 6.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
//! let mut canvas = Canvas::new(64, 48, [255, 255, 255]);
//! canvas.draw_particles(&camera, &[[0.0f64, 0.0, 0.0], [2.0, 0.0, 0.0]], 0.3, Colors::Uniform([200, 60, 40]))?;
//! canvas.save_png(dir.join("preview.png"))?;
//! # std::fs::remove_dir_all(&dir).unwrap();
//! # Ok(())
//! # }
//! ```

#[cfg(feature = "cases")]
pub mod cases;
pub mod checkpoint;
mod data;
mod error;
pub mod frames;
pub mod gmsh;
mod mesh;
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

pub use checkpoint::{
    CheckpointHeader, CheckpointProblem, parse_checkpoint, read_checkpoint, write_atomic, write_checkpoint,
};
pub use data::{DataArray, Element, Real, Values};
pub use error::IoError;
pub use frames::{FrameFormat, FrameSequence, FrameWriter};
pub use mesh::{DEGENERACY_TOLERANCE, TetMesh, TriMesh, ValidationReport};
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
