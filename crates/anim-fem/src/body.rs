//! A body of the user's own: a tetrahedral mesh file (Gmsh 2.2 or 4.1 `.msh`, TetGen
//! `.node`/`.ele`) or a closed triangle surface (`.obj`, filled with tetrahedra) with its
//! material, its placement (scale, rotation, translation), initial velocity and pinned vertices.
//! [`BodySpec`] is one entry of the `bodies` list of an `fem` scene file (see [`crate::kind`]);
//! [`crate::bodies`] merges several into one model with the obstacles, gravity and damping they
//! share.
//!
//! ```
//! # #[cfg(feature = "files")]
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! use anim_fem::body::BodySpec;
//!
//! let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../anim-io/testdata");
//! let spec: BodySpec = serde_json::from_value(serde_json::json!({
//!     "mesh": "cube_v41.msh",
//!     "material": { "young": 5e4, "poisson": 0.3, "density": 1000.0 },
//!     "translate": [0.0, 0.0, 0.5],
//! }))?;
//! let body = spec.load(&dir.join(&spec.mesh))?;
//! assert!(body.mesh.positions.iter().all(|p| p[2] >= 0.5 - 1e-12));
//! # Ok(())
//! # }
//! # #[cfg(not(feature = "files"))]
//! # fn main() {}
//! ```
//!
//! Units are SI: metres, kilograms, seconds, pascals. Scenes are z-up.

use anim_core::scene::{is_unit_scale, unit_scale};
use std::path::{Path, PathBuf};

use anim_core::scene::{BuildError, Placement, available_memory, is_default};
use serde::{Deserialize, Deserializer, Serialize};

use crate::error::FemError;
use crate::material::{Material, MaterialModel};
use crate::memory::MeshSize;
use crate::mesh::{TetMesh, validate};
#[cfg(feature = "files")]
use crate::mesh::{read_gmsh, read_tetgen};
use crate::model::ElementOrder;
use crate::sim::{FemParams, LinearSolverChoice, TimeIntegrator};

mod obj;

/// The material of a body.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialSpec {
    /// The energy density; default `"stable-neo-hookean"` (defined under inversion).
    #[serde(default = "default_model")]
    pub model: MaterialModel,
    /// Young's modulus (Pa), positive.
    pub young: f64,
    /// Poisson's ratio, in `(-1, 0.5)`.
    pub poisson: f64,
    /// Density (kg/m³), positive.
    pub density: f64,
}

fn default_model() -> MaterialModel {
    MaterialModel::StableNeoHookean
}

/// The pinned vertices of a body, spelled as in every kind: `vertices` (indices of the mesh
/// file's vertices) and a `box` (the vertices inside or on it, after the placement).
pub use anim_core::scene::{PinBox, PinError, PinSpec};

/// A body from a mesh file. Every field but `mesh` and `material` has a default; `cell` is
/// required for an OBJ surface and refused for a tetrahedral mesh.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BodySpec {
    /// The mesh file (in a scene file: relative to the scene file's folder): a Gmsh `.msh`
    /// (versions 2.2 and 4.1, ASCII; its 4-node tetrahedra), a TetGen `.node` or `.ele` (the
    /// pair is read), or a closed, consistently oriented triangle surface `.obj` (polygons are
    /// split into triangles) whose inside is filled with tetrahedra of edge about `cell`.
    pub mesh: PathBuf,
    /// The material.
    pub material: MaterialSpec,
    /// Uniform scale of the mesh about its origin, positive; default 1.
    #[serde(default = "unit_scale", skip_serializing_if = "is_unit_scale")]
    pub scale: f64,
    /// Rotation about the mesh's origin as roll, pitch, yaw (rad): `Rz(yaw) Ry(pitch) Rx(roll)`,
    /// applied after the scale; default none.
    #[serde(default, skip_serializing_if = "is_default")]
    pub rotate: [f64; 3],
    /// Translation (m), applied last; default none.
    #[serde(default, skip_serializing_if = "is_default")]
    pub translate: [f64; 3],
    /// Initial velocity of every vertex of the body but the pinned ones, which start at rest
    /// (m/s); default at rest.
    #[serde(default, skip_serializing_if = "is_default")]
    pub velocity: [f64; 3],
    /// The vertices of this body held fixed: `vertices`, indices of the mesh file's vertices
    /// (0-based in file order; not for an OBJ surface, whose tetrahedra's vertices are made by the
    /// fill), and those inside or on `box` after the placement (with 10-node elements, edge nodes
    /// too; the box must hold one); either or both. Default none.
    #[serde(default, deserialize_with = "pin_spec", skip_serializing_if = "Option::is_none")]
    pub pin: Option<PinSpec>,
    /// For an `.obj` surface (required there, refused for a tetrahedral mesh): the target edge
    /// length of its tetrahedra (m) in the placed body, after `scale` (the surface is filled in
    /// its own coordinates with `cell / scale`, then placed), positive.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cell: Option<f64>,
}

