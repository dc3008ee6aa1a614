//! The `mpm` scene kind through [`anim_core::scene`]: every preset builds, steps, checkpoints
//! and refuses what does not fit it; the dam break reports its surge-front error.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use crate::KIND;
use crate::kind::MpmSceneParams;
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
    p.quick_params.as_ref().expect("quick params")
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
fn the_presets_are_the_command_lines_built_in_mpm_scenes() {
    let presets = (KIND.presets)();
    let rows: Vec<_> = presets
        .iter()
        .map(|p| (p.name, p.run.dt, p.run.frames, p.run.steps_per_frame, p.params.clone()))
        .collect();
    assert_eq!(
        rows,
        [
            ("mpm", 0.0005, 120, 40, json!({ "preset": "three-materials" })),
            ("dam-break-2d-mpm", 0.00015625, 35, 64, json!({ "preset": "dam-break-2d", "resolution": 64 })),
            ("dam-break", 0.001, 100, 16, json!({ "preset": "dam-break-3d" })),
            ("snowball", 0.0005, 100, 16, json!({ "preset": "snowball" })),
        ]
    );
    for p in &presets {
        let read: MpmSceneParams = serde_json::from_value(p.params.clone()).expect("params");
        assert_eq!(serde_json::to_value(&read).expect("json"), p.params, "{}", p.name);
        assert_eq!(quick(p)["preset"], p.params["preset"], "{}", p.name);
    }
    // The transfer and kernel read and write under their scene-file names.
    let all = json!({
        "preset": "dam-break-2d", "resolution": 32, "transfer": "mls-mpm", "kernel": "cubic",
        "particles_per_cell": 3,
    });
    let read: MpmSceneParams = serde_json::from_value(all.clone()).expect("params");
    assert_eq!((read.transfer, read.kernel), (Some(crate::Transfer::Mls), Some(crate::Kernel::Cubic)));
    assert_eq!(serde_json::to_value(&read).expect("json"), all);
    let apic: MpmSceneParams =
        serde_json::from_value(json!({ "preset": "mpm", "transfer": "apic", "kernel": "quadratic" }))
            .expect("params");
    assert_eq!((apic.transfer, apic.kernel), (Some(crate::Transfer::Apic), Some(crate::Kernel::Quadratic)));
}

#[test]
fn every_preset_steps_three_times_and_moves() {
    for p in (KIND.presets)() {
        for params in [&p.params, quick(&p)] {
            let mut scene = build(params);
            let before = frame_of(scene.as_ref());
            for _ in 0..3 {
                scene.step(p.run.dt).expect("step");
            }
            let f = frame_of(scene.as_ref());
            assert!((f.time - 3.0 * p.run.dt).abs() < 1e-12, "{}: t = {}", p.name, f.time);
            assert_eq!(scene.time().to_bits(), f.time.to_bits());
            let v = &f.field("velocity").expect("velocity").values;
            assert_eq!((f.points.len(), v.len()), (before.points.len(), before.points.len()));
            assert!(!f.points.is_empty() && f.points.iter().chain(v).all(|x| x.is_finite()), "{}", p.name);
            // Sorted by block from the first step on: compare the sets of heights (y, up).
            let heights = |f: &Frame| {
                let mut y: Vec<f64> = f.points.chunks_exact(3).map(|p| p[1]).collect();
                y.sort_by(f64::total_cmp);
                y
            };
            assert_ne!(heights(&f), heights(&before), "{}: nothing moved", p.name);
            if p.name.ends_with("mpm") {
                assert!(f.points.chunks_exact(3).chain(v.chunks_exact(3)).all(|c| c[2] == 0.0), "{}", p.name);
            }
        }
    }
}

