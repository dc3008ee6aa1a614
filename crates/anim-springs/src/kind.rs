//! The `springs` scene kind: the crate's scenes behind anim-core's scene contracts
//! ([`anim_core::scene`]), so that the `anim` command line, `cargo xtask` and the Python bindings
//! run them without knowing the crate.
//!
//! | preset | scene | run |
//! | --- | --- | --- |
//! | `cloth` | [`hanging_cloth`](crate::scenes::hanging_cloth) at 32 x 32, backward Euler + sparse Cholesky | 120 frames of 2 steps of 0.01 s |
//! | `rope` | [`swinging_rope`](crate::scenes::swinging_rope), velocity Verlet | 120 frames of 40 steps of 0.5 ms |
//! | `jelly` | [`jelly_drop`](crate::scenes::jelly_drop), backward Euler + sparse Cholesky | 120 frames of 2 steps of 5 ms |
//!
//! A scene file's `[scene]` table (`kind = "springs"`) holds the fields of [`SpringsParams`]:
//! a `preset`, or `[[scene.bodies]]` tables ([`BodySpec`]), cloth and shells of the user's own
//! from OBJ triangle surfaces, each with its material (area density, edge and bending springs),
//! placement, initial velocity and pinned vertices, among scene-wide `obstacles` (planes,
//! spheres, boxes and capsules: anim-core's [`Shape`]) and `obstacle_meshes` (closed OBJ
//! surfaces, anim-core's [`ObstacleMesh`], sampled on a distance field of spacing `cell`), with
//! their `contact`, under `gravity`.
//! Bodies do not collide with each other. The scene is a [`SpringSimulation`] with its [`State`]: it implements
//! [`Checkpoint`] (the state and the simulation's memory, the integrator's included) and
//! [`View`] (the particles and their velocities; springs as lines, cloth triangles, pinned
//! particles, the ground and the sphere, box and capsule colliders). The network works z up
//! (gravity along `-z`, the scene file's coordinates); its view turns all of it y up, the frame
//! of every view ([`anim_core::scene::turn_z_up`]).

use crate::EARTH_GRAVITY;
use crate::body::{BodySpec, ContactSpec, build_bodies};
use crate::contact::Shape;
use crate::obstacles::mesh_colliders;
use crate::scenes;
use crate::sim::SpringSimulation;
use anim_core::integrate::{IntegratorKind, State};
use anim_core::linalg::LinearSolverKind;
use anim_core::scene::study::{self, Candidate, Family, Point, StudyAdapter, Tolerance};
use anim_core::scene::systems::integrator;
use anim_core::scene::{
    BuildContext, BuildError, Checkpoint, CheckpointError, Context, DynScene, Frame, MeshProp, ObstacleMesh,
    Preset, Prop, RunDefaults, SceneKind, Simulated, Up, View, ground_height, params,
    restore_state_and_memory, save_state_and_memory,
};
use serde::{Deserialize, Serialize};

/// The `springs` scene kind of anim-springs, for the workspace registry.
pub const KIND: SceneKind = SceneKind {
    kind: "springs",
    crate_name: "anim-springs",
    summary: "mass-spring networks (cloth, ropes, jelly) under any integrator of anim-core",
    presets,
    build,
    tolerance: Some(Tolerance { adapter: tolerance_adapter, error: study::reference_error }),
};

