//! The `rigid` scene kind through anim-core's dynamic scene contracts: every preset builds,
//! steps and draws; its frames are the segment end points with finite-difference velocities;
//! checkpoints resume bit for bit and foreign or damaged ones are refused; an overflow fails the
//! step and leaves the scene as it was; bad parameters name their field.

#![allow(clippy::unwrap_used, clippy::expect_used)] // integration tests: a failed unwrap is a failed test

use anim_core::scene::{BuildContext, CheckpointError, DynScene, Frame, Preset};
use anim_rigid::KIND;
use anim_rigid::scenes;

fn build(params: &serde_json::Value) -> Box<dyn DynScene> {
    (KIND.build)(params, &BuildContext::default()).unwrap()
}

fn preset(name: &str) -> Preset {
    (KIND.presets)().into_iter().find(|p| p.name == name).unwrap()
}

fn frame(scene: &dyn DynScene) -> Frame {
    let mut f = Frame::default();
    scene.frame(&mut f);
    f
}

/// Flat z-up triples `(x, y, z)` as the y-up `(x, z, -y)` every frame has.
fn y_up(values: &[f64]) -> Vec<f64> {
    values.chunks_exact(3).flat_map(|p| [p[0], p[2], -p[1]]).collect()
}

fn bits(f: &Frame) -> Vec<u64> {
    let v = &f.field("velocity").unwrap().values;
    [f.time].iter().chain(&f.points).chain(v).map(|x| x.to_bits()).collect()
}

fn build_error(params: serde_json::Value) -> String {
    (KIND.build)(&params, &BuildContext::default()).err().expect("refused").to_string()
}

#[test]
fn the_presets_are_the_command_lines_built_in_rigid_scenes() {
    let presets = (KIND.presets)();
    let names: Vec<_> = presets.iter().map(|p| (p.name, p.params.clone(), p.run)).collect();
    assert_eq!(
        names,
        [
            (
                "panda",
                serde_json::json!({"preset": "panda-swing"}),
                anim_core::scene::RunDefaults::new(0.001, 100, 30)
            ),
            (
                "chain",
                serde_json::json!({"preset": "pendulum-chain"}),
                anim_core::scene::RunDefaults::new(0.0005, 100, 60)
            ),
            (
                "t-handle",
                serde_json::json!({"preset": "t-handle"}),
                anim_core::scene::RunDefaults::new(0.001, 120, 200)
            ),
        ]
    );
    assert_eq!(KIND.kind, "rigid");
}

#[test]
fn every_preset_builds_steps_three_times_and_moves() {
    for preset in (KIND.presets)() {
        for params in [Some(&preset.params), preset.quick_params.as_ref()].into_iter().flatten() {
            let mut scene = build(params);
            let start = frame(scene.as_ref());
            let dt = preset.run.dt;
            for _ in 0..3 {
                scene.step(dt).unwrap();
            }
            let f = frame(scene.as_ref());
            let name = preset.name;
            assert_eq!(f.time.to_bits(), (dt + dt + dt).to_bits(), "{name}");
            assert!((f.time - 3.0 * dt).abs() < 1e-15, "{name}");
            let v = &f.field("velocity").unwrap().values;
            assert_eq!(v.len(), f.points.len(), "{name}");
            assert!(f.points.iter().chain(v).all(|x| x.is_finite()), "{name}");
            assert!(f.points.iter().zip(&start.points).any(|(a, b)| a != b), "{name}: nothing moved");
            assert!(v.iter().any(|x| *x != 0.0), "{name}: no velocity");
            let context = scene.context();
            assert_eq!(context.point_dim, 3);
            assert_eq!(context.lines.len() * 6, f.points.len(), "{name}");
            assert!(context.point_radius > 0.0);
            assert!(context.props.is_empty() && context.triangles.is_empty());
        }
    }
}

