//! Bodies of an `mpm` scene file: matter of the user's own, sampled with particles inside a box,
//! a sphere or a closed OBJ surface, each with its material and initial velocity, among plane,
//! box and sphere obstacles and, in 3D, fixed closed OBJ surfaces (`obstacle_meshes`, level-set
//! colliders of [`crate::mesh_collider`]) in the unit domain.
//!
//! A body fills its region with particles the way the built-in scenes fill theirs: a lattice
//! of `particles_per_cell` particles per grid cell and axis (spacing `s = h / particles_per_cell`),
//! laid from the lower corner of the body's bounding box, keeping the points inside the body;
//! each particle has the rest volume `s^D` and the mass `density s^D`. Body `k` is material `k`
//! of the simulation's table, so [`Particles::material`] tells the bodies apart.
//!
//! The domain is `[0, 1]^D` with walls [`MpmParams::wall_nodes`] cells thick on every side and
//! **y up** (gravity `(0, -9.81, 0)` unless the scene gives its own): a body must lie between the
//! walls' inner faces, and no particle may start inside an obstacle.
//!
//! ```
//! use anim_core::scene::BuildContext;
//! use anim_mpm::scenes::MpmScene;
//!
//! let params = serde_json::from_value(serde_json::json!({
//!     "resolution": 32,
//!     "bodies": [{
//!         "shape": { "box": { "center": [0.375, 0.375, 0.375], "half_extents": [0.125, 0.125, 0.125] } },
//!         "material": { "elastic": { "young": 2e4, "density": 1000.0 } },
//!     }],
//! }))?;
//! let MpmScene::Three(scene) = anim_mpm::bodies::build(&params, &BuildContext::default())? else {
//!     unreachable!("3D by default")
//! };
//! // 16^3 particles of (1/64)^3 m^3: the box's volume, 1000 kg/m^3 x (1/4 m)^3.
//! assert_eq!(scene.state.len(), 16 * 16 * 16);
//! let mass: f64 = scene.state.mass.iter().map(|&m| f64::from(m)).sum();
//! assert_eq!(mass, 15.625);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use anim_core::scene::unit_scale;
use std::path::PathBuf;

use crate::memory::{self, Matter};
use anim_core::glam::DVec3;
use anim_core::scene::{BuildContext, BuildError, Placement, is_default};
use anim_core::surface::ClosedSurface;
use anim_io::surface::read_closed_surface;
use serde::{Deserialize, Serialize};

use crate::kind::MpmSceneParams;
use crate::mesh_collider::MeshCollider;
use crate::scenes::{MpmScene, Scene};
use crate::{Collider, Material, MpmError, MpmParams, MpmSimulation, Particles, Shape};

/// Grid cells per axis of a scene of bodies without `resolution`.
pub const DEFAULT_RESOLUTION: usize = 64;

/// Particles per cell and axis of a scene of bodies without `particles_per_cell`.
pub const DEFAULT_PARTICLES_PER_CELL: usize = 2;

/// The most particles a scene may hold: their ids and the sort's slots are `u32`. Long before
/// that the memory runs out: a scene's memory, its particles counted over the bodies' bounding
/// boxes, is checked against the memory available before the grid or a particle is made
/// ([`crate::memory`]).
pub const MAX_PARTICLES: usize = u32::MAX as usize;

