//! Bodies of a scene file: the particles a box, a sphere and an OBJ cube get (count and mass
//! against the analytic volume), bodies keeping their own materials, a body resting on an
//! obstacle, and every refusal naming its field.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::Path;

use crate::bodies;
use crate::kind::MpmSceneParams;
use crate::scenes::{MpmScene, Scene};
use crate::{KIND, Material};
use anim_core::scene::{BuildContext, BuildError};
use anim_core::solver::Solver;
use serde_json::{Value, json};

pub(crate) fn testdata() -> &'static Path {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/testdata"))
}

fn params(value: Value) -> MpmSceneParams {
    serde_json::from_value(value).expect("scene-file parameters")
}

fn build(value: Value) -> Result<MpmScene, BuildError> {
    bodies::build(&params(value), &BuildContext { base: Some(testdata()) })
}

pub(crate) fn three(value: Value) -> Scene<3> {
    match build(value).expect("builds") {
        MpmScene::Three(s) => s,
        MpmScene::Two(_) => panic!("a 2D scene"),
    }
}

fn two(value: Value) -> Scene<2> {
    match build(value).expect("builds") {
        MpmScene::Two(s) => s,
        MpmScene::Three(_) => panic!("a 3D scene"),
    }
}

/// `(field, message)` of a refusal by the kind's build (the path a scene file goes).
pub(crate) fn refused(value: Value) -> (String, String) {
    match (KIND.build)(&value, &BuildContext { base: Some(testdata()) }).err().expect("refused") {
        BuildError::Invalid { field, message } | BuildError::Schema { field, message } => (field, message),
        other => (String::new(), other.to_string()),
    }
}

/// The mean height (y) and mean speed of the particles of material `k`.
pub(crate) fn body_height_and_speed(s: &Scene<3>, k: u16) -> (f64, f64) {
    let ps: Vec<usize> = (0..s.state.len()).filter(|&p| s.state.material[p] == k).collect();
    let n = ps.len() as f64;
    let y = ps.iter().map(|&p| f64::from(s.state.x[3 * p + 1])).sum::<f64>() / n;
    let v = ps.iter().map(|&p| f64::from(s.state.velocity(p).norm())).sum::<f64>() / n;
    (y, v)
}

fn mass<const D: usize>(s: &Scene<D>) -> f64 {
    s.state.mass.iter().map(|&m| f64::from(m)).sum()
}

pub(crate) fn jelly() -> Value {
    json!({ "elastic": { "young": 2e4, "poisson": 0.3, "density": 1000.0 } })
}

pub(crate) fn cube(center: [f64; 3], half: f64) -> Value {
    json!({ "box": { "center": center, "half_extents": [half, half, half] } })
}

/// A box whose faces lie on the particle lattice gets one particle per lattice cell: its count
/// is its volume over `s^D` and its mass `density x volume`, exactly (powers of two throughout).
#[test]
fn a_lattice_aligned_box_gets_its_exact_volume_and_mass() {
    // h = 1/32, 2 particles per cell and axis: s = 1/64; the box [0.25, 0.5] x [0.25, 0.75] x
    // [0.375, 0.5] is 16 x 32 x 8 lattice cells.
    let s = three(json!({
        "resolution": 32,
        "bodies": [{
            "shape": { "box": { "center": [0.375, 0.5, 0.4375], "half_extents": [0.125, 0.25, 0.0625] } },
            "material": jelly(),
            "velocity": [0.5, -1.0, 0.25],
        }],
    }));
    assert_eq!(s.state.len(), 16 * 32 * 8);
    assert_eq!(mass(&s), 1000.0 * 0.25 * 0.5 * 0.125);
    assert!(s.state.volume.iter().all(|&v| v == (1.0f32 / 64.0).powi(3)));
    assert!(s.state.v.chunks_exact(3).all(|v| v == [0.5, -1.0, 0.25]));
    let (lo, hi) = s.state.x.chunks_exact(3).fold(([1.0f32; 3], [0.0f32; 3]), |(lo, hi), p| {
        (std::array::from_fn(|a| lo[a].min(p[a])), std::array::from_fn(|a| hi[a].max(p[a])))
    });
    let half = 0.5 / 64.0;
    assert_eq!((lo, hi), ([0.25 + half, 0.25 + half, 0.375 + half], [0.5 - half, 0.75 - half, 0.5 - half]));
    // Three particles per cell and axis: s = 1/96, 24 x 48 x 12 (volume 1/96^3 each).
    let s = three(json!({
        "resolution": 32, "particles_per_cell": 3,
        "bodies": [{
            "shape": { "box": { "center": [0.375, 0.5, 0.4375], "half_extents": [0.125, 0.25, 0.0625] } },
            "material": jelly(),
        }],
    }));
    assert_eq!(s.state.len(), 24 * 48 * 12);
    assert!((mass(&s) - 15.625).abs() < 15.625 * 1e-6, "{}", mass(&s));
    // In 2D a rectangle in the x-y plane: area over s^2, density in kg/m^2.
    let s = two(json!({
        "dim": 2, "resolution": 32,
        "bodies": [{ "shape": { "box": { "center": [0.375, 0.5, 0.0], "half_extents": [0.125, 0.25, 9.0] } },
                     "material": jelly() }],
    }));
    assert_eq!(s.state.len(), 16 * 32);
    assert_eq!(mass(&s), 1000.0 * 0.25 * 0.5);
}

