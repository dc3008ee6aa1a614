//! Several bodies in one model: the mass of each is its density times its volume, a free body
//! keeps the exact momentum balance of its velocity and gravity, each element has its body's
//! material (a soft bar sags more than a stiff one by their Young's ratio), the bodies move as
//! if alone, pins hold, and every refusal of an `fem` scene names its field.

use super::*;
use crate::body::tests::{cube_obj, folder, testdata};
use crate::kind::KIND;
use crate::sim::{FemSimulation, TimeIntegrator};
use anim_core::scene::{BuildContext, BuildError};
use anim_core::solver::Solver;

fn spec(value: serde_json::Value) -> BodySpec {
    serde_json::from_value(value).expect("a valid spec")
}

/// The OBJ text of the box `[0, size]` as 12 outward triangles (the unit cube's, stretched).
fn box_obj(size: [f64; 3]) -> String {
    cube_obj(1.0, &[])
        .lines()
        .map(|line| match line.strip_prefix("v ") {
            Some(coords) => {
                let c: Vec<f64> = coords.split(' ').map(|x| x.parse().expect("number")).collect();
                format!("v {} {} {}\n", c[0] * size[0], c[1] * size[1], c[2] * size[2])
            }
            None => format!("{line}\n"),
        })
        .collect()
}

/// The volume of the Gmsh test cube (anim-io's testdata README): 0.1 x 0.7 x 0.123456789 m.
const TEST_CUBE_VOLUME: f64 = 0.1 * 0.7 * 0.123456789;

/// The total lumped mass is `sum_k rho_k V_k` for 4- and 10-node elements, and each body's
/// vertices carry its own `rho_k V_k`: a Gmsh box scaled by 2 (volume x 8) at 1000 kg/m³ and an
/// OBJ cube of side 0.4 (scaled from 1, 4 cells of 0.1 m across) at 300 kg/m³.
#[test]
fn the_mass_of_each_body_is_its_density_times_its_volume() {
    let dir = folder("bodies-mass");
    std::fs::write(dir.join("cube.obj"), cube_obj(1.0, &[])).expect("obj");
    std::fs::copy(testdata().join("cube_v41.msh"), dir.join("cube_v41.msh")).expect("msh");
    let bodies = [
        spec(serde_json::json!({
            "mesh": "cube_v41.msh",
            "material": { "young": 1e5, "poisson": 0.3, "density": 1000.0 },
            "scale": 2.0,
        })),
        spec(serde_json::json!({
            "mesh": "cube.obj", "cell": 0.1, "scale": 0.4, "translate": [3.0, 0.0, 0.0],
            "material": { "young": 1e6, "poisson": 0.45, "density": 300.0 },
        })),
    ];
    let want = [1000.0 * 8.0 * TEST_CUBE_VOLUME, 300.0 * 0.4f64.powi(3)];
    for order in [ElementOrder::Linear, ElementOrder::Quadratic] {
        let scene = build(&bodies, &World::default(), order, |p| dir.join(p)).expect("builds");
        let model = &scene.model;
        let owner = node_bodies(model, &[0, 8, 8 + 125]);
        let mut mass = [0.0; 2];
        for (i, m) in model.lumped_mass().iter().enumerate() {
            mass[owner[i]] += m;
        }
        for k in 0..2 {
            assert!(
                (mass[k] - want[k]).abs() < 1e-12 * want[k],
                "{order:?} body {k}: {} vs {}",
                mass[k],
                want[k]
            );
        }
        let total: f64 = model.lumped_mass().iter().sum();
        assert!((total - want[0] - want[1]).abs() < 1e-12 * total, "{order:?}");
        // The elements keep their body's material, in body order.
        assert_eq!(model.materials().len(), 2);
        let split = model.element_material().iter().position(|&m| m == 1).expect("body 1");
        assert_eq!(split, 6, "the Gmsh cube has 6 tetrahedra");
        assert!(model.element_material()[split..].iter().all(|&m| m == 1));
        assert_eq!(model.elements(), 6 + 6 * 64);
        assert_eq!((model.materials()[0].density, model.materials()[1].density), (1000.0, 300.0));
    }
    let _ = std::fs::remove_dir_all(dir);
}

