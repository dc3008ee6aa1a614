//! Several bodies of the user's own in one scene: each [`BodySpec`] is loaded, placed and
//! checked, then the bodies are merged into one [`FemModel`] (the vertices of body `k` after
//! those of bodies `0..k`, its elements of its own material) that shares the [`World`]: gravity,
//! the obstacles (shapes, and closed OBJ surfaces sampled on a distance field) with their
//! penalty stiffness and friction, and Rayleigh damping.
//!
//! Bodies do not collide with each other (contact is vertex against obstacle only): where two
//! bodies meet, they pass through each other.
//!
//! ```
//! # #[cfg(feature = "files")]
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! use anim_fem::bodies::{self, World};
//! use anim_fem::body::BodySpec;
//! use anim_fem::boundary::Obstacle;
//! use anim_fem::model::ElementOrder;
//!
//! let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../anim-io/testdata");
//! let body = |young: f64, x: f64| -> BodySpec {
//!     serde_json::from_value(serde_json::json!({
//!         "mesh": "cube_v41.msh",
//!         "material": { "young": young, "poisson": 0.3, "density": 1000.0 },
//!         "translate": [x, 0.0, 0.5],
//!     }))
//!     .expect("a body")
//! };
//! let world = World { obstacles: vec![Obstacle::ground(0.0)], ..World::default() };
//! let scene = bodies::build(&[body(1e5, 0.0), body(1e6, 2.0)], &world, ElementOrder::Linear, |p| dir.join(p))?;
//! assert_eq!(scene.model.materials().len(), 2);
//! # Ok(())
//! # }
//! # #[cfg(not(feature = "files"))]
//! # fn main() {}
//! ```

use std::path::{Path, PathBuf};

use crate::body::{BodyError, BodySpec, Budget, finite3, pin_error};
use crate::boundary::Obstacle;
use crate::memory::MeshSize;
use crate::mesh::TetMesh;
use crate::model::{EARTH_GRAVITY, ElementOrder, FemModel};
use crate::scenes::FemScene;
use crate::sim::{FemParams, LinearSolverChoice, TimeIntegrator};
use anim_core::integrate::State;
use anim_core::scene::ObstacleMesh;
use anim_core::surface::DistanceField;
#[cfg(feature = "files")]
use anim_io::surface::read_closed_surface;

/// What the bodies of a scene share.
#[derive(Debug, Clone, PartialEq)]
pub struct World {
    /// Gravity (m/s²); default `(0, 0, -9.81)`.
    pub gravity: [f64; 3],
    /// Obstacles every body collides with (planes, spheres, boxes, capsules); default none.
    pub obstacles: Vec<Obstacle>,
    /// Closed OBJ surfaces every body collides with, each placed and sampled on a distance
    /// field of spacing `cell` (see [`ObstacleMesh`]), paths resolved as the bodies' meshes
    /// are; default none.
    pub obstacle_meshes: Vec<ObstacleMesh>,
    /// Penalty stiffness of the obstacles (N/m) in backward Euler steps, positive; default
    /// `1e7`. Symplectic Euler projects vertices out of the obstacles instead.
    pub contact_stiffness: f64,
    /// Coulomb friction coefficient against the obstacles, `>= 0`; default 0 (frictionless).
    pub friction: f64,
    /// Rayleigh stiffness damping `gamma` (s), `>= 0`; default 0.
    pub rayleigh: f64,
}

/// The default penalty stiffness of the obstacles (N/m).
pub const DEFAULT_CONTACT_STIFFNESS: f64 = 1e7;

impl Default for World {
    fn default() -> Self {
        World {
            gravity: EARTH_GRAVITY,
            obstacles: Vec::new(),
            obstacle_meshes: Vec::new(),
            contact_stiffness: DEFAULT_CONTACT_STIFFNESS,
            friction: 0.0,
            rayleigh: 0.0,
        }
    }
}

