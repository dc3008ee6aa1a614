//! The `obstacle_meshes` of a `pbd` scene file: a cloth on a mesh box behaves as on the analytic
//! box, a body starting inside a mesh obstacle is pushed out as from a shape, and every bad
//! input is refused naming `obstacle_meshes[k].<field>` and the file.

use super::bodies_tests::{built, folder, refusal, write_cloth, write_cube_obj};
use super::*;
use anim_core::glam::DVec3;
use anim_core::solver::Solver;
use serde_json::{Value, json};

/// A scene of an `n x n` cloth of side 0.3 m at height `z` over the box `[-0.2, 0.2]^2 x [0,
/// 0.4]`: the unit cube OBJ placed (`mesh`) or anim-core's box shape.
fn cloth_over_box(cloth: &str, z: f64, mesh: bool) -> Value {
    let mut scene = json!({
        "friction": 0.5,
        "thickness": 0.01,
        "bodies": [{ "mesh": cloth, "material": { "density": 0.2 }, "translate": [0.0, 0.0, z] }],
    });
    if mesh {
        scene["obstacle_meshes"] =
            json!([{ "mesh": "cube.obj", "scale": 0.4, "translate": [-0.2, -0.2, 0.0], "cell": 0.01 }]);
    } else {
        scene["obstacles"] =
            json!([{ "box": { "center": [0.0, 0.0, 0.2], "half_extents": [0.2, 0.2, 0.2] } }]);
    }
    scene
}

/// Steps `steps` frames of 1/60 s; the positions.
fn run(sim: &mut PbdSimulation, state: &mut State, steps: usize) -> Vec<f64> {
    for _ in 0..steps {
        sim.step(state, 1.0 / 60.0).expect("step");
    }
    state.x.clone()
}

/// A cloth dropped onto the top face of a mesh box, well inside its edges, falls, lands and
/// rests as on the analytic box: the field of a flat face is linear and interpolated exactly,
/// so the runs differ by the `f32` rounding of the field's nodes only (`2^-24` of values below
/// 0.1 m). The scene's thickness and friction reach the mesh collider.
#[test]
fn a_cloth_lands_on_a_mesh_box_as_on_the_analytic_box() {
    let dir = folder("mesh-box");
    write_cube_obj(&dir);
    let cloth = write_cloth(&dir, "cloth", 7, 0.3);
    let (mut sim, mut state) = built(&dir, cloth_over_box(&cloth, 0.6, true));
    let mesh = sim.model().mesh_colliders()[0].clone();
    assert_eq!((mesh.thickness, mesh.static_friction, mesh.kinetic_friction), (0.01, 0.5, 0.5));
    // The picture draws the placed surface of the mesh obstacle.
    let drawn = anim_core::scene::View::context(&sim, &state).mesh_props;
    assert!(
        drawn.len() == 1 && drawn[0].triangles.len() == mesh.shape.surface().triangles().len(),
        "{drawn:?}"
    );
    let on_mesh = run(&mut sim, &mut state, 60);
    let (mut sim, mut state) = built(&dir, cloth_over_box(&cloth, 0.6, false));
    let exact = run(&mut sim, &mut state, 60);
    for (i, (m, e)) in on_mesh.iter().zip(&exact).enumerate() {
        assert!((m - e).abs() < 1e-8, "coordinate {i}: {m} on the mesh, {e} on the box");
    }
    // It fell 0.2 m onto the top (0.4 m) and rests there at the thickness.
    for p in on_mesh.chunks(3) {
        assert!((p[2] - 0.41).abs() < 1e-6, "{p:?}");
    }
}

/// A body starting inside a mesh obstacle is not refused, as one inside a shape obstacle is not:
/// the contacts push it out to the nearest face, and it does so as from the analytic box (here
/// 2 mm below the top face, it ends on the top).
#[test]
fn a_body_starting_inside_a_mesh_obstacle_is_pushed_out_as_from_a_shape() {
    let dir = folder("mesh-inside");
    write_cube_obj(&dir);
    let cloth = write_cloth(&dir, "cloth", 5, 0.3);
    let (mut sim, mut state) = built(&dir, cloth_over_box(&cloth, 0.398, true));
    let on_mesh = run(&mut sim, &mut state, 30);
    let (mut sim, mut state) = built(&dir, cloth_over_box(&cloth, 0.398, false));
    let exact = run(&mut sim, &mut state, 30);
    for (i, (m, e)) in on_mesh.iter().zip(&exact).enumerate() {
        assert!((m - e).abs() < 1e-8, "coordinate {i}: {m} on the mesh, {e} on the box");
    }
    for p in on_mesh.chunks(3) {
        assert!((p[2] - 0.41).abs() < 1e-6, "{p:?}");
    }
}