#[test]
fn the_frame_is_the_particles_widened_and_the_context_their_tank() {
    let mpm = build(&json!({ "preset": "three-materials", "resolution": 32 }));
    let mut scene = crate::scenes::by_name("three-materials", Some(32)).expect("known").expect("builds");
    let f = frame_of(mpm.as_ref());
    let positions = scene.positions();
    assert_eq!(f.points.len(), 3 * positions.len());
    for (p, q) in f.points.chunks_exact(3).zip(&positions) {
        assert_eq!(p, q.map(f64::from));
    }
    let c = mpm.context();
    assert_eq!((c.point_dim, c.point_radius), (3, 0.5 / 32.0));
    assert!(c.triangles.is_empty() && c.lines.is_empty() && c.pins.is_empty() && c.image.is_none());
    // Walls 3 nodes thick: the inner faces at 3 h and 1 - 3 h, flat in 2D.
    let (lo, hi) = (3.0 / 32.0, 1.0 - 3.0 / 32.0);
    assert_eq!(c.props, [Prop::Tank { lo: [lo, lo, 0.0], hi: [hi, hi, 0.0] }]);
    // The region: the blocks span x in [0.1, 0.9] (particle centres a quarter cell in), the
    // widest of their sides, widened sideways (x and z) by a third of that and extended down
    // along -y, y up, to 1.3 times that below their top.
    let (blo, bhi) = c.bounds.expect("bounds");
    let s = 0.25 / 32.0;
    let size = (0.9 - s) - (0.1 + s);
    let top = f.points.chunks_exact(3).map(|p| p[1]).fold(f64::NEG_INFINITY, f64::max);
    assert!((blo[0] - (0.1 + s - size / 3.0)).abs() < 1e-6 && (bhi[0] - (0.9 - s + size / 3.0)).abs() < 1e-6);
    assert!((blo[1] - (top - 1.3 * size)).abs() < 1e-6 && bhi[1] == top, "{blo:?} {bhi:?}");
    assert!((blo[2] + size / 3.0).abs() < 1e-6 && (bhi[2] - size / 3.0).abs() < 1e-6, "{blo:?} {bhi:?}");
    assert!(c.planar, "a 2D scene");
    // The same particles after a step as the scene of anim-mpm stepped by itself.
    let mut mpm = mpm;
    mpm.step(scene.dt()).expect("step");
    scene.step().expect("step");
    let f = frame_of(mpm.as_ref());
    assert_eq!(f.time, scene.time());
    for (p, q) in f.points.chunks_exact(3).zip(&scene.positions()) {
        assert_eq!(p, q.map(f64::from));
    }
    // The snowball's wall is a box collider.
    let snowball = build(quick(&preset("snowball"))).context();
    let (lo, hi) = (3.0 / 16.0, 1.0 - 3.0 / 16.0);
    assert_eq!(snowball.props[0], Prop::Tank { lo: [lo; 3], hi: [hi; 3] });
    let Prop::Cuboid { lo, hi } = snowball.props[1] else { panic!("{:?}", snowball.props) };
    let expect = ([0.8, 0.05, 0.05], [0.9, 0.95, 0.95]);
    for k in 0..3 {
        assert!((lo[k] - expect.0[k]).abs() < 1e-6 && (hi[k] - expect.1[k]).abs() < 1e-6, "{lo:?} {hi:?}");
    }
    assert_eq!(snowball.props.len(), 2);
}

#[test]
fn the_method_fields_reach_the_simulation() {
    let dam = |extra: serde_json::Value| {
        let mut p = json!({ "preset": "dam-break-2d", "resolution": 32 });
        p.as_object_mut().expect("object").extend(extra.as_object().expect("object").clone());
        build(&p)
    };
    assert_eq!(dam(json!({})).method(), "2D MLS-MPM, quadratic B-splines, CFL substeps");
    assert_eq!(
        dam(json!({ "transfer": "apic", "kernel": "cubic" })).method(),
        "2D APIC, cubic B-splines, CFL substeps"
    );
    assert_eq!(dam(json!({ "kernel": "cubic" })).method(), "2D MLS-MPM, cubic B-splines, CFL substeps");
    // The column 0.2 x 0.4 m at h = 1/32 holds floor(6.4 k) x floor(12.8 k) particles.
    for (k, count) in [(2, 12 * 25), (3, 19 * 38)] {
        let scene = dam(json!({ "particles_per_cell": k }));
        assert_eq!(frame_of(scene.as_ref()).points.len(), 3 * count, "{k} per cell");
    }
    assert_eq!(build(quick(&preset("dam-break"))).method(), "3D MLS-MPM, quadratic B-splines, CFL substeps");
}

