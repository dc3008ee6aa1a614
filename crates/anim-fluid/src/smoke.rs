//! A smoke scene of the user's own: the `fluid` scene kind without `preset`. The domain, its
//! grid and the solver's settings come from [`FluidSceneParams`], the smoke from its
//! [`sources`](FluidSceneParams::sources) and the solids from its
//! [`obstacles`](FluidSceneParams::obstacles), collider shapes ([`Shape`]), and its
//! [`obstacle_meshes`](FluidSceneParams::obstacle_meshes), closed OBJ surfaces.
//!
//! **Axes** are the grid's own, as in the presets: the domain is the box from the origin to
//! `size`, x to the right, **y up** (buoyancy pushes hot smoke along +y, the top is the high y
//! side) and z toward the viewer; a 2D scene is the x-y plane. Shapes and placed meshes are
//! given in these coordinates. A 2D scene reads the first two components of a shape's vectors
//! (a sphere is a disk, as in every 2-D solver of the workspace) and the cut of a mesh at
//! `z = 0`.
//!
//! **Cells and faces.** A cell is solid when the centre of the cell lies inside an obstacle
//! (strictly: a centre on a shape's surface is outside). A source acts on the fluid cells whose
//! centres lie inside it and, when it has a velocity, on the faces whose centres do (wall and
//! obstacle faces excepted). Every step, before advection, it raises the density of its cells to
//! its `density` (it never lowers it), sets their temperature to its `temperature` and the
//! velocity of its faces to its `velocity`: the presets' inflow, of any shape.
//!
//! ```
//! use anim_fluid::kind::FluidSceneParams;
//! use anim_core::scene::params;
//!
//! let p: FluidSceneParams = params(&serde_json::json!({
//!     "dim": 3,
//!     "resolution": 8,
//!     "sources": [ { "shape": { "sphere": { "center": [0.5, 0.0, 0.5], "radius": 0.2 } },
//!                    "velocity": [0.0, 0.5, 0.0] } ],
//!     "obstacles": [ { "box": { "center": [0.5, 0.75, 0.5], "half_extents": [0.3, 0.1, 0.3] } } ],
//! }))?;
//! let mut scene = p.scene()?;
//! assert_eq!(scene.dims(), [8, 12, 8]);
//! let report = scene.step()?;
//! assert!(report.constraint_violation.is_some_and(|d| d < 1e-3));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod region;
#[cfg(test)]
mod tests;

use anim_core::scene::{is_unit_scale, unit_scale};
use std::path::PathBuf;

use anim_core::geometry::Shape;
use anim_core::scene::{BuildContext, BuildError, Placement, is_default};
use serde::{Deserialize, Serialize};

use crate::advection::{Advection, Splitting};
use crate::kind::FluidSceneParams;
use crate::mac::{MacFluid, MacParams, RegionSource, Wall};
use crate::memory::MacLayout;
use crate::pressure::PressureMethod;
use crate::scenes::{FluidScene, FluidSim};
use region::Region;

/// The plume preset's settings, the defaults of a smoke scene of the user's own.
pub mod defaults {
    /// Dimension.
    pub const DIM: usize = 3;
    /// Cells along x.
    pub const RESOLUTION: usize = 32;
    /// Domain size in 3D (m): 1 wide, 1.5 high, 1 deep.
    pub const SIZE_3D: [f64; 3] = [1.0, 1.5, 1.0];
    /// Domain size in 2D (m).
    pub const SIZE_2D: [f64; 2] = [1.0, 1.5];
    /// Buoyancy weight of density `alpha` (m/s² per unit density; dense smoke sinks).
    pub const BUOYANCY_DENSITY: f64 = 0.05;
    /// Buoyancy weight of temperature `beta` (m/s² per unit temperature; hot smoke rises).
    pub const BUOYANCY_TEMPERATURE: f64 = 1.0;
    /// Ambient temperature.
    pub const AMBIENT_TEMPERATURE: f64 = 0.0;
    /// Vorticity confinement strength `eps`.
    pub const VORTICITY_CONFINEMENT: f64 = 2.0;
    /// Kinematic viscosity (m²/s).
    pub const VISCOSITY: f64 = 0.0;
    /// Relative residual of the pressure solve.
    pub const PRESSURE_TOLERANCE: f64 = 1e-5;
    /// A source's density.
    pub const SOURCE_DENSITY: f64 = 1.0;
    /// A source's temperature.
    pub const SOURCE_TEMPERATURE: f64 = 1.0;
}

