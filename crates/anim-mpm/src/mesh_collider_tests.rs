//! Mesh obstacles: the level set of a mesh cube against the equal box obstacle (inside nodes,
//! distances, face normals), a body landing on a mesh obstacle, and every refusal naming its
//! field.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use crate::bodies;
use crate::mesh_collider::{BAND, MAX_NODES, MeshCollider};
use crate::scenes::{MpmScene, Scene};
use crate::{Boundary, Collider, MpmParams, Shape, Vector};
use anim_core::scene::BuildContext;
use anim_core::solver::Solver;
use anim_core::surface::ClosedSurface;
use serde_json::{Value, json};

use crate::bodies_tests::{body_height_and_speed, cube, jelly, refused, testdata, three};

/// The box `[lo, hi]` as 12 outward triangles.
fn box_surface(lo: [f64; 3], hi: [f64; 3]) -> ClosedSurface {
    let (positions, triangles) = anim_core::surface::cuboid(lo, hi);
    ClosedSurface::new(positions, triangles).expect("a closed box")
}

#[test]
fn a_mesh_cube_is_the_equal_box_obstacle_on_the_grid() {
    // Faces between nodes (h = 1/32): x 11.3 h .. 20.9 h, y 6.7 h .. 16.3 h, z 11.1 h .. 20.7 h.
    let (lo, hi) = ([0.353, 0.21, 0.347], [0.653, 0.51, 0.647]);
    let params = MpmParams::with_resolution(32);
    let h = params.h();
    let mesh = MeshCollider::new(&box_surface(lo, hi), &params, Boundary::Slip).expect("builds");
    let center: [f64; 3] = std::array::from_fn(|a| 0.5 * (lo[a] + hi[a]));
    let half: [f64; 3] = std::array::from_fn(|a| 0.5 * (hi[a] - lo[a]));
    let shape = Shape::Box { center, half_extents: half };
    let grid = Collider::fixed(shape, Boundary::Slip).compile(0, 3).expect("valid");
    // The table's box: the bounds widened by 4 cells.
    assert_eq!(mesh.node_box(), ([7, 2, 7], [19, 20, 19]));
    let band = BAND as f64 * h;
    let (mut inside, mut normals) = (0, 0);
    for k in 0..=32 {
        for j in 0..=32 {
            for i in 0..=32 {
                let x = Vector::<3>::new(i as f32, j as f32, k as f32) * h as f32;
                let (phi, _) = grid.sdf(&x, 0.0);
                let Some(d) = mesh.distance([i, j, k]) else {
                    assert!(phi > 0.0, "node {:?} outside the table is inside the box", [i, j, k]);
                    continue;
                };
                assert_eq!(d <= 0.0, phi <= 0.0, "node {:?}: mesh {d}, box {phi}", [i, j, k]);
                inside += usize::from(d <= 0.0);
                // The exact distance within the band, the band beyond (1e-6 m, f32 round-off).
                let want = f64::from(phi).signum() * f64::from(phi).abs().min(band);
                assert!((f64::from(d) - want).abs() < 1e-6, "node {:?}: mesh {d}, box {want}", [i, j, k]);
                // Normals at inside nodes whose nearest face is the nearest of their neighbours
                // too (its margin over the next face above two cells), within the band.
                let p = [i, j, k].map(|c| c as f64 * h);
                let mut q: Vec<(f64, usize)> =
                    (0..3).map(|a| ((p[a] - center[a]).abs() - half[a], a)).collect();
                q.sort_by(|a, b| b.0.total_cmp(&a.0));
                if phi <= 0.0 && q[0].0 - q[1].0 > 2.0 * h && -q[0].0 < band - 1.5 * h {
                    let a = q[0].1;
                    let mut face = [0.0f32; 3];
                    face[a] = (p[a] - center[a]).signum() as f32;
                    let n = mesh.normal([i, j, k]).expect("inside");
                    let err = (0..3).map(|c| (n[c] - face[c]).abs()).fold(0.0, f32::max);
                    assert!(err < 1e-4, "node {:?}: normal {n:?}, face {face:?}", [i, j, k]);
                    normals += 1;
                }
            }
        }
    }
    // 9 x 10 x 9 nodes inside (x 12..=20, y 7..=16, z 12..=20).
    assert_eq!(inside, 9 * 10 * 9);
    assert!(normals > 50, "{normals} normals checked");
    // Deeper than the band, inside: no normal, the node is stopped.
    let deep = MeshCollider::new(&box_surface([0.2; 3], [0.8; 3]), &params, Boundary::Slip).unwrap();
    assert_eq!(deep.distance([16, 16, 16]), Some(-(band as f32)));
    assert_eq!(deep.normal([16, 16, 16]), Some([0.0; 3]));
    assert_eq!(deep.normal([2, 2, 2]), None);
}

