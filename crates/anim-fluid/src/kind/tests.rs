use super::*;
use anim_core::scene::{DynScene, Frame};

fn preset(name: &str) -> Preset {
    (KIND.presets)().into_iter().find(|p| p.name == name).expect("a preset")
}

fn build_value(value: &serde_json::Value) -> Result<Box<dyn DynScene>, BuildError> {
    (KIND.build)(value, &BuildContext::default())
}

fn quick(name: &str) -> (Box<dyn DynScene>, f64) {
    let p = preset(name);
    let params = p.quick_params.expect("quick params");
    (build_value(&params).expect("builds"), p.run.dt)
}

fn frame_of(scene: &dyn DynScene) -> Frame {
    let mut f = Frame::default();
    scene.frame(&mut f);
    f
}

/// A frame's time and fields (name, components, value bits).
type FrameBits = (u64, Vec<(&'static str, usize, Vec<u64>)>);

fn bits(f: &Frame) -> FrameBits {
    let fields =
        f.fields.iter().map(|x| (x.name, x.components, x.values.iter().map(|v| v.to_bits()).collect()));
    (f.time.to_bits(), fields.collect())
}

/// The checkpoint as JSON text: equal text is equal bits (shortest round-trip floats).
fn saved_text(scene: &dyn DynScene) -> String {
    scene.save().to_string()
}

fn err(value: serde_json::Value) -> String {
    build_value(&value).err().expect("refused").to_string()
}

#[test]
fn the_presets_are_the_command_lines_scenes_and_their_params_round_trip() {
    let presets = (KIND.presets)();
    let names: Vec<&str> = presets.iter().map(|p| p.name).collect();
    assert_eq!(names, scenes::NAMES);
    let runs: Vec<RunDefaults> = presets.iter().map(|p| p.run).collect();
    assert_eq!(
        runs,
        [
            RunDefaults::new(0.1, 100, 2),
            RunDefaults::new(0.046875, 64, 1),
            RunDefaults::new(0.015625, 128, 10)
        ]
    );
    for p in &presets {
        for value in [Some(&p.params), p.quick_params.as_ref()].into_iter().flatten() {
            let read: FluidSceneParams = params(value).expect("parameters");
            assert_eq!(read.preset.as_deref(), Some(p.name));
            assert_eq!(&serde_json::to_value(&read).expect("json"), value, "{}", p.name);
        }
    }
}

#[test]
fn enum_spellings_are_their_names() {
    for m in PressureMethod::ALL {
        assert_eq!(serde_json::to_value(m).expect("json"), json!(m.name()));
        assert_eq!(serde_json::from_value::<PressureMethod>(json!(m.name())).expect("read"), m);
    }
    for a in Advection::ALL {
        assert_eq!(serde_json::to_value(a).expect("json"), json!(a.name()));
        assert_eq!(serde_json::from_value::<Advection>(json!(a.name())).expect("read"), a);
    }
    for s in Splitting::ALL {
        assert_eq!(serde_json::to_value(s).expect("json"), json!(s.name()));
        assert_eq!(serde_json::from_value::<Splitting>(json!(s.name())).expect("read"), s);
    }
}

/// Every preset, at its own size and its quick one: three steps of its `dt` give finite
/// fields of the image grid's size, a time of 3 dt, and fields that changed.
#[test]
fn every_preset_builds_steps_and_draws() {
    for p in (KIND.presets)() {
        for value in [Some(&p.params), p.quick_params.as_ref()].into_iter().flatten() {
            let mut scene = build_value(value).expect("builds");
            let context = scene.context();
            let image = context.image.expect("an image grid");
            assert_eq!((context.point_dim, image.shown, image.origin), (0, "density", [0.0; 3]));
            let first = frame_of(scene.as_ref());
            for _ in 0..3 {
                scene.step(p.run.dt).expect("step");
            }
            let f = frame_of(scene.as_ref());
            assert!((f.time - 3.0 * p.run.dt).abs() < 1e-12, "{}: {}", p.name, f.time);
            assert_eq!(scene.time().to_bits(), f.time.to_bits());
            assert!(f.points.is_empty());
            let names: Vec<&str> = f.fields.iter().map(|x| x.name).collect();
            assert_eq!(names, ["density", "velocity"], "{}", p.name);
            let (density, velocity) = (&f.fields[0], &f.fields[1]);
            assert_eq!((density.components, velocity.components), (1, 3));
            assert_eq!((density.values.len(), velocity.values.len()), (image.cells(), 3 * image.cells()));
            assert!(density.values.iter().chain(&velocity.values).all(|x| x.is_finite()), "{}", p.name);
            assert_ne!(density.values, first.fields[0].values, "{}: the density did not change", p.name);
            assert_ne!(velocity.values, first.fields[1].values, "{}: the velocity did not change", p.name);
        }
    }
}

/// The frame is the old display state: the scene's density and cell-centre velocity after the
/// same steps taken by [`FluidScene::step_by`], and the context its grid and colour scale.
#[test]
fn frames_and_context_are_the_scenes_fields_and_grid() {
    for (name, res, range, method) in [
        ("smoke-box-2d", 16, (0.0, 50.0), "Stam's stable fluids (f32, 20 Gauss-Seidel sweeps)"),
        (
            "smoke-plume-3d",
            8,
            (0.0, 1.0),
            "3D MAC, maccormack advection, advect-project splitting, mgpcg pressure",
        ),
        (
            "lid-driven-cavity",
            16,
            (0.0, 1.0),
            "2D MAC, maccormack advection, advect-project splitting, mgpcg pressure",
        ),
    ] {
        let (mut scene, dt) = quick(name);
        let mut plain = scenes::by_name(name, Some(res)).expect("known").expect("builds");
        let mut t = 0.0;
        for _ in 0..4 {
            scene.step(dt).expect("step");
            plain.step_by(dt).expect("step");
            t += dt;
        }
        let mut expected = Frame { time: t, ..Frame::default() };
        plain.density_into(expected.field_mut("density", 1));
        plain.velocity_into(expected.field_mut("velocity", 3));
        assert_eq!(bits(&frame_of(scene.as_ref())), bits(&expected), "{name}");
        assert_eq!(scene.method(), method);
        let image = scene.context().image.expect("image");
        assert_eq!(
            (image.dims, image.dim, image.spacing.to_bits(), image.range),
            (plain.dims(), plain.dim(), plain.cell_size().to_bits(), range),
            "{name}"
        );
        let spheres = scene.context().props.len();
        assert_eq!(spheres, usize::from(name == "smoke-plume-3d"), "{name}");
    }
}

#[test]
fn the_cavity_measures_its_error_against_ghia() {
    let (mut scene, dt) = quick("lid-driven-cavity");
    let mut plain = scenes::by_name("lid-driven-cavity", Some(16)).expect("known").expect("builds");
    // At rest only the lid's half cell moves: the error is nearly the largest of Ghia's
    // interior centreline speeds, 0.84123 (u at y = 0.9766).
    let e0 = scene.reference_error().expect("an error");
    assert!(e0 > 0.7 && e0 <= 0.84123, "{e0}");
    for _ in 0..3 {
        scene.step(dt).expect("step");
        plain.step_by(dt).expect("step");
    }
    let FluidSim::Mac(fluid, state) = &plain.sim else { panic!("a MAC scene") };
    assert_eq!(scene.reference_error().map(f64::to_bits), Some(ghia_error(fluid, state).to_bits()));
    assert_ne!(scene.reference_error(), Some(e0));
    assert_eq!(quick("smoke-plume-3d").0.reference_error(), None);
    assert_eq!(quick("smoke-box-2d").0.reference_error(), None);
}

/// Step 4, save through JSON text, step 5 more; a fresh scene restored from the text and
/// stepped 5 times ends with the same checkpoint and the same frame bits.
#[test]
fn a_checkpoint_resumes_bit_for_bit() {
    for name in scenes::NAMES {
        let (mut a, dt) = quick(name);
        for _ in 0..4 {
            a.step(dt).expect("step");
        }
        let text = saved_text(a.as_ref());
        for _ in 0..5 {
            a.step(dt).expect("step");
        }
        let (mut b, _) = quick(name);
        b.restore(&serde_json::from_str(&text).expect("json")).expect("restore");
        for _ in 0..5 {
            b.step(dt).expect("step");
        }
        assert!(saved_text(a.as_ref()) == saved_text(b.as_ref()), "{name}: the checkpoints differ");
        assert_eq!(bits(&frame_of(a.as_ref())), bits(&frame_of(b.as_ref())), "{name}");
    }
}

#[test]
fn foreign_and_damaged_checkpoints_are_refused_and_change_nothing() {
    let (mut plume, dt) = quick("smoke-plume-3d");
    plume.step(dt).expect("step");
    let (smoke, cavity) = (quick("smoke-box-2d").0.save(), quick("lid-driven-cavity").0.save());
    let edit = |v: &serde_json::Value, f: &dyn Fn(&mut serde_json::Value)| {
        let mut v = v.clone();
        f(&mut v);
        v
    };
    let p = plume.save();
    let cases = [
        (
            "lid-driven-cavity",
            smoke.clone(),
            "`fluid`: anim-fluid: checkpoint does not fit this simulation: a stam memory",
        ),
        (
            "smoke-box-2d",
            cavity.clone(),
            "`fluid`: anim-fluid: checkpoint does not fit this simulation: a mac memory",
        ),
        ("smoke-plume-3d", cavity.clone(), "`fluid`: anim-fluid: u has 272 values"),
        (
            "smoke-plume-3d",
            edit(&p, &|v| v["saved"]["fluid"]["state"]["density"] = json!([1.0])),
            "`fluid`: anim-fluid: density has 1 values",
        ),
        ("smoke-plume-3d", edit(&p, &|v| v["saved"]["time"] = json!("soon")), "`time`: invalid type"),
        (
            "smoke-plume-3d",
            edit(&p, &|v| {
                v["saved"].as_object_mut().expect("object").remove("fluid");
            }),
            "the checkpoint has no `fluid`",
        ),
        (
            "smoke-plume-3d",
            edit(&p, &|v| {
                v["saved"].as_object_mut().expect("object").remove("time");
            }),
            "the checkpoint has no `time`",
        ),
        ("smoke-plume-3d", edit(&p, &|v| v["version"] = json!(3)), "layout version 3"),
        (
            // A checkpoint written before version 2, with Stam's solver under its old key.
            "smoke-box-2d",
            edit(&smoke, &|v| {
                v["version"] = json!(1);
                let fluid = v["saved"]["fluid"].as_object_mut().expect("object");
                let memory = fluid.remove("stam").expect("stam memory");
                fluid.insert("solver".into(), json!("seed"));
                fluid.insert("seed".into(), memory);
            }),
            "a checkpoint of layout version 1; this build reads version 2",
        ),
        (
            "smoke-box-2d",
            edit(&smoke, &|v| v["saved"]["fluid"]["stam"]["u"] = json!([0.0])),
            "`fluid`: anim-fluid: checkpoint does not fit this simulation: `u` has 1 values",
        ),
    ];
    for (name, saved, expect) in cases {
        let (mut scene, dt) = quick(name);
        scene.step(dt).expect("step");
        let before = saved_text(scene.as_ref());
        let msg = scene.restore(&saved).expect_err("refused").to_string();
        assert!(msg.contains(expect), "{name}: {expect}: {msg}");
        assert!(saved_text(scene.as_ref()) == before, "{name}: {expect}: the scene changed");
    }
}

#[test]
fn an_overflow_fails_the_step_and_leaves_the_scene_as_it_was() {
    for name in scenes::NAMES {
        let (mut scene, dt) = quick(name);
        scene.step(dt).expect("step");
        assert!(scene.provoke_overflow().is_some());
        let before = saved_text(scene.as_ref());
        let msg = scene.step(dt).expect_err("overflow").to_string();
        assert!(msg.starts_with("anim-fluid: step 1: non-finite "), "{name}: {msg}");
        assert!(saved_text(scene.as_ref()) == before, "{name}: the failed step changed the scene");
        assert!(scene.step(dt).is_err(), "{name}: the state still overflows");
    }
}

#[test]
fn bad_parameters_name_their_field() {
    let msg = err(json!({ "preset": "lid-driven-cavity", "resolutoin": 8 }));
    assert!(msg.contains("unknown field `resolutoin`"), "{msg}");
    assert_eq!(
        err(json!({ "preset": "smoke-box-3d" })),
        "field `preset`: unknown preset `smoke-box-3d` (one of smoke-box-2d, smoke-plume-3d, lid-driven-cavity)"
    );
    // A grid past the memory available is refused before it is made, with the estimate and the
    // memory; a smoke scene of the user's own alike, its cells counted over the domain.
    for (params, what) in [
        (json!({ "preset": "smoke-plume-3d", "resolution": 100_000 }), "100000 cells across"),
        (json!({ "preset": "lid-driven-cavity", "resolution": 1_000_000_000 }), "1000000000 cells across"),
        (json!({ "preset": "smoke-box-2d", "resolution": 1_000_000_000 }), "1000000000 cells across"),
        (
            json!({ "resolution": 100_000, "sources": [{ "shape": { "sphere": { "center": [0.5, 0.1, 0.5], "radius": 0.1 } } }] }),
            "100000 x 150000 x 100000 cells of 0.0000 m (resolution 100000)",
        ),
    ] {
        let start = std::time::Instant::now();
        let e = (KIND.build)(&params, &Default::default()).err().expect("refused");
        assert!(start.elapsed().as_secs_f64() < 1.0, "{params}: {:?}", start.elapsed());
        assert!(matches!(e, BuildError::Memory { .. }), "{params}: {e}");
        let msg = e.to_string();
        assert!(msg.starts_with(&format!("field `resolution`: {what} needs about ")), "{msg}");
        assert!(msg.contains(" grid cells x ") && msg.ends_with(" available"), "{msg}");
    }
    let msg = err(json!({ "preset": "smoke-box-2d", "resolution": 1 }));
    assert!(msg.starts_with("field `resolution`: anim-fluid: grid N must be at least 2"), "{msg}");
    for tol in [0.0, -1e-4] {
        let msg = err(json!({ "preset": "lid-driven-cavity", "resolution": 8, "pressure_tolerance": tol }));
        assert_eq!(msg, format!("field `pressure_tolerance`: must be a positive finite number, got {tol}"));
    }
    let msg = err(json!({ "preset": "lid-driven-cavity", "pressure_solver": "multigrid" }));
    assert!(msg.contains("unknown variant `multigrid`") && msg.contains("`mgpcg`"), "{msg}");
    for (field, value) in [
        ("pressure_solver", json!("cg")),
        ("pressure_tolerance", json!(1e-4)),
        ("advection", json!("bfecc")),
        ("splitting", json!("reflection")),
    ] {
        let mut p = json!({ "preset": "smoke-box-2d", "resolution": 8 });
        p[field] = value;
        assert_eq!(
            err(p),
            format!(
                "field `{field}`: smoke-box-2d runs Stam's solver (20 Gauss-Seidel sweeps, linear advection), which has no pressure, advection or splitting settings"
            )
        );
    }
}

#[test]
fn mac_settings_reach_the_solver() {
    let p: FluidSceneParams = params(&json!({
        "preset": "lid-driven-cavity", "resolution": 8, "pressure_solver": "rb-gauss-seidel",
        "pressure_tolerance": 1e-4, "advection": "sl-linear", "splitting": "reflection",
    }))
    .expect("parameters");
    let scene = p.scene().expect("builds");
    let FluidSim::Mac(fluid, _) = &scene.sim else { panic!("a MAC scene") };
    let q = fluid.params();
    assert_eq!(
        (q.pressure, q.pressure_tolerance, q.pressure_max_iterations, q.advection, q.splitting),
        (
            PressureMethod::RedBlackGaussSeidel,
            1e-4,
            PRESSURE_MAX_ITERATIONS,
            Advection::Linear,
            Splitting::Reflection
        )
    );
    assert_eq!(scene.method(), "2D MAC, sl-linear advection, reflection splitting, rb-gauss-seidel pressure");
    // Only the advection: the preset's pressure settings and cap stay.
    let p = FluidSceneParams {
        advection: Some(Advection::Bfecc),
        ..FluidSceneParams::preset("lid-driven-cavity", Some(8))
    };
    let scene = p.scene().expect("builds");
    let FluidSim::Mac(fluid, _) = &scene.sim else { panic!("a MAC scene") };
    let q = fluid.params();
    assert_eq!(
        (q.pressure, q.pressure_tolerance, q.pressure_max_iterations, q.advection),
        (PressureMethod::Mgpcg, 1e-8, 1000, Advection::Bfecc)
    );
}

#[test]
fn labels_of_the_pressure_study_parse_back() {
    assert_eq!(pressure_label("rb-gauss-seidel N=256"), Some((PressureMethod::RedBlackGaussSeidel, 256)));
    assert_eq!(pressure_label("mgpcg N=64"), Some((PressureMethod::Mgpcg, 64)));
    assert_eq!(pressure_label("sor N=64"), None);
}

#[test]
fn the_ghia_error_of_a_cavity_at_rest_is_ghias_largest_interior_speed() {
    // At rest every sampled velocity is 0 (Ghia's points lie more than half a cell from the lid
    // at N = 128), so the error is the largest |u| or |v| of Ghia et al. (1982), Table I/II at
    // Re = 100: u = 0.84123 at y = 0.9766.
    let scene = scenes::lid_driven_cavity(128, 100.0, Advection::MacCormack).unwrap();
    let FluidSim::Mac(fluid, state) = &scene.sim else { panic!("a MAC scene") };
    assert!((ghia_error(fluid, state) - 0.84123).abs() < 1e-12);
}

fn tolerance_family(
    study: &str,
    scene: &str,
    problem: &[(&str, f64)],
    series: &[&str],
) -> anim_core::scene::study::Family {
    let series: Vec<(&str, Vec<Point>)> = series.iter().map(|m| (*m, Vec::new())).collect();
    anim_core::scene::study::family(study, scene, None, problem, &series)
}

#[test]
fn the_cavity_takes_the_studys_resolution_and_pressure_solver_at_a_step_of_one_cell() {
    let f = tolerance_family(
        "fluid_cavity_ghia",
        "fluid/lid-driven-cavity",
        &[("pressure_tolerance", 1e-5)],
        &[],
    );
    let p = preset("lid-driven-cavity");
    let adapter = (KIND.tolerance.expect("mapped").adapter)(&p.params, &p.run, &f).expect("adapter");
    let c = adapter.candidate("mgpcg", &Point { param: 32.0, seconds: 0.3, error: 0.02 }).expect("runs");
    assert_eq!(c.summary, "resolution = 32, pressure_solver = mgpcg, pressure_tolerance = 1e-5");
    assert_eq!(c.settings.get("resolution"), Some(&json!(32)));
    assert_eq!(c.settings.get("pressure_solver"), Some(&json!("mgpcg")));
    assert_eq!(c.dt, Some(1.0 / 32.0));
    assert_eq!(
        adapter.candidate("sor", &Point { param: 32.0, seconds: 0.3, error: 0.02 }).unwrap_err(),
        "`sor` is not a method this build knows"
    );
    // A scene that sets the advection or the splitting is refused.
    let mut changed = p.params.clone();
    changed["splitting"] = json!("reflection");
    let e = (KIND.tolerance.expect("mapped").adapter)(&changed, &p.run, &f).err().expect("refused");
    assert_eq!(
        e,
        "sets `splitting`, but the fluid_cavity_ghia study measured the preset's own; remove the field or --tolerance"
    );
}

#[test]
fn the_smoke_plume_takes_the_series_measured_at_the_nearest_grid() {
    let f =
        tolerance_family("fluid_pressure_divergence", "fluid/smoke-plume-3d", &[], &["cg N=64", "cg N=256"]);
    let p = preset("smoke-plume-3d");
    let adapter = (KIND.tolerance.expect("mapped").adapter)(&p.params, &p.run, &f).expect("adapter");
    let pt = Point { param: 1e-5, seconds: 1e-4, error: 9e-6 };
    // 32 x 48 x 32 cells: the largest side, 48, is nearest N = 64 (log scale).
    assert_eq!(
        adapter.candidate("cg N=256", &pt).unwrap_err(),
        "measured at N = 256; the scene's grid (48 cells) is nearest N = 64"
    );
    let c = adapter.candidate("cg N=64", &pt).expect("runs");
    assert_eq!(c.summary, "pressure_solver = cg, pressure_tolerance = 1e-5");
    assert_eq!(c.dt, None);
    assert!(!c.settings.contains_key("resolution"));
}