/// Scene-file parameters of a `springs` scene: a preset of [`scenes`] with its own integrator
/// and linear solver unless overridden, or bodies of the user's own ([`BodySpec`]) among
/// obstacles. Give `preset` or `bodies`, not both.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpringsParams {
    /// The preset's name: `hanging-cloth`, `swinging-rope`, `jelly-drop` or `benchmark-cloth`
    /// ([`scenes::NAMES`]); give this or `bodies`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub preset: Option<String>,
    /// Particles per side of a preset (the preset's default when absent: 32 for the cloth, 40
    /// for the rope, 6 for the jelly, 128 for the benchmark cloth); at least 2 (3 for the
    /// rope), and no more than the memory holds: the scene's estimate ([`crate::memory`]) is
    /// checked against the memory available before building. Not with `bodies` (a body's
    /// resolution is its mesh's).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub resolution: Option<usize>,
    /// Integrator override (the preset's when absent; backward Euler for bodies); a
    /// beta-blend's `beta` in `[0, 1]`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub integrator: Option<IntegratorKind>,
    /// Linear solver override for implicit integrators (the preset's when absent; sparse
    /// Cholesky for bodies).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub linear_solver: Option<LinearSolverKind>,
    /// Cloth and shells from OBJ triangle surfaces ([`BodySpec`], `[[scene.bodies]]` tables);
    /// give this or `preset`.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub bodies: Vec<BodySpec>,
    /// With `bodies`: the obstacles every body collides with, anim-core's [`Shape`] (`plane`,
    /// `sphere`, `box`, `capsule`); default none.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub obstacles: Vec<Shape>,
    /// With `bodies`: closed OBJ surfaces every body collides with (anim-core's
    /// [`ObstacleMesh`]: `mesh` relative to the scene file, `scale`, `rotate`, `translate`, and
    /// `cell`, the spacing of the distance field they are sampled on, default the longest side
    /// over 64), with the same `contact`; default none.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub obstacle_meshes: Vec<ObstacleMesh>,
    /// With `bodies`: gravity (m/s²); default `[0, 0, -9.81]`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gravity: Option<[f64; 3]>,
    /// With `bodies`: the penalty contact against the obstacles ([`ContactSpec`]); default
    /// its defaults.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub contact: Option<ContactSpec>,
}

fn presets() -> Vec<Preset> {
    vec![
        Preset {
            name: "cloth",
            description: "a 32x32 cloth pinned at two corners falls and swings, backward Euler + sparse Cholesky",
            run: RunDefaults::new(0.01, 120, 2),
            params: serde_json::json!({ "preset": "hanging-cloth", "resolution": 32 }),
            quick_params: Some(serde_json::json!({ "preset": "hanging-cloth", "resolution": 8 })),
        },
        Preset {
            name: "rope",
            description: "a rope pinned at one end swings down, velocity Verlet",
            run: RunDefaults::new(0.0005, 120, 40),
            params: serde_json::json!({ "preset": "swinging-rope" }),
            quick_params: None,
        },
        Preset {
            name: "jelly",
            description: "a jelly cube dropped on the ground bounces, backward Euler + sparse Cholesky",
            run: RunDefaults::new(0.005, 120, 2),
            params: serde_json::json!({ "preset": "jelly-drop" }),
            quick_params: None,
        },
    ]
}

