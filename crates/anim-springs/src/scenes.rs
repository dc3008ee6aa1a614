//! Ready-to-run scenes: everything a caller (the `anim` command line, an example, a benchmark)
//! needs to simulate one, with the integrator and linear solver that suit it.
//!
//! | scene | what | integrator | linear solver | why |
//! | --- | --- | --- | --- | --- |
//! | [`hanging_cloth`] | a horizontal square cloth pinned at two corners falls and swings | linearised backward Euler, `dt = 1/100` s | sparse Cholesky (faer) | stiff structural springs: explicit methods would need `dt ~ 1e-4` s; measured on the 32 x 32 cloth (`examples/solver_choice.rs`): Cholesky 4.7 ms/step, Jacobi-PCG 12 ms/step (290 iterations to 1e-6), assembled Jacobi-PCG 47 ms/step, Jacobi and Gauss-Seidel do not reach 1e-6 in 5000 sweeps |
//! | [`swinging_rope`] | a horizontal rope pinned at one end swings down | velocity Verlet, `dt = 5e-4` s | none | soft springs: a symplectic explicit method is cheap and keeps the energy |
//! | [`jelly_drop`] | a tilted jelly cube falls on the ground and bounces | linearised backward Euler, `dt = 1/200` s | sparse Cholesky (faer) | contact stiffness plus a small system: a direct solve is exact and fast |
//! | [`benchmark_cloth`] | the `n x n` cloth of the benches and the Taichi comparison | symplectic Euler, `dt = 2e-5` s | none | the method Taichi's mass-spring examples use |
//!
//! Implicit scenes take one Newton iteration per step, the linearised backward Euler of Baraff and
//! Witkin (1998) (see [`animation_newton`]). All scenes are z-up with gravity [`EARTH_GRAVITY`]. The resolution argument scales the particle
//! count; `None` takes the scene's default.
//!
//! ```
//! use anim_springs::scenes;
//! use anim_core::solver::Solver;
//!
//! let scene = scenes::hanging_cloth(Some(8))?;
//! let (mut sim, mut state) = scene.into_simulation()?;
//! let report = sim.step(&mut state, 0.01)?;
//! assert!(report.energy.is_some());
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use crate::build::{Chain, Cloth, EARTH_GRAVITY, Lattice, NetworkBuilder, SpringParams};
use crate::contact::Collider;
use crate::error::{BuildError, InputError};
use crate::network::SpringNetwork;
use crate::sim::{SpringError, SpringSimulation};
use anim_core::glam::{DQuat, DVec3};
use anim_core::integrate::{IntegratorKind, NewtonParams, State};
use anim_core::linalg::{IterativeParams, LinearSolverKind};

/// A scene: the network, its initial state and how to step it.
#[derive(Debug, Clone)]
pub struct SpringScene {
    /// Short name ("hanging-cloth").
    pub name: &'static str,
    /// One-line description.
    pub description: &'static str,
    /// The network (model and scratch).
    pub network: SpringNetwork,
    /// Initial state.
    pub state: State,
    /// Suggested time step (s).
    pub dt: f64,
    /// Suggested simulated duration (s).
    pub duration: f64,
    /// Suggested integrator.
    pub integrator: IntegratorKind,
    /// Linear solver for implicit integrators.
    pub linear_solver: LinearSolverKind,
    /// Newton parameters for implicit integrators.
    pub newton: NewtonParams,
}

impl SpringScene {
    /// A simulation with the scene's integrator and solver, and the initial state.
    ///
    /// # Errors
    /// [`SpringError::BadIntegrator`] if the integrator was changed to an invalid one.
    pub fn into_simulation(self) -> Result<(SpringSimulation, State), SpringError> {
        let sim = SpringSimulation::new(self.network, self.integrator, self.newton, self.linear_solver)?;
        Ok((sim, self.state))
    }

    /// Number of steps of `dt` covering `duration`.
    #[must_use]
    pub fn steps(&self) -> usize {
        (self.duration / self.dt).round().max(1.0) as usize
    }
}

/// The built-in scene names, for command lines.
pub const NAMES: [&str; 4] = ["hanging-cloth", "swinging-rope", "jelly-drop", "benchmark-cloth"];

/// Builds a scene by name (see [`NAMES`]); `None` for an unknown name.
#[must_use]
pub fn by_name(name: &str, resolution: Option<usize>) -> Option<Result<SpringScene, BuildError>> {
    Some(match name {
        "hanging-cloth" => hanging_cloth(resolution),
        "swinging-rope" => swinging_rope(resolution),
        "jelly-drop" => jelly_drop(resolution),
        "benchmark-cloth" => benchmark_cloth(resolution.unwrap_or(128)),
        _ => return None,
    })
}

/// The resolution a scene takes when none is given and its smallest: particles per side (of
/// the rope: particles), `None` for an unknown name.
#[must_use]
pub fn resolution_range(name: &str) -> Option<(usize, usize)> {
    Some(match name {
        "hanging-cloth" => (32, 2),
        "swinging-rope" => (40, 3),
        "jelly-drop" => (6, 2),
        "benchmark-cloth" => (128, 2),
        _ => return None,
    })
}

