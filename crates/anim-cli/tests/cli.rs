//! Bad command-line input: every refused flag value and scene name gives an error naming it,
//! and nothing is written.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::process::Command;

fn anim(args: &[&str]) -> (bool, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_anim")).args(args).output().expect("the anim binary runs");
    (out.status.success(), String::from_utf8_lossy(&out.stderr).into_owned())
}

#[test]
fn bad_flags_and_names_are_refused_with_the_value_named() {
    let dir = std::env::temp_dir().join(format!("anim-cli-flags-{}", std::process::id()));
    let out = dir.to_str().unwrap();
    let cases: [(&[&str], &str); 20] = [
        (&["run", "kepler", "--frames", "0"], "--frames must be at least 1"),
        (&["run", "kepler", "--dt", "0"], "--dt must be a positive finite number, got 0"),
        (&["run", "kepler", "--dt", "-1e-3"], "got -0.001"),
        (&["run", "kepler", "--dt", "NaN"], "got NaN"),
        (&["run", "kepler", "--stride", "0"], "--stride must be at least 1"),
        (
            &["run", "kepler", "--preview-size", "8x8"],
            "8x8: width and height must each lie in [16, 4096] pixels",
        ),
        (
            &["run", "kepler", "--preview-size", "0x480"],
            "'--preview-size <WxH>': 0x480: width and height must",
        ),
        (&["run", "kepler", "--preview-size", "640x100000"], "640x100000: width and height must each lie in"),
        (
            &["run", "kepler", "--preview-size", "wide"],
            "wide: expected WIDTHxHEIGHT in pixels, such as 640x480",
        ),
        (&["run", "kepler", "--checkpoint-every", "0"], "--checkpoint-every must be at least 1"),
        (
            &["run", "mpm", "--color-by", "pressure"],
            "--color-by pressure: the scene's frames have no field `pressure`; it can be coloured by speed, \
             velocity, material, strain, none",
        ),
        (&["run", "kepler", "--color-by", "speed"], "--color-by speed: the scene's frames have no field"),
        (&["run", "smoke-box-2d", "--color-by", "none"], "it can be coloured by density, speed"),
        (&["run", "warp-drive"], "warp-drive: no such scene file, and no built-in scene of that name"),
        (&["resume", "no-such-checkpoint.anim"], "no-such-checkpoint.anim"),
        (&["run", "lid-driven-cavity", "--resolution", "1"], "field `scene.resolution`: anim-fluid: grid"),
        (
            &["run", "smoke-plume-3d", "--resolution", "100000"],
            "--resolution 100000: <built-in scene smoke-plume-3d>: field `scene.resolution`: 100000 cells across needs about",
        ),
        (&["run", "kepler", "--resolution", "8"], "--resolution 8: a kepler-orbit scene has no resolution"),
        (
            &["run", "smoke-box-2d", "--format", "csv"],
            "--format csv: smoke-box-2d is a grid scene: its frames are vti",
        ),
        (&["run", "kepler", "--format", "vti"], "--format vti: kepler is not a grid scene"),
    ];
    for (args, expect) in cases {
        let mut args = args.to_vec();
        args.extend(["--out", out]);
        if args[0] == "resume" {
            args.truncate(2);
        }
        let (ok, err) = anim(&args);
        assert!(!ok, "{args:?} was accepted");
        assert!(err.contains(expect), "{args:?}: {err}");
    }
    assert!(!dir.exists(), "a refused run wrote {}", dir.display());
}

