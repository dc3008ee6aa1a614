//! The user's bodies in a `pbd` scene file: masses from the densities, pins, resting contacts,
//! contacts between bodies, and the errors naming their field and file.

use super::*;
use crate::PbdModel;
use anim_core::solver::Solver;
use std::path::{Path, PathBuf};

/// A fresh folder for one test's files.
pub(super) fn folder(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("anim-pbd-bodies-{}-{test}", std::process::id()));
    std::fs::remove_dir_all(&dir).ok();
    std::fs::create_dir_all(&dir).expect("temporary folder");
    dir
}

/// Writes a TetGen pair `name.node`, `name.ele` of the `n^3` cells of side `h` from `origin`, six
/// tetrahedra each; returns the `.node` file's name.
fn write_tet_box(dir: &Path, name: &str, n: usize, origin: [f64; 3], h: f64) -> String {
    let (p, t) = crate::shapes::tet_box([n; 3], origin, h);
    let mut node = format!("{} 3 0 0\n", p.len());
    for (i, x) in p.iter().enumerate() {
        node += &format!("{i} {} {} {}\n", x[0], x[1], x[2]);
    }
    let mut ele = format!("{} 4 0\n", t.len());
    for (i, e) in t.iter().enumerate() {
        ele += &format!("{i} {} {} {} {}\n", e[0], e[1], e[2], e[3]);
    }
    std::fs::write(dir.join(format!("{name}.node")), node).expect("write");
    std::fs::write(dir.join(format!("{name}.ele")), ele).expect("write");
    format!("{name}.node")
}

/// Writes an OBJ square grid of `n x n` vertices and side `side` in the plane `z = 0` centred on
/// the origin (vertex `ix + n iy`); returns its name.
pub(super) fn write_cloth(dir: &Path, name: &str, n: usize, side: f64) -> String {
    let mut text = String::new();
    for iy in 0..n {
        for ix in 0..n {
            let s = |i: usize| -side / 2.0 + side * i as f64 / (n - 1) as f64;
            text += &format!("v {} {} 0\n", s(ix), s(iy));
        }
    }
    for iy in 0..n - 1 {
        for ix in 0..n - 1 {
            let a = iy * n + ix + 1;
            text += &format!("f {a} {} {}\nf {a} {} {}\n", a + 1, a + n + 1, a + n + 1, a + n);
        }
    }
    let file = format!("{name}.obj");
    std::fs::write(dir.join(&file), text).expect("write");
    file
}

fn scene(value: serde_json::Value) -> PbdSceneParams {
    anim_core::scene::params(&value).expect("reads")
}

fn build_in(dir: &Path, value: serde_json::Value) -> Result<(PbdSimulation, State), BuildError> {
    bodies::build_bodies(&scene(value), &BuildContext { base: Some(dir) })
}

pub(super) fn built(dir: &Path, value: serde_json::Value) -> (PbdSimulation, State) {
    build_in(dir, value).expect("builds")
}

/// The message of the refusal of `value`, through the kind's builder.
pub(super) fn refusal(dir: &Path, value: serde_json::Value) -> String {
    (KIND.build)(&value, &BuildContext { base: Some(dir) }).err().expect("refused").to_string()
}

fn total_mass(model: &PbdModel) -> f64 {
    model.particles().iter().map(|p| p.mass).sum()
}