/// The run loop of the command line's former rigid runner, written out: the display is the
/// segments' end points after every step, velocities by difference over `dt`, the time the
/// bodies' own; the frame must match it bit for bit once turned from the bodies' z up to the
/// frames' y up.
#[test]
fn frames_are_the_segment_end_points_with_velocities_by_difference() {
    use anim_core::solver::Solver;
    for (name, scene_name) in
        [("panda", "panda-swing"), ("chain", "pendulum-chain"), ("t-handle", "t-handle")]
    {
        let p = preset(name);
        let mut scene = build(&p.params);
        let reference = scenes::by_name(scene_name).unwrap().unwrap();
        let segments = reference.segments.clone();
        let mut data = anim_rigid::Data::new(&reference.model);
        let (mut sim, mut state) = reference.into_simulation().unwrap();
        let mut points = Vec::new();
        let mut x: Vec<f64> = Vec::new();
        let mut v: Vec<f64> = Vec::new();
        for step in 0..=12 {
            if step > 0 {
                sim.step(&mut state, p.run.dt).unwrap();
                scene.step(p.run.dt).unwrap();
            }
            scenes::segment_points(sim.model(), &mut data, &state.q, &segments, &mut points);
            let new: Vec<f64> = points.iter().flatten().flat_map(|p| p.to_array()).collect();
            v = if step == 0 {
                vec![0.0; new.len()]
            } else {
                new.iter().zip(&x).map(|(a, b)| (a - b) / p.run.dt).collect()
            };
            x = new;
            if step == 0 {
                let radius =
                    0.06 * points.iter().map(|[a, b]| (*a - *b).length()).fold(0.0, f64::max).max(1e-3);
                let context = scene.context();
                assert_eq!(context.point_radius.to_bits(), radius.to_bits(), "{name}");
                let (lo, hi) = context.bounds.unwrap();
                for q in y_up(&x).chunks_exact(3) {
                    assert!(
                        (0..3).all(|k| lo[k] <= q[k] && q[k] <= hi[k]),
                        "{name}: {q:?} outside {lo:?} {hi:?}"
                    );
                }
            }
        }
        let (x, v) = (y_up(&x), y_up(&v));
        let expected: Vec<u64> = [state.t].iter().chain(&x).chain(&v).map(|x| x.to_bits()).collect();
        assert_eq!(bits(&frame(scene.as_ref())), expected, "{name}");
        assert_eq!(scene.method(), format!("{:?}", sim.integrator()).to_lowercase());
    }
    assert_eq!(build(&preset("panda").params).method(), "rk4");
    assert_eq!(build(&preset("t-handle").params).method(), "freebodymidpoint");
}

#[test]
fn the_fixed_base_and_hinge_are_pins_and_the_free_body_has_none() {
    // The Panda's first segment runs from the world origin to joint 1, which turns about its
    // own origin; joint 2 sits at the same point (its placement is a rotation only), so the
    // second segment (joint 1 to 2) and the start of the third are fixed too. The chain hangs
    // from its first hinge.
    assert_eq!(build(&preset("panda").params).context().pins, [0, 1, 2, 3, 4]);
    assert_eq!(build(&preset("chain").params).context().pins, [0]);
    assert!(build(&preset("t-handle").params).context().pins.is_empty());
    // Pins do not move.
    let mut chain = build(&preset("chain").params);
    let before = frame(chain.as_ref());
    for _ in 0..20 {
        chain.step(5e-4).unwrap();
    }
    assert_eq!(frame(chain.as_ref()).points[..3], before.points[..3]);
}

#[test]
fn a_checkpoint_resumes_bit_for_bit() {
    for p in (KIND.presets)() {
        let dt = p.run.dt;
        let mut a = build(&p.params);
        for _ in 0..4 {
            a.step(dt).unwrap();
        }
        let (text, t4) = (a.save().to_string(), a.time());
        for _ in 0..5 {
            a.step(dt).unwrap();
        }
        let mut b = build(&p.params);
        b.restore(&serde_json::from_str(&text).unwrap()).unwrap();
        assert_eq!(b.time().to_bits(), t4.to_bits());
        for _ in 0..5 {
            b.step(dt).unwrap();
        }
        assert_eq!(a.save(), b.save(), "{}", p.name);
        assert_eq!(bits(&frame(a.as_ref())), bits(&frame(b.as_ref())), "{}", p.name);
    }
}

