//! The `fem` scene kind through [`anim_core::scene`]: every preset builds, steps, checkpoints
//! and refuses what does not fit it.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use crate::KIND;
use crate::kind::FemSceneParams;
use anim_core::scene::{BuildContext, CheckpointError, DynScene, Frame, Preset, Prop};
use serde_json::json;

fn build(params: &serde_json::Value) -> Box<dyn DynScene> {
    (KIND.build)(params, &BuildContext::default()).expect("builds")
}

fn refused(params: &serde_json::Value) -> String {
    (KIND.build)(params, &BuildContext::default()).err().expect("refused").to_string()
}

fn preset(name: &str) -> Preset {
    (KIND.presets)().into_iter().find(|p| p.name == name).expect("preset")
}

fn quick(p: &Preset) -> &serde_json::Value {
    p.quick_params.as_ref().unwrap_or(&p.params)
}

fn frame_of(scene: &dyn DynScene) -> Frame {
    let mut f = Frame::default();
    scene.frame(&mut f);
    f
}

fn bits(f: &Frame) -> Vec<u64> {
    let mut b: Vec<u64> = f.points.iter().map(|v| v.to_bits()).collect();
    for field in &f.fields {
        b.extend(field.values.iter().map(|v| v.to_bits()));
    }
    b.push(f.time.to_bits());
    b
}

#[test]
fn the_presets_are_the_command_lines_built_in_fem_scenes() {
    let presets = (KIND.presets)();
    let names: Vec<_> = presets.iter().map(|p| p.name).collect();
    assert_eq!(names, ["beam", "cube", "twisted-bar"]);
    assert_eq!(presets[0].params, json!({ "preset": "cantilever-beam" }));
    assert_eq!(presets[0].run.dt, 1.0 / 60.0);
    assert_eq!((presets[0].run.frames, presets[0].run.steps_per_frame), (120, 1));
    assert_eq!(presets[1].params, json!({ "preset": "soft-cube-drop" }));
    assert_eq!((presets[1].run.dt, presets[1].run.frames, presets[1].run.steps_per_frame), (0.005, 100, 2));
    assert_eq!(presets[2].params, json!({ "preset": "twisted-bar" }));
    assert_eq!((presets[2].run.dt, presets[2].run.frames, presets[2].run.steps_per_frame), (0.01, 100, 1));
    for p in &presets {
        // The parameters read back as they are written.
        let read: FemSceneParams = serde_json::from_value(p.params.clone()).expect("params");
        assert_eq!(serde_json::to_value(&read).expect("json"), p.params, "{}", p.name);
        let q = p.quick_params.as_ref().expect("quick");
        assert_eq!(q["preset"], p.params["preset"], "{}", p.name);
    }
}

#[test]
fn every_preset_steps_three_times_and_moves() {
    for p in (KIND.presets)() {
        for params in [Some(&p.params), p.quick_params.as_ref()].into_iter().flatten() {
            let mut scene = build(params);
            let before = frame_of(scene.as_ref());
            let context = scene.context();
            assert_eq!(context.point_dim, 3);
            assert_eq!(before.points.len() % 3, 0);
            for _ in 0..3 {
                scene.step(p.run.dt).expect("step");
            }
            let f = frame_of(scene.as_ref());
            assert!((f.time - 3.0 * p.run.dt).abs() < 1e-12, "{}: t = {}", p.name, f.time);
            assert_eq!(scene.time().to_bits(), f.time.to_bits());
            let v = &f.field("velocity").expect("velocity").values;
            assert_eq!((f.points.len(), v.len()), (before.points.len(), before.points.len()));
            assert!(f.points.iter().chain(v).all(|x| x.is_finite()), "{}", p.name);
            assert_ne!(f.points, before.points, "{}: nothing moved", p.name);
            assert!(v.iter().any(|&x| x != 0.0), "{}", p.name);
        }
    }
}

