//! The `fem` scene kind: anim-fem's presets and scene-file parameters, and the
//! [`Checkpoint`] and [`View`] of a [`FemSimulation`], so that the command line, `cargo xtask`
//! and the Python bindings run its scenes through [`anim_core::scene`] without knowing the crate.
//!
//! | preset | scene | run |
//! | --- | --- | --- |
//! | `beam` | `cantilever-beam`: a stable Neo-Hookean beam clamped at one end sags and swings, backward Euler | 120 frames of 1/60 s |
//! | `cube` | `soft-cube-drop`: a soft cube dropped on the ground, backward Euler with penalty contact | 100 frames of 2 x 5 ms |
//! | `twisted-bar` | `twisted-bar`: a bar twisted by a half turn at one end | 100 frames of 10 ms |
//!
//! A scene file may give a list of `bodies` instead of a preset ([`BodySpec`], one
//! `[[scene.bodies]]` table each): a Gmsh or TetGen tetrahedral mesh or a closed OBJ surface of
//! the user's, with its material, placement, initial velocity and pins (anim-core's `PinSpec`:
//! `vertices` of the mesh file and a `box`). The `[scene]` table then also holds what the
//! bodies share ([`World`]): `gravity`, `obstacles` (planes, spheres, boxes, capsules),
//! `obstacle_meshes` (closed OBJ surfaces, anim-core's [`ObstacleMesh`], sampled on a distance
//! field of spacing `cell`), `contact_stiffness`, `friction` and `rayleigh`. The bodies collide with the obstacles, not
//! with each other. A preset refuses these fields, and `bodies` refuses
//! `resolution`.
//!
//! The scenes work z up (gravity along `-z`, the scene file's coordinates); what they show is
//! y up like every view's: a frame holds every node (for 10-node bodies, the corners then the
//! edge nodes) and its velocity turned by `(x, y, z) -> (x, z, -y)`
//! ([`anim_core::scene::turn_z_up`]); the [`Context`], turned alike, gives the outward boundary
//! triangles, the (corner) tetrahedra, the pinned and kinematic nodes as pins, the ground and the
//! sphere, box and capsule obstacles.
//!
//! ```
//! use anim_core::scene::{BuildContext, Frame};
//!
//! let beam = (anim_fem::KIND.presets)().into_iter().find(|p| p.name == "beam").expect("preset");
//! let quick = beam.quick_params.as_ref().unwrap_or(&beam.params);
//! let mut scene = (anim_fem::KIND.build)(quick, &BuildContext::default())?;
//! scene.step(beam.run.dt)?;
//! let mut frame = Frame::default();
//! scene.frame(&mut frame);
//! assert_eq!(frame.time, beam.run.dt);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use crate::bodies::{self, DEFAULT_CONTACT_STIFFNESS, World};
use crate::body::BodySpec;
use crate::boundary::Obstacle;
use crate::material::MaterialModel;
use crate::model::{EARTH_GRAVITY, ElementOrder};
use crate::scenes;
use crate::sim::{FemSimulation, LinearSolverChoice, TimeIntegrator};
use anim_core::integrate::State;
use anim_core::scene::study::{self, Candidate, Family, Point, StudyAdapter, Tolerance};
use anim_core::scene::{
    BuildContext, BuildError, Checkpoint, CheckpointError, Context, DynScene, Frame, MeshProp, ObstacleMesh,
    Preset, Prop, RunDefaults, SceneKind, Simulated, Up, View, ground_height, params,
    restore_state_and_memory, save_state_and_memory,
};
use serde::{Deserialize, Serialize};

/// The `fem` scene kind of anim-fem, for the workspace registry.
pub const KIND: SceneKind = SceneKind {
    kind: "fem",
    crate_name: "anim-fem",
    summary: "hyperelastic solids of linear or 10-node tetrahedra: a clamped beam, a dropped cube, a twisted bar",
    presets,
    build,
    tolerance: Some(Tolerance { adapter: tolerance_adapter, error: study::reference_error }),
};

