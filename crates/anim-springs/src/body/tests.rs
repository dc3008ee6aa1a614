//! Bodies from OBJ files: mass, rest lengths, pins, resting contact and every refusal, through
//! [`build_bodies`] and through the scene kind as a scene file reaches it.

use super::*;
use crate::SpringKind;
use anim_core::glam::DVec3;
use anim_core::scene::{BuildContext, DynScene, Frame};

/// A folder of this test's own under the system's temporary folder, emptied.
fn folder(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("anim-springs-body-{}-{test}", std::process::id()));
    std::fs::remove_dir_all(&dir).ok();
    std::fs::create_dir_all(&dir).expect("temporary folder");
    dir
}

/// A flat `nx x ny` vertex grid spanning `[0, w] x [0, h]` at z = 0, quads split into two
/// triangles (vertex `iy nx + ix`, 1-based in the file).
fn grid_obj(nx: usize, ny: usize, w: f64, h: f64) -> String {
    let mut s = String::from("# a flat grid\n");
    for iy in 0..ny {
        for ix in 0..nx {
            let (x, y) = (w * ix as f64 / (nx - 1) as f64, h * iy as f64 / (ny - 1) as f64);
            s += &format!("v {x} {y} 0\n");
        }
    }
    for iy in 0..ny - 1 {
        for ix in 0..nx - 1 {
            let a = iy * nx + ix + 1;
            s += &format!("f {} {} {}\nf {} {} {}\n", a, a + 1, a + nx + 1, a, a + nx + 1, a + nx);
        }
    }
    s
}

/// The file's vertex positions, as written.
fn obj_positions(text: &str) -> Vec<DVec3> {
    text.lines()
        .filter_map(|l| l.strip_prefix("v "))
        .map(|l| {
            let c: Vec<f64> = l.split_whitespace().map(|w| w.parse().expect("number")).collect();
            DVec3::new(c[0], c[1], c[2])
        })
        .collect()
}

fn body(json: serde_json::Value) -> BodySpec {
    serde_json::from_value(json).expect("a body")
}

fn build(dir: &Path, bodies: &[BodySpec], obstacles: &[Shape]) -> Result<SpringScene, SceneError> {
    build_bodies(bodies, obstacles, crate::EARTH_GRAVITY, &ContactSpec::default(), |p| dir.join(p))
}

/// The refusal of a scene file's `[scene]` table, as the command line gets it.
fn refusal(dir: &Path, scene: serde_json::Value) -> (String, String) {
    match (crate::KIND.build)(&scene, &BuildContext { base: Some(dir) }) {
        Ok(_) => panic!("built: {scene}"),
        Err(SceneError::Invalid { field, message }) | Err(SceneError::Schema { field, message }) => {
            (field, message)
        }
        Err(other) => panic!("{other:?}"),
    }
}

fn frame_of(scene: &dyn DynScene) -> Frame {
    let mut frame = Frame::default();
    scene.frame(&mut frame);
    frame
}

/// A body of `grid.obj`: 0.3 kg/m^2, edge springs of 200 N/m.
fn cloth() -> serde_json::Value {
    serde_json::json!({ "mesh": "grid.obj", "material": { "density": 0.3, "stiffness": 200.0 } })
}