/// One body of an `mpm` scene file (a `[[scene.bodies]]` table): its region, given by exactly
/// one of `shape` and `mesh`, its material, its placement and its initial velocity.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BodySpec {
    /// A solid shape, anim-core's [`Shape`] spelling: `{ box = { center, half_extents } }` or
    /// `{ sphere = { center, radius } }` (m; a rectangle or a disk in the x-y plane in 2D, whose
    /// z components are ignored). Planes and capsules are not bodies.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shape: Option<Shape>,
    /// A closed triangle surface, a Wavefront `.obj` file (in a scene file: relative to the scene
    /// file's folder; polygons are fan-triangulated). It must be closed, manifold and
    /// consistently oriented after the placement; 3D only.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mesh: Option<PathBuf>,
    /// The material ([`Material`]): `{ elastic = { ... } }`, `{ snow = { ... } }`,
    /// `{ fluid = { ... } }` or `{ sand = { ... } }`, each field defaulting as its doc states.
    pub material: Material,
    /// Uniform scale about the shape's or mesh's origin, positive; default 1.
    #[serde(default = "unit_scale")]
    pub scale: f64,
    /// Rotation about the origin as roll, pitch, yaw (rad), `Rz(yaw) Ry(pitch) Rx(roll)`, after
    /// the scale (in 2D only the yaw, about z); default none.
    #[serde(default, skip_serializing_if = "is_default")]
    pub rotate: [f64; 3],
    /// Translation (m), applied last; default none.
    #[serde(default, skip_serializing_if = "is_default")]
    pub translate: [f64; 3],
    /// Initial velocity of every particle (m/s; the z component is ignored in 2D); default at
    /// rest.
    #[serde(default, skip_serializing_if = "is_default")]
    pub velocity: [f64; 3],
}

impl BodySpec {
    /// The body's placement.
    #[must_use]
    pub fn placement(&self) -> Placement {
        Placement { scale: self.scale, rotate: self.rotate, translate: self.translate }
    }
}

/// Builds the scene of `params`' bodies (its `bodies` non-empty; the caller refuses a `preset`
/// beside them), in 2D or 3D as its `dim` says; mesh files are read relative to `context`.
///
/// # Errors
/// [`BuildError::Memory`] of `resolution` for a scene whose memory, its particles counted over
/// the bodies' bounding boxes, exceeds the memory available ([`crate::memory`]);
/// [`BuildError::Invalid`] naming the field: `dim`, `resolution`, `particles_per_cell`,
/// `gravity`, `wall`, `boundary`, `obstacles[k]` (a capsule or a bad shape), `bodies[k]` (no or
/// two regions, outside the walls, no particle at this resolution, particles
/// inside an obstacle or a mesh obstacle), `obstacle_meshes` (in 2D), `obstacle_meshes[k]` (a
/// table past [`crate::mesh_collider::MAX_NODES`], outside the domain, no grid node inside),
/// `obstacle_meshes[k].mesh` and `.scale`/`.rotate`/`.translate`, `bodies[k].mesh` (the file
/// and its line, triangle or edge),
/// `bodies[k].shape`, `bodies[k].material.KIND.FIELD`, `bodies[k].scale`/`rotate`/`translate`/
/// `velocity`.
pub fn build(params: &MpmSceneParams, context: &BuildContext<'_>) -> Result<MpmScene, BuildError> {
    match params.dim.unwrap_or(3) {
        2 => build_in::<2>(params, context).map(MpmScene::Two),
        3 => build_in::<3>(params, context).map(MpmScene::Three),
        d => Err(BuildError::invalid("dim", format!("must be 2 or 3, got {d}"))),
    }
}