/// Scene-file parameters of an `fem` scene (the `[scene]` table without `kind`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FemSceneParams {
    /// The scene: `"cantilever-beam"`, `"soft-cube-drop"` or `"twisted-bar"` (see
    /// [`scenes`]); give this or `bodies`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub preset: Option<String>,
    /// Bodies of the user's own, each from a mesh file with its own material ([`BodySpec`]);
    /// give this (at least one) or `preset`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bodies: Option<Vec<BodySpec>>,
    /// With `bodies`: gravity (m/s²); absent: `(0, 0, -9.81)`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gravity: Option<[f64; 3]>,
    /// With `bodies`: the obstacles every body collides with (`plane`, `sphere`, `box`,
    /// `capsule`: [`Obstacle`]); absent: none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub obstacles: Option<Vec<Obstacle>>,
    /// With `bodies`: closed OBJ surfaces every body collides with (anim-core's
    /// [`ObstacleMesh`]: `mesh` relative to the scene file, `scale`, `rotate`, `translate`, and
    /// `cell`, the spacing of the distance field they are sampled on, default the longest side
    /// over 64), with the same `contact_stiffness` and `friction` as `obstacles`; absent: none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub obstacle_meshes: Option<Vec<ObstacleMesh>>,
    /// With `bodies`: penalty stiffness of the obstacles (N/m) in backward Euler steps (symplectic
    /// Euler projects instead), positive; absent: `1e7`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub contact_stiffness: Option<f64>,
    /// With `bodies`: Coulomb friction coefficient against the obstacles, `>= 0`; absent: 0
    /// (frictionless).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub friction: Option<f64>,
    /// With `bodies`: Rayleigh stiffness damping `gamma` (s), `>= 0`; absent: 0.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rayleigh: Option<f64>,
    /// With `preset`: cells across the beam or bar (4 by default; the length gets 10 times as
    /// many), or along the cube's side (6 by default); absent: the scene's default. No more
    /// than the memory holds: the scene's estimate ([`crate::memory`]) is checked against the
    /// memory available before the mesh is made.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub resolution: Option<usize>,
    /// Time integrator, `"backward-euler"` or `"symplectic-euler"`; absent: the scene's
    /// (backward Euler).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub integrator: Option<TimeIntegrator>,
    /// Linear solver inside Newton, `"cholesky"`, `"ldlt"` or `"jacobi-pcg"`; absent: the
    /// scene's (Cholesky).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub linear_solver: Option<LinearSolverChoice>,
    /// The element, `"tet4"` (linear tetrahedra) or `"tet10"` (10-node tetrahedra on the same
    /// mesh: no locking in bending, 4 to 7 times the nodes); absent: `"tet4"`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub element: Option<ElementOrder>,
}

fn presets() -> Vec<Preset> {
    let preset = |name, description, run, scene: &str, quick: Option<usize>| Preset {
        name,
        description,
        run,
        params: serde_json::json!({ "preset": scene }),
        quick_params: quick.map(|r| serde_json::json!({ "preset": scene, "resolution": r })),
    };
    vec![
        preset(
            "beam",
            "a stable Neo-Hookean FEM beam clamped at one end sags and swings, backward Euler",
            RunDefaults::new(0.016666666666666666, 120, 1),
            "cantilever-beam",
            Some(2),
        ),
        preset(
            "cube",
            "a soft FEM cube dropped on the ground, backward Euler with penalty contact",
            RunDefaults::new(0.005, 100, 2),
            "soft-cube-drop",
            Some(3),
        ),
        preset(
            "twisted-bar",
            "an FEM bar twisted by a half turn at one end (large rotation)",
            RunDefaults::new(0.01, 100, 1),
            "twisted-bar",
            Some(2),
        ),
    ]
}

