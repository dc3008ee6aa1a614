//! Ready-to-run scenes: everything a caller (the `anim` command line, an example, a benchmark)
//! needs to simulate one: the model, its initial state, a time step, a duration and the solver
//! settings that suit it. All scenes are z-up with gravity [`EARTH_GRAVITY`].
//!
//! | scene | what | method, solver | why |
//! | --- | --- | --- | --- |
//! | [`cloth_drape`] | a square cloth falls onto a sphere and drapes over it, friction on sphere and ground | XPBD, coloured Gauss-Seidel, 5 iterations x 4 substeps | inextensible cloth with soft isometric bending; substeps keep contacts crisp |
//! | [`flag`] | a flag attached to a swaying pole flaps in gusty wind | XPBD, coloured Gauss-Seidel, 8 iterations x 2 substeps | dihedral bending, attachments to a moving kinematic body, wind on triangles |
//! | [`rope`] | a rope of 100 links pinned at one end swings down over a capsule and a box | XPBD (rigid), sequential Gauss-Seidel, 2 iterations x 16 substeps | a long chain converges slowly with iterations; small steps fix it |
//! | [`soft_blob`] | a bunny-like tetrahedral blob drops on the ground and bounces | XPBD, coloured Gauss-Seidel, 5 iterations x 4 substeps | tet volume + compliant edges, restitution and friction |
//! | [`balloon`] | an inflated closed sphere (global volume constraint, pressure 1.5) drops onto a box | XPBD, coloured Gauss-Seidel, 5 iterations x 4 substeps | the global volume constraint |
//! | [`hanging_cloth`] | the 0.5 m cloth of the report's work-precision studies, pinned at two corners, hanging down | XPBD, sequential Gauss-Seidel, 1 iteration x 8 substeps | the studies' problem, for `anim run --tolerance` |
//! | [`benchmark_cloth`] | the `N x N` cloth of the benches and peer comparisons | XPBD, sequential Gauss-Seidel, 5 iterations | what pyPBD's and Newton's examples run |
//!
//! Output: positions are in the state (`x = [x0, y0, z0, ...]`); the model's
//! [`triangles`](PbdModel::triangles) (cloth, mesh and tet-mesh surfaces),
//! [`edges`](PbdModel::edges) (ropes) and [`tets`](PbdModel::tets) say how to draw them, and its
//! [`colliders`](PbdModel::colliders) where the obstacles are.
//!
//! ```
//! use anim_core::solver::Solver;
//! use anim_pbd::scenes;
//!
//! let scene = scenes::by_name("rope", Some(20)).expect("a known scene")?;
//! let (mut sim, mut state) = scene.into_simulation()?;
//! let report = sim.step(&mut state, 1.0 / 60.0)?;
//! assert!(report.constraint_violation.is_some());
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use crate::build::{
    Bending, BuildError, Chain, Cloth, EARTH_GRAVITY, InputError, MeshMass, MeshParams, PbdBuilder,
    TetMeshParams,
};
use crate::collide::{BodyMotion, Collider, KinematicBody, Pose, Shape};
use crate::constraint::{AttachTarget, ConstraintParams};
use crate::model::{PbdModel, Wind};
use crate::sim::{Method, PbdError, PbdParams, PbdSimulation, SolverKind};
use anim_core::glam::{DQuat, DVec3};
use anim_core::integrate::State;

/// A scene: the model, its initial state and how to step it.
#[derive(Debug, Clone)]
pub struct PbdScene {
    /// Short name ("cloth-drape").
    pub name: &'static str,
    /// One-line description.
    pub description: &'static str,
    /// The model.
    pub model: PbdModel,
    /// Initial state.
    pub state: State,
    /// Suggested time step (s).
    pub dt: f64,
    /// Suggested simulated duration (s).
    pub duration: f64,
    /// Suggested solver settings.
    pub params: PbdParams,
}

impl PbdScene {
    /// A simulation with the scene's settings, and the initial state.
    ///
    /// # Errors
    /// [`PbdError::BadParameter`] if the settings were changed to invalid ones.
    pub fn into_simulation(self) -> Result<(PbdSimulation, State), PbdError> {
        Ok((PbdSimulation::new(self.model, self.params)?, self.state))
    }