#[test]
fn the_context_names_surface_tetrahedra_pins_and_ground() {
    // The beam of 20 x 2 x 2 cells: 6 tetrahedra a cell, the 3 x 3 nodes at x = 0 clamped.
    let mut beam = build(&json!({ "preset": "cantilever-beam", "resolution": 2 }));
    let c = beam.context();
    assert_eq!(c.tetrahedra.len(), 6 * 20 * 2 * 2);
    assert_eq!(c.pins.len(), 9);
    assert!(c.props.is_empty() && c.lines.is_empty() && c.point_radius == 0.0 && c.image.is_none());
    let f = frame_of(beam.as_ref());
    let nodes = f.points.len() / 3;
    assert!(c.triangles.iter().flatten().chain(c.tetrahedra.iter().flatten()).all(|&i| i < nodes));
    for &pin in &c.pins {
        assert!(f.points[3 * pin].abs() < 1e-9, "pin {pin} is not on the clamped face");
    }
    // The region: the rest box (x in [0, 1], y in [-0.05, 0.05], z in [0.5, 0.6], z up)
    // widened by a third of its size (1 m) sideways and reaching 1.3 sizes below its top, drawn
    // y up: (x, y, z) -> (x, z, -y).
    let (lo, hi) = c.bounds.expect("bounds");
    let third = 1.0 / 3.0;
    let expected = ([-third, 0.6 - 1.3, -0.05 - third], [1.0 + third, 0.6, 0.05 + third]);
    for k in 0..3 {
        assert!(
            (lo[k] - expected.0[k]).abs() < 1e-12 && (hi[k] - expected.1[k]).abs() < 1e-12,
            "{lo:?} {hi:?}"
        );
    }
    // Clamped nodes stay where they are.
    beam.step(0.01).expect("step");
    let g = frame_of(beam.as_ref());
    for &pin in &c.pins {
        assert_eq!(g.points[3 * pin..3 * pin + 3], f.points[3 * pin..3 * pin + 3]);
    }
    // 10-node elements: the corner tetrahedra, and the clamped face's edge nodes pinned too.
    let beam10 = build(&json!({ "preset": "cantilever-beam", "resolution": 2, "element": "tet10" }));
    let c10 = beam10.context();
    assert_eq!(c10.tetrahedra, c.tetrahedra);
    assert_eq!(c10.pins.len(), 25);
    assert!(frame_of(beam10.as_ref()).points.len() > f.points.len());
    // The twisted bar holds both ends; the cube is free above the ground z = 0, drawn y = 0.
    let bar = build(&json!({ "preset": "twisted-bar", "resolution": 2 })).context();
    assert_eq!(bar.pins.len(), 18);
    let cube = build(&json!({ "preset": "soft-cube-drop", "resolution": 2 })).context();
    assert!(cube.pins.is_empty());
    assert_eq!(cube.props, [Prop::Ground { height: 0.0 }]);
    assert_eq!(cube.bounds.expect("bounds").0[1], 0.0);
}

#[test]
fn the_method_names_integrator_solver_and_element() {
    let beam = |extra: serde_json::Value| {
        let mut p = json!({ "preset": "cantilever-beam", "resolution": 1 });
        p.as_object_mut().expect("object").extend(extra.as_object().expect("object").clone());
        build(&p)
    };
    assert_eq!(beam(json!({})).method(), "backward-euler / cholesky");
    assert_eq!(beam(json!({ "element": "tet10" })).method(), "backward-euler / cholesky / tet10");
    let mut explicit = beam(json!({ "integrator": "symplectic-euler", "linear_solver": "jacobi-pcg" }));
    assert_eq!(explicit.method(), "symplectic-euler / jacobi-pcg");
    // An explicit step has no Newton update to report; the preset's backward Euler has.
    assert_eq!(explicit.step(1e-5).expect("step").residual, None);
    let report = beam(json!({})).step(1e-2).expect("step");
    assert!(report.iterations >= 1 && report.residual.is_some(), "{report:?}");
    assert_eq!(beam(json!({ "linear_solver": "ldlt" })).method(), "backward-euler / ldlt");
    assert_eq!(beam(json!({})).reference_error(), None);
}

#[test]
fn a_checkpoint_resumes_bit_for_bit() {
    for p in (KIND.presets)() {
        let params = quick(&p);
        let dt = p.run.dt;
        let mut a = build(params);
        for _ in 0..4 {
            a.step(dt).expect("step");
        }
        let text = a.save().to_string();
        for _ in 0..5 {
            a.step(dt).expect("step");
        }
        let mut b = build(params);
        b.restore(&serde_json::from_str(&text).expect("json")).expect("restore");
        for _ in 0..5 {
            b.step(dt).expect("step");
        }
        assert_eq!(a.save(), b.save(), "{}", p.name);
        assert_eq!(bits(&frame_of(a.as_ref())), bits(&frame_of(b.as_ref())), "{}", p.name);
        assert_eq!(a.save()["saved"]["simulation"]["steps"], json!(9), "{}", p.name);
    }
}

