//! URDF: any text is a model or a `UrdfError`, never a panic.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    let _ = anim_rigid::parse_urdf(text, &anim_rigid::UrdfOptions::default());
});
