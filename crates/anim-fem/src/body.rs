//! A body of the user's own: a tetrahedral mesh file (Gmsh 2.2 or 4.1 `.msh`, TetGen
//! `.node`/`.ele`) with its material, its placement (scale, rotation, translation), initial
//! velocity, pinned region, gravity and the obstacles around it. [`BodySpec`] is also the `body`
//! table of an `fem` scene file (see [`crate::kind`]).
//!
//! ```
//! use anim_fem::body::BodySpec;
//!
//! let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../anim-io/testdata");
//! let spec: BodySpec = serde_json::from_value(serde_json::json!({
//!     "mesh": "cube_v41.msh",
//!     "material": { "young": 5e4, "poisson": 0.3, "density": 1000.0 },
//!     "translate": [0.0, 0.0, 0.5],
//!     "obstacles": [ { "plane": { "point": [0.0, 0.0, 0.0], "normal": [0.0, 0.0, 1.0] } } ],
//! }))?;
//! let scene = spec.build(&dir.join(&spec.mesh), Default::default())?;
//! assert!(scene.model.mesh().positions.iter().all(|p| p[2] >= 0.5 - 1e-12));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! Units are SI: metres, kilograms, seconds, pascals. Scenes are z-up; gravity defaults to
//! `(0, 0, -9.81)`.

use std::path::{Path, PathBuf};

use anim_core::glam::{DMat3, DVec3, EulerRot};
use anim_core::scene::is_default;
use serde::{Deserialize, Serialize};

use crate::boundary::Obstacle;
use crate::error::FemError;
use crate::material::{Material, MaterialModel};
use crate::mesh::{TetMesh, read_gmsh, read_tetgen};
use crate::model::{EARTH_GRAVITY, ElementOrder, FemModel};
use crate::scenes::FemScene;
use crate::sim::FemParams;
use anim_core::integrate::State;

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

/// An axis-aligned box (world coordinates, after the body's placement): the vertices inside or
/// on it are pinned.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PinBox {
    /// The lower corner (m).
    pub min: [f64; 3],
    /// The upper corner (m).
    pub max: [f64; 3],
}

fn one() -> f64 {
    1.0
}

fn default_contact_stiffness() -> f64 {
    1e7
}

/// A body from a tetrahedral mesh file. Every field but `mesh` and `material` has a default.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BodySpec {
    /// The mesh file (in a scene file: relative to the scene file's folder): a Gmsh `.msh`
    /// (versions 2.2 and 4.1, ASCII; its 4-node tetrahedra) or a TetGen `.node` or `.ele` (the
    /// pair is read).
    pub mesh: PathBuf,
    /// The material.
    pub material: MaterialSpec,
    /// Uniform scale of the mesh about its origin, positive; default 1.
    #[serde(default = "one")]
    pub scale: f64,
    /// Rotation about the mesh's origin as roll, pitch, yaw (rad): `Rz(yaw) Ry(pitch) Rx(roll)`,
    /// applied after the scale; default none.
    #[serde(default, skip_serializing_if = "is_default")]
    pub rotate: [f64; 3],
    /// Translation (m), applied last; default none.
    #[serde(default, skip_serializing_if = "is_default")]
    pub translate: [f64; 3],
    /// Initial velocity of every vertex (m/s); default at rest.
    #[serde(default, skip_serializing_if = "is_default")]
    pub velocity: [f64; 3],
    /// The vertices held fixed: those in this box (after the placement); default none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pin: Option<PinBox>,
    /// Gravity (m/s²); default `(0, 0, -9.81)`.
    #[serde(default = "earth_gravity")]
    pub gravity: [f64; 3],
    /// Obstacles the body collides with: `plane` and `sphere` shapes (FEM contact takes no box or
    /// capsule); default none.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub obstacles: Vec<Obstacle>,
    /// Penalty stiffness of the obstacles (N/m), positive; default `1e7`.
    #[serde(default = "default_contact_stiffness")]
    pub contact_stiffness: f64,
    /// Coulomb friction coefficient against the obstacles, `>= 0`; default 0 (frictionless).
    #[serde(default, skip_serializing_if = "is_default")]
    pub friction: f64,
    /// Rayleigh stiffness damping `gamma` (s); default 0.
    #[serde(default, skip_serializing_if = "is_default")]
    pub rayleigh: f64,
}

fn earth_gravity() -> [f64; 3] {
    EARTH_GRAVITY
}

/// Why a body could not be built: the field of [`BodySpec`] at fault and the cause.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{message}")]
pub struct BodyError {
    /// The field (`mesh`, `material`, `scale`, `pin`, `obstacles[1]`, ...).
    pub field: String,
    /// What is wrong; for the mesh, the file and line or element.
    pub message: String,
}

