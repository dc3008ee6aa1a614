//! # anim-core
//!
//! The shared vocabulary of the anim workspace: the math every solver crate builds on, and the
//! traits through which `cargo xtask` drives every crate the same way.
//!
//! | module | what it models | method / source |
//! | --- | --- | --- |
//! | [`lie`] | SO(3)/so(3) hat, vee, exp (Rodrigues), log; SE(3), twists, their exp/log, adjoints, screws | Murray, Li & Sastry 1994; Lynch & Park 2017 |
//! | [`linalg`] | linear operators, CG / Jacobi-PCG, Jacobi and Gauss-Seidel, CSR matrices with faer interop, a sparse direct solve, the Schur-complement block solve, 3x3 SVD and polar decomposition | conjugate gradients, Schur complements (Zhang 2005), the rotation-variant SVD (Irving, Teran & Fedkiw 2004) |
//! | [`integrate`] | second-order systems `x'' = M^-1 f(x, v)` and their integrators: explicit, symplectic and backward Euler, the beta-blend, position Verlet, leapfrog, velocity Verlet, implicit midpoint and RK4 | linearised backward Euler (Baraff & Witkin 1998); Verlet; Runge-Kutta |
//! | [`solver`] | the time-stepping [`Solver`](solver::Solver) trait and the [`StepReport`](solver::StepReport) every step returns | - |
//! | [`scene`] | the contracts of a runnable scene: [`Checkpoint`](scene::Checkpoint), [`View`](scene::View), the object-safe [`DynScene`](scene::DynScene), and the [`SceneKind`](scene::SceneKind) and [`Preset`](scene::Preset) a crate registers; the scene-file fields every kind spells alike ([`Placement`](scene::Placement), [`PinSpec`](scene::PinSpec)) | - |
//! | [`geometry`] | the collider [`Shape`](geometry::Shape) every solver shares (plane, sphere, box, capsule) with its signed distance, and the closest point on a triangle | Ericson 2005 (5.1.5) |
//! | [`surface`] | a closed triangle surface ([`ClosedSurface`](surface::ClosedSurface)): its check, inside tests, lattice sampling and tetrahedralisation | generalized winding numbers (Jacobson et al. 2013) with Van Oosterom-Strackee solid angles; Kuhn's six tetrahedra per lattice cube |
//! | [`diagnostics`] | detection of non-finite state at the step that produced it | - |
//! | [`scalar`] | the [`Real`](scalar::Real) trait that lets kernels run in `f32` or `f64` | - |
//!
//! Precision: Lie-group and integrator code is `f64` (rigid-body and FEM accuracy oracles need it);
//! the 3x3 SVD is generic over [`Real`](scalar::Real) because MPM runs its particles in `f32`.
//!
//! ```
//! use anim_core::integrate::{Integrator, IntegratorKind, State, systems::HarmonicOscillator};
//!
//! // A unit harmonic oscillator, x'' = -x, advanced one period with velocity Verlet.
//! let mut system = HarmonicOscillator::new(1.0, 1.0);
//! let mut state = State::new(vec![1.0], vec![0.0]);
//! let mut integrator = IntegratorKind::VelocityVerlet.build(1);
//! let dt = 2.0 * std::f64::consts::PI / 1000.0;
//! for _ in 0..1000 {
//!     integrator.step(&mut system, &mut state, dt)?;
//! }
//! assert!((state.x[0] - 1.0).abs() < 1e-4);
//! # Ok::<(), anim_core::integrate::IntegrateError>(())
//! ```

pub mod alloc_count;
pub mod bspline;
#[cfg(feature = "cases")]
pub mod cases;
pub mod diagnostics;
pub mod geometry;
pub mod input;
pub mod integrate;
pub mod lie;
pub mod linalg;
pub mod par;
pub mod scalar;
pub mod scene;
pub mod solver;
pub mod surface;

pub use glam;

/// The code blocks of the workspace README, compiled and run as doc tests.
#[doc = include_str!("../../../README.md")]
#[cfg(doctest)]
pub struct ReadmeDoctests;