fn build_in<const D: usize>(p: &MpmSceneParams, context: &BuildContext<'_>) -> Result<Scene<D>, BuildError> {
    let params = sim_params::<D>(p)?;
    let per_cell = p.particles_per_cell.unwrap_or(DEFAULT_PARTICLES_PER_CELL);
    if !(1..=8).contains(&per_cell) {
        return Err(BuildError::invalid(
            "particles_per_cell",
            format!("must lie in [1, 8] (per axis), got {per_cell}"),
        ));
    }
    if p.bodies.len() > usize::from(u16::MAX) {
        return Err(BuildError::invalid(
            "bodies",
            format!("{} bodies; at most {}", p.bodies.len(), u16::MAX),
        ));
    }
    for (k, body) in p.bodies.iter().enumerate() {
        body.material.compile(k).map_err(|e| material_error(k, &body.material, e))?;
    }
    let lattice = Lattice {
        spacing: params.h() / per_cell as f64,
        per_cell,
        resolution: params.resolution,
        lo: params.wall_nodes as f64 * params.h(),
        hi: params.size - params.wall_nodes as f64 * params.h(),
        wall_nodes: params.wall_nodes,
    };
    let regions = p
        .bodies
        .iter()
        .enumerate()
        .map(|(k, body)| Region::of::<D>(body, k, context))
        .collect::<Result<Vec<_>, _>>()?;
    // The memory of the scene before the grid's tables or a particle exist: the particles
    // counted over the bodies' bounding boxes (an upper bound), the grid over the domain.
    let mut matter = Matter::default();
    for (k, region) in regions.iter().enumerate() {
        let counts = lattice.counts::<D>(region, k)?;
        let extent: Vec<f64> = counts.iter().map(|&c| c / per_cell as f64).collect();
        matter = matter.and(Matter::in_box(counts.iter().product(), &extent));
    }
    let n = params.resolution;
    memory::need(D, n as f64, &matter).check(
        "resolution",
        &format!(
            "{n} cells per axis with {per_cell} particles per cell and axis ({:.3e} lattice points in the \
             bodies' bounding boxes)",
            matter.particles
        ),
    )?;
    if matter.particles > MAX_PARTICLES as f64 {
        return Err(BuildError::invalid(
            "bodies",
            format!(
                "their bounding boxes hold {:.3e} lattice points at resolution {n} with {per_cell} particles per \
                 cell and axis, more than the {MAX_PARTICLES} particles a scene indexes",
                matter.particles
            ),
        ));
    }
    let materials = p.bodies.iter().map(|b| b.material).collect();
    let mut sim = MpmSimulation::<D>::new(params.clone(), materials).map_err(simulation_error)?;
    let meshes = obstacle_meshes::<D>(p, &params, context)?;
    sim.set_mesh_colliders(meshes).map_err(|e| BuildError::invalid("obstacle_meshes", reason(e)))?;
    let mut state = Particles::<D>::new();
    for (k, (body, region)) in p.bodies.iter().zip(&regions).enumerate() {
        let points = lattice.fill::<D>(region, k)?;
        seed(&mut state, body, k, &points, lattice.spacing)?;
    }
    check_obstacles(&params, &state)?;
    check_obstacle_meshes(sim.mesh_colliders(), &state)?;
    Ok(Scene { name: "bodies", description: "bodies of a scene file", sim, state, dt: 5e-4, duration: 1.0 })
}

/// The simulation parameters of the scene-wide fields, each checked.
fn sim_params<const D: usize>(p: &MpmSceneParams) -> Result<MpmParams, BuildError> {
    let n = p.resolution.unwrap_or(DEFAULT_RESOLUTION);
    // The grid's `u32` block keys; the memory is checked once the matter is counted.
    let max = crate::sim::max_resolution(D);
    if !(8..=max).contains(&n) {
        return Err(BuildError::invalid("resolution", format!("must lie in [8, {max}] in {D}D, got {n}")));
    }
    let mut params = MpmParams::with_resolution(n);
    if let Some(t) = p.transfer {
        params.transfer = t;
    }
    if let Some(k) = p.kernel {
        params.kernel = k;
    }
    if let Some(g) = p.gravity {
        if !g.iter().all(|c| (*c as f32).is_finite()) {
            return Err(BuildError::invalid("gravity", format!("{g:?} must be finite (in f32)")));
        }
        params.gravity = g;
    }
    if let Some(wall) = p.wall {
        wall.validate("wall").map_err(|e| BuildError::invalid("wall", reason(e)))?;
        params.wall = wall;
    }
    let boundary = p.boundary.unwrap_or_default();
    boundary.validate("boundary").map_err(|e| BuildError::invalid("boundary", reason(e)))?;
    for (k, shape) in p.obstacles.iter().enumerate() {
        let field = format!("obstacles[{k}]");
        if let Shape::Capsule { .. } = shape {
            return Err(BuildError::invalid(
                field,
                "a capsule has no MPM grid boundary: obstacles are planes, boxes and spheres",
            ));
        }
        shape.check_in(D).map_err(|e| BuildError::invalid(field.clone(), e))?;
        let collider = Collider::fixed(*shape, boundary);
        collider.compile(k, D).map_err(|e| BuildError::invalid(field, reason(e)))?;
        params.colliders.push(collider);
    }
    Ok(params)
}

