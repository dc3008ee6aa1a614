use super::*;
use crate::kind::KIND;
use crate::scenes::{self, PLUME_SPHERE_CENTRE, PLUME_SPHERE_RADIUS};
use anim_core::scene::params;
use serde_json::{Value, json};

fn scene_of(value: Value) -> Result<FluidScene, BuildError> {
    params::<FluidSceneParams>(&value)?.scene()
}

fn mac(scene: &FluidScene) -> (&MacFluid, &crate::mac::MacState) {
    match &scene.sim {
        FluidSim::Mac(f, s) => (f, s),
        FluidSim::Stam(_) => panic!("a MAC scene"),
    }
}

/// The error of `value` as the command line prints it (`field `F`: message`).
fn err(value: Value) -> String {
    scene_of(value).expect_err("refused").to_string()
}

/// The centre of cell `c` (x fastest) of a grid of `dims` cells of size `h`, computed here.
fn centre(c: usize, dims: [usize; 3], h: f64, dim: usize) -> [f64; 3] {
    let (i, j, k) = (c % dims[0], (c / dims[0]) % dims[1], c / (dims[0] * dims[1]));
    let z = if dim == 3 { (k as f64 + 0.5) * h } else { 0.0 };
    [(i as f64 + 0.5) * h, (j as f64 + 0.5) * h, z]
}

fn distance(p: [f64; 3], c: [f64; 3]) -> f64 {
    ((p[0] - c[0]).powi(2) + (p[1] - c[1]).powi(2) + (p[2] - c[2]).powi(2)).sqrt()
}

/// Checks the solid cells of a `dim`-dimensional `fluid` against a ball of centre `c`: a cell
/// whose centre is nearer than `inner` must be solid, one at `r` or beyond must not; returns the
/// cells between (undecided by the check) and the solid cells.
fn solid_ball(fluid: &MacFluid, dim: usize, c: [f64; 3], inner: f64, r: f64) -> (usize, usize) {
    let (mut band, mut solid) = (0, 0);
    for (k, &is_solid) in fluid.solid().iter().enumerate() {
        let d = distance(centre(k, fluid.dims(), fluid.h(), dim), c);
        if d < inner {
            assert!(is_solid, "{dim}D cell {k} at distance {d} is inside the surface");
        } else if d >= r {
            assert!(!is_solid, "{dim}D cell {k} at distance {d} is outside the surface");
        } else {
            band += 1;
        }
        solid += usize::from(is_solid);
    }
    (band, solid)
}

/// A closed UV sphere as OBJ text: `rings` latitude bands, `segments` around, one vertex at
/// each pole, triangles facing outward.
fn sphere_obj(center: [f64; 3], r: f64, rings: usize, segments: usize) -> String {
    use std::f64::consts::PI;
    let mut text = String::from("# a UV sphere\n");
    let mut v = |p: [f64; 3]| text.push_str(&format!("v {} {} {}\n", p[0], p[1], p[2]));
    v([center[0], center[1] + r, center[2]]);
    for i in 1..rings {
        let theta = PI * i as f64 / rings as f64;
        for j in 0..segments {
            let phi = 2.0 * PI * j as f64 / segments as f64;
            v([
                center[0] + r * theta.sin() * phi.cos(),
                center[1] + r * theta.cos(),
                center[2] - r * theta.sin() * phi.sin(),
            ]);
        }
    }
    v([center[0], center[1] - r, center[2]]);
    // 1-based OBJ indices: the top pole 1, ring i (1..rings-1) from 2 + (i-1) segments.
    let at = |i: usize, j: usize| 2 + (i - 1) * segments + j % segments;
    let bottom = 2 + (rings - 1) * segments;
    let mut f = String::new();
    for j in 0..segments {
        f.push_str(&format!("f 1 {} {}\n", at(1, j), at(1, j + 1)));
        f.push_str(&format!("f {bottom} {} {}\n", at(rings - 1, j + 1), at(rings - 1, j)));
    }
    for i in 1..rings - 1 {
        for j in 0..segments {
            f.push_str(&format!("f {} {} {} {}\n", at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)));
        }
    }
    text + &f
}

/// A fresh folder under the system's temporary folder.
fn temp_dir(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("anim-fluid-smoke-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temporary folder");
    dir
}

