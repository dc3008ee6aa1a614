use super::*;

#[test]
fn every_scene_builds_and_steps() {
    for name in NAMES {
        let mut scene = by_name(name, Some(8)).unwrap().unwrap();
        scene.step().unwrap();
        let (d, dims) = scene.density();
        assert_eq!(d.len(), dims.iter().product::<usize>());
        assert_eq!(scene.velocity().0.len(), d.len());
    }
    assert!(by_name("nope", None).is_none());
    assert!(matches!(smoke_box_2d(1), Err(FluidError::BadGrid { .. })));
}

fn memory_text(scene: &FluidScene) -> String {
    serde_json::to_string(&scene.memory()).unwrap()
}

/// Run n steps, save through JSON text, run m more; a fresh scene given the saved memory
/// and run m steps ends with the same bits (JSON prints every value in its shortest
/// round-trip form, so equal text is equal bits; `-0.0` prints differently from `0.0`).
#[test]
fn every_scene_resumes_from_its_memory_bit_for_bit() {
    for (name, res) in [("smoke-box-2d", 16), ("lid-driven-cavity", 12), ("smoke-plume-3d", 8)] {
        let mut whole = by_name(name, Some(res)).unwrap().unwrap();
        for _ in 0..3 {
            whole.step().unwrap();
        }
        let saved = memory_text(&whole);
        for _ in 0..4 {
            whole.step().unwrap();
        }
        let mut resumed = by_name(name, Some(res)).unwrap().unwrap();
        resumed.restore_memory(&serde_json::from_str(&saved).unwrap()).unwrap();
        assert_eq!(resumed.steps_taken(), 3, "{name}");
        for _ in 0..4 {
            resumed.step().unwrap();
        }
        assert_eq!(memory_text(&whole), memory_text(&resumed), "{name}");
        let bits = |v: Vec<f64>| v.into_iter().map(f64::to_bits).collect::<Vec<_>>();
        assert_eq!(bits(whole.density().0), bits(resumed.density().0), "{name}");
        assert_eq!(whole.time().to_bits(), resumed.time().to_bits(), "{name}");
        // The run moved: the comparison is not between two resting fields.
        assert!(whole.velocity().0.iter().any(|c| c[0] != 0.0 || c[1] != 0.0), "{name}");
    }
}

/// The MAC solver's warm-start pressure is part of what a step reads: restoring the state
/// alone does not continue the run bit for bit.
#[test]
fn mac_memory_needs_the_warm_start_pressure() {
    let mut whole = smoke_plume_3d(8).unwrap();
    for _ in 0..3 {
        whole.step().unwrap();
    }
    let mut saved = whole.memory();
    whole.step().unwrap();
    let mut cold = smoke_plume_3d(8).unwrap();
    let FluidSim::Mac(f, _) = &cold.sim else { panic!("a MAC scene") };
    saved["simulation"] = f.memory();
    cold.restore_memory(&saved).unwrap();
    cold.step().unwrap();
    assert_ne!(memory_text(&whole), memory_text(&cold));
}

