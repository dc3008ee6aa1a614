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
    let cases: [(&[&str], &str); 9] = [
        (&["run", "kepler", "--frames", "0"], "--frames must be at least 1"),
        (&["run", "kepler", "--dt", "0"], "--dt must be a positive finite number, got 0"),
        (&["run", "kepler", "--dt", "-1e-3"], "got -0.001"),
        (&["run", "kepler", "--dt", "NaN"], "got NaN"),
        (&["run", "kepler", "--stride", "0"], "--stride must be at least 1"),
        (&["run", "kepler", "--preview-width", "8"], "--preview-width must lie in [16, 4096], got 8"),
        (&["run", "kepler", "--checkpoint-every", "0"], "--checkpoint-every must be at least 1"),
        (&["run", "warp-drive"], "warp-drive: no such scene file, and no built-in scene of that name"),
        (&["resume", "no-such-checkpoint.anim"], "no-such-checkpoint.anim"),
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
