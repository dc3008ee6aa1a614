//! Fluid bodies and obstacles of a `flip` scene file ([`crate::kind::FlipSceneParams`] with
//! `[[scene.bodies]]` instead of a preset): each body is a shape or the inside of a closed OBJ
//! surface, filled with particles; obstacles are solid cells.
//!
//! Coordinates are the crate's own, **y up**: the tank's inside is the cube `[0, 1]^3` (the
//! square `[0, 1]^2` in 2D, the plane `z = 0`), gravity `(0, -9.81, 0)` by default, and its
//! walls are one cell thick outside it. `resolution` cells span the inside along each axis.
//!
//! - **Seeding.** The particles of every body are cut from one lattice, that of the presets
//!   ([`scenes::fill_box`]): 2 particles per cell and axis at offsets `(k + 1/2) h / 2` from the
//!   tank's inside corner, no jitter, at the body's `velocity`. A lattice point inside several
//!   bodies is seeded once, by the first of them in file order (so no cell gets a body's
//!   particles twice, and a later body fills only what the earlier ones left).
//! - **Obstacles.** A cell is solid when its centre is inside an obstacle (a [`Shape`] of
//!   `obstacles` or a closed OBJ surface of `obstacle_meshes`); the particles of a body that
//!   fall in solid cells are dropped.
//! - **Refusals**, each naming its field: a body that reaches outside the tank's inside
//!   (`bodies[k]`), a body with no lattice point inside it at this resolution or none left once
//!   earlier bodies and solid cells have taken theirs (`bodies[k]`), a mesh that does not read or
//!   is not a closed, consistently oriented surface (`bodies[k].mesh`, the file and the line,
//!   triangle or edge), an obstacle that covers no cell centre (`obstacles[k]`), in 2D any
//!   motion out of the plane, and a scene whose memory, its particles counted over the bodies'
//!   bounding boxes, exceeds the memory available (`resolution`, [`crate::memory`]), refused
//!   before the grid or a particle is made.
//!
//! A 2D scene reads the first two components of each shape (a sphere is a disk, a box a
//! rectangle) and cuts a mesh by the plane `z = 0` after its placement; rotations there are yaw
//! only, and translations, velocities and gravity have no z.
//!
//! ```
//! use anim_flip::kind::FlipSceneParams;
//!
//! let params: FlipSceneParams = serde_json::from_value(serde_json::json!({
//!     "dim": 2,
//!     "resolution": 16,
//!     "bodies": [{ "shape": { "box": { "center": [0.5, 0.25, 0.0], "half_extents": [0.5, 0.25, 0.0] } } }],
//! }))?;
//! let (_, particles) = anim_flip::body::build::<2>(&params, &Default::default())?;
//! // 16 x 8 cells, 4 particles per cell.
//! assert_eq!(particles.len(), 16 * 8 * 4);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! [`scenes::fill_box`]: crate::scenes::fill_box

mod region;
mod scene;
#[cfg(test)]
mod tests;

pub use scene::BodyScene;

use crate::kind::FlipSceneParams;
use crate::mac::{flatten, unflatten};
use crate::memory;
use crate::particles::Particles;
use crate::sim::{FlipParams, FlipSimulation};
use anim_core::geometry::Shape;
use anim_core::scene::unit_scale;
use anim_core::scene::{BuildContext, BuildError, MeshProp, Placement, is_default};
use region::Region;
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

/// A body of fluid: one `shape` or one closed `mesh`, placed, at an initial velocity.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FluidBody {
    /// The body's shape, in the [`Shape`] spelling: `{ box = { center, half_extents } }`,
    /// `{ sphere = { center, radius } }` or `{ capsule = { a, b, radius } }` (a plane is
    /// unbounded and refused). Give this or `mesh`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shape: Option<Shape>,
    /// A closed triangle surface, a Wavefront OBJ file relative to the scene file (polygons are
    /// fan-triangulated; `l` lines are not part of the surface); the fluid fills its inside. Give
    /// this or `shape`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mesh: Option<PathBuf>,
    /// Uniform scale about the origin of the shape's or mesh's coordinates, positive. Default 1.
    #[serde(default = "unit_scale")]
    pub scale: f64,
    /// Roll, pitch, yaw (rad) about that origin after the scale: `Rz(yaw) Ry(pitch) Rx(roll)`;
    /// in 2D, yaw only. Default none.
    #[serde(default, skip_serializing_if = "is_default")]
    pub rotate: [f64; 3],
    /// Translation (m), applied last; in 2D, z is 0. Default none.
    #[serde(default, skip_serializing_if = "is_default")]
    pub translate: [f64; 3],
    /// Initial velocity of the body's particles (m/s); in 2D, z is 0. Default at rest.
    #[serde(default, skip_serializing_if = "is_default")]
    pub velocity: [f64; 3],
}

