//! # anim-pbd
//!
//! Position based dynamics (Müller et al. 2007) and extended PBD, XPBD (Macklin et al. 2016): cloth, ropes,
//! soft bodies and balloons as particles held by constraints, with collisions against planes,
//! spheres, boxes, capsules and closed triangle meshes, friction and restitution. Parallel, and bitwise deterministic for
//! any number of threads.
//!
//! ## What it models
//!
//! The model of Müller et al. 2007, exactly: `N` **vertices** ([`Particle`]) with mass `m_i`, position `x_i`,
//! velocity `v_i` and inverse mass `w_i = 1/m_i` (0 for a pinned particle), and `M`
//! **constraints** ([`Constraint`]), each with a cardinality `n_j`, a function
//! `C_j: R^{3 n_j} -> R`, an index set, a stiffness `k_j` in `[0, 1]` and a type, equality
//! `C_j = 0` or inequality `C_j >= 0`; for XPBD also a compliance `alpha_j >= 0` and a damping
//! `beta_j`. The functions ([`constraint`] has the formulas and their sources):
//!
//! - **distance** `|x_i - x_j| - l` (stretch; also a minimum distance as an inequality);
//! - **bending**: the **dihedral angle** across an edge (Müller et al. 2007) and the **isometric
//!   quadratic bending** model of Bergou et al. 2006 (as in Bender et al. 2014), the right one for
//!   inextensible cloth: its energy is quadratic in the positions;
//! - **tetrahedral volume** `V - V_0`, and a **global volume** `sum_t x_a . (x_b x x_c) / 6 -
//!   k_pressure V_0` over a closed mesh (balloons);
//! - **attachment** `|x_i - t| - d` to a fixed point or a point of a moving [`KinematicBody`];
//! - **contacts**, inequality constraints against [`Collider`]s (shapes) and [`MeshCollider`]s
//!   (closed triangle meshes as signed distance fields, with continuous contact: a particle's
//!   path over a substep is marched through the field, so a surface thinner than its motion is
//!   not crossed) generated every step (line 8 of the loop), with static and kinetic
//!   **friction** and **restitution** ([`collide`]);
//!   between bodies ([`ContactBody`], [`PbdBuilder::contact_body`]), a particle of one body
//!   against the closest surface triangle of another, with friction (no self-collision).
//!
//! [`PbdBuilder`] makes models from particles and constraints, or from whole shapes: a chain, a
//! cloth grid, any triangle mesh, any tetrahedral mesh given as `positions` + `tets` arrays
//! ([`shapes`] builds tetrahedralised boxes and a bunny-like blob, and icospheres); every bad input
//! is a [`BuildError`] naming the element (bad index, negative mass, `k` outside `[0, 1]`, negative
//! compliance, degenerate rest shape, open volume mesh, ...).
//!
//! ## The loop (Müller et al. 2007; Macklin et al. 2016)
//!
//! [`PbdSimulation`] runs the 17-line loop of Müller et al. 2007 (Algorithm 1), per substep of `h = dt / substeps`:
//!
//! ```text
//! (5)  v_i <- v_i + h w_i f_ext(x_i)          (7)  p_i <- x_i + h v_i
//! (6)  dampVelocities                          (8)  generateCollisionConstraints(x_i -> p_i)
//! (9-11) solverIterations times: projectConstraints(C_1 .. C_{M + M_coll}, p)
//! (12-15) v_i <- (p_i - x_i) / h,  x_i <- p_i  (16) velocityUpdate (restitution)
//! ```
//!
//! with the projection of a constraint (mass-weighted, so that it carries no linear or angular
//! impulse, Müller et al.'s remark on ghost forces)
//!
//! ```text
//! PBD:   dp_i = -k' C / (sum_j w_j |grad_j C|^2) w_i grad_i C,   k' = 1 - (1 - k)^(1/n_s)
//! XPBD:  dlambda = (-C - alpha~ lambda) / (sum_j w_j |grad_j C|^2 + alpha~),  alpha~ = alpha / h^2   (eq. 18)
//!        dp_i = w_i grad_i C dlambda,  lambda <- lambda + dlambda                               (eq. 17)
//! ```
//!
//! **Stiffness.** PBD multiplies the projection step by `k' = 1 - (1 - k)^(1/n_s)`, `n_s` the solver
//! iterations per substep, as Müller et al. 2007 (section 3.3) do, so that a lone constraint keeps
//! the fraction `1 - k` of its error whatever `n_s` ([`PbdParams::stiffness_correction`] turns it
//! off and uses `k` raw). Even so PBD's effective stiffness depends on `dt` (as `1/dt^2`) and,
//! without the correction, strongly on the iteration count: `cargo xtask conformance` measures a
//! chain's effective stiffness going from 604 to 38,651 N/m as `dt` goes from 1/30 to 1/240 s.
//! XPBD's compliance is a material constant: the same chain settles within 2e-4 (of the total
//! stretch) of the analytic static stretch `alpha T` for every iteration count in {5, 20, 100}
//! and `dt` in {1/30, 1/60, 1/240} s. **Damping**: Müller's velocity damping at line (6)
//! ([`PbdParams::velocity_damping`]) and, in XPBD, Macklin et al. 2016's constraint damping
//! `beta` (eq. 26); `beta = 0` gives equation 18 exactly.
//!
//! ## Which method, which solver
//!
//! | choice | when |
//! | --- | --- |
//! | [`Method::Xpbd`] (default) | whenever the material matters: stiffness from a compliance in SI units, independent of `dt` and iterations |
//! | [`Method::Pbd`] | when only "stiff" or "soft" matters and you tune `k` visually, as in the original PBD |
//! | [`SolverKind::GaussSeidel`] | PBD's sequential sweep in model order: one thread, the reference |
//! | [`SolverKind::ColoredGaussSeidel`] | the same convergence per iteration, constraints grouped into independent colours (computed once); the fastest on one thread (about 30% faster than model order: no dependency chains), parallel for very large colours |
//! | [`SolverKind::Jacobi`] | every constraint from the same positions, averaged per particle: embarrassingly parallel but needs several times the iterations |
//! | `substeps` > 1 | long chains and stiff materials: many substeps of 1-2 iterations converge far better than the same work in iterations (Macklin et al. 2019); `cargo xtask report` has the curves |
//!
//! The results of all three solvers are bitwise identical for any rayon thread count (tested with
//! pools of 1, 2 and 4). Nothing allocates inside a step once the simulation exists: contact
//! buffers are sized for every particle against every collider up front, and those of the
//! contacts between bodies for each particle against four other bodies (a step grows them only
//! for a particle touching more at once, or in a scene so wide that rounding spreads the contact
//! grid; `sim/body_contacts.rs`).
//!
//! **Failures** never pass silently: a step that makes a position or velocity non-finite, or
//! stretches a distance constraint beyond [`PbdParams::max_stretch`], returns a [`PbdError`]
//! naming the step, the particle and the constraint, and leaves the state and the simulation's
//! memory as they were. A non-finite value is [`PbdError::NonFinite`], whose message begins with
//! `anim-pbd: step N:` and gives the particle's component, the value and its last finite
//! position or velocity.
//!
//! ## Speed
//!
//! On the 100 x 100 benchmark cloth ([`scenes::benchmark_cloth`]: 29,601 distance and 29,205
//! isometric bending constraints, XPBD, 5 iterations, dt = 1/60, one thread of this 2-core
//! machine) a step took 4.4 ms with the coloured Gauss-Seidel sweep and 6.4 ms with the
//! sequential sweep in model order; Jan Bender's PositionBasedDynamics (`pyPBD` 2.2.2, C++,
//! double precision, sequential Gauss-Seidel) took 25 ms on the same cloth in the same run, so
//! 5.7x and 3.9x (at 20 iterations: 16.7 and 25.3 ms against 88.7 ms; on the 50 x 50 cloth 4.4x
//! to 4.6x and 2.9x to 3.2x). NVIDIA Newton's XPBD on the CPU (Jacobi without averaging)
//! diverged on this cloth at 5 and 20 iterations, N = 50 and 100. `cargo xtask bench --peers`
//! measures all of them side by side. A dihedral bending projection costs about three isometric
//! ones (an `atan2`).
//!
//! ## Example
//!
//! ```
//! use anim_core::solver::Solver;
//! use anim_pbd::{
//!     Bending, Cloth, Collider, ConstraintParams, EARTH_GRAVITY, Method, PbdBuilder, PbdParams, PbdSimulation,
//!     SolverKind,
//! };
//!
//! // A 20 x 20 cloth, inextensible, with soft isometric bending, dropped onto a sphere.
//! let mut b = PbdBuilder::new();
//! b.gravity(EARTH_GRAVITY);
//! b.cloth(&Cloth {
//!     nx: 20,
//!     ny: 20,
//!     origin: [-0.5, -0.5, 1.0],
//!     u: [1.0, 0.0, 0.0],
//!     v: [0.0, 1.0, 0.0],
//!     particle_mass: 1e-3,
//!     stretch: ConstraintParams::rigid(),
//!     bending: Bending::Isometric(ConstraintParams::with_compliance(10.0)),
//! })?;
//! b.collider(Collider::sphere([0.0, 0.0, 0.5], 0.3).with_thickness(0.01).with_friction(0.5, 0.3));
//! let model = b.build()?;
//! let mut state = model.rest_state();
//! let params = PbdParams::new(Method::Xpbd, SolverKind::ColoredGaussSeidel, 5, 2);
//! let mut sim = PbdSimulation::new(model, params)?;
//! for _ in 0..60 {
//!     sim.step(&mut state, 1.0 / 60.0)?;
//! }
//! // After a second the cloth rests on the sphere: its centre is at the sphere's top + thickness.
//! let centre_z = state.x[3 * (10 * 20 + 10) + 2];
//! assert!((centre_z - 0.81).abs() < 0.02, "centre at {centre_z}");
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! [`KIND`] (kind `pbd`) puts the scenes behind anim-core's scene contracts
//! ([`anim_core::scene`]) with the presets the `anim` command line runs: `drape` (cloth on a
//! sphere), `flag`, `blob` (the soft tetrahedral blob), `pbd-rope` and `pbd-cloth` (the report's
//! hanging cloth), or a scene file's own soft bodies and cloths from mesh files
//! ([`kind::BodySpec`]); [`PbdSimulation`] is a checkpointable, viewable solver ([`kind`]).
//!
//! `examples/cloth_drape.rs` runs any built-in scene ([`scenes`]: cloth draped over a sphere, a
//! flag in the wind on a swaying pole, a rope of 100 links, a soft tetrahedral blob, a balloon)
//! and prints energy, momentum, constraint violation and timings:
//! `cargo run --release -p anim-pbd --example cloth_drape -- flag`.
//! `examples/mesh_sphere.rs` measures a [`MeshCollider`] against the analytic sphere for several
//! field spacings (resting positions, field build time, step time):
//! `cargo run --release -p anim-pbd --example mesh_sphere`.
//!
//! ## Precision
//!
//! Everything is `f64`, like the peers measured against (pyPBD is built in double precision): a
//! step is bound by the latency of the sequential projections, not by memory bandwidth, so `f32`
//! would gain little.
//!
//! ## References
//!
//! Müller, Heidelberger, Hennix, Ratcliff, "Position based dynamics", 2007 (the loop, the
//! projection, `k'`, damping, collisions, bending, balloons); Macklin, Müller, Chentanez, "XPBD",
//! 2016 (eqs. 17, 18, 26); Macklin et al., "Unified particle physics", 2014 (Jacobi averaging,
//! friction); Macklin et al., "Small steps in physics simulation", 2019; Müller et al.,
//! "Detailed rigid body simulation with XPBD", 2020 (restitution); Bergou, Wardetzky, Harmon,
//! Zorin, Grinspun, "A quadratic bending model for inextensible surfaces", 2006; Bender, Müller,
//! Macklin, "Position-based simulation methods in computer graphics", 2014; Bridson, Marino,
//! Fedkiw, "Simulation of clothing with folds and wrinkles", 2003 (dihedral gradients).

mod build;
#[cfg(feature = "cases")]
pub mod cases;
pub mod collide;
pub mod constraint;
pub mod kind;
pub mod memory;
mod model;
mod project;
pub mod scenes;
pub mod shapes;
mod sim;

pub use build::{
    Bending, BuildError, Chain, Cloth, ClothHandle, EARTH_GRAVITY, InputError, MeshMass, MeshParams,
    PbdBuilder, TetMeshParams,
};
pub use collide::{BodyContact, BodyMotion, Collider, KinematicBody, MeshCollider, Pose, Shape};
pub use constraint::{AttachTarget, Constraint, ConstraintFunction, ConstraintParams, ConstraintType};
pub use kind::KIND;
pub use model::{ContactBody, Particle, PbdModel, SparseGradient, VolumeMesh, Wind};
pub use sim::{Method, PbdError, PbdParams, PbdSimulation, SolverKind, StepInfo};

#[cfg(test)]
mod tests;