impl World {
    /// Checks the scalars and the gravity, naming the field.
    fn check(&self) -> Result<(), BodyError> {
        finite3("gravity", self.gravity)?;
        let positive = |x: f64| x > 0.0 && x.is_finite();
        let non_negative = |x: f64| x >= 0.0 && x.is_finite();
        if !positive(self.contact_stiffness) {
            return Err(BodyError::new(
                "contact_stiffness",
                format!("must be positive and finite, got {}", self.contact_stiffness),
            ));
        }
        if !non_negative(self.friction) {
            return Err(BodyError::new(
                "friction",
                format!("must be finite and >= 0, got {}", self.friction),
            ));
        }
        if !non_negative(self.rayleigh) {
            return Err(BodyError::new(
                "rayleigh",
                format!("must be finite and >= 0, got {}", self.rayleigh),
            ));
        }
        Ok(())
    }
}

/// The scene of `bodies` in `world` with `order` elements; `resolve` turns each body's
/// [`mesh`](BodySpec::mesh) into the file to read (a scene file resolves it against its
/// folder).
///
/// # Errors
/// [`BodyError`] naming the field of the `[scene]` table: `bodies` for an empty list;
/// `bodies[k].mesh`, `bodies[k].cell`, `bodies[k].material`, ... for the errors of
/// [`BodySpec::load`], and `bodies[k].cell` (an OBJ surface, refused before it is filled) or
/// `bodies[k].mesh` (a mesh file) for the body that takes the scene past the memory available
/// (the scene's estimate, [`crate::memory`], with [`BodyError::memory`]; backward Euler with
/// Cholesky, the scene's method); `bodies[k].pin` for a pin box that holds no vertex of body `k`
/// (and the pin errors of [`BodySpec::load`]);
/// `gravity`, `contact_stiffness`, `friction`, `rayleigh` for a value out of range;
/// `obstacles[i]` for an invalid shape; `obstacle_meshes[k].mesh` for a file that does not read
/// or a surface that is not closed, manifold and consistently oriented (the file and the
/// triangle, edge or vertex), `obstacle_meshes[k].cell` for a spacing that is not positive and
/// finite or too fine, `obstacle_meshes[k].scale` (`.rotate`, `.translate`) for a bad placement.
pub fn build(
    bodies: &[BodySpec],
    world: &World,
    order: ElementOrder,
    resolve: impl Fn(&Path) -> PathBuf,
) -> Result<FemScene, BodyError> {
    let p = FemParams::default();
    build_with(bodies, world, order, (p.integrator, p.linear_solver), resolve)
}

/// As [`build`], the scene stepped by `method` (its time integrator and linear solver), whose
/// memory the bodies are checked against.
///
/// # Errors
/// As [`build`].
pub fn build_with(
    bodies: &[BodySpec],
    world: &World,
    order: ElementOrder,
    method: (TimeIntegrator, LinearSolverChoice),
    resolve: impl Fn(&Path) -> PathBuf,
) -> Result<FemScene, BodyError> {
    let mut scene = build_within(bodies, world, resolve, Budget::new(order, method.0, method.1))?;
    scene.params.integrator = method.0;
    scene.params.linear_solver = method.1;
    Ok(scene)
}