/// The integrator and linear solver a scene suggests, `None` for an unknown name.
#[must_use]
pub fn method(name: &str) -> Option<(IntegratorKind, LinearSolverKind)> {
    Some(match name {
        "hanging-cloth" | "jelly-drop" => (IntegratorKind::BackwardEuler, LinearSolverKind::Cholesky),
        "swinging-rope" => (IntegratorKind::VelocityVerlet, LinearSolverKind::Cg),
        "benchmark-cloth" => (IntegratorKind::SymplecticEuler, LinearSolverKind::JacobiPcg),
        _ => return None,
    })
}

/// Newton settings for animation: the linearised implicit step (one Newton iteration,
/// `[M - h^2 K(x0) - h D(x0)] dv = h f(x0) + h^2 K v0`, Baraff and Witkin's scheme), with the
/// linear solve to a relative residual of `1e-6`.
///
/// Why not Newton to convergence: even with anim-core's line search (on the residual norm), full
/// Newton on a cloth that folds, with compressed springs whose definite Jacobian drops their
/// transverse stiffness, can stall (the hanging cloth at `dt = 0.01` s does after about half a
/// second), and each step costs several linear solves. One iteration of the linearised step is
/// Baraff and Witkin's scheme as published, is stable at large steps, and costs one solve.
#[must_use]
pub fn animation_newton() -> NewtonParams {
    let mut p = NewtonParams::linearized();
    p.linear = IterativeParams::new(1e-6, 5000);
    p
}

/// The resolution `n` of the scene `shape`, its default when `None` ([`resolution_range`]).
/// There is no upper bound here: the `springs` kind's builder refuses a size whose memory
/// ([`crate::memory`]) the machine does not have before building.
fn resolution(shape: &'static str, n: Option<usize>) -> Result<usize, BuildError> {
    let (default, min) = resolution_range(shape).unwrap_or((2, 2));
    let n = n.unwrap_or(default);
    if n < min {
        return Err(BuildError::Input(InputError::BadParameter {
            shape,
            name: "resolution",
            requirement: "must be at least 2 for cloth and jelly, 3 for the rope",
            value: n.to_string(),
        }));
    }
    Ok(n)
}

/// A 1 m square cloth of `n x n` particles (default 32) lying flat at height 1 m, pinned at the
/// two corners of one edge; it falls and swings down under gravity. Total mass 0.2 kg;
/// structural, shear and bending springs of stiffness 1000, 200 and 20 N/m with light damping.
///
/// # Errors
/// [`InputError::BadParameter`] for a resolution below 2.
pub fn hanging_cloth(n: Option<usize>) -> Result<SpringScene, BuildError> {
    let n = resolution("hanging-cloth", n)?;
    let mut b = NetworkBuilder::new();
    b.gravity(EARTH_GRAVITY);
    let r = b.cloth(&Cloth {
        nx: n,
        ny: n,
        origin: [0.0, 0.0, 1.0],
        u: [1.0, 0.0, 0.0],
        v: [0.0, 1.0, 0.0],
        mass: 0.2,
        structural: SpringParams::new(1000.0, 0.02),
        shear: Some(SpringParams::new(200.0, 0.004)),
        bending: Some(SpringParams::new(20.0, 0.0004)),
    })?;
    b.pin(r.start).pin(r.start + n - 1);
    let network = b.build()?;
    let state = network.rest_state();
    Ok(SpringScene {
        name: "hanging-cloth",
        description: "a square cloth pinned at two corners falls and swings (backward Euler, sparse Cholesky)",
        network,
        state,
        dt: 0.01,
        duration: 3.0,
        integrator: IntegratorKind::BackwardEuler,
        linear_solver: LinearSolverKind::Cholesky,
        newton: animation_newton(),
    })
}

/// A 1 m rope of `n` particles (default 40) held horizontally at height 1 m, pinned at one end,
/// released to swing like a pendulum. Total mass 0.1 kg, springs of 200 N/m.
///
/// # Errors
/// [`InputError::BadParameter`] for a resolution below 3.
pub fn swinging_rope(n: Option<usize>) -> Result<SpringScene, BuildError> {
    let n = resolution("swinging-rope", n)?;
    let mut b = NetworkBuilder::new();
    b.gravity(EARTH_GRAVITY);
    let mass = 0.1 / n as f64;
    let k = 200.0 * (n - 1) as f64 / 39.0;
    let r = b.chain(&Chain {
        count: n,
        start: [0.0, 0.0, 1.0],
        end: [1.0, 0.0, 1.0],
        mass,
        spring: SpringParams::new(k, 0.001),
    })?;
    b.pin(r.start);
    let network = b.build()?;
    let state = network.rest_state();
    // Velocity Verlet is stable for dt < sqrt(m / k) on a chain; take a fifth of that.
    let dt = 0.2 * (mass / k).sqrt();
    Ok(SpringScene {
        name: "swinging-rope",
        description: "a rope pinned at one end swings down (velocity Verlet)",
        network,
        state,
        dt,
        duration: 3.0,
        integrator: IntegratorKind::VelocityVerlet,
        linear_solver: LinearSolverKind::Cg,
        newton: animation_newton(),
    })
}