fn vent() -> Value {
    json!({ "shape": { "box": { "center": [0.5, 0.05, 0.5], "half_extents": [0.1, 0.05, 0.1] } },
            "velocity": [0.0, 0.5, 0.0] })
}

/// With the plume's vent as a box source and its sphere as an obstacle, a smoke scene of the
/// user's own at its default settings is the `smoke-plume-3d` preset, bit for bit: the defaults
/// are the plume's and a region source acts exactly as the preset's box.
#[test]
fn the_plume_rebuilt_from_a_source_and_an_obstacle_is_the_preset_bit_for_bit() {
    for n in [8, 16] {
        let mut own = scene_of(json!({
            "resolution": n,
            "sources": [vent()],
            "obstacles": [ { "sphere": { "center": PLUME_SPHERE_CENTRE, "radius": PLUME_SPHERE_RADIUS } } ],
        }))
        .expect("builds");
        let mut preset = scenes::smoke_plume_3d(n).expect("builds");
        assert_eq!((own.dims(), own.dt.to_bits()), (preset.dims(), preset.dt.to_bits()));
        // The same settings; the preset's vent is a box of its settings, the file's a region.
        let mut settings = mac(&preset).0.params().clone();
        assert_eq!(settings.sources.len(), 1);
        settings.sources.clear();
        assert_eq!(mac(&own).0.params(), &settings);
        for _ in 0..3 {
            own.step().expect("step");
            preset.step().expect("step");
        }
        assert!(own.memory() == preset.memory(), "n = {n}: the states differ");
        assert!(mac(&own).1.density.iter().sum::<f64>() > 0.0);
    }
}

/// A cell is solid exactly when its centre is inside an obstacle: spheres (2D disks), boxes
/// and capsules, against the analytic shapes evaluated here at the cell centres.
#[test]
fn obstacle_cells_are_the_cells_whose_centres_lie_inside() {
    let (c1, r1) = ([0.37, 0.81, 0.55], 0.23);
    let (b, half) = ([0.7, 0.3, 0.4], [0.15, 0.1, 0.2]);
    for (dim, n) in [(3, 13), (2, 40)] {
        let size = if dim == 3 { json!([1.0, 1.5, 1.0]) } else { json!([1.0, 1.5]) };
        let scene = scene_of(json!({
            "dim": dim, "resolution": n, "size": size,
            "sources": [ { "shape": { "sphere": { "center": [0.2, 0.0, 0.5], "radius": 0.15 } } } ],
            "obstacles": [
                { "sphere": { "center": c1, "radius": r1 } },
                { "box": { "center": b, "half_extents": half } },
            ],
        }))
        .expect("builds");
        let (fluid, _) = mac(&scene);
        let (dims, h) = (fluid.dims(), fluid.h());
        assert_eq!(h, 1.0 / n as f64);
        let mut solid = 0;
        for (c, &is_solid) in fluid.solid().iter().enumerate() {
            let p = centre(c, dims, h, dim);
            let mut q = c1;
            if dim == 2 {
                q[2] = 0.0; // a 2D scene reads a sphere as the disk of its first two components
            }
            let in_sphere = distance(p, q) < r1;
            let in_box = (0..dim).all(|a| (p[a] - b[a]).abs() < half[a]);
            assert_eq!(is_solid, in_sphere || in_box, "{dim}D cell {c} at {p:?}");
            solid += usize::from(is_solid);
        }
        assert!(solid > 20, "{dim}D: {solid} solid cells");
    }
    // A capsule: the points within its radius of its axis.
    let (a, b, r) = ([0.2, 0.6, 0.3], [0.8, 0.9, 0.6], 0.12);
    let scene = scene_of(json!({
        "resolution": 12,
        "sources": [vent()],
        "obstacles": [ { "capsule": { "a": a, "b": b, "radius": r } } ],
    }))
    .expect("builds");
    let (fluid, _) = mac(&scene);
    let axis = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let len2 = axis.iter().map(|x| x * x).sum::<f64>();
    for (c, &is_solid) in fluid.solid().iter().enumerate() {
        let p = centre(c, fluid.dims(), fluid.h(), 3);
        let t = ((0..3).map(|k| (p[k] - a[k]) * axis[k]).sum::<f64>() / len2).clamp(0.0, 1.0);
        let near = [a[0] + t * axis[0], a[1] + t * axis[1], a[2] + t * axis[2]];
        assert_eq!(is_solid, distance(p, near) < r, "cell {c} at {p:?}");
    }
}

