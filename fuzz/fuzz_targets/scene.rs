//! Scene files: any text either parses into a scene whose runner builds (or is refused with a
//! `SceneError`), never a panic.
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    let path = Path::new("fuzz.toml");
    if let Ok(file) = anim_cli::scene::parse(text, path)
        && let Ok(mut runner) = anim_cli::runner::build(&file.scene, path, None)
    {
        // One step with the scene's own dt: a scene that builds must step or return an error.
        let _ = runner.step(file.run.dt);
    }
});