#[test]
fn the_mass_is_the_area_density_times_the_placed_area() {
    let dir = folder("mass");
    std::fs::write(dir.join("grid.obj"), grid_obj(7, 4, 1.0, 0.5)).expect("write");
    // Scaled by 2 and turned: 2 m x 1 m.
    let mut spec = body(cloth());
    spec.scale = 2.0;
    spec.rotate = [0.3, -0.7, 1.1];
    let scene = build(&dir, &[spec], &[]).expect("builds");
    let mass = scene.network.total_mass();
    assert!((mass - 0.3 * 2.0).abs() < 1e-14, "{mass}");
    // Lumped by area, a third of each triangle (half a cell): an interior vertex of this grid
    // has six triangles, the corner 0 two, the corner 6 one.
    let cell = (2.0 / 6.0) * (1.0 / 3.0);
    let m = |v: usize| scene.network.particles()[v].mass;
    assert!((m(8) - 0.3 * cell).abs() < 1e-15, "{}", m(8));
    assert!((m(0) - 0.3 * cell / 3.0).abs() < 1e-15, "{}", m(0));
    assert!((m(6) - 0.3 * cell / 6.0).abs() < 1e-15, "{}", m(6));
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn springs_rest_at_the_placed_edge_lengths_with_bending_across_interior_edges() {
    let dir = folder("rest");
    let text = grid_obj(5, 4, 0.8, 0.6);
    std::fs::write(dir.join("grid.obj"), &text).expect("write");
    let mut spec = body(cloth());
    spec.scale = 1.7;
    spec.rotate = [0.2, 0.0, -0.4];
    spec.translate = [3.0, -1.0, 2.0];
    spec.material.bending = Some(2.0);
    spec.material.bending_damping = 0.01;
    let scene = build(&dir, &[spec], &[]).expect("builds");
    let file = obj_positions(&text);
    // The edges of a 5 x 4 vertex grid of split quads: rows, columns, one diagonal per cell.
    let (cells, nx, ny) = (4 * 3, 5, 4);
    let edges = (nx - 1) * ny + nx * (ny - 1) + cells;
    let interior = edges - 2 * ((nx - 1) + (ny - 1));
    let springs = scene.network.springs();
    assert_eq!(springs.len(), edges + interior);
    for s in springs {
        let length = 1.7 * (file[s.i] - file[s.j]).length();
        let placed = DVec3::from_array(scene.network.model().rest_positions()[s.i])
            - DVec3::from_array(scene.network.model().rest_positions()[s.j]);
        assert_eq!(placed.length().to_bits(), s.rest_length.to_bits(), "{s:?}");
        match s.kind {
            SpringKind::Structural => {
                assert!((s.rest_length - length).abs() < 1e-14, "{s:?}: {length}");
                assert_eq!((s.stiffness, s.damping), (200.0, 0.0));
            }
            SpringKind::Bending => assert_eq!((s.stiffness, s.damping), (2.0, 0.01)),
            other => panic!("a {other:?} spring"),
        }
    }
    assert_eq!(springs.iter().filter(|s| s.kind == SpringKind::Bending).count(), interior);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn pinned_vertices_start_at_rest_and_do_not_move() {
    let dir = folder("pins");
    std::fs::write(dir.join("grid.obj"), grid_obj(6, 6, 1.0, 1.0)).expect("write");
    // Pinned: vertex 0 and 5 by index, the row y = 1 (vertices 30 to 35) by a box around it.
    let mut flag = cloth();
    flag["translate"] = serde_json::json!([0.0, 0.0, 1.0]);
    flag["velocity"] = serde_json::json!([0.0, 0.5, 0.0]);
    flag["pin"] = serde_json::json!({ "vertices": [5, 0, 5], "box": { "min": [-0.1, 0.9, 0.9], "max": [1.1, 1.1, 1.1] } });
    let mut scene = (crate::KIND.build)(
        &serde_json::json!({ "bodies": [flag], "linear_solver": "jacobi-pcg" }),
        &BuildContext { base: Some(&dir) },
    )
    .expect("builds");
    let pins: Vec<usize> = [0, 5].into_iter().chain(30..36).collect();
    assert_eq!(scene.context().pins, pins);
    assert_eq!(scene.method(), "backward-euler / jacobi-pcg");
    // The frames are y up: the velocity (0, 0.5, 0) of the z-up scene file is (0, 0, -0.5).
    let start = frame_of(scene.as_ref());
    let v = &start.field("velocity").expect("v").values;
    for p in 0..36 {
        let expected = if pins.contains(&p) { [0.0; 3] } else { [0.0, 0.0, -0.5] };
        assert_eq!(v[3 * p..3 * p + 3], expected, "vertex {p}");
    }
    for _ in 0..30 {
        scene.step(0.01).expect("step");
    }
    let end = frame_of(scene.as_ref());
    for p in 0..36 {
        let (a, b) = (&start.points[3 * p..3 * p + 3], &end.points[3 * p..3 * p + 3]);
        if pins.contains(&p) {
            assert_eq!(a, b, "pinned vertex {p} moved");
        } else {
            // Falling along -y, the frames' down.
            assert!(b[1] < a[1] - 1e-3, "free vertex {p} did not fall: {a:?} -> {b:?}");
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// A cloth smaller than a box's top, released just above it, comes to rest on it: no vertex
/// ever sinks a smoothing width into the box (grown by the contact thickness), and at rest each
/// sinks the penalty depth of its own weight, `e(p) = m g`.
#[test]
fn a_cloth_on_a_box_top_rests_above_it_within_the_penalty_depth() {
    let dir = folder("rest-on-box");
    std::fs::write(dir.join("grid.obj"), grid_obj(9, 9, 0.4, 0.4)).expect("write");
    let top = 0.5;
    let mut spec = body(serde_json::json!({
        "mesh": "grid.obj",
        "material": { "density": 0.2, "stiffness": 100.0, "damping": 0.05, "bending": 1.0 },
        "translate": [-0.2, -0.2, top + 0.008],
    }));
    spec.rotate = [0.0, 0.0, 0.3];
    let table = Shape::Box { center: [0.0, 0.0, 0.25], half_extents: [0.4, 0.4, 0.25] };
    for thickness in [0.0, 0.003] {
        let contact = ContactSpec { thickness, ..ContactSpec::default() };
        let scene = build_bodies(&[spec.clone()], &[table], crate::EARTH_GRAVITY, &contact, |p| dir.join(p))
            .expect("builds");
        let masses: Vec<f64> = scene.network.particles().iter().map(|p| p.mass).collect();
        let (mut sim, mut state) = scene.into_simulation().expect("simulation");
        let surface = top + thickness;
        let mut lowest = f64::INFINITY;
        for _ in 0..400 {
            sim.advance(&mut state, 0.005).expect("step");
            lowest = lowest.min(state.x.chunks_exact(3).map(|p| p[2]).fold(f64::INFINITY, f64::min));
        }
        assert!(lowest > surface - contact.smoothing, "thickness {thickness}: a vertex sank to {lowest}");
        // At rest: e(p) = k p^2 / (2 delta) = m g below the smoothing width.
        let (k, delta) = (contact.stiffness, contact.smoothing);
        for (v, (p, m)) in state.x.chunks_exact(3).zip(&masses).enumerate() {
            let depth = (2.0 * delta * m * 9.81 / k).sqrt();
            assert!(depth < delta);
            let sunk = surface - p[2];
            assert!(
                (sunk - depth).abs() < 1e-3 * depth,
                "thickness {thickness}, vertex {v}: sunk {sunk}, penalty depth {depth}"
            );
        }
        assert!(state.v.iter().all(|v| v.abs() < 1e-6), "thickness {thickness}: still moving");
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn bodies_keep_their_own_materials_and_pins() {
    let dir = folder("two");
    std::fs::write(dir.join("grid.obj"), grid_obj(3, 3, 1.0, 1.0)).expect("write");
    std::fs::write(dir.join("small.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").expect("write");
    let a = body(cloth());
    let mut b = body(serde_json::json!({
        "mesh": "small.obj", "material": { "density": 2.0, "stiffness": 50.0, "damping": 0.5 },
        "translate": [5.0, 0.0, 0.0], "pin": { "vertices": [2] },
    }));
    b.velocity = [1.0, 0.0, 0.0];
    let scene = build(&dir, &[a, b], &[]).expect("builds");
    let net = &scene.network;
    assert_eq!(net.num_particles(), 9 + 3);
    let mass = |r: std::ops::Range<usize>| r.map(|p| net.particles()[p].mass).sum::<f64>();
    assert!((mass(0..9) - 0.3).abs() < 1e-15 && (mass(9..12) - 1.0).abs() < 1e-15);
    let pinned: Vec<usize> = (0..12).filter(|&p| net.particles()[p].pinned).collect();
    assert_eq!(pinned, [11]);
    let second: Vec<_> = net.springs().iter().filter(|s| s.i >= 9).collect();
    assert_eq!(second.len(), 3);
    assert!(second.iter().all(|s| s.j >= 9 && (s.stiffness, s.damping) == (50.0, 0.5)));
    assert!(net.springs().iter().filter(|s| s.i < 9).all(|s| s.j < 9 && s.stiffness == 200.0));
    assert_eq!(&scene.state.v[27..], [1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
    assert!(scene.state.v[..27].iter().all(|v| *v == 0.0));
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_scene_of_bodies_reads_back_the_same_and_resumes_bit_for_bit() {
    let dir = folder("checkpoint");
    std::fs::write(dir.join("grid.obj"), grid_obj(4, 4, 1.0, 1.0)).expect("write");
    let params = serde_json::json!({
        "bodies": [{
            "mesh": "grid.obj", "material": { "density": 0.3, "stiffness": 200.0, "bending": 1.0 },
            "scale": 0.5, "translate": [0.0, 0.0, 0.3], "pin": { "box": { "min": [0, 0, 0], "max": [0.1, 0.1, 1] } },
        }],
        "obstacles": [
            { "plane": { "point": [0, 0, 0], "normal": [0, 0, 1] } },
            { "capsule": { "a": [0, 0.2, 0.1], "b": [0.5, 0.2, 0.1], "radius": 0.1 } },
        ],
        "gravity": [0.0, 0.0, -9.81],
        "contact": { "stiffness": 2e4 },
    });
    let read: crate::kind::SpringsParams = anim_core::scene::params(&params).expect("reads");
    let back = serde_json::to_value(&read).expect("writes");
    let again: crate::kind::SpringsParams = anim_core::scene::params(&back).expect("reads back");
    assert_eq!(read, again);
    assert!(back["bodies"][0].get("rotate").is_none() && back["bodies"][0]["scale"] == 0.5);
    let context = BuildContext { base: Some(&dir) };
    let mut a = (crate::KIND.build)(&params, &context).expect("builds");
    assert_eq!(a.method(), "backward-euler / cholesky");
    let props = a.context().props;
    assert_eq!(props.len(), 2, "{props:?}"); // the ground and the capsule
    for _ in 0..3 {
        a.step(0.01).expect("step");
    }
    let saved = serde_json::to_string(&a.save()).expect("json");
    for _ in 0..3 {
        a.step(0.01).expect("step");
    }
    let mut b = (crate::KIND.build)(&params, &context).expect("builds");
    b.restore(&serde_json::from_str(&saved).expect("json")).expect("restores");
    for _ in 0..3 {
        b.step(0.01).expect("step");
    }
    assert_eq!(a.save(), b.save());
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn refusals_name_the_field_the_file_and_the_element() {
    let dir = folder("refusals");
    std::fs::write(dir.join("grid.obj"), grid_obj(3, 3, 1.0, 1.0)).expect("write");
    let scene = |bodies: serde_json::Value| serde_json::json!({ "bodies": [bodies] });
    let with = |key: &str, value: serde_json::Value| {
        let mut b = cloth();
        b[key] = value;
        scene(b)
    };
    let grid = dir.join("grid.obj").display().to_string();

    // A pin index out of range names the index and the vertex count.
    let (field, message) = refusal(&dir, with("pin", serde_json::json!({ "vertices": [8, 9] })));
    assert_eq!(field, "bodies[0].pin.vertices[1]");
    assert_eq!(message, format!("vertex 9 is out of range: {grid} has 9 vertices (0 to 8)"));
    // An empty pin box, and a pin table without either.
    let (field, message) =
        refusal(&dir, with("pin", serde_json::json!({ "box": { "min": [2, 2, 2], "max": [3, 3, 3] } })));
    assert_eq!(field, "bodies[0].pin");
    assert!(message.contains("holds no vertex") && message.contains(&grid), "{message}");
    assert_eq!(refusal(&dir, with("pin", serde_json::json!({}))).0, "bodies[0].pin");
    // A box with min above max is refused as such, not as holding no vertex.
    let (field, message) =
        refusal(&dir, with("pin", serde_json::json!({ "box": { "min": [1, 0, 0], "max": [0, 1, 1] } })));
    assert_eq!(field, "bodies[0].pin.box");
    assert!(message.contains("min <= max"), "{message}");
    // A missing file is named.
    let (field, message) = refusal(&dir, with("mesh", serde_json::json!("nowhere/cloth.obj")));
    assert_eq!(field, "bodies[0].mesh");
    assert!(message.contains(&dir.join("nowhere/cloth.obj").display().to_string()), "{message}");
    // A bad scale; NaN and infinity reach the builder only from Rust (JSON has neither).
    let (field, message) = refusal(&dir, with("scale", serde_json::json!(0.0)));
    assert_eq!((field.as_str(), message.as_str()), ("bodies[0].scale", "must be positive and finite, got 0"));
    let mut spec = body(cloth());
    spec.translate = [0.0, f64::NAN, 0.0];
    match build(&dir, &[body(cloth()), spec.clone()], &[]) {
        Err(SceneError::Invalid { field, message }) => {
            assert_eq!(field, "bodies[1].translate");
            assert!(message.contains("NaN"), "{message}");
        }
        other => panic!("{other:?}"),
    }
    spec.translate = [0.0; 3];
    spec.rotate = [f64::INFINITY, 0.0, 0.0];
    assert!(
        matches!(build(&dir, &[spec.clone()], &[]), Err(SceneError::Invalid { field, .. }) if field == "bodies[0].rotate")
    );
    spec.rotate = [0.0; 3];
    spec.scale = 1e308;
    spec.translate = [1e308, 0.0, 0.0];
    match build(&dir, &[spec], &[]) {
        Err(SceneError::Invalid { field, message }) => {
            assert_eq!(field, "bodies[0].scale");
            assert!(message.contains(&grid) && message.contains("not finite"), "{message}");
        }
        other => panic!("{other:?}"),
    }
    // An obstacle refused: named by its index, and its shape.
    let mut bad = scene(cloth());
    bad["obstacles"] = serde_json::json!([
        { "plane": { "point": [0, 0, 0], "normal": [0, 0, 1] } },
        { "sphere": { "center": [0, 0, 0], "radius": -1 } },
    ]);
    let (field, message) = refusal(&dir, bad);
    assert_eq!(
        (field.as_str(), message.as_str()),
        ("obstacles[1]", "sphere radius must be positive and finite, got -1")
    );
    // Material, contact, gravity.
    let mut b = cloth();
    b["material"]["stiffness"] = serde_json::json!(-5.0);
    assert_eq!(refusal(&dir, scene(b)).0, "bodies[0].material.stiffness");
    let mut b = cloth();
    b["material"]["bending_damping"] = serde_json::json!(0.1);
    assert_eq!(refusal(&dir, scene(b)).0, "bodies[0].material.bending_damping");
    let mut bad = scene(cloth());
    bad["contact"] = serde_json::json!({ "friction": -1.0 });
    assert_eq!(refusal(&dir, bad).0, "contact.friction");
    let mut bad = scene(cloth());
    bad["contact"] = serde_json::json!({ "thickness": -0.001 });
    let (field, message) = refusal(&dir, bad);
    assert_eq!(
        (field.as_str(), message.as_str()),
        ("contact.thickness", "must be non-negative and finite, got -0.001")
    );
    // Preset-only and preset fields.
    let mut bad = scene(cloth());
    bad["resolution"] = serde_json::json!(8);
    assert_eq!(refusal(&dir, bad).0, "resolution");
    let mut bad = scene(cloth());
    bad["preset"] = serde_json::json!("hanging-cloth");
    assert_eq!(refusal(&dir, bad).0, "bodies");
    // A misspelt field, by serde.
    let (field, message) = refusal(&dir, with("velocty", serde_json::json!([0, 0, 0])));
    assert!(field.is_empty() || field.starts_with("bodies"), "{field}");
    assert!(message.contains("unknown field `velocty`"), "{message}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn bad_surfaces_are_refused_with_the_file_and_the_element() {
    let dir = folder("surfaces");
    let cases = [
        (
            "zero.obj",
            "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nf 1 2 4\nf 1 2 3\n",
            "triangle 1 [0, 1, 2] is degenerate: zero area",
        ),
        ("isolated.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 5 5 5\nf 1 2 3\n", "vertex 3 belongs to no triangle"),
        ("lines.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nl 1 2\n", "1 line segments"),
        ("empty.obj", "v 0 0 0\n", "no faces"),
        ("bad.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n", "4: vertex index 7 but the file has 3 vertices"),
        (
            "fin.obj",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nf 1 2 3\nf 1 2 4\nf 1 2 5\n",
            "edge (0, 1) is shared by 3 triangles; bending needs a manifold mesh (or leave out `material.bending`)",
        ),
    ];
    for (name, text, needle) in cases {
        std::fs::write(dir.join(name), text).expect("write");
        let b = serde_json::json!({
            "mesh": name, "material": { "density": 1.0, "stiffness": 1.0, "bending": 1.0 },
        });
        let (field, message) = refusal(&dir, serde_json::json!({ "bodies": [b] }));
        assert_eq!(field, "bodies[0].mesh", "{name}");
        let file = dir.join(name).display().to_string();
        assert!(message.starts_with(&file) && message.contains(needle), "{name}: {message}");
    }
    std::fs::remove_dir_all(&dir).ok();
}