    /// Number of steps of `dt` covering `duration`.
    #[must_use]
    pub fn steps(&self) -> usize {
        (self.duration / self.dt).round().max(1.0) as usize
    }
}

/// The built-in scene names, for command lines.
pub const NAMES: [&str; 7] =
    ["cloth-drape", "flag", "rope", "soft-blob", "balloon", "hanging-cloth", "benchmark-cloth"];

/// Builds a scene by name (see [`NAMES`]); `None` for an unknown name. The resolution scales the
/// particle count (cloth side, flag width, rope links, blob cells, balloon subdivisions);
/// `None` takes the scene's default.
#[must_use]
pub fn by_name(name: &str, resolution: Option<usize>) -> Option<Result<PbdScene, BuildError>> {
    Some(match name {
        "cloth-drape" => cloth_drape(resolution),
        "flag" => flag(resolution),
        "rope" => rope(resolution),
        "soft-blob" => soft_blob(resolution),
        "balloon" => balloon(resolution),
        "hanging-cloth" => hanging_cloth(resolution),
        "benchmark-cloth" => benchmark_cloth(resolution.unwrap_or(50)),
        _ => return None,
    })
}

/// The resolution a scene takes when none is given and its smallest: the cloth's side, the
/// flag's width, the rope's links, the blob's cells, the balloon's subdivisions; `None` for an
/// unknown name.
#[must_use]
pub fn resolution_range(name: &str) -> Option<(usize, usize)> {
    Some(match name {
        "cloth-drape" => (32, 2),
        "flag" => (24, 3),
        "rope" => (100, 2),
        "soft-blob" => (6, 2),
        "balloon" => (3, 0),
        "hanging-cloth" => (14, 2),
        "benchmark-cloth" => (50, 2),
        _ => return None,
    })
}

/// The resolution `n` of the scene `shape`, its default when `None` ([`resolution_range`]).
/// There is no upper bound here: the `pbd` kind's builder refuses a size whose memory
/// ([`crate::memory`]) the machine does not have before building.
fn resolution(shape: &'static str, n: Option<usize>) -> Result<usize, BuildError> {
    let (default, min) = resolution_range(shape).unwrap_or((2, 2));
    let n = n.unwrap_or(default);
    if n < min {
        return Err(BuildError::Input(InputError::BadParameter {
            shape,
            name: "resolution",
            requirement: "is below the scene's smallest (cloth, hanging cloth and rope 2, flag 3, blob 2)",
            value: n.to_string(),
        }));
    }
    Ok(n)
}

fn params(method: Method, solver: SolverKind, iterations: usize, substeps: usize) -> PbdParams {
    PbdParams::new(method, solver, iterations, substeps)
}

/// A 1.2 m square cloth of `n x n` particles (default 32), 0.3 kg, released flat 0.5 m above a
/// sphere of radius 0.35 m resting on the ground; it falls, drapes over the sphere and slides
/// until friction holds it. Rigid distance constraints, isometric bending with compliance 20
/// (bending stiffness 0.05 J).
///
/// # Errors
/// [`InputError::BadParameter`] for a resolution below 2.
pub fn cloth_drape(n: Option<usize>) -> Result<PbdScene, BuildError> {
    let n = resolution("cloth-drape", n)?;
    let mut b = PbdBuilder::new();
    b.gravity(EARTH_GRAVITY);
    b.cloth(&Cloth {
        nx: n,
        ny: n,
        origin: [-0.6, -0.6, 1.2],
        u: [1.2, 0.0, 0.0],
        v: [0.0, 1.2, 0.0],
        particle_mass: 0.3 / (n * n) as f64,
        stretch: ConstraintParams::rigid(),
        bending: Bending::Isometric(ConstraintParams::with_compliance(20.0)),
    })?;
    let thick = 0.01;
    b.collider(Collider::sphere([0.05, 0.0, 0.35], 0.35).with_thickness(thick).with_friction(0.6, 0.4));
    b.collider(Collider::ground(0.0).with_thickness(thick).with_friction(0.6, 0.4));
    let model = b.build()?;
    let state = model.rest_state();
    Ok(PbdScene {
        name: "cloth-drape",
        description: "a square cloth falls onto a sphere and drapes over it (XPBD, coloured Gauss-Seidel)",
        model,
        state,
        dt: 1.0 / 60.0,
        duration: 4.0,
        params: params(Method::Xpbd, SolverKind::ColoredGaussSeidel, 5, 4),
    })
}