/// A sphere's lattice cells (of side `s`) whose centres lie inside it cover the ball of radius
/// `r - sqrt(3) s / 2` and lie in the ball of radius `r + sqrt(3) s / 2`: its mass lies between
/// the masses of those balls, a band that narrows with the resolution.
#[test]
fn a_sphere_gets_its_volume_within_the_lattice_error() {
    let (r, rho) = (0.2, 400.0);
    let ball = |r: f64| rho * 4.0 / 3.0 * std::f64::consts::PI * r.powi(3);
    for n in [24, 48] {
        let s = three(json!({
            "resolution": n,
            "bodies": [{ "shape": { "sphere": { "center": [0.5, 0.45, 0.55], "radius": r } },
                         "material": { "snow": { "density": rho } } }],
        }));
        let spacing = 1.0 / (2 * n) as f64;
        let m = mass(&s);
        let slack = 3f64.sqrt() / 2.0 * spacing;
        assert!(ball(r - slack) <= m && m <= ball(r + slack), "n = {n}: {m} vs {}", ball(r));
        // Every particle's own cell centre is inside the sphere.
        assert!(s.state.x.chunks_exact(3).all(|p| {
            let d2: f64 = p.iter().zip([0.5, 0.45, 0.55]).map(|(x, c)| (f64::from(*x) - c).powi(2)).sum();
            d2 <= r * r * (1.0 + 1e-6)
        }));
    }
    // A disk in 2D, between the disks of radius r -+ s / sqrt(2).
    let s = two(json!({
        "dim": 2, "resolution": 48,
        "bodies": [{ "shape": { "sphere": { "center": [0.5, 0.45, 0.0], "radius": r } },
                     "material": { "snow": { "density": rho } } }],
    }));
    let disk = |r: f64| rho * std::f64::consts::PI * r * r;
    let slack = (1.0 / 96.0) / 2f64.sqrt();
    assert!(disk(r - slack) <= mass(&s) && mass(&s) <= disk(r + slack), "{}", mass(&s));
}

/// The unit cube of an OBJ file, scaled and moved onto a lattice-aligned box, gets the box's
/// particles: the same count, positions and mass.
#[test]
fn an_obj_cube_gets_the_particles_of_the_equal_box() {
    let mesh = three(json!({
        "resolution": 32,
        "bodies": [{ "mesh": "cube.obj", "scale": 0.25, "translate": [0.25, 0.3125, 0.5],
                     "material": jelly() }],
    }));
    let shape = three(json!({
        "resolution": 32,
        "bodies": [{ "shape": cube([0.375, 0.4375, 0.625], 0.125), "material": jelly() }],
    }));
    assert_eq!(shape.state.len(), 16 * 16 * 16);
    assert_eq!(mesh.state.len(), shape.state.len());
    assert_eq!(mass(&mesh), mass(&shape));
    assert_eq!(mass(&mesh), 1000.0 * 0.25f64.powi(3));
    let sorted = |s: &Scene<3>| {
        let mut p: Vec<[u32; 3]> =
            s.state.x.chunks_exact(3).map(|c| [0, 1, 2].map(|a| c[a].to_bits())).collect();
        p.sort_unstable();
        p
    };
    assert_eq!(sorted(&mesh), sorted(&shape));
    // Turned by a quarter about z and placed at the same centre, it is the same cube.
    let turned = three(json!({
        "resolution": 32,
        "bodies": [{ "mesh": "cube.obj", "scale": 0.25, "rotate": [0.0, 0.0, std::f64::consts::FRAC_PI_2],
                     "translate": [0.5, 0.3125, 0.5], "material": jelly() }],
    }));
    assert_eq!(turned.state.len(), 16 * 16 * 16);
}

