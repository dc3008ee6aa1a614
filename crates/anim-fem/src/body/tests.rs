//! Bodies from mesh files: the placement against the formula, free fall against the exact
//! momentum balance, pins held, and every refusal naming its field and the file.

use super::*;
use crate::kind::KIND;
use anim_core::scene::{BuildContext, BuildError};
use anim_core::solver::Solver;

fn testdata() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../anim-io/testdata")
}

fn spec(value: serde_json::Value) -> BodySpec {
    serde_json::from_value(value).expect("a valid spec")
}

fn cube(extra: serde_json::Value) -> BodySpec {
    let mut value = serde_json::json!({
        "mesh": "cube_v41.msh",
        "material": { "young": 5e4, "poisson": 0.3, "density": 1000.0 },
    });
    value.as_object_mut().expect("object").extend(extra.as_object().expect("object").clone());
    spec(value)
}

/// A folder of this test process with a one-tetrahedron TetGen mesh, positive or inverted.
fn tetgen(test: &str, inverted: bool) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("anim-fem-body-{}-{test}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temporary folder");
    std::fs::write(dir.join("tet.node"), "4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n").expect("node");
    let ele = if inverted { "1 4 0\n1 1 3 2 4\n" } else { "1 4 0\n1 1 2 3 4\n" };
    std::fs::write(dir.join("tet.ele"), ele).expect("ele");
    dir
}

#[test]
fn the_placement_scales_then_rotates_then_translates() {
    let raw = anim_io::gmsh::read_gmsh(testdata().join("cube_v41.msh")).expect("reads").tet_mesh();
    let placed = cube(serde_json::json!({
        "scale": 2.0,
        "rotate": [0.0, 0.0, std::f64::consts::FRAC_PI_2],
        "translate": [1.0, 2.0, 3.0],
    }))
    .build(&testdata().join("cube_v41.msh"), ElementOrder::Linear)
    .expect("builds");
    let positions = &placed.model.mesh().positions;
    assert_eq!(positions.len(), raw.positions.len());
    for (p, q) in raw.positions.iter().zip(positions) {
        // A quarter turn about z takes (x, y) to (-y, x).
        let want = [-2.0 * p[1] + 1.0, 2.0 * p[0] + 2.0, 2.0 * p[2] + 3.0];
        assert!((0..3).all(|k| (q[k] - want[k]).abs() < 1e-14), "{q:?} vs {want:?}");
    }
}

#[test]
fn a_falling_body_keeps_the_exact_momentum_balance() {
    // The internal forces sum to zero, so backward Euler moves the centre of mass exactly as
    // V_n = V_0 + n h g and X_n = X_0 + n h V_0 + h^2 g n (n + 1) / 2.
    let v0 = [0.5, -0.25, 1.0];
    let body = cube(serde_json::json!({ "velocity": v0 }));
    let scene = body.build(&testdata().join("cube_v41.msh"), ElementOrder::Linear).expect("builds");
    let mass = scene.model.lumped_mass().to_vec();
    let (mut sim, mut state) = scene.into_simulation().expect("simulation");
    let com = |x: &[f64]| {
        let total: f64 = mass.iter().sum();
        let mut c = [0.0; 3];
        for (i, m) in mass.iter().enumerate() {
            for k in 0..3 {
                c[k] += m * x[3 * i + k] / total;
            }
        }
        c
    };
    let x0 = com(&state.x);
    let (h, n) = (0.01, 50);
    for _ in 0..n {
        sim.step(&mut state, h).expect("step");
    }
    let g = EARTH_GRAVITY;
    let nf = n as f64;
    let x = com(&state.x);
    for k in 0..3 {
        let want = x0[k] + nf * h * v0[k] + h * h * g[k] * nf * (nf + 1.0) / 2.0;
        assert!((x[k] - want).abs() < 1e-9, "axis {k}: {} vs {want}", x[k]);
    }
}