/// The radius of the flag's pole (m).
pub const POLE_RADIUS: f64 = 0.025;

/// A 1.2 m x 0.8 m flag of `n x (2n/3)` particles (default 24), 0.15 kg/m^2, hanging from a pole
/// that sways 5 cm at 0.5 Hz: its pole-side column is attached (rigidly) to points of the pole,
/// a kinematic body. Gusty wind of 6 m/s blows along +x with a sideways component; dihedral
/// bending with compliance 5 (0.2 J/rad^2).
///
/// # Errors
/// [`InputError::BadParameter`] for a resolution below 3.
pub fn flag(n: Option<usize>) -> Result<PbdScene, BuildError> {
    let nx = resolution("flag", n)?;
    let nz = (2 * nx).div_ceil(3).max(2);
    let (width, height) = (1.2, 0.8);
    let mut b = PbdBuilder::new();
    b.gravity(EARTH_GRAVITY);
    // The pole, drawn from the ground to 5 cm above the flag: a 2.5 cm capsule whose surface
    // the attached edge (x = 0) touches.
    let pole = b.body(
        KinematicBody::new(
            Pose::from_translation([0.0, 0.0, 1.2]),
            BodyMotion::Oscillate { amplitude: [0.0, 0.05, 0.0], frequency: 0.5 },
        )
        .with_look(Shape::Capsule {
            a: [-POLE_RADIUS, 0.0, -1.2],
            b: [-POLE_RADIUS, 0.0, 0.85],
            radius: POLE_RADIUS,
        }),
    );
    let mass = 0.15 * width * height / (nx * nz) as f64;
    let cloth = b.cloth(&Cloth {
        nx,
        ny: nz,
        origin: [0.0, 0.0, 1.2],
        u: [width, 0.0, 0.0],
        v: [0.0, 0.0, height],
        particle_mass: mass,
        stretch: ConstraintParams::rigid(),
        bending: Bending::Dihedral(ConstraintParams::with_compliance(5.0)),
    })?;
    for iz in 0..nz {
        let local = [0.0, 0.0, height * iz as f64 / (nz - 1) as f64];
        b.attach(cloth.at(0, iz), AttachTarget::Body { body: pole, local }, 0.0, ConstraintParams::rigid());
    }
    b.wind(Wind { velocity: [6.0, 1.5, 0.0], drag: 0.6, gust: 0.4 });
    b.collider(Collider::ground(0.0).with_thickness(0.01).with_friction(0.5, 0.3));
    let model = b.build()?;
    let state = model.rest_state();
    Ok(PbdScene {
        name: "flag",
        description: "a flag on a swaying pole flaps in gusty wind (XPBD, dihedral bending)",
        model,
        state,
        dt: 1.0 / 60.0,
        duration: 6.0,
        params: params(Method::Xpbd, SolverKind::ColoredGaussSeidel, 8, 2),
    })
}

/// A 2 m rope of `links` links (default 100), 0.2 kg, held horizontally at 1.5 m and pinned at
/// one end; it swings down, wraps over a horizontal capsule and lands on a box. Rigid distance
/// constraints, solved with "small steps" (16 substeps of 2 iterations).
///
/// # Errors
/// [`InputError::BadParameter`] for fewer than 2 links.
pub fn rope(links: Option<usize>) -> Result<PbdScene, BuildError> {
    let links = resolution("rope", links)?;
    let mut b = PbdBuilder::new();
    b.gravity(EARTH_GRAVITY);
    let r = b.chain(&Chain {
        count: links + 1,
        start: [0.0, 0.0, 1.5],
        end: [2.0, 0.0, 1.5],
        mass: 0.2 / (links + 1) as f64,
        stretch: ConstraintParams::rigid(),
    })?;
    b.pin(r.start);
    let thick = 0.01;
    b.collider(
        Collider::capsule([0.7, -0.5, 0.9], [0.7, 0.5, 0.9], 0.08)
            .with_thickness(thick)
            .with_friction(0.3, 0.2),
    );
    b.collider(
        Collider::cuboid([0.9, 0.0, 0.15], [0.25, 0.4, 0.15]).with_thickness(thick).with_friction(0.5, 0.4),
    );
    b.collider(Collider::ground(0.0).with_thickness(thick).with_friction(0.5, 0.4));
    let model = b.build()?;
    let state = model.rest_state();
    Ok(PbdScene {
        name: "rope",
        description: "a rope of 100 links swings down over a capsule onto a box (XPBD, small steps)",
        model,
        state,
        dt: 1.0 / 60.0,
        duration: 5.0,
        params: params(Method::Xpbd, SolverKind::GaussSeidel, 2, 16),
    })
}

