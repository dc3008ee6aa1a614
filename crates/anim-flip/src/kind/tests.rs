use super::*;
use anim_core::scene::{DynScene, Frame};

fn find(name: &str) -> Preset {
    (KIND.presets)().into_iter().find(|p| p.name == name).expect("a preset")
}

fn build_value(value: &serde_json::Value) -> Result<Box<dyn DynScene>, BuildError> {
    (KIND.build)(value, &BuildContext::default())
}

fn quick(name: &str) -> (Box<dyn DynScene>, f64) {
    let p = find(name);
    (build_value(&p.quick_params.expect("quick params")).expect("builds"), p.run.dt)
}

fn frame_of(scene: &dyn DynScene) -> Frame {
    let mut f = Frame::default();
    scene.frame(&mut f);
    f
}

/// A frame's time, points and velocities as bits.
fn bits(f: &Frame) -> (u64, Vec<u64>, Vec<u64>) {
    let velocity = f.field("velocity").expect("velocities");
    let b = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    (f.time.to_bits(), b(&f.points), b(&velocity.values))
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
    let frames: Vec<(f64, usize, usize)> =
        presets.iter().map(|p| (p.run.dt, p.run.frames, p.run.steps_per_frame)).collect();
    assert_eq!(frames, [(0.02, 100, 1), (0.02, 75, 1), (0.02, 75, 1), (0.02, 75, 1), (0.02, 250, 1)]);
    assert_eq!(presets[4].params, json!({ "preset": "sloshing-tank", "resolution": 64, "transfer": "apic" }));
    for p in &presets {
        let quick = p.quick_params.as_ref().expect("quick params");
        assert_eq!(quick["resolution"], json!(if p.name.ends_with("3d") { 8 } else { 16 }));
        for value in [&p.params, quick] {
            let read: FlipSceneParams = params(value).expect("parameters");
            assert_eq!(read.preset.as_deref(), Some(p.name));
            assert_eq!(&serde_json::to_value(&read).expect("json"), value, "{}", p.name);
        }
    }
}

#[test]
fn transfers_are_spelled_as_scene_files_write_them() {
    for (t, v) in [
        (Transfer::Pic, json!("pic")),
        (Transfer::Apic, json!("apic")),
        (Transfer::Flip(0.97), json!({ "flip": 0.97 })),
    ] {
        assert_eq!(serde_json::to_value(t).expect("json"), v);
        assert_eq!(serde_json::from_value::<Transfer>(v).expect("read"), t);
    }
    let p: FlipSceneParams =
        params(&json!({ "preset": "drop-2d", "transfer": { "flip": 0.5 } })).expect("parameters");
    assert_eq!(p.transfer, Some(Transfer::Flip(0.5)));
}

/// Every preset, at its own size and its quick one: three steps of its `dt` give finite
/// points and velocities, a time of 3 dt, and particles that moved.
#[test]
fn every_preset_builds_steps_and_draws() {
    for p in (KIND.presets)() {
        for value in [Some(&p.params), p.quick_params.as_ref()].into_iter().flatten() {
            let mut scene = build_value(value).expect("builds");
            assert_eq!(scene.context().point_dim, 3);
            let first = frame_of(scene.as_ref());
            for _ in 0..3 {
                scene.step(p.run.dt).expect("step");
            }
            let f = frame_of(scene.as_ref());
            assert!((f.time - 3.0 * p.run.dt).abs() < 1e-12, "{}: {}", p.name, f.time);
            assert_eq!(scene.time().to_bits(), f.time.to_bits());
            let v = &f.field("velocity").expect("velocities").values;
            assert!(!f.points.is_empty() && v.len() == f.points.len(), "{}", p.name);
            assert!(f.points.iter().chain(v).all(|x| x.is_finite()), "{}", p.name);
            assert_ne!(f.points, first.points, "{}: nothing moved", p.name);
        }
    }
}