/// A solid obstacle from a closed OBJ surface (anim-core's spelling): the cells whose centres
/// are inside it are solid; in 2D its rotation is a yaw and its translation has z = 0.
pub use anim_core::scene::ObstacleMesh;

/// Default cells across the tank: as the presets, 64 in 2D and 32 in 3D.
#[must_use]
pub fn default_resolution(dim: usize) -> usize {
    if dim == 3 { 32 } else { 64 }
}

/// Default gravity of a scene of bodies (m/s^2), y up.
pub const GRAVITY: [f64; 3] = [0.0, -9.81, 0.0];

/// Volume correction of a scene of bodies: that of the drop and dam-break presets
/// ([`FlipParams::volume_correction`]).
pub const VOLUME_CORRECTION: f64 = 0.5;

fn invalid(field: impl Into<String>, message: impl Into<String>) -> BuildError {
    BuildError::invalid(field, message)
}

/// The placement of a body or obstacle mesh, checked (its fields prefixed with `prefix`, like
/// `bodies[0]`), and in 2D kept in the plane.
fn placement(
    prefix: &str,
    scale: f64,
    rotate: [f64; 3],
    translate: [f64; 3],
    dim: usize,
) -> Result<Placement, BuildError> {
    let p = Placement { scale, rotate, translate };
    p.check().map_err(|e| e.within(prefix))?;
    if dim == 2 {
        if rotate[0] != 0.0 || rotate[1] != 0.0 {
            return Err(invalid(
                format!("{prefix}.rotate"),
                format!("a 2D scene turns bodies in its plane only: give [0, 0, yaw], got {rotate:?}"),
            ));
        }
        if translate[2] != 0.0 {
            return Err(invalid(
                format!("{prefix}.translate"),
                format!("a 2D scene lies in the plane z = 0: give z = 0, got {translate:?}"),
            ));
        }
    }
    Ok(p)
}

/// A vector of the scene file as one of a `dim`-dimensional scene: finite, and in 2D with z 0.
fn vector<const D: usize>(field: &str, v: [f64; 3]) -> Result<[f64; D], BuildError> {
    if !v.iter().all(|x| x.is_finite()) {
        return Err(invalid(field, format!("{v:?} holds a non-finite value")));
    }
    if D == 2 && v[2] != 0.0 {
        return Err(invalid(field, format!("a 2D scene lies in the plane z = 0: give z = 0, got {v:?}")));
    }
    Ok(std::array::from_fn(|k| v[k]))
}

/// Coordinates rounded to nanometres, for messages.
fn rounded(v: &[f64]) -> Vec<f64> {
    v.iter().map(|x| (x * 1e9).round() / 1e9).collect()
}

/// The scene of `params.bodies` in `D` dimensions (`params.dim`, 3 when absent): the simulation
/// in its tank of `resolution` cells across, its obstacles marked solid, and the bodies'
/// particles (in the simulation's frame, whose origin is the outer corner of the walls).
///
/// # Errors
/// [`BuildError::Invalid`] naming the field, as the module documentation lists.
pub fn build<const D: usize>(
    params: &FlipSceneParams,
    context: &BuildContext<'_>,
) -> Result<(BodyScene<D>, Particles<D>), BuildError> {
    let res = params.resolution.unwrap_or_else(|| default_resolution(D));
    if res < 4 {
        return Err(invalid(
            "resolution",
            format!("a {D}D scene takes at least 4 cells across its 1 m tank, got {res}"),
        ));
    }
    let mut flip = FlipParams::<D>::default();
    if let Some(t) = params.transfer {
        flip.transfer = t;
    }
    flip.volume_correction = VOLUME_CORRECTION;
    flip.gravity = vector::<D>("gravity", params.gravity.unwrap_or(GRAVITY))?;
    let h = 1.0 / res as f64;
    let bodies = body_regions::<D>(params, context)?;
    check_memory::<D>(res, &bodies)?;
    let mut sim =
        FlipSimulation::new([res + 2; D], h, flip).map_err(|e| invalid("resolution", e.to_string()))?;
    let (origin, _) = sim.fluid_box();
    let obstacles = obstacles::<D>(params, context)?;
    mark_solid(&mut sim, &obstacles)?;
    let particles = seed(&sim, &bodies, origin)?;
    let shapes = params.obstacles.clone();
    // In 2D a mesh obstacle is its cross-section z = 0, which the preview does not draw.
    let meshes = match D {
        3 => obstacles.iter().filter_map(|(_, region)| region.surface()).map(MeshProp::from).collect(),
        _ => Vec::new(),
    };
    Ok((BodyScene::new(sim, origin, shapes, meshes), particles))
}