/// A bunny-like soft blob (body, head, ears, tail) of radius 0.25 m tetrahedralised on a grid of
/// `cells` cells across the body (default 6), density 100 kg/m^3, tilted and dropped from 0.4 m
/// onto the ground. Rigid tetrahedral volumes, compliant edges (`alpha = 2e-4` m/N), restitution
/// 0.3, friction 0.6.
///
/// # Errors
/// [`InputError::BadParameter`] for a resolution below 2.
pub fn soft_blob(cells: Option<usize>) -> Result<PbdScene, BuildError> {
    let cells = resolution("soft-blob", cells)?;
    let (pos, tets) = crate::shapes::tet_blob([0.0, 0.0, 0.0], 0.25, cells);
    let rot = DQuat::from_axis_angle(DVec3::new(1.0, 0.5, 0.0).normalize(), 0.5);
    let lift = DVec3::new(0.0, 0.0, 0.75);
    let pos: Vec<[f64; 3]> = pos.iter().map(|&p| (rot * DVec3::from_array(p) + lift).to_array()).collect();
    let mut b = PbdBuilder::new();
    b.gravity(EARTH_GRAVITY);
    b.tet_mesh(
        &pos,
        &tets,
        &TetMeshParams {
            mass: MeshMass::Density(100.0),
            stretch: Some(ConstraintParams::with_compliance(2e-4)),
            volume: Some(ConstraintParams::rigid()),
        },
    )?;
    b.collider(Collider::ground(0.0).with_friction(0.6, 0.5).with_restitution(0.3));
    let model = b.build()?;
    let state = model.rest_state();
    Ok(PbdScene {
        name: "soft-blob",
        description: "a bunny-like tetrahedral blob drops on the ground and bounces (XPBD tet volumes)",
        model,
        state,
        dt: 1.0 / 60.0,
        duration: 3.0,
        params: params(Method::Xpbd, SolverKind::ColoredGaussSeidel, 5, 4),
    })
}

/// A balloon: an icosphere of radius 0.3 m subdivided `s` times (default 3: 642 particles),
/// 0.05 kg, inflated to 1.5 times its volume by a global volume constraint, dropped from 1 m
/// onto a box. Soft edges (`alpha = 1e-3` m/N), soft isometric bending.
///
/// # Errors
/// A [`BuildError`] of the builder; any subdivision count is taken (the `pbd` kind checks the
/// memory it needs first).
pub fn balloon(s: Option<usize>) -> Result<PbdScene, BuildError> {
    let s = resolution("balloon", s)?;
    let (unit, tris) = crate::shapes::icosphere(s);
    let pos: Vec<[f64; 3]> =
        unit.iter().map(|&p| (DVec3::from_array(p) * 0.3 + DVec3::new(0.0, 0.0, 1.0)).to_array()).collect();
    let mut b = PbdBuilder::new();
    b.gravity(EARTH_GRAVITY);
    let r = b.triangle_mesh(
        &pos,
        &tris,
        &MeshParams {
            mass: MeshMass::PerVertex(0.05 / pos.len() as f64),
            stretch: ConstraintParams::with_compliance(1e-3),
            bending: Bending::Isometric(ConstraintParams::with_compliance(50.0)),
        },
    )?;
    let shifted: Vec<[usize; 3]> = tris.iter().map(|t| t.map(|i| r.start + i)).collect();
    b.global_volume(&shifted, 1.5, ConstraintParams::rigid());
    b.collider(
        Collider::cuboid([0.1, 0.0, 0.2], [0.3, 0.3, 0.2]).with_friction(0.5, 0.4).with_restitution(0.2),
    );
    b.collider(Collider::ground(0.0).with_friction(0.5, 0.4));
    let model = b.build()?;
    let state = model.rest_state();
    Ok(PbdScene {
        name: "balloon",
        description: "an inflated balloon (global volume constraint) drops onto a box",
        model,
        state,
        dt: 1.0 / 60.0,
        duration: 3.0,
        params: params(Method::Xpbd, SolverKind::ColoredGaussSeidel, 5, 4),
    })
}