#[test]
fn a_soft_body_weighs_its_density_times_its_volume_and_a_cloth_its_area_density_times_its_area() {
    let dir = folder("mass");
    let cube = write_tet_box(&dir, "cube", 3, [0.0; 3], 1.0 / 3.0);
    let cloth = write_cloth(&dir, "cloth", 6, 1.0);
    // The unit cube scaled by 0.5: 0.125 m^3 at 800 kg/m^3 is 100 kg; the unit square scaled by
    // 2: 4 m^2 at 0.3 kg/m^2 is 1.2 kg.
    let (sim, _) = built(
        &dir,
        serde_json::json!({ "bodies": [
            { "mesh": cube, "material": { "density": 800.0 }, "scale": 0.5 },
        ] }),
    );
    let m = total_mass(sim.model());
    assert!((m - 100.0).abs() < 1e-10, "{m}");
    assert_eq!(sim.model().num_particles(), 64);
    let (sim, _) = built(
        &dir,
        serde_json::json!({ "bodies": [
            { "mesh": cloth, "material": { "density": 0.3 }, "scale": 2.0, "translate": [0.0, 0.0, 1.0] },
        ] }),
    );
    let m = total_mass(sim.model());
    assert!((m - 1.2).abs() < 1e-12, "{m}");
    // Both in one scene: the masses add, the cloth's particles after the cube's.
    let (sim, _) = built(
        &dir,
        serde_json::json!({ "bodies": [
            { "mesh": cube, "material": { "density": 800.0 }, "scale": 0.5 },
            { "mesh": cloth, "material": { "density": 0.3 }, "scale": 2.0, "translate": [0.0, 0.0, 1.0] },
        ] }),
    );
    assert!((total_mass(sim.model()) - 101.2).abs() < 1e-9);
    assert_eq!(sim.model().num_particles(), 64 + 36);
    assert_eq!(sim.model().contact_bodies().len(), 2);
    assert_eq!(sim.model().contact_bodies()[1].particles, (64, 100));
    assert!(sim.model().contact_bodies()[0].closed && !sim.model().contact_bodies()[1].closed);
}

#[test]
fn the_placement_scales_rotates_and_translates_the_mesh() {
    let dir = folder("placement");
    let cloth = write_cloth(&dir, "cloth", 3, 1.0);
    // Vertex 2 is (0.5, -0.5, 0): scaled by 2, yawed a quarter turn, lifted by 1.
    let (_, state) = built(
        &dir,
        serde_json::json!({ "bodies": [{
            "mesh": cloth, "material": { "density": 1.0 }, "scale": 2.0,
            "rotate": [0.0, 0.0, std::f64::consts::FRAC_PI_2], "translate": [0.0, 0.0, 1.0],
            "velocity": [0.5, 0.0, 0.0],
        }] }),
    );
    let x = &state.x[6..9];
    assert!((x[0] - 1.0).abs() < 1e-12 && (x[1] - 1.0).abs() < 1e-12 && (x[2] - 1.0).abs() < 1e-12, "{x:?}");
    assert!(state.v.chunks(3).all(|v| v == [0.5, 0.0, 0.0]));
}

#[test]
fn pinned_vertices_stay_put_and_start_at_rest() {
    let dir = folder("pins");
    let cloth = write_cloth(&dir, "cloth", 9, 1.0);
    // Corner 0 by index, corner 8 by a box: the first row's ends.
    let (mut sim, mut state) = built(
        &dir,
        serde_json::json!({ "bodies": [{
            "mesh": cloth,
            "material": { "density": 0.2, "bending": { "isometric": { "compliance": 1.0 } } },
            "translate": [0.0, 0.0, 1.0],
            "velocity": [0.0, 1.0, 0.0],
            "pin": { "vertices": [0], "box": { "min": [0.49, -0.51, 0.9], "max": [0.51, -0.49, 1.1] } },
        }] }),
    );
    let pinned: Vec<usize> = (0..81).filter(|&i| sim.model().inverse_masses()[i] == 0.0).collect();
    assert_eq!(pinned, [0, 8]);
    let before = state.x.clone();
    for &i in &pinned {
        assert_eq!(&state.v[3 * i..3 * i + 3], &[0.0; 3]);
    }
    let mut lowest = [f64::INFINITY; 2];
    for _ in 0..60 {
        sim.step(&mut state, 1.0 / 60.0).expect("step");
        for (low, i) in lowest.iter_mut().zip([72, 80]) {
            *low = low.min(state.x[3 * i + 2]);
        }
    }
    for &i in &pinned {
        assert_eq!(state.x[3 * i..3 * i + 3], before[3 * i..3 * i + 3], "pinned vertex {i} moved");
    }
    // The free corners of the last row swung down, a side's length below the pins.
    for low in lowest {
        assert!(low < 0.05, "{low}");
    }
}