#[test]
fn a_scene_file_with_an_error_names_file_line_and_field() {
    let dir = std::env::temp_dir().join(format!("anim-cli-scene-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("bad.toml");
    std::fs::write(
        &path,
        "name = \"x\"\n[run]\ndt = 0.01\nframes = 3\nfrmes = 2\n[scene]\nkind = \"kepler-orbit\"\n",
    )
    .unwrap();
    let (ok, err) = anim(&["run", path.to_str().unwrap(), "--quiet", "--no-preview"]);
    assert!(!ok);
    assert!(err.contains("bad.toml:5:") && err.contains("frmes"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

fn temp(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("anim-cli-fluid-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

#[test]
fn fluid_scenes_are_listed_by_anim_scenes_and_run_help() {
    let out = Command::new(env!("CARGO_BIN_EXE_anim")).arg("scenes").output().unwrap();
    assert!(out.status.success());
    let list = String::from_utf8_lossy(&out.stdout);
    let help = Command::new(env!("CARGO_BIN_EXE_anim")).args(["run", "--help"]).output().unwrap();
    assert!(help.status.success());
    let help = String::from_utf8_lossy(&help.stdout);
    for name in ["smoke-box-2d", "smoke-plume-3d", "lid-driven-cavity"] {
        assert!(list.lines().any(|l| l.starts_with(name)), "{name} not in {list}");
        assert!(help.lines().any(|l| l.starts_with(name)), "{name} not in {help}");
    }
}

/// A fluid run writes `.vti` frames of the density and velocity, their `.pvd`, the density
/// preview and the metrics.
#[test]
fn a_fluid_run_writes_vti_frames_a_series_and_a_density_preview() {
    for (scene, resolution, extent) in
        [("lid-driven-cavity", "12", "0 12 0 12 0 0"), ("smoke-plume-3d", "6", "0 6 0 9 0 6")]
    {
        let dir = temp(scene);
        let d = dir.to_str().unwrap();
        let args = [
            "run",
            scene,
            "--resolution",
            resolution,
            "--frames",
            "3",
            "--out",
            d,
            "--quiet",
            "--preview-size",
            "48x48",
        ];
        let (ok, err) = anim(&args);
        assert!(ok, "{scene}: {err}");
        for k in 0..3 {
            let frame = dir.join("frames").join(format!("frame_0000{k}.vti"));
            let text = std::fs::read_to_string(&frame).unwrap();
            assert!(text.contains(&format!("WholeExtent=\"{extent}\"")), "{scene}: {text:.300}");
            assert!(text.contains("Name=\"density\"") && text.contains("Name=\"velocity\""));
        }
        let pvd = std::fs::read_to_string(dir.join("frames").join("frames.pvd")).unwrap();
        assert!(pvd.contains("file=\"frame_00002.vti\""), "{pvd}");
        for file in ["preview.gif", "preview.png", "metrics.json"] {
            assert!(dir.join(file).exists(), "{scene}: no {file}");
        }
        let metrics = std::fs::read_to_string(dir.join("metrics.json")).unwrap();
        assert!(metrics.contains("\"status\": \"completed\"") && metrics.contains("fluid/"), "{metrics}");
        std::fs::remove_dir_all(&dir).ok();
    }
}

/// `anim resume` of a fluid run: the frames after the checkpoint are byte for byte those of an
/// uninterrupted run (base64 of the values: equal text is equal bits).
#[test]
fn a_resumed_fluid_run_writes_the_frames_of_an_uninterrupted_one() {
    for (scene, resolution) in [("smoke-box-2d", "16"), ("smoke-plume-3d", "6")] {
        let whole = temp(&format!("{scene}-whole"));
        let parts = temp(&format!("{scene}-parts"));
        let common = ["--resolution", resolution, "--no-preview", "--quiet"];
        let run = |out: &std::path::Path, frames: &str, extra: &[&str]| {
            let mut args = vec!["run", scene, "--frames", frames, "--out", out.to_str().unwrap()];
            args.extend(common);
            args.extend(extra);
            let (ok, err) = anim(&args);
            assert!(ok, "{scene}: {err}");
        };
        run(&whole, "6", &[]);
        run(&parts, "4", &["--checkpoint-every", "3"]);
        let ckpt = parts.join("checkpoint.anim");
        let (ok, err) = anim(&["resume", ckpt.to_str().unwrap(), "--frames", "6", "--quiet"]);
        assert!(ok, "{scene}: {err}");
        for k in 0..6 {
            let name = format!("frame_0000{k}.vti");
            let a = std::fs::read(whole.join("frames").join(&name)).unwrap();
            let b = std::fs::read(parts.join("frames").join(&name)).unwrap();
            assert!(a == b, "{scene}: {name} differs");
        }
        std::fs::remove_dir_all(&whole).ok();
        std::fs::remove_dir_all(&parts).ok();
    }
}

/// A particle-fluid run writes one point cloud per frame holding every particle, and the flip
/// presets are listed.
#[test]
fn a_flip_run_writes_particle_point_clouds() {
    let out = Command::new(env!("CARGO_BIN_EXE_anim")).arg("scenes").output().unwrap();
    let list = String::from_utf8_lossy(&out.stdout);
    for name in anim_flip::scenes::NAMES {
        assert!(list.lines().any(|l| l.starts_with(name)), "{name} not in {list}");
    }
    let dir = temp("flip-drop-2d");
    let (ok, err) = anim(&[
        "run",
        "drop-2d",
        "--resolution",
        "12",
        "--frames",
        "3",
        "--format",
        "ply",
        "--no-preview",
        "--quiet",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let Some(anim_flip::scenes::FlipScene::Two(scene)) =
        anim_flip::scenes::by_name("drop-2d", Some(12), None).map(|r| r.unwrap())
    else {
        panic!("drop-2d is 2D");
    };
    let count = scene.particles.len();
    let mut frames: Vec<_> = std::fs::read_dir(dir.join("frames"))
        .unwrap()
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "ply"))
        .collect();
    frames.sort();
    assert_eq!(frames.len(), 3, "{frames:?}");
    for f in frames {
        let bytes = std::fs::read(&f).unwrap();
        let header = String::from_utf8_lossy(&bytes[..bytes.len().min(400)]);
        assert!(header.contains(&format!("element vertex {count}")), "{}: {header}", f.display());
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// A FEM scene file with `element = "tet10"` runs 10-node elements (the method names them) and
/// `anim resume` continues it to the same frames as an uninterrupted run.
#[test]
fn a_tet10_fem_scene_runs_and_resumes_bit_for_bit() {
    let dir = temp("fem-tet10");
    std::fs::create_dir_all(&dir).unwrap();
    let scene = dir.join("beam10.toml");
    std::fs::write(
        &scene,
        "name = \"beam10\"\n[run]\ndt = 0.01\nframes = 6\nsteps_per_frame = 1\n[scene]\nkind = \"fem\"\n\
         preset = \"cantilever-beam\"\nresolution = 1\nelement = \"tet10\"\n",
    )
    .unwrap();
    let (whole, parts) = (dir.join("whole"), dir.join("parts"));
    let run = |out: &std::path::Path, frames: &str, extra: &[&str]| {
        let mut args = vec![
            "run",
            scene.to_str().unwrap(),
            "--frames",
            frames,
            "--out",
            out.to_str().unwrap(),
            "--no-preview",
            "--quiet",
        ];
        args.extend(extra);
        let (ok, err) = anim(&args);
        assert!(ok, "{err}");
    };
    run(&whole, "6", &[]);
    run(&parts, "4", &["--checkpoint-every", "3"]);
    let metrics = std::fs::read_to_string(whole.join("metrics.json")).unwrap();
    assert!(metrics.contains("tet10"), "{metrics}");
    let ckpt = parts.join("checkpoint.anim");
    let (ok, err) = anim(&["resume", ckpt.to_str().unwrap(), "--frames", "6", "--quiet"]);
    assert!(ok, "{err}");
    let frames = |d: &std::path::Path| {
        let mut f: Vec<_> = std::fs::read_dir(d.join("frames"))
            .unwrap()
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|e| e == "vtu"))
            .collect();
        f.sort();
        f
    };
    let (a, b) = (frames(&whole), frames(&parts));
    assert_eq!(a.len(), 6, "{a:?}");
    assert_eq!(b.len(), 6, "{b:?}");
    for (fa, fb) in a.iter().zip(&b) {
        assert!(std::fs::read(fa).unwrap() == std::fs::read(fb).unwrap(), "{} differs", fa.display());
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn the_kinds_are_listed_and_any_parameter_can_be_set_from_the_command_line() {
    let out = Command::new(env!("CARGO_BIN_EXE_anim")).args(["list", "--kinds"]).output().unwrap();
    assert!(out.status.success());
    let list = String::from_utf8_lossy(&out.stdout);
    for kind in anim::kinds() {
        assert!(list.lines().any(|l| l.starts_with(kind.kind) && l.contains(kind.crate_name)), "{list}");
    }
    let dir = temp("set");
    let out = dir.to_str().unwrap();
    let (ok, err) =
        anim(&["run", "kepler", "--set", "integrator=rk4", "--frames", "2", "--no-preview", "--out", out]);
    assert!(ok, "{err}");
    let metrics = std::fs::read_to_string(dir.join("metrics.json")).unwrap();
    assert!(metrics.contains("\"method\": \"rk4\""), "{metrics}");
    // A table value, and an unknown parameter named with the kind's own list.
    let (ok, err) = anim(&[
        "run",
        "kepler",
        "--set",
        "integrator={beta-blend={beta=0.5}}",
        "--frames",
        "1",
        "--no-preview",
        "--out",
        out,
    ]);
    assert!(ok, "{err}");
    let (ok, err) = anim(&["run", "kepler", "--set", "eccentricty=0.3", "--out", out]);
    assert!(!ok && err.contains("field `scene.eccentricty`: unknown field `eccentricty`"), "{err}");
    let (ok, err) = anim(&["run", "kepler", "--set", "kind=springs", "--out", out]);
    assert!(!ok && err.contains("--set kind=springs: KEY must name a parameter"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

/// A robot scene whose URDF is missing names the URDF; a joint name the robot does not have is
/// refused on its line of the `[scene.robot]` table, with the robot's joints.
#[test]
fn a_robot_scene_names_a_missing_urdf_and_an_unknown_joint_on_its_line() {
    let dir = temp("robot-errors");
    std::fs::create_dir_all(&dir).unwrap();
    let head = "name = \"r\"\n[run]\ndt = 0.001\nframes = 2\n[scene]\nkind = \"rigid\"\n[scene.robot]\n";
    let missing = dir.join("missing.toml");
    std::fs::write(&missing, format!("{head}urdf = \"no-such-robot.urdf\"\n")).unwrap();
    let (ok, err) = anim(&["run", missing.to_str().unwrap(), "--quiet", "--no-preview"]);
    assert!(!ok);
    assert!(err.contains("missing.toml:8:") && err.contains("no-such-robot.urdf"), "{err}");
    let panda = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../anim-rigid/testdata/panda.urdf");
    let unknown = dir.join("unknown.toml");
    let body = format!("urdf = {:?}\nq0 = {{ panda_joint9 = 1.0 }}\n", panda.to_str().unwrap());
    std::fs::write(&unknown, format!("{head}{body}")).unwrap();
    let (ok, err) = anim(&["run", unknown.to_str().unwrap(), "--quiet", "--no-preview"]);
    assert!(!ok);
    assert!(
        err.contains("unknown.toml:9:") && err.contains("panda_joint9") && err.contains("panda_joint7"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// An `fem` body whose mesh has an inverted element is refused before anything runs, naming the
/// scene file's line, the mesh file and the element.
#[test]
fn a_broken_mesh_is_refused_naming_the_file_and_element() {
    let dir = temp("broken-mesh");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("tet.node"), "4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n").unwrap();
    std::fs::write(dir.join("tet.ele"), "1 4 0\n1 1 3 2 4\n").unwrap();
    let scene = dir.join("broken.toml");
    let text = "name = \"b\"\n[run]\ndt = 0.01\nframes = 2\n[scene]\nkind = \"fem\"\n[[scene.bodies]]\n\
                mesh = \"tet.ele\"\nmaterial = { young = 1e5, poisson = 0.3, density = 1000.0 }\n";
    std::fs::write(&scene, text).unwrap();
    let out = dir.join("out");
    let (ok, err) = anim(&["run", scene.to_str().unwrap(), "--out", out.to_str().unwrap(), "--quiet"]);
    assert!(!ok);
    assert!(err.contains("broken.toml:8:") && err.contains("tet.ele") && err.contains("element 0"), "{err}");
    assert!(!out.exists(), "a refused run wrote {}", out.display());
    std::fs::remove_dir_all(&dir).ok();
}

/// What a loader skips reaches the user: a glTF file that uses an extension the skinning
/// ignores runs, and the run prints a note naming the extension and keeps it in its metrics.
#[test]
fn a_gltf_loader_note_is_printed_and_kept_in_the_metrics() {
    let dir = temp("gltf-note");
    std::fs::create_dir_all(&dir).unwrap();
    let skin =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../anim-skin/testdata/skin_embedded.gltf");
    let mut gltf: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(skin).unwrap()).unwrap();
    gltf["extensionsUsed"] = serde_json::json!(["KHR_materials_emissive_strength"]);
    std::fs::write(dir.join("noted.gltf"), gltf.to_string()).unwrap();
    let scene = dir.join("noted.toml");
    let text = "name = \"noted\"\n[run]\ndt = 0.05\nframes = 2\n[scene]\nkind = \"skinning\"\nfile = \"noted.gltf\"\nmethod = \"lbs\"\n";
    std::fs::write(&scene, text).unwrap();
    let out = dir.join("out");
    let run = Command::new(env!("CARGO_BIN_EXE_anim"))
        .args(["run", scene.to_str().unwrap(), "--out", out.to_str().unwrap(), "--no-preview"])
        .output()
        .expect("the anim binary runs");
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    assert!(
        stdout
            .lines()
            .any(|l| l.starts_with("note: extension KHR_materials_emissive_strength is used and ignored")),
        "{stdout}"
    );
    let metrics: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("metrics.json")).unwrap()).unwrap();
    let notes = metrics["notes"].as_array().expect("notes");
    assert!(
        notes.len() == 1 && notes[0].as_str().unwrap().contains("KHR_materials_emissive_strength"),
        "{notes:?}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// The chain starts at rest level with its pivot, so its total energy starts at 0: its change is
/// measured against the energy in play (the kinetic energy and the fall it gains), not against
/// the initial total. RK4 keeps the total to about 1e-9 of that over 40 frames.
#[test]
fn the_energy_change_is_relative_to_the_energy_in_play() {
    let dir = temp("energy");
    let d = dir.to_str().unwrap();
    let (ok, err) =
        anim(&["run", "chain", "--frames", "40", "--out", d, "--quiet", "--no-preview", "--no-viewer"]);
    assert!(ok, "{err}");
    let metrics: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("metrics.json")).unwrap()).unwrap();
    let e0 = metrics["energy_initial"].as_f64().unwrap();
    let scale = metrics["energy_scale"].as_f64().unwrap();
    let change = metrics["relative_energy_change"].as_f64().unwrap();
    // 32 links of the chain fall: tens of joules in play, while the total stays near 0.
    assert!(scale > 10.0 && e0.abs() < 1e-3 * scale, "scale {scale}, initial {e0}");
    assert!(change.abs() < 1e-6, "{change}");
    assert!(metrics["energy_scale_is"].as_str().unwrap().contains("kinetic"));
    std::fs::remove_dir_all(&dir).ok();
}

/// FEM `.vtu` frames hold the volume (the tetrahedra, 6 per cell of the cube's 3 x 3 x 3 box
/// mesh) and a strain measure; MPM frames hold each particle's material and strain.
#[test]
fn frames_carry_the_volume_strain_and_materials() {
    let dir = temp("volume");
    let d = dir.to_str().unwrap();
    let (ok, err) =
        anim(&["run", "cube", "--resolution", "3", "--frames", "2", "--out", d, "--quiet", "--no-preview"]);
    assert!(ok, "{err}");
    let vtu = std::fs::read_to_string(dir.join("frames/frame_00001.vtu")).unwrap();
    assert!(vtu.contains("NumberOfPoints=\"64\" NumberOfCells=\"162\""), "{vtu:.300}");
    assert!(vtu.contains("Name=\"strain\""));
    std::fs::remove_dir_all(&dir).ok();
    let (ok, err) =
        anim(&["run", "mpm", "--resolution", "32", "--frames", "1", "--out", d, "--quiet", "--no-preview"]);
    assert!(ok, "{err}");
    let vtu = std::fs::read_to_string(dir.join("frames/frame_00000.vtu")).unwrap();
    assert!(vtu.contains("Name=\"material\"") && vtu.contains("Name=\"strain\""), "{vtu:.300}");
    std::fs::remove_dir_all(&dir).ok();
}

/// A run says that its output is y up: `"up": "y"` in `metrics.json`, and the field data `up`
/// holding `(0, 1, 0)` in its `.vtu` frames; the default preview is 640 x 480 pixels.
#[test]
fn a_run_states_that_y_is_up() {
    let dir = temp("up");
    let (ok, err) = anim(&[
        "run",
        "cloth",
        "--resolution",
        "4",
        "--frames",
        "2",
        "--quiet",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let metrics: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("metrics.json")).unwrap()).unwrap();
    assert_eq!(metrics["up"], "y", "{metrics}");
    let frame = std::fs::read_to_string(dir.join("frames").join("frame_00001.vtu")).unwrap();
    let field = frame.split("<FieldData>").nth(1).and_then(|f| f.split("</FieldData>").next()).unwrap_or("");
    assert!(field.contains("Name=\"up\"") && field.contains(">\n0 1 0\n<"), "{field}");
    let png = std::fs::read(dir.join("preview.png")).unwrap();
    // The PNG header's width and height (big-endian, after the IHDR tag).
    assert_eq!(
        (&png[12..16], &png[16..20], &png[20..24]),
        (&b"IHDR"[..], &640u32.to_be_bytes()[..], &480u32.to_be_bytes()[..])
    );
    std::fs::remove_dir_all(&dir).ok();
}