#[test]
fn bodies_land_on_a_mesh_obstacle_without_passing_through() {
    // The slab x, z in [0.2, 0.8], y up to 0.4 (cube.obj is the unit cube), below the domain's
    // floor too: the table is clipped to the domain.
    let top = 0.4;
    let mut s = three(json!({
        "resolution": 16,
        "obstacle_meshes": [{ "mesh": "cube.obj", "scale": 0.6, "translate": [0.2, -0.2, 0.2] }],
        "boundary": { "separate": { "friction": 0.5 } },
        "bodies": [
            { "shape": cube([0.35, 0.6, 0.5], 0.1), "material": jelly() },
            { "shape": cube([0.65, 0.6, 0.5], 0.1), "material": { "snow": {} } },
        ],
    }));
    let h = 1.0 / 16.0;
    let mesh = s.sim.mesh_colliders()[0].clone();
    let body = body_height_and_speed;
    let mut lowest = f32::MAX;
    let mut deepest = f64::MAX;
    let (mut bottom, mut rebound) = (f64::MAX, f64::MIN);
    for _ in 0..500 {
        s.sim.step(&mut s.state, 1e-3).unwrap();
        lowest = s.state.x.chunks_exact(3).map(|p| p[1]).fold(lowest, f32::min);
        for p in s.state.x.chunks_exact(3) {
            if let Some(phi) = mesh.interpolate(std::array::from_fn(|a| f64::from(p[a]))) {
                deepest = deepest.min(phi);
            }
        }
        let (y, _) = body(&s, 0);
        if y < bottom {
            (bottom, rebound) = (y, y);
        }
        rebound = rebound.max(y);
    }
    // Without the obstacle the bodies would fall to the domain's floor (y = 3 h).
    assert!(f64::from(lowest) > top - 0.5 * h, "lowest particle at y = {lowest}");
    assert!(deepest > -0.5 * h, "a particle reached {deepest} m inside the obstacle");
    assert!(bottom < top + 0.1 && rebound > bottom + 0.5 * h, "{bottom} {rebound}");
    let (snow_y, snow_speed) = body(&s, 1);
    assert!(snow_y > top && snow_y < top + 0.1, "snow centre at y = {snow_y}");
    assert!(snow_speed < 0.05, "snow's mean speed {snow_speed}");
}

#[test]
fn mesh_obstacles_are_refused_by_field() {
    let scene = |mesh: Value, body: Value| json!({ "resolution": 32, "obstacle_meshes": [mesh], "bodies": [{ "shape": body, "material": jelly() }] });
    let slab = json!({ "mesh": "cube.obj", "scale": 0.3, "translate": [0.35, 0.1, 0.35] });
    let above = cube([0.5, 0.6, 0.5], 0.1);
    assert!(matches!(
        bodies::build(
            &serde_json::from_value(scene(slab.clone(), above.clone())).unwrap(),
            &BuildContext { base: Some(testdata()) }
        ),
        Ok(MpmScene::Three(_))
    ));
    // A body starting inside: the body and the obstacle named.
    let (field, message) = refused(scene(slab.clone(), cube([0.5, 0.3, 0.5], 0.1)));
    assert!(field == "bodies[0]" && message.contains("obstacle_meshes[0]"), "{field}: {message}");
    // Open, missing and non-OBJ files: the mesh field and the file.
    for (file, words) in [("open_cube.obj", "edge"), ("no-such.obj", "no-such.obj"), ("cube.msh", ".obj")] {
        let (field, message) = refused(scene(json!({ "mesh": file }), above.clone()));
        assert_eq!(field, "obstacle_meshes[0].mesh", "{message}");
        assert!(message.contains(file) && message.to_lowercase().contains(words), "{message}");
    }
    // The placement, by field.
    let (field, _) = refused(scene(json!({ "mesh": "cube.obj", "scale": -1.0 }), above.clone()));
    assert_eq!(field, "obstacle_meshes[0].scale");
    let (field, message) =
        refused(scene(json!({ "mesh": "cube.obj", "translate": [5.0, 5.0, 5.0] }), above.clone()));
    assert!(field == "obstacle_meshes[0]" && message.contains("outside the domain"), "{message}");
    let (_, message) = refused(scene(json!({ "mesh": "cube.obj", "colour": "red" }), above.clone()));
    assert!(message.contains("colour"), "{message}");
    // `cell` sets the distance field of the particle and element kinds; here the grid is used.
    let (field, message) = refused(scene(json!({ "mesh": "cube.obj", "cell": 0.01 }), above.clone()));
    assert!(field == "obstacle_meshes[0].cell" && message.contains("own grid"), "{field}: {message}");
    // A table past the cap: 0.051 to 0.951 m at resolution 300 is nodes 15.3 to 285.3, widened
    // by 4: nodes 11 to 290, 280 per axis.
    let mut big =
        scene(json!({ "mesh": "cube.obj", "scale": 0.9, "translate": [0.051, 0.051, 0.051] }), above.clone());
    big["resolution"] = json!(300);
    let (field, message) = refused(big);
    assert_eq!(field, "obstacle_meshes[0]");
    let nodes = 280usize.pow(3);
    assert!(message.contains(&nodes.to_string()) && message.contains(&MAX_NODES.to_string()), "{message}");
    // 2D scenes and presets take none.
    let mut flat = scene(slab.clone(), above);
    flat["dim"] = json!(2);
    let (field, message) = refused(flat);
    assert!(field == "obstacle_meshes" && message.contains("3D"), "{field}: {message}");
    let (field, message) = refused(json!({ "preset": "snowball", "obstacle_meshes": [slab] }));
    assert!(field == "obstacle_meshes" && message.contains("snowball"), "{field}: {message}");
}

