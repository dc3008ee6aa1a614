//! A body from a closed triangle surface in an OBJ file: read with anim-io's OBJ reader
//! (polygons split into fans of triangles), checked closed, manifold and consistently oriented
//! by [`ClosedSurface::new`], and filled with tetrahedra of edge about `cell` by
//! [`ClosedSurface::tetrahedralize`] (a lattice of that spacing over the surface's bounds, its
//! boundary vertices moved onto the surface).

use std::path::Path;

use anim_core::surface::{ClosedSurface, SurfaceError};
use anim_io::obj::{Polygons, read_obj};

use super::BodyError;
use crate::mesh::TetMesh;

/// The tetrahedra filling the closed surface of the OBJ file `path`, with edges of about `cell`
/// (in the file's units; checked positive and finite by the caller).
///
/// # Errors
/// Field `mesh` for a file that does not read (its line) or a surface that is not closed,
/// manifold and consistently oriented (the triangle, edge or vertex, numbered from 0 in file
/// order); field `cell` for a cell too coarse to leave a tetrahedron inside or so fine that the
/// lattice would be too large.
pub(super) fn fill(path: &Path, cell: f64) -> Result<TetMesh, BodyError> {
    let file = path.display();
    let obj = read_obj(path, Polygons::Triangulate).map_err(|e| {
        let text = e.to_string();
        let named = if text.contains(&file.to_string()) { text } else { format!("{file}: {text}") };
        BodyError::new("mesh", named)
    })?;
    let numbering = if obj.triangulated_polygons > 0 {
        "vertices and triangles numbered from 0 in file order, polygons split into fans of triangles"
    } else {
        "vertices and triangles numbered from 0 in file order"
    };
    let surface = ClosedSurface::new(obj.positions, obj.triangles)
        .map_err(|e| BodyError::new("mesh", format!("{file}: {e} ({numbering})")))?;
    let (positions, tets) = surface.tetrahedralize(cell).map_err(|e| match e {
        SurfaceError::Resolution(_) => BodyError::new("cell", format!("{file}: {e}")),
        other => BodyError::new("mesh", format!("{file}: {other}")),
    })?;
    Ok(TetMesh { positions, tets })
}
