//! # anim-fem
//!
//! Tetrahedral finite elements for hyperelastic solids (Sifakis & Barbič 2012), with the material
//! models of `anim-material`.
//!
//! | module | what it models | method / source |
//! | --- | --- | --- |
//! | [`mesh`] | tetrahedral meshes: validation (degenerate / inverted rest elements named), Gmsh and TetGen input, boundary surface | - |
//! | [`generate`] | built-in meshes: tetrahedralised boxes (beams, cubes, bars) at any resolution, graded boxes, Cook's membrane, 10-node refinement | - |
//! | [`material`] | the six hyperelastic models (linear, StVK, corotated linear, Neo-Hookean, fixed corotated, stable Neo-Hookean) with Lamé parameters from `(E, nu)` | Sifakis & Barbič 2012; Stomakhin et al. 2012 (fixed corotated); Smith et al. 2018 (stable Neo-Hookean) |
//! | [`element`] | the linear tetrahedron: `Dm^-1`, `W = abs(det Dm)/6`, `F = Ds Dm^-1`, forces `H = -W P(F) Dm^-T`, `f4 = -(f1+f2+f3)`, stiffness | Sifakis & Barbič 2012, Algorithm 1 |
//! | [`assembly`] | ordered parallel assembly of forces and the sparse stiffness (identical for any thread count) | - |
//! | [`model`] | a body of linear or 10-node tetrahedra ([`ElementOrder`](model::ElementOrder)): precomputed rest data, a material per element, lumped or consistent mass, gravity, loads, pinned and kinematic vertices, obstacles with a friction coefficient each | - |
//! | [`boundary`] | kinematic motions; plane, sphere, box and capsule obstacles and closed triangle meshes on a signed distance field (penalty contact) | - |
//! | [`friction`] | Coulomb friction at obstacle contacts: velocity-level in explicit steps, IPC's lagged smoothed potential (Li et al. 2020, section 5) in backward Euler | - |
//! | [`newton`] | Newton on the incremental potential with a backtracking line search, Rayleigh damping `gamma` | backward Euler as an incremental potential |
//! | [`sim`] | symplectic Euler and backward Euler steps, quasi-static solves, the `Solver` implementation | symplectic and backward Euler |
//! | [`tet10`] | the 10-node tetrahedron (no locking in bending or near incompressibility): shape functions, 4-point quadrature, closed-form consistent mass, HRZ lumping | - |
//! | [`quadratic`] | bodies of 10-node tetrahedra in both time steppers, and the quasi-static front end [`QuadraticModel`](quadratic::QuadraticModel) | - |
//! | [`ldlt`] | sparse `L D L^T` (faer) for symmetric indefinite Newton matrices | - |
//! | [`scenes`] | cantilever beam, soft cube drop, twisted bar | - |
//! | [`body`] | a body of the user's own from a Gmsh or TetGen mesh or a closed OBJ surface (filled with tetrahedra): material, placement, velocity, pins | - |
//! | [`bodies`] | several such bodies merged into one model, each element of its body's material, with the gravity, obstacles, friction and damping they share | - |
//! | [`kind`] | the `fem` scene kind: presets, scene-file parameters, checkpoints and frames | - |
//!
//! **Element order.** [`FemModel::new`](model::FemModel::new) builds linear tetrahedra,
//! [`FemModel::quadratic`](model::FemModel::quadratic) and
//! [`FemModel::with_order`](model::FemModel::with_order) 10-node ones; the simulation, the
//! scenes ([`scenes::by_name_with_order`]) and checkpoints do not care which.
//!
//! **Scene kind.** [`KIND`] registers the crate's scenes with the workspace
//! ([`anim_core::scene::SceneKind`], scene files of `kind = "fem"`): the presets `beam`
//! (`cantilever-beam`), `cube` (`soft-cube-drop`) and `twisted-bar`, built from
//! [`kind::FemSceneParams`] (preset, resolution, integrator, linear solver, element), or a list
//! of `bodies` ([`body::BodySpec`]) bringing the user's own meshes, with their obstacles;
//! [`FemSimulation`](sim::FemSimulation) is their [`Checkpoint`](anim_core::scene::Checkpoint)
//! and [`View`](anim_core::scene::View).
//!
//! **Model / data split.** A [`FemModel`](model::FemModel) is built once and never modified by an
//! algorithm; a [`FemSimulation`](sim::FemSimulation) owns the settings and every scratch buffer
//! (sized at construction, so a step does not allocate); the state (`t`, `x`, `v`) is separate
//! and serialisable ([`anim_core::integrate::State`]).
//!
//! **Precision.** `f64` throughout: the FEM results are accuracy oracles (cantilever, Cook's
//! membrane) and Newton on stiff materials needs the precision.
//!
//! **Determinism.** Element loops run in parallel into per-element buffers; forces and matrix
//! entries are summed by gathering in a fixed element order; the direct solvers run
//! sequentially. Results are bitwise identical for any rayon thread count.
//!
//! **Divergence.** A step that produces a NaN or infinity returns
//! [`FemError::NonFiniteState`] (the vertex, its component `x`/`y`/`z`, the value and the
//! vertex's last finite position or velocity) or [`FemError::NonFiniteElement`] (an element whose
//! energy or stress is not finite, with its `det F`); both messages begin with
//! `anim-fem: step N:`, and the state and the step count are left as they were before the step.
//!
//! ```
//! use anim_core::solver::Solver;
//! use anim_fem::generate::box_mesh;
//! use anim_fem::material::{Material, MaterialModel};
//! use anim_fem::model::{EARTH_GRAVITY, FemModel};
//! use anim_fem::sim::{FemParams, FemSimulation, TimeIntegrator};
//!
//! // A 1 m beam of 10 x 1 x 1 cells (60 tetrahedra), clamped at x = 0, sagging under gravity.
//! let mesh = box_mesh([0.0; 3], [1.0, 0.1, 0.1], [10, 1, 1])?;
//! let material = Material::new(MaterialModel::StableNeoHookean, 1e7, 0.3, 1000.0)?;
//! let mut model = FemModel::new(mesh, material)?.with_gravity(EARTH_GRAVITY);
//! let clamp = model.vertices_where(|p| p[0] == 0.0);
//! model.pin_vertices(&clamp)?;
//! let mut sim = FemSimulation::new(model, FemParams::new(TimeIntegrator::BackwardEuler))?;
//! let mut state = sim.rest_state();
//! for _ in 0..30 {
//!     let report = sim.step(&mut state, 1.0 / 60.0)?;
//!     assert!(report.iterations <= 10);
//! }
//! let tip_z = state.x[3 * 10 + 2]; // vertex (10, 0, 0) of the grid: the lower tip corner
//! assert!(tip_z < 0.0);
//! # Ok::<(), anim_fem::FemError>(())
//! ```

pub mod assembly;
pub mod bodies;
pub mod body;
pub mod boundary;
#[cfg(feature = "cases")]
pub mod cases;
pub mod element;
pub mod error;
pub mod friction;
pub mod generate;
pub mod kind;
pub mod ldlt;
pub mod material;
pub mod memory;
pub mod mesh;
pub mod model;
pub mod newton;
pub mod quadratic;
pub mod scenes;
pub mod sim;
pub mod tet10;

pub use error::FemError;
pub use kind::KIND;

#[cfg(test)]
mod contact_shape_tests;
#[cfg(test)]
mod contact_tests;
#[cfg(test)]
mod kind_tests;
#[cfg(test)]
mod mesh_obstacle_tests;
#[cfg(test)]
mod tests;
#[cfg(test)]
mod tests_quadratic;