/// Two bodies of different materials: body k is material k, each particle has its body's
/// material, mass and velocity, and a step keeps them apart.
#[test]
fn two_bodies_keep_their_own_materials() {
    let mut s = three(json!({
        "resolution": 16,
        "bodies": [
            { "shape": cube([0.32, 0.5, 0.5], 0.125), "material": jelly(), "velocity": [1.0, 0.0, 0.0] },
            { "shape": { "sphere": { "center": [0.68, 0.5, 0.5], "radius": 0.12 } },
              "material": { "snow": { "density": 400.0, "young": 2e4 } } },
        ],
    }));
    let materials = s.sim.materials().to_vec();
    assert!(matches!(materials[0], Material::Elastic(m) if m.young == 2e4 && m.poisson == 0.3));
    assert!(matches!(materials[1], Material::Snow(m) if m.young == 2e4 && m.theta_c == 2.5e-2));
    let count = |s: &Scene<3>, k: u16| s.state.material.iter().filter(|&&m| m == k).count();
    let (jelly_count, snow_count) = (count(&s, 0), count(&s, 1));
    assert_eq!(jelly_count, 8 * 8 * 8);
    assert!(snow_count > 0 && jelly_count + snow_count == s.state.len());
    let cell = (1.0f32 / 32.0).powi(3);
    for p in 0..s.state.len() {
        let (x, k) = (s.state.x[3 * p], s.state.material[p]);
        // The jelly lies left of x = 0.5, the snow right of it.
        assert_eq!(k, u16::from(x > 0.5), "particle {p} at x = {x}");
        let (mass, vx) = if k == 0 { (1000.0 * cell, 1.0) } else { (400.0 * cell, 0.0) };
        assert_eq!((s.state.mass[p], s.state.v[3 * p]), (mass, vx));
    }
    for _ in 0..3 {
        s.sim.step(&mut s.state, 1e-3).unwrap();
    }
    assert_eq!((count(&s, 0), count(&s, 1)), (jelly_count, snow_count));
    for p in 0..s.state.len() {
        let id = s.state.id[p] as usize;
        assert_eq!(s.state.material[p], u16::from(id >= jelly_count), "particle id {id}");
    }
}

/// A jelly cube and a snow cube dropped side by side onto a box obstacle (separating, with
/// friction) land on it and stay on it: no particle gets more than half a cell into it (the
/// grid boundary acts on nodes, so particles stop within a cell), the jelly bounces off it and
/// the snow comes to rest on it, squashed.
#[test]
fn bodies_land_on_an_obstacle_without_passing_through() {
    let top = 0.4;
    let mut s = three(json!({
        "resolution": 16,
        "obstacles": [{ "box": { "center": [0.5, 0.3, 0.5], "half_extents": [0.3, 0.1, 0.3] } }],
        "boundary": { "separate": { "friction": 0.5 } },
        "bodies": [
            { "shape": cube([0.35, 0.6, 0.5], 0.1), "material": jelly() },
            { "shape": cube([0.65, 0.6, 0.5], 0.1), "material": { "snow": {} } },
        ],
    }));
    let h = 1.0 / 16.0;
    let body = body_height_and_speed;
    let mut lowest = f32::MAX;
    // The jelly's centre: lowest so far, highest since.
    let (mut bottom, mut rebound) = (f64::MAX, f64::MIN);
    for _ in 0..500 {
        s.sim.step(&mut s.state, 1e-3).unwrap();
        lowest = s.state.x.chunks_exact(3).map(|p| p[1]).fold(lowest, f32::min);
        let (y, _) = body(&s, 0);
        if y < bottom {
            (bottom, rebound) = (y, y);
        }
        rebound = rebound.max(y);
    }
    assert!(f64::from(lowest) > top - 0.5 * h, "lowest particle at y = {lowest}");
    // The jelly's centre came within its half edge (0.1) of the top face and went back up by
    // more than half a cell.
    assert!(bottom < top + 0.1 && rebound > bottom + 0.5 * h, "{bottom} {rebound}");
    let (snow_y, snow_speed) = body(&s, 1);
    assert!(snow_y > top && snow_y < top + 0.1, "snow centre at y = {snow_y}");
    assert!(snow_speed < 0.05, "snow's mean speed {snow_speed}");
}

