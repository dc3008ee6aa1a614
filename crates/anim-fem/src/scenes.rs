//! Ready-to-run scenes: the model, its initial state, a time step, a duration and the solver
//! settings that suit it. All scenes are z-up with gravity [`EARTH_GRAVITY`], SI units.
//!
//! | scene | what | method | why |
//! | --- | --- | --- | --- |
//! | `cantilever-beam` | a 1 m x 0.1 m x 0.1 m beam (E = 10 MPa) clamped at one end sags under gravity and swings | stable Neo-Hookean, backward Euler, dt = 1/60 s | a large-but-smooth deflection, the reference case of the conformance suite |
//! | `soft-cube-drop` | a 0.3 m jelly cube (E = 50 kPa) dropped from 0.5 m bounces on the ground | stable Neo-Hookean, backward Euler, dt = 1/120 s, penalty contact | impact, large compression |
//! | `twisted-bar` | a bar clamped at one end while the other end turns about the bar axis at half a turn per second | fixed corotated, backward Euler, dt = 1/60 s | large rotations and shear; corotated models stay defined |
//!
//! Every scene is built of linear tetrahedra by default; [`by_name_with_order`] builds it of
//! 10-node tetrahedra on the same mesh ([`ElementOrder::Quadratic`]: the beam then bends as
//! Euler-Bernoulli theory says instead of locking, with 4 to 7 times the nodes and 4 quadrature
//! points per element).
//!
//! Output: positions are in the state (`x = [x0, y0, z0, ...]`, the edge nodes after the corners
//! for 10-node bodies); the model's [`surface`](FemModel::surface) gives the outward boundary
//! triangles (of the corners) for drawing.
//!
//! ```
//! use anim_core::solver::Solver;
//! use anim_fem::scenes;
//!
//! let scene = scenes::by_name("twisted-bar", Some(2)).expect("a known scene")?;
//! let (mut sim, mut state) = scene.into_simulation()?;
//! let report = sim.step(&mut state, 1.0 / 60.0)?;
//! assert!(report.iterations >= 1);
//! assert!(!sim.model().surface().is_empty());
//! # Ok::<(), anim_fem::FemError>(())
//! ```

use crate::boundary::{Motion, Obstacle};
use crate::error::FemError;
use crate::generate::box_mesh;
use crate::material::{Material, MaterialModel};
use crate::model::{EARTH_GRAVITY, ElementOrder, FemModel};
use crate::sim::{FemParams, FemSimulation};
use anim_core::integrate::State;

/// A scene: the model, its initial state and how to step it.
#[derive(Debug, Clone)]
pub struct FemScene {
    /// Short name ("twisted-bar").
    pub name: &'static str,
    /// One-line description.
    pub description: &'static str,
    /// The model.
    pub model: FemModel,
    /// Initial state.
    pub state: State,
    /// Suggested time step (s).
    pub dt: f64,
    /// Suggested simulated duration (s).
    pub duration: f64,
    /// Suggested solver settings.
    pub params: FemParams,
}

impl FemScene {
    /// A simulation with the scene's settings, and the initial state.
    ///
    /// # Errors
    /// [`FemError::BadParameter`] if the settings were changed to invalid ones.
    pub fn into_simulation(self) -> Result<(FemSimulation, State), FemError> {
        Ok((FemSimulation::new(self.model, self.params)?, self.state))
    }

    /// Number of steps of `dt` covering `duration`.
    #[must_use]
    pub fn steps(&self) -> usize {
        (self.duration / self.dt).round().max(1.0) as usize
    }
}

/// The built-in scene names, for command lines.
pub const NAMES: [&str; 3] = ["cantilever-beam", "soft-cube-drop", "twisted-bar"];

/// Builds a scene by name (see [`NAMES`]); `None` for an unknown name. The resolution is the
/// number of cells across the beam or bar (4 by default; the length gets 10 times as many), or
/// along each side of the cube (6 by default).
#[must_use]
pub fn by_name(name: &str, resolution: Option<usize>) -> Option<Result<FemScene, FemError>> {
    by_name_with_order(name, resolution, ElementOrder::Linear)
}

/// [`by_name`] with the element order of the body (the same mesh, refined to 10-node elements
/// for [`ElementOrder::Quadratic`]).
#[must_use]
pub fn by_name_with_order(
    name: &str,
    resolution: Option<usize>,
    order: ElementOrder,
) -> Option<Result<FemScene, FemError>> {
    // No upper bound here: the `fem` kind refuses a resolution whose memory
    // (`crate::memory`) the machine does not have before the mesh is made.
    let n = resolution_default(name).map(|default| resolution.unwrap_or(default))?;
    Some(match name {
        "cantilever-beam" => cantilever_beam_of(n, order),
        "soft-cube-drop" => soft_cube_drop_of(n, order),
        "twisted-bar" => twisted_bar_of(n, order),
        _ => return None,
    })
}

/// The cells across a preset when none is given (4 for the beam and the bar, 6 for the cube);
/// `None` for an unknown name.
#[must_use]
pub fn resolution_default(name: &str) -> Option<usize> {
    match name {
        "cantilever-beam" | "twisted-bar" => Some(4),
        "soft-cube-drop" => Some(6),
        _ => None,
    }
}

fn initial_state(model: &FemModel) -> State {
    let x = model.rest_positions();
    let v = vec![0.0; x.len()];
    State { t: 0.0, x, v }
}

