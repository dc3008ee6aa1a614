//! The registry of scene kinds (`anim::KINDS`) against the command line's built-in scenes: every
//! built-in scene is a registered preset with the same description, run settings and scene
//! parameters, and the scene its crate builds steps to the same frames, bit for bit, as the
//! command line's runner of that scene.

#![allow(clippy::expect_used)]

use anim_cli::runner;
use anim_cli::scene::{self, Scene};
use anim_cli::view::Snapshot;
use anim_core::scene::{BuildContext, Frame};
use std::path::Path;

/// The `[scene]` table of a built-in scene's text without `kind`, as JSON, and the kind.
fn scene_params(text: &str) -> (String, serde_json::Value) {
    let table: toml::Table = toml::from_str(text).expect("toml");
    let mut scene = table["scene"].as_table().expect("[scene]").clone();
    let kind = scene.remove("kind").expect("kind").as_str().expect("a string").to_string();
    (kind, serde_json::to_value(scene).expect("json"))
}

#[test]
fn every_builtin_scene_is_a_registered_preset_with_the_same_settings() {
    assert_eq!(anim::presets().len(), scene::BUILTIN.len());
    for (name, description, text) in scene::BUILTIN {
        let file = scene::parse(text, Path::new(name)).expect("parse");
        let (kind, preset) = anim::preset(name).unwrap_or_else(|| panic!("{name} is not registered"));
        let (kind_name, params) = scene_params(text);
        assert_eq!(kind.kind, kind_name, "{name}");
        assert_eq!(preset.description, description, "{name}");
        assert_eq!(
            (preset.run.dt.to_bits(), preset.run.frames, preset.run.steps_per_frame),
            (file.run.dt.to_bits(), file.run.frames, file.run.steps_per_frame),
            "{name}"
        );
        assert_eq!(preset.params, params, "{name}");
    }
}

/// The grid fluids and particle fluids at the small resolutions of the runner's own tests.
fn small(name: &str, file: &mut scene::SceneFile, params: &mut serde_json::Value) {
    let three = name.ends_with("3d");
    let r = match &mut file.scene {
        Scene::Fluid { resolution, .. } | Scene::Flip { resolution, .. } => {
            let r = if three { 8 } else { 16 };
            *resolution = Some(r);
            r
        }
        _ => return,
    };
    params["resolution"] = serde_json::json!(r);
}

fn same(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
}

#[test]
fn every_registered_scene_steps_to_the_runners_frames_bit_for_bit() {
    for (name, _, text) in scene::BUILTIN {
        let mut file = scene::parse(text, Path::new(name)).expect("parse");
        let (kind, preset) = anim::preset(name).expect("registered");
        let mut params = preset.params.clone();
        small(name, &mut file, &mut params);
        let mut old = runner::build(&file.scene, Path::new(name), None).expect("runner");
        let mut new = (kind.build)(&params, &BuildContext::default()).expect("registered build");
        assert_eq!(old.method(), new.method(), "{name}");
        let (mut snap, mut frame) = (Snapshot::default(), Frame::default());
        for step in 0..4 {
            if step > 0 {
                let mut a = old.step(file.run.dt).expect("runner step");
                let b = new.step(file.run.dt).expect("scene step");
                // The seed solver's report carried its f32 clock; the scene reports the run's
                // clock, which the frames carry and compare below.
                a.time = b.time;
                assert_eq!(a, b, "{name}: step reports");
            }
            old.snapshot(None, &mut snap);
            new.frame(&mut frame);
            assert_eq!(snap.t.to_bits(), frame.time.to_bits(), "{name}: time at step {step}");
            let context = new.context();
            let (x, v) = if context.image.is_some() {
                (frame.field("density"), frame.field("velocity"))
            } else {
                (None, frame.field("velocity"))
            };
            let x = x.map_or(frame.points.as_slice(), |f| f.values.as_slice());
            let v = v.map_or(&[][..], |f| f.values.as_slice());
            assert!(same(&snap.x, x), "{name}: positions at step {step}");
            assert!(same(&snap.v, v), "{name}: velocities at step {step}");
            // Where the runner measured against a reference, the scene measures the same; the
            // cavity's error against Ghia et al. is new with its kind.
            if let Some(e) = old.exact_error().or(old.study_error()) {
                assert_eq!(Some(e), new.reference_error(), "{name}");
            }
        }
    }
}
