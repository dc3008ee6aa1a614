//! The `skinning` scene kind through anim-core's dynamic scene contracts: the preset and glTF
//! files build, step and draw; frames are every method's posed vertices side by side with
//! velocities by finite difference; checkpoints resume bit for bit and foreign or damaged ones
//! are refused; a pose that fails leaves the scene as it was; bad parameters name their field.

#![allow(clippy::unwrap_used, clippy::expect_used)] // integration tests: a failed unwrap is a failed test

use anim_core::scene::{BuildContext, CheckpointError, DynScene, Frame, Preset, RunDefaults};
use anim_skin::kind::SkinningChoice;
use anim_skin::{KIND, SkinningMethod, scenes};
use std::path::{Path, PathBuf};

fn testdata() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("testdata")
}

fn build_in(params: &serde_json::Value, base: Option<&Path>) -> Result<Box<dyn DynScene>, String> {
    (KIND.build)(params, &BuildContext { base }).map_err(|e| e.to_string())
}

fn build(params: &serde_json::Value) -> Box<dyn DynScene> {
    build_in(params, None).unwrap()
}

fn twist() -> Preset {
    (KIND.presets)().remove(0)
}

fn frame(scene: &dyn DynScene) -> Frame {
    let mut f = Frame::default();
    scene.frame(&mut f);
    f
}

fn bits(f: &Frame) -> Vec<u64> {
    let v = &f.field("velocity").unwrap().values;
    [f.time].iter().chain(&f.points).chain(v).map(|x| x.to_bits()).collect()
}

#[test]
fn the_preset_is_the_command_lines_built_in_twist() {
    let presets = (KIND.presets)();
    assert_eq!(presets.len(), 1);
    let p = &presets[0];
    assert_eq!((p.name, p.run), ("twist", RunDefaults::new(0.02, 100, 1)));
    assert_eq!(p.params, serde_json::json!({ "preset": "twisted-cylinder", "method": "both" }));
    assert_eq!(p.description, "a cylinder twisted 180 degrees: LBS's candy-wrapper collapse beside DQS");
    assert_eq!(KIND.kind, "skinning");
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
            assert_eq!(f.time.to_bits(), (dt + dt + dt).to_bits());
            assert!((f.time - 3.0 * dt).abs() < 1e-15);
            let v = &f.field("velocity").unwrap().values;
            assert_eq!(v.len(), f.points.len());
            assert!(f.points.iter().chain(v).all(|x| x.is_finite()));
            assert!(f.points.iter().zip(&start.points).any(|(a, b)| a != b), "nothing moved");
            assert!(v.iter().any(|x| *x != 0.0), "no velocity");
            let context = scene.context();
            assert_eq!(context.point_dim, 3);
            assert!(context.triangles.iter().flatten().all(|&i| 3 * i < f.points.len()));
            assert!(scene.provoke_overflow().is_none(), "nothing is integrated");
        }
    }
}

/// The former command-line runner written out: every method poses the clip at `t`, shifted
/// along x by 1.4 widths of the time-0 LBS pose (centred), velocities by difference over
/// `t - t_previous`; the frame must match it bit for bit.
#[test]
fn frames_are_the_methods_side_by_side_with_velocities_by_difference() {
    for (choice, methods) in [
        ("both", vec![SkinningMethod::Lbs, SkinningMethod::Dqs]),
        ("lbs", vec![SkinningMethod::Lbs]),
        ("dqs", vec![SkinningMethod::Dqs]),
    ] {
        let mut scene = build(&serde_json::json!({ "preset": "twisted-cylinder", "method": choice }));
        let reference = scenes::twisted_cylinder(None).unwrap();
        let mut data = reference.data();
        reference.pose(&mut data, 0.0, SkinningMethod::Lbs).unwrap();
        let mut p = Vec::new();
        data.positions(&mut p);
        let lo = p.iter().map(|q| q[0]).fold(f64::MAX, f64::min);
        let hi = p.iter().map(|q| q[0]).fold(f64::MIN, f64::max);
        let n = p.len();
        let count = methods.len() as f64;
        let (mut t, mut x, mut v) = (0.0_f64, Vec::new(), Vec::new());
        let dt = 0.02;
        for step in 0..=40 {
            let t_new = if step == 0 { 0.0 } else { t + dt };
            if step > 0 {
                scene.step(dt).unwrap();
            }
            let mut new = Vec::new();
            for (k, &m) in methods.iter().enumerate() {
                let offset = (k as f64 - 0.5 * (count - 1.0)) * 1.4 * (hi - lo);
                reference.pose(&mut data, t_new, m).unwrap();
                data.positions(&mut p);
                new.extend(p.iter().flat_map(|q| [q[0] + offset, q[1], q[2]]));
            }
            let h = t_new - t;
            v = if step == 0 {
                vec![0.0; new.len()]
            } else {
                new.iter().zip(&x).map(|(a, b)| (a - b) / h).collect()
            };
            (t, x) = (t_new, new);
            if step == 0 {
                let context = scene.context();
                let base = reference.character.triangles();
                assert_eq!(context.triangles.len(), base.len() * methods.len());
                for (k, tri) in context.triangles.iter().enumerate() {
                    let shift = (k / base.len()) * n;
                    assert_eq!(*tri, base[k % base.len()].map(|i| i as usize + shift));
                }
                let (lo, hi) = context.bounds.unwrap();
                assert!(x.chunks_exact(3).all(|q| (0..3).all(|k| lo[k] <= q[k] && q[k] <= hi[k])));
                assert!(context.lines.is_empty() && context.props.is_empty() && context.point_radius == 0.0);
            }
        }
        let expected: Vec<u64> = [t].iter().chain(&x).chain(&v).map(|x| x.to_bits()).collect();
        assert_eq!(bits(&frame(scene.as_ref())), expected, "{choice}");
        let label =
            methods.iter().map(|m| format!("{m:?}").to_lowercase()).collect::<Vec<_>>().join(" beside ");
        assert_eq!(scene.method(), label);
    }
    // The two cylinders of the preset side by side: the twist collapses the LBS one.
    assert_eq!(build(&twist().params).method(), "lbs beside dqs");
}