/// The hanging cloth of the report's work-precision studies (`pbd-cloth-position`,
/// `pbd-cloth-constraint`): a 0.5 m square of `n x n` particles (default 14), 0.1 kg, in the
/// horizontal plane `z = 1`, pinned at the two corners of one edge; stiff distances
/// (compliance 1e-7 m/N, PBD stiffness 1) and soft isometric bending (compliance 5, PBD
/// stiffness 0.1), so that both PBD and XPBD run it. Steps of 1/60 s over 0.5 s, XPBD with
/// sequential Gauss-Seidel, 1 iteration x 8 substeps.
///
/// # Errors
/// [`InputError::BadParameter`] for a resolution below 2.
pub fn hanging_cloth(n: Option<usize>) -> Result<PbdScene, BuildError> {
    let n = resolution("hanging-cloth", n)?;
    let mut b = PbdBuilder::new();
    b.gravity(EARTH_GRAVITY);
    let c = b.cloth(&Cloth {
        nx: n,
        ny: n,
        origin: [0.0, 0.0, 1.0],
        u: [0.5, 0.0, 0.0],
        v: [0.0, 0.5, 0.0],
        particle_mass: 0.1 / (n * n) as f64,
        stretch: ConstraintParams::with_compliance(1e-7),
        bending: Bending::Isometric(ConstraintParams::with_compliance(5.0).stiffness(0.1)),
    })?;
    b.pin(c.at(0, 0)).pin(c.at(n - 1, 0));
    let model = b.build()?;
    let state = model.rest_state();
    Ok(PbdScene {
        name: "hanging-cloth",
        description: "the report's hanging cloth, pinned at two corners (XPBD, Gauss-Seidel)",
        model,
        state,
        dt: 1.0 / 60.0,
        duration: 0.5,
        params: params(Method::Xpbd, SolverKind::GaussSeidel, 1, 8),
    })
}

/// Parameters of [`benchmark_cloth`], shared with the peer scripts (`xtask/peers/pbd/`), which
/// must build the same cloth.
pub mod benchmark {
    /// Side length (m).
    pub const SIZE: f64 = 1.0;
    /// Mass of each particle (kg; pyPBD's default).
    pub const PARTICLE_MASS: f64 = 1.0;
    /// Distance compliance (m/N): pyPBD's XPBD stiffness 1e5.
    pub const STRETCH_COMPLIANCE: f64 = 1e-5;
    /// Isometric bending compliance: pyPBD's XPBD bending stiffness 50.
    pub const BENDING_COMPLIANCE: f64 = 0.02;
    /// Time step (s).
    pub const DT: f64 = 1.0 / 60.0;
}

/// The benchmark cloth: `n x n` particles in the horizontal plane `z = 0` (for `n = 100`: 29,601
/// distance and 29,205 isometric bending constraints), pinned at the two corners of one edge,
/// parameters in [`benchmark`], XPBD with 5 sequential Gauss-Seidel iterations.
///
/// # Errors
/// [`InputError::BadParameter`] for `n < 2`.
pub fn benchmark_cloth(n: usize) -> Result<PbdScene, BuildError> {
    use benchmark::*;
    let mut b = PbdBuilder::new();
    b.gravity(EARTH_GRAVITY);
    let c = b.cloth(&Cloth {
        nx: n,
        ny: n,
        origin: [0.0, 0.0, 0.0],
        u: [SIZE, 0.0, 0.0],
        v: [0.0, SIZE, 0.0],
        particle_mass: PARTICLE_MASS,
        stretch: ConstraintParams::with_compliance(STRETCH_COMPLIANCE),
        bending: Bending::Isometric(ConstraintParams::with_compliance(BENDING_COMPLIANCE)),
    })?;
    b.pin(c.at(0, 0)).pin(c.at(n - 1, 0));
    let model = b.build()?;
    let state = model.rest_state();
    Ok(PbdScene {
        name: "benchmark-cloth",
        description: "the benchmark cloth (XPBD, distance + isometric bending)",
        model,
        state,
        dt: DT,
        duration: 100.0 * DT,
        params: params(Method::Xpbd, SolverKind::GaussSeidel, 5, 1),
    })
}
