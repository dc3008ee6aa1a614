//! Bodies of the user's own: cloth and shells from Wavefront OBJ triangle surfaces, each with its
//! material, placement, initial velocity and pins, among scene-wide obstacles. [`BodySpec`] is
//! one `[[scene.bodies]]` table of a `springs` scene file, [`ContactSpec`] its `contact` table
//! (see [`crate::kind`]); [`build_bodies`] makes the scene.
//!
//! A body is [`NetworkBuilder::mesh`] on the placed surface: a structural spring on every edge,
//! at the placed edge's length, optionally a bending spring across every interior edge (between
//! the two vertices opposite it), and the vertex masses lumped from the area density (each
//! vertex gets a third of the area of its triangles). Bodies do not touch each other: each meets
//! only the obstacles, through the crate's penalty contact ([`crate::contact`]).
//!
//! ```
//! use anim_springs::body::{BodySpec, ContactSpec, build_bodies};
//!
//! let dir = std::env::temp_dir().join(format!("anim-springs-body-doc-{}", std::process::id()));
//! std::fs::create_dir_all(&dir)?;
//! std::fs::write(dir.join("square.obj"), "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n")?;
//! let body: BodySpec = serde_json::from_value(serde_json::json!({
//!     "mesh": "square.obj",
//!     "material": { "density": 0.2, "stiffness": 100.0 },
//!     "translate": [0.0, 0.0, 1.0],
//!     "pin": { "vertices": [0, 1] },
//! }))?;
//! let scene = build_bodies(&[body], &[], [0.0, 0.0, -9.81], &ContactSpec::default(), |p| dir.join(p))?;
//! // 1 m^2 at 0.2 kg/m^2; five edges (the square's four and the diagonal of its two triangles).
//! assert!((scene.network.total_mass() - 0.2).abs() < 1e-15);
//! assert_eq!(scene.network.num_springs(), 5);
//! assert!(scene.state.x.chunks_exact(3).all(|p| p[2] == 1.0));
//! std::fs::remove_dir_all(&dir)?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use anim_core::scene::{is_unit_scale, unit_scale};
use std::path::{Path, PathBuf};

use anim_core::integrate::IntegratorKind;
use anim_core::linalg::LinearSolverKind;
use anim_core::scene::{BuildError as SceneError, Placement, is_default};
use anim_io::obj::{Polygons, read_obj};
use serde::{Deserialize, Serialize};

use crate::build::{MeshMass, MeshSprings, NetworkBuilder, SpringParams};
use crate::contact::{Collider, Shape};
use crate::error::{BuildError, InputError};
use crate::scenes::{SpringScene, animation_newton};

/// The material of a body: its area density and its springs.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialSpec {
    /// Area density (kg/m², > 0): each vertex gets a third of the area of its triangles (lumped
    /// mass), so the body weighs `density` times its placed surface area.
    pub density: f64,
    /// Stiffness of each edge spring (N/m, > 0), per spring. On a regular mesh the sheet's
    /// stretching stiffness (tension per unit width per unit strain, N/m) is of the order of
    /// this value whatever the resolution: halving the edges doubles the springs across a
    /// given width and halves their extension.
    pub stiffness: f64,
    /// Damping along each edge spring (N·s/m, >= 0); default 0.
    #[serde(default, skip_serializing_if = "is_default")]
    pub damping: f64,
    /// Stiffness of a bending spring across every interior edge, between the two vertices
    /// opposite it (N/m, > 0), per spring; absent: no bending springs (the surface folds
    /// freely). Needs a manifold surface (no edge shared by more than two triangles).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bending: Option<f64>,
    /// Damping along each bending spring (N·s/m, >= 0); default 0. Only with `bending`.
    #[serde(default, skip_serializing_if = "is_default")]
    pub bending_damping: f64,
}

pub use anim_core::scene::{PinBox, PinError, PinSpec};

/// A cloth or shell from an OBJ triangle surface. Every field but `mesh` and `material` has a
/// default.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BodySpec {
    /// The OBJ file (in a scene file: relative to the scene file's folder). Its faces are the
    /// triangles (larger polygons are split into fans); every vertex must belong to a triangle;
    /// `l` line elements are refused.
    pub mesh: PathBuf,
    /// The material.
    pub material: MaterialSpec,
    /// Uniform scale of the mesh about its origin, > 0; default 1.
    #[serde(default = "unit_scale", skip_serializing_if = "is_unit_scale")]
    pub scale: f64,
    /// Roll, pitch, yaw (rad): the rotation `Rz(yaw) Ry(pitch) Rx(roll)` about the mesh's
    /// origin, applied after the scale; default none.
    #[serde(default, skip_serializing_if = "is_default")]
    pub rotate: [f64; 3],
    /// Translation (m), applied last; default none.
    #[serde(default, skip_serializing_if = "is_default")]
    pub translate: [f64; 3],
    /// Initial velocity of every free vertex (m/s); default at rest.
    #[serde(default, skip_serializing_if = "is_default")]
    pub velocity: [f64; 3],
    /// The vertices held fixed; default none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pin: Option<PinSpec>,
}