/// The level-set colliders of `obstacle_meshes` (3D only), each surface read relative to
/// `context`, placed and checked.
fn obstacle_meshes<const D: usize>(
    p: &MpmSceneParams,
    params: &MpmParams,
    context: &BuildContext<'_>,
) -> Result<Vec<MeshCollider>, BuildError> {
    if p.obstacle_meshes.is_empty() {
        return Ok(Vec::new());
    }
    if D != 3 {
        return Err(BuildError::invalid(
            "obstacle_meshes",
            "mesh obstacles are 3D; a 2D scene (dim = 2) takes the shapes of `obstacles`",
        ));
    }
    let boundary = p.boundary.unwrap_or_default();
    let mut out = Vec::with_capacity(p.obstacle_meshes.len());
    for (k, m) in p.obstacle_meshes.iter().enumerate() {
        let at = |field: &str| format!("obstacle_meshes[{k}].{field}");
        m.refuse_cell().map_err(|e| BuildError::invalid(at("cell"), e))?;
        let surface = read_closed_surface(&context.resolve(&m.mesh), &m.placement())
            .map_err(|e| e.within(&format!("obstacle_meshes[{k}]")))?;
        let collider = MeshCollider::new(&surface, params, boundary)
            .map_err(|e| BuildError::invalid(format!("obstacle_meshes[{k}]"), e))?;
        out.push(collider);
    }
    Ok(out)
}

/// The reason of a parameter or collider error, without the crate's prefix.
fn reason(e: MpmError) -> String {
    match e {
        MpmError::BadParameter { reason, .. } | MpmError::BadCollider { reason, .. } => reason,
        other => other.to_string(),
    }
}

/// A material error of body `k` at its field, `bodies[k].material.KIND.FIELD`.
fn material_error(k: usize, material: &Material, e: MpmError) -> BuildError {
    let (kind, poisson) = match material {
        Material::Elastic(m) => ("elastic", m.poisson),
        Material::Snow(m) => ("snow", m.poisson),
        Material::Fluid(_) => ("fluid", 0.0),
        Material::Sand(m) => ("sand", m.poisson),
    };
    match e {
        MpmError::BadMaterial { field, reason, .. } => {
            let field = match field {
                "young/poisson" if !(poisson > -1.0 && poisson < 0.5) => "poisson",
                "young/poisson" => "young",
                other => other,
            };
            BuildError::invalid(format!("bodies[{k}].material.{kind}.{field}"), reason)
        }
        other => BuildError::invalid(format!("bodies[{k}].material"), other.to_string()),
    }
}

/// An error of [`MpmSimulation::new`] at the scene-file field it concerns (the fields were
/// checked before, so this is a safety net).
fn simulation_error(e: MpmError) -> BuildError {
    match e {
        MpmError::BadCollider { index, reason } => BuildError::invalid(format!("obstacles[{index}]"), reason),
        MpmError::BadParameter { name: "wall friction", reason } => BuildError::invalid("wall", reason),
        MpmError::BadParameter { name: "collider friction", reason } => {
            BuildError::invalid("boundary", reason)
        }
        MpmError::BadParameter { name: name @ ("resolution" | "gravity"), reason } => {
            BuildError::invalid(name, reason)
        }
        other => BuildError::invalid("bodies", other.to_string()),
    }
}

