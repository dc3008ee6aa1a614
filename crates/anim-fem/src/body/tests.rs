//! One body from a mesh file: the placement against the formula, OBJ surfaces filled with
//! tetrahedra of the right volume, and every refusal naming its field and the file.

use super::*;
use crate::mesh::signed_volume6;

pub(crate) fn testdata() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../anim-io/testdata")
}

fn spec(value: serde_json::Value) -> BodySpec {
    serde_json::from_value(value).expect("a valid spec")
}

/// The Gmsh test cube with a material and the `extra` fields.
fn cube(extra: serde_json::Value) -> BodySpec {
    let mut value = serde_json::json!({
        "mesh": "cube_v41.msh",
        "material": { "young": 5e4, "poisson": 0.3, "density": 1000.0 },
    });
    value.as_object_mut().expect("object").extend(extra.as_object().expect("object").clone());
    spec(value)
}

/// A folder of this test process for `test`.
pub(crate) fn folder(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("anim-fem-body-{}-{test}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temporary folder");
    dir
}

/// A folder with a one-tetrahedron TetGen mesh, positive or inverted.
fn tetgen(test: &str, inverted: bool) -> PathBuf {
    let dir = folder(test);
    std::fs::write(dir.join("tet.node"), "4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n").expect("node");
    let ele = if inverted { "1 4 0\n1 1 3 2 4\n" } else { "1 4 0\n1 1 2 3 4\n" };
    std::fs::write(dir.join("tet.ele"), ele).expect("ele");
    dir
}

/// The OBJ text of the box `[0, size]^3` as 12 outward triangles (anim-core's `cuboid`: corner
/// `k` at the bits of `k`), without the triangles listed in `missing` (0-based).
pub(crate) fn cube_obj(size: f64, missing: &[usize]) -> String {
    let (p, t) = anim_core::surface::cuboid([0.0; 3], [size; 3]);
    let mut text: String = p.iter().map(|v| format!("v {} {} {}\n", v[0], v[1], v[2])).collect();
    for (_, f) in t.iter().enumerate().filter(|(k, _)| !missing.contains(k)) {
        text += &format!("f {} {} {}\n", f[0] + 1, f[1] + 1, f[2] + 1);
    }
    text
}

fn volume(mesh: &TetMesh) -> f64 {
    mesh.tets
        .iter()
        .map(|t| {
            let p = t.map(|v| mesh.positions[v]);
            signed_volume6(p[0], p[1], p[2], p[3]) / 6.0
        })
        .sum()
}

#[test]
fn the_placement_scales_then_rotates_then_translates() {
    let raw = anim_io::gmsh::read_gmsh(testdata().join("cube_v41.msh")).expect("reads").tet_mesh();
    let placed = cube(serde_json::json!({
        "scale": 2.0,
        "rotate": [0.0, 0.0, std::f64::consts::FRAC_PI_2],
        "translate": [1.0, 2.0, 3.0],
    }))
    .load(&testdata().join("cube_v41.msh"))
    .expect("loads");
    let positions = &placed.mesh.positions;
    assert_eq!(positions.len(), raw.positions.len());
    for (p, q) in raw.positions.iter().zip(positions) {
        // A quarter turn about z takes (x, y) to (-y, x).
        let want = [-2.0 * p[1] + 1.0, 2.0 * p[0] + 2.0, 2.0 * p[2] + 3.0];
        assert!((0..3).all(|k| (q[k] - want[k]).abs() < 1e-14), "{q:?} vs {want:?}");
    }
}

