//! # anim-fluid
//!
//! Grid fluids: Jos Stam's stable fluids (Stam 1999, 2003) reproduced operation for operation,
//! and beside it a MAC-grid solver for 2D and 3D with better advection and pressure solvers.
//!
//! ## What it models
//!
//! The incompressible Navier-Stokes equations,
//! `div u = 0`, `du/dt = -(u . grad) u - grad p / rho + nu Lap u + f`, solved by the operator
//! splitting of Stam's stable fluids (1999) `w0 -(add force)-> w1 -(advect)-> w2 -(diffuse)-> w3 -(project)-> w4`, with a
//! density (smoke) carried by the flow. Two solvers:
//!
//! - [`stam`]: the C routines of Stam's *Real-Time Fluid Dynamics for Games* (GDC 2003) (`IX`, `add_source`, `set_bnd`, `lin_solve`
//!   with 20 Gauss-Seidel sweeps, `diffuse`, `advect`, `project`, `dens_step`, `vel_step`) on
//!   an `N x N` grid with a one-cell border, in `f32`, with the same operations in the same
//!   order: density and velocity are **identical to the last bit** to the C code compiled
//!   without contraction (unit tests against committed C output; `cargo xtask conformance`
//!   against the C transcription in `testdata/stable_fluids.c` at N = 64 and 128, 100 steps).
//! - [`mac`]: a staggered (MAC) grid in 2D or 3D (one code base), velocity advection by
//!   semi-Lagrangian steps with linear or monotone cubic interpolation, or BFECC / MacCormack
//!   with a limiter ([`advection`]); Stam's advect-then-project splitting or
//!   advection-reflection (Zehnder et al. 2018, [`advection::Splitting`]), second order in
//!   time; implicit viscosity; projection by Jacobi, red-black
//!   Gauss-Seidel, conjugate gradients or multigrid-preconditioned CG ([`pressure`]); solid
//!   obstacles, no-slip (moving), free-slip and open walls, inflow boxes; buoyant smoke
//!   (density and temperature) with vorticity confinement.
//!
//! [`pressure`] works on cells labelled fluid / air / solid, so a particle fluid (PIC, FLIP,
//! APIC) reuses it for its free-surface projection.
//!
//! ## Scenes
//!
//! [`KIND`] registers the crate's scenes with anim-core's scene contracts as the `fluid` kind
//! ([`kind`]): the presets `smoke-box-2d` (Stam's solver), `smoke-plume-3d` and
//! `lid-driven-cavity` (the MAC solver), built from their scene-file parameters
//! ([`kind::FluidSceneParams`]: preset, resolution, pressure solver and tolerance, advection,
//! splitting), checkpointed and drawn as density and velocity fields on an image grid. Without a
//! preset, a scene file builds a smoke scene of its own ([`smoke`]): the MAC solver on a box of
//! its size, with sources and obstacles of collider shapes or closed OBJ surfaces.
//!
//! ## Which solver
//!
//! | choice | when |
//! | --- | --- |
//! | [`stam::StamFluid`] | Stam's GDC 2003 solver exactly (games, previews); not divergence free (20 sweeps do not converge) |
//! | [`mac::MacFluid`] + [`pressure::PressureMethod::Mgpcg`] | whenever the flow must be incompressible to a tolerance; iterations nearly independent of resolution |
//! | [`pressure::PressureMethod::ConjugateGradient`] | small grids (below about 64^2), where multigrid's setup does not pay |
//! | Jacobi, red-black Gauss-Seidel | reference points of the work-precision study; only for loose tolerances on small grids |
//! | [`advection::Advection::MacCormack`] (default) / `Bfecc` | sharp smoke, little numerical viscosity (two extra semi-Lagrangian passes) |
//! | `Linear` | the cheapest, most diffusive; unconditionally stable at any CFL |
//! | `MonotoneCubic` | sharper than linear without over/undershoot, one pass with 4^d samples |
//!
//! ## Guarantees
//!
//! - `step` allocates nothing: every buffer is sized by the constructor (`tests/no_alloc.rs`
//!   counts the allocations of Stam and MAC steps, every pressure method and both splittings).
//! - Results are bitwise identical for any rayon thread count (every stage reads the previous
//!   stage's arrays only; red-black ordering; dot products summed over fixed chunks in order).
//! - Bad input (empty or 1-cell grids, `dt <= 0`, `h <= 0`, negative viscosity, non-finite
//!   forces, a moving wall with a normal velocity) is a [`FluidError`] naming the parameter;
//!   a step that produces NaN or infinity returns [`FluidError::NonFinite`] naming the step,
//!   field, cell, value and the cell's last finite value, and leaves the simulation bitwise as
//!   it was before the step (the state is copied aside into preallocated buffers first; for the
//!   MAC solver the warm-start pressure too). Every error message begins with `anim-fluid: `.
//! - **Checkpoints**: [`scenes::FluidScene::memory`] (built on [`stam::StamFluid::memory`],
//!   the serde [`mac::MacState`] and [`mac::MacFluid::memory`]) is everything a step reads
//!   (velocity, density, temperature, the warm-start pressure, step count, time) as a
//!   `serde_json` value; restoring it into a scene built the same way continues bit for bit,
//!   and a memory of another grid, solver or shape is a [`FluidError::Checkpoint`] naming the
//!   problem, never a panic.
//!
//! ## Speed
//!
//! Stam's solver on one thread against Stam's C code compiled with `cc -O3 -march=native`
//! (gcc 12.2; same source pattern, same 20 sweeps), per step, medians of 3 interleaved runs of
//! `examples/stam_timing.rs` and the C driver's `time` mode on this shared 2-core machine under
//! heavy load: N = 128: 40 ms against 69 ms (1.7x faster); N = 256: 83 against 139 ms (1.7x);
//! N = 512: 0.92 against 1.59 s (1.7x). An earlier, quieter run gave 15.5 / 33 ms, 71 / 132 ms
//! and 0.62 / 0.97 s (2.1x, 1.9x, 1.6x). The gain comes from the contiguous wavefront sweep of
//! [`stam::lin_solve`]: the same operands per cell, but no strided access and independent chains.
//! The failure guard (the six arrays copied aside before each step, so that a step producing
//! NaN can be undone) costs 8 us of a 4.0 ms step at N = 128, 0.13 ms of 27 ms at N = 256 and
//! 0.7 ms of 184 ms at N = 512 (0.2-0.5%; medians of 3 runs of `examples/stam_timing.rs`, which
//! times the same copies).
//! `cargo xtask bench --peers` repeats the comparison (in one loaded run it measured 5.3x, 2.8x
//! and 2.6x at N = 128, 256, 512), adds MGPCG against red-black Gauss-Seidel at equal residual
//! and Taichi's stable-fluids example (512 x 512, 500 Jacobi iterations: 477 ms per step on one
//! thread against 726 ms for our Stam mode in the same run; Taichi's vectorised Jacobi sweeps
//! beat the inherently sequential Gauss-Seidel chains of Stam's solver).
//!
//! ## Accuracy (measured here)
//!
//! - **Taylor-Green** vortex (unit box, free-slip walls, `nu = 0.01`, t = 1): the amplitude's
//!   relative error against `exp(-2 nu pi^2 t)` at N = 128.
//!   - Advect-then-project, CFL 0.5: 0.78% with monotone cubic, BFECC and MacCormack, 2.9%
//!     with linear semi-Lagrangian advection. The second-order schemes' error is the
//!     first-order splitting of advection and projection, about `2 dt` whatever N. Linear
//!     interpolation adds a numerical viscosity `h^2 alpha (1 - alpha) / (2 dt)` that falls as
//!     the CFL number grows while the splitting error rises: under this splitting linear is
//!     within 2% at N = 128 at no CFL from 0.25 to 4 (best 2.66% at CFL 1).
//!   - Advection-reflection removes the splitting error: at CFL 2, 0.012-0.013% with the three
//!     higher-order schemes and 1.14% with linear (0.60% at CFL 4), for two projections per
//!     step (table in `docs/guides/anim-fluid.md`, `examples/taylor_green_cfl.rs`).
//! - **Lid-driven cavity**, Re = 100, run to steady state, max error over Ghia, Ghia and Shin's
//!   (1982) centreline points (u on x = 0.5 / v on y = 0.5): N = 32: linear 0.021 / 0.022,
//!   cubic 0.0092 / 0.0080, BFECC 0.011 / 0.0066, MacCormack 0.011 / 0.0071; N = 64: linear
//!   0.012 / 0.0074, cubic 0.0031 / 0.0053, BFECC 0.0025 / 0.0056, MacCormack 0.0027 / 0.0055;
//!   N = 128, MacCormack: 0.0027 / 0.0074.
//! - **Projection**: every solver reaches its relative residual tolerance; on the 2D 64^2 box
//!   with a sphere at 1e-6: Jacobi 30,890 sweeps, red-black Gauss-Seidel 13,170, CG 304,
//!   MGPCG 8 iterations; at 256^2: Jacobi 428,490 sweeps (254 s on a loaded machine),
//!   Gauss-Seidel 184,490, CG 1,191, MGPCG 8 (0.44 s). Jacobi's count grows as `N^2`
//!   ([`pressure::JACOBI_WEIGHT`]).
//! - **Pressure solvers at N = 512** (the same box, the solve alone): to a relative residual of
//!   1e-2 MGPCG takes 4 iterations (0.11 s) where 4,000 red-black Gauss-Seidel sweeps (6.0 s)
//!   only reach 2.3e-2: more than 53x; to 1e-4, 6 iterations (0.094 s) against more than 8.9 s,
//!   more than 95x. At the loose residual 20 sweeps leave (0.31), 20 sweeps (0.09 s) are cheaper
//!   than one MGPCG iteration (0.18 s); a later set of three loaded runs gave medians of 0.054 s
//!   for the sweeps against 0.052 s for the iteration, and 0.21 s for MGPCG to 1e-4 against
//!   Gauss-Seidel short of it after 49 to 76 s (at least 236x).
//!
//! ## Precision
//!
//! The Stam mode is `f32` (as Stam's C code). The MAC solver is `f64`: its conformance cases ask for
//! relative pressure residuals down to 1e-10 (Taylor-Green), beyond what `f32` sums reach on
//! 128^2 grids.
//!
//! ## Example
//!
//! ```
//! use anim_core::solver::Solver;
//! use anim_fluid::advection::Advection;
//! use anim_fluid::mac::{MacFluid, MacParams, Wall};
//! use anim_fluid::pressure::PressureMethod;
//!
//! // A 32 x 32 lid-driven cavity at Re = 100.
//! let mut walls = [[Wall::NoSlip([0.0; 3]); 2]; 3];
//! walls[1][1] = Wall::NoSlip([1.0, 0.0, 0.0]);
//! let params = MacParams {
//!     viscosity: 0.01,
//!     advection: Advection::MacCormack,
//!     pressure: PressureMethod::Mgpcg,
//!     pressure_tolerance: 1e-8,
//!     walls,
//!     ..MacParams::default()
//! };
//! let (mut fluid, mut state) = MacFluid::new([32, 32, 1], 2, 1.0 / 32.0, params)?;
//! for _ in 0..10 {
//!     let report = fluid.step(&mut state, 1.0 / 32.0)?;
//!     assert!(report.residual.is_some_and(|r| r <= 1e-8));
//! }
//! // The lid drags the fluid to the right just below it.
//! assert!(fluid.velocity_at_point(&state, [0.5, 0.95, 0.0])[0] > 0.1);
//! # Ok::<(), anim_fluid::FluidError>(())
//! ```

pub mod advection;
#[cfg(feature = "cases")]
pub mod cases;
pub mod error;
pub mod kind;
pub mod mac;
pub mod memory;
pub mod pressure;
pub mod scenes;
pub mod smoke;
pub mod stam;

pub use error::FluidError;
pub use kind::KIND;
