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
//! A scene file's `[scene]` table (`kind = "springs"`) holds the fields of [`SpringsParams`].
//! The scene is a [`SpringSimulation`] with its [`State`]: it implements
//! [`Checkpoint`] (the state and the simulation's memory, the integrator's included) and
//! [`View`] (the particles and their velocities; springs as lines, cloth triangles, pinned
//! particles, the ground and sphere colliders).

use crate::contact::Shape;
use crate::scenes;
use crate::sim::SpringSimulation;
use anim_core::integrate::{IntegratorKind, State};
use anim_core::linalg::LinearSolverKind;
use anim_core::scene::{
    BuildContext, BuildError, Checkpoint, CheckpointError, Context, DynScene, Frame, Preset, Prop,
    RunDefaults, SceneKind, Simulated, View, params, saved_state,
};
use serde::{Deserialize, Serialize};

/// The `springs` scene kind of anim-springs, for the workspace registry.
pub const KIND: SceneKind = SceneKind {
    kind: "springs",
    crate_name: "anim-springs",
    summary: "mass-spring networks (cloth, ropes, jelly) under any integrator of anim-core",
    presets,
    build,
};

/// Scene-file parameters of a `springs` scene: a preset of [`scenes`] with its own integrator
/// and linear solver unless overridden.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpringsParams {
    /// The preset's name: `hanging-cloth`, `swinging-rope`, `jelly-drop` or `benchmark-cloth`
    /// ([`scenes::NAMES`]). Required.
    pub preset: String,
    /// Particles per side (the preset's default when absent: 32 for the cloth, 40 for the rope,
    /// 6 for the jelly, 128 for the benchmark cloth); at least 2 (3 for the rope), at most 4096.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub resolution: Option<usize>,
    /// Integrator override (the preset's when absent); a beta-blend's `beta` in `[0, 1]`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub integrator: Option<IntegratorKind>,
    /// Linear solver override for implicit integrators (the preset's when absent).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub linear_solver: Option<LinearSolverKind>,
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
fn build(value: &serde_json::Value, _: &BuildContext<'_>) -> Result<Box<dyn DynScene>, BuildError> {
    let p: SpringsParams = params(value)?;
    if let Some(integrator) = &p.integrator {
        integrator.validate().map_err(|m| BuildError::invalid("integrator", m))?;
    }
    let mut scene = match scenes::by_name(&p.preset, p.resolution) {
        Some(Ok(scene)) => scene,
        Some(Err(e)) => return Err(BuildError::invalid("resolution", e.to_string())),
        None => {
            return Err(BuildError::invalid(
                "preset",
                format!("unknown preset `{}` (one of {})", p.preset, scenes::NAMES.join(", ")),
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

impl Checkpoint for SpringSimulation {
    const VERSION: u32 = 1;

    fn time(&self, state: &State) -> f64 {
        state.t
    }

    fn save(&self, state: &State) -> serde_json::Value {
        serde_json::json!({ "state": state, "simulation": self.memory() })
    }

    fn restore(&mut self, state: &mut State, saved: &serde_json::Value) -> Result<(), CheckpointError> {
        let restored = saved_state(saved, "state", state)?;
        let memory =
            saved.get("simulation").ok_or_else(|| CheckpointError::Missing { field: "simulation".into() })?;
        // The memory is checked and taken whole, or not at all.
        self.restore_memory(memory).map_err(|e| CheckpointError::invalid("simulation", e.to_string()))?;
        *state = restored;
        Ok(())
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
        let ground = colliders.iter().find_map(|c| match c.shape {
            Shape::Plane { point, normal: [0.0, 0.0, 1.0] } => Some(point[2]),
            _ => None,
        });
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
        context.props.extend(colliders.iter().filter_map(|c| match c.shape {
            Shape::Sphere { center, radius } => Some(Prop::Sphere { center, radius }),
            Shape::Plane { .. } => None,
        }));
        context.bounds = Some(anim_core::scene::frame_box(&state.x, ground, true));
        context
    }

    fn frame(&self, state: &State, out: &mut Frame) {
        out.time = state.t;
        out.points.clone_from(&state.x);
        out.field_mut("velocity", 3).extend_from_slice(&state.v);
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
        assert!(context.props.is_empty());
        assert_eq!(context.bounds, Some(([-1.0 / 3.0, -1.0 / 3.0, 1.0 - 1.3], [4.0 / 3.0, 4.0 / 3.0, 1.0])));
        assert_eq!(scene.method(), "backward-euler / cholesky");
        for _ in 0..2 {
            scene.step(0.01).expect("step");
            anim_core::solver::Solver::step(&mut sim, &mut state, 0.01).expect("step");
        }
        let frame = frame_of(scene.as_ref());
        assert_eq!(bits(&frame.points), bits(&state.x));
        assert_eq!(bits(&frame.field("velocity").expect("v").values), bits(&state.v));
        assert_eq!(frame.time.to_bits(), state.t.to_bits());
        // The jelly has the ground, and the rope is explicit.
        let jelly = build_params(&preset("jelly").params);
        let context = jelly.context();
        assert_eq!(context.props, vec![Prop::Ground { height: 0.0 }]);
        assert!(context.pins.is_empty());
        assert_eq!(context.bounds.expect("bounds").0[2], 0.0);
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
        assert!(msg.contains("missing field `preset`"), "{msg}");
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