/// A closed OBJ cube of side 1 on a lattice of cell 0.25 is filled exactly: 6 x 4^3
/// tetrahedra of total volume 1, scaled by `scale^3`; the cell is in metres of the placed body.
#[test]
fn an_obj_cube_is_filled_with_tetrahedra_of_its_volume() {
    let dir = folder("obj-cube");
    std::fs::write(dir.join("cube.obj"), cube_obj(1.0, &[])).expect("obj");
    let body = |scale: f64| {
        cube(serde_json::json!({ "mesh": "cube.obj", "cell": 0.25 * scale, "scale": scale }))
            .load(&dir.join("cube.obj"))
            .expect("loads")
    };
    let unit = body(1.0);
    assert_eq!(unit.mesh.tets.len(), 6 * 4 * 4 * 4);
    assert!((volume(&unit.mesh) - 1.0).abs() < 1e-12, "{}", volume(&unit.mesh));
    let half = body(0.5);
    assert_eq!(half.mesh.tets.len(), 6 * 4 * 4 * 4);
    assert!((volume(&half.mesh) - 0.125).abs() < 1e-12, "{}", volume(&half.mesh));
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn refusals_name_the_field_and_the_file() {
    let cube_file = testdata().join("cube_v41.msh");
    let refuse = |body: BodySpec, file: &Path| body.load(file).expect_err("refused");
    let e = refuse(cube(serde_json::json!({})), Path::new("/nowhere/body.msh"));
    assert_eq!(e.field, "mesh");
    assert!(e.message.contains("/nowhere/body.msh"), "{e}");
    let e = refuse(cube(serde_json::json!({})), Path::new("body.stl"));
    assert_eq!(e.field, "mesh");
    assert!(e.message.contains("body.stl") && e.message.contains("unknown mesh format"), "{e}");
    let dir = tetgen("inverted", true);
    let e = refuse(cube(serde_json::json!({})), &dir.join("tet.ele"));
    assert_eq!(e.field, "mesh");
    assert!(e.message.contains("tet.ele") && e.message.contains("element 0"), "{e}");
    let e = refuse(cube(serde_json::json!({ "scale": 0.0 })), &cube_file);
    assert_eq!(e.field, "scale");
    let mut turned = cube(serde_json::json!({}));
    turned.rotate = [0.0, f64::NAN, 0.0];
    assert_eq!(refuse(turned, &cube_file).field, "rotate");
    let e = refuse(
        cube(serde_json::json!({ "material": { "young": 1e4, "poisson": 0.5, "density": 1.0 } })),
        &cube_file,
    );
    assert_eq!(e.field, "material");
    let mut thrown = cube(serde_json::json!({}));
    thrown.velocity = [0.0, f64::INFINITY, 0.0];
    assert_eq!(refuse(thrown, &cube_file).field, "velocity");
    let mut pinned =
        cube(serde_json::json!({ "pin": { "box": { "min": [0.0, 0.0, 0.0], "max": [1.0, 1.0, 1.0] } } }));
    if let Some(region) = pinned.pin.as_mut().and_then(|p| p.region.as_mut()) {
        region.max[2] = f64::NAN;
    }
    assert_eq!(refuse(pinned, &cube_file).field, "pin.box");
    // `cell` is for surfaces only.
    let e = refuse(cube(serde_json::json!({ "cell": 0.1 })), &cube_file);
    assert_eq!(e.field, "cell");
    assert!(e.message.contains("cube_v41.msh") && e.message.contains("OBJ"), "{e}");
    let _ = std::fs::remove_dir_all(dir);
}

/// An OBJ surface needs a positive `cell` that leaves a tetrahedron inside; an open surface is
/// refused naming the file and an edge without a neighbour.
#[test]
fn obj_refusals_name_the_cell_or_the_file_and_the_edge() {
    let dir = folder("obj-refusals");
    std::fs::write(dir.join("cube.obj"), cube_obj(1.0, &[])).expect("obj");
    std::fs::write(dir.join("holed.obj"), cube_obj(1.0, &[5])).expect("obj");
    let load = |file: &str, cell: Option<f64>| {
        let mut extra = serde_json::json!({ "mesh": file });
        if let Some(cell) = cell {
            extra["cell"] = serde_json::json!(cell);
        }
        cube(extra).load(&dir.join(file)).expect_err("refused")
    };
    let e = load("cube.obj", None);
    assert_eq!(e.field, "cell");
    assert!(e.message.contains("cube.obj") && e.message.contains("give `cell`"), "{e}");
    for bad in [0.0, -0.1] {
        assert_eq!(load("cube.obj", Some(bad)).field, "cell");
    }
    let e = load("cube.obj", Some(10.0));
    assert_eq!(e.field, "cell");
    assert!(e.message.contains("cube.obj") && e.message.contains("too coarse"), "{e}");
    let e = load("holed.obj", Some(0.25));
    assert_eq!(e.field, "mesh");
    assert!(e.message.contains("holed.obj") && e.message.contains("not closed"), "{e}");
    assert!(e.message.contains("edge (") && e.message.contains("numbered from 0"), "{e}");
    let _ = std::fs::remove_dir_all(dir);
}

/// `cell` is the edge in metres of the placed body, as in every kind: a body scaled by 2 with cell
/// `c` is filled with the tetrahedra of the unscaled asset with cell `c / 2` (the same elements,
/// the positions doubled). The example's blob, scaled by 1.4, gives at `cell = 0.049` the 1,209
/// tetrahedra that an independent re-implementation of the fill counts in its file at 0.035.
#[test]
fn the_cell_is_in_metres_of_the_placed_body() {
    let dir = folder("obj-cell-metres");
    std::fs::write(dir.join("cube.obj"), cube_obj(1.0, &[])).expect("obj");
    let cube_body = |cell: f64, scale: f64| {
        cube(serde_json::json!({ "mesh": "cube.obj", "cell": cell, "scale": scale }))
            .load(&dir.join("cube.obj"))
            .expect("loads")
            .mesh
    };
    let (unscaled, scaled) = (cube_body(0.125, 1.0), cube_body(0.25, 2.0));
    assert_eq!(unscaled.tets.len(), 6 * 8 * 8 * 8);
    assert_eq!(scaled.tets, unscaled.tets);
    for (p, q) in scaled.positions.iter().zip(&unscaled.positions) {
        assert!((0..3).all(|k| (p[k] - 2.0 * q[k]).abs() < 1e-15), "{p:?} vs 2 x {q:?}");
    }
    let assets = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/scenes/assets");
    let blob = |cell: f64, scale: f64| {
        cube(serde_json::json!({ "mesh": "blob.obj", "cell": cell, "scale": scale }))
            .load(&assets.join("blob.obj"))
            .expect("loads")
            .mesh
            .tets
            .len()
    };
    assert_eq!((blob(0.035, 1.0), blob(0.049, 1.4)), (1209, 1209));
    let _ = std::fs::remove_dir_all(dir);
}

/// The unit cube at `cell = 0.0084` would lay 120^3 lattice cubes, up to 10,368,000 tetrahedra
/// (18 GB of element buffers alone, some 300 GB with the Cholesky factor): refused at once,
/// before the fill, naming `cell`, the counts, the estimate and the memory checked against.
#[test]
fn a_cell_too_fine_for_the_memory_is_refused_before_the_fill() {
    let dir = folder("obj-too-fine");
    std::fs::write(dir.join("cube.obj"), cube_obj(1.0, &[])).expect("obj");
    let gib = 1024.0 * 1024.0 * 1024.0;
    let budget = |available: f64| Budget {
        available: Some(available),
        ..Budget::new(ElementOrder::Linear, TimeIntegrator::BackwardEuler, LinearSolverChoice::Cholesky)
    };
    let start = std::time::Instant::now();
    let spec = cube(serde_json::json!({ "mesh": "cube.obj", "cell": 0.0084 }));
    let e = spec.load_within(&dir.join("cube.obj"), &budget(64.0 * gib)).expect_err("refused");
    assert!(start.elapsed().as_secs_f64() < 20.0, "refused after {:?}", start.elapsed());
    assert_eq!(e.field, "cell");
    for part in ["cube.obj", "120 x 120 x 120", "10368000 tetrahedra", "needs about", "64.0 GiB available"] {
        assert!(e.message.contains(part), "{part}: {e}");
    }
    assert!(e.message.ends_with(": take a larger cell"), "{e}");
    let (bytes, available) = e.memory.expect("a refusal of memory");
    let elements = 10_368_000.0 * 1752.0;
    assert!(bytes > elements && available == 64.0 * gib, "{bytes}");
    // The same surface at a coarser cell fits, and the public `load` checks the machine's memory.
    assert!(
        cube(serde_json::json!({ "mesh": "cube.obj", "cell": 0.25 }))
            .load_within(&dir.join("cube.obj"), &budget(gib))
            .is_ok()
    );
    let e = cube(serde_json::json!({ "mesh": "cube.obj", "cell": 1e-5 }))
        .load(&dir.join("cube.obj"))
        .expect_err("refused");
    assert_eq!(e.field, "cell");
    assert!(e.memory.is_some(), "{e}");
    let _ = std::fs::remove_dir_all(dir);
}

/// `pin` is anim-core's `PinSpec`, as in pbd and springs: `vertices` index the mesh file's
/// vertices and are checked against it, refused for an OBJ surface; the box must have finite
/// corners in order; an empty table and the old `{ min, max }` spelling are refused.
#[test]
fn pin_refusals_name_the_field_and_the_cause() {
    let dir = folder("pin-refusals");
    std::fs::write(dir.join("cube.obj"), cube_obj(1.0, &[])).expect("obj");
    let cube_file = testdata().join("cube_v41.msh");
    // The field at fault, and the message.
    let refuse = |pin: serde_json::Value, file: &Path| {
        let mut extra = serde_json::json!({ "pin": pin });
        if file.extension().is_some_and(|e| e == "obj") {
            extra["mesh"] = "cube.obj".into();
            extra["cell"] = 0.5.into();
        }
        let e = cube(extra).load(file).expect_err("refused");
        (e.field, e.message)
    };
    let (f, m) = refuse(serde_json::json!({ "vertices": [0, 8] }), &cube_file);
    assert_eq!(f, "pin.vertices[1]");
    assert_eq!(m, format!("vertex 8 is out of range: {} has 8 vertices (0 to 7)", cube_file.display()));
    let (f, m) = refuse(serde_json::json!({ "vertices": [0] }), &dir.join("cube.obj"));
    assert_eq!(f, "pin");
    assert!(m.contains("cube.obj") && m.contains("pin them with a `box`"), "{m}");
    let (f, m) =
        refuse(serde_json::json!({ "box": { "min": [0.0, 1.0, 0.0], "max": [1.0, 0.0, 1.0] } }), &cube_file);
    assert_eq!(f, "pin.box");
    assert!(m.starts_with("the box needs finite corners with min <= max"), "{m}");
    // An empty table: the table, with the message every kind gives.
    assert_eq!(
        refuse(serde_json::json!({}), &cube_file),
        ("pin".into(), "give `vertices`, `box` or both".into())
    );
    // A vertex in no tetrahedron: a fifth, unused vertex in a TetGen mesh.
    std::fs::write(dir.join("tet.node"), "5 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n5 2 2 2\n")
        .expect("node");
    std::fs::write(dir.join("tet.ele"), "1 4 0\n1 1 2 3 4\n").expect("ele");
    let (f, m) = refuse(serde_json::json!({ "vertices": [4] }), &dir.join("tet.node"));
    assert_eq!(f, "pin");
    assert!(m.contains("vertex 4 of") && m.contains("tet.node") && m.contains("no tetrahedron"), "{m}");
    // The box alone, as fem spelled it before: an unknown field.
    let old = serde_json::json!({
        "mesh": "cube_v41.msh", "material": { "young": 5e4, "poisson": 0.3, "density": 1000.0 },
        "pin": { "min": [0.0, 0.0, 0.0], "max": [1.0, 1.0, 1.0] },
    });
    let e = serde_json::from_value::<BodySpec>(old).expect_err("refused").to_string();
    assert!(e.contains("unknown field `min`") && e.contains("pin = { box = { min = [...]"), "{e}");
    let typo = serde_json::json!({
        "mesh": "cube_v41.msh", "material": { "young": 5e4, "poisson": 0.3, "density": 1000.0 },
        "pin": { "vertex": [0] },
    });
    let e = serde_json::from_value::<BodySpec>(typo).expect_err("refused").to_string();
    assert!(e.contains("unknown field `vertex`, expected `vertices` or `box`"), "{e}");
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn a_one_tetrahedron_tetgen_body_loads_from_either_file() {
    let dir = tetgen("either", false);
    for file in ["tet.node", "tet.ele"] {
        let body = cube(serde_json::json!({})).load(&dir.join(file)).expect("loads");
        assert_eq!((body.mesh.positions.len(), body.mesh.tets.len()), (4, 1));
    }
    let _ = std::fs::remove_dir_all(dir);
}