/// The regions of `obstacles` and `obstacle_meshes`, each with its field.
fn obstacles<const D: usize>(
    params: &FlipSceneParams,
    context: &BuildContext<'_>,
) -> Result<Vec<(String, Region)>, BuildError> {
    let mut out = Vec::new();
    for (k, shape) in params.obstacles.iter().enumerate() {
        let field = format!("obstacles[{k}]");
        shape.check_in(D).map_err(|e| invalid(&field, e))?;
        out.push((field, Region::shape(*shape, Placement::default(), D)));
    }
    for (k, m) in params.obstacle_meshes.iter().enumerate() {
        let prefix = format!("obstacle_meshes[{k}]");
        m.refuse_cell().map_err(|e| invalid(format!("{prefix}.cell"), e))?;
        let place = placement(&prefix, m.scale, m.rotate, m.translate, D)?;
        let region = Region::mesh(&m.mesh, place, context, &prefix)?;
        out.push((prefix, region));
    }
    Ok(out)
}

/// Marks the cells whose centres are inside an obstacle as solid.
///
/// # Errors
/// An obstacle that covers no cell centre of the tank's inside.
fn mark_solid<const D: usize>(
    sim: &mut FlipSimulation<D>,
    obstacles: &[(String, Region)],
) -> Result<(), BuildError> {
    let n = sim.grid().cells();
    let h = sim.grid().h();
    let mut solid = sim.solid().to_vec();
    for (field, region) in obstacles {
        // The inner cells whose centres may lie in the region's bounds.
        let (start, counts) = index_box::<D>(region, h, [n[0] - 2; D]);
        let inside = region.inside_lattice(start, counts, h).map_err(|e| invalid(field.as_str(), e))?;
        let mut covered = 0usize;
        for (f, _) in inside.iter().enumerate().filter(|(_, i)| **i) {
            let idx = unflatten(counts, f);
            // Inner cell `start + idx` is grid cell `start + idx + 1` (past the wall).
            solid[flatten(n, std::array::from_fn(|a| start[a] + idx[a] + 1))] = true;
            covered += 1;
        }
        if covered == 0 {
            return Err(invalid(
                field.as_str(),
                format!(
                    "covers no cell centre of the tank's inside at resolution {} (cells {h} m): it would have no effect",
                    n[0] - 2
                ),
            ));
        }
    }
    // `set_solid` gives cell centres `(i + 1/2) h`, of cell `i`.
    sim.set_solid(|x| solid[flatten(n, std::array::from_fn(|a| (x[a] / h) as usize))]);
    Ok(())
}

/// The box of lattice points `(i + 1/2) spacing`, `i < len` per axis, that may lie in the
/// region's bounds: its first index and its extent per axis (at least 1, clamped to the lattice).
fn index_box<const D: usize>(region: &Region, spacing: f64, len: [usize; D]) -> ([usize; D], [usize; D]) {
    let start: [usize; D] =
        std::array::from_fn(|a| ((region.lo[a] / spacing - 0.5).floor().max(0.0) as usize).min(len[a] - 1));
    let counts = std::array::from_fn(|a| {
        let end = ((region.hi[a] / spacing - 0.5).ceil().max(0.0) as usize).min(len[a] - 1);
        end.max(start[a]) - start[a] + 1
    });
    (start, counts)
}

/// A body of the scene: its field (`bodies[k]`), its placed region and its velocity.
struct Body<const D: usize> {
    name: String,
    region: Region,
    velocity: [f64; D],
}