fn source_density() -> f64 {
    defaults::SOURCE_DENSITY
}

fn source_temperature() -> f64 {
    defaults::SOURCE_TEMPERATURE
}

/// A source of smoke: a region given as a collider shape (`shape`) or a closed OBJ surface
/// (`mesh`, placed by `scale`, `rotate`, `translate`), and what it holds there.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SourceSpec {
    /// The region as a collider shape, in the `anim_core::geometry::Shape` spelling:
    /// `{ sphere = { center, radius } }`, `{ box = { center, half_extents } }`,
    /// `{ capsule = { a, b, radius } }` or `{ plane = { point, normal } }` (the half-space behind
    /// the normal). Give this or `mesh`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shape: Option<Shape>,
    /// The region as a closed OBJ surface, relative to the scene file's folder. Give this or
    /// `shape`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mesh: Option<PathBuf>,
    /// Uniform scale of the mesh about its origin, positive; default 1. Only with `mesh`.
    #[serde(default = "unit_scale", skip_serializing_if = "is_unit_scale")]
    pub scale: f64,
    /// Rotation of the mesh about its origin as roll, pitch, yaw (rad), `Rz(yaw) Ry(pitch)
    /// Rx(roll)`, after the scale; default none. Only with `mesh`.
    #[serde(default, skip_serializing_if = "is_default")]
    pub rotate: [f64; 3],
    /// Translation of the mesh (m), applied last; default none. Only with `mesh`.
    #[serde(default, skip_serializing_if = "is_default")]
    pub translate: [f64; 3],
    /// Density the source's cells are raised to every step, finite; default 1 (the plume's).
    #[serde(default = "source_density", skip_serializing_if = "is_unit_scale")]
    pub density: f64,
    /// Temperature the source's cells are set to every step, finite; default 1 (the plume's).
    #[serde(default = "source_temperature", skip_serializing_if = "is_unit_scale")]
    pub temperature: f64,
    /// Velocity (m/s) set every step on the faces inside the source (the plume's vent blows
    /// `[0, 0.5, 0]`); default none: the source leaves the velocity to the flow. A 2D scene
    /// takes a zero z component.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub velocity: Option<[f64; 3]>,
}

/// A closed OBJ surface as an obstacle (a table of `obstacle_meshes`; anim-core's spelling);
/// in 2D it is placed in 3D and cut at `z = 0`.
pub use anim_core::scene::ObstacleMesh;

/// The grid of a smoke scene: cell counts, dimension, cell size.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Grid {
    dims: [usize; 3],
    dim: usize,
    h: f64,
}

impl Grid {
    /// `"24 x 36 x 24 cells of 0.0417 m (resolution 24)"`.
    fn describe(&self, resolution: usize) -> String {
        let dims: Vec<String> = self.dims[..self.dim].iter().map(usize::to_string).collect();
        format!("{} cells of {:.4} m (resolution {resolution})", dims.join(" x "), self.h)
    }

    /// The domain's upper corner (m).
    fn top(&self) -> [f64; 3] {
        std::array::from_fn(|a| if a < self.dim { self.dims[a] as f64 * self.h } else { 0.0 })
    }
}

/// The length of an optional list, as a count for the memory estimate.
#[allow(clippy::ref_option)]
fn count<T>(list: &Option<Vec<T>>) -> f64 {
    list.as_ref().map_or(0, Vec::len) as f64
}