#[test]
fn a_soft_body_comes_to_rest_on_the_ground_at_the_thickness() {
    let dir = folder("rest");
    let cube = write_tet_box(&dir, "cube", 3, [-0.15, -0.15, 0.0], 0.1);
    let thickness = 0.01;
    let (mut sim, mut state) = built(
        &dir,
        serde_json::json!({
            "obstacles": [{ "plane": { "point": [0.0, 0.0, 0.0], "normal": [0.0, 0.0, 1.0] } }],
            "friction": 0.5,
            "thickness": thickness,
            "bodies": [{
                "mesh": cube,
                "material": { "density": 500.0, "stretch": { "compliance": 1e-5 } },
                "translate": [0.0, 0.0, 0.2],
            }],
        }),
    );
    let mut lowest = f64::INFINITY;
    for step in 0..120 {
        sim.step(&mut state, 1.0 / 60.0).expect("step");
        let z = state.x.chunks(3).map(|p| p[2]).fold(f64::INFINITY, f64::min);
        if step >= 30 {
            lowest = lowest.min(z);
        }
    }
    // It fell 0.2 m and stays above the ground: never more than a tenth of the thickness inside
    // it, and at rest within 1% of the thickness.
    assert!(lowest > 0.9 * thickness, "lowest {lowest}");
    let z = state.x.chunks(3).map(|p| p[2]).fold(f64::INFINITY, f64::min);
    assert!((z - thickness).abs() < 0.01 * thickness, "{z}");
    let speed = state.v.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    assert!(speed < 1e-2, "{speed}");
}

/// A cloth dropped on a soft box rests on its top, `thickness` above it; without contacts
/// between bodies it falls through the box to the ground.
#[test]
fn a_cloth_rests_on_a_soft_body_unless_bodies_do_not_collide() {
    let dir = folder("drape");
    let cube = write_tet_box(&dir, "cube", 3, [-0.3, -0.3, 0.0], 0.2);
    let cloth = write_cloth(&dir, "cloth", 11, 0.4);
    let thickness = 0.01;
    let run = |contacts: bool, method: &str| {
        let (mut sim, mut state) = built(
            &dir,
            serde_json::json!({
                "method": method,
                "obstacles": [{ "plane": { "point": [0.0, 0.0, 0.0], "normal": [0.0, 0.0, 1.0] } }],
                "friction": 0.5,
                "thickness": thickness,
                "body_contacts": contacts,
                "bodies": [
                    { "mesh": cube, "material": { "density": 200.0 }, "translate": [0.0, 0.0, 0.0105] },
                    {
                        "mesh": cloth,
                        "material": { "density": 0.2, "bending": { "isometric": { "compliance": 1.0 } } },
                        "translate": [0.0, 0.0, 0.8],
                    },
                ],
            }),
        );
        for _ in 0..90 {
            sim.step(&mut state, 1.0 / 60.0).expect("step");
        }
        let cloth_z: Vec<f64> = state.x[3 * 64..].chunks(3).map(|p| p[2]).collect();
        let top = state.x[..3 * 64].chunks(3).map(|p| p[2]).fold(f64::NEG_INFINITY, f64::max);
        (cloth_z, top)
    };
    // The box's top is at 0.61; the cloth (0.4 m wide, over a 0.6 m box) lies flat on it, with
    // XPBD's multipliers and with PBD's projections.
    for method in ["xpbd", "pbd"] {
        let (cloth, top) = run(true, method);
        let lowest = cloth.iter().copied().fold(f64::INFINITY, f64::min);
        assert!((top - 0.6105).abs() < 0.005, "{method}: box top {top}");
        assert!(
            lowest > top + 0.9 * thickness && lowest < top + 1.1 * thickness,
            "{method}: cloth {lowest}, top {top}"
        );
    }
    let (cloth, _) = run(false, "xpbd");
    let highest = cloth.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    assert!(highest < 0.1, "without contacts between bodies the cloth falls through: {highest}");
}