#[test]
fn a_body_outside_the_domain_or_its_walls_is_refused_by_index() {
    let scene = |center: [f64; 3]| {
        json!({
            "resolution": 32,
            "bodies": [
                { "shape": cube([0.5, 0.5, 0.5], 0.1), "material": jelly() },
                { "shape": cube(center, 0.125), "material": jelly() },
            ],
        })
    };
    // Walls 3 cells thick at 32 cells: matter lies in [0.09375, 0.90625].
    let (field, message) = refused(scene([0.5, 0.5, 1.2]));
    assert_eq!(field, "bodies[1]");
    assert!(message.contains("z = 1.3250") && message.contains("[0.0938, 0.9062]"), "{message}");
    let (field, message) = refused(scene([0.15, 0.5, 0.5]));
    assert_eq!(field, "bodies[1]");
    assert!(message.contains("x = 0.0250") && message.contains("walls 3 cells thick"), "{message}");
    assert!(build(scene([0.21875, 0.5, 0.5])).is_ok(), "touching the wall's inner face");
    assert_eq!(refused(scene([0.21875 - 1e-9, 0.5, 0.5])).0, "bodies[1]");
    // A mesh body is checked after its placement.
    let (field, message) = refused(json!({
        "resolution": 32,
        "bodies": [{ "mesh": "cube.obj", "scale": 0.5, "translate": [0.6, 0.2, 0.2], "material": jelly() }],
    }));
    assert_eq!(field, "bodies[0]");
    assert!(message.contains("x = 1.1000"), "{message}");
}

#[test]
fn an_open_obj_surface_is_refused_naming_the_file_and_an_edge() {
    let (field, message) = refused(json!({
        "bodies": [
            { "shape": cube([0.5, 0.5, 0.5], 0.1), "material": jelly() },
            { "mesh": "open_cube.obj", "scale": 0.2, "translate": [0.2, 0.2, 0.2], "material": jelly() },
        ],
    }));
    assert_eq!(field, "bodies[1].mesh");
    assert!(message.contains("open_cube.obj") && message.to_lowercase().contains("edge"), "{message}");
    // A missing file and a file of another format are named too.
    let (field, message) = refused(json!({ "bodies": [{ "mesh": "no-such.obj", "material": jelly() }] }));
    assert_eq!(field, "bodies[0].mesh");
    assert!(message.contains("no-such.obj"), "{message}");
    let (field, message) = refused(json!({ "bodies": [{ "mesh": "cube.msh", "material": jelly() }] }));
    assert_eq!(field, "bodies[0].mesh");
    assert!(message.contains("cube.msh") && message.contains(".obj"), "{message}");
}

