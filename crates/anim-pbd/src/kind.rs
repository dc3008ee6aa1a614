//! The `pbd` scene kind: the crate's scenes behind anim-core's scene contracts
//! ([`anim_core::scene`]), so that the `anim` command line, `cargo xtask` and the Python bindings
//! run them without knowing the crate.
//!
//! | preset | scene | run |
//! | --- | --- | --- |
//! | `drape` | [`cloth_drape`](crate::scenes::cloth_drape): cloth falling onto a sphere | 120 frames of 1/60 s |
//! | `flag` | [`flag`](crate::scenes::flag): a flag on a swaying pole in gusty wind | 120 frames of 1/60 s |
//! | `blob` | [`soft_blob`](crate::scenes::soft_blob): a tetrahedral blob dropped on the ground | 120 frames of 1/60 s |
//! | `pbd-rope` | [`rope`](crate::scenes::rope): 100 links swinging over a capsule onto a box | 120 frames of 1/60 s |
//! | `pbd-cloth` | [`hanging_cloth`](crate::scenes::hanging_cloth): the report's 14 x 14 cloth | 30 frames of 1/60 s |
//!
//! A scene file's `[scene]` table (`kind = "pbd"`) holds the fields of [`PbdSceneParams`]: a
//! `preset` above, or the user's own `bodies` ([`BodySpec`], one `[[scene.bodies]]` table each):
//! soft bodies from tetrahedral meshes (Gmsh `.msh`, TetGen `.node`/`.ele`, or a closed OBJ
//! surface filled with tetrahedra) and cloths from OBJ surfaces, each with its material
//! ([`BodyMaterial`]), placement, initial velocity and pins ([`PinSpec`]), among `obstacles`
//! (anim-core's [`Shape`](crate::Shape): plane, sphere, box, capsule) and `obstacle_meshes`
//! (closed OBJ surfaces, each a [`MeshCollider`](crate::MeshCollider) of its signed distance
//! field) with a scene-wide friction, restitution and thickness. The bodies collide with the obstacles and with each other
//! (particles against the other bodies' surfaces; a body does not collide with itself).
//!
//! ```toml
//! [scene]
//! kind = "pbd"
//! obstacles = [ { plane = { point = [0, 0, 0], normal = [0, 0, 1] } } ]
//! friction = 0.5
//!
//! [[scene.bodies]]
//! mesh = "assets/torus.msh"                  # soft: a tetrahedral mesh
//! material = { density = 200.0, stretch = { compliance = 1e-4 } }
//! translate = [0.0, 0.0, 0.11]
//!
//! [[scene.bodies]]
//! mesh = "assets/cloth.obj"                  # cloth: an OBJ surface
//! material = { density = 0.2, bending = { isometric = { compliance = 1.0 } } }
//! translate = [0.0, 0.0, 0.5]
//! pin = { vertices = [0, 40] }
//! ```
//!
//! The scene is a [`PbdSimulation`] with its [`State`]: it implements [`Checkpoint`] (the state and
//! the simulation's memory: step count, external forces, pending body targets) and [`View`]
//! (the particles and their velocities; the model's triangles, or the boundary of its
//! tetrahedra, its edges and tetrahedra, the particles of zero inverse mass as pins, and the
//! static colliders: ground, spheres, capsules, boxes and mesh colliders on no kinematic body).
//! The model works z up (gravity along `-z`, the scene file's coordinates); its view turns all
//! of it y up, the frame of every view ([`anim_core::scene::turn_z_up`]).

use crate::constraint::ConstraintFunction;
use crate::scenes;
use crate::sim::{Method, PbdSimulation};
use anim_core::integrate::State;
use anim_core::mesh::boundary_triangles;
use anim_core::scene::study::{self, Candidate, Family, Point, StudyAdapter, Tolerance};
use anim_core::scene::{
    BuildContext, BuildError, Checkpoint, CheckpointError, Context, DynScene, Frame, MeshProp, ObstacleMesh,
    Preset, Prop, RunDefaults, SceneKind, Simulated, Up, View, ground_height, params,
    restore_state_and_memory, save_state_and_memory,
};
use serde::{Deserialize, Serialize};