#[test]
fn a_scene_of_bodies_reads_back_as_it_was_written() {
    let value = serde_json::json!({
        "method": "xpbd", "iterations": 3, "substeps": 6,
        "obstacles": [{ "sphere": { "center": [0.0, 0.0, 0.5], "radius": 0.5 } }],
        "friction": 0.4, "restitution": 0.1, "thickness": 0.02, "gravity": [0.0, 0.0, -1.0],
        "body_contacts": false,
        "bodies": [
            { "type": "soft", "mesh": "a.msh", "material": { "density": 100.0, "volume": { "compliance": 1e-6 } },
              "scale": 2.0, "rotate": [0.1, 0.2, 0.3], "translate": [1.0, 2.0, 3.0], "velocity": [0.0, 0.0, -1.0] },
            { "mesh": "b.obj", "material": { "density": 0.1, "stretch": { "compliance": 1e-6, "damping": 0.1 },
              "bending": { "dihedral": { "compliance": 2.0 } } },
              "pin": { "vertices": [3], "box": { "min": [0.0, 0.0, 0.0], "max": [1.0, 1.0, 1.0] } } },
        ],
    });
    let p = scene(value.clone());
    assert_eq!(p.bodies[0].kind(), Some(BodyType::Soft));
    assert_eq!(p.bodies[1].kind(), Some(BodyType::Cloth));
    let written = serde_json::to_value(&p).expect("writes");
    assert_eq!(scene(written.clone()), p);
    // Defaults are left out; the constraint parameters are written whole.
    assert_eq!(written["bodies"][1].as_object().expect("table").len(), 3, "{written}");
    assert_eq!(written["bodies"][1]["material"]["stretch"]["stiffness"], 1.0);
    assert_eq!(written["obstacles"], value["obstacles"]);
}

#[test]
fn the_kind_of_a_body_follows_its_file_unless_given() {
    let body = |mesh: &str, cell: Option<f64>| -> BodySpec {
        serde_json::from_value(
            serde_json::json!({ "mesh": mesh, "cell": cell, "material": { "density": 1.0 } }),
        )
        .expect("reads")
    };
    assert_eq!(body("a.msh", None).kind(), Some(BodyType::Soft));
    assert_eq!(body("a.1.ele", None).kind(), Some(BodyType::Soft));
    assert_eq!(body("a.OBJ", None).kind(), Some(BodyType::Cloth));
    assert_eq!(body("a.obj", Some(0.1)).kind(), Some(BodyType::Soft));
    assert_eq!(body("a.stl", None).kind(), None);
}

#[test]
fn a_pin_out_of_range_names_the_field_the_index_and_the_vertex_count() {
    let dir = folder("pin-range");
    let cloth = write_cloth(&dir, "cloth", 4, 1.0);
    let msg = refusal(
        &dir,
        serde_json::json!({ "bodies": [
            { "mesh": cloth, "material": { "density": 1.0 } },
            { "mesh": cloth, "material": { "density": 1.0 }, "pin": { "vertices": [0, 16] } },
        ] }),
    );
    let file = dir.join("cloth.obj");
    assert_eq!(
        msg,
        format!(
            "field `bodies[1].pin.vertices[1]`: vertex 16 is out of range: {} has 16 vertices (0 to 15)",
            file.display()
        )
    );
    // A box that holds no vertex of the placed body names the field too.
    let msg = refusal(
        &dir,
        serde_json::json!({ "bodies": [{
            "mesh": cloth, "material": { "density": 1.0 }, "translate": [0.0, 0.0, 1.0],
            "pin": { "box": { "min": [-1.0, -1.0, -0.1], "max": [1.0, 1.0, 0.1] } },
        }] }),
    );
    assert!(
        msg.starts_with(
            "field `bodies[0].pin`: the box from [-1.0, -1.0, -0.1] to [1.0, 1.0, 0.1] holds no vertex"
        ),
        "{msg}"
    );
    assert!(msg.ends_with("spans [-0.5, -0.5, 1.0] to [0.5, 0.5, 1.0])"), "{msg}");
    // A pin table with neither `vertices` nor `box` pins nothing: refused, as in every kind.
    let msg = refusal(
        &dir,
        serde_json::json!({ "bodies": [{ "mesh": cloth, "material": { "density": 1.0 }, "pin": {} }] }),
    );
    assert_eq!(msg, "field `bodies[0].pin`: give `vertices`, `box` or both");
}