/// Builds a `springs` scene from its parameters ([`SpringsParams`]).
fn build(value: &serde_json::Value, context: &BuildContext<'_>) -> Result<Box<dyn DynScene>, BuildError> {
    let p: SpringsParams = params(value)?;
    if let Some(integrator) = &p.integrator {
        integrator.validate().map_err(|m| BuildError::invalid("integrator", m))?;
    }
    let mut scene = match (&p.preset, p.bodies.is_empty()) {
        (Some(name), true) => {
            for (field, given) in [
                ("obstacles", !p.obstacles.is_empty()),
                ("obstacle_meshes", !p.obstacle_meshes.is_empty()),
                ("gravity", p.gravity.is_some()),
                ("contact", p.contact.is_some()),
            ] {
                if given {
                    return Err(BuildError::invalid(
                        field,
                        format!("only with `bodies`: the preset `{name}` has its own"),
                    ));
                }
            }
            crate::memory::check_scene(name, p.resolution, p.integrator, p.linear_solver)?;
            preset_scene(name, p.resolution)?
        }
        (None, false) => {
            if p.resolution.is_some() {
                return Err(BuildError::invalid(
                    "resolution",
                    "a preset's field: a body's resolution is its mesh's",
                ));
            }
            let contact = p.contact.unwrap_or_default();
            let mut scene = build_bodies(
                &p.bodies,
                &p.obstacles,
                p.gravity.unwrap_or(EARTH_GRAVITY),
                &contact,
                |mesh| context.resolve(mesh),
            )?;
            if !p.obstacle_meshes.is_empty() {
                let meshes = mesh_colliders(&p.obstacle_meshes, &contact, |mesh| context.resolve(mesh))?;
                scene
                    .network
                    .add_mesh_colliders(meshes)
                    .map_err(|e| BuildError::invalid("obstacle_meshes", e.to_string()))?;
            }
            scene
        }
        (Some(_), false) => {
            return Err(BuildError::invalid("bodies", "give a built-in `preset` or `bodies`, not both"));
        }
        (None, true) => {
            return Err(BuildError::invalid(
                "preset",
                format!(
                    "give a built-in `preset` (one of {}) or `[[scene.bodies]]`",
                    scenes::NAMES.join(", ")
                ),
            ));
        }
    };
    if let Some(integrator) = p.integrator {
        scene.integrator = integrator;
    }
    if let Some(linear) = p.linear_solver {
        scene.linear_solver = linear;
    }
    let (sim, state) =
        scene.into_simulation().map_err(|e| BuildError::invalid("integrator", e.to_string()))?;
    Ok(Simulated::new(sim, state).boxed())
}

/// The preset `name` at `resolution`.
fn preset_scene(name: &str, resolution: Option<usize>) -> Result<scenes::SpringScene, BuildError> {
    match scenes::by_name(name, resolution) {
        Some(Ok(scene)) => Ok(scene),
        Some(Err(e)) => Err(BuildError::invalid("resolution", e.to_string())),
        None => Err(BuildError::invalid(
            "preset",
            format!("unknown preset `{name}` (one of {})", scenes::NAMES.join(", ")),
        )),
    }
}

impl Checkpoint for SpringSimulation {
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
        let i = self.network().particles().iter().position(|p| !p.pinned)?;
        // Both: a position alone may only stretch the springs, a velocity alone drift finitely.
        state.x[3 * i] = f64::MAX;
        state.v[3 * i] = f64::MAX;
        Some(format!("position and velocity x of particle {i} set to f64::MAX"))
    }
}

impl View for SpringSimulation {
    fn method(&self) -> String {
        let integrator = self.integrator_kind();
        if integrator.is_implicit() {
            format!("{} / {}", integrator.label(), self.linear_solver().name())
        } else {
            integrator.label()
        }
    }

    fn context(&self, state: &State) -> Context {
        let network = self.network();
        let colliders = network.model().colliders();
        let ground = ground_height(colliders.iter().map(|c| &c.shape), Up::Z);
        let springs = network.springs();
        let mean_length = if springs.is_empty() {
            0.01
        } else {
            springs.iter().map(|s| s.rest_length).sum::<f64>() / springs.len() as f64
        };
        let mut context = Context::default();
        context.point_dim = 3;
        context.triangles = network.triangles().to_vec();
        context.lines = springs.iter().map(|s| [s.i, s.j]).collect();
        context.pins =
            network.particles().iter().enumerate().filter(|(_, p)| p.pinned).map(|(i, _)| i).collect();
        context.point_radius = 0.15 * mean_length;
        context.props.extend(ground.map(|height| Prop::Ground { height }));
        context.props.extend(colliders.iter().filter_map(|c| Prop::of_shape(&c.shape)));
        context
            .mesh_props
            .extend(network.model().mesh_colliders().iter().map(|c| MeshProp::from(c.shape.surface())));
        context.bounds = Some(anim_core::scene::frame_box(&state.x, Up::Z, ground, true));
        // Built z up, the network's frame; drawn y up.
        context.turn_z_up();
        context
    }