/// A [`PinSpec`], with the box alone (`pin = { min, max }`, fem's spelling before every kind
/// shared one) refused naming the spelling to use.
fn pin_spec<'de, D: Deserializer<'de>>(d: D) -> Result<Option<PinSpec>, D::Error> {
    use serde::de::Error;
    let value = serde_json::Value::deserialize(d)?;
    if ["min", "max"].iter().any(|k| value.get(k).is_some()) {
        return Err(D::Error::custom(
            "unknown field `min`/`max`: a pin box is written `pin = { box = { min = [...], max = [...] } }`, \
             beside or instead of `vertices = [...]`",
        ));
    }
    PinSpec::deserialize(value).map(Some).map_err(D::Error::custom)
}

/// Why a body could not be built: the field at fault and the cause.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{message}")]
pub struct BodyError {
    /// The field: of a [`BodySpec`] (`mesh`, `material`, `scale`, `pin`, ...) from
    /// [`BodySpec::load`]; of the `[scene]` table (`bodies[1].mesh`, `obstacles[0]`,
    /// `gravity`, ...) from [`crate::bodies::build`].
    pub field: String,
    /// What is wrong; for the mesh, the file and line or element.
    pub message: String,
    /// For a body that takes its scene past the memory available: the scene's estimate and the
    /// memory it was checked against (bytes; anim-core's [`MemoryNeed`](anim_core::scene::MemoryNeed)).
    pub memory: Option<(f64, f64)>,
}

impl BodyError {
    pub(crate) fn new(field: impl Into<String>, message: impl std::fmt::Display) -> Self {
        BodyError { field: field.into(), message: message.to_string(), memory: None }
    }

    /// The same error with its field inside `prefix` (`bodies[2]` makes `mesh`
    /// `bodies[2].mesh`).
    #[must_use]
    pub fn within(self, prefix: &str) -> Self {
        BodyError { field: format!("{prefix}.{}", self.field), ..self }
    }

    /// The same error as anim-core's [`BuildError`]: [`BuildError::Memory`] for a refusal of
    /// memory, [`BuildError::Invalid`] otherwise.
    #[must_use]
    pub fn into_build_error(self) -> BuildError {
        match self.memory {
            Some((bytes, available)) => {
                BuildError::Memory { field: self.field, message: self.message, bytes, available }
            }
            None => BuildError::invalid(self.field, self.message),
        }
    }
}

/// The memory a body may still take in its scene.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Budget {
    /// The memory the scene is checked against (bytes; `None`: unknown, anim-core's bound).
    pub(crate) available: Option<f64>,
    /// The meshes of the bodies before this one.
    pub(crate) used: MeshSize,
    /// The scene's elements.
    pub(crate) order: ElementOrder,
    /// The scene's time integrator.
    pub(crate) integrator: TimeIntegrator,
    /// The scene's linear solver.
    pub(crate) solver: LinearSolverChoice,
}

impl Budget {
    /// The budget of a scene of `order` elements stepped by `integrator` and `solver`: nothing
    /// used, the memory available now.
    pub(crate) fn new(order: ElementOrder, integrator: TimeIntegrator, solver: LinearSolverChoice) -> Self {
        Self { available: available_memory(), used: MeshSize::mesh(0.0, 0.0), order, integrator, solver }
    }