mod bodies;
mod body;
mod obstacles;
mod surface;

pub use bodies::{DEFAULT_ITERATIONS, DEFAULT_SUBSTEPS, DEFAULT_THICKNESS};
pub use body::{BodyMaterial, BodySpec, BodyType, PinBox, PinSpec};

/// The `pbd` scene kind of anim-pbd, for the workspace registry.
pub const KIND: SceneKind = SceneKind {
    kind: "pbd",
    crate_name: "anim-pbd",
    summary: "position based dynamics and XPBD: cloth, flags, ropes and soft bodies with collisions",
    presets,
    build,
    tolerance: Some(Tolerance { adapter: tolerance_adapter, error: study::reference_error }),
};

/// The largest iteration or substep count a `pbd` scene takes.
pub const MAX_PBD_COUNT: usize = 100_000;

/// Scene-file parameters of a `pbd` scene: a preset of [`scenes`] with its own solver settings
/// unless overridden, or the user's own bodies among obstacles (give `preset` or `bodies`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PbdSceneParams {
    /// The preset's name: `cloth-drape`, `flag`, `rope`, `soft-blob`, `balloon`,
    /// `hanging-cloth` or `benchmark-cloth` ([`scenes::NAMES`]). Required unless `bodies` is
    /// given.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub preset: Option<String>,
    /// Resolution (the preset's default when absent): the cloth's side (at least 2, default 32;
    /// 14 for the hanging cloth; 50 for the benchmark cloth), the flag's width (at least 3,
    /// default 24), the rope's links (at least 2, default 100), the blob's cells (at least 2,
    /// default 6), the balloon's subdivisions (default 3). No more than the memory holds: the
    /// scene's estimate ([`crate::memory`]) is checked against the memory available before
    /// building. Presets only.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub resolution: Option<usize>,
    /// `"pbd"` (stiffness) or `"xpbd"` (compliance); the preset's when absent, `"xpbd"` for
    /// bodies.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub method: Option<Method>,
    /// Solver iterations per substep, 1 to [`MAX_PBD_COUNT`] (the preset's when absent,
    /// [`DEFAULT_ITERATIONS`] for bodies).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub iterations: Option<usize>,
    /// Substeps per step, 1 to [`MAX_PBD_COUNT`] (the preset's when absent, [`DEFAULT_SUBSTEPS`]
    /// for bodies).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub substeps: Option<usize>,
    /// The user's bodies, instead of a preset: soft bodies and cloths ([`BodySpec`]).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub bodies: Vec<BodySpec>,
    /// Static obstacles the bodies collide with: anim-core's shapes (`plane`, `sphere`, `box`,
    /// `capsule`), all of which PBD takes; a plane is a solid half-space. Default none. Bodies
    /// only.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub obstacles: Vec<crate::Shape>,
    /// Static obstacles from closed OBJ surfaces (anim-core's [`ObstacleMesh`]: `mesh` relative
    /// to the scene file, `scale`, `rotate`, `translate`, and `cell`, the spacing of the signed
    /// distance field the surface is sampled on, default its longest side over 64), each a
    /// [`MeshCollider`](crate::MeshCollider) with the scene's friction, restitution and
    /// thickness. Default none. Bodies only.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub obstacle_meshes: Vec<ObstacleMesh>,
    /// Friction coefficient (static and kinetic) against the obstacles and between bodies,
    /// `>= 0`. Default 0. Bodies only.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub friction: Option<f64>,
    /// Coefficient of restitution against the obstacles, in `[0, 1]`. Default 0. Bodies only.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub restitution: Option<f64>,
    /// Distance kept between particles and the obstacles, and between a body's particles and
    /// another body's surface (m, > 0). Default [`DEFAULT_THICKNESS`]. Bodies only.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub thickness: Option<f64>,
    /// Gravity (m/s^2). Default `[0, 0, -9.81]`. Bodies only.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gravity: Option<[f64; 3]>,
    /// Whether the bodies collide with each other. Default `true`. Bodies only.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub body_contacts: Option<bool>,
}

