//! # anim-springs
//!
//! Mass-spring systems: cloth, ropes and jelly made of point masses joined by
//! Hooke springs, stepped by every integrator of anim-core, in parallel and bitwise
//! deterministic for any thread count.
//!
//! ## What it models
//!
//! - **Particles** with a mass, pinned or free ([`Particle`]); positions and velocities live in
//!   anim-core's [`State`](anim_core::integrate::State) as `x = [x0, y0, z0, x1, ...]`.
//! - **Springs** `(i, j, l, k, c)` ([`Spring`]): Hooke's law plus damping along the
//!   spring,
//!
//!   ```text
//!   f_ij = -k (|x_i - x_j| - l) (x_i - x_j)/|x_i - x_j|  -  c ((v_i - v_j) . n) n,    f_i = sum_j f_ij
//!   ```
//!
//!   (Hooke's law, `f_i = sum_{j != i} f_ij`, `dv_i/dt = f_i / m_i`, `dx_i/dt = v_i`).
//! - **Gravity** and **colliders** (planes, spheres, axis-aligned boxes, capsules, and closed
//!   triangle meshes on a signed distance field, [`MeshCollider`]) as penalty forces with
//!   friction ([`contact`]).
//! - **Builders** ([`NetworkBuilder`]): a chain, a cloth grid with structural, shear and bending
//!   springs, a 3-D lattice with face and body diagonals, any triangle mesh (an edge spring per
//!   unique edge, optional bending springs across interior edges; [`TriangleMesh::from_obj`]
//!   reads OBJ files). Bad input is a [`BuildError`] naming the element, never a panic.
//! - **Scenes** ([`scenes`]): a hanging cloth, a swinging rope, a jelly cube dropped on the
//!   ground, and the benchmark cloth, each with its suggested integrator, solver and step.
//! - **Scene kind** ([`KIND`], kind `springs`): the scenes behind anim-core's scene contracts
//!   ([`anim_core::scene`]), with the presets `cloth` (the 32 x 32 hanging cloth), `rope` (the
//!   swinging rope) and `jelly` (the jelly drop) that the `anim` command line runs, and scene
//!   files of the user's own cloth and shells from OBJ surfaces among obstacles ([`body`]);
//!   [`SpringSimulation`] is a checkpointable, viewable solver ([`kind`]).
//!
//! [`SpringNetwork`] implements anim-core's [`SecondOrderSystem`](anim_core::integrate::SecondOrderSystem)
//! (for the explicit methods) and [`MechanicalSystem`](anim_core::integrate::MechanicalSystem) (for
//! the implicit ones): the 3x3 block force Jacobian `K_s = -k [(1 - l/L)(I - n n^T) + n n^T]`
//! with the definiteness fix for compressed springs, and `D_s = -c n n^T`, applied matrix-free,
//! as a diagonal, or assembled into a [`CsrMatrix`](anim_core::linalg::CsrMatrix) whose pattern is
//! built once ([`network`] explains the equations, the fix and the parallel scheme).
//! [`SpringSimulation`] couples a network with an integrator as anim-core's
//! [`Solver`](anim_core::solver::Solver), stops a diverging run at the step and spring that blew
//! up, and reports energy and momenta. A NaN or infinity is [`SpringError::NonFinite`], whose
//! message begins with `anim-springs: step N:` and names the particle, its component, the value
//! and the particle's last finite position or velocity; a failed step leaves the state and the
//! integrator's memory as they were.
//!
//! ## Which integrator, which solver
//!
//! Explicit methods are simple but "explode" when `dt` exceeds `c sqrt(m / k)` with
//! `c ~ 1`; implicit methods cost more per step and allow much larger steps. Measured by
//! `cargo xtask stability` on a hanging chain of 8 masses with damping ratio 0.05 as `k` sweeps
//! `1e2 .. 1e8` (the fitted `c` in `dt <= c sqrt(m/k)` with the per-particle `m` and per-spring
//! `k`; the fitted exponent of `sqrt(m/k)` is 0.996 to 0.999, 0.96 for explicit Euler):
//!
//! | integrator | order | measured `c` | use it for |
//! | --- | --- | --- | --- |
//! | explicit Euler | 1 | 0.10 in 20,000-step runs, 0.12 in 4,000 (theory `2 zeta = 0.1`; unstable at any `dt` without damping) | nothing but teaching: it gains energy |
//! | symplectic Euler | 1 | 0.95 | fast soft cloth and ropes at small `dt` (what Taichi's examples use) |
//! | position Verlet | 2 | 0.89 | soft ropes and cloth with good energy behaviour |
//! | leapfrog, velocity Verlet | 2 | 0.95 | soft ropes and cloth with good energy behaviour |
//! | RK4 | 4 | 1.62 (damping extends its undamped 1.41) | accurate reference runs of soft systems |
//! | backward Euler (beta = 1) | 1 | unconditional (stable at `omega dt = 1054`) | stiff cloth and jelly at animation frame rates (damps) |
//! | beta-blend(1/2) | 1 | unconditional in practice | less numerical damping than backward Euler |
//! | implicit midpoint | 2 | unconditional | stiff systems when energy must be kept |
//!
//! Implicit steps solve `(M - h^2 beta K - h beta D) dv = r` with Newton: Jacobi-preconditioned
//! CG (matrix-free, the default) is the fastest on cloth; sparse Cholesky is exact and robust on
//! small or stiff systems (contact); Jacobi and Gauss-Seidel sweeps work on the
//! assembled matrix but need many sweeps when `h^2 k / m` is large. `cargo xtask report` has the
//! work-precision curves of all of them on the cloth. For animation take one Newton iteration,
//! the linearised backward Euler of Baraff & Witkin 1998 ([`scenes::animation_newton`]): anim-core's Newton has no line
//! search, and full Newton on folding stiff cloth can stall.
//!
//! Orders measured on the two-particle spring (`cargo xtask conformance`): 1.02 explicit Euler,
//! 0.99 symplectic Euler, 0.98 backward Euler, 0.99 beta-blend(1/2), 2.00 position Verlet,
//! leapfrog, velocity Verlet and implicit midpoint, 3.99 RK4.
//!
//! ## Speed
//!
//! On the 128 x 128 benchmark cloth (97,026 springs, 2 cores): a force evaluation takes about
//! 0.5 ms, a symplectic Euler step about 0.65 ms, bitwise identical for 1, 2 or 4 threads. The
//! same step in Taichi 1.7.4 (CPU, f64, same thread count; `cargo xtask bench --peers`) takes
//! about 1.6 to 2.1 ms with a spring list and atomic adds, the data structure we use, and
//! about 0.52 ms with a hard-coded grid stencil that only works for grid cloth.
//!
//! ## Example
//!
//! ```
//! use anim_core::integrate::{IntegratorKind, NewtonParams};
//! use anim_core::linalg::LinearSolverKind;
//! use anim_springs::{Cloth, EARTH_GRAVITY, NetworkBuilder, SpringParams, SpringSimulation};
//!
//! // A 10 x 10 cloth pinned at two corners, released flat: backward Euler at 100 Hz.
//! let mut b = NetworkBuilder::new();
//! b.gravity(EARTH_GRAVITY);
//! let cloth = b.cloth(&Cloth {
//!     nx: 10,
//!     ny: 10,
//!     origin: [0.0, 0.0, 1.0],
//!     u: [1.0, 0.0, 0.0],
//!     v: [0.0, 1.0, 0.0],
//!     mass: 0.1,
//!     structural: SpringParams::new(500.0, 0.01),
//!     shear: Some(SpringParams::new(100.0, 0.0)),
//!     bending: None,
//! })?;
//! b.pin(cloth.start).pin(cloth.start + 9);
//! let network = b.build()?;
//! let mut state = network.rest_state();
//! let mut sim = SpringSimulation::new(
//!     network,
//!     IntegratorKind::BackwardEuler,
//!     NewtonParams::with_tolerance(1e-6),
//!     LinearSolverKind::JacobiPcg,
//! )?;
//! sim.run(&mut state, 0.01, 50)?;
//! // After half a second the free edge, 1 m from the pins, has swung down to the bottom of its arc.
//! let lowest = state.x.chunks_exact(3).map(|p| p[2]).fold(f64::INFINITY, f64::min);
//! assert!(lowest < 0.1, "lowest point {lowest}");
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! `examples/hanging_cloth.rs` runs the hanging-cloth scene and prints energy, momentum and
//! timings: `cargo run --release -p anim-springs --example hanging_cloth`.
//!
//! ## Precision
//!
//! Everything is `f64`: the springs are also the workspace's reference for implicit solvers, and
//! the benchmark shows the force evaluation is memory-bound, so `f32` would gain little.

pub mod analytic;
pub mod body;
mod build;
#[cfg(feature = "cases")]
pub mod cases;
pub mod contact;
mod error;
mod geom;
pub mod kind;
pub mod memory;
mod mesh;
pub mod network;
mod obstacles;
pub mod scenes;
mod sim;

pub use build::{Chain, Cloth, EARTH_GRAVITY, Lattice, MeshMass, MeshSprings, NetworkBuilder, SpringParams};
pub use contact::{Collider, MeshCollider, Shape};
pub use error::{BuildError, InputError};
pub use kind::KIND;
pub use mesh::TriangleMesh;
pub use network::{
    EnergyParts, JacobianMode, Particle, Spring, SpringKind, SpringModel, SpringNetwork, Stretch,
};
pub use sim::{DEFAULT_MAX_STRETCH, SpringError, SpringSimulation};

#[cfg(test)]
mod tests;