#[test]
fn obstacles_are_planes_boxes_and_spheres_and_no_body_starts_inside_one() {
    let body = json!({ "shape": cube([0.5, 0.6, 0.5], 0.1), "material": jelly() });
    let (field, message) = refused(json!({
        "obstacles": [
            { "plane": { "point": [0.0, 0.2, 0.0], "normal": [0.0, 1.0, 0.0] } },
            { "capsule": { "a": [0.3, 0.3, 0.5], "b": [0.7, 0.3, 0.5], "radius": 0.05 } },
        ],
        "bodies": [body.clone()],
    }));
    assert_eq!(field, "obstacles[1]");
    assert!(message.contains("capsule"), "{message}");
    let (field, message) = refused(json!({
        "obstacles": [{ "sphere": { "center": [0.5, 0.5, 0.5], "radius": -0.1 } }],
        "bodies": [body.clone()],
    }));
    assert_eq!(field, "obstacles[0]");
    assert!(message.contains("radius"), "{message}");
    let (field, message) = refused(json!({
        "obstacles": [
            { "plane": { "point": [0.0, 0.2, 0.0], "normal": [0.0, 1.0, 0.0] } },
            { "sphere": { "center": [0.5, 0.45, 0.5], "radius": 0.1 } },
        ],
        "bodies": [{ "shape": cube([0.2, 0.6, 0.5], 0.05), "material": jelly() }, body.clone()],
    }));
    assert_eq!(field, "bodies[1]");
    assert!(message.contains("inside obstacles[1] (a sphere)"), "{message}");
    let (field, message) =
        refused(json!({ "boundary": { "separate": { "friction": -1.0 } }, "bodies": [body] }));
    assert_eq!(field, "boundary");
    assert!(message.contains("friction -1"), "{message}");
}

#[test]
fn a_body_without_particles_at_this_resolution_is_refused_naming_it() {
    let (field, message) = refused(json!({
        "resolution": 16, "particles_per_cell": 1,
        "bodies": [
            { "shape": cube([0.5, 0.5, 0.5], 0.1), "material": jelly() },
            { "shape": { "box": { "center": [0.3, 0.3, 0.3], "half_extents": [0.1, 0.01, 0.1] } }, "material": jelly() },
        ],
    }));
    assert_eq!(field, "bodies[1]");
    assert!(message.contains("no particle at resolution 16 with 1 particles per cell"), "{message}");
}

#[test]
fn each_field_of_a_body_is_checked_by_name() {
    let body = |extra: Value| {
        let mut b = json!({ "shape": cube([0.5, 0.5, 0.5], 0.1), "material": jelly() });
        for (k, v) in extra.as_object().unwrap() {
            b[k] = v.clone();
        }
        json!({ "bodies": [b] })
    };
    let cases = [
        (json!({ "material": { "elastic": { "young": -1.0 } } }), "bodies[0].material.elastic.young"),
        (json!({ "material": { "snow": { "poisson": 0.5 } } }), "bodies[0].material.snow.poisson"),
        (json!({ "material": { "fluid": { "bulk": 0.0 } } }), "bodies[0].material.fluid.bulk"),
        (json!({ "material": { "sand": { "density": 1e-60 } } }), "bodies[0].material.sand.density"),
        (json!({ "material": { "elastic": { "stiffness": 1.0 } } }), "bodies[0].material.elastic.stiffness"),
        (json!({ "scale": 0.0 }), "bodies[0].scale"),
        (json!({ "translate": [0.0, 1e300, 0.0] }), "bodies[0]"),
        (json!({ "velocity": [1e300, 0.0, 0.0] }), "bodies[0].velocity"),
        (
            json!({ "shape": { "plane": { "point": [0.5, 0.5, 0.5], "normal": [0.0, 1.0, 0.0] } } }),
            "bodies[0].shape",
        ),
        (json!({ "shape": { "sphere": { "center": [0.5, 0.5, 0.5], "radius": 0.0 } } }), "bodies[0].shape"),
        (json!({ "mesh": "cube.obj" }), "bodies[0]"),
    ];
    for (extra, want) in cases {
        let (field, message) = refused(body(extra.clone()));
        assert_eq!(field, want, "{extra}: {message}");
    }
    let (field, message) = refused(json!({ "bodies": [{ "material": jelly() }] }));
    assert_eq!(field, "bodies[0]");
    assert!(message.contains("`shape`") && message.contains("`mesh`"), "{message}");
    // 2D: no meshes, no roll or pitch.
    let (field, _) = refused(json!({ "dim": 2, "bodies": [{ "mesh": "cube.obj", "material": jelly() }] }));
    assert_eq!(field, "bodies[0].mesh");
    let mut tilted = body(json!({ "rotate": [0.1, 0.0, 0.0] }));
    tilted["dim"] = json!(2);
    assert_eq!(refused(tilted).0, "bodies[0].rotate");
}