impl BodyError {
    fn new(field: impl Into<String>, message: impl std::fmt::Display) -> Self {
        BodyError { field: field.into(), message: message.to_string() }
    }
}

/// Reads a tetrahedral mesh by its extension: `.msh` (Gmsh), `.node` or `.ele` (TetGen).
///
/// # Errors
/// [`FemError::MeshInput`] naming the file for an unknown extension or a file that does not
/// read; the validation errors of [`crate::mesh::validate`] naming the element.
pub fn read_mesh(path: &Path) -> Result<TetMesh, FemError> {
    match path.extension().and_then(|e| e.to_str()) {
        Some("msh") => read_gmsh(path),
        Some("node" | "ele") => read_tetgen(path),
        _ => Err(FemError::MeshInput(format!(
            "{}: unknown mesh format (a Gmsh .msh or a TetGen .node/.ele)",
            path.display()
        ))),
    }
}

impl BodySpec {
    /// The body of this spec, its mesh read from `mesh` (the caller resolves
    /// [`mesh`](Self::mesh) against its folder), as a scene with `order` elements.
    ///
    /// # Errors
    /// [`BodyError`] naming the field: a mesh that does not read or has a degenerate or
    /// inverted element (the message names the file or the element), a bad material, a scale
    /// that is not positive, non-finite values, a pin box that holds no vertex, an obstacle FEM
    /// contact does not take.
    pub fn build(&self, mesh: &Path, order: ElementOrder) -> Result<FemScene, BodyError> {
        let mut tets = read_mesh(mesh).map_err(|e| BodyError::new("mesh", mesh_message(mesh, &e)))?;
        self.place(&mut tets)?;
        let m = &self.material;
        let material = Material::new(m.model, m.young, m.poisson, m.density)
            .map_err(|e| BodyError::new("material", e))?;
        finite3("gravity", self.gravity)?;
        let mut model = FemModel::with_order(tets, material, order)
            .map_err(|e| BodyError::new("mesh", format!("{}: {e}", mesh.display())))?
            .with_gravity(self.gravity);
        if let Some(pin) = self.pin {
            finite3("pin", pin.min)?;
            finite3("pin", pin.max)?;
            let inside = |p: [f64; 3]| (0..3).all(|k| p[k] >= pin.min[k] && p[k] <= pin.max[k]);
            let pinned = model.vertices_where(inside);
            if pinned.is_empty() {
                return Err(BodyError::new("pin", "the pin box holds no vertex of the placed mesh"));
            }
            model.pin_vertices(&pinned).map_err(|e| BodyError::new("pin", e))?;
        }
        for (k, obstacle) in self.obstacles.iter().enumerate() {
            model
                .add_obstacle_with_friction(*obstacle, self.contact_stiffness, self.friction)
                .map_err(|e| BodyError::new(format!("obstacles[{k}]"), e))?;
        }
        finite3("velocity", self.velocity)?;
        let x = model.rest_positions();
        let v = self.velocity.iter().copied().cycle().take(x.len()).collect();
        let params = FemParams::default().with_rayleigh(self.rayleigh);
        Ok(FemScene {
            name: "body",
            description: "a body from a tetrahedral mesh file",
            model,
            state: State { t: 0.0, x, v },
            dt: 1.0 / 120.0,
            duration: 1.0,
            params,
        })
    }

    /// Scales, rotates and translates the mesh in place.
    fn place(&self, mesh: &mut TetMesh) -> Result<(), BodyError> {
        if !(self.scale > 0.0 && self.scale.is_finite()) {
            return Err(BodyError::new("scale", format!("must be positive and finite, got {}", self.scale)));
        }
        let [roll, pitch, yaw] = finite3("rotate", self.rotate)?;
        let t = DVec3::from_array(finite3("translate", self.translate)?);
        let r = DMat3::from_euler(EulerRot::ZYX, yaw, pitch, roll);
        for p in &mut mesh.positions {
            *p = (r * (self.scale * DVec3::from_array(*p)) + t).to_array();
        }
        Ok(())
    }
}

/// A mesh error with the file named once.
fn mesh_message(path: &Path, e: &FemError) -> String {
    let text = e.to_string();
    let file = path.display().to_string();
    if text.contains(&file) { text } else { format!("{file}: {text}") }
}

fn finite3(field: &str, v: [f64; 3]) -> Result<[f64; 3], BodyError> {
    if v.iter().all(|x| x.is_finite()) {
        Ok(v)
    } else {
        Err(BodyError::new(field, format!("{v:?} holds a non-finite value")))
    }
}

#[cfg(test)]
mod tests;