/// A free body of a scene keeps the exact momentum balance of its `velocity` and the scene's
/// gravity: the internal forces sum to zero, so backward Euler gives the total momentum
/// `P_n = M (V_0 + n h g)` and the centre of mass `X_n = X_0 + n h V_0 + h^2 g n (n + 1) / 2`,
/// with `M = rho V` from the test cube's volume, for 4- and 10-node elements.
#[test]
fn a_falling_body_keeps_the_exact_momentum_balance() {
    let v0 = [0.5, -0.25, 1.0];
    let g = [0.3, 0.0, -9.81];
    let body = spec(serde_json::json!({
        "mesh": "cube_v41.msh", "velocity": v0,
        "material": { "young": 5e4, "poisson": 0.3, "density": 1000.0 },
    }));
    let world = World { gravity: g, ..World::default() };
    let total = 1000.0 * TEST_CUBE_VOLUME;
    for order in [ElementOrder::Linear, ElementOrder::Quadratic] {
        let scene =
            build(std::slice::from_ref(&body), &world, order, |p| testdata().join(p)).expect("builds");
        let mass = scene.model.lumped_mass().to_vec();
        let (mut sim, mut state) = scene.into_simulation().expect("simulation");
        let sum = |x: &[f64]| {
            let mut c = [0.0; 3];
            for (i, m) in mass.iter().enumerate() {
                for k in 0..3 {
                    c[k] += m * x[3 * i + k];
                }
            }
            c
        };
        let x0 = sum(&state.x).map(|c| c / total);
        let (h, n) = (0.01, 50);
        for _ in 0..n {
            sim.step(&mut state, h).expect("step");
        }
        let nf = f64::from(n);
        let (x, p) = (sum(&state.x).map(|c| c / total), sum(&state.v));
        for k in 0..3 {
            let want = total * (v0[k] + nf * h * g[k]);
            assert!((p[k] - want).abs() < 1e-11 * total, "{order:?} momentum {k}: {} vs {want}", p[k]);
            let want = x0[k] + nf * h * v0[k] + h * h * g[k] * nf * (nf + 1.0) / 2.0;
            assert!((x[k] - want).abs() < 1e-11, "{order:?} centre {k}: {} vs {want}", x[k]);
        }
    }
}

/// Two bars of the same mesh, clamped at `x = 0`, one four times stiffer, sag under a small load
/// (g = 0.1 m/s²: deflections of a few millimetres over a metre, the linear regime): the soft
/// bar's tip deflects four times as far (to 1e-3), solved quasi-statically in one model.
#[test]
fn a_soft_bar_sags_more_than_a_stiff_one_by_their_youngs_ratio() {
    let dir = folder("bodies-bars");
    std::fs::write(dir.join("bar.obj"), box_obj([1.0, 0.1, 0.1])).expect("obj");
    let bar = |young: f64, y: f64| {
        spec(serde_json::json!({
            "mesh": "bar.obj", "cell": 0.05, "translate": [0.0, y, 1.0],
            "material": { "young": young, "poisson": 0.3, "density": 1000.0 },
            "pin": { "box": { "min": [-0.01, y - 0.01, 0.99], "max": [0.01, y + 0.11, 1.11] } },
        }))
    };
    let world = World { gravity: [0.0, 0.0, -0.1], ..World::default() };
    let scene = build(&[bar(1e7, 0.0), bar(2.5e6, 0.5)], &world, ElementOrder::Linear, |p| dir.join(p))
        .expect("builds");
    let mut sim = FemSimulation::new(scene.model, scene.params.with_newton_tolerance(1e-12)).expect("sim");
    let mut x = scene.state.x.clone();
    sim.solve_static(&mut x, 1).expect("static solve");
    // The sag of the tip (x = 1) of the bar at `y`: the mean downward displacement there.
    let rest = &scene.state.x;
    let sag = |y: f64| {
        let tip: Vec<usize> = (0..rest.len() / 3)
            .filter(|&i| (rest[3 * i] - 1.0).abs() < 1e-9 && (rest[3 * i + 1] - y).abs() < 0.2)
            .collect();
        assert_eq!(tip.len(), 9, "a 3 x 3 tip face");
        tip.iter().map(|&i| rest[3 * i + 2] - x[3 * i + 2]).sum::<f64>() / tip.len() as f64
    };
    let (stiff, soft) = (sag(0.0), sag(0.5));
    assert!(stiff > 1e-4 && soft < 0.02, "sags {stiff} and {soft}");
    assert!((soft / stiff - 4.0).abs() < 4e-3, "ratio {} (sags {stiff}, {soft})", soft / stiff);
    let _ = std::fs::remove_dir_all(dir);
}

