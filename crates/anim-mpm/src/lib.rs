//! # anim-mpm
//!
//! The material point method: APIC (Jiang et al. 2015) and MLS-MPM (Hu et al. 2018) in 2D and 3D
//! from one code base (`const D: usize`), with elastic, snow, weakly compressible fluid and sand
//! materials on a sparse block grid; parallel with rayon and bitwise deterministic for any
//! number of threads.
//!
//! ## What it models
//!
//! Matter is a set of **particles** ([`Particles`]: position, velocity, the affine matrix `C_p`,
//! the deformation gradient `F_p`, a plastic scalar, mass, rest volume, material), carried
//! through a background **grid** each step (APIC, Jiang et al. 2015):
//!
//! ```text
//! P2G   m_i = sum_p w_ip m_p,   (m v)_i = sum_p w_ip [m_p v_p + m_p C_p (x_i - x_p)] + forces
//! grid  v_i = (m v)_i / m_i + dt g,  then the boundary conditions (walls, colliders)
//! G2P   v_p = sum_i w_ip v_i,   C_p = D_p^-1 sum_i w_ip v_i (x_i - x_p)^T,   x_p += dt v_p
//!       F_p <- (I + dt grad v_p) F_p,  then plasticity
//! ```
//!
//! - [`kernel`]: quadratic and cubic B-splines `w_ip`, `D_p = h^2/4 I` and `h^2/3 I`;
//! - [`transfer`](Transfer): APIC computes the grid force `-sum_p V_p P F_p^T grad w_ip`;
//!   MLS-MPM fuses it into the affine momentum, `m_p C_p - dt D_p^-1 V_p P F_p^T` (Hu et al. 2018);
//! - [`material`]: elastic (the shared `anim-material` fixed corotated and Neo-Hookean models),
//!   snow as in Stomakhin et al. 2013 (`F = F_E F_P`, singular values of `F_E` clamped to
//!   `[1 - theta_c, 1 + theta_s]`, Lamé parameters hardened by `exp(xi (1 - J_P))`, `xi = 10`,
//!   `E = 1e4`, `nu = 0.2`), a weakly compressible fluid with the `J`-based equation of state,
//!   and Drucker-Prager sand; the return maps live in [`plasticity`], sand's log-strain
//!   elasticity in [`hencky`];
//! - [`boundary`]: sticky / slip / separating conditions on the domain walls and on analytic
//!   planes, boxes and spheres, fixed or moving;
//! - the grid is sparse: blocks of `4^D` nodes are allocated only where particles are (a dense
//!   `u32` table of block slots, `1/4^D` of the node count, maps block coordinates to the pool),
//!   so a scene pays only for the space its matter occupies; particles are re-sorted by block
//!   every step as a by-product of the double-buffered G2P;
//! - [`scenes`]: the classic three-material 2D scene, a 3D dam break, a snowball hitting a wall,
//!   and the two peer-benchmark scenes (Taichi's `mpm88` and `mpm3d`).
//! - [`kind`]: the `mpm` scene kind, [`KIND`], which registers the scenes with the workspace
//!   ([`anim_core::scene::SceneKind`], scene files of `kind = "mpm"`): the presets `mpm`
//!   (`three-materials`), `dam-break-2d-mpm` (`dam-break-2d`, with its surge front against
//!   Martin & Moyce as the reference error), `dam-break` (`dam-break-3d`) and `snowball`, built
//!   from [`kind::MpmSceneParams`] (preset, resolution, transfer, kernel, particles per cell) and
//!   run as a [`kind::MpmRun`] (checkpoints and frames);
//! - [`bodies`]: a scene file's own bodies instead of a preset: boxes, spheres and closed OBJ
//!   surfaces filled with particles, each with its material and velocity, among plane, box and
//!   sphere obstacles and, in 3D, closed OBJ surfaces;
//! - [`mesh_collider`]: those mesh obstacles as level-set colliders: the signed distance sampled
//!   once on the grid nodes around the mesh (`f32`, at most 2^24 nodes), read by the grid update
//!   with its central-difference normal.
//!
//! The G2P affine update is `C_p = D_p^-1 sum ...` with `D_p^-1 = 4/dx^2` for the quadratic
//! kernel (Jiang et al. 2015; Hu et al. 2018), and snow's plastic update is
//! `F_P^{n+1} = F_E^-1 F^{n+1}` (Stomakhin et al. 2013).
//!
//! ## A step
//!
//! 1. survey: CFL numbers, input checks; the step is split into substeps if needed;
//! 2. binning: particles keyed by the block of their stencil's base node, counting sort;
//! 3. P2G: each occupied particle block scatters (with the particle's stress, computed on the
//!    fly) into a private window of `8^D` nodes;
//! 4. grid update: each grid block sums the windows overlapping it in a fixed order, divides by
//!    mass, adds gravity, applies the boundary conditions;
//! 5. G2P: the windows are refilled with grid velocities; each particle gathers its velocity,
//!    affine matrix and velocity gradient, moves, updates `F` and applies its return map, and is
//!    written in sorted order into the second buffer, which then becomes the state.
//!
//! ## Precision, parallelism, determinism
//!
//! Particles and grid are `f32` (the work-precision study of `cargo xtask report` shows the
//! discretisation error of the dam break far above `f32` round-off); totals are summed in `f64`.
//! P2G scatters each particle block into a private window; grid blocks sum the windows that
//! overlap them in a fixed order. No float atomics: the same state comes out for 1, 2 or N
//! threads, bit for bit. Nothing is allocated per step once the particle and block counts have
//! been reached (the buffers only grow).
//!
//! On x86-64 CPUs with AVX2 the transfers run AVX2 variants of the kernels, chosen at run time
//! (module `avx2`: in 2D two stencil nodes or two partial sums per 256-bit register; the rest of
//! the step compiled with AVX2). They use no fused multiply-adds and do the portable kernels'
//! operations in the same order per lane, so the results are the same bits on any CPU (a test
//! compares both paths).
//!
//! ## Robustness
//!
//! Each step measures the advective CFL number `max |v| dt / h` and the elastic-wave number
//! `max c dt / h` and splits itself into enough substeps ([`StepStats::substeps`]); a particle
//! leaving the domain is clamped back or removed and counted ([`OutOfDomain`]); grid nodes
//! without mass get zero velocity; a non-finite result is reported as
//! [`MpmError::NonFinite`], whose message begins with `anim-mpm: step N:` and names the
//! particle (by id), the field and its component or matrix entry, the value and the particle's
//! whole last finite vector or matrix, with the particles and the simulation's memory (step
//! count, time) left as they were before the step.
//!
//! ```
//! use anim_core::solver::Solver;
//! use anim_mpm::{Fluid, Material, MpmParams, MpmSimulation, Particles};
//!
//! // A 2D water block falling in a box of 32 x 32 cells.
//! let params = MpmParams::with_resolution(32);
//! let h = params.h() as f32;
//! let mut sim = MpmSimulation::<2>::new(params, vec![Material::Fluid(Fluid::default())])?;
//! let mut water = Particles::<2>::new();
//! let vol = (h / 2.0) * (h / 2.0);
//! for i in 0..24 {
//!     for j in 0..24 {
//!         let x = [0.3 + i as f32 * h / 2.0, 0.3 + j as f32 * h / 2.0];
//!         water.push(x, [0.0, 0.0], 1000.0 * vol, vol, 0)?;
//!     }
//! }
//! let before = sim.totals(&water).mass;
//! for _ in 0..10 {
//!     let report = sim.step(&mut water, 1e-3)?;
//!     assert!(report.energy.is_some());
//! }
//! assert_eq!(water.len(), 576);
//! assert!((sim.totals(&water).mass - before).abs() < 1e-9);
//! # Ok::<(), anim_mpm::MpmError>(())
//! ```