impl BodySpec {
    /// The placement of the mesh.
    #[must_use]
    pub fn placement(&self) -> Placement {
        Placement { scale: self.scale, rotate: self.rotate, translate: self.translate }
    }
}

/// The penalty contact of every body against every obstacle: the fields of a [`Collider`]
/// (see [`crate::contact`] for the force).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactSpec {
    /// Penalty stiffness `k_c` (N/m, > 0); default `1e4`. A vertex of mass `m` rests
    /// `m g / k_c + smoothing / 2` deeper than `thickness` (`sqrt(2 smoothing m g / k_c)` when
    /// that is less than `smoothing`).
    #[serde(default = "default_stiffness")]
    pub stiffness: f64,
    /// Normal damping `tau_n` (s/m, >= 0): the damping force is `tau_n |v_n|` times the elastic
    /// one; default `0.1`.
    #[serde(default = "default_damping")]
    pub damping: f64,
    /// Viscous friction `tau_t` (s/m, >= 0): the friction force is `tau_t |v_t|` times the
    /// elastic normal one (a Coulomb coefficient growing with the slip speed); default `1`.
    #[serde(default = "default_friction")]
    pub friction: f64,
    /// Width (m, >= 0) over which the penalty stiffness ramps up from 0 to `stiffness`, for
    /// robust implicit steps; default `1e-3`.
    #[serde(default = "default_smoothing")]
    pub smoothing: f64,
    /// Distance (m, >= 0) outside the obstacles at which the vertices are held: the cloth's
    /// thickness. Over a curved obstacle it keeps the triangles clear of the surface between
    /// their vertices; default 0.
    #[serde(default, skip_serializing_if = "is_default")]
    pub thickness: f64,
}

fn default_stiffness() -> f64 {
    1e4
}

fn default_damping() -> f64 {
    0.1
}

fn default_friction() -> f64 {
    1.0
}

fn default_smoothing() -> f64 {
    1e-3
}

impl Default for ContactSpec {
    fn default() -> Self {
        Self {
            stiffness: default_stiffness(),
            damping: default_damping(),
            friction: default_friction(),
            smoothing: default_smoothing(),
            thickness: 0.0,
        }
    }
}

/// Builds the scene of `bodies` among `obstacles` under `gravity`: every body read from
/// `resolve(&body.mesh)`, placed, checked and added to one network, stepped by backward Euler
/// (one Newton iteration, [`animation_newton`]) with sparse Cholesky unless the caller changes
/// them. Suggested step 5 ms.
///
/// # Errors
/// A scene-file [`BuildError`](SceneError) naming the field, `bodies[k].mesh` (the file that
/// does not read, or the triangle or vertex at fault, with the file's name),
/// `bodies[k].material.stiffness`, `bodies[k].pin`, `obstacles[k]`, `gravity`,
/// `contact.stiffness`, ...
pub fn build_bodies(
    bodies: &[BodySpec],
    obstacles: &[Shape],
    gravity: [f64; 3],
    contact: &ContactSpec,
    resolve: impl Fn(&Path) -> PathBuf,
) -> Result<SpringScene, SceneError> {
    if bodies.is_empty() {
        return Err(SceneError::invalid("bodies", "give at least one body"));
    }
    let mut b = NetworkBuilder::new();
    let mut velocities: Vec<[f64; 3]> = Vec::new();
    let mut pinned: Vec<usize> = Vec::new();
    for (k, body) in bodies.iter().enumerate() {
        let first = b.num_particles();
        let pins = add_body(&mut b, body, &resolve(&body.mesh), &format!("bodies[{k}]"))?;
        let count = b.num_particles() - first;
        velocities.resize(velocities.len() + count, body.velocity);
        pinned.extend(pins.into_iter().map(|i| first + i));
    }
    if !gravity.iter().all(|g| g.is_finite()) {
        return Err(SceneError::invalid("gravity", format!("{gravity:?} holds a non-finite value")));
    }
    b.gravity(gravity);
    check_contact(contact)?;
    for (k, &shape) in obstacles.iter().enumerate() {
        let collider = Collider {
            shape,
            stiffness: contact.stiffness,
            damping: contact.damping,
            friction: contact.friction,
            smoothing: contact.smoothing,
            thickness: contact.thickness,
        };
        collider.check().map_err(|e| SceneError::invalid(format!("obstacles[{k}]"), e))?;
        b.collider(collider);
    }
    for &p in &pinned {
        b.pin(p);
        velocities[p] = [0.0; 3];
    }
    // Everything was checked above; what is left is the size of the whole.
    let network = b.build().map_err(|e| SceneError::invalid("bodies", e.to_string()))?;
    let mut state = network.rest_state();
    state.v = velocities.into_iter().flatten().collect();
    Ok(SpringScene {
        name: "bodies",
        description: "cloth and shells from OBJ surfaces among obstacles (backward Euler, sparse Cholesky)",
        network,
        state,
        dt: 0.005,
        duration: 2.0,
        integrator: IntegratorKind::BackwardEuler,
        linear_solver: LinearSolverKind::Cholesky,
        newton: animation_newton(),
    })
}