/// Bodies do not touch: two bodies thrown in one model move, step by step and bit for bit, as
/// each does alone (symplectic Euler, with the ground).
#[test]
fn each_body_moves_as_if_it_were_alone() {
    let dir = testdata();
    let body = |young: f64, x: f64, v: f64| {
        spec(serde_json::json!({
            "mesh": "cube_v41.msh", "translate": [x, 0.0, 0.0], "velocity": [v, 0.0, -1.0],
            "material": { "young": young, "poisson": 0.3, "density": 1000.0 },
        }))
    };
    let (a, b) = (body(1e5, 0.0, 0.5), body(4e5, 0.05, -0.5));
    let world = World { obstacles: vec![Obstacle::ground(0.3)], friction: 0.2, ..World::default() };
    let run = |bodies: &[BodySpec]| {
        let mut scene = build(bodies, &world, ElementOrder::Linear, |p| dir.join(p)).expect("builds");
        scene.params.integrator = TimeIntegrator::SymplecticEuler;
        let (mut sim, mut state) = scene.into_simulation().expect("sim");
        let mut lowest = f64::INFINITY;
        for _ in 0..400 {
            sim.step(&mut state, 2e-4).expect("step");
            lowest = state.x.chunks(3).map(|p| p[2]).fold(lowest, f64::min);
        }
        (state.x, lowest)
    };
    let (both, lowest) = run(&[a.clone(), b.clone()]);
    let ((alone_a, _), (alone_b, _)) = (run(&[a]), run(&[b]));
    assert!(both[..24].iter().map(|z| z.to_bits()).eq(alone_a.iter().map(|z| z.to_bits())));
    assert!(both[24..].iter().map(|z| z.to_bits()).eq(alone_b.iter().map(|z| z.to_bits())));
    // The bodies overlap (they pass through each other) and have landed on the ground.
    assert!(lowest < 0.3 + 1e-9, "lowest z {lowest}");
}

/// A pin box holds the vertices of its own body only, where they were placed.
#[test]
fn pins_hold_their_own_body() {
    let dir = testdata();
    let body = |x: f64, pin: bool| {
        let mut value = serde_json::json!({
            "mesh": "cube_v41.msh", "translate": [x, 0.0, 1.0],
            "material": { "young": 5e4, "poisson": 0.3, "density": 1000.0 },
        });
        if pin {
            // Around both bodies' lower faces (z = 1 + 1/3).
            value["pin"] =
                serde_json::json!({ "box": { "min": [-1.0, -1.0, 1.3], "max": [2.0, 1.0, 1.34] } });
        }
        spec(value)
    };
    let scene =
        build(&[body(0.0, false), body(1.0, true)], &World::default(), ElementOrder::Linear, |p| dir.join(p))
            .expect("builds");
    let x0 = scene.state.x.clone();
    let fixed = scene.model.fixed().to_vec();
    let (mut sim, mut state) = scene.into_simulation().expect("sim");
    for _ in 0..20 {
        sim.step(&mut state, 0.01).expect("step");
    }
    for i in 0..16 {
        let lower = x0[3 * i + 2] < 1.34;
        assert_eq!(fixed[3 * i], i >= 8 && lower, "vertex {i}");
        if i >= 8 && lower {
            assert_eq!(&state.x[3 * i..3 * i + 3], &x0[3 * i..3 * i + 3], "vertex {i} moved");
        } else {
            assert!(state.x[3 * i + 2] < x0[3 * i + 2] - 1e-4, "vertex {i} did not move down");
        }
    }
}