#[test]
fn a_missing_or_broken_mesh_file_is_named() {
    let dir = folder("missing");
    let msg = refusal(
        &dir,
        serde_json::json!({ "bodies": [{ "mesh": "nowhere.msh", "material": { "density": 1.0 } }] }),
    );
    let file = dir.join("nowhere.msh");
    assert!(msg.starts_with(&format!("field `bodies[0].mesh`: {}", file.display())), "{msg}");
    let msg = refusal(
        &dir,
        serde_json::json!({ "bodies": [{ "mesh": "thing.stl", "material": { "density": 1.0 } }] }),
    );
    assert!(
        msg.starts_with("field `bodies[0].mesh`: ") && msg.contains("thing.stl: unknown mesh format"),
        "{msg}"
    );
    // A triangle of zero area names the file, the triangle and its vertices.
    std::fs::write(dir.join("flat.obj"), "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nf 1 2 4\nf 1 2 3\n")
        .expect("write");
    let msg = refusal(
        &dir,
        serde_json::json!({ "bodies": [{ "mesh": "flat.obj", "material": { "density": 1.0 } }] }),
    );
    assert_eq!(
        msg,
        format!(
            "field `bodies[0].mesh`: {}: triangle 1 (vertices 0, 1, 2) has zero area",
            dir.join("flat.obj").display()
        )
    );
    // An inverted tetrahedron names the file, the tetrahedron and its vertices.
    std::fs::write(dir.join("flip.node"), "5 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n3 0 0 1\n4 1 1 1\n")
        .expect("write");
    std::fs::write(dir.join("flip.ele"), "2 4 0\n0 0 1 2 3\n1 1 3 2 4\n").expect("write");
    let msg = refusal(
        &dir,
        serde_json::json!({ "bodies": [{ "mesh": "flip.ele", "material": { "density": 1.0 } }] }),
    );
    assert!(
        msg.starts_with(&format!(
            "field `bodies[0].mesh`: {}: tetrahedron 1 (vertices 1, 3, 2, 4) is inverted",
            dir.join("flip.ele").display()
        )),
        "{msg}"
    );
    // A parse error names the file and its line.
    std::fs::write(dir.join("bad.obj"), "v 0 0 0\nv 1 0 zero\n").expect("write");
    let msg = refusal(
        &dir,
        serde_json::json!({ "bodies": [{ "mesh": "bad.obj", "material": { "density": 1.0 } }] }),
    );
    assert!(msg.contains("bad.obj:2:"), "{msg}");
}

/// A placed mesh too large for its volumes to be finite (`1e330 m^3`) is refused naming the
/// scale, not reported as a zero-volume tetrahedron or a zero-area triangle.
#[test]
fn a_scale_too_large_to_measure_the_mesh_is_named() {
    let dir = folder("huge");
    let cube = write_tet_box(&dir, "cube", 1, [0.0; 3], 1.0);
    let cloth = write_cloth(&dir, "cloth", 3, 1.0);
    for (mesh, scale, span) in [(&cube, 1e110, "1e110"), (&cloth, 1e160, "1e160")] {
        let msg = refusal(
            &dir,
            serde_json::json!({ "bodies": [
                { "mesh": cloth, "material": { "density": 1.0 } },
                { "mesh": mesh, "material": { "density": 1.0 }, "scale": scale },
            ] }),
        );
        assert_eq!(
            msg,
            format!(
                "field `bodies[1].scale`: {}: placed, the mesh spans {span} m, too large to measure its \
                 volumes (the scale is too large)",
                dir.join(mesh).display()
            )
        );
    }
}

