//! A scene file's `obstacle_meshes` (anim-core's [`ObstacleMesh`]): each closed OBJ surface
//! read relative to the scene file, placed and checked closed (anim-io's
//! [`read_closed_surface`]), sampled on a distance field of
//! spacing `cell` covering the contact's thickness, then a [`MeshCollider`] with the scene's
//! `contact` parameters.

use std::path::{Path, PathBuf};

use anim_core::scene::{BuildError, ObstacleMesh};
use anim_io::surface::read_closed_surface;

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
        let table = format!("obstacle_meshes[{k}]");
        let path = resolve(&m.mesh);
        let surface = read_closed_surface(&path, &m.placement()).map_err(|e| e.within(&table))?;
        // The penalty acts within the thickness of the surface: the field covers that much more.
        let field = m
            .field(&surface, contact.thickness)
            .map_err(|e| BuildError::invalid(format!("{table}.cell"), format!("{}: {e}", path.display())))?;
        out.push(MeshCollider {
            shape: field,
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