/// The memory of a scene is counted over its bodies: the body that takes the estimate past the
/// memory available is refused, naming its `cell` (an OBJ surface, counted from its lattice
/// before it is filled) or its `mesh`, with the tetrahedra the bodies before it took.
#[test]
fn the_body_past_the_memory_is_refused() {
    let dir = folder("bodies-limit");
    std::fs::write(dir.join("cube.obj"), cube_obj(1.0, &[])).expect("obj");
    std::fs::copy(testdata().join("cube_v41.msh"), dir.join("cube_v41.msh")).expect("msh");
    let material = serde_json::json!({ "young": 1e5, "poisson": 0.3, "density": 1000.0 });
    let msh = spec(serde_json::json!({ "mesh": "cube_v41.msh", "material": material }));
    // 6 x 4^3 = 384 tetrahedra.
    let obj = spec(serde_json::json!({ "mesh": "cube.obj", "cell": 0.25, "material": material }));
    let world = World::default();
    let (be, cholesky) = (TimeIntegrator::BackwardEuler, LinearSolverChoice::Cholesky);
    let budget =
        |order, available: f64| Budget { available: Some(available), ..Budget::new(order, be, cholesky) };
    let within = |bodies: &[BodySpec], order, available: f64| {
        build_within(bodies, &world, |p| dir.join(p), budget(order, available))
    };
    let linear = ElementOrder::Linear;
    let msh_vertices =
        crate::body::read_mesh(&dir.join("cube_v41.msh")).expect("reads").positions.len() as f64;
    // The mesh file first: the OBJ is checked, before its fill, with the file's counts and the
    // lattice's.
    let need = |size: MeshSize| size.need(linear, be, cholesky).bytes();
    let both = need(MeshSize::mesh(msh_vertices, 6.0).and(MeshSize::lattice([4.0; 3])));
    let scene = within(&[msh.clone(), obj.clone()], linear, both).expect("at the limit");
    assert_eq!(scene.model.elements(), 6 + 384);
    let e = within(&[msh.clone(), obj.clone()], linear, both - 1.0).expect_err("past the limit");
    assert_eq!(e.field, "bodies[1].cell");
    assert_eq!(e.memory, Some((both, both - 1.0)));
    for part in [
        "cube.obj at a cell of 0.25 m (4 x 4 x 4 lattice cubes",
        "up to 384 tetrahedra), with the 6 tetrahedra of the bodies before, needs about",
        "available: take a larger cell",
    ] {
        assert!(e.message.contains(part), "{part}: {e}");
    }
    // A mesh file is checked with its own counts once read: a second copy takes the scene past.
    let two = need(MeshSize::mesh(msh_vertices, 6.0).and(MeshSize::mesh(msh_vertices, 6.0)));
    assert!(within(&[msh.clone(), msh.clone()], linear, two).is_ok());
    let e = within(&[msh.clone(), msh], linear, two - 1.0).expect_err("past the limit");
    assert_eq!(e.field, "bodies[1].mesh");
    let part = "cube_v41.msh (6 tetrahedra), with the 6 tetrahedra of the bodies before, needs about";
    assert!(e.message.contains(part), "{part}: {e}");
    assert!(e.message.ends_with("available: take a coarser mesh"), "{e}");
    // 10-node elements take more: a lattice of 15^3 cubes (up to 20,250 tetrahedra) that fits
    // as tet4 is refused as tet10 before the fill.
    let fine = spec(serde_json::json!({ "mesh": "cube.obj", "cell": 0.07, "material": material }));
    let lattice = MeshSize::lattice([15.0; 3]);
    let tet4 = lattice.need(linear, be, cholesky).bytes();
    assert!(lattice.need(ElementOrder::Quadratic, be, cholesky).bytes() > 4.0 * tet4);
    let e = within(std::slice::from_ref(&fine), ElementOrder::Quadratic, tet4).expect_err("tet10 past");
    assert_eq!(e.field, "bodies[0].cell");
    assert!(e.message.contains("up to 20250 tetrahedra)"), "{e}");
    assert!(within(&[fine], linear, tet4).is_ok());
    // Through the kind, against the machine's memory: a cell of 10 microns on a 1 m cube (1e15
    // lattice cubes) is refused on any machine, as a refusal of memory naming the field.
    let tiny = serde_json::json!({ "bodies": [{ "mesh": "cube.obj", "cell": 1e-5, "material": material }] });
    let context = BuildContext { base: Some(&dir) };
    match (KIND.build)(&tiny, &context).err().expect("refused") {
        BuildError::Memory { field, message, bytes, .. } => {
            assert_eq!(field, "bodies[0].cell");
            assert!(message.contains("100000 x 100000 x 100000 lattice cubes") && bytes > 1e18, "{message}");
        }
        other => panic!("{other:?}"),
    }
    let _ = std::fs::remove_dir_all(dir);
}