    fn frame(&self, state: &State, out: &mut Frame) {
        out.time = state.t;
        out.points.clone_from(&state.x);
        out.field_mut("velocity", 3).extend_from_slice(&state.v);
        out.turn_z_up(3, &["velocity"]);
    }
}

/// The `springs-cloth` study on a `hanging-cloth` scene: explicit integrators only (the scene
/// takes one linearised Newton iteration per step, the study converged Newton to 1e-10), the
/// study's step scaled by the ratio of the highest spring frequencies estimated as
/// `sqrt(k_max N / M)` (stiffest spring, particle count, total mass) when the scene's is higher,
/// and by `(H / T)^(2/p)` when the run is longer than the study's horizon.
struct ClothAdapter {
    scale: f64,
    horizon: f64,
    duration: f64,
}

impl StudyAdapter for ClothAdapter {
    fn candidate(&self, method: &str, point: &Point) -> Result<Candidate, String> {
        let Self { scale, horizon, duration } = *self;
        if method.contains(" / ") {
            return Err("implicit (the scene takes one linearised Newton iteration per step, the study converged Newton)".into());
        }
        let kind = integrator(method).ok_or_else(|| study::unknown_method(method))?;
        let length = study::horizon_factor(horizon, duration, kind.order());
        let factor = scale * length;
        let mut settings = serde_json::Map::new();
        settings.insert("integrator".into(), serde_json::json!(kind));
        Ok(Candidate {
            settings,
            summary: format!("integrator = {}", kind.label()),
            dt: Some(point.param * factor),
            cost: 1.0 / factor,
            dt_swept: true,
            note: format!("spring frequency ratio {scale:.4} x run length (H/T)^(2/p) = {length:.4}"),
        })
    }
}

/// The adapter of a `springs` scene to its study (the registry maps `springs/hanging-cloth`).
fn tolerance_adapter(
    value: &serde_json::Value,
    run: &RunDefaults,
    family: &Family,
) -> Result<Box<dyn StudyAdapter>, String> {
    let p: SpringsParams = params(value).map_err(study::unreadable)?;
    let preset = p.preset.ok_or("--tolerance: a springs scene of bodies has no study, only the presets")?;
    crate::memory::check_scene(&preset, p.resolution, p.integrator, p.linear_solver)
        .map_err(study::unreadable)?;
    let scene = scenes::by_name(&preset, p.resolution)
        .ok_or_else(|| format!("--tolerance: unknown springs preset `{preset}`"))?
        .map_err(study::unreadable)?;
    let net = &scene.network;
    let k = net.springs().iter().map(|s| s.stiffness).fold(0.0, f64::max);
    let count = (scene.state.x.len() / 3) as f64;
    let omega_scene = (k * count / net.total_mass()).sqrt();
    let n = study::problem(family, "n")?;
    let omega_study = (study::problem(family, "stiffness")? * n * n / study::problem(family, "mass")?).sqrt();
    Ok(Box::new(ClothAdapter {
        scale: (omega_study / omega_scene).min(1.0),
        horizon: study::horizon(family)?,
        duration: study::duration(run),
    }))
}

#[cfg(test)]
mod tolerance_tests {
    use super::*;
    use anim_core::scene::study::family;

    fn pt(param: f64, seconds: f64, error: f64) -> Point {
        Point { param, seconds, error }
    }

