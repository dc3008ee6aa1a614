//! The `obstacle_meshes` of a `pbd` scene file: closed OBJ surfaces, placed, each sampled as a
//! signed distance field ([`ObstacleMesh::field`]) for a [`MeshCollider`](crate::MeshCollider).

use anim_core::scene::{BuildContext, BuildError, ObstacleMesh};
use anim_core::surface::DistanceField;
use anim_io::surface::read_closed_surface;

/// The distance fields of `meshes`, each surface read relative to `context`, placed, checked
/// closed ([`read_closed_surface`]) and sampled over its bounds widened by `margin` (m): the
/// errors name `obstacle_meshes[k]` and its field (`mesh` with the file, `cell`, `scale`,
/// `rotate`, `translate`).
pub(super) fn fields(
    meshes: &[ObstacleMesh],
    context: &BuildContext<'_>,
    margin: f64,
) -> Result<Vec<DistanceField>, BuildError> {
    let mut out = Vec::with_capacity(meshes.len());
    for (k, m) in meshes.iter().enumerate() {
        let table = format!("obstacle_meshes[{k}]");
        let path = context.resolve(&m.mesh);
        let surface = read_closed_surface(&path, &m.placement()).map_err(|e| e.within(&table))?;
        let field = m
            .field(&surface, margin)
            .map_err(|e| BuildError::invalid(format!("{table}.cell"), format!("{}: {e}", path.display())))?;
        out.push(field);
    }
    Ok(out)
}
