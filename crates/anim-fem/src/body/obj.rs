//! A body from a closed triangle surface in an OBJ file: read with anim-io's
//! [`read_closed_surface`] (polygons split into fans of triangles, checked closed, manifold and
//! consistently oriented by anim-core's `ClosedSurface::new`), and filled with tetrahedra of
//! edge about `cell` by `ClosedSurface::tetrahedralize` (a lattice of that spacing over the
//! surface's bounds, its boundary vertices moved onto the surface). `cell` is in metres of the
//! placed body: the surface is filled in its own coordinates with `cell / scale`, so the lattice
//! follows the body and not its rotation. The lattice is counted first: a surface whose lattice
//! would make a scene of more memory than is available ([`crate::memory`]) is refused before
//! anything is allocated.

use std::path::Path;

#[cfg(feature = "files")]
use anim_core::scene::Placement;
#[cfg(feature = "files")]
use anim_core::surface::SurfaceError;
#[cfg(feature = "files")]
use anim_io::surface::read_closed_surface;

use super::{BodyError, Budget};
#[cfg(feature = "files")]
use crate::memory::MeshSize;
use crate::mesh::TetMesh;

/// The tetrahedra filling the closed surface of the OBJ file `path`, in the file's coordinates,
/// with edges of about `cell` once scaled by `scale` (`cell` in metres, `scale` the body's; both
/// checked positive and finite by the caller), within the memory `budget` leaves.
///
/// # Errors
/// Field `mesh` for a file that does not read (its line) or a surface that is not closed,
/// manifold and consistently oriented (the triangle, edge or vertex, numbered from 0 in file
/// order); field `cell` for a cell too coarse to leave a tetrahedron inside, or so fine that
/// the lattice's tetrahedra would take the scene past the memory `budget` leaves.
#[cfg(feature = "files")]
pub(super) fn fill(path: &Path, cell: f64, scale: f64, budget: &Budget) -> Result<TetMesh, BodyError> {
    let file = path.display();
    let surface =
        read_closed_surface(path, &Placement::default()).map_err(|e| BodyError::new(e.field(), &e))?;
    // The lattice `tetrahedralize` lays: ceil(extent / own) cubes on each axis, six tetrahedra
    // per cube at most.
    let own = cell / scale;
    let (lo, hi) = surface.bounds();
    let cubes = [0, 1, 2].map(|a| ((hi[a] - lo[a]) / own).ceil().max(1.0));
    let most = 6.0 * cubes.iter().product::<f64>();
    let what = format!(
        "{file} at a cell of {cell} m ({} x {} x {} lattice cubes over the scaled surface's bounds, up to {most:.0} \
         tetrahedra)",
        cubes[0], cubes[1], cubes[2]
    );
    budget.check("cell", &what, MeshSize::lattice(cubes), "take a larger cell")?;
    let (positions, tets) = surface.tetrahedralize(own).map_err(|e| match e {
        SurfaceError::Resolution(_) if scale != 1.0 => BodyError::new(
            "cell",
            format!("{file}: {e} (that is `cell` = {cell} m over the scale {scale}, in the OBJ's own units)"),
        ),
        SurfaceError::Resolution(_) => BodyError::new("cell", format!("{file}: {e}")),
        other => BodyError::new("mesh", format!("{file}: {other}")),
    })?;
    Ok(TetMesh { positions, tets })
}

/// Refuses the surface: this build has no `files` feature to read it.
#[cfg(not(feature = "files"))]
pub(super) fn fill(path: &Path, _cell: f64, _scale: f64, _budget: &Budget) -> Result<TetMesh, BodyError> {
    Err(BodyError::new("mesh", crate::mesh::needs_files(path)))
}