/// The grid from `dim`, `size` and `resolution`: `resolution` cells along x, and along y (and
/// z) as many cells of the same size as cover the size, refused past the memory available
/// ([`crate::memory`]).
fn grid(p: &FluidSceneParams) -> Result<Grid, BuildError> {
    let dim = p.dim.unwrap_or(defaults::DIM);
    if dim != 2 && dim != 3 {
        return Err(BuildError::invalid("dim", format!("must be 2 or 3, got {dim}")));
    }
    let size: Vec<f64> = match &p.size {
        Some(size) => size.clone(),
        None if dim == 3 => defaults::SIZE_3D.to_vec(),
        None => defaults::SIZE_2D.to_vec(),
    };
    if size.len() != dim {
        return Err(BuildError::invalid(
            "size",
            format!("a {dim}D domain takes {dim} sizes (m), got {}: {size:?}", size.len()),
        ));
    }
    if let Some(s) = size.iter().find(|s| !(**s > 0.0 && s.is_finite())) {
        return Err(BuildError::invalid("size", format!("sizes must be positive and finite, got {s}")));
    }
    let n = p.resolution.unwrap_or(defaults::RESOLUTION);
    if n < 2 {
        return Err(BuildError::invalid("resolution", format!("must be at least 2 cells across, got {n}")));
    }
    let h = size[0] / n as f64;
    let mut cells = [n as f64, 1.0, 1.0];
    for a in 1..dim {
        // The smallest whole number of cells covering the size (the plume's ceil(3n/2)),
        // forgiving the rounding of the division.
        cells[a] = (size[a] / h * (1.0 - 1e-12)).ceil();
        if !(cells[a] >= 2.0) {
            return Err(BuildError::invalid(
                "size",
                format!("size[{a}] = {} m is less than two cells of {h} m (size[0] / resolution)", size[a]),
            ));
        }
    }
    // The memory of the grid, in `f64` before any count becomes a `usize`: the fluid, each
    // source's masks and region (8 bytes a cell), each obstacle's mask (1 byte a cell).
    let layout = MacLayout {
        dim,
        pressure: p.pressure_solver.unwrap_or(PressureMethod::Mgpcg),
        splitting: p.splitting.unwrap_or(Splitting::AdvectProject),
        obstacles: count(&p.obstacles) + count(&p.obstacle_meshes) > 0.0,
    };
    let masks = 8.0 * count(&p.sources) + count(&p.obstacles) + count(&p.obstacle_meshes);
    let total: f64 = cells.iter().product();
    let shown: Vec<String> = cells[..dim].iter().map(|c| format!("{c}")).collect();
    let what = format!("{} cells of {h:.4} m (resolution {n})", shown.join(" x "));
    layout.need(total, masks).check("resolution", &what)?;
    let dims = cells.map(|c| c as usize);
    Ok(Grid { dims, dim, h })
}

