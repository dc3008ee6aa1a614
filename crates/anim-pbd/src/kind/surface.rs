//! A soft body from a closed OBJ surface: the surface (placed) checked as a closed, manifold,
//! consistently oriented surface and filled with tetrahedra of edge about `cell` by anim-core's
//! [`ClosedSurface::tetrahedralize`] (Kuhn cubes of a lattice kept by centroid, the boundary
//! snapped onto the surface).

use anim_core::surface::{ClosedSurface, SurfaceError, Tetrahedra};

/// The tetrahedra filling the closed surface `positions`, `triangles` of `file`, of edge about
/// `cell`; or the field (under the body: `mesh` for the surface, `cell` for the resolution) and
/// the message, naming the file.
pub(super) fn tetrahedralize(
    file: &str,
    positions: Vec<[f64; 3]>,
    triangles: Vec<[usize; 3]>,
    cell: f64,
) -> Result<Tetrahedra, (&'static str, String)> {
    let surface = ClosedSurface::new(positions, triangles)
        .map_err(|e| ("mesh", format!("{file}: a soft body's surface must be closed: {e}")))?;
    surface.tetrahedralize(cell).map_err(|e| match e {
        SurfaceError::Resolution(_) => ("cell", format!("{file}: {e}")),
        _ => ("mesh", format!("{file}: {e}")),
    })
}