#[test]
fn malformed_or_foreign_memories_are_refused_and_change_nothing() {
    let mut stam = by_name("smoke-box-2d", Some(8)).unwrap().unwrap();
    let mut mac = by_name("lid-driven-cavity", Some(8)).unwrap().unwrap();
    let mut mac3 = by_name("smoke-plume-3d", Some(6)).unwrap().unwrap();
    for scene in [&mut stam, &mut mac, &mut mac3] {
        scene.step().unwrap();
    }
    let other_stam = by_name("smoke-box-2d", Some(10)).unwrap().unwrap().memory();
    let other_mac = by_name("lid-driven-cavity", Some(10)).unwrap().unwrap().memory();
    let edit = |m: &serde_json::Value, f: &dyn Fn(&mut serde_json::Value)| {
        let mut m = m.clone();
        f(&mut m);
        m
    };
    let (sm, mm, m3) = (stam.memory(), mac.memory(), mac3.memory());
    // 0: Stam's 2D box, 1: a MAC 2D cavity, 2: the MAC 3D plume.
    let cases: Vec<(usize, serde_json::Value, &str)> = vec![
        (0, serde_json::json!(42), "no `solver`"),
        (0, mm.clone(), "a mac memory for a scene run by the stam solver"),
        (0, other_stam, "N = 10 grid, this fluid has N = 8"),
        (0, edit(&sm, &|m| m["stam"]["u"].as_array_mut().unwrap().truncate(5)), "`u` has 5 values"),
        (0, edit(&sm, &|m| m["stam"]["v"][3] = "x".into()), "not a Stam-fluid memory"),
        (0, edit(&sm, &|m| m["stam"]["steps"] = (-1).into()), "not a Stam-fluid memory"),
        (0, edit(&sm, &|m| m["stam"]["params"]["dt"] = 0.5.into()), "settings"),
        (0, edit(&sm, &|m| m["stam"]["extra"] = 1.into()), "unknown field `extra`"),
        (1, sm.clone(), "a stam memory for a scene run by the mac solver"),
        (1, other_mac, "u has 110 values, expected 72"),
        (1, edit(&mm, &|m| m["simulation"]["dims"] = serde_json::json!([8, 9, 1])), "[8, 9, 1] grid"),
        (
            1,
            edit(&mm, &|m| m["simulation"]["pressure"].as_array_mut().unwrap().pop().map(|_| ()).unwrap()),
            "`pressure` has 63 values",
        ),
        (1, edit(&mm, &|m| m["state"]["density"][0] = serde_json::Value::Null), "`state`"),
        (1, edit(&mm, &|m| m["state"]["time"] = (-1.0).into()), "time -1"),
        (
            1,
            edit(&mm, &|m| {
                m.as_object_mut().unwrap().remove("simulation");
            }),
            "no `simulation`",
        ),
        (2, edit(&m3, &|m| m["state"]["vel"][2] = serde_json::json!([])), "w has 0 values, expected 378"),
    ];
    let mut scenes = [stam, mac, mac3];
    for (which, memory, expect) in cases {
        let scene = &mut scenes[which];
        let before = memory_text(scene);
        let err = scene.restore_memory(&memory).unwrap_err();
        let msg = err.to_string();
        assert!(msg.starts_with("anim-fluid: ") && msg.contains(expect), "{expect}: {msg}");
        assert_eq!(memory_text(scene), before, "{expect}: the scene changed");
    }
}

#[test]
fn plume_rises() {
    let mut scene = smoke_plume_3d(10).unwrap();
    for _ in 0..10 {
        scene.step().unwrap();
    }
    let FluidSim::Mac(_, state) = &scene.sim else { panic!("a MAC scene") };
    // Upward flow leaves the vent and smoke has entered the box.
    assert!(state.vel[1].iter().fold(0.0f64, |m, &x| m.max(x)) > 0.1);
    assert!(state.density.iter().sum::<f64>() > 1.0);
}

/// Taylor-Green vortex in the unit box with free-slip walls: `u = sin(pi x) cos(pi y)`,
/// `v = -cos(pi x) sin(pi y)` decays as `exp(-2 nu pi^2 t)`.
pub(super) fn taylor_green(n: usize, advection: Advection, nu: f64, t_end: f64) -> (f64, f64) {
    let r = taylor_green_decay(n, advection, Splitting::AdvectProject, nu, t_end, 0.5).unwrap();
    (r.amplitude, r.exact)
}

#[test]
fn taylor_green_decay_matches_analytic_at_low_resolution() {
    let (a, exact) = taylor_green(32, Advection::MacCormack, 0.05, 0.5);
    assert!((a / exact - 1.0).abs() < 0.02, "{a} vs {exact}");
}

/// The Taylor-Green vortex is a steady Euler flow whose advection term is a gradient: the
/// splitting error of advect-then-project (first order, about `2 dt` of the amplitude at
/// `t = 1`) is the whole error of MacCormack at N = 32, CFL 2 (dt = 1/16). Advection-
/// reflection's error is of second order in `dt`; halving the step of advect-then-project
/// (what two half steps without the reflection would give) would still leave about 3%.
#[test]
fn reflection_removes_the_first_order_splitting_error() {
    let run = |splitting| {
        let r = taylor_green_decay(32, Advection::MacCormack, splitting, 0.01, 1.0, 2.0).unwrap();
        (r.amplitude / r.exact - 1.0).abs()
    };
    let (chorin, reflection) = (run(Splitting::AdvectProject), run(Splitting::Reflection));
    assert!(chorin > 0.05, "advect-project {chorin}");
    assert!(reflection < 0.005, "reflection {reflection}");
}