/// The solver's settings: the plume's, with the fields the file sets.
fn settings(p: &FluidSceneParams) -> Result<MacParams, BuildError> {
    let finite = |field: &str, v: Option<f64>, default: f64| match v {
        Some(x) if !x.is_finite() => Err(BuildError::invalid(field, format!("must be finite, got {x}"))),
        _ => Ok(v.unwrap_or(default)),
    };
    let non_negative = |field: &str, v: Option<f64>, default: f64| match v {
        Some(x) if !(x >= 0.0 && x.is_finite()) => {
            Err(BuildError::invalid(field, format!("must be finite and >= 0, got {x}")))
        }
        _ => Ok(v.unwrap_or(default)),
    };
    let mut walls = [[Wall::NoSlip([0.0; 3]); 2]; 3];
    if p.open_top.unwrap_or(true) {
        walls[1][1] = Wall::Open;
    }
    Ok(MacParams {
        viscosity: non_negative("viscosity", p.viscosity, defaults::VISCOSITY)?,
        advection: Advection::MacCormack,
        pressure: PressureMethod::Mgpcg,
        pressure_tolerance: defaults::PRESSURE_TOLERANCE,
        buoyancy_density: finite("buoyancy_density", p.buoyancy_density, defaults::BUOYANCY_DENSITY)?,
        buoyancy_temperature: finite(
            "buoyancy_temperature",
            p.buoyancy_temperature,
            defaults::BUOYANCY_TEMPERATURE,
        )?,
        ambient_temperature: finite(
            "ambient_temperature",
            p.ambient_temperature,
            defaults::AMBIENT_TEMPERATURE,
        )?,
        vorticity_confinement: non_negative(
            "vorticity_confinement",
            p.vorticity_confinement,
            defaults::VORTICITY_CONFINEMENT,
        )?,
        walls,
        ..MacParams::default()
    })
}

/// Builds the smoke scene of `p` (a scene without `preset`), reading meshes relative to
/// `context`. The solver settings of the file (pressure, advection, splitting) are the caller's
/// to apply.
pub(crate) fn build(p: &FluidSceneParams, context: &BuildContext<'_>) -> Result<FluidScene, BuildError> {
    let grid = grid(p)?;
    let resolution = grid.dims[0];
    let params = settings(p)?;
    let sources = match &p.sources {
        Some(s) if !s.is_empty() => s,
        _ => {
            return Err(BuildError::invalid(
                "sources",
                format!(
                    "a fluid scene is a preset (`preset`, one of {}) or a smoke scene of your own with \
                     at least one source: `sources = [ {{ shape = {{ sphere = {{ center = [0.5, 0.1, 0.5], \
                     radius = 0.1 }} }} }} ]`",
                    crate::scenes::NAMES.join(", ")
                ),
            ));
        }
    };
    let (mut fluid, state) = MacFluid::new(grid.dims, grid.dim, grid.h, params)
        .map_err(|e| BuildError::invalid("resolution", e.to_string()))?;
    let domain = ([0.0; 3], grid.top());

    // Obstacles: each must cover a cell; the union is solid.
    let mut solid = vec![false; fluid.solid().len()];
    let mut covered: Vec<(String, Vec<bool>)> = Vec::new();
    let shapes: Vec<Shape> = p.obstacles.iter().flatten().copied().collect();
    let regions = shapes.iter().enumerate().map(|(k, shape)| {
        let field = format!("obstacles[{k}]");
        Region::shape(*shape, grid.dim).map(|r| (field.clone(), r)).map_err(|e| BuildError::invalid(field, e))
    });
    let meshes = p.obstacle_meshes.iter().flatten().enumerate().map(|(k, m)| {
        let field = format!("obstacle_meshes[{k}]");
        m.refuse_cell().map_err(|e| BuildError::invalid(format!("{field}.cell"), e))?;
        Region::mesh(&m.mesh, m.placement(), context, &field).map(|r| (field, r))
    });
    for region in regions.chain(meshes) {
        let (field, region) = region?;
        let cells = region.cell_mask(&fluid).map_err(|e| BuildError::invalid(&field, e))?;
        if !cells.contains(&true) {
            return Err(BuildError::invalid(
                &field,
                region.misses(domain, grid.dim, &grid.describe(resolution)),
            ));
        }
        for (s, c) in solid.iter_mut().zip(&cells) {
            *s |= *c;
        }
        covered.push((field, cells));
    }
    fluid.set_solid_cells(&solid).map_err(|e| BuildError::invalid("obstacles", e.to_string()))?;

    // Sources: each must cover a fluid cell.
    for (k, s) in sources.iter().enumerate() {
        let field = format!("sources[{k}]");
        let region = source_region(s, grid.dim, context, &field)?;
        let cells = region.cell_mask(&fluid).map_err(|e| BuildError::invalid(&field, e))?;
        if !cells.contains(&true) {
            return Err(BuildError::invalid(
                &field,
                region.misses(domain, grid.dim, &grid.describe(resolution)),
            ));
        }
        if cells.iter().zip(&solid).all(|(c, s)| !c || *s) {
            let inside: Vec<&str> = covered
                .iter()
                .filter(|(_, o)| cells.iter().zip(o).any(|(c, o)| *c && *o))
                .map(|(name, _)| name.as_str())
                .collect();
            return Err(BuildError::invalid(
                &field,
                format!(
                    "lies inside {}: every cell it covers is solid at {}",
                    inside.join(" and "),
                    grid.describe(resolution)
                ),
            ));
        }
        if let Some(v) = s.velocity
            && grid.dim == 2
            && v[2] != 0.0
        {
            return Err(BuildError::invalid(
                format!("{field}.velocity"),
                format!("a 2D scene has no z velocity, got {v:?}"),
            ));
        }
        let faces = if s.velocity.is_some() {
            region.face_masks(&fluid).map_err(|e| BuildError::invalid(&field, e))?
        } else {
            empty_faces(&fluid)
        };
        fluid
            .add_region_source(RegionSource {
                cells,
                faces,
                density: s.density,
                temperature: s.temperature,
                velocity: s.velocity,
            })
            .map_err(|e| BuildError::invalid(&field, e.to_string()))?;
    }
    Ok(FluidScene {
        name: "smoke",
        description: "smoke from the scene file's sources around its obstacles",
        sim: FluidSim::Mac(fluid, state),
        dt: 1.5 * grid.h,
        duration: 3.0,
        shapes,
    })
}