#[test]
fn the_dam_break_measures_its_front_against_martin_and_moyce() {
    // The surge-front error appears once the run passes Martin & Moyce's first time,
    // T = 0.41, t = 0.41 / sqrt(2 g / a) = 0.0414 s.
    let mut dam = build(&json!({ "preset": "dam-break-2d", "resolution": 16 }));
    let dt = crate::scenes::dam_break_2d_dt(16);
    assert_eq!(dam.reference_error(), None);
    let first = 0.41 / (2.0 * 9.81 / 0.2f64).sqrt();
    while dam.time() + dt < first {
        dam.step(dt).expect("step");
    }
    assert_eq!(dam.reference_error(), None, "before T = 0.41");
    dam.step(dt).expect("step");
    let e = dam.reference_error().expect("after T = 0.41");
    assert!(e.is_finite() && e > 0.0 && e < 1.0, "{e}");
    assert_eq!(dam.save()["saved"]["surge_front"]["z"].as_array().map(Vec::len), Some(1));
    // Other scenes carry no reference; the 2D ones save a null tracker, the 3D ones none.
    let mut mpm = build(quick(&preset("mpm")));
    mpm.step(1e-3).expect("step");
    assert_eq!(mpm.reference_error(), None);
    assert_eq!(mpm.save()["saved"]["surge_front"], serde_json::Value::Null);
    assert!(mpm.save()["saved"].as_object().expect("saved").contains_key("surge_front"));
    assert!(
        !build(quick(&preset("snowball"))).save()["saved"]
            .as_object()
            .expect("saved")
            .contains_key("surge_front")
    );
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
        assert_eq!(a.reference_error().map(f64::to_bits), b.reference_error().map(f64::to_bits));
        assert_eq!(a.save()["saved"]["simulation"]["steps"], json!(9), "{}", p.name);
    }
}

#[test]
fn a_foreign_or_damaged_checkpoint_is_refused_and_changes_nothing() {
    let mut dam = build(quick(&preset("dam-break-2d-mpm")));
    dam.step(1e-4).expect("step");
    let before = dam.save();
    let check = |scene: &mut Box<dyn DynScene>, saved: serde_json::Value, field: &str| {
        let err = scene.restore(&saved).expect_err("refused");
        assert!(err.to_string().contains(&format!("`{field}`")), "{field}: {err}");
        assert_eq!(scene.save(), before, "{field}: the refusal changed the scene");
        err
    };
    // Other presets: another dimension, another particle count.
    let err = check(&mut dam, build(quick(&preset("snowball"))).save(), "dim");
    assert!(err.to_string().contains("a 3D checkpoint for a 2D scene"), "{err}");
    let err = check(&mut dam, build(quick(&preset("mpm"))).save(), "particles");
    assert!(err.to_string().contains("particles; this scene has"), "{err}");
    // Damaged: a short array, a foreign material, no memory, no clock, no tracker.
    let mut short = before.clone();
    short["saved"]["particles"]["v"].as_array_mut().expect("v").pop();
    let err = check(&mut dam, short, "particles");
    assert!(err.to_string().contains("array `v`"), "{err}");
    let mut material = before.clone();
    material["saved"]["particles"]["material"][0] = json!(5);
    check(&mut dam, material, "particles");
    let mut no_memory = before.clone();
    no_memory["saved"].as_object_mut().expect("saved").remove("simulation");
    assert_eq!(
        check(&mut dam, no_memory, "simulation"),
        CheckpointError::Missing { field: "simulation".into() }
    );
    let mut no_time = before.clone();
    no_time["saved"]["simulation"].as_object_mut().expect("memory").remove("time");
    check(&mut dam, no_time, "simulation");
    let mut no_front = before.clone();
    no_front["saved"].as_object_mut().expect("saved").remove("surge_front");
    check(&mut dam, no_front, "surge_front");
    let mut null_front = before.clone();
    null_front["saved"]["surge_front"] = serde_json::Value::Null;
    check(&mut dam, null_front, "surge_front");
    let mut long_front = before.clone();
    long_front["saved"]["surge_front"]["z"] = json!(vec![1.0; 16]);
    check(&mut dam, long_front, "surge_front");
    let mut no_dim = before.clone();
    no_dim["saved"].as_object_mut().expect("saved").remove("dim");
    check(&mut dam, no_dim, "dim");
    let mut old = before.clone();
    old["version"] = json!(2);
    assert_eq!(dam.restore(&old), Err(CheckpointError::Version { found: 2, expected: 1 }));
    assert_eq!(dam.save(), before);
}

