//! `anim run NAME --resolution 1000000000` on every registered preset (`anim::CRATES`): a
//! preset with a resolution is refused for its memory, naming the field, the estimate and the
//! memory available, within 5 s and with nothing written (the estimate comes from the
//! parameters, before anything is allocated); a preset without one says it has none.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::process::Command;
use std::time::{Duration, Instant};

/// The crates whose presets have no resolution: rigid bodies, skinning, anim-core's systems.
const WITHOUT_RESOLUTION: [&str; 3] = ["anim-rigid", "anim-skin", "anim-core"];

#[test]
fn a_resolution_of_a_billion_is_refused_for_its_memory_on_every_preset() {
    let dir = std::env::temp_dir().join(format!("anim-cli-memory-{}", std::process::id()));
    let out = dir.to_str().unwrap();
    let mut refused = 0;
    for member in anim::CRATES {
        for kind in member.kinds {
            for preset in (kind.presets)() {
                let name = preset.name;
                let start = Instant::now();
                let run = Command::new(env!("CARGO_BIN_EXE_anim"))
                    .args([
                        "run",
                        name,
                        "--resolution",
                        "1000000000",
                        "--out",
                        out,
                        "--quiet",
                        "--no-preview",
                    ])
                    .output()
                    .expect("the anim binary runs");
                let took = start.elapsed();
                let err = String::from_utf8_lossy(&run.stderr);
                let first = err.lines().next().unwrap_or_default();
                assert_eq!(run.status.code(), Some(1), "{name}: {err}");
                assert!(took < Duration::from_secs(5), "{name}: refused after {took:?}");
                if WITHOUT_RESOLUTION.contains(&member.name) {
                    let expect =
                        format!("error: --resolution 1000000000: a {} scene has no resolution", kind.kind);
                    assert_eq!(first, expect, "{name}");
                    continue;
                }
                let expect = format!(
                    "error: --resolution 1000000000: <built-in scene {name}>: field `scene.resolution`: 1000000000 "
                );
                assert!(first.starts_with(&expect), "{name}: {first}");
                assert!(first.contains(" needs about ") && first.ends_with(" available"), "{name}: {first}");
                refused += 1;
            }
        }
    }
    // cloth, rope, jelly; drape, flag, blob, pbd-rope, pbd-cloth; beam, cube, twisted-bar; four
    // MPM presets; three grid fluids; five FLIP presets.
    assert_eq!(refused, 23);
    assert!(!dir.exists(), "a refused run wrote {}", dir.display());
}