/// Where a body's matter is: a solid shape under a placement, or a closed surface placed
/// already.
enum Region {
    Solid { shape: Shape, placement: Placement },
    Surface(ClosedSurface),
}

impl Region {
    /// Body `k`'s region, its mesh read relative to `context`; everything checked.
    fn of<const D: usize>(body: &BodySpec, k: usize, context: &BuildContext<'_>) -> Result<Self, BuildError> {
        let at = |field: &str| format!("bodies[{k}].{field}");
        let placement = body.placement();
        placement.check().map_err(|e| e.within(&format!("bodies[{k}]")))?;
        if D == 2 && (body.rotate[0] != 0.0 || body.rotate[1] != 0.0) {
            return Err(BuildError::invalid(
                at("rotate"),
                format!(
                    "a 2D body turns in the x-y plane only: roll and pitch must be 0, got {:?}",
                    body.rotate
                ),
            ));
        }
        match (&body.shape, &body.mesh) {
            (Some(shape), None) => {
                match shape {
                    Shape::Box { .. } | Shape::Sphere { .. } => {}
                    other => {
                        return Err(BuildError::invalid(
                            at("shape"),
                            format!(
                                "a {} is not a body: bodies are boxes, spheres or closed meshes",
                                other.name()
                            ),
                        ));
                    }
                }
                shape.check_in(D).map_err(|e| BuildError::invalid(at("shape"), e))?;
                // In 2D the third components are ignored, whatever they hold.
                let shape = if D == 2 { shape.in_plane() } else { *shape };
                Ok(Region::Solid { shape, placement })
            }
            (None, Some(mesh)) if D == 3 => {
                let path = context.resolve(mesh);
                Ok(Region::Surface(
                    read_closed_surface(&path, &placement).map_err(|e| e.within(&format!("bodies[{k}]")))?,
                ))
            }
            (None, Some(_)) => Err(BuildError::invalid(
                at("mesh"),
                "a mesh is a 3D body; in 2D (dim = 2) bodies are boxes and spheres in the x-y plane",
            )),
            (Some(_), Some(_)) => {
                Err(BuildError::invalid(format!("bodies[{k}]"), "give one of `shape` and `mesh`, not both"))
            }
            (None, None) => Err(BuildError::invalid(
                format!("bodies[{k}]"),
                "a body needs a `shape` (box or sphere) or a `mesh` (a closed OBJ surface)",
            )),
        }
    }

    /// The axis-aligned bounding box of the placed region.
    fn bounds(&self) -> ([f64; 3], [f64; 3]) {
        match self {
            Region::Surface(s) => s.bounds(),
            Region::Solid { shape: Shape::Sphere { center, radius }, placement } => {
                let c = placement.apply(*center);
                let r = radius * placement.scale;
                (c.map(|x| x - r), c.map(|x| x + r))
            }
            Region::Solid { shape, placement } => {
                let (center, half) = match *shape {
                    Shape::Box { center, half_extents } => (center, half_extents),
                    _ => ([0.0; 3], [0.0; 3]),
                };
                let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
                for corner in 0..8 {
                    let sign = |a: usize| if corner >> a & 1 == 1 { 1.0 } else { -1.0 };
                    let p = placement.apply(std::array::from_fn(|a| center[a] + sign(a) * half[a]));
                    for a in 0..3 {
                        lo[a] = lo[a].min(p[a]);
                        hi[a] = hi[a].max(p[a]);
                    }
                }
                (lo, hi)
            }
        }
    }