    #[test]
    fn the_hanging_cloth_takes_explicit_methods_only_at_the_stiffer_cloths_step() {
        let f = family(
            "springs-cloth",
            "springs/hanging-cloth",
            Some(0.25),
            &[("n", 10.0), ("size", 0.5), ("mass", 0.1), ("stiffness", 100.0)],
            &[],
        );
        let preset = (KIND.presets)().into_iter().find(|p| p.name == "cloth").expect("preset");
        let tolerance = KIND.tolerance.expect("mapped");
        let adapter = (tolerance.adapter)(&preset.params, &preset.run, &f).expect("adapter");
        let e = adapter.candidate("backward-euler / cholesky", &pt(0.01, 1e-4, 1e-4)).unwrap_err();
        assert!(e.starts_with("implicit ("), "{e}");
        assert_eq!(
            adapter.candidate("leapfrog-x", &pt(0.01, 1e-4, 1e-4)).unwrap_err(),
            "`leapfrog-x` is not a method this build knows"
        );
        let c = adapter.candidate("rk4", &pt(6.25e-4, 2e-3, 1e-6)).expect("explicit");
        assert_eq!(c.summary, "integrator = rk4");
        assert_eq!(c.settings.get("integrator"), Some(&serde_json::json!(IntegratorKind::Rk4)));
        // The preset: 32 x 32 particles, 0.2 kg, structural 1000 N/m; the study's 10 x 10, 0.1 kg,
        // 100 N/m. The scene runs 120 x 2 x 0.01 = 2.4 s against 0.25 s.
        let omega = |k: f64, count: f64, mass: f64| (k * count / mass).sqrt();
        let dt = 6.25e-4 * omega(100.0, 100.0, 0.1) / omega(1000.0, 1024.0, 0.2) * (0.25f64 / 2.4).sqrt();
        let got = c.dt.expect("a step");
        assert!((got - dt).abs() < 1e-9 * dt, "{got} != {dt}");
        assert!((c.cost - 6.25e-4 / dt).abs() < 1e-9 * c.cost);
        assert!(c.dt_swept);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use anim_core::scene::StepError;

    fn preset(name: &str) -> Preset {
        (KIND.presets)().into_iter().find(|p| p.name == name).expect("preset")
    }

    fn build_params(params: &serde_json::Value) -> Box<dyn DynScene> {
        (KIND.build)(params, &BuildContext::default()).expect("builds")
    }

    fn frame_of(scene: &dyn DynScene) -> Frame {
        let mut frame = Frame::default();
        scene.frame(&mut frame);
        frame
    }

    fn bits(values: &[f64]) -> Vec<u64> {
        values.iter().map(|v| v.to_bits()).collect()
    }

    /// Flat z-up triples `(x, y, z)` as the y-up `(x, z, -y)` every frame has.
    fn y_up(values: &[f64]) -> Vec<f64> {
        values.chunks_exact(3).flat_map(|p| [p[0], p[2], -p[1]]).collect()
    }

    fn build_err(params: &serde_json::Value) -> String {
        (KIND.build)(params, &BuildContext::default()).err().expect("refused").to_string()
    }

    #[test]
    fn every_preset_builds_steps_and_moves_with_finite_frames() {
        let presets = (KIND.presets)();
        assert_eq!(presets.iter().map(|p| p.name).collect::<Vec<_>>(), ["cloth", "rope", "jelly"]);
        for p in &presets {
            for params in std::iter::once(&p.params).chain(&p.quick_params) {
                let mut scene = build_params(params);
                let before = frame_of(scene.as_ref());
                for _ in 0..3 {
                    scene.step(p.run.dt).expect("step");
                }
                let frame = frame_of(scene.as_ref());
                assert!((frame.time - 3.0 * p.run.dt).abs() < 1e-12, "{}: {}", p.name, frame.time);
                assert_eq!(scene.time().to_bits(), frame.time.to_bits(), "{}", p.name);
                assert_eq!(frame.points.len(), before.points.len(), "{}", p.name);
                assert!(frame.points.iter().all(|x| x.is_finite()), "{}", p.name);
                let v = frame.field("velocity").expect("velocity");
                assert_eq!((v.components, v.values.len()), (3, frame.points.len()), "{}", p.name);
                assert!(v.values.iter().all(|x| x.is_finite()), "{}", p.name);
                assert_ne!(frame.points, before.points, "{}: nothing moved", p.name);
            }
        }
    }

    #[test]
    fn presets_are_the_scene_files_of_their_scenes_and_serialise_back_the_same() {
        let cloth = preset("cloth");
        assert_eq!(cloth.run, RunDefaults::new(0.01, 120, 2));
        assert_eq!(cloth.params, serde_json::json!({ "preset": "hanging-cloth", "resolution": 32 }));
        assert_eq!(preset("rope").run, RunDefaults::new(0.0005, 120, 40));
        assert_eq!(preset("jelly").run, RunDefaults::new(0.005, 120, 2));
        for p in (KIND.presets)() {
            for params in std::iter::once(&p.params).chain(&p.quick_params) {
                let read: SpringsParams = anim_core::scene::params(params).expect("reads");
                assert_eq!(&serde_json::to_value(&read).expect("writes"), params, "{}", p.name);
            }
        }
    }

    /// The network works z up (gravity along -z); its frames are y up: a hanging cloth, held
    /// at two corners, falls along -y in them (its mean height drops and its mean velocity
    /// points down -y), while x, across the held edge, barely moves.
    #[test]
    fn a_hanging_cloth_falls_along_minus_y_in_its_frames() {
        let mut scene = build_params(&serde_json::json!({ "preset": "hanging-cloth", "resolution": 8 }));
        let mean = |values: &[f64], k: usize| {
            values.chunks_exact(3).map(|p| p[k]).sum::<f64>() / (values.len() / 3) as f64
        };
        // It starts level: every point at the height y = 1.
        let start = frame_of(scene.as_ref());
        assert!(start.points.chunks_exact(3).all(|p| p[1] == 1.0), "{:?}", &start.points[..6]);
        for _ in 0..20 {
            scene.step(0.01).expect("step");
        }
        let later = frame_of(scene.as_ref());
        let v = &later.field("velocity").expect("velocity").values;
        let moved = |k: usize| mean(&later.points, k) - mean(&start.points, k);
        let (dx, dy, dz) = (moved(0), moved(1), moved(2));
        assert!(
            dy < -0.05 && dx.abs() < 0.1 * dy.abs() && dz.abs() < 0.5 * dy.abs(),
            "moved by {dx} along x, {dy} along y, {dz} along z"
        );
        assert!(
            mean(v, 1) < 0.0 && mean(v, 1).abs() > mean(v, 0).abs(),
            "mean velocity {}, {}",
            mean(v, 0),
            mean(v, 1)
        );
    }

    #[test]
    fn the_frame_and_context_are_the_simulation_state_and_its_picture() {
        let mut scene = build_params(&serde_json::json!({ "preset": "hanging-cloth", "resolution": 4 }));
        let (sim, mut state) = scenes::hanging_cloth(Some(4)).expect("scene").into_simulation().expect("sim");
        let mut sim = sim;
        let context = scene.context();
        assert_eq!(context, sim.context(&state));
        assert_eq!(context.point_dim, 3);
        assert_eq!(context.pins, vec![0, 3]);
        assert_eq!(context.triangles.len(), 2 * 3 * 3);
        assert_eq!(context.lines.len(), sim.network().num_springs());
        assert_eq!(context.lines[0], [sim.network().springs()[0].i, sim.network().springs()[0].j]);
        // No ground, no sphere: the cloth falls, so the box reaches 1.3 sides below its top.
        // The network's box from (-1/3, -1/3, 1 - 1.3) to (4/3, 4/3, 1), z up, drawn y up.
        assert!(context.props.is_empty());
        assert_eq!(context.bounds, Some(([-1.0 / 3.0, 1.0 - 1.3, -4.0 / 3.0], [4.0 / 3.0, 1.0, 1.0 / 3.0])));
        assert_eq!(scene.method(), "backward-euler / cholesky");
        for _ in 0..2 {
            scene.step(0.01).expect("step");
            anim_core::solver::Solver::step(&mut sim, &mut state, 0.01).expect("step");
        }
        let frame = frame_of(scene.as_ref());
        assert_eq!(bits(&frame.points), bits(&y_up(&state.x)));
        assert_eq!(bits(&frame.field("velocity").expect("v").values), bits(&y_up(&state.v)));
        assert_eq!(frame.time.to_bits(), state.t.to_bits());
        // The jelly has the ground (z = 0 in the network, y = 0 drawn), and the rope is explicit.
        let jelly = build_params(&preset("jelly").params);
        let context = jelly.context();
        assert_eq!(context.props, vec![Prop::Ground { height: 0.0 }]);
        assert!(context.pins.is_empty());
        assert_eq!(context.bounds.expect("bounds").0[1], 0.0);
        let rope = build_params(&preset("rope").params);
        assert_eq!(rope.method(), "velocity-verlet");
        assert_eq!(rope.context().pins, vec![0]);
        assert!(rope.reference_error().is_none());
    }

    #[test]
    fn overrides_reach_the_simulation() {
        let scene = build_params(&serde_json::json!({
            "preset": "hanging-cloth", "resolution": 3,
            "integrator": { "beta-blend": { "beta": 0.5 } }, "linear_solver": "jacobi-pcg",
        }));
        assert_eq!(scene.method(), "beta-blend(0.5) / jacobi-pcg");
        let scene = build_params(&serde_json::json!({ "preset": "swinging-rope", "integrator": "rk4" }));
        assert_eq!(scene.method(), "rk4");
    }

    #[test]
    fn a_checkpoint_resumes_bit_for_bit() {
        for p in (KIND.presets)() {
            let params = p.quick_params.as_ref().unwrap_or(&p.params);
            let dt = p.run.dt;
            let mut a = build_params(params);
            for _ in 0..4 {
                a.step(dt).expect("step");
            }
            let text = serde_json::to_string(&a.save()).expect("json");
            for _ in 0..5 {
                a.step(dt).expect("step");
            }
            let mut b = build_params(params);
            b.restore(&serde_json::from_str(&text).expect("json")).expect("restore");
            for _ in 0..5 {
                b.step(dt).expect("step");
            }
            assert_eq!(a.save(), b.save(), "{}", p.name);
            let (fa, fb) = (frame_of(a.as_ref()), frame_of(b.as_ref()));
            assert_eq!(bits(&fa.points), bits(&fb.points), "{}", p.name);
            let v = |f: &Frame| bits(&f.field("velocity").expect("v").values);
            assert_eq!(v(&fa), v(&fb), "{}", p.name);
            assert_eq!(fa.time.to_bits(), fb.time.to_bits(), "{}", p.name);
        }
    }

    #[test]
    fn a_foreign_or_damaged_checkpoint_is_refused_and_changes_nothing() {
        let rope = build_params(&preset("rope").params);
        let mut cloth = build_params(&preset("cloth").quick_params.expect("quick"));
        cloth.step(0.01).expect("step");
        let before = cloth.save();
        let expect = |scene: &mut Box<dyn DynScene>, saved: &serde_json::Value, needle: &str| {
            let err = scene.restore(saved).expect_err("refused").to_string();
            assert!(err.contains(needle), "{needle}: {err}");
        };
        // Another preset: 40 particles against 64.
        expect(
            &mut cloth,
            &rope.save(),
            "`state`: 120 positions and 120 velocities; this scene has 192 and 192",
        );
        // Another integrator's memory (velocity Verlet's into backward Euler).
        let mut other = before.clone();
        other["saved"]["simulation"] = rope.save()["saved"]["simulation"].clone();
        expect(&mut cloth, &other, "`simulation`");
        let mut damaged = before.clone();
        damaged["saved"]["state"]["x"].as_array_mut().expect("x").pop();
        expect(&mut cloth, &damaged, "`state`: 191 positions");
        let mut missing = before.clone();
        missing["saved"].as_object_mut().expect("object").remove("simulation");
        expect(&mut cloth, &missing, "the checkpoint has no `simulation`");
        let mut missing = before.clone();
        missing["saved"]["simulation"].as_object_mut().expect("object").remove("steps");
        expect(&mut cloth, &missing, "`simulation`: checkpoint does not fit this simulation: no step count");
        let mut missing = before.clone();
        missing["saved"].as_object_mut().expect("object").remove("state");
        expect(&mut cloth, &missing, "the checkpoint has no `state`");
        let mut old = before.clone();
        old["version"] = serde_json::json!(2);
        expect(&mut cloth, &old, "layout version 2");
        assert_eq!(cloth.save(), before);
    }

    #[test]
    fn an_overflow_fails_the_step_and_leaves_the_scene_as_it_was() {
        for p in (KIND.presets)() {
            let mut scene = build_params(p.quick_params.as_ref().unwrap_or(&p.params));
            scene.step(p.run.dt).expect("step");
            let what = scene.provoke_overflow().expect("provoked");
            assert!(what.contains("f64::MAX"), "{what}");
            let before = scene.save();
            let err: StepError = scene.step(p.run.dt).expect_err("overflow");
            let msg = err.to_string();
            assert!(msg.starts_with("anim-springs: step 1: non-finite "), "{}: {msg}", p.name);
            assert!(
                matches!(err.get::<crate::SpringError>(), Some(crate::SpringError::NonFinite(_))),
                "{msg}"
            );
            assert_eq!(scene.save(), before, "{}", p.name);
        }
    }

    #[test]
    fn bad_parameters_name_their_field() {
        let msg = build_err(&serde_json::json!({ "preset": "hanging-cloth", "resolutoin": 8 }));
        assert!(msg.contains("unknown field `resolutoin`"), "{msg}");
        let msg = build_err(&serde_json::json!({ "resolution": 8 }));
        assert_eq!(
            msg,
            "field `preset`: give a built-in `preset` (one of hanging-cloth, swinging-rope, jelly-drop, benchmark-cloth) or `[[scene.bodies]]`"
        );
        for (field, value) in [
            ("obstacles", serde_json::json!([{ "sphere": { "center": [0, 0, 0], "radius": 1 } }])),
            ("gravity", serde_json::json!([0, 0, -1])),
            ("contact", serde_json::json!({ "stiffness": 1.0 })),
        ] {
            let msg = build_err(&serde_json::json!({ "preset": "hanging-cloth", field: value }));
            assert_eq!(
                msg,
                format!("field `{field}`: only with `bodies`: the preset `hanging-cloth` has its own")
            );
        }
        let msg = build_err(&serde_json::json!({ "preset": "flying-carpet" }));
        assert_eq!(
            msg,
            "field `preset`: unknown preset `flying-carpet` (one of hanging-cloth, swinging-rope, jelly-drop, benchmark-cloth)"
        );
        let msg = build_err(&serde_json::json!({ "preset": "hanging-cloth", "resolution": 1 }));
        assert!(msg.starts_with("field `resolution`: ") && msg.contains('1'), "{msg}");
        let msg = build_err(&serde_json::json!({ "preset": "swinging-rope", "resolution": 2 }));
        assert!(msg.starts_with("field `resolution`: "), "{msg}");
        let msg = build_err(&serde_json::json!({
            "preset": "hanging-cloth", "integrator": { "beta-blend": { "beta": 2.0 } },
        }));
        assert_eq!(msg, "field `integrator`: beta must lie in [0, 1], got 2");
        let msg = build_err(&serde_json::json!({ "preset": "hanging-cloth", "integrator": "warp-drive" }));
        assert!(msg.contains("warp-drive"), "{msg}");
        let msg = build_err(&serde_json::json!({ "preset": "hanging-cloth", "linear_solver": "lu" }));
        assert!(msg.contains("lu"), "{msg}");
    }
}