    /// Refuses a body of mesh `added` (`what` describes it) whose scene, with the bodies before
    /// it, would need more memory than the budget ([`MeshSize::need`]); `advice` says what to
    /// change.
    pub(crate) fn check(
        &self,
        field: &str,
        what: &str,
        added: MeshSize,
        advice: &str,
    ) -> Result<(), BodyError> {
        let before = if self.used.elements > 0.0 {
            format!(", with the {} tetrahedra of the bodies before,", self.used.elements)
        } else {
            String::new()
        };
        let need = self.used.and(added).need(self.order, self.integrator, self.solver);
        need.check_within(field, &format!("{what}{before}"), self.available).map_err(|e| match e {
            BuildError::Memory { message, bytes, available, .. } => BodyError {
                field: field.to_string(),
                message: format!("{message}: {advice}"),
                memory: Some((bytes, available)),
            },
            other => BodyError::new(field, other),
        })
    }
}

/// A body read, placed and checked: its tetrahedra in world coordinates and its material.
#[derive(Debug, Clone)]
pub struct LoadedBody {
    /// The placed mesh, its elements checked (none degenerate or inverted).
    pub mesh: TetMesh,
    /// The material.
    pub material: Material,
    /// The vertices of [`PinSpec::vertices`], checked in range and in an element (the box is
    /// applied to the merged model's nodes, see [`crate::bodies`]).
    pub pinned: Vec<usize>,
}

/// Reads a tetrahedral mesh by its extension: `.msh` (Gmsh), `.node` or `.ele` (TetGen).
///
/// # Errors
/// [`FemError::MeshInput`] naming the file for an unknown extension or a file that does not
/// read; the validation errors of [`crate::mesh::validate`] naming the element.
#[cfg(feature = "files")]
pub fn read_mesh(path: &Path) -> Result<TetMesh, FemError> {
    match path.extension().and_then(|e| e.to_str()) {
        Some("msh") => read_gmsh(path),
        Some("node" | "ele") => read_tetgen(path),
        _ => Err(FemError::MeshInput(format!(
            "{}: unknown mesh format (a Gmsh .msh, a TetGen .node/.ele or an OBJ surface .obj)",
            path.display()
        ))),
    }
}

/// Refuses every mesh file: this build has no `files` feature.
///
/// # Errors
/// Always [`FemError::MeshInput`], naming the file and the feature.
#[cfg(not(feature = "files"))]
pub fn read_mesh(path: &Path) -> Result<TetMesh, FemError> {
    Err(FemError::MeshInput(crate::mesh::needs_files(path)))
}

/// Whether `path` names an OBJ surface (by its extension).
fn is_obj(path: &Path) -> bool {
    path.extension().and_then(|e| e.to_str()) == Some("obj")
}

impl BodySpec {
    /// The placement of the mesh: [`scale`](Self::scale), [`rotate`](Self::rotate),
    /// [`translate`](Self::translate).
    #[must_use]
    pub fn placement(&self) -> Placement {
        Placement { scale: self.scale, rotate: self.rotate, translate: self.translate }
    }

    /// Reads the body's mesh from `mesh` (the caller resolves [`mesh`](Self::mesh) against its
    /// folder; for an OBJ surface, fills it with tetrahedra of edge about
    /// [`cell`](Self::cell)), places it and checks it, with the body's material.
    ///
    /// # Errors
    /// [`BodyError`] naming the field of the spec: a mesh that does not read, an OBJ surface
    /// that is not closed (the message names the file and the triangle or edge), a degenerate or
    /// inverted element after the placement (the file and the element), `cell` missing for an
    /// OBJ or given for a tetrahedral mesh or not positive, a bad material or placement, a
    /// non-finite velocity; a `pin` with neither `vertices` nor `box`, a box that is not finite
    /// with `min <= max`, `vertices` on an OBJ surface or out of range or in no element; a body
    /// whose scene of linear elements (backward Euler, Cholesky) would need more memory than
    /// is available ([`crate::memory`], with [`BodyError::memory`]): `cell` for an OBJ surface
    /// whose lattice could hold that many (refused before it is filled), `mesh` for a mesh file.
    pub fn load(&self, mesh: &Path) -> Result<LoadedBody, BodyError> {
        let p = FemParams::default();
        self.load_within(mesh, &Budget::new(ElementOrder::Linear, p.integrator, p.linear_solver))
    }