/// A scene with a mesh obstacle (its table built and its steps run in a pool of `threads`).
fn landing_in(threads: usize) -> Scene<3> {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("pool");
    pool.install(|| {
        let mut s = three(json!({
            "resolution": 16,
            "obstacle_meshes": [{ "mesh": "cube.obj", "scale": 0.5, "rotate": [0.3, 0.2, 0.1],
                                  "translate": [0.25, -0.1, 0.25] }],
            "boundary": { "separate": { "friction": 0.3 } },
            "bodies": [{ "shape": cube([0.45, 0.65, 0.5], 0.1), "material": jelly() }],
        }));
        for _ in 0..150 {
            s.sim.step(&mut s.state, 2e-3).unwrap();
        }
        s
    })
}

#[test]
fn a_scene_with_a_mesh_obstacle_is_bitwise_identical_for_any_thread_count() {
    let one = landing_in(1);
    let h = 1.0 / 16.0;
    // The body reached the obstacle: some particle is within a cell of its surface.
    let mesh = &one.sim.mesh_colliders()[0];
    let near = one
        .state
        .x
        .chunks_exact(3)
        .filter_map(|p| mesh.interpolate(std::array::from_fn(|a| f64::from(p[a]))));
    assert!(near.fold(f64::MAX, f64::min) < h, "the body never came near the obstacle");
    for threads in [2, 3] {
        let other = landing_in(threads);
        assert!(one.state.x.iter().zip(&other.state.x).all(|(a, b)| a.to_bits() == b.to_bits()), "{threads}");
        assert_eq!(one.state, other.state, "{threads} threads");
    }
}

/// The scene's picture holds each mesh obstacle's placed surface, in the frames' coordinates.
#[test]
fn the_context_draws_a_mesh_obstacle_where_it_is() {
    let params = json!({
        "resolution": 16,
        "obstacle_meshes": [{ "mesh": "cube.obj", "scale": 0.6, "translate": [0.2, -0.2, 0.2] }],
        "bodies": [{ "shape": cube([0.5, 0.6, 0.5], 0.1), "material": jelly() }],
    });
    let scene = (crate::kind::KIND.build)(&params, &BuildContext { base: Some(testdata()) }).expect("builds");
    let context = scene.context();
    assert_eq!(context.mesh_props.len(), 1);
    let mesh = &context.mesh_props[0];
    assert_eq!(mesh.triangles.len(), 12);
    let lo = mesh.positions.iter().fold([f64::INFINITY; 3], |a, p| std::array::from_fn(|k| a[k].min(p[k])));
    let hi =
        mesh.positions.iter().fold([f64::NEG_INFINITY; 3], |a, p| std::array::from_fn(|k| a[k].max(p[k])));
    let close = |a: [f64; 3], b: [f64; 3]| a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-12);
    assert!(close(lo, [0.2, -0.2, 0.2]) && close(hi, [0.8, 0.4, 0.8]), "{lo:?} {hi:?}");
}