#[test]
fn an_overflow_fails_the_step_and_leaves_the_scene_as_it_was() {
    for p in (KIND.presets)() {
        let mut scene = build(quick(&p));
        scene.step(p.run.dt).expect("step");
        assert!(scene.provoke_overflow().expect("provoked").contains("1e30"));
        let before = scene.save();
        let frame = bits(&frame_of(scene.as_ref()));
        let err = scene.step(p.run.dt).expect_err("overflow");
        let msg = err.to_string();
        assert!(msg.starts_with("anim-mpm: step 1: non-finite "), "{}: {msg}", p.name);
        assert!(matches!(err.get::<crate::MpmError>(), Some(crate::MpmError::NonFinite { .. })));
        assert_eq!(scene.save(), before, "{}", p.name);
        assert_eq!(bits(&frame_of(scene.as_ref())), frame, "{}", p.name);
    }
}

#[test]
fn bad_parameters_name_their_field() {
    let msg = refused(&json!({ "preset": "three-materials", "resolutoin": 16 }));
    assert!(msg.contains("unknown field `resolutoin`"), "{msg}");
    let msg = refused(&json!({ "preset": "jelly" }));
    assert_eq!(
        msg,
        "field `preset`: unknown preset `jelly` (one of three-materials, dam-break-2d, dam-break-3d, snowball, benchmark-2d, benchmark-3d)"
    );
    let msg = refused(&json!({ "preset": "three-materials", "resolution": 4 }));
    assert!(msg.starts_with("field `resolution`: ") && msg.contains("[8, 262135] in 2D"), "{msg}");
    for (k, expected) in [(9, "got 9"), (0, "got 0")] {
        let msg = refused(&json!({ "preset": "dam-break-2d", "particles_per_cell": k }));
        assert_eq!(msg, format!("field `particles_per_cell`: must lie in [1, 8] (per axis), {expected}"));
    }
    let msg = refused(&json!({ "preset": "three-materials", "particles_per_cell": 3 }));
    assert_eq!(
        msg,
        "field `particles_per_cell`: three-materials places its own particles; only dam-break-2d takes particles_per_cell"
    );
    let msg = refused(&json!({ "preset": "dam-break-2d", "transfer": "pic" }));
    assert!(msg.contains("unknown variant `pic`") && msg.contains("mls-mpm"), "{msg}");
    let msg = refused(&json!({ "preset": "dam-break-2d", "kernel": "quartic" }));
    assert!(msg.contains("unknown variant `quartic`") && msg.contains("cubic"), "{msg}");
    let msg = refused(&json!({ "preset": "dam-break-2d", "transfer": "Mls" }));
    assert!(msg.contains("unknown variant `Mls`"), "{msg}");
}

mod tolerance {
    use crate::kind::{KIND, mpm_label};
    use crate::{Kernel, Transfer};
    use anim_core::scene::study::{Point, family};

    #[test]
    fn labels_of_the_mpm_study_parse_back() {
        assert_eq!(mpm_label("MLS-MPM quadratic, 2x2 ppc"), Some((Transfer::Mls, Kernel::Quadratic, 2)));
        assert_eq!(mpm_label("APIC cubic, 2x2 ppc"), Some((Transfer::Apic, Kernel::Cubic, 2)));
        assert_eq!(mpm_label("MLS-MPM quadratic, 3x3 ppc"), Some((Transfer::Mls, Kernel::Quadratic, 3)));
        for bad in
            ["MLS-MPM quadratic", "FLIP quadratic, 2x2 ppc", "APIC quartic, 2x2 ppc", "APIC cubic, 2x3 ppc"]
        {
            assert_eq!(mpm_label(bad), None, "{bad}");
        }
    }

