//! An incompressible particle fluid: PIC, FLIP and APIC on a staggered (MAC) grid with a
//! free-surface pressure projection, in 2D and 3D.
//!
//! APIC (Jiang et al. 2015) as a fluid solver: the grid velocity, then a Chorin-style pressure
//! projection `v^{n+1} = Project(v^^{n+1})`; particles carry the fluid (velocity `v_p` and the
//! affine matrix `C_p`), the grid enforces incompressibility. One substep:
//!
//! ```text
//! P2G     u_i  = sum_p w_ip (v_p + C_p (x_i - x_p)) / sum_p w_ip      (per face component)
//! forces  u_i += dt g,  u = 0 on faces touching a solid
//! project u   -= grad s,  A s = -h div u over fluid cells, s = 0 in air  (free surface)
//! G2P     v_p  = sum_i w_ip u_i                    (PIC; FLIP adds the change; APIC also C_p)
//!         C_p  = D_p^-1 sum_i w_ip u_i (x_i - x_p)^T,  D_p^-1 = 4/h^2 (quadratic B-spline)
//! advect  x_p += dt u(x_p + dt/2 u(x_p))   (midpoint rule through the projected grid field,
//!                                           u read multilinearly between the faces)
//! ```
//!
//! The B-splines do not interpolate, so the faces behind the box walls hold the mirror image of
//! the faces in front with opposite sign, and a kernel sample at a wall has zero normal velocity.
//!
//! Choices that depart from the plain APIC step, switchable in [`FlipParams`]: positions are
//! advected through the divergence-free grid velocity (`grid_advection`, default on; off gives
//! the plain `x_p += dt v_p`), read multilinearly between the faces (`advection_sampling`,
//! [`Sampling::Linear`], default; [`Sampling::Kernel`] reads it with the transfer's kernel), and
//! an optional volume correction (`volume_correction`) adds a target outflow in cells whose
//! particle density exceeds the rest density. Without it particles compressed in a violent flow
//! are never spread apart again: in the 2D collapse of a 0.25 x 0.5 m column on a 32^2 grid the
//! density-based volume estimate falls by about 30% over 10 s. With `volume_correction = 1` it
//! ends within 0.2%, and its largest drop over the 10 s is below 1% (FLIP and APIC at CFL 1, PIC
//! at CFL 0.5; `cargo xtask conformance --filter anim-flip`).
//!
//! Optional reseeding ([`reseed`]) keeps every interior cell's particle count between bounds. It
//! is a sampling tool, not a volume fix: particles are the fluid's mass, and topping up cells that
//! sampling noise left sparse adds mass the volume correction then spreads out. In the sloshing
//! column above, bounds 2..8 per cell grew the fluid until it filled the box.
//!
//! Modules:
//! - [`particles`]: the particle arrays (structure of arrays) and their momenta;
//! - [`mac`]: the staggered grid, face layout and velocity extrapolation;
//! - [`classify`]: particle binning and fluid / air / solid cell labels;
//! - [`transfer`]: P2G and G2P by [`Transfer::Pic`], [`Transfer::Flip`] (blend) and
//!   [`Transfer::Apic`] with the B-splines of [`anim_core::bspline`] (shared with `anim-mpm`);
//! - [`project`]: body forces, solid walls and the pressure projection through
//!   `anim_fluid::pressure` (MGPCG, CG, Gauss-Seidel, Jacobi);
//! - [`sim`]: [`FlipSimulation`] with CFL substeps, the non-finite guard and checkpoints, and
//!   optional wall-time measurement of each substep's parts ([`StepTimes`]: transfer,
//!   projection, advection, other; [`FlipSimulation::set_timing`], off by default);
//! - [`reseed`]: optional per-cell particle count control after advection ([`Reseed`] in
//!   [`FlipParams::reseed`]): sparse interior cells topped up, crowded cells thinned;
//! - [`surface`]: a surface for output, [`ParticleSurface`]: Zhu & Bridson's particle level set
//!   on a lattice, meshed by marching squares ([`Contour`]) in 2D and naive surface nets
//!   ([`Mesh`], through the `fast-surface-nets` crate) in 3D;
//! - [`tank`]: [`TankMotion`], a tank shaken or accelerated along one axis, simulated in its
//!   own frame (body force `g - a_tank(t)`, `FlipParams::tank_motion`);
//! - [`scenes`]: seeding ([`scenes::fill_box`], [`scenes::fill_region`]), still water, the dam
//!   break in 2D ([`scenes::dam_break`]) and 3D ([`scenes::dam_break_3d`], and the benchmark
//!   block [`scenes::benchmark_dam_break_3d`]: `n^3 / 2` particles), a rotating disk, a
//!   drop falling into a pool ([`scenes::drop_into_pool`], 2D and 3D), a sloshing tank
//!   ([`scenes::sloshing_tank`], 2D and 3D), and the presets of the `anim` command
//!   ([`scenes::by_name`]: `dam-break-2d`, `dam-break-3d`, `drop-2d`, `drop-3d`,
//!   `sloshing-tank`);
//! - [`kind`]: [`KIND`], the presets as the `flip` scene kind of anim-core's scene contracts;
//! - [`body`]: fluid bodies (shapes and closed OBJ surfaces, placed, moving) and obstacles of a
//!   `flip` scene file, seeded on the presets' lattice ([`body::build`], [`body::BodyScene`]);
//! - [`error`]: the error type [`FlipError`].
//!
//! [`KIND`] registers the presets `dam-break-2d`, `dam-break-3d`, `drop-2d`, `drop-3d` and
//! `sloshing-tank` as the `flip` scene kind ([`kind`]): built from their scene-file parameters
//! ([`kind::FlipSceneParams`]: preset, resolution, transfer, or bodies of fluid and obstacles
//! instead of a preset, [`body`]), checkpointed, and drawn as particles in the world frame, y
//! up as the solver works, with the tank as a prop.
//!
//! The sloshing tank's first mode oscillates with the period of linear theory,
//! `omega^2 = g k tanh(k d)`, to within 3.3% at 64 cells per metre (`tests/scenes.rs`; the
//! error, +3% to +4% at 48 and 64 cells, is the free surface's cell granularity); a wave lower
//! than about a cell is not seen by the projection at all.
//!
//! Everything runs in f64; P2G is a gather over particles binned by cell, so every sum has a
//! fixed order and results are bitwise identical for any number of rayon threads.
//!
//! # Example
//!
//! ```
//! use anim_flip::{FlipParams, scenes};
//!
//! // Still water in a 16 x 16 box stays (nearly) at rest under gravity.
//! let (mut sim, mut particles) = scenes::still_water::<2>(16, FlipParams::default())?;
//! for _ in 0..10 {
//!     let info = sim.advance(&mut particles, 0.01)?;
//!     assert!(info.max_divergence < 1e-4);
//! }
//! assert!(particles.max_speed() < 0.05);
//! # Ok::<(), anim_flip::FlipError>(())
//! ```

pub mod body;
#[cfg(feature = "cases")]
pub mod cases;
pub mod classify;
pub mod error;
pub mod kind;
pub mod mac;
pub mod memory;
pub mod particles;
pub mod project;
pub mod reseed;
pub mod scenes;
pub mod sim;
pub mod surface;
pub mod tank;
pub mod transfer;

#[cfg(test)]
mod tests;

pub use error::FlipError;
pub use kind::KIND;
pub use particles::Particles;
pub use reseed::Reseed;
pub use sim::{FlipParams, FlipSimulation, Sampling, StepInfo, StepTimes};
pub use surface::{Contour, Mesh, ParticleSurface, SurfaceParams};
pub use tank::TankMotion;
pub use transfer::Transfer;