#[cfg(target_arch = "x86_64")]
mod avx2;
pub mod bodies;
pub mod boundary;
#[cfg(feature = "cases")]
pub mod cases;
mod grid;
pub mod hencky;
pub mod kernel;
pub mod kind;
pub mod material;
pub mod memory;
pub mod mesh_collider;
mod particle_transfer;
mod particles;
pub mod plasticity;
pub mod scenes;
mod sim;
mod simd;
mod transfer;

#[cfg(test)]
mod bodies_tests;
#[cfg(test)]
mod kind_tests;
#[cfg(test)]
mod mesh_collider_tests;
#[cfg(test)]
mod tests;

pub use boundary::{Boundary, Collider, Shape};
pub use kernel::Kernel;
pub use kind::KIND;
pub use material::{Elastic, ElasticModel, Fluid, Material, Sand, Snow};
pub use particles::Particles;
pub use sim::{MpmParams, MpmSimulation, OutOfDomain, StepStats, Totals, Transfer, max_resolution};

/// A `D`-vector of the particle precision.
pub type Vector<const D: usize> = nalgebra::SVector<f32, D>;
/// A `D x D` matrix of the particle precision.
pub type Mat<const D: usize> = nalgebra::SMatrix<f32, D, D>;

/// Errors of the MPM crate: bad input (named) and numerical failure (step and particle named).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum MpmError {
    /// A checkpointed memory that does not belong to this simulation.
    #[error("checkpoint does not fit this simulation: {0}")]
    Checkpoint(String),
    /// Only 2 and 3 dimensions are supported.
    #[error("dimension {0} is not supported (2 or 3)")]
    Dimension(usize),
    /// A simulation parameter is out of range.
    #[error("parameter `{name}`: {reason}")]
    BadParameter {
        /// The parameter.
        name: &'static str,
        /// Why it was refused.
        reason: String,
    },
    /// A material of the table has a bad parameter.
    #[error("material {index}, field `{field}`: {reason}")]
    BadMaterial {
        /// Index in the material table.
        index: usize,
        /// The field.
        field: &'static str,
        /// Why it was refused.
        reason: String,
    },
    /// A collider is malformed.
    #[error("collider {index}: {reason}")]
    BadCollider {
        /// Index in the collider list.
        index: usize,
        /// Why it was refused.
        reason: String,
    },
    /// A particle is invalid (given by its id, its index at creation).
    #[error("particle {index}: {reason}")]
    BadParticle {
        /// The particle's id.
        index: usize,
        /// Why it was refused.
        reason: String,
    },
    /// The particle arrays are inconsistent.
    #[error("particle state, array `{field}`: {reason}")]
    BadState {
        /// The array.
        field: &'static str,
        /// What is wrong.
        reason: String,
    },
    /// The CFL limits would need more substeps than allowed.
    #[error(
        "step {step}: CFL number {cfl:.3} (elastic waves {wave_cfl:.3}) needs {needed} substeps, more than max_substeps = {limit}"
    )]
    TooManySubsteps {
        /// The step.
        step: u64,
        /// Advective CFL number of the requested step.
        cfl: f64,
        /// Elastic-wave CFL number of the requested step.
        wave_cfl: f64,
        /// Substeps needed.
        needed: f64,
        /// The limit.
        limit: usize,
    },
    /// The step produced a NaN or infinity; the particles are left as they were before the step.
    #[error(
        "anim-mpm: step {step}: non-finite {field} of particle {particle}{} (value {value}); last finite {field} of particle {particle}: {last_finite:?}",
        describe_component(*component, last_finite.len())
    )]
    NonFinite {
        /// Completed steps before the failing one.
        step: u64,
        /// The particle's id.
        particle: usize,
        /// Which quantity: "position", "velocity", "deformation gradient", "affine matrix" or
        /// "plastic state".
        field: &'static str,
        /// The first offending entry of that quantity: the axis (0, 1, 2 for `x`, `y`, `z`) of a
        /// vector, the column-major index of a matrix, 0 for the plastic state.
        component: usize,
        /// The value.
        value: f64,
        /// The particle's whole quantity before the step (the `D` entries of a vector, the `D^2`
        /// column-major entries of a matrix, or the one plastic value).
        last_finite: Vec<f64>,
    },
}

/// `", component y"` for an entry of a vector of `len <= 3`, `", entry (row r, column c)"` for
/// a column-major matrix entry, nothing for a scalar.
fn describe_component(component: usize, len: usize) -> String {
    match len {
        0 | 1 => String::new(),
        2 | 3 => format!(", component {}", ["x", "y", "z"][component.min(2)]),
        _ => {
            let d = if len == 4 { 2 } else { 3 };
            format!(", entry (row {}, column {})", component % d, component / d)
        }
    }
}