/// A closed OBJ sphere (vertices on the sphere, so the surface lies between the sphere and the
/// sphere shrunk by the chords' sagitta) marks as solid every cell whose centre is inside the
/// shrunk sphere and none outside the sphere; placed by its scale and translation.
#[test]
fn a_mesh_obstacle_marks_the_cells_inside_its_surface() {
    let dir = temp_dir("mesh-obstacle");
    let (rings, segments) = (24, 48);
    std::fs::write(dir.join("ball.obj"), sphere_obj([0.0; 3], 1.0, rings, segments)).expect("write");
    let (c, r) = ([0.45, 0.7, 0.52], 0.27);
    let value = json!({
        "resolution": 16,
        "sources": [vent()],
        "obstacle_meshes": [ { "mesh": "ball.obj", "scale": r, "translate": c } ],
    });
    let p: FluidSceneParams = params(&value).expect("parameters");
    let scene = p.scene_in(&BuildContext { base: Some(&dir) }).expect("builds");
    let (fluid, _) = mac(&scene);
    // Each face spans at most pi / rings of latitude and 2 pi / segments of longitude: its
    // points are at least r cos(pi / rings) from the centre.
    let inner = r * (std::f64::consts::PI / rings as f64).cos();
    let (band, solid) = solid_ball(fluid, 3, c, inner, r);
    assert!(band < solid / 10, "{band} of {solid} cells undecided");
    // A 2D scene cuts the mesh at z = 0: the disk of the sphere's equator (the sphere centred on
    // z = 0), and a mesh that does not reach z = 0 is refused.
    let (c, r) = ([0.45, 0.7, 0.0], 0.27);
    let value = json!({
        "dim": 2, "resolution": 40,
        "sources": [ { "shape": { "sphere": { "center": [0.5, 0.0, 0.0], "radius": 0.1 } } } ],
        "obstacle_meshes": [ { "mesh": "ball.obj", "scale": r, "translate": c } ],
    });
    let p: FluidSceneParams = params(&value).expect("parameters");
    let scene = p.scene_in(&BuildContext { base: Some(&dir) }).expect("builds");
    let (fluid, _) = mac(&scene);
    let inner = r * (std::f64::consts::PI / segments as f64 * 2.0).cos();
    let (band, solid) = solid_ball(fluid, 2, c, inner, r);
    assert!(solid > 100 && band < solid / 10, "{band} of {solid} cells undecided");
    let mut value = value;
    value["obstacle_meshes"][0]["translate"] = json!([0.45, 0.7, 0.5]);
    let p: FluidSceneParams = params(&value).expect("parameters");
    let msg = p.scene_in(&BuildContext { base: Some(&dir) }).expect_err("refused").to_string();
    assert!(msg.starts_with("field `obstacle_meshes[0]`: a 2D scene cuts meshes at z = 0"), "{msg}");
    std::fs::remove_dir_all(&dir).ok();
}

