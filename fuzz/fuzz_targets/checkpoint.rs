//! Checkpoints: any bytes are a checkpoint or a clear `IoError`; a parsed payload handed to a
//! runner's `restore` is accepted or refused, never a panic.
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let path = Path::new("fuzz.anim");
    let Ok((_, payload)) = anim_io::parse_checkpoint::<serde_json::Value>(data, path) else { return };
    for name in ["kepler", "rope", "panda", "twist"] {
        let Some(text) = anim_cli::scene::builtin(name) else { continue };
        let Ok(file) = anim_cli::scene::parse(text, Path::new(name)) else { continue };
        if let Ok(mut runner) = anim_cli::runner::build(&file.scene, Path::new(name), None)
            && runner.restore(payload.get("runner").unwrap_or(&payload)).is_ok()
        {
            let _ = runner.step(file.run.dt);
        }
    }
});