/// A cloth draped over a mesh sphere stays outside it: every particle at least 95% of the
/// thickness from the surface by the field, every step while it falls onto it and slides over
/// it, and its centre rests on the top.
#[test]
fn a_cloth_stays_outside_a_mesh_sphere() {
    let dir = folder("mesh-sphere");
    let (p, t) = anim_core::surface::icosphere(3);
    let mut text = String::new();
    for v in &p {
        text += &format!("v {} {} {}\n", v[0], v[1], v[2]);
    }
    for f in &t {
        text += &format!("f {} {} {}\n", f[0] + 1, f[1] + 1, f[2] + 1);
    }
    std::fs::write(dir.join("ball.obj"), text).expect("write");
    let cloth = write_cloth(&dir, "cloth", 15, 0.8);
    let (mut sim, mut state) = built(
        &dir,
        json!({
            "friction": 0.3,
            "thickness": 0.01,
            "obstacle_meshes": [{ "mesh": "ball.obj", "scale": 0.2, "translate": [0.0, 0.0, 0.2] }],
            "bodies": [{ "mesh": cloth, "material": { "density": 0.2, "bending": { "isometric": { "compliance": 10.0 } } },
                         "translate": [0.0, 0.0, 0.5] }],
        }),
    );
    let field = sim.model().mesh_colliders()[0].shape.clone();
    for step in 0..90 {
        sim.step(&mut state, 1.0 / 60.0).expect("step");
        for p in state.x.chunks(3) {
            if let Some(s) = field.sample(DVec3::new(p[0], p[1], p[2])) {
                assert!(s.distance > 0.0095, "step {step}: a particle {} m from the surface", s.distance);
            }
        }
    }
    // It came down onto the ball: the centre vertex rests on its top, at the thickness within 5%.
    let c = 3 * (7 * 15 + 7);
    let centre = DVec3::new(state.x[c], state.x[c + 1], state.x[c + 2]);
    let s = field.sample(centre).expect("in the field");
    assert!(s.distance < 0.0105 && centre.truncate().length() < 0.01, "centre at {centre}, {s:?}");
}

/// Bad `obstacle_meshes` are refused naming `obstacle_meshes[k].<field>` and the file.
#[test]
fn mesh_obstacles_are_refused_by_field_and_file() {
    let dir = folder("mesh-refused");
    write_cube_obj(&dir);
    let cloth = write_cloth(&dir, "cloth", 3, 0.3);
    let with = |mesh: Value| {
        let mut scene = cloth_over_box(&cloth, 0.6, true);
        scene["obstacle_meshes"] = json!([{ "mesh": "cube.obj", "translate": [5.0, 0.0, 0.0] }, mesh]);
        scene
    };
    let field = |msg: &str| msg.split('`').nth(1).unwrap_or_default().to_string();
    let file = |name: &str| dir.join(name).display().to_string();
    // Missing, not an OBJ, open: the mesh field and the file.
    let msg = refusal(&dir, with(json!({ "mesh": "no-such.obj" })));
    assert!(field(&msg) == "obstacle_meshes[1].mesh" && msg.contains(&file("no-such.obj")), "{msg}");
    std::fs::write(dir.join("cube.stl"), "solid").expect("write");
    let msg = refusal(&dir, with(json!({ "mesh": "cube.stl" })));
    assert!(field(&msg) == "obstacle_meshes[1].mesh" && msg.contains(".obj"), "{msg}");
    let cube = std::fs::read_to_string(dir.join("cube.obj")).expect("read");
    let open: Vec<&str> = cube.lines().filter(|l| *l != "f 1 3 4").collect();
    assert_eq!(open.len(), cube.lines().count() - 1);
    std::fs::write(dir.join("open.obj"), open.join("\n")).expect("write");
    let msg = refusal(&dir, with(json!({ "mesh": "open.obj" })));
    assert!(
        field(&msg) == "obstacle_meshes[1].mesh" && msg.contains(&file("open.obj")) && msg.contains("edge"),
        "{msg}"
    );
    assert!(msg.contains("edge (0, 3) of triangle 0"), "{msg}");
    // The cell: not positive, or so fine that the field would exceed 2^24 nodes.
    for cell in [0.0, -0.01] {
        let msg = refusal(&dir, with(json!({ "mesh": "cube.obj", "cell": cell })));
        assert!(field(&msg) == "obstacle_meshes[1].cell" && msg.contains("positive"), "{msg}");
    }
    let msg = refusal(&dir, with(json!({ "mesh": "cube.obj", "cell": 1e-3 })));
    assert!(
        field(&msg) == "obstacle_meshes[1].cell" && msg.contains(&file("cube.obj")) && msg.contains("2^24"),
        "{msg}"
    );
    // The placement, by field; an unknown field by name.
    let msg = refusal(&dir, with(json!({ "mesh": "cube.obj", "scale": -1.0 })));
    assert_eq!(field(&msg), "obstacle_meshes[1].scale", "{msg}");
    let msg = refusal(&dir, with(json!({ "mesh": "cube.obj", "scale": 1e200 })));
    assert!(
        field(&msg) == "obstacle_meshes[1].scale"
            && msg.contains(&file("cube.obj"))
            && msg.contains("too large"),
        "{msg}"
    );
    let msg = refusal(&dir, with(json!({ "mesh": "cube.obj", "colour": "red" })));
    assert!(msg.contains("colour"), "{msg}");
    // A preset brings its own obstacles.
    let msg = refusal(&dir, json!({ "preset": "cloth-drape", "obstacle_meshes": [{ "mesh": "cube.obj" }] }));
    assert_eq!(field(&msg), "obstacle_meshes", "{msg}");
}