    #[test]
    fn the_dam_break_takes_the_studys_settings_and_step() {
        let f = family("mpm_dam_break", "mpm/dam-break-2d", None, &[], &[]);
        let tolerance = KIND.tolerance.expect("mapped");
        let p = (KIND.presets)().into_iter().find(|p| p.name == "dam-break-2d-mpm").expect("preset");
        let adapter = (tolerance.adapter)(&p.params, &p.run, &f).expect("adapter");
        let c = adapter
            .candidate("APIC cubic, 2x2 ppc", &Point { param: 32.0, seconds: 0.8, error: 0.08 })
            .expect("runs");
        assert_eq!(c.summary, "resolution = 32, transfer = apic, kernel = cubic, particles_per_cell = 2");
        // Half a cell per sound crossing at c = 50 m/s, h = 1/32 m.
        let dt = c.dt.expect("a step");
        assert!((dt - 0.5 / 32.0 / 50.0).abs() < 1e-15, "{dt}");
        // The settings are the scene's own parameters: they build.
        let mut params = p.params.clone();
        for (k, v) in c.settings {
            params[k] = v;
        }
        params["resolution"] = serde_json::json!(16);
        assert!((KIND.build)(&params, &Default::default()).is_ok());
        // The other presets are not the study's.
        let other = (KIND.presets)().into_iter().find(|p| p.name == "mpm").expect("preset");
        let e = (tolerance.adapter)(&other.params, &other.run, &f).err().expect("unmapped");
        assert_eq!(e, "--tolerance: the mpm_dam_break study has no mapping to this scene");
    }
}

/// The dam breaks fall along -y in their frames, as the solver and every view are y up: over
/// the first 0.15 s the water's mean height drops and the column spreads along the floor, its
/// front running out along x (and, for the 3D column standing clear of the side walls, along z
/// too), while its top comes down. The 2D one stays in the plane z = 0.
#[test]
fn the_dam_breaks_fall_along_minus_y_in_their_frames() {
    for (name, dim) in [("dam-break", 3), ("dam-break-2d-mpm", 2)] {
        let p = preset(name);
        let mut scene = build(quick(&p));
        // Mean, lowest and highest coordinate along each axis.
        let spread = |f: &Frame| {
            let n = (f.points.len() / 3) as f64;
            let mut out = [(0.0, f64::INFINITY, f64::NEG_INFINITY); 3];
            for q in f.points.chunks_exact(3) {
                for (k, o) in out.iter_mut().enumerate() {
                    *o = (o.0 + q[k] / n, o.1.min(q[k]), o.2.max(q[k]));
                }
            }
            out
        };
        let before = spread(&frame_of(scene.as_ref()));
        let steps = (0.15 / p.run.dt).round() as usize;
        for _ in 0..steps {
            scene.step(p.run.dt).expect("step");
        }
        let after = frame_of(scene.as_ref());
        let now = spread(&after);
        let (mean_drop, top_drop) = (before[1].0 - now[1].0, before[1].2 - now[1].2);
        let runs_out = now[0].2 - before[0].2;
        assert!(mean_drop > 0.005 && top_drop > 0.01, "{name}: mean y fell {mean_drop}, top {top_drop}");
        assert!(runs_out > 0.01, "{name}: the front ran {runs_out} along x");
        if dim == 3 {
            let (wider_lo, wider_hi) = (before[2].1 - now[2].1, now[2].2 - before[2].2);
            assert!(wider_lo > 0.0 && wider_hi > 0.0, "{name}: z spread by {wider_lo}, {wider_hi}");
        } else {
            assert!(after.points.chunks_exact(3).all(|q| q[2] == 0.0), "{name}");
        }
    }
}
