//! A scene file's `obstacle_meshes` (anim-core's [`ObstacleMesh`]): each closed OBJ surface
//! read relative to the scene file, placed, checked closed and sampled on a distance field of
//! spacing `cell` covering the contact's thickness, then a [`MeshCollider`] with the scene's
//! `contact` parameters.

use std::path::{Path, PathBuf};

use anim_core::scene::{BuildError, ObstacleMesh};
use anim_core::surface::ClosedSurface;
use anim_io::obj::{Polygons, read_obj};

use crate::body::ContactSpec;
use crate::contact::MeshCollider;

/// The colliders of `meshes`, each file `resolve(&mesh)`, with the parameters of `contact`
/// (checked by the caller).
///
/// # Errors
/// [`BuildError::Invalid`] naming `obstacle_meshes[k].mesh` and the file (not an `.obj`, a
/// file that does not read, a surface that is not closed, manifold and consistently oriented:
/// the triangle, edge or vertex), `obstacle_meshes[k].cell` (a spacing that is not positive and
/// finite, or too fine), `obstacle_meshes[k].scale` (`.rotate`, `.translate`).
pub(crate) fn mesh_colliders(
    meshes: &[ObstacleMesh],
    contact: &ContactSpec,
    resolve: impl Fn(&Path) -> PathBuf,
) -> Result<Vec<MeshCollider>, BuildError> {
    let mut out = Vec::with_capacity(meshes.len());
    for (k, m) in meshes.iter().enumerate() {
        let at = |field: &str| format!("obstacle_meshes[{k}].{field}");
        let placement = m.placement();
        placement.check().map_err(|e| match e {
            BuildError::Invalid { field, message } => BuildError::invalid(at(&field), message),
            other => BuildError::invalid(at("scale"), other.to_string()),
        })?;
        let path = resolve(&m.mesh);
        let file = path.display();
        if !path.extension().and_then(|e| e.to_str()).is_some_and(|e| e.eq_ignore_ascii_case("obj")) {
            return Err(BuildError::invalid(
                at("mesh"),
                format!("{file}: a mesh obstacle is a Wavefront OBJ surface (.obj)"),
            ));
        }
        let obj = read_obj(&path, Polygons::Triangulate).map_err(|e| {
            let text = e.to_string();
            BuildError::invalid(
                at("mesh"),
                if text.contains(&file.to_string()) { text } else { format!("{file}: {text}") },
            )
        })?;
        let mut positions = obj.positions;
        placement.apply_all(&mut positions);
        let surface = ClosedSurface::new(positions, obj.triangles).map_err(|e| {
            BuildError::invalid(
                at("mesh"),
                format!("{file}: {e} (vertices and triangles numbered from 0 in file order)"),
            )
        })?;
        // The penalty acts within the thickness of the surface: the field covers that much more.
        let field = m
            .field(&surface, contact.thickness)
            .map_err(|e| BuildError::invalid(at("cell"), format!("{file}: {e}")))?;
        out.push(MeshCollider {
            field,
            stiffness: contact.stiffness,
            damping: contact.damping,
            friction: contact.friction,
            smoothing: contact.smoothing,
            thickness: contact.thickness,
        });
    }
    Ok(out)
}

#[cfg(test)]
mod tests;