#[test]
fn obstacles_pbd_cannot_collide_with_are_refused_by_index_and_shape() {
    let dir = folder("obstacles");
    let cloth = write_cloth(&dir, "cloth", 3, 1.0);
    let body = serde_json::json!({ "mesh": cloth, "material": { "density": 1.0 } });
    // A shape anim-core does not have.
    let msg = refusal(
        &dir,
        serde_json::json!({ "bodies": [body], "obstacles": [
            { "plane": { "point": [0.0, 0.0, 0.0], "normal": [0.0, 0.0, 1.0] } },
            { "cylinder": { "a": [0.0, 0.0, 0.0], "b": [0.0, 0.0, 1.0], "radius": 0.1 } },
        ] }),
    );
    assert!(msg.starts_with("field `obstacles[1]`: unknown variant `cylinder`"), "{msg}");
    // A shape without a solid to collide with: a sphere of no radius, a plane without a normal.
    let msg = refusal(
        &dir,
        serde_json::json!({ "bodies": [body], "obstacles": [{ "sphere": { "center": [0.0, 0.0, 0.0], "radius": 0.0 } }] }),
    );
    assert_eq!(msg, "field `obstacles[0]`: sphere: sphere radius must be positive and finite, got 0");
    let msg = refusal(
        &dir,
        serde_json::json!({ "bodies": [body], "obstacles": [
            { "box": { "center": [0.0, 0.0, 0.0], "half_extents": [1.0, 1.0, 1.0] } },
            { "plane": { "point": [0.0, 0.0, 0.0], "normal": [0.0, 0.0, 0.0] } },
        ] }),
    );
    assert!(msg.starts_with("field `obstacles[1]`: plane: plane normal must be non-zero"), "{msg}");
    // Every shape PBD collides with builds.
    let (sim, _) = built(
        &dir,
        serde_json::json!({ "bodies": [body], "obstacles": [
            { "plane": { "point": [0.0, 0.0, -1.0], "normal": [0.0, 0.3, 1.0] } },
            { "sphere": { "center": [0.0, 0.0, -2.0], "radius": 0.5 } },
            { "box": { "center": [2.0, 0.0, -2.0], "half_extents": [0.5, 0.5, 0.5] } },
            { "capsule": { "a": [-2.0, 0.0, -2.0], "b": [-2.0, 1.0, -2.0], "radius": 0.2 } },
        ] }),
    );
    assert_eq!(sim.model().colliders().len(), 4);
}

