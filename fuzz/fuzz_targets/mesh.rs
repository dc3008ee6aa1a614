//! Mesh readers (Gmsh 2.2/4.1, TetGen, OBJ): any text is a mesh or an `IoError`, never a panic.
#![no_main]

use anim_io::obj::Polygons;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    let _ = anim_io::gmsh::parse_gmsh(text, "fuzz.msh");
    let _ = anim_io::obj::parse_obj(text, "fuzz.obj", Polygons::Triangulate);
    // The first line that starts with `#ele` splits the input into a .node and an .ele text.
    let (node, ele) = text.split_once("#ele").unwrap_or((text, ""));
    let _ = anim_io::tetgen::parse_tetgen(node, "fuzz.node", ele, "fuzz.ele");
});