#[test]
fn a_foreign_or_damaged_checkpoint_is_refused_and_changes_nothing() {
    let cube = build(quick(&preset("cube")));
    let mut beam = build(quick(&preset("beam")));
    beam.step(preset("beam").run.dt).expect("step");
    let before = beam.save();
    let check = |beam: &mut Box<dyn DynScene>, saved: serde_json::Value, field: &str| {
        let err = beam.restore(&saved).expect_err("refused");
        assert!(err.to_string().contains(&format!("`{field}`")), "{field}: {err}");
        assert_eq!(beam.save(), before, "{field}: the refusal changed the scene");
        err
    };
    // Another preset: other sizes.
    let err = check(&mut beam, cube.save(), "state");
    assert!(err.to_string().contains("this scene has"), "{err}");
    // Damaged: a position short, a velocity of the wrong type, no memory, no step count.
    let mut short = before.clone();
    short["saved"]["state"]["x"].as_array_mut().expect("x").pop();
    check(&mut beam, short, "state");
    let mut wrong = before.clone();
    wrong["saved"]["state"]["v"][0] = json!("fast");
    check(&mut beam, wrong, "state");
    let mut no_memory = before.clone();
    no_memory["saved"].as_object_mut().expect("saved").remove("simulation");
    let err = check(&mut beam, no_memory, "simulation");
    assert_eq!(err, CheckpointError::Missing { field: "simulation".into() });
    let mut no_steps = before.clone();
    no_steps["saved"]["simulation"] = json!({});
    let err = check(&mut beam, no_steps, "simulation");
    assert!(err.to_string().contains("no step count"), "{err}");
    let mut no_state = before.clone();
    no_state["saved"].as_object_mut().expect("saved").remove("state");
    check(&mut beam, no_state, "state");
    let mut old = before.clone();
    old["version"] = json!(7);
    assert_eq!(beam.restore(&old), Err(CheckpointError::Version { found: 7, expected: 1 }));
    assert_eq!(beam.save(), before);
}

#[test]
fn an_overflow_fails_the_step_and_leaves_the_scene_as_it_was() {
    for p in (KIND.presets)() {
        let mut scene = build(quick(&p));
        scene.step(p.run.dt).expect("step");
        let what = scene.provoke_overflow().expect("provoked");
        assert!(what.contains("f64::MAX"), "{what}");
        let before = scene.save();
        let frame = bits(&frame_of(scene.as_ref()));
        let err = scene.step(p.run.dt).expect_err("overflow");
        let msg = err.to_string();
        assert!(msg.starts_with("anim-fem: step 1: ") && msg.contains("non-finite"), "{}: {msg}", p.name);
        assert!(err.get::<crate::FemError>().is_some());
        assert_eq!(scene.save(), before, "{}", p.name);
        assert_eq!(bits(&frame_of(scene.as_ref())), frame, "{}", p.name);
    }
}

#[test]
fn bad_parameters_name_their_field() {
    let msg = refused(&json!({ "preset": "cantilever-beam", "resolutoin": 2 }));
    assert!(msg.contains("unknown field `resolutoin`"), "{msg}");
    let msg = refused(&json!({ "preset": "flying-carpet" }));
    assert_eq!(
        msg,
        "field `preset`: unknown preset `flying-carpet` (one of cantilever-beam, soft-cube-drop, twisted-bar)"
    );
    let msg = refused(&json!({ "preset": "cantilever-beam", "resolution": 0 }));
    assert!(msg.starts_with("field `resolution`: "), "{msg}");
    let msg = refused(&json!({ "preset": "cantilever-beam", "linear_solver": "lu" }));
    assert!(msg.contains("unknown variant `lu`") && msg.contains("jacobi-pcg"), "{msg}");
    let msg = refused(&json!({ "preset": "cantilever-beam", "element": "tet7" }));
    assert!(msg.contains("tet7") && msg.contains("tet10"), "{msg}");
    let msg = refused(&json!({ "resolution": 2 }));
    assert!(msg.starts_with("field `preset`: give a built-in `preset`") && msg.contains("`bodies`"), "{msg}");
}

mod tolerance {
    use crate::kind::{KIND, fem_label};
    use crate::material::MaterialModel;
    use crate::sim::{LinearSolverChoice, TimeIntegrator};
    use anim_core::scene::study::{Point, family};