impl FemSceneParams {
    /// The names of the fields that go with `bodies` only and are given.
    fn world_fields(&self) -> impl Iterator<Item = &'static str> {
        [
            ("gravity", self.gravity.is_some()),
            ("obstacles", self.obstacles.is_some()),
            ("obstacle_meshes", self.obstacle_meshes.is_some()),
            ("contact_stiffness", self.contact_stiffness.is_some()),
            ("friction", self.friction.is_some()),
            ("rayleigh", self.rayleigh.is_some()),
        ]
        .into_iter()
        .filter_map(|(name, given)| given.then_some(name))
    }

    /// What the bodies share: the fields given, the defaults for the others.
    fn world(&self) -> World {
        World {
            gravity: self.gravity.unwrap_or(EARTH_GRAVITY),
            obstacles: self.obstacles.clone().unwrap_or_default(),
            obstacle_meshes: self.obstacle_meshes.clone().unwrap_or_default(),
            contact_stiffness: self.contact_stiffness.unwrap_or(DEFAULT_CONTACT_STIFFNESS),
            friction: self.friction.unwrap_or(0.0),
            rayleigh: self.rayleigh.unwrap_or(0.0),
        }
    }
}

fn build(value: &serde_json::Value, context: &BuildContext<'_>) -> Result<Box<dyn DynScene>, BuildError> {
    let p: FemSceneParams = params(value)?;
    let order = p.element.unwrap_or_default();
    let mut scene = match (&p.preset, &p.bodies) {
        (Some(name), None) => {
            if let Some(field) = p.world_fields().next() {
                return Err(BuildError::invalid(
                    field,
                    format!("a preset brings its own `{field}`; the field goes with `bodies`"),
                ));
            }
            let own = crate::sim::FemParams::default();
            let integrator = p.integrator.unwrap_or(own.integrator);
            let solver = p.linear_solver.unwrap_or(own.linear_solver);
            crate::memory::check_preset(name, p.resolution, order, integrator, solver)?;
            scenes::by_name_with_order(name, p.resolution, order)
                .ok_or_else(|| {
                    BuildError::invalid(
                        "preset",
                        format!("unknown preset `{name}` (one of {})", scenes::NAMES.join(", ")),
                    )
                })?
                .map_err(|e| BuildError::invalid("resolution", e.to_string()))?
        }
        (None, Some(bodies)) => {
            if p.resolution.is_some() {
                return Err(BuildError::invalid(
                    "resolution",
                    "a preset's field: the resolution of bodies is their meshes' (or `cell` for an OBJ surface)",
                ));
            }
            let own = crate::sim::FemParams::default();
            let method =
                (p.integrator.unwrap_or(own.integrator), p.linear_solver.unwrap_or(own.linear_solver));
            bodies::build_with(bodies, &p.world(), order, method, |path| context.resolve(path))
                .map_err(crate::body::BodyError::into_build_error)?
        }
        (Some(_), Some(_)) => {
            return Err(BuildError::invalid("bodies", "give a built-in `preset` or `bodies`, not both"));
        }
        (None, None) => {
            return Err(BuildError::invalid(
                "preset",
                format!(
                    "give a built-in `preset` (one of {}) or `bodies` (`[[scene.bodies]]` tables, each with a `mesh` file)",
                    scenes::NAMES.join(", ")
                ),
            ));
        }
    };
    if let Some(i) = p.integrator {
        scene.params.integrator = i;
    }
    if let Some(l) = p.linear_solver {
        scene.params.linear_solver = l;
    }
    let field = if p.bodies.is_some() { "bodies" } else { "preset" };
    let (sim, state) = scene.into_simulation().map_err(|e| BuildError::invalid(field, e.to_string()))?;
    Ok(Simulated::new(sim, state).boxed())
}

impl Checkpoint for FemSimulation {
    const VERSION: u32 = 1;

    fn time(&self, state: &State) -> f64 {
        state.t
    }

    fn save(&self, state: &State) -> serde_json::Value {
        save_state_and_memory(state, self.memory())
    }