#[test]
fn pinned_vertices_stay_where_they_were_placed() {
    let body = cube(serde_json::json!({
        "translate": [0.0, 0.0, 1.0],
        "pin": { "min": [-1.0, -1.0, 1.3], "max": [1.0, 1.0, 1.34] },
    }));
    let scene = body.build(&testdata().join("cube_v41.msh"), ElementOrder::Linear).expect("builds");
    let x0 = scene.state.x.clone();
    let bottom: Vec<usize> = (0..x0.len() / 3).filter(|&i| x0[3 * i + 2] < 1.34).collect();
    assert_eq!(bottom.len(), 4, "the cube's four lower corners");
    let (mut sim, mut state) = scene.into_simulation().expect("simulation");
    for _ in 0..20 {
        sim.step(&mut state, 0.01).expect("step");
    }
    for i in bottom {
        assert_eq!(&state.x[3 * i..3 * i + 3], &x0[3 * i..3 * i + 3], "vertex {i} moved");
    }
    // The free (upper) corners sag under gravity.
    for i in (0..x0.len() / 3).filter(|&i| x0[3 * i + 2] > 1.4) {
        assert!(state.x[3 * i + 2] < x0[3 * i + 2] - 1e-4, "vertex {i} did not sag");
    }
}

#[test]
fn refusals_name_the_field_and_the_file() {
    let cube_file = testdata().join("cube_v41.msh");
    let refuse = |body: BodySpec, file: &Path| body.build(file, ElementOrder::Linear).expect_err("refused");
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
    let e = refuse(
        cube(serde_json::json!({ "material": { "young": 1e4, "poisson": 0.5, "density": 1.0 } })),
        &cube_file,
    );
    assert_eq!(e.field, "material");
    let e = refuse(
        cube(serde_json::json!({ "pin": { "min": [5.0, 5.0, 5.0], "max": [6.0, 6.0, 6.0] } })),
        &cube_file,
    );
    assert_eq!(e.field, "pin");
    let boxed = serde_json::json!({ "obstacles": [
        { "plane": { "point": [0.0, 0.0, 0.0], "normal": [0.0, 0.0, 1.0] } },
        { "box": { "center": [0.0, 0.0, 0.0], "half_extents": [1.0, 1.0, 1.0] } },
    ] });
    let e = refuse(cube(boxed), &cube_file);
    assert_eq!(e.field, "obstacles[1]");
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn a_one_tetrahedron_tetgen_body_builds_from_either_file() {
    let dir = tetgen("either", false);
    for file in ["tet.node", "tet.ele"] {
        let scene = cube(serde_json::json!({})).build(&dir.join(file), ElementOrder::Linear).expect("builds");
        assert_eq!((scene.model.mesh().positions.len(), scene.model.mesh().tets.len()), (4, 1));
    }
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn the_fem_kind_takes_a_preset_or_a_body_and_names_the_field_it_refuses() {
    let base = testdata();
    let build = |value: serde_json::Value| (KIND.build)(&value, &BuildContext { base: Some(&base) });
    let field = |e: BuildError| match e {
        BuildError::Invalid { field, message } | BuildError::Schema { field, message } => (field, message),
        other => panic!("unexpected {other}"),
    };
    let body = serde_json::json!({
        "mesh": "cube_v41.msh",
        "material": { "young": 5e4, "poisson": 0.3, "density": 1000.0 },
    });
    assert!(build(serde_json::json!({ "body": body })).is_ok());
    assert!(build(serde_json::json!({ "body": body, "element": "tet10" })).is_ok());
    let (f, m) = field(build(serde_json::json!({})).err().expect("refused"));
    assert_eq!(f, "preset");
    assert!(m.contains("`body` table"), "{m}");
    assert_eq!(
        field(build(serde_json::json!({ "preset": "twisted-bar", "body": body })).err().expect("x")).0,
        "body"
    );
    assert_eq!(
        field(build(serde_json::json!({ "body": body, "resolution": 3 })).err().expect("x")).0,
        "resolution"
    );
    let missing = serde_json::json!({ "body": { "mesh": "missing.msh", "material": body["material"] } });
    let (f, m) = field(build(missing).err().expect("x"));
    assert_eq!(f, "body.mesh");
    assert!(m.contains("missing.msh"), "{m}");
    let typo =
        serde_json::json!({ "body": { "mesh": "cube_v41.msh", "material": body["material"], "scal": 2.0 } });
    assert!(field(build(typo).err().expect("x")).1.contains("scal"));
}