/// After each step with a sphere and a mesh obstacle the velocity is divergence-free in every
/// fluid cell to the pressure solve's tolerance, and no fluid crosses an obstacle's faces. The
/// box is closed: an open top extrapolates the velocity onto its faces after the projection (its
/// boundary condition), which leaves the top row's cells out of the solve's balance.
#[test]
fn steps_around_obstacles_end_divergence_free_with_no_flow_into_them() {
    let dir = temp_dir("divergence");
    std::fs::write(dir.join("ball.obj"), sphere_obj([0.0; 3], 1.0, 12, 24)).expect("write");
    for (dim, mesh) in [(3, true), (2, false)] {
        let meshes = if mesh {
            json!([ { "mesh": "ball.obj", "scale": 0.12, "translate": [0.25, 0.9, 0.5] } ])
        } else {
            json!([])
        };
        let value = json!({
            "dim": dim, "resolution": 12, "pressure_tolerance": 1e-10, "open_top": false,
            "sources": [vent()],
            "obstacles": [ { "sphere": { "center": [0.5, 0.45, 0.5], "radius": 0.15 } } ],
            "obstacle_meshes": meshes,
        });
        let p: FluidSceneParams = params(&value).expect("parameters");
        let mut scene = p.scene_in(&BuildContext { base: Some(&dir) }).expect("builds");
        for _ in 0..6 {
            let report = scene.step().expect("step");
            let (fluid, state) = mac(&scene);
            let divergence = fluid.max_divergence(state);
            assert_eq!(report.constraint_violation, Some(fluid.last_step().divergence));
            // The solve stops at 1e-10 of the largest imbalance it starts from, at most about
            // the vent's 0.5 m/s over a cell of 1/12 m, 6 1/s (measured: at most 4e-10 1/s).
            assert!(divergence < 1e-8, "{dim}D: max |div u| = {divergence}");
            // Faces between a solid cell and any other carry no flow.
            let (d, solid) = (fluid.dims(), fluid.solid());
            for a in 0..dim {
                let fd = fluid.face_dims(a);
                let stride = [1, d[0], d[0] * d[1]][a];
                for (f, &u) in state.vel[a].iter().enumerate() {
                    let (i, j, k) = (f % fd[0], (f / fd[0]) % fd[1], f / (fd[0] * fd[1]));
                    let n = [i, j, k];
                    if n[a] == 0 || n[a] == d[a] {
                        continue;
                    }
                    let hi = i + d[0] * (j + d[1] * k);
                    if solid[hi] || solid[hi - stride] {
                        assert_eq!(u, 0.0, "{dim}D face {f} of component {a}");
                    }
                }
            }
        }
        assert!(mac(&scene).1.density.iter().sum::<f64>() > 0.0);
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// A source holds the density of the fluid cells whose centres lie inside it at its own: from
/// rest, one step leaves exactly `density x` the volume of those cells (nothing moves yet: the
/// forces of the step act on the fluid before the source), a second step does not add to it
/// (a source holds, it does not accumulate), and the covered volume is the sphere's to within
/// the cells' size.
#[test]
fn a_source_holds_its_cells_at_its_density() {
    use std::f64::consts::PI;
    for (dim, n) in [(3, 32), (2, 64)] {
        let (c, r, density) = ([0.5, 0.3, 0.5], 0.15, 2.5);
        let size = if dim == 3 { json!([1.0, 1.5, 1.0]) } else { json!([1.0, 1.5]) };
        let mut scene = scene_of(json!({
            "dim": dim, "resolution": n, "size": size, "buoyancy_temperature": 0.0,
            "buoyancy_density": 0.0, "vorticity_confinement": 0.0,
            "sources": [ { "shape": { "sphere": { "center": c, "radius": r } }, "density": density,
                           "temperature": 3.0 } ],
        }))
        .expect("builds");
        let h = scene.cell_size();
        let cell = h.powi(dim as i32);
        let dims = scene.dims();
        let inside: Vec<bool> = (0..dims.iter().product())
            .map(|k| {
                let mut q = c;
                if dim == 2 {
                    q[2] = 0.0;
                }
                distance(centre(k, dims, h, dim), q) < r
            })
            .collect();
        let count = inside.iter().filter(|x| **x).count();
        for step in 0..2 {
            scene.step().expect("step");
            let (_, state) = mac(&scene);
            let total: f64 = state.density.iter().sum::<f64>() * cell;
            assert_eq!(total, density * count as f64 * cell, "{dim}D after step {}", step + 1);
            for (k, &is_inside) in inside.iter().enumerate() {
                let expected = if is_inside { (density, 3.0) } else { (0.0, 0.0) };
                assert_eq!((state.density[k], state.temperature[k]), expected, "{dim}D cell {k}");
            }
        }
        // Every cell whose centre is inside lies within half a cell diagonal of the sphere
        // (disk), and every point that far inside is in such a cell: the covered volume lies
        // between the volumes of the radii r -+ sqrt(d) h / 2.
        let ball = |r: f64| if dim == 3 { 4.0 / 3.0 * PI * r.powi(3) } else { PI * r * r };
        let s = (dim as f64).sqrt() * h / 2.0;
        let covered = count as f64 * cell;
        assert!(ball(r - s) <= covered && covered <= ball(r + s), "{dim}D: {covered} against {}", ball(r));
    }
}

/// A source with a velocity drives the smoke it makes: the plume rises from a vent on the
/// floor that blows upward, with buoyancy off.
#[test]
fn a_source_with_a_velocity_blows_its_smoke_along() {
    let height = |velocity: [f64; 3]| {
        let mut scene = scene_of(json!({
            "resolution": 10, "buoyancy_temperature": 0.0, "buoyancy_density": 0.0,
            "sources": [ { "shape": { "sphere": { "center": [0.5, 0.0, 0.5], "radius": 0.25 } },
                           "velocity": velocity } ],
        }))
        .expect("builds");
        for _ in 0..8 {
            scene.step().expect("step");
        }
        let (fluid, state) = mac(&scene);
        let total: f64 = state.density.iter().sum();
        let moment: f64 =
            state.density.iter().enumerate().map(|(k, d)| d * centre(k, fluid.dims(), fluid.h(), 3)[1]).sum();
        moment / total
    };
    let (still, blown) = (height([0.0; 3]), height([0.0, 0.7, 0.0]));
    // Without a velocity nothing moves the smoke: its mean height is the source's cells'.
    assert!(still < 0.13, "{still}");
    assert!(blown > still + 0.1, "mean height {blown} with the vent blowing, {still} without");
}

#[test]
fn sources_and_obstacles_that_miss_the_grid_are_named() {
    let source = |center: [f64; 3], radius: f64| json!({ "shape": { "sphere": { "center": center, "radius": radius } } });
    let msg = err(json!({ "resolution": 8, "sources": [vent(), source([0.5, 2.0, 0.5], 0.2)] }));
    assert!(
        msg.starts_with("field `sources[1]`: lies outside the domain [0, 1] x [0, 1.5] x [0, 1]"),
        "{msg}"
    );
    let msg = err(json!({ "resolution": 8, "sources": [source([0.5, 0.5, 0.5], 0.01)] }));
    assert!(
        msg.starts_with(
            "field `sources[0]`: covers no cell centre of the 8 x 12 x 8 cells of 0.1250 m (resolution 8)"
        ),
        "{msg}"
    );
    let msg = err(json!({
        "resolution": 8,
        "sources": [vent(), source([0.5, 0.7, 0.5], 0.1)],
        "obstacles": [ { "box": { "center": [0.5, 0.2, 0.5], "half_extents": [0.1, 0.1, 0.1] } },
                       { "sphere": { "center": [0.5, 0.7, 0.5], "radius": 0.3 } } ],
    }));
    assert!(
        msg.starts_with("field `sources[1]`: lies inside obstacles[1]: every cell it covers is solid"),
        "{msg}"
    );
    let msg = err(json!({
        "resolution": 8,
        "sources": [vent()],
        "obstacles": [ { "sphere": { "center": [0.5, 0.7, 0.5], "radius": 0.3 } },
                       { "sphere": { "center": [0.5, 0.7, 0.5], "radius": 0.03 } } ],
    }));
    assert!(
        msg.starts_with(
            "field `obstacles[1]`: covers no cell centre of the 8 x 12 x 8 cells of 0.1250 m (resolution 8)"
        ),
        "{msg}"
    );
    let msg = err(json!({
        "resolution": 8, "sources": [vent()],
        "obstacles": [ { "box": { "center": [3.0, 0.7, 0.5], "half_extents": [0.5, 0.5, 0.5] } } ],
    }));
    assert!(msg.starts_with("field `obstacles[0]`: lies outside the domain"), "{msg}");
    // A plane whose solid side (below y = -1) is beyond the domain has no extent to report.
    let msg = err(json!({
        "resolution": 8, "sources": [vent()],
        "obstacles": [ { "plane": { "point": [0.0, -1.0, 0.0], "normal": [0.0, 1.0, 0.0] } } ],
    }));
    assert!(
        msg.starts_with("field `obstacles[0]`: its solid side holds no cell centre")
            && msg.contains("the plane lies beyond the domain"),
        "{msg}"
    );
}

#[test]
fn mesh_problems_name_the_field_and_the_file() {
    let dir = temp_dir("mesh-errors");
    let context = BuildContext { base: Some(&dir) };
    let build = |value: Value| (KIND.build)(&value, &context).err().expect("refused").to_string();
    let msg = build(json!({ "sources": [vent()], "obstacle_meshes": [ { "mesh": "missing.obj" } ] }));
    assert!(msg.starts_with("field `obstacle_meshes[0].mesh`: ") && msg.contains("missing.obj"), "{msg}");
    // A cube without its top: open.
    let open = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n\
                f 1 3 2\nf 1 4 3\nf 1 2 6\nf 1 6 5\nf 2 3 7\nf 2 7 6\nf 3 4 8\nf 3 8 7\nf 4 1 5\nf 4 5 8\n";
    std::fs::write(dir.join("open.obj"), open).expect("write");
    let msg = build(json!({ "sources": [vent()], "obstacle_meshes": [ { "mesh": "open.obj" } ] }));
    assert!(
        msg.starts_with("field `obstacle_meshes[0].mesh`: ")
            && msg.contains("open.obj: the surface is not closed"),
        "{msg}"
    );
    std::fs::write(dir.join("bad.obj"), "v 0 0 0\nv 1 0 zero\n").expect("write");
    let msg = build(json!({ "sources": [ { "mesh": "bad.obj" } ] }));
    assert!(msg.starts_with("field `sources[0].mesh`: ") && msg.contains("bad.obj:2:"), "{msg}");
    std::fs::write(dir.join("ball.obj"), sphere_obj([0.0; 3], 1.0, 6, 8)).expect("write");
    let msg =
        build(json!({ "sources": [vent()], "obstacle_meshes": [ { "mesh": "ball.obj", "scale": 0.0 } ] }));
    assert!(msg.starts_with("field `obstacle_meshes[0].scale`: must be positive"), "{msg}");
    // A mesh obstacle between cell centres is named with the grid; a source inside it too.
    let msg = build(json!({ "resolution": 8, "sources": [vent()],
                            "obstacle_meshes": [ { "mesh": "ball.obj", "scale": 0.03, "translate": [0.5, 0.5, 0.5] } ] }));
    assert!(
        msg.starts_with("field `obstacle_meshes[0]`: covers no cell centre of the 8 x 12 x 8 cells"),
        "{msg}"
    );
    let msg = build(json!({ "resolution": 8,
                            "sources": [vent(), { "shape": { "sphere": { "center": [0.5, 0.8, 0.5], "radius": 0.1 } } }],
                            "obstacles": [ { "sphere": { "center": [0.1, 0.1, 0.1], "radius": 0.1 } } ],
                            "obstacle_meshes": [ { "mesh": "ball.obj", "scale": 0.3, "translate": [0.5, 0.8, 0.5] } ] }));
    assert!(msg.starts_with("field `sources[1]`: lies inside obstacle_meshes[0]: every cell"), "{msg}");
    let msg = build(json!({ "sources": [ { "mesh": "ball.obj", "scale": 0.2, "translate": [0.5, 0.3, 0.5] },
                                         { "mesh": "ball.obj", "scale": 0.2, "translate": [5.0, 0.3, 0.5] } ] }));
    assert!(msg.starts_with("field `sources[1]`: lies outside the domain"), "{msg}");
    // A mesh source inside the domain builds, relative to the context's folder.
    let value = json!({ "resolution": 8, "sources": [ { "mesh": "ball.obj", "scale": 0.2, "translate": [0.5, 0.3, 0.5] } ] });
    assert!((KIND.build)(&value, &context).is_ok());
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn bad_fields_of_a_smoke_scene_are_named() {
    let shape = json!({ "sphere": { "center": [0.5, 0.1, 0.5], "radius": 0.1 } });
    let cases = [
        (json!({}), "field `sources`: a fluid scene is a preset (`preset`, one of smoke-box-2d"),
        (json!({ "sources": [] }), "field `sources`: a fluid scene is a preset"),
        (
            json!({ "preset": "smoke-plume-3d", "sources": [vent()] }),
            "field `sources`: belongs to a smoke scene of your own; preset `smoke-plume-3d` keeps its own",
        ),
        (json!({ "preset": "lid-driven-cavity", "dim": 2 }), "field `dim`: belongs to a smoke scene"),
        (json!({ "dim": 4, "sources": [vent()] }), "field `dim`: must be 2 or 3, got 4"),
        (
            json!({ "dim": 2, "sources": [vent()] , "size": [1.0, 1.0, 1.0] }),
            "field `size`: a 2D domain takes 2 sizes",
        ),
        (json!({ "size": [1.0, -1.0, 1.0], "sources": [vent()] }), "field `size`: sizes must be positive"),
        (
            json!({ "size": [1.0, 0.01, 1.0], "sources": [vent()] }),
            "field `size`: size[1] = 0.01 m is less than two cells",
        ),
        (json!({ "resolution": 1, "sources": [vent()] }), "field `resolution`: must be at least 2"),
        // Past the memory available, whatever the machine: refused before the grid is made.
        (
            json!({ "resolution": 3000000, "sources": [vent()] }),
            "field `resolution`: 3000000 x 4500000 x 3000000 cells of 0.0000 m (resolution 3000000) needs about ",
        ),
        (
            json!({ "size": [1.0, 10.0, 1.0], "resolution": 1000000, "sources": [vent()] }),
            "field `resolution`: 1000000 x 10000000 x 1000000 cells of 0.0000 m (resolution 1000000) needs about ",
        ),
        (json!({ "viscosity": -1.0, "sources": [vent()] }), "field `viscosity`: must be finite and >= 0"),
        (json!({ "vorticity_confinement": -1.0, "sources": [vent()] }), "field `vorticity_confinement`"),
        (
            json!({ "sources": [ { "shape": shape, "scale": 2.0 } ] }),
            "field `sources[0].scale`: places a `mesh` source",
        ),
        (
            json!({ "sources": [ { "shape": shape, "mesh": "x.obj" } ] }),
            "field `sources[0]`: give one of `shape` and `mesh`, not both",
        ),
        (json!({ "sources": [ { "density": 2.0 } ] }), "field `sources[0]`: needs a region"),
        (
            json!({ "sources": [ { "shape": { "sphere": { "center": [0.5, 0.1, 0.5], "radius": -0.1 } } } ] }),
            "field `sources[0].shape`: sphere radius must be positive",
        ),
        (
            json!({ "dim": 2, "sources": [ { "shape": shape, "velocity": [0.0, 1.0, 1.0] } ] }),
            "field `sources[0].velocity`: a 2D scene has no z velocity",
        ),
        (
            json!({ "sources": [vent()], "obstacles": [ { "sphere": { "center": [0.5, 0.5, 0.5], "radius": 0.0 } } ] }),
            "field `obstacles[0]`: sphere radius must be positive",
        ),
        (
            json!({ "sources": [vent()], "obstacles": [ { "sphere": { "center": [0.5, 0.5, 0.5], "radiu": 0.1 } } ] }),
            "field `obstacles[0].sphere.radiu`: unknown field `radiu`, expected `center` or `radius`",
        ),
        (
            json!({ "sources": [vent()], "obstacles": [ { "mesh": "x.obj" } ] }),
            "field `obstacles[0]`: unknown variant `mesh`",
        ),
        (
            json!({ "sources": [vent()], "obstacle_meshes": [ { "mesh": "x.obj", "scael": 2.0 } ] }),
            "field `obstacle_meshes[0].scael`: unknown field `scael`, expected one of `mesh`, `scale`",
        ),
        (
            json!({ "preset": "smoke-plume-3d", "obstacle_meshes": [] }),
            "field `obstacle_meshes`: belongs to a smoke scene of your own",
        ),
        (
            json!({ "sources": [vent()], "pressure_tolerance": 0.0 }),
            "field `pressure_tolerance`: must be a positive finite number",
        ),
    ];
    for (value, expected) in cases {
        let msg = (KIND.build)(&value, &BuildContext::default()).err().expect("refused").to_string();
        assert!(msg.starts_with(expected), "{value}:\n  {msg}\n  expected {expected}");
    }
    // Values JSON cannot carry (a TOML `nan`) are refused too.
    let mut p = FluidSceneParams::smoke(vec![params(&vent()).expect("source")]);
    p.buoyancy_density = Some(f64::NAN);
    let msg = p.scene().expect_err("refused").to_string();
    assert!(msg.starts_with("field `buoyancy_density`: must be finite, got NaN"), "{msg}");
    let mut p = FluidSceneParams::smoke(vec![params(&vent()).expect("source")]);
    p.sources.as_mut().expect("sources")[0].density = f64::INFINITY;
    let msg = p.scene().expect_err("refused").to_string();
    assert!(msg.starts_with("field `sources[0].density`: must be finite, got inf"), "{msg}");
}

/// A smoke scene's parameters read back to the same JSON, its settings reach the solver, its
/// shape obstacles are drawn, and a checkpoint resumes it bit for bit.
#[test]
fn a_smoke_scene_round_trips_draws_its_shapes_and_resumes() {
    let value = json!({
        "dim": 3, "resolution": 8, "size": [1.0, 1.25, 0.75], "buoyancy_density": 0.1,
        "buoyancy_temperature": 2.0, "ambient_temperature": 0.5, "vorticity_confinement": 1.0,
        "viscosity": 0.001, "open_top": false, "advection": "bfecc", "splitting": "reflection",
        "pressure_solver": "cg", "pressure_tolerance": 1e-7,
        "sources": [vent(), { "mesh": "ball.obj", "scale": 0.1, "rotate": [0.1, 0.0, 0.0],
                              "translate": [0.2, 0.2, 0.3], "density": 0.5, "temperature": 2.0 }],
        "obstacles": [ { "sphere": { "center": [0.5, 0.6, 0.4], "radius": 0.2 } },
                       { "plane": { "point": [0.0, 1.0, 0.0], "normal": [0.0, -1.0, 1.0] } } ],
        "obstacle_meshes": [ { "mesh": "ball.obj", "scale": 0.1, "translate": [0.8, 0.8, 0.4] } ],
    });
    let p: FluidSceneParams = params(&value).expect("parameters");
    assert_eq!(serde_json::to_value(&p).expect("json"), value);
    let dir = temp_dir("round-trip");
    std::fs::write(dir.join("ball.obj"), sphere_obj([0.0; 3], 1.0, 8, 12)).expect("write");
    let context = BuildContext { base: Some(&dir) };
    let scene = p.scene_in(&context).expect("builds");
    assert_eq!(scene.dims(), [8, 10, 6]);
    let (fluid, state) = mac(&scene);
    let q = fluid.params();
    assert_eq!(
        (
            q.buoyancy_density,
            q.buoyancy_temperature,
            q.ambient_temperature,
            q.vorticity_confinement,
            q.viscosity
        ),
        (0.1, 2.0, 0.5, 1.0, 0.001)
    );
    assert_eq!(
        (q.advection, q.splitting, q.pressure, q.pressure_tolerance),
        (Advection::Bfecc, crate::advection::Splitting::Reflection, PressureMethod::ConjugateGradient, 1e-7)
    );
    assert!(q.walls.iter().flatten().all(|w| *w == Wall::NoSlip([0.0; 3])));
    assert!(state.temperature.iter().all(|t| *t == 0.5));
    let mut built = (KIND.build)(&value, &context).expect("builds");
    let props = built.context().props;
    assert_eq!(props, vec![anim_core::scene::Prop::Sphere { center: [0.5, 0.6, 0.4], radius: 0.2 }]);
    let dt = 0.05;
    for _ in 0..2 {
        built.step(dt).expect("step");
    }
    let saved = built.save();
    for _ in 0..2 {
        built.step(dt).expect("step");
    }
    let mut again = (KIND.build)(&value, &context).expect("builds");
    again.restore(&saved).expect("restores");
    for _ in 0..2 {
        again.step(dt).expect("step");
    }
    assert!(again.save() == built.save());
    std::fs::remove_dir_all(&dir).ok();
}

/// The defaults of a smoke scene are the `smoke-plume-3d` preset's settings.
#[test]
fn the_defaults_are_the_plumes() {
    let preset = scenes::smoke_plume_3d(defaults::RESOLUTION).expect("builds");
    let (fluid, _) = mac(&preset);
    let q = fluid.params();
    assert_eq!(
        (
            q.buoyancy_density,
            q.buoyancy_temperature,
            q.ambient_temperature,
            q.vorticity_confinement,
            q.viscosity
        ),
        (
            defaults::BUOYANCY_DENSITY,
            defaults::BUOYANCY_TEMPERATURE,
            defaults::AMBIENT_TEMPERATURE,
            defaults::VORTICITY_CONFINEMENT,
            defaults::VISCOSITY
        )
    );
    assert_eq!(q.pressure_tolerance, defaults::PRESSURE_TOLERANCE);
    let s = q.sources[0];
    assert_eq!((s.density, s.temperature), (defaults::SOURCE_DENSITY, defaults::SOURCE_TEMPERATURE));
    let h = preset.cell_size();
    let top = [0, 1, 2].map(|a| preset.dims()[a] as f64 * h);
    assert_eq!(top, defaults::SIZE_3D);
}