    fn restore(&mut self, state: &mut State, saved: &serde_json::Value) -> Result<(), CheckpointError> {
        // The memory is read whole (a step count) or refused: nothing is changed before this
        // succeeds.
        restore_state_and_memory(saved, state, |memory| self.restore_memory(memory))
    }

    /// Moves the first free node to `f64::MAX` along x: the elements around it then have a
    /// non-finite stress, which the step reports as [`FemError::NonFiniteElement`](crate::FemError).
    fn provoke_overflow(&mut self, state: &mut State) -> Option<String> {
        let fixed = self.model().fixed();
        let node = (0..self.model().vertices()).find(|&i| !fixed[3 * i..3 * i + 3].iter().any(|&f| f))?;
        state.x[3 * node] = f64::MAX;
        Some(format!("x of node {node} set to f64::MAX"))
    }
}

impl View for FemSimulation {
    /// `integrator / linear solver`, then the element (`/ tet10`) for 10-node bodies.
    fn method(&self) -> String {
        let p = self.params();
        let method = format!("{} / {}", p.integrator.name(), p.linear_solver.name());
        match self.model().order() {
            ElementOrder::Linear => method,
            order => format!("{method} / {}", order.name()),
        }
    }

    /// The boundary triangles, the (corner) tetrahedra, as pins the nodes whose three
    /// coordinates are held (pinned or moved kinematically), the ground (the first obstacle
    /// plane `z >= h`, drawn `y >= h`) and the sphere, box and capsule obstacles, and the region
    /// the body stays in: its bounding box at `state`, widened sideways by a third of its size
    /// and extended down by its size or to the ground; all of it turned y up.
    fn context(&self, state: &State) -> Context {
        let model = self.model();
        let ground = ground_height(model.obstacles(), Up::Z);
        // Every obstacle but the planes (a ground is drawn as `Prop::Ground`).
        let solids: Vec<Prop> = model.obstacles().iter().filter_map(Prop::of_shape).collect();
        let fixed = model.fixed();
        // `Context` is non-exhaustive: filled field by field.
        let mut context = Context::default();
        context.point_dim = 3;
        context.triangles = model.surface().to_vec();
        context.tetrahedra.clone_from(&model.mesh().tets);
        context.pins =
            (0..model.vertices()).filter(|&i| fixed[3 * i..3 * i + 3].iter().all(|&f| f)).collect();
        context.bounds = Some(anim_core::scene::frame_box(&state.x, Up::Z, ground, true));
        context.props.extend(ground.map(|height| Prop::Ground { height }));
        context.props.extend(solids);
        context.mesh_props.extend(model.mesh_obstacles().iter().map(|f| MeshProp::from(f.surface())));
        // Built z up, the model's frame; drawn y up.
        context.turn_z_up();
        context
    }

    fn frame(&self, state: &State, out: &mut Frame) {
        out.time = state.t;
        out.points.clone_from(&state.x);
        out.field_mut("velocity", 3).extend_from_slice(&state.v);
        self.model().nodal_strain(&state.x, out.field_mut("strain", 1));
        out.turn_z_up(3, &["velocity"]);
    }
}

/// A label of the FEM beam study: `"<model> symplectic-euler"` or
/// `"<model> backward-euler (<solver>)"` (names of [`MaterialModel::name`],
/// [`TimeIntegrator::name`], [`LinearSolverChoice::name`]); reports from before the solver sweep
/// wrote `"<model> backward-euler"`, the default solver (`None` here; Cholesky).
#[must_use]
pub fn fem_label(label: &str) -> Option<(MaterialModel, TimeIntegrator, Option<LinearSolverChoice>)> {
    let (model, rest) = label.split_once(' ')?;
    let model = MaterialModel::ALL.into_iter().find(|m| m.name() == model)?;
    let explicit = TimeIntegrator::SymplecticEuler;
    if rest == explicit.name() {
        return Some((model, explicit, None));
    }
    let implicit = TimeIntegrator::BackwardEuler;
    let rest = rest.strip_prefix(implicit.name())?;
    if rest.is_empty() {
        return Some((model, implicit, None));
    }
    let solver = rest.strip_prefix(" (")?.strip_suffix(')')?;
    let solver = LinearSolverChoice::ALL.into_iter().find(|s| s.name() == solver)?;
    Some((model, implicit, Some(solver)))
}

