//! Scene files: any text either parses into a scene that its registered kind builds (or is
//! refused with a `SceneError`), never a panic.
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    let path = Path::new("fuzz.toml");
    if let Ok(file) = anim_cli::scene::parse(text, path)
        && let Ok(mut scene) = anim_cli::scene::build(&file, path, Some(text))
    {
        // One step with the scene's own dt: a scene that builds must step or return an error.
        let _ = scene.step(file.run.dt);
    }
});
