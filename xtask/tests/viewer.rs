//! The browser viewer check (`cargo xtask viewer`): a cloth, a 3D MPM scene and a 2D grid
//! fluid opened in headless Chromium, their first and last frames not blank and different.
//! Skipped with a note where Chromium is absent, unless `ANIM_REQUIRE_CHROMIUM` is set.

use std::process::Command;

#[test]
fn the_viewer_draws_three_scenes_in_headless_chromium() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let out = std::env::temp_dir().join(format!("anim-viewer-check-{}", std::process::id()));
    let status = Command::new(env!("CARGO_BIN_EXE_xtask"))
        .args(["viewer", "--out"])
        .arg(&out)
        .current_dir(&root)
        .status()
        .unwrap_or_else(|e| panic!("running xtask viewer: {e}"));
    assert!(status.success(), "xtask viewer failed (its table above names the scene)");
    let _ = std::fs::remove_dir_all(&out);
}