    /// As [`load`](Self::load), within the memory `budget` leaves.
    pub(crate) fn load_within(&self, mesh: &Path, budget: &Budget) -> Result<LoadedBody, BodyError> {
        let placement = self.placement();
        placement.check().map_err(|e| match e {
            BuildError::Invalid { field, message } => BodyError::new(field, message),
            other => BodyError::new("scale", other),
        })?;
        let m = &self.material;
        let material = Material::new(m.model, m.young, m.poisson, m.density)
            .map_err(|e| BodyError::new("material", e))?;
        finite3("velocity", self.velocity)?;
        if let Some(pin) = &self.pin {
            pin.check().map_err(|e| pin_error("pin", &e))?;
        }
        let (mut tets, source) = if is_obj(mesh) {
            let Some(cell) = self.cell else {
                return Err(BodyError::new(
                    "cell",
                    format!(
                        "{} is a surface: give `cell`, the edge length (m) of the tetrahedra that fill it as placed",
                        mesh.display()
                    ),
                ));
            };
            if !(cell > 0.0 && cell.is_finite()) {
                return Err(BodyError::new("cell", format!("must be positive and finite, got {cell}")));
            }
            if self.pin.as_ref().is_some_and(|p| !p.vertices.is_empty()) {
                return Err(BodyError::new(
                    "pin",
                    format!(
                        "`vertices` name vertices of a mesh file, but the tetrahedra filling {} have vertices of \
                         their own: pin them with a `box`",
                        mesh.display()
                    ),
                ));
            }
            let tets = obj::fill(mesh, cell, self.scale, budget)?;
            (tets, format!("{} (filled with tetrahedra of cell {cell} m)", mesh.display()))
        } else {
            if self.cell.is_some() {
                return Err(BodyError::new(
                    "cell",
                    format!(
                        "`cell` is for OBJ surfaces; {} is a tetrahedral mesh (leave `cell` out)",
                        mesh.display()
                    ),
                ));
            }
            let tets = read_mesh(mesh).map_err(|e| BodyError::new("mesh", mesh_message(mesh, &e)))?;
            let size = MeshSize::mesh(tets.positions.len() as f64, tets.tets.len() as f64);
            let what = format!("{} ({} tetrahedra)", mesh.display(), tets.tets.len());
            budget.check("mesh", &what, size, "take a coarser mesh")?;
            (tets, mesh.display().to_string())
        };
        let pinned = match &self.pin {
            Some(pin) => pinned_vertices(pin, &tets, &mesh.display().to_string())?,
            None => Vec::new(),
        };
        placement.apply_all(&mut tets.positions);
        validate(&tets.positions, &tets.tets)
            .map_err(|e| BodyError::new("mesh", format!("{source}: {e}")))?;
        Ok(LoadedBody { mesh: tets, material, pinned })
    }
}

/// A refusal of the `pin` table `field`, as a [`BodyError`] of the field at fault
/// ([`PinError::field_under`]: `field`, or its part `vertices[k]`, `box`).
pub(crate) fn pin_error(field: impl Into<String>, e: &PinError) -> BodyError {
    BodyError::new(e.field_under(&field.into()), e)
}

/// The listed vertices of `pin` of the mesh read from `file`, checked in range and in an element.
fn pinned_vertices(pin: &PinSpec, mesh: &TetMesh, file: &str) -> Result<Vec<usize>, BodyError> {
    let pinned = pin.listed(mesh.positions.len(), file).map_err(|e| pin_error("pin", &e))?;
    if pinned.is_empty() {
        return Ok(pinned);
    }
    let mut used = vec![false; mesh.positions.len()];
    for &v in mesh.tets.iter().flatten() {
        used[v] = true;
    }
    if let Some(i) = pinned.iter().find(|&&i| !used[i]) {
        return Err(BodyError::new("pin", format!("vertex {i} of {file} belongs to no tetrahedron")));
    }
    Ok(pinned)
}

/// A mesh error with the file named once.
fn mesh_message(path: &Path, e: &FemError) -> String {
    let text = e.to_string();
    let file = path.display().to_string();
    if text.contains(&file) { text } else { format!("{file}: {text}") }
}

pub(crate) fn finite3(field: &str, v: [f64; 3]) -> Result<[f64; 3], BodyError> {
    if v.iter().all(|x| x.is_finite()) {
        Ok(v)
    } else {
        Err(BodyError::new(field, format!("{v:?} holds a non-finite value")))
    }
}

#[cfg(test)]
#[cfg(feature = "files")]
pub(crate) mod tests;