/// The frame is the old display state: the preset's particles after the same steps, in the
/// world frame (the moving tank's displacement and velocity added along x) with y up as the
/// solver has it, 2D scenes in the plane z = 0, and the context the tank, a quarter-cell radius
/// and the swept region as bounds.
#[test]
fn frames_are_the_particles_y_up_in_the_world_frame() {
    for name in scenes::NAMES {
        let (mut scene, dt) = quick(name);
        let dim = if name.ends_with("3d") { 3 } else { 2 };
        let mut plain =
            scenes::by_name(name, Some(if dim == 3 { 8 } else { 16 }), None).expect("known").expect("builds");
        for _ in 0..4 {
            scene.step(dt).expect("step");
            match &mut plain {
                FlipScene::Two(s) => s.sim.advance(&mut s.particles, dt).map(|_| ()),
                FlipScene::Three(s) => s.sim.advance(&mut s.particles, dt).map(|_| ()),
            }
            .expect("step");
        }
        let f = frame_of(scene.as_ref());
        let context = scene.context();
        let (x, v, t, lo, hi, motion, h) = match &plain {
            FlipScene::Two(s) => {
                let (lo, hi) = s.sim.fluid_box();
                let pad = |a: [f64; 2]| vec![a[0], a[1], 0.0];
                let flat = |a: &[[f64; 2]]| a.iter().flat_map(|p| [p[0], p[1], 0.0]).collect::<Vec<_>>();
                let m = s.sim.params().tank_motion;
                (
                    flat(&s.particles.x),
                    flat(&s.particles.v),
                    s.sim.time(),
                    pad(lo),
                    pad(hi),
                    m,
                    s.sim.grid().h(),
                )
            }
            FlipScene::Three(s) => {
                let (lo, hi) = s.sim.fluid_box();
                let flat = |a: &[[f64; 3]]| a.iter().flatten().copied().collect::<Vec<_>>();
                let m = s.sim.params().tank_motion;
                (
                    flat(&s.particles.x),
                    flat(&s.particles.v),
                    s.sim.time(),
                    lo.to_vec(),
                    hi.to_vec(),
                    m,
                    s.sim.grid().h(),
                )
            }
        };
        assert_eq!(name == "sloshing-tank", motion.is_some());
        let (shift, dv) = motion.map_or((0.0, 0.0), |m| (m.displacement(t), m.velocity(t)));
        if name == "sloshing-tank" {
            assert!(shift != 0.0 && dv != 0.0, "the tank does not move");
        }
        // (x, y, z) y up -> (x + shift, y, z), unturned; in 2D z = 0.
        let moved = |a: &[f64], s: f64| -> Vec<f64> {
            a.chunks_exact(3).flat_map(|c| [c[0] + s, c[1], c[2]]).collect()
        };
        let expected = Frame { time: t, points: moved(&x, shift), ..Frame::default() };
        let mut expected = expected;
        expected.field_mut("velocity", 3).extend(moved(&v, dv));
        assert_eq!(bits(&f), bits(&expected), "{name}");
        assert_eq!(f.fields.len(), 1);
        // The tank at rest, y up; the bounds reach as far as the tank moves.
        let amplitude = motion.map_or(0.0, |m| m.amplitude);
        let tank: ([f64; 3], [f64; 3]) = (std::array::from_fn(|k| lo[k]), std::array::from_fn(|k| hi[k]));
        assert_eq!(context.planar, dim == 2, "{name}");
        assert_eq!(context.props, vec![Prop::Tank { lo: tank.0, hi: tank.1 }], "{name}");
        let (mut blo, mut bhi) = tank;
        blo[0] -= amplitude;
        bhi[0] += amplitude;
        assert_eq!(context.bounds, Some((blo, bhi)), "{name}");
        assert_eq!(context.point_radius, 0.25 * h);
        assert!(context.pins.is_empty() && context.image.is_none());
        assert_eq!(scene.method(), format!("{dim}D APIC on a MAC grid, MGPCG pressure, CFL substeps"));
    }
    let flip = build_value(&json!({ "preset": "drop-2d", "resolution": 16, "transfer": { "flip": 0.97 } }));
    assert_eq!(flip.expect("builds").method(), "2D FLIP 0.97 on a MAC grid, MGPCG pressure, CFL substeps");
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
    let (mut drop, dt) = quick("drop-2d");
    drop.step(dt).expect("step");
    let d = drop.save();
    let edit = |f: &dyn Fn(&mut serde_json::Value)| {
        let mut v = d.clone();
        f(&mut v["saved"]);
        v
    };
    let cases = [
        (
            quick("dam-break-2d").0.save(),
            "`cells`: a checkpoint of a [16, 15] grid; this scene's is [16, 16]",
        ),
        (quick("drop-3d").0.save(), "`dim`: a 3D checkpoint for a 2D scene"),
        (
            edit(&|s| s["particles"]["x"][1] = json!(2.0)),
            "2.0] lies outside the tank [0.0625, 0.0625] - [0.9375, 0.9375]",
        ),
        (edit(&|s| s["particles"]["v"][0] = json!(null)), "`particles`: invalid type: null"),
        (
            edit(&|s| {
                for key in ["x", "v"] {
                    s["particles"][key].as_array_mut().expect("array").truncate(2);
                }
                s["particles"]["c"].as_array_mut().expect("array").truncate(4);
            }),
            "`particles`: 1 particles; this scene has",
        ),
        (
            edit(&|s| s["particles"]["c"].as_array_mut().expect("array").truncate(3)),
            "`particles`: particle arrays",
        ),
        (
            edit(&|s| s["simulation"]["time"] = json!("later")),
            "`simulation`: anim-flip: checkpoint: no finite time",
        ),
        (edit(&|s| drop_key(s, "simulation")), "the checkpoint has no `simulation`"),
        (edit(&|s| drop_key(s, "particles")), "the checkpoint has no `particles`"),
        (edit(&|s| drop_key(s, "cells")), "the checkpoint has no `cells`"),
    ];
    let before = saved_text(drop.as_ref());
    for (saved, expect) in cases {
        let msg = drop.restore(&saved).expect_err("refused").to_string();
        assert!(msg.contains(expect), "{expect}: {msg}");
        assert!(saved_text(drop.as_ref()) == before, "{expect}: the scene changed");
    }
}