/// A jelly cube of `n^3` particles (default 6), edge 0.25 m, mass 1 kg, tilted by 0.4 rad and
/// dropped from 0.5 m onto the ground plane `z = 0` (penalty contact with friction). Springs
/// along the edges, face diagonals and body diagonals.
///
/// # Errors
/// [`InputError::BadParameter`] for a resolution below 2.
pub fn jelly_drop(n: Option<usize>) -> Result<SpringScene, BuildError> {
    let n = resolution("jelly-drop", n)?;
    let spacing = 0.25 / (n - 1) as f64;
    let mut b = NetworkBuilder::new();
    b.gravity(EARTH_GRAVITY);
    let k = 2000.0 * (n - 1) as f64 / 5.0;
    b.lattice(&Lattice {
        n: [n, n, n],
        origin: [0.0, 0.0, 0.0],
        spacing,
        mass: 1.0,
        edge: SpringParams::new(k, 0.05),
        face_diagonal: Some(SpringParams::new(k, 0.05)),
        body_diagonal: Some(SpringParams::new(k, 0.05)),
    })?;
    b.collider(Collider::ground(0.0, 2.0e4).with_damping(0.1).with_friction(1.0).with_smoothing(1e-3));
    let network = b.build()?;
    // Tilt about a horizontal axis through the centre and lift to 0.5 m.
    let mut state = network.rest_state();
    let center = DVec3::splat(0.125);
    let rot = DQuat::from_axis_angle(DVec3::new(1.0, 1.0, 0.0).normalize(), 0.4);
    let lift = DVec3::new(0.0, 0.0, 0.5);
    for p in state.x.chunks_exact_mut(3) {
        let q = rot * (DVec3::new(p[0], p[1], p[2]) - center) + center + lift;
        p.copy_from_slice(&q.to_array());
    }
    Ok(SpringScene {
        name: "jelly-drop",
        description: "a tilted jelly cube drops on the ground and bounces (backward Euler, sparse Cholesky)",
        network,
        state,
        dt: 0.005,
        duration: 2.0,
        integrator: IntegratorKind::BackwardEuler,
        linear_solver: LinearSolverKind::Cholesky,
        newton: animation_newton(),
    })
}

/// Parameters of [`benchmark_cloth`], shared with the Taichi peer script
/// (`xtask/peers/taichi_cloth.py`), which must build the same cloth.
pub mod benchmark {
    /// Side length (m).
    pub const SIZE: f64 = 1.0;
    /// Height of the cloth plane (m).
    pub const HEIGHT: f64 = 1.0;
    /// Total mass (kg).
    pub const MASS: f64 = 1.0;
    /// Structural stiffness (N/m).
    pub const K_STRUCTURAL: f64 = 1000.0;
    /// Shear stiffness (N/m).
    pub const K_SHEAR: f64 = 500.0;
    /// Bending stiffness (N/m).
    pub const K_BENDING: f64 = 200.0;
    /// Damping of every spring (N s/m).
    pub const DAMPING: f64 = 0.001;
    /// Time step of the symplectic Euler benchmark (s).
    pub const DT: f64 = 2e-5;
}

/// The benchmark cloth: `n x n` particles (128 gives 97,026 springs), parameters in
/// [`benchmark`], pinned at two corners, stepped with symplectic Euler.
///
/// # Errors
/// [`InputError::BadParameter`] for `n < 2`.
pub fn benchmark_cloth(n: usize) -> Result<SpringScene, BuildError> {
    use benchmark::*;
    let mut b = NetworkBuilder::new();
    b.gravity(EARTH_GRAVITY);
    let r = b.cloth(&Cloth {
        nx: n,
        ny: n,
        origin: [0.0, 0.0, HEIGHT],
        u: [SIZE, 0.0, 0.0],
        v: [0.0, SIZE, 0.0],
        mass: MASS,
        structural: SpringParams::new(K_STRUCTURAL, DAMPING),
        shear: Some(SpringParams::new(K_SHEAR, DAMPING)),
        bending: Some(SpringParams::new(K_BENDING, DAMPING)),
    })?;
    b.pin(r.start).pin(r.start + n - 1);
    let network = b.build()?;
    let state = network.rest_state();
    Ok(SpringScene {
        name: "benchmark-cloth",
        description: "the benchmark cloth (symplectic Euler)",
        network,
        state,
        dt: DT,
        duration: 200.0 * DT,
        integrator: IntegratorKind::SymplecticEuler,
        linear_solver: LinearSolverKind::JacobiPcg,
        newton: animation_newton(),
    })
}