/// The step of every preset: 1/60 s.
const DT: f64 = 0.016666666666666666;

fn presets() -> Vec<Preset> {
    let preset = |name, description, frames, scene: &str, quick: Option<usize>| Preset {
        name,
        description,
        run: RunDefaults::new(DT, frames, 1),
        params: serde_json::json!({ "preset": scene }),
        quick_params: quick.map(|n| serde_json::json!({ "preset": scene, "resolution": n })),
    };
    vec![
        preset("drape", "XPBD cloth falling onto a sphere and draping over it", 120, "cloth-drape", Some(8)),
        preset("flag", "an XPBD flag on a swaying pole in the wind", 120, "flag", Some(6)),
        preset("blob", "a soft tetrahedral blob (XPBD) falling on the ground", 120, "soft-blob", Some(3)),
        preset("pbd-rope", "a 100-link XPBD rope swinging against obstacles", 120, "rope", Some(20)),
        preset(
            "pbd-cloth",
            "the report's 14x14 XPBD cloth pinned at two corners, hanging down for 0.5 s",
            30,
            "hanging-cloth",
            None,
        ),
    ]
}

/// Builds a `pbd` scene from its parameters ([`PbdSceneParams`]).
fn build(value: &serde_json::Value, context: &BuildContext<'_>) -> Result<Box<dyn DynScene>, BuildError> {
    let p: PbdSceneParams = params(value)?;
    for (field, count) in [("iterations", p.iterations), ("substeps", p.substeps)] {
        if let Some(k) = count
            && !(1..=MAX_PBD_COUNT).contains(&k)
        {
            return Err(BuildError::invalid(field, format!("must lie in [1, {MAX_PBD_COUNT}], got {k}")));
        }
    }
    let preset = match (&p.preset, p.bodies.is_empty()) {
        (Some(_), false) => {
            return Err(BuildError::invalid("preset", "give `preset` or `bodies`, not both"));
        }
        (None, true) => {
            return Err(BuildError::invalid(
                "preset",
                format!(
                    "a pbd scene needs a `preset` (one of {}) or `bodies` ([[scene.bodies]] tables)",
                    scenes::NAMES.join(", ")
                ),
            ));
        }
        (None, false) => {
            let (sim, state) = bodies::build_bodies(&p, context)?;
            return Ok(Simulated::new(sim, state).boxed());
        }
        (Some(preset), true) => preset,
    };
    bodies::refuse_body_fields(&p)?;
    crate::memory::check_scene(preset, p.resolution)?;
    let mut scene = match scenes::by_name(preset, p.resolution) {
        Some(Ok(scene)) => scene,
        Some(Err(e)) => return Err(BuildError::invalid("resolution", e.to_string())),
        None => {
            return Err(BuildError::invalid(
                "preset",
                format!("unknown preset `{}` (one of {})", preset, scenes::NAMES.join(", ")),
            ));
        }
    };
    if let Some(method) = p.method {
        scene.params.method = method;
    }
    if let Some(iterations) = p.iterations {
        scene.params.iterations = iterations;
    }
    if let Some(substeps) = p.substeps {
        scene.params.substeps = substeps;
    }
    let (sim, state) = scene.into_simulation().map_err(|e| BuildError::invalid("preset", e.to_string()))?;
    Ok(Simulated::new(sim, state).boxed())
}

impl Checkpoint for PbdSimulation {
    const VERSION: u32 = 1;

    fn time(&self, state: &State) -> f64 {
        state.t
    }

    fn save(&self, state: &State) -> serde_json::Value {
        save_state_and_memory(state, self.memory())
    }

    fn restore(&mut self, state: &mut State, saved: &serde_json::Value) -> Result<(), CheckpointError> {
        // The memory is checked and taken whole, or not at all.
        restore_state_and_memory(saved, state, |memory| self.restore_memory(memory))
    }