/// `pin.vertices` are the mesh file's vertex indices, of their own body: vertex `i` of the second
/// body is the file's vertex `i` as placed, and it alone is held, for 4- and 10-node elements;
/// with a box too, both are pinned.
#[test]
fn listed_vertices_are_pinned_by_their_index_in_the_file() {
    let dir = testdata();
    let file = anim_io::gmsh::read_gmsh(dir.join("cube_v41.msh")).expect("reads").tet_mesh();
    let body = |x: f64, pin: Option<serde_json::Value>| {
        let mut value = serde_json::json!({
            "mesh": "cube_v41.msh", "translate": [x, 0.0, 1.0],
            "material": { "young": 5e4, "poisson": 0.3, "density": 1000.0 },
        });
        if let Some(pin) = pin {
            value["pin"] = pin;
        }
        spec(value)
    };
    // The lowest and the highest vertex of the file, by z then x.
    let by_height = |i: &usize, j: &usize| {
        let (p, q) = (file.positions[*i], file.positions[*j]);
        (p[2], p[0], p[1]).partial_cmp(&(q[2], q[0], q[1])).expect("finite")
    };
    let lowest = (0..8).min_by(by_height).expect("vertices");
    let highest = (0..8).max_by(by_height).expect("vertices");
    for order in [ElementOrder::Linear, ElementOrder::Quadratic] {
        let listed = serde_json::json!({ "vertices": [highest, lowest, highest] });
        let scene =
            build(&[body(0.0, None), body(1.0, Some(listed))], &World::default(), order, |p| dir.join(p))
                .expect("builds");
        let x0 = scene.state.x.clone();
        for i in 0..8 {
            let want = [file.positions[i][0] + 1.0, file.positions[i][1], file.positions[i][2] + 1.0];
            assert_eq!(&x0[3 * (8 + i)..3 * (8 + i) + 3], &want, "vertex {i} of body 1");
        }
        let fixed = scene.model.fixed().to_vec();
        let held: Vec<usize> = (0..fixed.len() / 3).filter(|&i| fixed[3 * i]).collect();
        let mut want = vec![8 + lowest, 8 + highest];
        want.sort_unstable();
        assert_eq!(held, want, "{order:?}");
        let (mut sim, mut state) = scene.into_simulation().expect("sim");
        for _ in 0..10 {
            sim.step(&mut state, 0.01).expect("step");
        }
        for &i in &held {
            assert_eq!(&state.x[3 * i..3 * i + 3], &x0[3 * i..3 * i + 3], "{order:?} vertex {i} moved");
        }
        assert!(state.x[2] < x0[2] - 1e-4, "{order:?}: the free body did not fall");
        // With a box around the lower face of the second body too, both are held.
        let both = serde_json::json!({
            "vertices": [highest], "box": { "min": [0.5, -1.0, 1.3], "max": [2.0, 1.0, 1.34] },
        });
        let scene =
            build(&[body(0.0, None), body(1.0, Some(both))], &World::default(), order, |p| dir.join(p))
                .expect("builds");
        let fixed = scene.model.fixed();
        let x0 = &scene.state.x;
        for i in 0..fixed.len() / 3 {
            let body1 = x0[3 * i] > 0.5;
            let want = body1 && (x0[3 * i + 2] < 1.34 || i == 8 + highest);
            assert_eq!(fixed[3 * i], want, "{order:?} vertex {i}");
        }
    }
}

