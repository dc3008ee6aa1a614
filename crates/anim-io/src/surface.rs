//! A closed surface from an OBJ file, placed (feature `surface`): what every scene kind that
//! takes a user's closed mesh (a body to fill or sample, a mesh obstacle, a fluid's source or
//! obstacle) reads the same way, with one error that names the file, the element at fault
//! and the cause.
//!
//! [`read_closed_surface`] checks the [`Placement`], reads the file with [`read_obj`]
//! (polygons split into fans of triangles), places its vertices and checks the result with
//! [`ClosedSurface::new`]: closed, manifold, consistently oriented, no zero-area triangle. A
//! [`SurfaceFileError`] says which field of the scene file's table is at fault
//! ([`field`](SurfaceFileError::field): `mesh`, or `scale`, `rotate`, `translate`), so that a
//! kind names its own field (`obstacle_meshes[0].mesh`, `bodies[2].scale`).
//!
//! ```
//! use anim_core::scene::Placement;
//! use anim_io::surface::{SurfaceFileError, read_closed_surface};
//!
//! let dir = std::env::temp_dir().join(format!("anim-io-surface-doc-{}", std::process::id()));
//! std::fs::create_dir_all(&dir)?;
//! // A tetrahedron with one face missing.
//! let path = dir.join("open.obj");
//! std::fs::write(&path, "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\n")?;
//! let e = read_closed_surface(&path, &Placement::default()).unwrap_err();
//! assert_eq!(e.field(), "mesh");
//! assert!(e.to_string().contains("open.obj") && e.to_string().contains("edge ("), "{e}");
//! // Closed, and moved up by 1 m.
//! std::fs::write(&path, "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n")?;
//! let up = Placement { translate: [0.0, 0.0, 1.0], ..Placement::default() };
//! let surface = read_closed_surface(&path, &up)?;
//! assert_eq!(surface.bounds().0, [0.0, 0.0, 1.0]);
//! # std::fs::remove_dir_all(&dir)?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use std::path::{Path, PathBuf};

use anim_core::scene::{BuildError, Placement};
use anim_core::surface::{ClosedSurface, SurfaceError};

use crate::IoError;
use crate::obj::{Polygons, read_obj};

/// Why an OBJ file does not give a closed surface where a scene places it.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SurfaceFileError {
    /// The placement's own fields: a scale that is not positive and finite, a rotation or
    /// translation that is not finite.
    #[error("{message}")]
    Placement {
        /// `scale`, `rotate` or `translate`.
        field: String,
        /// What is wrong with it.
        message: String,
    },
    /// The file's name does not end in `.obj`.
    #[error("{}: a closed surface is read from a Wavefront OBJ file (.obj)", path.display())]
    NotObj {
        /// The file.
        path: PathBuf,
    },
    /// The file does not read, or does not parse (the error names the file and the line).
    #[error(transparent)]
    Read(#[from] IoError),
    /// The placed surface's extent overflows (a scale far too large): the message names the
    /// scale.
    #[error(
        "{}: placed at scale {scale:e}, the surface is too large to measure: scale it down",
        path.display()
    )]
    TooLarge {
        /// The file.
        path: PathBuf,
        /// The placement's scale.
        scale: f64,
        /// The surface's refusal (its extent or a placed vertex overflows).
        cause: SurfaceError,
    },
    /// The triangles are not a closed, manifold, consistently oriented surface, or a triangle
    /// has no area: the cause names the triangle, edge or vertex, numbered from 0 in the file's
    /// order.
    #[error("{}: {cause} ({})", path.display(), numbering(.split_polygons))]
    NotClosed {
        /// The file.
        path: PathBuf,
        /// The surface's refusal.
        cause: SurfaceError,
        /// Whether the file held polygons of more than three vertices, split into triangles
        /// (the triangle numbers then count the split ones).
        split_polygons: bool,
    },
}

/// How the elements of a refusal are numbered.
fn numbering(split_polygons: &bool) -> &'static str {
    if *split_polygons {
        "vertices and triangles numbered from 0 in file order, polygons split into fans of triangles"
    } else {
        "vertices and triangles numbered from 0 in file order"
    }
}

impl SurfaceFileError {
    /// The field of the scene file's table at fault: `scale`, `rotate` or `translate` for the
    /// placement (and `scale` for a surface placed too large to measure), `mesh` for the file.
    #[must_use]
    pub fn field(&self) -> &str {
        match self {
            SurfaceFileError::Placement { field, .. } => field,
            SurfaceFileError::TooLarge { .. } => "scale",
            SurfaceFileError::NotObj { .. }
            | SurfaceFileError::Read(_)
            | SurfaceFileError::NotClosed { .. } => "mesh",
        }
    }

    /// The error as a [`BuildError::Invalid`] of the table `table` of a scene file
    /// (`obstacle_meshes[2]`, `bodies[0]`), at its [`field`](Self::field):
    /// `obstacle_meshes[2].mesh`.
    #[must_use]
    pub fn within(&self, table: &str) -> BuildError {
        BuildError::invalid(format!("{table}.{}", self.field()), self.to_string())
    }
}

/// The closed surface of the OBJ file `path`, its vertices moved by `placement` (see the
/// [module](self)).
///
/// # Errors
/// [`SurfaceFileError`]: in this order, a placement whose fields are not finite (or a scale
/// that is not positive), a name that does not end in `.obj`, a file that does not read or
/// parse (a coordinate that is not finite among them), a placed surface too large to measure, a
/// surface that is not closed, manifold and consistently oriented or has a zero-area triangle.
pub fn read_closed_surface(path: &Path, placement: &Placement) -> Result<ClosedSurface, SurfaceFileError> {
    placement.check().map_err(|e| match e {
        BuildError::Invalid { field, message } => SurfaceFileError::Placement { field, message },
        other => SurfaceFileError::Placement { field: "scale".into(), message: other.to_string() },
    })?;
    if !path.extension().and_then(|e| e.to_str()).is_some_and(|e| e.eq_ignore_ascii_case("obj")) {
        return Err(SurfaceFileError::NotObj { path: path.to_path_buf() });
    }
    let obj = read_obj(path, Polygons::Triangulate)?;
    let split_polygons = obj.triangulated_polygons > 0;
    let mut positions = obj.positions;
    placement.apply_all(&mut positions);
    // The reader refuses a coordinate that is not finite: one here overflowed in the placement.
    ClosedSurface::new(positions, obj.triangles).map_err(|cause| match cause {
        SurfaceError::NonFinite { .. } | SurfaceError::TooLarge { .. } => {
            SurfaceFileError::TooLarge { path: path.to_path_buf(), scale: placement.scale, cause }
        }
        cause => SurfaceFileError::NotClosed { path: path.to_path_buf(), cause, split_polygons },
    })
}

#[cfg(test)]
mod tests;