/// The bodies' regions, placed and checked inside the tank.
fn body_regions<const D: usize>(
    params: &FlipSceneParams,
    context: &BuildContext<'_>,
) -> Result<Vec<Body<D>>, BuildError> {
    let mut out = Vec::with_capacity(params.bodies.len());
    for (k, body) in params.bodies.iter().enumerate() {
        let name = format!("bodies[{k}]");
        let place = placement(&name, body.scale, body.rotate, body.translate, D)?;
        let velocity = vector::<D>(&format!("{name}.velocity"), body.velocity)?;
        let region = match (&body.shape, &body.mesh) {
            (Some(shape), None) => {
                let field = format!("{name}.shape");
                shape.check_in(D).map_err(|e| invalid(&field, e))?;
                if let Shape::Plane { .. } = shape {
                    return Err(invalid(field, "a plane is unbounded: fill a pool with a box"));
                }
                Region::shape(*shape, place, D)
            }
            (None, Some(mesh)) => Region::mesh(mesh, place, context, &name)?,
            (Some(_), Some(_)) => return Err(invalid(name, "give a `shape` or a `mesh`, not both")),
            (None, None) => {
                return Err(invalid(name, "give a `shape` (box, sphere, capsule) or a closed OBJ `mesh`"));
            }
        };
        let outside = (0..D).any(|a| !(region.lo[a] >= -1e-9 && region.hi[a] <= 1.0 + 1e-9));
        if outside {
            return Err(invalid(
                name,
                format!(
                    "reaches outside the tank: it spans {:?} to {:?} (m); the tank's inside is 0 to 1 m along each axis",
                    rounded(&region.lo[..D]),
                    rounded(&region.hi[..D])
                ),
            ));
        }
        out.push(Body { name, region, velocity });
    }
    Ok(out)
}

/// Refuses a scene of `bodies` at `res` cells across whose memory exceeds what is available
/// ([`crate::memory`]): the tank's `(res + 2)^D` cells, its lattice of `(2 res)^D` points and
/// the particles, counted over the bodies' bounding boxes (an upper bound), before the grid or
/// a particle is made.
fn check_memory<const D: usize>(res: usize, bodies: &[Body<D>]) -> Result<(), BuildError> {
    let side = 2.0 * res as f64;
    let spacing = 1.0 / side;
    let lattice = side.powi(D as i32);
    let boxed: f64 = bodies
        .iter()
        .map(|b| {
            (0..D)
                .map(|a| ((b.region.hi[a] - b.region.lo[a]) / spacing + 1.0).ceil().clamp(1.0, side))
                .product::<f64>()
        })
        .sum();
    let particles = boxed.min(lattice);
    let cells = (res as f64 + 2.0).powi(D as i32);
    memory::need(D, cells, particles).with(lattice, "lattice points", 1.0).check(
        "resolution",
        &format!("{res} cells across ({particles:.3e} lattice points in the bodies' bounding boxes)"),
    )
}

/// The particles of the bodies: the lattice points of the presets inside each body, each point
/// seeded once (by the first body that holds it), none in solid cells.
fn seed<const D: usize>(
    sim: &FlipSimulation<D>,
    bodies: &[Body<D>],
    origin: [f64; D],
) -> Result<Particles<D>, BuildError> {
    let n = sim.grid().cells();
    let h = sim.grid().h();
    let res = n[0] - 2;
    let per_axis = 2;
    let spacing = h / per_axis as f64;
    let counts = [per_axis * res; D];
    let mut taken = vec![false; counts.iter().product()];
    let mut particles = Particles::new();
    for Body { name, region, velocity } in bodies {
        let (name, velocity) = (name.as_str(), *velocity);
        let (start, box_counts) = index_box::<D>(region, spacing, counts);
        let lattice = region.inside_lattice(start, box_counts, spacing).map_err(|e| invalid(name, e))?;
        crate::scenes::reserve(&mut particles, lattice.iter().filter(|i| **i).count());
        let (mut inside, mut earlier, mut solid) = (0usize, 0usize, 0usize);
        let before = particles.len();
        for (f, _) in lattice.iter().enumerate().filter(|(_, i)| **i) {
            inside += 1;
            let local = unflatten(box_counts, f);
            let idx: [usize; D] = std::array::from_fn(|a| start[a] + local[a]);
            let slot = &mut taken[flatten(counts, idx)];
            if *slot {
                earlier += 1;
                continue;
            }
            *slot = true;
            // The presets' lattice point, `fill_box`'s arithmetic from the tank's inside corner.
            let x: [f64; D] = std::array::from_fn(|a| origin[a] + (idx[a] as f64 + 0.5) * spacing);
            let cell: [usize; D] = std::array::from_fn(|a| ((x[a] / h) as usize).min(n[a] - 1));
            if sim.solid()[flatten(n, cell)] {
                solid += 1;
                continue;
            }
            particles.push(x, velocity);
        }
        if inside == 0 {
            return Err(invalid(
                name,
                format!(
                    "holds no particle at resolution {res} (particles {spacing} m apart): make it larger or raise the resolution"
                ),
            ));
        }
        if particles.len() == before {
            return Err(invalid(
                name,
                format!(
                    "none of its {inside} particles is left: {earlier} belong to earlier bodies, {solid} lie in solid cells of obstacles"
                ),
            ));
        }
    }
    Ok(particles)
}