    /// The lattice points inside the region: the cell centres of the `counts` cells `spacing`
    /// wide from `lo` (first `D` axes) that lie inside.
    fn points<const D: usize>(
        &self,
        lo: [f64; 3],
        counts: [usize; D],
        spacing: f64,
    ) -> Result<Vec<[f64; D]>, String> {
        let (shape, placement) = match self {
            Region::Surface(s) => {
                // The same cells, laid from the lower corner of the surface's bounds.
                let points = s.sample_inside(spacing).map_err(|e| e.to_string())?;
                return Ok(points.into_iter().map(|p| std::array::from_fn(|a| p[a])).collect());
            }
            Region::Solid { shape, placement } => (shape, placement),
        };
        // The lattice point in the shape's own frame: the placement undone.
        let r = placement.rotation().transpose();
        let t = DVec3::from_array(placement.translate);
        let local = |x: [f64; D]| -> [f64; 3] {
            // In 2D the point lies in the plane of the translation (the rotation is a yaw).
            let w = std::array::from_fn(|a| if a < D { x[a] } else { placement.translate[a] });
            ((r * (DVec3::from_array(w) - t)) / placement.scale).to_array()
        };
        let inside = |q: [f64; 3]| match *shape {
            Shape::Box { center, half_extents } => {
                (0..D).all(|a| (q[a] - center[a]).abs() <= half_extents[a])
            }
            Shape::Sphere { center, radius } => {
                (0..D).map(|a| (q[a] - center[a]).powi(2)).sum::<f64>() <= radius * radius
            }
            _ => false,
        };
        let total: usize = counts.iter().product();
        let mut out = Vec::new();
        for flat in 0..total {
            let mut rest = flat;
            let mut x = [0.0; D];
            for a in 0..D {
                x[a] = lo[a] + ((rest % counts[a]) as f64 + 0.5) * spacing;
                rest /= counts[a];
            }
            if inside(local(x)) {
                out.push(x);
            }
        }
        Ok(out)
    }
}

/// The particle lattice of a scene and the region between the walls.
struct Lattice {
    /// Particle spacing `h / per_cell` (m).
    spacing: f64,
    per_cell: usize,
    resolution: usize,
    /// The walls' inner faces: matter lies in `[lo, hi]` on every axis.
    lo: f64,
    hi: f64,
    wall_nodes: usize,
}

impl Lattice {
    /// The lattice cells along each axis over body `k`'s region's bounding box (in `f64`: a
    /// region of any size counts), the region checked between the walls.
    fn counts<const D: usize>(&self, region: &Region, k: usize) -> Result<[f64; D], BuildError> {
        let body = format!("bodies[{k}]");
        let (lo, hi) = region.bounds();
        for a in 0..D {
            let axis = ["x", "y", "z"][a];
            for (v, outside) in [(lo[a], lo[a] < self.lo), (hi[a], hi[a] > self.hi)] {
                if outside || !v.is_finite() {
                    return Err(BuildError::invalid(
                        body,
                        format!(
                            "reaches {axis} = {v:.4} m, outside the domain's walls: at resolution {} the \
                             matter of a scene lies in [{:.4}, {:.4}] m on every axis (the domain is \
                             [0, 1] m, its walls {} cells thick)",
                            self.resolution, self.lo, self.hi, self.wall_nodes
                        ),
                    ));
                }
            }
        }
        Ok(std::array::from_fn(|a| ((hi[a] - lo[a]) / self.spacing).ceil().max(1.0)))
    }

    /// The lattice points of body `k`'s region, which must lie between the walls and get at
    /// least one point; the scene's memory is checked before ([`Lattice::counts`]).
    fn fill<const D: usize>(&self, region: &Region, k: usize) -> Result<Vec<[f64; D]>, BuildError> {
        let body = format!("bodies[{k}]");
        let (lo, _) = region.bounds();
        let counts: [usize; D] = self.counts::<D>(region, k)?.map(|c| c as usize);
        let points =
            region.points::<D>(lo, counts, self.spacing).map_err(|e| BuildError::invalid(body.clone(), e))?;
        if points.is_empty() {
            return Err(BuildError::invalid(
                body,
                format!(
                    "gets no particle at resolution {} with {} particles per cell and axis (spacing \
                     {:.4} m): it is thinner than the spacing; raise resolution or particles_per_cell",
                    self.resolution, self.per_cell, self.spacing
                ),
            ));
        }
        Ok(points)
    }
}