/// Pinned vertices start at rest, whatever their body's `velocity` (as anim-core's `PinSpec`
/// says and pbd and springs do); the others, of either body, start with their body's, for 4- and
/// 10-node elements (the edge nodes in the pin box pinned too).
#[test]
fn pinned_vertices_start_at_rest() {
    let dir = testdata();
    let body = |x: f64, v: [f64; 3], pin: bool| {
        let mut value = serde_json::json!({
            "mesh": "cube_v41.msh", "translate": [x, 0.0, 1.0], "velocity": v,
            "material": { "young": 5e4, "poisson": 0.3, "density": 1000.0 },
        });
        if pin {
            // The lower face of the body at x = 1 (z = 1 + 1/3).
            value["pin"] = serde_json::json!({ "box": { "min": [0.5, -1.0, 1.3], "max": [2.0, 1.0, 1.34] } });
        }
        spec(value)
    };
    let velocity = [[0.25, 0.0, -1.0], [0.5, -0.5, 2.0]];
    let bodies = [body(0.0, velocity[0], false), body(1.0, velocity[1], true)];
    for order in [ElementOrder::Linear, ElementOrder::Quadratic] {
        let scene = build(&bodies, &World::default(), order, |p| dir.join(p)).expect("builds");
        let (x, v) = (&scene.state.x, &scene.state.v);
        let fixed = scene.model.fixed();
        let mut pinned = 0;
        for i in 0..x.len() / 3 {
            let lower = x[3 * i + 2] < 1.34;
            let k = usize::from(x[3 * i] > 0.5);
            assert!((0..3).all(|c| fixed[3 * i + c] == (k == 1 && lower)), "{order:?} vertex {i}");
            let want = if k == 1 && lower { [0.0; 3] } else { velocity[k] };
            assert_eq!(&v[3 * i..3 * i + 3], &want, "{order:?} vertex {i}");
            pinned += usize::from(k == 1 && lower);
        }
        // The four lower corners, and for 10-node elements the midpoints of the five edges of
        // the face's two triangles.
        assert_eq!(pinned, if order == ElementOrder::Linear { 4 } else { 9 }, "{order:?}");
    }
}

fn field(e: BuildError) -> (String, String) {
    match e {
        BuildError::Invalid { field, message } | BuildError::Schema { field, message } => (field, message),
        other => panic!("unexpected {other}"),
    }
}