#[test]
fn the_scene_fields_are_checked_and_a_preset_takes_none_of_the_bodies_fields() {
    let bodies = json!([{ "shape": cube([0.5, 0.5, 0.5], 0.1), "material": jelly() }]);
    let with = |field: &str, value: Value| {
        let mut p = json!({ "bodies": bodies });
        p[field] = value;
        refused(p)
    };
    assert_eq!(with("dim", json!(4)).0, "dim");
    assert_eq!(with("resolution", json!(4)).0, "resolution");
    assert_eq!(with("particles_per_cell", json!(9)).0, "particles_per_cell");
    assert_eq!(with("gravity", json!([0.0, -1e300, 0.0])).0, "gravity");
    assert_eq!(with("wall", json!({ "separate": { "friction": -0.5 } })).0, "wall");
    let (field, message) = with("preset", json!("snowball"));
    assert!(field == "preset" && message.contains("not both"), "{message}");
    let (field, message) = refused(json!({}));
    assert!(field == "preset" && message.contains("[[scene.bodies]]"), "{message}");
    for (field, value) in [
        ("dim", json!(3)),
        ("gravity", json!([0.0, -9.81, 0.0])),
        ("obstacles", json!([{ "sphere": { "center": [0.5, 0.5, 0.5], "radius": 0.1 } }])),
        ("boundary", json!("sticky")),
        ("wall", json!("slip")),
    ] {
        let mut p = json!({ "preset": "snowball" });
        p[field] = value;
        let (got, message) = refused(p);
        assert!(got == field && message.contains("snowball"), "{field}: {got} {message}");
    }
}

/// The scene-file spelling of the materials and boundaries: kinds in kebab case, every field
/// optional with its documented default, unknown fields refused.
#[test]
fn materials_and_boundaries_read_with_their_defaults() {
    let m: Material = serde_json::from_value(json!({ "elastic": { "model": "neo-hookean" } })).unwrap();
    assert_eq!(
        m,
        Material::Elastic(crate::Elastic { model: crate::ElasticModel::NeoHookean, ..Default::default() })
    );
    for (value, want) in [
        (json!({ "snow": {} }), Material::Snow(crate::Snow::default())),
        (
            json!({ "fluid": { "gamma": 7.0 } }),
            Material::Fluid(crate::Fluid { gamma: 7.0, ..Default::default() }),
        ),
        (json!({ "sand": {} }), Material::Sand(crate::Sand::default())),
    ] {
        assert_eq!(serde_json::from_value::<Material>(value).unwrap(), want);
    }
    assert!(serde_json::from_value::<Material>(json!({ "snow": { "young": 1.0, "theta": 1.0 } })).is_err());
    assert!(serde_json::from_value::<Material>(json!({ "jelly": {} })).is_err());
    use crate::Boundary;
    for (value, want) in [
        (json!("sticky"), Boundary::Sticky),
        (json!("slip"), Boundary::Slip),
        (json!({ "separate": { "friction": 0.25 } }), Boundary::Separate { friction: 0.25 }),
        (json!({ "separate": {} }), Boundary::Separate { friction: 0.0 }),
        (json!("separate-frictionless"), Boundary::SeparateFrictionless),
    ] {
        assert_eq!(serde_json::from_value::<Boundary>(value.clone()).unwrap(), want, "{value}");
        assert_eq!(serde_json::from_value::<Boundary>(serde_json::to_value(want).unwrap()).unwrap(), want);
    }
}

