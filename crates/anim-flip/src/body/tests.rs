use super::*;
use crate::kind::KIND;
use crate::scenes;
use anim_core::scene::{Frame, Prop, View};
use anim_core::solver::Solver;
use serde_json::{Value, json};
use std::path::Path;

fn read(value: Value) -> FlipSceneParams {
    serde_json::from_value(value).expect("parameters")
}

/// The crate's test data folder as the scene file's folder.
fn testdata() -> BuildContext<'static> {
    BuildContext { base: Some(Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/testdata"))) }
}

fn build3(value: Value) -> Result<(BodyScene<3>, Particles<3>), BuildError> {
    build::<3>(&read(value), &testdata())
}

fn boxed(center: [f64; 3], half: [f64; 3]) -> Value {
    json!({ "box": { "center": center, "half_extents": half } })
}

/// The refusal of `value` by the kind's build (field and message).
fn refusal(value: Value) -> (String, String) {
    match (KIND.build)(&value, &testdata()) {
        Err(BuildError::Invalid { field, message } | BuildError::Memory { field, message, .. }) => {
            (field, message)
        }
        Err(other) => panic!("refused otherwise: {other}"),
        Ok(_) => panic!("built: {value}"),
    }
}

/// Positions as sortable bits.
fn sorted_bits<const D: usize>(x: &[[f64; D]]) -> Vec<[u64; D]> {
    let mut v: Vec<[u64; D]> = x.iter().map(|p| p.map(f64::to_bits)).collect();
    v.sort_unstable();
    v
}

/// A lattice-aligned box of 8 x 8 x 4 cells at 16 cells across holds 8 particles per cell, the
/// presets' lattice: the points `fill_box` seeds in that box of the same tank, bit for bit.
#[test]
fn a_box_body_holds_its_cells_times_the_particles_per_cell_on_the_presets_lattice() {
    let (scene, p) = build3(
        json!({ "resolution": 16, "bodies": [{ "shape": boxed([0.5, 0.25, 0.375], [0.25, 0.25, 0.125]) }] }),
    )
    .expect("builds");
    assert_eq!(p.len(), 8 * 8 * 4 * 8);
    let h = 1.0 / 16.0;
    assert_eq!(scene.origin, [h; 3]);
    // The presets cut their regions from the lattice over the whole fluid box (`drop-3d`).
    let mut expected = Particles::new();
    let (lo, hi) = scene.sim.fluid_box();
    let in_box = |x: [f64; 3]| {
        let y = scene.to_scene(&x);
        (0.25..0.75).contains(&y[0]) && (0.0..0.5).contains(&y[1]) && (0.25..0.5).contains(&y[2])
    };
    scenes::fill_region(&mut expected, h, 2, lo, hi, in_box, |_| [0.0, 0.0, 0.0]);
    assert_eq!(sorted_bits(&p.x), sorted_bits(&expected.x));
    // 2D: a 0.5 x 0.25 m rectangle at 32 cells across, 16 x 8 cells of 4 particles, moving.
    let params = read(json!({
        "dim": 2,
        "resolution": 32,
        "bodies": [{ "shape": boxed([0.25, 0.125, 0.0], [0.25, 0.125, 0.0]), "velocity": [1.0, -2.0, 0.0] }],
    }));
    let (_, p) = build::<2>(&params, &testdata()).expect("builds");
    assert_eq!(p.len(), 16 * 8 * 4);
    assert!(p.v.iter().all(|v| *v == [1.0, -2.0]));
}

/// Overlapping bodies: a lattice point is seeded once, by the first body holding it, so the
/// count is that of the union and the overlap moves at the first body's velocity.
#[test]
fn overlapping_bodies_seed_each_point_once_the_first_body_first() {
    let a = json!({ "shape": boxed([0.25, 0.25, 0.25], [0.25, 0.25, 0.25]), "velocity": [1.0, 0.0, 0.0] });
    let b = json!({ "shape": boxed([0.375, 0.25, 0.25], [0.25, 0.25, 0.25]), "velocity": [-1.0, 0.0, 0.0] });
    let (_, p) = build3(json!({ "resolution": 8, "bodies": [a, b] })).expect("builds");
    // Union: 5 x 4 x 4 cells of 8 particles; the first body's 4 x 4 x 4 cells at +1 m/s.
    assert_eq!(p.len(), 5 * 4 * 4 * 8);
    assert_eq!(p.v.iter().filter(|v| v[0] == 1.0).count(), 4 * 4 * 4 * 8);
    let (_, p) = build3(json!({ "resolution": 8, "bodies": [b, a] })).expect("builds");
    assert_eq!(p.v.iter().filter(|v| v[0] == -1.0).count(), 4 * 4 * 4 * 8);
}

/// A closed OBJ cube placed onto a box seeds exactly the box's particles; a sphere holds its
/// volume to within the lattice's error, which shrinks with the resolution.
#[test]
fn a_mesh_cube_seeds_the_box_and_a_sphere_its_volume() {
    let cube = json!({ "mesh": "cube.obj", "scale": 0.25, "translate": [0.5, 0.375, 0.5], "velocity": [0.0, -1.0, 0.0] });
    let (_, from_mesh) = build3(json!({ "resolution": 16, "bodies": [cube] })).expect("builds");
    let (_, from_box) = build3(
        json!({ "resolution": 16, "bodies": [{ "shape": boxed([0.5, 0.375, 0.5], [0.125, 0.125, 0.125]) }] }),
    )
    .expect("builds");
    assert_eq!(from_mesh.len(), 4 * 4 * 4 * 8);
    assert_eq!(sorted_bits(&from_mesh.x), sorted_bits(&from_box.x));
    // A quarter turn about y maps the cube onto itself.
    let turned = json!({ "mesh": "cube.obj", "scale": 0.25, "rotate": [0.0, std::f64::consts::FRAC_PI_2, 0.0], "translate": [0.5, 0.375, 0.5] });
    let (_, p) = build3(json!({ "resolution": 16, "bodies": [turned] })).expect("builds");
    assert_eq!(sorted_bits(&p.x), sorted_bits(&from_box.x));
    // 2D: the cube cut by the plane z = 0 is the square of the box.
    let square = json!({ "mesh": "cube.obj", "scale": 0.25, "rotate": [0.0, 0.0, 0.3], "translate": [0.5, 0.375, 0.0] });
    let flat = json!({
        "shape": { "box": { "center": [0.0, 0.0, 0.0], "half_extents": [0.5, 0.5, 0.0] } },
        "scale": 0.25,
        "rotate": [0.0, 0.0, 0.3],
        "translate": [0.5, 0.375, 0.0],
    });
    let two =
        |body: Value| build::<2>(&read(json!({ "dim": 2, "resolution": 32, "bodies": [body] })), &testdata());
    let (from_mesh, from_box) = (two(square).expect("builds").1, two(flat).expect("builds").1);
    assert!(from_mesh.len() > 8 * 8 * 4 * 9 / 10);
    assert_eq!(sorted_bits(&from_mesh.x), sorted_bits(&from_box.x));
    let r: f64 = 0.2;
    let exact = 4.0 / 3.0 * std::f64::consts::PI * r.powi(3);
    let mut errors = vec![];
    for n in [16, 32] {
        let sphere = json!({ "sphere": { "center": [0.5, 0.5, 0.5], "radius": r } });
        let (_, p) = build3(json!({ "resolution": n, "bodies": [{ "shape": sphere }] })).expect("builds");
        let spacing = 0.5 / n as f64;
        let volume = p.len() as f64 * spacing.powi(3);
        errors.push((volume - exact).abs() / exact);
    }
    assert!(errors[0] < 0.05 && errors[1] < errors[0], "{errors:?}");
}

/// The obstacles of the example at 16 cells: a sphere standing in a pool, a blob falling onto
/// it.
fn pool_around_a_sphere(dim: usize) -> Value {
    let z = if dim == 3 { 0.5 } else { 0.0 };
    json!({
        "dim": dim,
        "resolution": 16,
        "obstacles": [ { "sphere": { "center": [0.5, 0.12, z], "radius": 0.16 } } ],
        "bodies": [
            { "shape": { "sphere": { "center": [0.45, 0.6, z], "radius": 0.12 } }, "velocity": [0.0, -1.5, 0.0] },
            { "shape": boxed([0.5, 0.05, z], [0.5, 0.05, 0.5]) },
        ],
    })
}

/// Cells whose centres are inside the sphere obstacle are solid and the others (but the walls)
/// not; no particle is seeded in them or enters them over a second of falling and splashing,
/// and the density-estimated volume stays within 0.1% of its start (0.015% measured: the
/// volume correction at work).
#[test]
fn obstacle_cells_are_solid_no_particle_enters_them_and_the_volume_is_kept() {
    let (mut scene, mut p) = build3(pool_around_a_sphere(3)).expect("builds");
    let n = scene.sim.grid().cells();
    let h = scene.sim.grid().h();
    let mut obstacle_cells = 0;
    for c in 0..n.iter().product() {
        let idx = crate::mac::unflatten(n, c);
        let wall = (0..3).any(|a| idx[a] == 0 || idx[a] == n[a] - 1);
        let centre: [f64; 3] = std::array::from_fn(|a| (idx[a] as f64 + 0.5) * h - scene.origin[a]);
        let d2 = (centre[0] - 0.5).powi(2) + (centre[1] - 0.12).powi(2) + (centre[2] - 0.5).powi(2);
        let inside = d2 < 0.16 * 0.16;
        obstacle_cells += usize::from(inside && !wall);
        assert_eq!(scene.sim.solid()[c], wall || inside, "cell {idx:?}");
    }
    assert!(obstacle_cells > 20, "{obstacle_cells}");
    let in_solid = |scene: &BodyScene<3>, p: &Particles<3>| {
        p.x.iter().filter(|x| scene.sim.solid()[flatten(n, x.map(|c| (c / h) as usize))]).count()
    };
    assert_eq!(in_solid(&scene, &p), 0);
    let count = p.len();
    let v0 = scene.sim.volume_estimate(&p, 8.0);
    assert!((v0 - count as f64 * h.powi(3) / 8.0).abs() < 1e-9 * v0, "{v0}");
    let mut lowest = 1.0f64;
    for _ in 0..50 {
        scene.step(&mut p, 0.02).expect("step");
        assert_eq!(in_solid(&scene, &p), 0, "at {} s", scene.sim.time());
        lowest = lowest.min(scene.sim.volume_estimate(&p, 8.0) / v0);
    }
    assert_eq!(p.len(), count);
    let ratio = scene.sim.volume_estimate(&p, 8.0) / v0;
    assert!((ratio - 1.0).abs() < 1e-3 && lowest > 0.999, "volume ratio {ratio}, lowest {lowest}");
    // Something happened: the blob reached the pool.
    assert!(p.x.iter().all(|x| x[1] - scene.origin[1] < 0.45), "the blob did not fall");
}

/// Frames are in the scene file's frame (the tank's inside from the origin), y up as the file
/// and every view's frames are; the context draws the tank from the origin to 1 m and the
/// sphere obstacle; a 2D scene lies in the plane z = 0.
#[test]
fn frames_and_props_are_in_the_scene_files_frame_y_up() {
    let mut scene = (KIND.build)(&pool_around_a_sphere(3), &testdata()).expect("builds");
    let mut frame = Frame::default();
    scene.frame(&mut frame);
    let points: Vec<&[f64]> = frame.points.chunks_exact(3).collect();
    // The pool's lowest particles half a spacing above the floor (y) and in from the wall z = 0.
    let spacing = 0.5 / 16.0;
    let min_y = points.iter().map(|p| p[1]).fold(f64::INFINITY, f64::min);
    let min_z = points.iter().map(|p| p[2]).fold(f64::INFINITY, f64::min);
    assert!(
        (min_y - spacing / 2.0).abs() < 1e-12 && (min_z - spacing / 2.0).abs() < 1e-12,
        "{min_y} {min_z}"
    );
    let velocity = &frame.field("velocity").expect("velocities").values;
    assert!(velocity.chunks_exact(3).any(|v| v == [0.0, -1.5, 0.0]));
    let context = scene.context();
    assert_eq!(
        context.props,
        vec![
            Prop::Tank { lo: [0.0; 3], hi: [1.0; 3] },
            Prop::Sphere { center: [0.5, 0.12, 0.5], radius: 0.16 },
        ]
    );
    assert_eq!(context.bounds, Some(([0.0; 3], [1.0; 3])));
    assert!(!context.planar);
    scene.step(0.02).expect("step");
    // 2D: the plane z = 0.
    let scene = (KIND.build)(&pool_around_a_sphere(2), &testdata()).expect("builds");
    scene.frame(&mut frame);
    assert!(frame.points.chunks_exact(3).all(|p| p[2] == 0.0 && p[0] > 0.0 && p[1] > 0.0));
    assert_eq!(scene.context().props[1], Prop::Sphere { center: [0.5, 0.12, 0.0], radius: 0.16 });
    assert!(scene.context().mesh_props.is_empty() && scene.context().planar);
}

/// A scene of bodies resumes from its checkpoint bit for bit.
#[test]
fn a_scene_of_bodies_resumes_from_its_checkpoint() {
    let make = || (KIND.build)(&pool_around_a_sphere(2), &testdata()).expect("builds");
    let mut a = make();
    for _ in 0..3 {
        a.step(0.02).expect("step");
    }
    let saved = a.save().to_string();
    for _ in 0..3 {
        a.step(0.02).expect("step");
    }
    let mut b = make();
    b.restore(&serde_json::from_str(&saved).expect("json")).expect("restore");
    for _ in 0..3 {
        b.step(0.02).expect("step");
    }
    // Equal JSON text is equal bits (shortest round-trip floats).
    let (left, right) = (a.save().to_string(), b.save().to_string());
    assert!(left == right, "the checkpoints differ");
}

#[test]
fn a_body_outside_the_tank_is_refused_by_its_index() {
    let inside = json!({ "shape": boxed([0.5, 0.2, 0.5], [0.1, 0.1, 0.1]) });
    let outside = json!({ "shape": { "sphere": { "center": [0.875, 0.5, 0.5], "radius": 0.25 } } });
    let (field, message) = refusal(json!({ "bodies": [inside, outside] }));
    assert_eq!(field, "bodies[1]");
    assert_eq!(
        message,
        "reaches outside the tank: it spans [0.625, 0.25, 0.25] to [1.125, 0.75, 0.75] (m); the tank's inside is 0 to 1 m along each axis"
    );
    // A mesh too large for the tank, and a box reaching below the floor.
    let big = json!({ "mesh": "cube.obj", "scale": 2.0 });
    assert_eq!(refusal(json!({ "bodies": [big] })).0, "bodies[0]");
    let low = json!({ "shape": boxed([0.5, 0.05, 0.5], [0.1, 0.1, 0.1]) });
    assert_eq!(refusal(json!({ "dim": 2, "bodies": [low] })).0, "bodies[0]");
}

#[test]
fn an_open_mesh_is_refused_with_its_file_and_edge() {
    let (field, message) = refusal(
        json!({ "bodies": [{ "mesh": "open-cube.obj", "scale": 0.2, "translate": [0.5, 0.5, 0.5] }] }),
    );
    assert_eq!(field, "bodies[0].mesh");
    assert!(message.contains("testdata/open-cube.obj: ") && message.contains("edge"), "{message}");
    let (field, message) = refusal(json!({
        "bodies": [{ "shape": boxed([0.5, 0.5, 0.5], [0.1, 0.1, 0.1]) }],
        "obstacle_meshes": [{ "mesh": "open-cube.obj" }],
    }));
    assert_eq!(field, "obstacle_meshes[0].mesh");
    assert!(message.contains("open-cube.obj: ") && message.contains("edge"), "{message}");
    let (field, message) = refusal(json!({ "bodies": [{ "mesh": "missing.obj" }] }));
    assert_eq!(field, "bodies[0].mesh");
    assert!(message.contains("missing.obj"), "{message}");
}

#[test]
fn an_empty_body_is_refused_with_the_resolution() {
    let dot = json!({ "shape": { "sphere": { "center": [0.5, 0.5, 0.5], "radius": 0.01 } } });
    let (field, message) = refusal(json!({ "resolution": 8, "bodies": [dot] }));
    assert_eq!(field, "bodies[0]");
    assert_eq!(
        message,
        "holds no particle at resolution 8 (particles 0.0625 m apart): make it larger or raise the resolution"
    );
    // A body wholly inside an earlier one, and one wholly inside an obstacle.
    let big = json!({ "shape": boxed([0.5, 0.5, 0.5], [0.2, 0.2, 0.2]) });
    let small = json!({ "shape": boxed([0.5, 0.5, 0.5], [0.1, 0.1, 0.1]) });
    let (field, message) = refusal(json!({ "resolution": 8, "bodies": [big, small] }));
    assert_eq!(field, "bodies[1]");
    assert_eq!(
        message,
        "none of its 64 particles is left: 64 belong to earlier bodies, 0 lie in solid cells of obstacles"
    );
    let (field, message) = refusal(
        json!({ "resolution": 8, "bodies": [small], "obstacles": [boxed([0.5, 0.5, 0.5], [0.3, 0.3, 0.3])] }),
    );
    assert_eq!(field, "bodies[0]");
    assert!(message.ends_with("0 belong to earlier bodies, 64 lie in solid cells of obstacles"), "{message}");
}

#[test]
fn other_refusals_name_their_field() {
    let body = json!({ "shape": boxed([0.5, 0.5, 0.5], [0.1, 0.1, 0.1]) });
    let cases = [
        (json!({ "bodies": [{}] }), "bodies[0]", "give a `shape`"),
        (
            json!({ "bodies": [{ "shape": boxed([0.5, 0.5, 0.5], [0.1, 0.1, 0.1]), "mesh": "cube.obj" }] }),
            "bodies[0]",
            "not both",
        ),
        (
            json!({ "bodies": [{ "shape": { "plane": { "point": [0.0, 0.0, 0.0], "normal": [0.0, 1.0, 0.0] } } }] }),
            "bodies[0].shape",
            "unbounded",
        ),
        (
            json!({ "bodies": [{ "shape": { "sphere": { "center": [0.5, 0.5, 0.5], "radius": -1.0 } } }] }),
            "bodies[0].shape",
            "radius",
        ),
        (
            json!({ "bodies": [{ "shape": boxed([0.5, 0.5, 0.5], [0.1, 0.1, 0.1]), "scale": 0.0 }] }),
            "bodies[0].scale",
            "positive",
        ),
        (
            json!({ "dim": 2, "bodies": [{ "shape": boxed([0.5, 0.5, 0.5], [0.1, 0.1, 0.1]), "rotate": [0.1, 0.0, 0.0] }] }),
            "bodies[0].rotate",
            "[0, 0, yaw]",
        ),
        (
            json!({ "dim": 2, "bodies": [{ "shape": boxed([0.5, 0.5, 0.5], [0.1, 0.1, 0.1]), "velocity": [0.0, 0.0, 1.0] }] }),
            "bodies[0].velocity",
            "z = 0",
        ),
        (json!({ "dim": 2, "gravity": [0.0, -9.81, 1.0], "bodies": [body] }), "gravity", "z = 0"),
        (json!({ "dim": 4, "bodies": [body] }), "dim", "must be 2 or 3, got 4"),
        (json!({ "resolution": 1_000_000_000, "bodies": [body] }), "resolution", "1000000000 cells across ("),
        (json!({ "resolution": 3, "bodies": [body] }), "resolution", "at least 4 cells across"),
        (json!({ "transfer": { "flip": 2.0 }, "bodies": [body] }), "transfer", "[0, 1]"),
        (
            json!({ "obstacles": [{ "sphere": { "center": [5.0, 5.0, 5.0], "radius": 0.1 } }], "bodies": [body] }),
            "obstacles[0]",
            "covers no cell centre",
        ),
        (
            json!({ "obstacles": [{ "capsule": { "a": [0.5, 0.5, 0.5], "b": [0.5, 0.5, 0.5], "radius": 0.1 } }], "bodies": [body] }),
            "obstacles[0]",
            "coincide",
        ),
        (json!({ "preset": "drop-3d", "bodies": [body] }), "bodies", "not both"),
        (
            json!({ "preset": "drop-3d", "gravity": [0.0, -1.0, 0.0] }),
            "gravity",
            "belongs to a scene of `bodies`",
        ),
        (
            json!({ "preset": "drop-3d", "obstacles": [{ "sphere": { "center": [0.5, 0.5, 0.5], "radius": 0.1 } }] }),
            "obstacles",
            "belongs to",
        ),
        (json!({ "resolution": 16 }), "preset", "or `[[scene.bodies]]`"),
        (json!({ "bodies": [] }), "preset", "or `[[scene.bodies]]`"),
    ];
    for (value, field, part) in cases {
        let (f, message) = refusal(value.clone());
        assert_eq!(f, field, "{value}: {message}");
        assert!(message.contains(part), "{value}: {message}");
    }
    let typo = (KIND.build)(
        &json!({ "bodies": [{ "shape": boxed([0.5, 0.5, 0.5], [0.1, 0.1, 0.1]), "velocty": [0.0, 0.0, 0.0] }] }),
        &testdata(),
    );
    assert!(typo.err().expect("refused").to_string().contains("unknown field `velocty`"));
}

/// Obstacle meshes make the cells inside them solid, as the equal box obstacle does.
#[test]
fn an_obstacle_mesh_makes_the_cells_of_the_equal_box_solid() {
    let body = json!({ "shape": boxed([0.5, 0.8, 0.5], [0.1, 0.1, 0.1]) });
    let (by_mesh, particles) = build3(json!({
        "resolution": 16,
        "bodies": [body],
        "obstacle_meshes": [{ "mesh": "cube.obj", "scale": 0.25, "translate": [0.5, 0.25, 0.5] }],
    }))
    .expect("builds");
    let (by_box, _) =
        build3(json!({ "resolution": 16, "bodies": [body], "obstacles": [boxed([0.5, 0.25, 0.5], [0.125, 0.125, 0.125])] }))
            .expect("builds");
    assert_eq!(by_mesh.sim.solid(), by_box.sim.solid());
    assert_eq!(by_mesh.sim.solid().iter().filter(|s| **s).count(), 18 * 18 * 18 - 16 * 16 * 16 + 4 * 4 * 4);
    // Drawn where the box is (the box prop's corners), the shape obstacle as a prop.
    assert!(by_mesh.meshes.len() == 1 && by_box.meshes.is_empty());
    let corners = |p: &[[f64; 3]]| {
        let lo = p.iter().fold([f64::INFINITY; 3], |a, q| std::array::from_fn(|k| a[k].min(q[k])));
        let hi = p.iter().fold([f64::NEG_INFINITY; 3], |a, q| std::array::from_fn(|k| a[k].max(q[k])));
        (lo, hi)
    };
    let drawn = by_box.context(&particles).props[1];
    assert_eq!(by_mesh.context(&particles).mesh_props, by_mesh.meshes);
    assert_eq!(drawn, {
        let (lo, hi) = corners(&by_mesh.meshes[0].positions);
        Prop::Cuboid { lo, hi }
    });
}
