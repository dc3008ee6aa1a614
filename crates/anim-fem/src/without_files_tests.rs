//! A build without feature `files` reads no mesh file: a scene file naming a Gmsh, TetGen or
//! OBJ body is refused at the field that names it, with the file and the
//! feature in the message, before any file is opened (the files named here do not exist).

use crate::bodies::{World, build};
use crate::body::{BodySpec, read_mesh};
use crate::error::FemError;
use crate::model::ElementOrder;
use std::path::Path;

fn body(value: serde_json::Value) -> BodySpec {
    serde_json::from_value(value).expect("a valid spec")
}

#[test]
fn mesh_files_are_refused_naming_the_file_and_the_feature() {
    let material = serde_json::json!({ "young": 1e5, "poisson": 0.3, "density": 1000.0 });
    for (spec, field, file) in [
        (serde_json::json!({ "mesh": "block.msh", "material": material }), "bodies[0].mesh", "block.msh"),
        (serde_json::json!({ "mesh": "block.node", "material": material }), "bodies[0].mesh", "block.node"),
        (
            serde_json::json!({ "mesh": "block.obj", "cell": 0.1, "material": material }),
            "bodies[0].mesh",
            "block.obj",
        ),
    ] {
        let e = build(&[body(spec)], &World::default(), ElementOrder::Linear, |p| p.to_path_buf())
            .expect_err("no mesh file is read");
        assert_eq!(e.field, field, "{e}");
        assert!(e.message.contains(file) && e.message.contains("`files` feature"), "{e}");
    }
    match read_mesh(Path::new("block.msh")) {
        Err(FemError::MeshInput(m)) => {
            assert!(m.contains("block.msh") && m.contains("`files` feature"), "{m}")
        }
        other => panic!("expected a refusal naming the feature, got {other:?}"),
    }
}