/// The `fem-beam` study on a `cantilever-beam` scene: only the series of the scene's material
/// model; the study's step scaled by the ratio of wave speeds `sqrt(E/rho)` (study over scene),
/// by the ratio of cell sizes when the scene's cells are smaller, and by `(H / T)^2` when the
/// run is longer than the study's horizon (the integrators are first order).
struct BeamAdapter {
    model: MaterialModel,
    scale: f64,
    horizon: f64,
    duration: f64,
}

impl StudyAdapter for BeamAdapter {
    fn candidate(&self, method: &str, point: &Point) -> Result<Candidate, String> {
        let Self { model, scale, horizon, duration } = *self;
        let (m, integrator, solver) = fem_label(method).ok_or_else(|| study::unknown_method(method))?;
        if m != model {
            return Err(format!("{} material (the scene's is {})", m.name(), model.name()));
        }
        let length = study::horizon_factor(horizon, duration, 1);
        let factor = scale * length;
        let solver = solver.unwrap_or(LinearSolverChoice::Cholesky);
        let mut settings = serde_json::Map::new();
        settings.insert("integrator".into(), serde_json::json!(integrator));
        settings.insert("linear_solver".into(), serde_json::json!(solver));
        let summary = match integrator {
            TimeIntegrator::SymplecticEuler => format!("integrator = {}", integrator.name()),
            TimeIntegrator::BackwardEuler => {
                format!("integrator = {}, linear_solver = {}", integrator.name(), solver.name())
            }
        };
        Ok(Candidate {
            settings,
            summary,
            dt: Some(point.param * factor),
            cost: 1.0 / factor,
            dt_swept: true,
            note: format!("wave speed and cell ratios {scale:.4} x run length (H/T)^2 = {length:.4}"),
        })
    }
}

/// The adapter of an `fem` scene to its study (the registry maps `fem/cantilever-beam`).
fn tolerance_adapter(
    value: &serde_json::Value,
    run: &RunDefaults,
    family: &Family,
) -> Result<Box<dyn StudyAdapter>, String> {
    let p: FemSceneParams = params(value).map_err(study::unreadable)?;
    let preset =
        p.preset.as_deref().ok_or("--tolerance: the report's studies cover the fem presets, not bodies")?;
    let own = crate::sim::FemParams::default();
    let (integrator, solver) =
        (p.integrator.unwrap_or(own.integrator), p.linear_solver.unwrap_or(own.linear_solver));
    crate::memory::check_preset(preset, p.resolution, ElementOrder::Linear, integrator, solver)
        .map_err(study::unreadable)?;
    let scene = scenes::by_name(preset, p.resolution)
        .ok_or_else(|| format!("--tolerance: unknown fem preset `{preset}`"))?
        .map_err(study::unreadable)?;
    let material = *scene.model.material();
    let mesh = scene.model.mesh();
    let cell = mesh
        .tets
        .iter()
        .flat_map(|t| {
            let p = |i: usize| anim_core::glam::DVec3::from_array(mesh.positions[t[i]]);
            [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)].map(|(a, b)| p(a).distance(p(b)))
        })
        .fold(f64::INFINITY, f64::min);
    let speed = |young: f64, density: f64| (young / density).sqrt();
    let ratio = speed(study::problem(family, "young")?, study::problem(family, "density")?)
        / speed(material.lame.young(), material.density);
    let scale = ratio * (cell / study::problem(family, "cell")?).min(1.0);
    Ok(Box::new(BeamAdapter {
        model: material.model,
        scale,
        horizon: study::horizon(family)?,
        duration: study::duration(run),
    }))
}