/// A 2D scene of bodies runs through the kind like the 2D presets: frames in the z = 0 plane,
/// the method 2D, framed by the domain's walls.
#[test]
fn a_2d_scene_of_bodies_steps_through_the_kind() {
    let params = json!({
        "dim": 2, "resolution": 32, "transfer": "apic",
        "obstacles": [{ "box": { "center": [0.5, 0.2, 0.0], "half_extents": [0.3, 0.05, 0.0] } }],
        "bodies": [
            { "shape": { "sphere": { "center": [0.3, 0.6, 0.0], "radius": 0.1 } }, "material": { "fluid": {} } },
            { "shape": cube([0.7, 0.6, 0.0], 0.1), "material": { "sand": {} }, "rotate": [0.0, 0.0, 0.3] },
        ],
    });
    let mut scene = (KIND.build)(&params, &BuildContext::default()).expect("builds");
    assert_eq!(scene.method(), "2D APIC, quadratic B-splines, CFL substeps");
    scene.step(1e-3).expect("steps");
    let mut frame = anim_core::scene::Frame::default();
    scene.frame(&mut frame);
    assert!(!frame.points.is_empty() && frame.points.chunks_exact(3).all(|p| p[2] == 0.0));
    let bounds = scene.context().bounds.expect("bounds");
    assert_eq!(bounds, ([3.0 / 32.0, 3.0 / 32.0, 0.0], [29.0 / 32.0, 29.0 / 32.0, 0.0]));
}

/// In 2D the third components of a body's shape are ignored, whatever they hold: a sphere at
/// `z = 1e308` scaled by 10 (its z overflows) gets the particles of the same disk at `z = 0`,
/// and a box of any depth those of the same rectangle.
#[test]
fn a_2d_body_ignores_the_third_components_of_its_shape() {
    let disk = |z: f64, scale: f64| {
        two(json!({
            "dim": 2, "resolution": 32,
            "bodies": [{
                "shape": { "sphere": { "center": [0.05, 0.05, z], "radius": 0.01 } },
                "material": jelly(), "scale": scale,
            }],
        }))
    };
    let (flat, far) = (disk(0.0, 10.0), disk(1e308, 10.0));
    assert!(!flat.state.x.is_empty());
    assert_eq!(far.state.x, flat.state.x);
    let rectangle = |depth: f64| {
        two(json!({
            "dim": 2, "resolution": 32,
            "bodies": [{
                "shape": { "box": { "center": [0.25, 0.25, 0.0], "half_extents": [0.05, 0.05, depth] } },
                "material": jelly(), "scale": 2.0,
            }],
        }))
    };
    assert_eq!(rectangle(1e308).state.x, rectangle(0.1).state.x);
}

/// A resolution past the memory available is refused before anything is allocated, for bodies
/// (their particles counted over their bounding boxes) and presets alike, naming the field,
/// the estimate and the memory; past the grid's `u32` block keys (6495 cells per axis in 3D,
/// 262135 in 2D) the scene refuses it whatever the memory.
#[test]
fn a_resolution_past_the_memory_is_refused() {
    let memory = |params: serde_json::Value| {
        let start = std::time::Instant::now();
        let e = (KIND.build)(&params, &BuildContext::default()).err().expect("refused");
        assert!(start.elapsed().as_secs_f64() < 1.0, "{:?}", start.elapsed());
        match e {
            BuildError::Memory { field, message, bytes, available } => {
                assert_eq!(field, "resolution");
                assert!(bytes > available && message.contains(" available"), "{message}");
                message
            }
            other => panic!("{other:?}"),
        }
    };
    let body = json!([{ "shape": cube([0.5, 0.5, 0.5], 0.1), "material": jelly() }]);
    let m = memory(json!({ "bodies": body, "resolution": 6000 }));
    assert!(m.starts_with("6000 cells per axis with 2 particles per cell and axis (1.38"), "{m}");
    assert!(m.contains("e10 lattice points in the bodies' bounding boxes) needs about "), "{m}");
    let m = memory(json!({ "preset": "snowball", "resolution": 6000 }));
    assert!(m.starts_with("6000 cells per axis needs about "), "{m}");
    let m = memory(json!({ "preset": "dam-break-2d", "resolution": 200_000, "particles_per_cell": 8 }));
    assert!(m.starts_with("200000 cells per axis needs about "), "{m}");
    let (field, message) = refused(json!({ "bodies": body, "resolution": 6496 }));
    assert!(field == "resolution" && message.contains("[8, 6495] in 3D"), "{field}: {message}");
    let e = crate::scenes::by_name("dam-break-2d", Some(262_136)).expect("known").expect_err("refused");
    assert!(e.to_string().contains("[8, 262135] in 2D"), "{e}");
}