    fn provoke_overflow(&mut self, state: &mut State) -> Option<String> {
        let i = self.model().inverse_masses().iter().position(|&w| w > 0.0)?;
        // Both: the predicted position `x + h v` then overflows whatever the substep.
        state.x[3 * i] = f64::MAX;
        state.v[3 * i] = f64::MAX;
        Some(format!("position and velocity x of particle {i} set to f64::MAX"))
    }
}

impl View for PbdSimulation {
    fn method(&self) -> String {
        let p = self.params();
        format!(
            "{} / {}, {} iteration{} x {} substep{}",
            format!("{:?}", p.method).to_lowercase(),
            format!("{:?}", p.solver).to_lowercase(),
            p.iterations,
            if p.iterations == 1 { "" } else { "s" },
            p.substeps,
            if p.substeps == 1 { "" } else { "s" },
        )
    }

    fn context(&self, state: &State) -> Context {
        let model = self.model();
        let mut triangles = model.triangles().to_vec();
        if triangles.is_empty() && !model.tets().is_empty() {
            triangles = boundary_triangles(model.tets(), state.x.len() / 3);
        }
        let fixed = || model.colliders().iter().filter(|c| c.body.is_none()).map(|c| &c.shape);
        let ground = ground_height(fixed(), Up::Z);
        // Spheres first, then capsules and boxes, each in collider order.
        let props: Vec<Prop> = fixed().filter_map(Prop::of_shape).collect();
        let (spheres, others): (Vec<Prop>, Vec<Prop>) =
            props.into_iter().partition(|p| matches!(p, Prop::Sphere { .. }));
        let edges = model.edges().to_vec();
        let mean = if edges.is_empty() {
            0.01
        } else {
            edges
                .iter()
                .map(|[i, j]| {
                    let (a, b) = (&state.x[3 * i..3 * i + 3], &state.x[3 * j..3 * j + 3]);
                    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
                })
                .sum::<f64>()
                / edges.len() as f64
        };
        let mut context = Context::default();
        context.point_dim = 3;
        context.triangles = triangles;
        context.lines = edges;
        context.tetrahedra = model.tets().to_vec();
        // Pinned particles (no inverse mass) and particles held to a point or a moving body with
        // no slack (the flag's pole side).
        let held = model.constraints().iter().filter_map(|c| match c.function {
            ConstraintFunction::Attachment { particle, distance: 0.0, .. } => Some(particle),
            _ => None,
        });
        let mut pins: Vec<usize> = model
            .inverse_masses()
            .iter()
            .enumerate()
            .filter(|&(_, &w)| w == 0.0)
            .map(|(i, _)| i)
            .chain(held)
            .collect();
        pins.sort_unstable();
        pins.dedup();
        context.pins = pins;
        context.point_radius = 0.2 * mean;
        context.props.extend(ground.map(|height| Prop::Ground { height }));
        context.props.extend(spheres);
        context.props.extend(others);
        // Mesh obstacles fixed in the world (on no kinematic body), as shapes are.
        context.mesh_props.extend(
            model
                .mesh_colliders()
                .iter()
                .filter(|c| c.body.is_none())
                .map(|c| MeshProp::from(c.shape.surface())),
        );
        context.bounds = Some(anim_core::scene::frame_box(&state.x, Up::Z, ground, true));
        // Built z up, the model's frame; drawn y up.
        context.turn_z_up();
        context
    }

    fn frame(&self, state: &State, out: &mut Frame) {
        out.time = state.t;
        out.points.clone_from(&state.x);
        out.field_mut("velocity", 3).extend_from_slice(&state.v);
        // The moving bodies drawn where they are (the flag's pole).
        out.props.clear();
        out.props.extend(
            self.model()
                .bodies()
                .iter()
                .filter_map(|b| b.look_at(state.t))
                .filter_map(|s| Prop::of_shape(&s)),
        );
        out.turn_z_up(3, &["velocity"]);
    }
}