/// Reads, places, checks and adds one body; returns its pinned vertices (file indices).
fn add_body(
    b: &mut NetworkBuilder,
    body: &BodySpec,
    path: &Path,
    at: &str,
) -> Result<Vec<usize>, SceneError> {
    let field = |name: &str| format!("{at}.{name}");
    let file = path.display();
    let mut mesh = read_obj(path, Polygons::Triangulate)
        .map_err(|e| SceneError::invalid(field("mesh"), e.to_string()))?;
    if !mesh.lines.is_empty() {
        return Err(SceneError::invalid(
            field("mesh"),
            format!(
                "{file}: {} line segments (`l` elements): a springs body is made of triangles only",
                mesh.lines.len()
            ),
        ));
    }
    if mesh.triangles.is_empty() {
        return Err(SceneError::invalid(field("mesh"), format!("{file}: no faces (a body needs triangles)")));
    }
    let placement = body.placement();
    placement.check().map_err(|e| prefixed(at, e))?;
    placement.apply_all(&mut mesh.positions);
    if let Some((v, p)) = mesh.positions.iter().enumerate().find(|(_, p)| !p.iter().all(|c| c.is_finite())) {
        return Err(SceneError::invalid(
            field("scale"),
            format!(
                "{file}: vertex {v} is placed at {p:?}, which is not finite (scale or translation too large)"
            ),
        ));
    }
    let m = &body.material;
    positive(&field("material.density"), m.density)?;
    positive(&field("material.stiffness"), m.stiffness)?;
    non_negative(&field("material.damping"), m.damping)?;
    non_negative(&field("material.bending_damping"), m.bending_damping)?;
    match m.bending {
        Some(k) => positive(&field("material.bending"), k)?,
        None if m.bending_damping != 0.0 => {
            return Err(SceneError::invalid(
                field("material.bending_damping"),
                "there are no bending springs to damp: give `bending` too",
            ));
        }
        None => {}
    }
    if !body.velocity.iter().all(|c| c.is_finite()) {
        return Err(SceneError::invalid(
            field("velocity"),
            format!("{:?} holds a non-finite value", body.velocity),
        ));
    }
    let pins = match &body.pin {
        Some(pin) => pinned_vertices(pin, &mesh.positions, &field("pin"), &file.to_string())?,
        None => Vec::new(),
    };
    let springs = MeshSprings {
        mass: MeshMass::AreaDensity(m.density),
        edge: SpringParams::new(m.stiffness, m.damping),
        bending: m.bending.map(|k| SpringParams::new(k, m.bending_damping)),
    };
    b.mesh(&mesh.positions, &mesh.triangles, &springs).map_err(|e| {
        let message = match e {
            BuildError::Input(InputError::NonManifoldEdge { .. }) => {
                format!("{file}: {e} (or leave out `material.bending`)")
            }
            e => format!("{file}: {e}"),
        };
        SceneError::invalid(field("mesh"), message)
    })?;
    Ok(pins)
}

/// The vertices `pin` holds ([`PinSpec::resolve`]), its refusal on `field` or the part of the
/// table at fault ([`PinError::field_under`]: `pin.vertices[k]`, `pin.box`).
fn pinned_vertices(
    pin: &PinSpec,
    positions: &[[f64; 3]],
    field: &str,
    file: &str,
) -> Result<Vec<usize>, SceneError> {
    pin.resolve(positions, file).map_err(|e| SceneError::invalid(e.field_under(field), e.to_string()))
}

fn check_contact(c: &ContactSpec) -> Result<(), SceneError> {
    positive("contact.stiffness", c.stiffness)?;
    non_negative("contact.damping", c.damping)?;
    non_negative("contact.friction", c.friction)?;
    non_negative("contact.smoothing", c.smoothing)?;
    non_negative("contact.thickness", c.thickness)
}

/// A placement error with its field under the body's.
fn prefixed(at: &str, e: SceneError) -> SceneError {
    match e {
        SceneError::Invalid { field, message } => SceneError::invalid(format!("{at}.{field}"), message),
        other => SceneError::invalid(at, other.to_string()),
    }
}

fn positive(field: &str, v: f64) -> Result<(), SceneError> {
    if v > 0.0 && v.is_finite() {
        Ok(())
    } else {
        Err(SceneError::invalid(field, format!("must be positive and finite, got {v}")))
    }
}

fn non_negative(field: &str, v: f64) -> Result<(), SceneError> {
    if v >= 0.0 && v.is_finite() {
        Ok(())
    } else {
        Err(SceneError::invalid(field, format!("must be non-negative and finite, got {v}")))
    }
}

#[cfg(test)]
mod tests;
