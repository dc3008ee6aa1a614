//! `anim run --checkpoint-every` and `anim resume`: the frames after a resume are those of an
//! uninterrupted run, bit for bit (CSV rows print every value in its shortest round-trip form,
//! so equal text is equal bits); damaged checkpoints are clear errors.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::{Path, PathBuf};
use std::process::Command;

fn anim(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_anim")).args(args).output().expect("the anim binary runs")
}

fn temp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("anim-cli-resume-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

fn csv_rows(dir: &Path) -> Vec<String> {
    std::fs::read_to_string(dir.join("frames.csv")).unwrap().lines().map(str::to_string).collect()
}

#[test]
fn a_resumed_run_writes_the_frames_of_an_uninterrupted_one() {
    for scene in ["kepler", "oscillator"] {
        let whole = temp(&format!("{scene}-whole"));
        let parts = temp(&format!("{scene}-parts"));
        let w = whole.to_str().unwrap();
        let p = parts.to_str().unwrap();
        let out = anim(&["run", scene, "--frames", "40", "--out", w, "--no-preview", "--quiet"]);
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        // The first part checkpoints at frame 25, then dies (simulated by stopping at 30 and
        // resuming from the checkpoint, which is at 25: frames 25..30 are written again).
        let out = anim(&[
            "run",
            scene,
            "--frames",
            "30",
            "--out",
            p,
            "--no-preview",
            "--quiet",
            "--checkpoint-every",
            "25",
        ]);
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let ckpt = parts.join("checkpoint.anim");
        assert!(ckpt.exists());
        // Keep the rows up to the checkpoint, as a crash right after it would have left them.
        let rows = csv_rows(&parts);
        std::fs::write(parts.join("frames.csv"), rows[..26].join("\n") + "\n").unwrap();
        let out = anim(&["resume", ckpt.to_str().unwrap(), "--frames", "40", "--quiet"]);
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        assert_eq!(csv_rows(&whole), csv_rows(&parts), "{scene}");
        let metrics = std::fs::read_to_string(parts.join("metrics.json")).unwrap();
        assert!(metrics.contains("\"resumed_from_frame\": 25"), "{metrics}");
        std::fs::remove_dir_all(&whole).ok();
        std::fs::remove_dir_all(&parts).ok();
    }
}

#[test]
fn mesh_frames_continue_their_numbering_and_series() {
    let dir = temp("cloth");
    let d = dir.to_str().unwrap();
    let out = anim(&[
        "run",
        "rope",
        "--frames",
        "4",
        "--out",
        d,
        "--no-preview",
        "--quiet",
        "--checkpoint-every",
        "2",
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let ckpt = dir.join("checkpoint.anim");
    let out = anim(&["resume", ckpt.to_str().unwrap(), "--frames", "6", "--quiet"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let pvd = std::fs::read_to_string(dir.join("frames/frames.pvd")).unwrap();
    // Frames 0 and 1 from the first part, 2..5 from the resumed one (2 and 3 rewritten).
    for k in 0..6 {
        assert!(pvd.contains(&format!("frame_{k:05}.vtu")), "frame {k} missing from {pvd}");
    }
    assert!(!pvd.contains("frame_00006.vtu"), "{pvd}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn damaged_or_foreign_checkpoints_are_clear_errors() {
    let dir = temp("damaged");
    let d = dir.to_str().unwrap();
    let out = anim(&[
        "run",
        "kepler",
        "--frames",
        "4",
        "--out",
        d,
        "--no-preview",
        "--quiet",
        "--checkpoint-every",
        "2",
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let ckpt = dir.join("checkpoint.anim");
    let good = std::fs::read(&ckpt).unwrap();
    let cases: [(&str, Vec<u8>, &str); 3] = [
        ("truncated", good[..good.len() / 2].to_vec(), "truncated"),
        (
            "wrong version",
            String::from_utf8(good.clone())
                .unwrap()
                .replacen("\"version\":1", "\"version\":9", 1)
                .into_bytes(),
            "version 9",
        ),
        ("not a checkpoint", b"name = \"kepler\"\n".to_vec(), "not an anim checkpoint"),
    ];
    for (what, bytes, expect) in cases {
        let path = dir.join(format!("{}.anim", what.replace(' ', "-")));
        std::fs::write(&path, bytes).unwrap();
        let out = anim(&["resume", path.to_str().unwrap(), "--quiet"]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{what}");
        assert!(
            err.contains(expect) && err.contains(path.file_name().unwrap().to_str().unwrap()),
            "{what}: {err}"
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// Ctrl-C ends a run cleanly: the frame being stepped is finished, the folder completed (every
/// file the `.pvd` lists exists, the preview and metrics with status "interrupted" are
/// written, and a checkpoint since `--checkpoint-every` was given), the exit status is 130, and
/// the checkpoint resumes.
#[cfg(unix)]
#[test]
fn an_interrupted_run_finishes_its_folder_and_resumes() {
    let dir = std::env::temp_dir().join(format!("anim-cli-interrupt-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    // Wait for a few frames, then interrupt.
    let child = spawn_until_frames(
        &["run", "cloth", "--frames", "1000000", "--checkpoint-every", "1000000"],
        &dir,
        3,
    );
    let pvd_dir = dir.join("frames");
    interrupt(&child);
    let out = child.wait_with_output().expect("the run ends");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(130), "{stderr}");
    assert!(stderr.contains("interrupted after frame"), "{stderr}");
    let metrics: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("metrics.json")).unwrap()).unwrap();
    assert_eq!(metrics["status"], "interrupted");
    let pvd = std::fs::read_to_string(pvd_dir.join("frames.pvd")).unwrap();
    let listed: Vec<&str> = pvd.split("file=\"").skip(1).filter_map(|s| s.split('"').next()).collect();
    assert!(listed.len() >= 3, "{pvd}");
    assert!(listed.iter().all(|f| pvd_dir.join(f).is_file()), "{listed:?}");
    assert!(dir.join("preview.png").is_file() && dir.join("checkpoint.anim").is_file());
    // The browser viewer lists the same frames, every one present.
    let shown = viewer_frames(&dir);
    assert_eq!(shown.len(), listed.len(), "{shown:?}");
    assert!(dir.join("viewer.html").is_file());
    // The checkpoint is at the last frame written: resuming for two more frames adds two files.
    let resumed = std::process::Command::new(env!("CARGO_BIN_EXE_anim"))
        .arg("resume")
        .arg(dir.join("checkpoint.anim"))
        .args(["--frames", &(listed.len() + 2).to_string(), "--quiet"])
        .output()
        .expect("resume runs");
    assert!(resumed.status.success(), "{}", String::from_utf8_lossy(&resumed.stderr));
    let pvd = std::fs::read_to_string(pvd_dir.join("frames.pvd")).unwrap();
    assert_eq!(pvd.matches("file=\"").count(), listed.len() + 2, "{pvd}");
    assert_eq!(viewer_frames(&dir).len(), listed.len() + 2);
    std::fs::remove_dir_all(&dir).ok();
}

/// `timeout -s INT 3 anim run mpm` delivers SIGINT twice at once (to the process, then to its
/// process group), and a loaded machine may handle the two apart: that is one interrupt, not the
/// second Ctrl-C that quits at once. Two signals 20 ms apart finish the folder: metrics with
/// status "interrupted", a `.pvd` whose every listed file exists, exit status 130.
#[cfg(unix)]
#[test]
fn an_interrupt_delivered_twice_at_once_still_finishes_the_folder() {
    let dir = std::env::temp_dir().join(format!("anim-cli-twice-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let child = spawn_until_frames(&["run", "mpm", "--no-viewer"], &dir, 2);
    let pvd_dir = dir.join("frames");
    for _ in 0..2 {
        interrupt(&child);
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    let out = child.wait_with_output().expect("the run ends");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(130), "{stderr}");
    assert!(stderr.contains("interrupted after frame"), "{stderr}");
    let metrics: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("metrics.json")).expect("metrics.json"))
            .unwrap();
    assert_eq!(metrics["status"], "interrupted");
    let pvd = std::fs::read_to_string(pvd_dir.join("frames.pvd")).expect("frames.pvd");
    let listed: Vec<&str> = pvd.split("file=\"").skip(1).filter_map(|s| s.split('"').next()).collect();
    assert!(!listed.is_empty() && listed.iter().all(|f| pvd_dir.join(f).is_file()), "{listed:?}");
    std::fs::remove_dir_all(&dir).ok();
}

/// `anim ARGS --quiet --out DIR`, started and left running once `DIR/frames` holds `frames`
/// files (two minutes at most).
#[cfg(unix)]
fn spawn_until_frames(args: &[&str], dir: &Path, frames: usize) -> std::process::Child {
    let child = std::process::Command::new(env!("CARGO_BIN_EXE_anim"))
        .args(args)
        .args(["--quiet", "--out"])
        .arg(dir)
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("the anim binary runs");
    let start = std::time::Instant::now();
    while std::fs::read_dir(dir.join("frames")).map_or(0, |d| d.count()) < frames {
        assert!(start.elapsed().as_secs() < 120, "no frames written");
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    child
}

/// Sends SIGINT to `child`.
#[cfg(unix)]
fn interrupt(child: &std::process::Child) {
    let kill = std::process::Command::new("kill").args(["-INT", &child.id().to_string()]).status();
    assert!(kill.is_ok_and(|s| s.success()));
}

/// The frame files `viewer/index.js` lists, after checking each is present.
fn viewer_frames(dir: &Path) -> Vec<String> {
    let text = std::fs::read_to_string(dir.join("viewer/index.js")).unwrap();
    let json = text.trim().strip_prefix("ANIM.index(").and_then(|t| t.strip_suffix(");")).unwrap();
    let index: serde_json::Value = serde_json::from_str(json).unwrap();
    let files: Vec<String> =
        index["frames"].as_array().unwrap().iter().map(|f| f[1].as_str().unwrap().to_string()).collect();
    assert!(files.iter().all(|f| dir.join("viewer").join(f).is_file()), "{files:?}");
    files
}