/// Adds body `k`'s particles at `points`, with rest volume `spacing^D` and the material's
/// density.
fn seed<const D: usize>(
    state: &mut Particles<D>,
    body: &BodySpec,
    k: usize,
    points: &[[f64; D]],
    spacing: f64,
) -> Result<(), BuildError> {
    let volume = spacing.powi(D as i32);
    let density = body.material.density();
    let mass = (density * volume) as f32;
    if !(mass > 0.0 && mass.is_finite()) {
        let kind = match body.material {
            Material::Elastic(_) => "elastic",
            Material::Snow(_) => "snow",
            Material::Fluid(_) => "fluid",
            Material::Sand(_) => "sand",
        };
        return Err(BuildError::invalid(
            format!("bodies[{k}].material.{kind}.density"),
            format!("{density} kg/m^{D} gives particles of mass {mass} kg (volume {volume:e} m^{D}) in f32"),
        ));
    }
    let velocity: [f32; D] = std::array::from_fn(|a| body.velocity[a] as f32);
    if !body.velocity.iter().all(|v| (*v as f32).is_finite()) {
        return Err(BuildError::invalid(
            format!("bodies[{k}].velocity"),
            format!("{:?} must be finite (in f32)", body.velocity),
        ));
    }
    let material = k as u16;
    crate::scenes::reserve(state, points.len());
    for x in points {
        state
            .push(x.map(|c| c as f32), velocity, mass, volume as f32, material)
            .map_err(|e| BuildError::invalid(format!("bodies[{k}]"), e.to_string()))?;
    }
    Ok(())
}

/// Refuses particles that start inside an obstacle, naming the body and the obstacle.
fn check_obstacles<const D: usize>(params: &MpmParams, state: &Particles<D>) -> Result<(), BuildError> {
    for (j, collider) in params.colliders.iter().enumerate() {
        let grid =
            collider.compile(j, D).map_err(|e| BuildError::invalid(format!("obstacles[{j}]"), reason(e)))?;
        let inside = |p: &usize| grid.sdf::<D>(&state.position(*p), 0.0).0 < 0.0;
        if let Some(p) = (0..state.len()).find(inside) {
            let k = state.material[p];
            let count = (0..state.len()).filter(|q| state.material[*q] == k && inside(q)).count();
            return Err(BuildError::invalid(
                format!("bodies[{k}]"),
                format!(
                    "{count} of its particles start inside obstacles[{j}] (a {}), the first at {:?}; move the body \
                     or the obstacle",
                    collider.shape.name(),
                    &state.x[p * D..p * D + D]
                ),
            ));
        }
    }
    Ok(())
}

/// Refuses particles that start inside a mesh obstacle (the table's trilinear interpolation
/// negative at the particle), naming the body and the obstacle.
fn check_obstacle_meshes<const D: usize>(
    meshes: &[MeshCollider],
    state: &Particles<D>,
) -> Result<(), BuildError> {
    for (j, mesh) in meshes.iter().enumerate() {
        let inside = |p: &usize| {
            let x: [f64; 3] =
                std::array::from_fn(|a| if a < D { f64::from(state.x[p * D + a]) } else { 0.0 });
            mesh.interpolate(x).is_some_and(|phi| phi < 0.0)
        };
        if let Some(p) = (0..state.len()).find(inside) {
            let k = state.material[p];
            let count = (0..state.len()).filter(|q| state.material[*q] == k && inside(q)).count();
            return Err(BuildError::invalid(
                format!("bodies[{k}]"),
                format!(
                    "{count} of its particles start inside obstacle_meshes[{j}], the first at {:?}; move the \
                     body or the obstacle",
                    &state.x[p * D..p * D + D]
                ),
            ));
        }
    }
    Ok(())
}