fn drop_key(v: &mut serde_json::Value, key: &str) {
    v.as_object_mut().expect("object").remove(key);
}

#[test]
fn an_overflow_fails_the_step_and_leaves_the_scene_as_it_was() {
    for name in scenes::NAMES {
        let (mut scene, dt) = quick(name);
        scene.step(dt).expect("step");
        assert!(scene.provoke_overflow().is_some());
        let before = saved_text(scene.as_ref());
        let msg = scene.step(dt).expect_err("overflow").to_string();
        assert!(msg.starts_with("anim-flip: non-finite "), "{name}: {msg}");
        assert!(saved_text(scene.as_ref()) == before, "{name}: the failed step changed the scene");
    }
}

#[test]
fn bad_parameters_name_their_field() {
    let msg = err(json!({ "preset": "drop-2d", "resolutoin": 8 }));
    assert!(msg.contains("unknown field `resolutoin`"), "{msg}");
    assert_eq!(
        err(json!({ "preset": "drop-4d" })),
        "field `preset`: unknown preset `drop-4d` (one of dam-break-2d, dam-break-3d, drop-2d, drop-3d, sloshing-tank)"
    );
    // A tank past the memory available is refused before it is made, with the estimate and the
    // memory, for presets and bodies alike.
    let body = json!({ "shape": { "sphere": { "center": [0.5, 0.5, 0.5], "radius": 0.1 } } });
    for params in [
        json!({ "preset": "drop-3d", "resolution": 1_000_000_000 }),
        json!({ "preset": "sloshing-tank", "resolution": 1_000_000_000 }),
        json!({ "bodies": [body], "resolution": 1_000_000_000 }),
    ] {
        let start = std::time::Instant::now();
        let e = (KIND.build)(&params, &Default::default()).err().expect("refused");
        assert!(start.elapsed().as_secs_f64() < 1.0, "{params}: {:?}", start.elapsed());
        assert!(matches!(e, BuildError::Memory { .. }), "{params}: {e}");
        let msg = e.to_string();
        assert!(
            msg.starts_with("field `resolution`: 1000000000 cells across ") && msg.contains("needs about "),
            "{msg}"
        );
    }
    let msg = err(json!({ "preset": "drop-2d", "resolution": 2 }));
    assert!(msg.starts_with("field `resolution`: anim-flip: parameter `cells[0]`"), "{msg}");
    assert_eq!(
        err(json!({ "preset": "drop-2d", "transfer": { "flip": 1.5 } })),
        "field `transfer`: the FLIP blend must lie in [0, 1], got 1.5"
    );
    let msg = err(json!({ "preset": "drop-2d", "transfer": "flip" }));
    assert!(msg.contains("transfer") || msg.contains("flip"), "{msg}");
}