#[test]
fn fields_that_do_not_fit_the_body_or_the_scene_are_refused_by_name() {
    let dir = folder("fields");
    let cloth = write_cloth(&dir, "cloth", 3, 1.0);
    let cube = write_tet_box(&dir, "cube", 1, [0.0; 3], 1.0);
    let cases = [
        (
            serde_json::json!({ "preset": "flag", "bodies": [{ "mesh": cloth, "material": { "density": 1.0 } }] }),
            "field `preset`: give `preset` or `bodies`, not both",
        ),
        (serde_json::json!({ "iterations": 3 }), "field `preset`: a pbd scene needs a `preset`"),
        (
            serde_json::json!({ "preset": "flag", "friction": 0.3 }),
            "field `friction`: only a scene with `bodies` takes `friction`; a preset brings its own",
        ),
        (
            serde_json::json!({ "preset": "flag", "obstacles": [] , "gravity": [0.0, 0.0, -1.0] }),
            "field `gravity`: only a scene with `bodies` takes `gravity`",
        ),
        (
            serde_json::json!({ "resolution": 8, "bodies": [{ "mesh": cloth, "material": { "density": 1.0 } }] }),
            "field `resolution`: a scene with `bodies` takes no `resolution`",
        ),
        (
            serde_json::json!({ "bodies": [{ "type": "cloth", "mesh": cube, "material": { "density": 1.0 } }] }),
            "field `bodies[0].type`: a cloth is made of an OBJ surface",
        ),
        (
            serde_json::json!({ "bodies": [{ "type": "soft", "mesh": cloth, "material": { "density": 1.0 } }] }),
            "field `bodies[0].cell`: a soft body from the OBJ surface",
        ),
        (
            serde_json::json!({ "bodies": [{ "mesh": cube, "cell": 0.1, "material": { "density": 1.0 } }] }),
            "field `bodies[0].cell`: only a soft body from an OBJ surface is tetrahedralised",
        ),
        (
            serde_json::json!({ "bodies": [{ "mesh": cube, "material": { "density": 1.0, "bending": "none" } }] }),
            "field `bodies[0].material.bending`: a soft body has no bending",
        ),
        (
            serde_json::json!({ "bodies": [{ "mesh": cloth, "material": { "density": 1.0, "volume": {} } }] }),
            "field `bodies[0].material.volume`: a cloth has a volume constraint only with `pressure`",
        ),
        (
            serde_json::json!({ "bodies": [{ "mesh": cloth, "material": { "density": 1.0, "pressure": 1.2 } }] }),
            "field `bodies[0].material.pressure`: ",
        ),
        (
            serde_json::json!({ "bodies": [{ "mesh": cloth, "material": { "density": -1.0 } }] }),
            "field `bodies[0].material.density`: must be positive and finite, got -1",
        ),
        (
            serde_json::json!({ "bodies": [{ "mesh": cloth, "material": { "density": 1.0, "stretch": { "compliance": -1.0 } } }] }),
            "field `bodies[0].material.stretch`: compliance must be non-negative and finite, got -1",
        ),
        (
            serde_json::json!({ "bodies": [{ "mesh": cloth, "material": { "density": 1.0 }, "scale": 0.0 }] }),
            "field `bodies[0].scale`: must be positive and finite, got 0",
        ),
        (
            serde_json::json!({ "bodies": [{ "mesh": cloth, "material": { "density": 1.0, "youngs": 3.0 } }] }),
            "field `bodies[0].material.youngs`: unknown field `youngs`, expected one of `density`, `stretch`, `volume`, `bending`, `pressure`",
        ),
        (
            serde_json::json!({ "thickness": 0.0, "bodies": [{ "mesh": cloth, "material": { "density": 1.0 } }] }),
            "field `thickness`: must be positive and finite, got 0",
        ),
    ];
    for (value, start) in cases {
        let msg = refusal(&dir, value.clone());
        assert!(msg.starts_with(start), "{value}: {msg}");
    }
    let msg = refusal(
        &dir,
        serde_json::json!({ "bodies": [{ "mesh": cloth, "material": { "density": 1.0, "pressure": 1.2 } }] }),
    );
    assert!(msg.contains("cloth.obj: a cloth with pressure must be a closed surface, but edge"), "{msg}");
    // A closed cloth whose triangles face inward (the unit cube's, reversed) has no pressure.
    let cube = write_cube_obj(&dir);
    let text = std::fs::read_to_string(dir.join(&cube)).expect("read");
    let reversed: String = text
        .lines()
        .map(|l| match l.split_whitespace().collect::<Vec<_>>()[..] {
            ["f", a, b, c] => format!("f {a} {c} {b}\n"),
            _ => format!("{l}\n"),
        })
        .collect();
    std::fs::write(dir.join("inward.obj"), reversed).expect("write");
    let msg = refusal(
        &dir,
        serde_json::json!({ "bodies": [{ "mesh": "inward.obj", "material": { "density": 1.0, "pressure": 1.2 } }] }),
    );
    assert_eq!(
        msg,
        format!(
            "field `bodies[0].material.pressure`: {}: the enclosed volume -1e0 is not positive: the triangles \
             face inward",
            dir.join("inward.obj").display()
        )
    );
}

/// A closed cloth with pressure is a balloon: it inflates to `pressure` times its volume.
#[test]
fn a_closed_cloth_with_pressure_inflates() {
    let dir = folder("balloon");
    let (p, t) = crate::shapes::icosphere(2);
    let mut text = String::new();
    for x in &p {
        text += &format!("v {} {} {}\n", x[0], x[1], x[2]);
    }
    for f in &t {
        text += &format!("f {} {} {}\n", f[0] + 1, f[1] + 1, f[2] + 1);
    }
    std::fs::write(dir.join("ball.obj"), text).expect("write");
    let (mut sim, mut state) = built(
        &dir,
        serde_json::json!({
            "gravity": [0.0, 0.0, 0.0],
            "bodies": [{ "mesh": "ball.obj", "scale": 0.2,
              "material": { "density": 0.1, "stretch": { "compliance": 1e-2 }, "pressure": 1.5 } }],
        }),
    );
    assert!(sim.model().contact_bodies().is_empty(), "one body: no contacts between bodies");
    let v0 = sim.model().volume_mesh(0).volume(&state.x);
    for _ in 0..120 {
        sim.step(&mut state, 1.0 / 60.0).expect("step");
    }
    let v = sim.model().volume_mesh(0).volume(&state.x);
    assert!((v / v0 - 1.5).abs() < 0.01, "{}", v / v0);
}