/// As [`build`], within the memory of `budget` (its order and method the scene's).
fn build_within(
    bodies: &[BodySpec],
    world: &World,
    resolve: impl Fn(&Path) -> PathBuf,
    budget: Budget,
) -> Result<FemScene, BodyError> {
    let order = budget.order;
    if bodies.is_empty() {
        return Err(BodyError::new("bodies", "give at least one body (a `[[scene.bodies]]` table)"));
    }
    world.check()?;
    let mut positions = Vec::new();
    let mut tets = Vec::new();
    let mut materials = Vec::with_capacity(bodies.len());
    let mut element_material = Vec::new();
    // The first corner vertex of each body, and one past the last.
    let mut starts = vec![0];
    // The vertices each body's `pin` lists, numbered in the merged mesh.
    let mut listed = Vec::with_capacity(bodies.len());
    for (k, body) in bodies.iter().enumerate() {
        let used = MeshSize::mesh(positions.len() as f64, tets.len() as f64);
        let loaded = body
            .load_within(&resolve(&body.mesh), &Budget { used, ..budget })
            .map_err(|e| e.within(&format!("bodies[{k}]")))?;
        let offset = positions.len();
        let id = u32::try_from(k).map_err(|_| BodyError::new("bodies", "too many bodies"))?;
        element_material.extend(std::iter::repeat_n(id, loaded.mesh.tets.len()));
        tets.extend(loaded.mesh.tets.iter().map(|t| t.map(|v| v + offset)));
        positions.extend(loaded.mesh.positions);
        materials.push(loaded.material);
        listed.push(loaded.pinned.iter().map(|v| v + offset).collect::<Vec<_>>());
        starts.push(positions.len());
    }
    let mesh = TetMesh { positions, tets };
    let mut model = FemModel::with_materials(mesh, materials, element_material, order)
        .map_err(|e| BodyError::new("bodies", e))?
        .with_gravity(world.gravity);
    let owner = node_bodies(&model, &starts);
    for (k, (body, listed)) in bodies.iter().zip(&listed).enumerate() {
        let field = || format!("bodies[{k}].pin");
        model.pin_vertices(listed).map_err(|e| BodyError::new(field(), e))?;
        if let Some(region) = body.pin.as_ref().and_then(|p| p.region) {
            let of = format!("body {k} ({})", body.mesh.display());
            let inside = region
                .select(&model.mesh().positions, &of, |i| owner[i] == k)
                .map_err(|e| pin_error(field(), &e))?;
            model.pin_vertices(&inside).map_err(|e| BodyError::new(field(), e))?;
        }
    }
    for (i, obstacle) in world.obstacles.iter().enumerate() {
        model
            .add_obstacle_with_friction(*obstacle, world.contact_stiffness, world.friction)
            .map_err(|e| BodyError::new(format!("obstacles[{i}]"), e))?;
    }
    for (k, m) in world.obstacle_meshes.iter().enumerate() {
        let field =
            mesh_field(m, &resolve(&m.mesh)).map_err(|e| e.within(&format!("obstacle_meshes[{k}]")))?;
        model
            .add_mesh_obstacle(field, world.contact_stiffness, world.friction)
            .map_err(|e| BodyError::new(format!("obstacle_meshes[{k}]"), e))?;
    }
    let x = model.rest_positions();
    // Pinned vertices start at rest, whatever their body's velocity.
    let fixed = model.fixed();
    let v = owner
        .iter()
        .flat_map(|&k| bodies[k].velocity)
        .zip(fixed)
        .map(|(v, &pinned)| if pinned { 0.0 } else { v })
        .collect();
    let params = FemParams::default().with_rayleigh(world.rayleigh);
    Ok(FemScene {
        name: "bodies",
        description: "bodies from mesh files",
        model,
        state: State { t: 0.0, x, v },
        dt: 1.0 / 120.0,
        duration: 1.0,
        params,
    })
}

/// The distance field of a mesh obstacle read from `path`: placed, checked closed
/// ([`read_closed_surface`]), sampled at its `cell`. Errors name the field of the table (`mesh`,
/// `cell`, `scale`, ...).
#[cfg(feature = "files")]
fn mesh_field(m: &ObstacleMesh, path: &Path) -> Result<DistanceField, BodyError> {
    let surface = read_closed_surface(path, &m.placement()).map_err(|e| BodyError::new(e.field(), &e))?;
    // Contact needs the field where `phi < 0` only: no margin beyond the two cells `field` adds.
    m.field(&surface, 0.0).map_err(|e| BodyError::new("cell", format!("{}: {e}", path.display())))
}

/// Refuses the obstacle's surface: this build has no `files` feature to read it.
#[cfg(not(feature = "files"))]
fn mesh_field(_m: &ObstacleMesh, path: &Path) -> Result<DistanceField, BodyError> {
    Err(BodyError::new("mesh", crate::mesh::needs_files(path)))
}

/// The body of every node of `model`: a corner vertex by the range of its body (`starts[k]..
/// starts[k + 1]`), an edge node of a 10-node body by an element that holds it.
fn node_bodies(model: &FemModel, starts: &[usize]) -> Vec<usize> {
    let corners = starts.last().copied().unwrap_or(0);
    let mut owner = vec![0; model.vertices()];
    for k in 0..starts.len() - 1 {
        owner[starts[k]..starts[k + 1]].fill(k);
    }
    if let Some(elements) = model.quadratic_elements() {
        for (el, &m) in elements.iter().zip(model.element_material()) {
            for &node in &el[4..] {
                if node >= corners {
                    owner[node] = m as usize;
                }
            }
        }
    }
    owner
}

#[cfg(test)]
#[cfg(feature = "files")]
mod tests;