/// All-false face masks of the fluid's lattices.
fn empty_faces(fluid: &MacFluid) -> [Vec<bool>; 3] {
    std::array::from_fn(|a| {
        vec![false; if a < fluid.dim() { fluid.face_dims(a).iter().product() } else { 0 }]
    })
}

/// The region of source `s`, checked: exactly one of `shape` and `mesh`, a placement only with
/// a mesh, finite values.
fn source_region(
    s: &SourceSpec,
    dim: usize,
    context: &BuildContext<'_>,
    field: &str,
) -> Result<Region, BuildError> {
    for (name, v) in [("density", s.density), ("temperature", s.temperature)] {
        if !v.is_finite() {
            return Err(BuildError::invalid(format!("{field}.{name}"), format!("must be finite, got {v}")));
        }
    }
    if let Some(v) = s.velocity
        && !v.iter().all(|x| x.is_finite())
    {
        return Err(BuildError::invalid(format!("{field}.velocity"), format!("must be finite, got {v:?}")));
    }
    let placement = Placement { scale: s.scale, rotate: s.rotate, translate: s.translate };
    match (&s.shape, &s.mesh) {
        (Some(shape), None) => {
            let unplaced = Placement::default();
            for (name, set) in [
                ("scale", placement.scale != unplaced.scale),
                ("rotate", placement.rotate != unplaced.rotate),
                ("translate", placement.translate != unplaced.translate),
            ] {
                if set {
                    return Err(BuildError::invalid(
                        format!("{field}.{name}"),
                        "places a `mesh` source; give a `shape` where it goes (its centre, ends or point)",
                    ));
                }
            }
            Region::shape(*shape, dim).map_err(|e| BuildError::invalid(format!("{field}.shape"), e))
        }
        (None, Some(mesh)) => Region::mesh(mesh, placement, context, field),
        (Some(_), Some(_)) => Err(BuildError::invalid(field, "give one of `shape` and `mesh`, not both")),
        (None, None) => Err(BuildError::invalid(
            field,
            "needs a region: `shape = { sphere = { center = [x, y, z], radius = r } }` (or box, capsule, \
             plane) or `mesh = \"file.obj\"`",
        )),
    }
}