/// Writes the closed OBJ surface of the unit cube `[0, 1]^3`, twelve outward triangles.
pub(super) fn write_cube_obj(dir: &Path) -> String {
    let (corners, faces) = anim_core::surface::cuboid([0.0; 3], [1.0; 3]);
    let mut text = String::new();
    for v in corners {
        text += &format!("v {} {} {}\n", v[0], v[1], v[2]);
    }
    for f in faces {
        text += &format!("f {} {} {}\n", f[0] + 1, f[1] + 1, f[2] + 1);
    }
    std::fs::write(dir.join("cube.obj"), text).expect("write");
    "cube.obj".into()
}

/// A closed OBJ surface with `cell` is a soft body of tetrahedra filling it: its mass is the
/// density times the enclosed volume, and it stays above the ground.
#[test]
fn a_closed_obj_surface_with_a_cell_is_filled_with_tetrahedra() {
    let dir = folder("obj-soft");
    let cube = write_cube_obj(&dir);
    let body = |cell: f64, pin: serde_json::Value| {
        serde_json::json!({
            "obstacles": [{ "plane": { "point": [0.0, 0.0, 0.0], "normal": [0.0, 0.0, 1.0] } }],
            "thickness": 0.01,
            "bodies": [{ "mesh": cube, "cell": cell, "scale": 0.4, "translate": [-0.2, -0.2, 0.1],
                         "material": { "density": 250.0, "stretch": { "compliance": 1e-5 } }, "pin": pin }],
        })
    };
    let (mut sim, mut state) = built(&dir, body(0.1, serde_json::Value::Null));
    assert!(!sim.model().tets().is_empty());
    // 0.4^3 m^3 at 250 kg/m^3: 16 kg.
    let m = total_mass(sim.model());
    assert!((m - 16.0).abs() < 1e-9, "{m}");
    for _ in 0..60 {
        sim.step(&mut state, 1.0 / 60.0).expect("step");
    }
    let z = state.x.chunks(3).map(|p| p[2]).fold(f64::INFINITY, f64::min);
    assert!((z - 0.01).abs() < 1e-3, "{z}");
    // Its vertices are not the file's: pins by index are refused, pins by box taken.
    let msg = refusal(&dir, body(0.1, serde_json::json!({ "vertices": [0] })));
    assert!(msg.starts_with("field `bodies[0].pin`: `vertices` name vertices of the mesh file"), "{msg}");
    let (sim, _) = built(
        &dir,
        body(0.1, serde_json::json!({ "box": { "min": [-1.0, -1.0, 0.45], "max": [1.0, 1.0, 1.0] } })),
    );
    let pinned = sim.model().inverse_masses().iter().filter(|&&w| w == 0.0).count();
    assert_eq!(pinned, 25, "the top face's 5 x 5 lattice vertices");
    // A cell larger than the body leaves no tetrahedron: refused on `cell`.
    let msg = refusal(&dir, body(2.0, serde_json::Value::Null));
    assert!(msg.starts_with("field `bodies[0].cell`: ") && msg.contains("cube.obj"), "{msg}");
    // An open surface cannot be filled.
    let cloth = write_cloth(&dir, "cloth", 3, 1.0);
    let msg = refusal(
        &dir,
        serde_json::json!({ "bodies": [{ "mesh": cloth, "cell": 0.1, "material": { "density": 1.0 } }] }),
    );
    assert!(msg.starts_with("field `bodies[0].mesh`: ") && msg.contains("must be closed"), "{msg}");
}