#[test]
#[cfg(feature = "gltf")]
fn a_gltf_file_is_read_relative_to_the_scene_folder_with_dqs_by_default() {
    let dir = testdata();
    let scene = build_in(&serde_json::json!({ "file": "skin.glb" }), Some(&dir)).unwrap();
    assert_eq!(scene.method(), "dqs");
    let scene = build_in(&serde_json::json!({ "file": "skin.glb", "method": "both" }), Some(&dir)).unwrap();
    assert_eq!(scene.method(), "lbs beside dqs");
    let err = build_in(&serde_json::json!({ "file": "nope.glb" }), Some(&dir)).err().unwrap();
    assert!(err.starts_with("field `file`: ") && err.contains("nope.glb"), "{err}");
    // The same name without the folder is looked up from the working directory.
    assert!(build_in(&serde_json::json!({ "file": "skin.glb" }), None).is_err());
}

/// A file whose meshes have no skin has nothing to pose: it is refused naming the file, not run
/// as an empty scene.
#[test]
#[cfg(feature = "gltf")]
fn a_file_without_a_skinned_mesh_is_refused() {
    let text = std::fs::read_to_string(testdata().join("skin_embedded.gltf")).unwrap();
    let mut gltf: serde_json::Value = serde_json::from_str(&text).unwrap();
    for node in gltf["nodes"].as_array_mut().unwrap() {
        node.as_object_mut().unwrap().remove("skin");
    }
    gltf.as_object_mut().unwrap().remove("skins");
    let dir = std::env::temp_dir().join(format!("anim-skin-unskinned-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("unskinned.gltf"), gltf.to_string()).unwrap();
    let err = build_in(&serde_json::json!({ "file": "unskinned.gltf" }), Some(&dir)).err().unwrap();
    assert!(
        err.starts_with("field `file`: ")
            && err.contains("unskinned.gltf: no skinned mesh")
            && err.contains("skipped"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// A file without an animation is shown in its rest pose: every step leaves the vertices where
/// they were, at zero velocity.
#[test]
#[cfg(feature = "gltf")]
fn a_file_without_an_animation_holds_its_rest_pose() {
    let text = std::fs::read_to_string(testdata().join("skin_embedded.gltf")).unwrap();
    let mut gltf: serde_json::Value = serde_json::from_str(&text).unwrap();
    gltf.as_object_mut().unwrap().remove("animations");
    let dir = std::env::temp_dir().join(format!("anim-skin-still-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("still.gltf"), gltf.to_string()).unwrap();
    let mut scene = build_in(&serde_json::json!({ "file": "still.gltf" }), Some(&dir)).unwrap();
    let rest = frame(scene.as_ref()).points;
    assert!(!rest.is_empty());
    for _ in 0..3 {
        scene.step(0.1).unwrap();
    }
    let f = frame(scene.as_ref());
    assert_eq!(f.points, rest);
    assert!(f.field("velocity").unwrap().values.iter().all(|v| *v == 0.0));
    std::fs::remove_dir_all(&dir).ok();
}

/// The embedded asset scales joint 4 on its way to t = 2 s, which DQS refuses: the failing step
/// names it and leaves the scene (LBS half included) as it was.
#[test]
#[cfg(feature = "gltf")]
fn a_pose_that_fails_leaves_the_scene_as_it_was() {
    let params = serde_json::json!({ "file": "skin_embedded.gltf", "method": "both" });
    let mut scene = build_in(&params, Some(&testdata())).unwrap();
    let mut failed = None;
    for _ in 0..200 {
        let (before, frame_before) = (scene.save(), bits(&frame(scene.as_ref())));
        if let Err(e) = scene.step(0.02) {
            assert_eq!(scene.save(), before);
            assert_eq!(bits(&frame(scene.as_ref())), frame_before);
            failed = Some(e.to_string());
            break;
        }
    }
    let msg = failed.expect("DQS refuses the scaled joint before t = 4 s");
    assert!(msg.starts_with("anim-skin: Dqs pose at t = "), "{msg}");
    assert!(msg.contains("skin joint 4: skinning matrix is not rigid"), "{msg}");
    // So does a step that is not positive.
    let mut scene = build(&twist().params);
    let before = scene.save();
    let err = scene.step(0.0).unwrap_err().to_string();
    assert_eq!(err, "anim-skin: time step must be positive and finite, got 0");
    assert!(scene.step(f64::NAN).is_err());
    assert_eq!(scene.save(), before);
}

#[test]
#[cfg(not(feature = "gltf"))]
fn without_the_gltf_feature_a_file_is_refused_naming_the_feature() {
    let err = build_in(&serde_json::json!({ "file": "skin.glb" }), Some(&testdata())).err().unwrap();
    assert!(err.contains("skin.glb"), "{err}");
    assert!(err.contains("anim-skin's `gltf` feature"), "{err}");
}

#[test]
fn a_checkpoint_resumes_bit_for_bit() {
    let p = twist();
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
    assert_eq!(a.save(), b.save());
    assert_eq!(bits(&frame(a.as_ref())), bits(&frame(b.as_ref())));
}

#[test]
fn a_foreign_or_damaged_checkpoint_is_refused_and_changes_nothing() {
    let mut scene = build(&twist().params);
    scene.step(0.02).unwrap();
    let before = scene.save();
    let mut one = build(&serde_json::json!({ "preset": "twisted-cylinder", "method": "lbs" }));
    one.step(0.02).unwrap();
    let err = scene.restore(&one.save()).unwrap_err();
    assert_eq!(
        err,
        CheckpointError::invalid("state", "3942 positions and 3942 velocities; this scene has 7884 and 7884")
    );
    let mut damaged = before.clone();
    damaged["saved"].as_object_mut().unwrap().remove("state");
    assert_eq!(scene.restore(&damaged).unwrap_err(), CheckpointError::Missing { field: "state".into() });
    let mut damaged = before.clone();
    damaged["saved"]["state"]["v"].as_array_mut().unwrap().pop();
    let err = scene.restore(&damaged).unwrap_err();
    assert!(matches!(&err, CheckpointError::Invalid { field, .. } if field == "state"), "{err}");
    let mut damaged = before.clone();
    damaged["saved"]["state"]["x"] = serde_json::json!(1.0);
    let err = scene.restore(&damaged).unwrap_err();
    assert!(matches!(&err, CheckpointError::Invalid { field, .. } if field == "state"), "{err}");
    let mut damaged = before.clone();
    damaged["version"] = serde_json::json!(2);
    assert_eq!(scene.restore(&damaged).unwrap_err(), CheckpointError::Version { found: 2, expected: 1 });
    assert_eq!(scene.save(), before);
}

#[test]
fn nothing_is_integrated_so_nothing_can_be_made_to_overflow() {
    let mut scene = build(&twist().params);
    scene.step(0.02).unwrap();
    let before = scene.save();
    assert_eq!(scene.provoke_overflow(), None);
    assert_eq!(scene.save(), before);
    scene.step(0.02).unwrap();
}

#[test]
fn bad_parameters_name_their_field() {
    let err =
        build_in(&serde_json::json!({ "preset": "twisted-cylinder", "resolution": 8 }), None).err().unwrap();
    assert!(err.contains("unknown field `resolution`"), "{err}");
    let err = build_in(&serde_json::json!({ "preset": "twisted" }), None).err().unwrap();
    assert_eq!(err, "field `preset`: unknown preset `twisted` (one of twisted-cylinder)");
    for both_or_none in
        [serde_json::json!({ "preset": "twisted-cylinder", "file": "a.glb" }), serde_json::json!({})]
    {
        let err = build_in(&both_or_none, None).err().unwrap();
        assert_eq!(err, "field `preset`: give exactly one of `preset` and `file`");
    }
    let err = build_in(&serde_json::json!({ "preset": "twisted-cylinder", "method": "blend" }), None)
        .err()
        .unwrap();
    assert!(err.contains("unknown variant `blend`"), "{err}");
}

#[test]
fn the_skinning_choice_reads_and_writes_its_scene_file_spelling() {
    for (choice, text) in
        [(SkinningChoice::Lbs, "lbs"), (SkinningChoice::Dqs, "dqs"), (SkinningChoice::Both, "both")]
    {
        assert_eq!(serde_json::to_value(choice).unwrap(), serde_json::json!(text));
        assert_eq!(serde_json::from_value::<SkinningChoice>(serde_json::json!(text)).unwrap(), choice);
        assert_eq!(text.parse::<SkinningChoice>().unwrap(), choice);
        assert_eq!(choice.to_string(), text);
    }
    assert!("LBS".parse::<SkinningChoice>().is_err());
}