#[test]
fn a_foreign_or_damaged_checkpoint_is_refused_and_changes_nothing() {
    let mut panda = build(&preset("panda").params);
    panda.step(1e-3).unwrap();
    let before = panda.save();
    let mut other = build(&preset("chain").params);
    other.step(5e-4).unwrap();
    let err = panda.restore(&other.save()).unwrap_err();
    assert_eq!(
        err,
        CheckpointError::invalid("rigid", "32 coordinates and 32 velocities; this model has 7 and 7")
    );
    let handle = build(&preset("t-handle").params);
    let err = panda.restore(&handle.save()).unwrap_err();
    assert_eq!(
        err,
        CheckpointError::invalid("rigid", "7 coordinates and 6 velocities; this model has 7 and 7")
    );
    assert_eq!(panda.save(), before);

    // Missing fields, each named.
    for field in ["rigid", "display", "simulation"] {
        let mut damaged = before.clone();
        damaged["saved"].as_object_mut().unwrap().remove(field);
        assert_eq!(panda.restore(&damaged).unwrap_err(), CheckpointError::Missing { field: field.into() });
        assert_eq!(panda.save(), before);
    }
    // Wrong sizes and values.
    let mut damaged = before.clone();
    damaged["saved"]["display"]["x"].as_array_mut().unwrap().pop();
    let err = panda.restore(&damaged).unwrap_err();
    assert!(matches!(&err, CheckpointError::Invalid { field, .. } if field == "display"), "{err}");
    let mut damaged = before.clone();
    damaged["saved"]["rigid"]["v"].as_array_mut().unwrap().pop();
    let err = panda.restore(&damaged).unwrap_err();
    assert!(err.to_string().starts_with("`rigid`: 7 coordinates and 6 velocities"), "{err}");
    let mut damaged = before.clone();
    damaged["saved"]["display"]["t"] = serde_json::json!(0.5);
    let err = panda.restore(&damaged).unwrap_err();
    assert!(matches!(&err, CheckpointError::Invalid { field, .. } if field == "display"), "{err}");
    let mut damaged = before.clone();
    damaged["saved"]["simulation"] = serde_json::json!({ "newton_matrix": null });
    let err = panda.restore(&damaged).unwrap_err();
    assert!(matches!(&err, CheckpointError::Invalid { field, .. } if field == "simulation"), "{err}");
    let mut damaged = before.clone();
    damaged["saved"]["rigid"]["q"] = serde_json::json!("nope");
    let err = panda.restore(&damaged).unwrap_err();
    assert!(matches!(&err, CheckpointError::Invalid { field, .. } if field == "rigid"), "{err}");
    assert_eq!(panda.save(), before);
    // The scene still runs as if nothing had happened.
    let mut twin = build(&preset("panda").params);
    twin.step(1e-3).unwrap();
    panda.step(1e-3).unwrap();
    twin.step(1e-3).unwrap();
    assert_eq!(panda.save(), twin.save());
}

#[test]
fn an_overflow_fails_the_step_and_leaves_the_scene_as_it_was() {
    for p in (KIND.presets)() {
        let mut scene = build(&p.params);
        scene.step(p.run.dt).unwrap();
        assert!(scene.provoke_overflow().is_some());
        let before = scene.save();
        let frame_before = bits(&frame(scene.as_ref()));
        let err = scene.step(p.run.dt).unwrap_err();
        let msg = err.to_string();
        assert!(msg.starts_with("anim-rigid: step 1: non-finite"), "{}: {msg}", p.name);
        assert!(err.get::<anim_rigid::sim::SimError>().is_some());
        assert_eq!(scene.save(), before, "{}", p.name);
        assert_eq!(bits(&frame(scene.as_ref())), frame_before, "{}", p.name);
    }
}

#[test]
fn bad_parameters_name_their_field() {
    let err = build_error(serde_json::json!({ "preset": "t-handle", "resolution": 8 }));
    assert!(err.contains("unknown field `resolution`"), "{err}");
    let err = build_error(serde_json::json!({ "preset": "pendulum" }));
    assert_eq!(
        err,
        "field `preset`: unknown preset `pendulum` (one of panda-swing, pendulum-chain, t-handle)"
    );
    let err = build_error(serde_json::json!({}));
    assert!(
        err.starts_with("field `preset`: give a built-in `preset`") && err.contains("`robot` table"),
        "{err}"
    );
    let err = build_error(serde_json::json!({ "preset": 3 }));
    assert!(err.contains("invalid type"), "{err}");
}