/// Through the `fem` kind: each refusal names the field of the `[scene]` table, and the file.
#[test]
fn the_fem_kind_names_the_field_it_refuses() {
    let dir = folder("bodies-kind");
    std::fs::write(dir.join("cube.obj"), cube_obj(1.0, &[])).expect("obj");
    std::fs::write(dir.join("holed.obj"), cube_obj(1.0, &[7])).expect("obj");
    std::fs::copy(testdata().join("cube_v41.msh"), dir.join("cube_v41.msh")).expect("msh");
    let build = |value: serde_json::Value| (KIND.build)(&value, &BuildContext { base: Some(&dir) });
    let refused = |value: serde_json::Value| field(build(value).err().expect("refused"));
    let material = serde_json::json!({ "young": 5e4, "poisson": 0.3, "density": 1000.0 });
    let msh = serde_json::json!({ "mesh": "cube_v41.msh", "material": material });
    let obj = serde_json::json!({ "mesh": "cube.obj", "cell": 0.5, "material": material });
    let with = |base: &serde_json::Value, key: &str, value: serde_json::Value| {
        let mut b = base.clone();
        b[key] = value;
        b
    };
    assert!(build(serde_json::json!({ "bodies": [msh, obj] })).is_ok());
    assert!(build(serde_json::json!({ "bodies": [msh, obj], "element": "tet10" })).is_ok());
    let boxes = serde_json::json!([
        { "plane": { "point": [0.0, 0.0, 0.0], "normal": [0.0, 0.0, 1.0] } },
        { "box": { "center": [0.0, 0.0, 0.0], "half_extents": [1.0, 1.0, 0.1] } },
        { "capsule": { "a": [0.0, 0.0, 0.0], "b": [1.0, 0.0, 0.0], "radius": 0.1 } },
    ]);
    assert!(build(serde_json::json!({ "bodies": [msh], "obstacles": boxes, "friction": 0.3 })).is_ok());

    // A pin box around body 0 only is empty for body 1.
    let pin = serde_json::json!({ "box": { "min": [-0.31, 0.0, 0.3], "max": [-0.19, 0.72, 0.46] } });
    let (f, m) =
        refused(serde_json::json!({ "bodies": [with(&msh, "pin", pin.clone()), with(&obj, "pin", pin)] }));
    assert_eq!(f, "bodies[1].pin");
    assert!(m.contains("body 1") && m.contains("cube.obj"), "{m}");
    let (f, m) = refused(serde_json::json!({ "bodies": [msh, with(&obj, "mesh", "holed.obj".into())] }));
    assert_eq!(f, "bodies[1].mesh");
    assert!(m.contains("holed.obj") && m.contains("edge ("), "{m}");
    let (f, m) = refused(serde_json::json!({ "bodies": [with(&msh, "cell", 0.1.into())] }));
    assert_eq!(f, "bodies[0].cell");
    assert!(m.contains("cube_v41.msh"), "{m}");
    let mut no_cell = obj.clone();
    no_cell.as_object_mut().expect("object").remove("cell");
    let (f, m) = refused(serde_json::json!({ "bodies": [msh, no_cell] }));
    assert_eq!(f, "bodies[1].cell");
    assert!(m.contains("cube.obj"), "{m}");
    let (f, m) = refused(serde_json::json!({ "bodies": [msh, with(&msh, "mesh", "missing.msh".into())] }));
    assert_eq!(f, "bodies[1].mesh");
    assert!(m.contains("missing.msh"), "{m}");
    let bad_box =
        serde_json::json!([{ "box": { "center": [0.0, 0.0, 0.0], "half_extents": [1.0, 0.0, 1.0] } }]);
    assert_eq!(refused(serde_json::json!({ "bodies": [msh], "obstacles": bad_box })).0, "obstacles[0]");
    for (key, value) in [("friction", -0.1), ("contact_stiffness", 0.0), ("rayleigh", -1.0)] {
        let mut scene = serde_json::json!({ "bodies": [msh] });
        scene[key] = value.into();
        assert_eq!(refused(scene).0, key);
    }
    assert_eq!(refused(serde_json::json!({ "bodies": [] })).0, "bodies");
    // Presets and bodies take their own fields.
    let (f, m) = refused(serde_json::json!({ "preset": "soft-cube-drop", "obstacles": boxes }));
    assert_eq!(f, "obstacles");
    assert!(m.contains("goes with `bodies`"), "{m}");
    assert_eq!(
        refused(serde_json::json!({ "preset": "soft-cube-drop", "gravity": [0.0, 0.0, -1.0] })).0,
        "gravity"
    );
    assert_eq!(refused(serde_json::json!({ "bodies": [msh], "resolution": 3 })).0, "resolution");
    assert_eq!(refused(serde_json::json!({ "bodies": [msh], "preset": "twisted-bar" })).0, "bodies");
    let (f, m) = refused(serde_json::json!({}));
    assert_eq!(f, "preset");
    assert!(m.contains("`bodies`"), "{m}");
    // Unknown fields: a typo in a body, the one-body table of old.
    assert!(refused(serde_json::json!({ "bodies": [with(&msh, "scal", 2.0.into())] })).1.contains("scal"));
    assert!(refused(serde_json::json!({ "body": msh })).1.contains("body"));
    // The pin box alone, as fem spelled it before every kind shared `pin = { vertices, box }`.
    let old_pin = serde_json::json!({ "min": [-1.0, -1.0, 0.0], "max": [1.0, 1.0, 1.0] });
    let (f, m) = refused(serde_json::json!({ "bodies": [with(&msh, "pin", old_pin)] }));
    assert_eq!(f, "bodies[0].pin");
    assert!(m.contains("`min`") && m.contains("pin = { box = { min"), "{m}");
    let _ = std::fs::remove_dir_all(dir);
}