    #[test]
    fn labels_of_the_fem_study_parse_back() {
        // The beam study's labels, spelled as its brief gives them.
        for model in MaterialModel::ALL {
            assert_eq!(
                fem_label(&format!("{} symplectic-euler", model.name())),
                Some((model, TimeIntegrator::SymplecticEuler, None))
            );
            for solver in LinearSolverChoice::ALL {
                assert_eq!(
                    fem_label(&format!("{} backward-euler ({})", model.name(), solver.name())),
                    Some((model, TimeIntegrator::BackwardEuler, Some(solver)))
                );
            }
        }
        assert_eq!(
            fem_label("linear backward-euler"),
            Some((MaterialModel::Linear, TimeIntegrator::BackwardEuler, None))
        );
        for bad in [
            "stable-neo-hookean",
            "rubber symplectic-euler",
            "linear backward-euler (lu)",
            "linear backward-eulerx",
        ] {
            assert_eq!(fem_label(bad), None, "{bad}");
        }
    }

    #[test]
    fn the_beam_keeps_its_material_and_scales_the_studys_step() {
        let f = family(
            "fem-beam",
            "fem/cantilever-beam",
            Some(0.5),
            &[("young", 1e6), ("density", 1000.0), ("cell", 0.05)],
            &[],
        );
        let preset = (KIND.presets)().into_iter().find(|p| p.name == "beam").expect("preset");
        let adapter =
            (KIND.tolerance.expect("mapped").adapter)(&preset.params, &preset.run, &f).expect("adapter");
        let pt = Point { param: 2.5e-3, seconds: 0.2, error: 8e-3 };
        let e = adapter.candidate("neo-hookean symplectic-euler", &pt).unwrap_err();
        assert_eq!(e, "neo-hookean material (the scene's is stable-neo-hookean)");
        let c =
            adapter.candidate("stable-neo-hookean backward-euler (ldlt)", &pt).expect("the scene's material");
        assert_eq!(c.summary, "integrator = backward-euler, linear_solver = ldlt");
        assert_eq!(c.settings.get("linear_solver"), Some(&serde_json::json!("ldlt")));
        // The preset: E = 10 MPa, rho = 1000, 4 cells across 0.1 m; the study's beam E = 1 MPa,
        // 2 cells: wave speeds sqrt(1e6 / 1e7), cells 0.025 / 0.05; the scene runs 120 frames of
        // 1/60 s = 2 s, four times the 0.5 s horizon, a first-order method: (1/4)^2.
        let dt = 2.5e-3 * (0.1f64).sqrt() * 0.5 / 16.0;
        let got = c.dt.expect("a step");
        assert!((got - dt).abs() < 1e-9 * dt, "{got} != {dt}");
        assert_eq!(c.note, "wave speed and cell ratios 0.1581 x run length (H/T)^2 = 0.0625");
        let c = adapter.candidate("stable-neo-hookean symplectic-euler", &pt).expect("explicit");
        assert_eq!(c.summary, "integrator = symplectic-euler");
    }
}

/// A preset's resolution past the memory available is refused before the mesh is made, naming
/// the field, the estimate and the memory; one that fits is built.
#[test]
fn a_preset_resolution_past_the_memory_is_refused() {
    for (preset, resolution, element) in [
        ("soft-cube-drop", 100_000, "tet4"),
        ("cantilever-beam", 1_000_000_000, "tet4"),
        ("twisted-bar", 50_000, "tet10"),
    ] {
        let start = std::time::Instant::now();
        let e = (KIND.build)(
            &json!({ "preset": preset, "resolution": resolution, "element": element }),
            &Default::default(),
        )
        .err()
        .expect("refused");
        assert!(start.elapsed().as_secs_f64() < 1.0, "{preset}: {:?}", start.elapsed());
        let msg = e.to_string();
        assert!(matches!(e, anim_core::scene::BuildError::Memory { .. }), "{preset}: {msg}");
        assert!(
            msg.starts_with(&format!("field `resolution`: {resolution} cells across needs about "))
                && msg.contains(" available"),
            "{preset}: {msg}"
        );
    }
    let fits = (KIND.build)(
        &json!({ "preset": "cantilever-beam", "resolution": 3, "element": "tet10" }),
        &Default::default(),
    );
    assert!(fits.is_ok());
}
