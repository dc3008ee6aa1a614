//! The `obstacle_meshes` of a `pbd` scene file: closed OBJ surfaces, placed, each sampled as a
//! signed distance field ([`ObstacleMesh::field`]) for a [`MeshCollider`](crate::MeshCollider).

use anim_core::scene::{BuildContext, BuildError, ObstacleMesh, Placement};
use anim_core::surface::{ClosedSurface, DistanceField, SurfaceError};
use std::path::Path;

/// The distance fields of `meshes`, each surface read relative to `context`, placed, checked
/// closed and sampled over its bounds widened by `margin` (m): the errors name
/// `obstacle_meshes[k]` and its field (`mesh` with the file, `cell`, `scale`, `rotate`,
/// `translate`).
pub(super) fn fields(
    meshes: &[ObstacleMesh],
    context: &BuildContext<'_>,
    margin: f64,
) -> Result<Vec<DistanceField>, BuildError> {
    let mut out = Vec::with_capacity(meshes.len());
    for (k, m) in meshes.iter().enumerate() {
        let at = |field: &str| format!("obstacle_meshes[{k}].{field}");
        let placement = m.placement();
        placement.check().map_err(|e| e.within(&format!("obstacle_meshes[{k}]")))?;
        let path = context.resolve(&m.mesh);
        let surface =
            read_surface(&path, &placement).map_err(|(field, e)| BuildError::invalid(at(field), e))?;
        let field = m
            .field(&surface, margin)
            .map_err(|e| BuildError::invalid(at("cell"), format!("{}: {e}", path.display())))?;
        out.push(field);
    }
    Ok(out)
}

/// Reads an OBJ surface (polygons split into triangle fans), places it and checks that it is
/// closed; on failure the field at fault (`mesh`, or `scale` for a surface placed too large to
/// measure) and the message, naming the file.
fn read_surface(path: &Path, placement: &Placement) -> Result<ClosedSurface, (&'static str, String)> {
    let file = path.display();
    if !path.extension().and_then(|e| e.to_str()).is_some_and(|e| e.eq_ignore_ascii_case("obj")) {
        return Err(("mesh", format!("{file}: a mesh obstacle is a Wavefront OBJ surface (.obj)")));
    }
    let obj = anim_io::obj::read_obj(path, anim_io::obj::Polygons::Triangulate).map_err(|e| {
        let text = e.to_string();
        ("mesh", if text.contains(&file.to_string()) { text } else { format!("{file}: {text}") })
    })?;
    let mut positions = obj.positions;
    placement.apply_all(&mut positions);
    ClosedSurface::new(positions, obj.triangles).map_err(|e| match e {
        SurfaceError::NonFinite { .. } | SurfaceError::TooLarge { .. } => (
            "scale",
            format!(
                "{file}: placed at scale {:e}, the surface is too large to measure: scale it down",
                placement.scale
            ),
        ),
        _ => ("mesh", format!("{file}: {e}")),
    })
}
