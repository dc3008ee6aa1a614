//! glTF skins: any bytes (.gltf JSON or .glb) load into a character or a `LoadError`, never a
//! panic; a character that loads poses at t = 0.5 with LBS.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(scene) = anim_skin::scenes::from_gltf_slice(data, std::path::Path::new("fuzz.glb")) {
        let mut posed = scene.data();
        let _ = scene.pose(&mut posed, 0.5, anim_skin::SkinningMethod::Lbs);
    }
});
