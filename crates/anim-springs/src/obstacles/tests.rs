//! A scene file's `obstacle_meshes`: a cloth rests on a mesh block as on the same `box` obstacle,
//! and refusals name the kind's field and the file.

use anim_core::scene::{BuildContext, BuildError, Frame};

/// A folder of this test's own under the system's temporary folder.
fn folder(test: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("anim-springs-obstacles-{}-{test}", std::process::id()));
    std::fs::remove_dir_all(&dir).ok();
    std::fs::create_dir_all(&dir).expect("temporary folder");
    dir
}

/// The unit cube `[0, 1]^3` as 12 outward triangles (anim-core's `cuboid`), without the
/// triangles in `missing`.
fn cube_obj(missing: &[usize]) -> String {
    let (p, t) = anim_core::surface::cuboid([0.0; 3], [1.0; 3]);
    let mut text: String = p.iter().map(|v| format!("v {} {} {}\n", v[0], v[1], v[2])).collect();
    for (_, f) in t.iter().enumerate().filter(|(k, _)| !missing.contains(k)) {
        text += &format!("f {} {} {}\n", f[0] + 1, f[1] + 1, f[2] + 1);
    }
    text
}

/// A flat 5 x 5 cloth of 0.4 m at z = 0.
fn cloth_obj() -> String {
    let mut s = String::new();
    for iy in 0..5 {
        for ix in 0..5 {
            s += &format!("v {} {} 0\n", 0.1 * ix as f64, 0.1 * iy as f64);
        }
    }
    for iy in 0..4 {
        for ix in 0..4 {
            let a = iy * 5 + ix + 1;
            s += &format!("f {} {} {}\nf {} {} {}\n", a, a + 1, a + 6, a, a + 6, a + 5);
        }
    }
    s
}

fn field_of(e: BuildError) -> (String, String) {
    match e {
        BuildError::Invalid { field, message } | BuildError::Schema { field, message } => (field, message),
        other => panic!("unexpected {other}"),
    }
}

#[test]
fn a_cloth_rests_on_a_mesh_block_and_refusals_name_the_field_and_the_file() {
    let dir = folder("kind");
    std::fs::write(dir.join("block.obj"), cube_obj(&[])).expect("obj");
    std::fs::write(dir.join("holed.obj"), cube_obj(&[7])).expect("obj");
    std::fs::write(dir.join("cloth.obj"), cloth_obj()).expect("cloth");
    let build = |value: serde_json::Value| (crate::KIND.build)(&value, &BuildContext { base: Some(&dir) });
    let refused = |value: serde_json::Value| field_of(build(value).err().expect("refused"));
    let cloth = serde_json::json!({
        "mesh": "cloth.obj",
        "material": { "density": 0.2, "stiffness": 200.0 },
        "translate": [-0.2, -0.2, 0.52],
    });
    // The unit block scaled to 1 m about its corner, moved to [-0.5, 0.5]^2 x [-0.5, 0.5]: its
    // top at z = 0.5 under the whole cloth.
    let block = serde_json::json!({ "mesh": "block.obj", "translate": [-0.5, -0.5, -0.5], "cell": 0.05 });
    let with = |key: &str, value: serde_json::Value| {
        let mut b = block.clone();
        b[key] = value;
        b
    };
    let contact = serde_json::json!({ "stiffness": 1e3, "thickness": 0.01 });
    let scene = |meshes: serde_json::Value| serde_json::json!({ "bodies": [cloth], "obstacle_meshes": meshes, "contact": contact });
    // The picture draws the block's twelve triangles where it is placed, its height (z in the
    // scene file) along y in the picture.
    let drawn = build(scene(serde_json::json!([block]))).expect("builds").context().mesh_props;
    assert!(drawn.len() == 1 && drawn[0].triangles.len() == 12, "{drawn:?}");
    let lowest = drawn[0].positions.iter().map(|p| p[1]).fold(f64::INFINITY, f64::min);
    assert_eq!(lowest, block["translate"][2].as_f64().unwrap());
    let rest = |params: serde_json::Value| {
        let mut s = build(params).expect("builds");
        for _ in 0..100 {
            s.step(0.005).expect("steps");
        }
        let mut frame = Frame::default();
        s.frame(&mut frame);
        frame.points
    };
    let on_mesh = rest(scene(serde_json::json!([block])));
    let boxed =
        serde_json::json!([{ "box": { "center": [0.0, 0.0, 0.0], "half_extents": [0.5, 0.5, 0.5] } }]);
    let on_box = rest(serde_json::json!({ "bodies": [cloth], "obstacles": boxed, "contact": contact }));
    // Resting on the top, held 1 cm off it (the frames' y is the scene's z).
    assert!(on_mesh.chunks(3).all(|p| (p[1] - 0.51).abs() < 2e-3), "{on_mesh:?}");
    // The top face is flat: the field is exact there, to the f32 of its nodes.
    let apart = on_mesh.iter().zip(&on_box).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    assert!(apart < 1e-6, "{apart}");

    // The file's refusals are anim-io's `read_closed_surface`'s and the cell's anim-core's
    // `ObstacleMesh::field`'s, tested there: here, that they name the kind's field and the file.
    let (f, m) = refused(scene(serde_json::json!([block, with("mesh", "holed.obj".into())])));
    assert_eq!(f, "obstacle_meshes[1].mesh");
    assert!(m.contains("holed.obj") && m.contains("edge ("), "{m}");
    let (f, m) = refused(scene(serde_json::json!([with("cell", 0.0.into())])));
    assert_eq!(f, "obstacle_meshes[0].cell");
    assert!(m.contains("block.obj") && m.contains("positive"), "{m}");
    let (f, _) = refused(scene(serde_json::json!([with("scale", (-1.0).into())])));
    assert_eq!(f, "obstacle_meshes[0].scale");
    let (f, m) = refused(serde_json::json!({ "preset": "hanging-cloth", "obstacle_meshes": [block] }));
    assert_eq!(f, "obstacle_meshes");
    assert!(m.contains("bodies"), "{m}");
}