/// A label of the PBD cloth studies: `"<Pbd|Xpbd> substeps (1 iteration)"` (`true`: substeps
/// swept) or `"<Pbd|Xpbd> iterations (1 substep)"` (`false`).
#[must_use]
pub fn pbd_label(label: &str) -> Option<(Method, bool)> {
    let (method, rest) = label.split_once(' ')?;
    let method = [Method::Pbd, Method::Xpbd].into_iter().find(|m| format!("{m:?}") == method)?;
    match rest {
        "substeps (1 iteration)" => Some((method, true)),
        "iterations (1 substep)" => Some((method, false)),
        _ => None,
    }
}

/// The `pbd-cloth-position` study on a `hanging-cloth` scene: the method, and the iteration or
/// substep count scaled by the ratio of cloth sides (scene over study) when the scene's cloth is
/// finer and, for substeps, by `(T/H)^2` when the run is longer than the study's horizon (the
/// series sweeping iterations at one substep are then left out); the study's step.
struct ClothAdapter {
    scale: f64,
    study_dt: f64,
    horizon: f64,
    duration: f64,
}

impl StudyAdapter for ClothAdapter {
    fn candidate(&self, method: &str, point: &Point) -> Result<Candidate, String> {
        let Self { scale, study_dt, horizon, duration } = *self;
        let (m, substeps) = pbd_label(method).ok_or_else(|| study::unknown_method(method))?;
        let k = point.param.round();
        if !(1.0..=1e4).contains(&k) {
            return Err(format!("count {k} out of range"));
        }
        let length = study::horizon_factor(horizon, duration, 1);
        let (iterations, substeps, note) = if substeps {
            let count = (k * scale / length * (1.0 - 1e-12)).ceil();
            let note =
                format!("{count} substeps: cloth side ratio {scale:.4} x run length (H/T)^2 = {length:.4}");
            (1.0, count, note)
        } else {
            if length < 1.0 {
                return Err(format!(
                    "swept iterations at one substep: the error was measured over the study's {horizon} s and \
                     iterations do not shrink the step, so it does not bound a {duration:.4} s run"
                ));
            }
            let count = (k * scale * (1.0 - 1e-12)).ceil();
            (count, 1.0, format!("{count} iterations: cloth side ratio {scale:.4}"))
        };
        if iterations.max(substeps) > MAX_PBD_COUNT as f64 {
            return Err(format!("{} per step needed on this scene", iterations.max(substeps)));
        }
        let (i, s) = (iterations as usize, substeps as usize);
        let mut settings = serde_json::Map::new();
        settings.insert("method".into(), serde_json::json!(m));
        settings.insert("iterations".into(), serde_json::json!(i));
        settings.insert("substeps".into(), serde_json::json!(s));
        Ok(Candidate {
            settings,
            summary: format!(
                "method = {}, iterations = {i}, substeps = {s}",
                format!("{m:?}").to_lowercase()
            ),
            dt: Some(study_dt),
            cost: iterations * substeps / k,
            dt_swept: false,
            note,
        })
    }
}

/// The adapter of a `pbd` scene to its study (the registry maps `pbd/hanging-cloth`).
fn tolerance_adapter(
    value: &serde_json::Value,
    run: &RunDefaults,
    family: &Family,
) -> Result<Box<dyn StudyAdapter>, String> {
    let p: PbdSceneParams = params(value).map_err(study::unreadable)?;
    let Some(preset) = &p.preset else {
        return Err("--tolerance: the pbd studies measured the presets, not a scene of its own bodies".into());
    };
    crate::memory::check_scene(preset, p.resolution).map_err(study::unreadable)?;
    let scene = scenes::by_name(preset, p.resolution)
        .ok_or_else(|| format!("--tolerance: unknown pbd preset `{preset}`"))?
        .map_err(study::unreadable)?;
    // The cloth's side in particles (the scene and the study's cloths are square).
    let side = ((scene.state.x.len() / 3) as f64).sqrt();
    Ok(Box::new(ClothAdapter {
        scale: (side / study::problem(family, "n")?).max(1.0),
        study_dt: study::problem(family, "dt")?,
        horizon: study::horizon(family)?,
        duration: study::duration(run),
    }))
}

#[cfg(test)]
mod bodies_tests;
#[cfg(test)]
mod obstacles_tests;
#[cfg(test)]
mod tests;