/// The benchmark beam of the criterion benches and the peer comparison: 1 m x 0.16 m x 0.16 m,
/// `cells x cells/6.25 x cells/6.25` cubic cells (`50 x 8 x 8` = 19,200 tetrahedra for
/// `cells = 50`), stable Neo-Hookean with E = 1 MPa, nu = 0.45, rho = 1000 kg/m^3, clamped at
/// x = 0, under gravity, backward Euler at dt = 0.01 s.
///
/// # Errors
/// [`FemError::BadParameter`] for `cells < 7`.
pub fn benchmark_beam(cells: usize) -> Result<FemScene, FemError> {
    let across = ((cells as f64) * 0.16).round() as usize;
    if across == 0 {
        return Err(FemError::BadParameter { name: "cells", value: cells as f64, reason: "must be >= 4" });
    }
    let mesh = box_mesh([0.0, -0.08, 0.0], [1.0, 0.16, 0.16], [cells, across, across])?;
    let material = Material::new(MaterialModel::StableNeoHookean, 1e6, 0.45, 1000.0)?;
    let mut model = FemModel::new(mesh, material)?.with_gravity(EARTH_GRAVITY);
    let clamp = model.vertices_where(|p| p[0] < 1e-9);
    model.pin_vertices(&clamp)?;
    Ok(FemScene {
        name: "benchmark-beam",
        description: "the benchmark beam of the benches and peer comparisons",
        state: initial_state(&model),
        model,
        dt: 0.01,
        duration: 1.0,
        params: FemParams::default().with_energy_report(false),
    })
}

/// The cantilever beam (see the [module docs](self)).
///
/// # Errors
/// [`FemError::BadParameter`] for a zero resolution.
pub fn cantilever_beam(resolution: usize) -> Result<FemScene, FemError> {
    cantilever_beam_of(resolution, ElementOrder::Linear)
}

fn cantilever_beam_of(resolution: usize, order: ElementOrder) -> Result<FemScene, FemError> {
    let n = resolution;
    let mesh = box_mesh([0.0, -0.05, 0.5], [1.0, 0.1, 0.1], [10 * n, n, n])?;
    let material = Material::new(MaterialModel::StableNeoHookean, 1e7, 0.3, 1000.0)?;
    let mut model = FemModel::with_order(mesh, material, order)?.with_gravity(EARTH_GRAVITY);
    let clamp = model.vertices_where(|p| p[0] < 1e-9);
    model.pin_vertices(&clamp)?;
    Ok(FemScene {
        name: "cantilever-beam",
        description: "a clamped beam sagging under gravity",
        state: initial_state(&model),
        model,
        dt: 1.0 / 60.0,
        duration: 3.0,
        params: FemParams::default(),
    })
}

/// The soft cube drop (see the [module docs](self)).
///
/// # Errors
/// [`FemError::BadParameter`] for a zero resolution.
pub fn soft_cube_drop(resolution: usize) -> Result<FemScene, FemError> {
    soft_cube_drop_of(resolution, ElementOrder::Linear)
}

fn soft_cube_drop_of(resolution: usize, order: ElementOrder) -> Result<FemScene, FemError> {
    let n = resolution;
    let mesh = box_mesh([-0.15, -0.15, 0.5], [0.3, 0.3, 0.3], [n, n, n])?;
    let material = Material::new(MaterialModel::StableNeoHookean, 5e4, 0.3, 1000.0)?;
    let mut model = FemModel::with_order(mesh, material, order)?.with_gravity(EARTH_GRAVITY);
    model.add_obstacle(Obstacle::ground(0.0), 1e7)?;
    let mut state = initial_state(&model);
    // A slight spin so the landing is not symmetric.
    for (i, v) in state.v.chunks_mut(3).enumerate() {
        let p = model.mesh().positions[i];
        v[0] = -2.0 * (p[1] - 0.0);
        v[1] = 2.0 * (p[0] - 0.0);
    }
    Ok(FemScene {
        name: "soft-cube-drop",
        description: "a jelly cube dropped on the ground",
        state,
        model,
        dt: 1.0 / 120.0,
        duration: 2.0,
        params: FemParams::default().with_rayleigh(0.002),
    })
}

/// The twisted bar (see the [module docs](self)).
///
/// # Errors
/// [`FemError::BadParameter`] for a zero resolution.
pub fn twisted_bar(resolution: usize) -> Result<FemScene, FemError> {
    twisted_bar_of(resolution, ElementOrder::Linear)
}

fn twisted_bar_of(resolution: usize, order: ElementOrder) -> Result<FemScene, FemError> {
    let n = resolution;
    let mesh = box_mesh([0.0, -0.05, 0.45], [1.0, 0.1, 0.1], [10 * n, n, n])?;
    let material = Material::new(MaterialModel::FixedCorotated, 1e6, 0.3, 1000.0)?;
    let mut model = FemModel::with_order(mesh, material, order)?;
    let left = model.vertices_where(|p| p[0] < 1e-9);
    let right = model.vertices_where(|p| p[0] > 1.0 - 1e-9);
    model.pin_vertices(&left)?;
    let motion = Motion::Rotate {
        center: [1.0, 0.0, 0.5],
        axis: [1.0, 0.0, 0.0],
        angular_velocity: std::f64::consts::PI,
    };
    model.add_kinematic(&right, motion)?;
    Ok(FemScene {
        name: "twisted-bar",
        description: "a bar twisted by half a turn per second at one end",
        state: initial_state(&model),
        model,
        dt: 1.0 / 60.0,
        duration: 2.0,
        params: FemParams::default().with_rayleigh(0.01),
    })
}
