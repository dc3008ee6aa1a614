//! Mesh obstacles: the penalty of a distance field against finite differences, a cube resting on
//! a mesh sphere and on a mesh box where it rests on the analytic sphere and box, the explicit
//! projection keeping vertices out, thread-count determinism, and the scene file's
//! `obstacle_meshes` (a body resting on one, every refusal naming its field and the file).

#![allow(clippy::unwrap_used, clippy::expect_used)]

use crate::KIND;
use crate::body::tests::{cube_obj, folder, testdata};
use crate::boundary::{Collider, Obstacle};
use crate::generate::box_mesh;
use crate::material::{Material, MaterialModel};
use crate::model::{EARTH_GRAVITY, FemModel};
use crate::sim::{FemParams, FemSimulation, TimeIntegrator};
use anim_core::glam::DVec3;
use anim_core::integrate::State;
use anim_core::scene::{BuildContext, Frame};
use anim_core::solver::Solver;
use anim_core::surface::{ClosedSurface, DistanceField, icosphere};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

const RADIUS: f64 = 0.5;

/// An icosphere of `subdivisions` scaled to `RADIUS` about the origin and turned to have a
/// vertex (which lies on the sphere) at the top, and its sagitta: how far its faces come inside
/// the sphere, `RADIUS` minus the least distance from the centre to a face's plane (the deepest
/// point of a face is the foot of the perpendicular from the centre).
fn mesh_ball(subdivisions: usize) -> (ClosedSurface, f64) {
    let (p, t) = icosphere(subdivisions);
    // The icosahedron's vertex (0, 1, phi) / |.| turned about x onto +z.
    let golden = 0.5 * (1.0 + 5f64.sqrt());
    let turn = anim_core::glam::DMat3::from_rotation_x(1f64.atan2(golden));
    let top = turn * DVec3::new(0.0, 1.0, golden).normalize();
    assert!(top.z > 1.0 - 1e-12, "{top}");
    let p: Vec<[f64; 3]> = p.iter().map(|v| (RADIUS * (turn * DVec3::from_array(*v))).to_array()).collect();
    let nearest = t
        .iter()
        .map(|f| {
            let [a, b, c] = f.map(|i| DVec3::from_array(p[i]));
            let n = (b - a).cross(c - a).normalize();
            n.dot(a).abs()
        })
        .fold(f64::INFINITY, f64::min);
    (ClosedSurface::new(p, t).unwrap(), RADIUS - nearest)
}

/// The box `[lo, hi]` as a closed surface of 12 outward triangles.
fn mesh_box(lo: [f64; 3], hi: [f64; 3]) -> ClosedSurface {
    let (p, t) = anim_core::surface::cuboid(lo, hi);
    ClosedSurface::new(p, t).unwrap()
}

fn material() -> Material {
    Material::new(MaterialModel::StableNeoHookean, 1e5, 0.3, 1000.0).unwrap()
}

/// A 10 cm cube of 2 x 2 x 2 cells with its bottom centre at `(0, 0, z)`, under gravity.
fn cube(z: f64) -> FemModel {
    let mesh = box_mesh([-0.05, -0.05, z], [0.1; 3], [2, 2, 2]).unwrap();
    FemModel::new(mesh, material()).unwrap().with_gravity(EARTH_GRAVITY)
}

fn settle(model: FemModel, params: FemParams, dt: f64, steps: usize) -> State {
    let mut sim = FemSimulation::new(model, params).unwrap();
    let mut state = sim.rest_state();
    for _ in 0..steps {
        sim.step(&mut state, dt).unwrap();
    }
    state
}

fn largest_difference(a: &[f64], b: &[f64]) -> f64 {
    a.chunks(3)
        .zip(b.chunks(3))
        .map(|(p, q)| DVec3::from_slice(p).distance(DVec3::from_slice(q)))
        .fold(0.0, f64::max)
}

/// The penalty of a mesh obstacle: its gradient is the energy's (central differences), and the
/// difference quotient of the gradient is the Gauss-Newton Hessian `k g g^T` plus the dropped
/// curvature term `k phi H` (`H` the field's Hessian), so the Hessian used leaves out exactly
/// that term.
#[test]
fn the_mesh_penalty_is_the_derivative_of_its_energy() {
    let (ball, _) = mesh_ball(4);
    let field = DistanceField::around(&ball, 0.02, 0.05).unwrap();
    let c = Collider::Mesh(&field);
    let k = 1e4;
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let step = 1e-7;
    let mut checked = 0;
    while checked < 50 {
        let dir =
            DVec3::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
        if dir.length() < 0.1 {
            continue;
        }
        let x = (dir.normalize() * (RADIUS - rng.random_range(0.005..0.04))).to_array();
        let (_, g, h) = c.penalty(k, x).expect("inside");
        let (phi, grad_phi) = c.gradient(x).unwrap();
        let curvature = field.sample(DVec3::from_array(x)).unwrap().hessian;
        let energy = |y: [f64; 3]| c.penalty(k, y).map_or(0.0, |(e, _, _)| e);
        let gradient = |y: [f64; 3]| c.penalty(k, y).map_or([0.0; 3], |(_, g, _)| g);
        for a in 0..3 {
            let mut xp = x;
            let mut xm = x;
            xp[a] += step;
            xm[a] -= step;
            let fd = (energy(xp) - energy(xm)) / (2.0 * step);
            assert!((fd - g[a]).abs() <= 1e-6 * k * phi.abs(), "{x:?} gradient {a}: {fd} vs {}", g[a]);
            let (gp, gm) = (gradient(xp), gradient(xm));
            for r in 0..3 {
                let fdh = (gp[r] - gm[r]) / (2.0 * step);
                let exact = h[3 * r + a] + k * phi * curvature.col(a)[r];
                assert!((fdh - exact).abs() <= 1e-5 * k, "{x:?} hessian ({r}, {a}): {fdh} vs {exact}");
            }
            // The Gauss-Newton block is `k g g^T` with `g` the field's gradient.
            for r in 0..3 {
                assert_eq!(h[3 * r + a], k * grad_phi[r] * grad_phi[a]);
            }
        }
        checked += 1;
    }
}

/// A soft plate, every vertex held in x and y, settles (backward Euler, penalty, friction,
/// Rayleigh damping) over the top of an icosphere of 5120 triangles sampled every 1 cm and over
/// the analytic sphere of the same radius, bending over it. The field's distance is within the
/// icosphere's sagitta (its faces lie inside the sphere by up to that) plus the interpolation
/// error (`h^2 / 8` times the curvature `1 / R`) of the sphere's; a vertex held in x and y meets
/// a surface lower by `d` along the normal `n` a height `d / n_z` lower, so the vertices end
/// apart by at most that over the least `n_z` under the plate (its corners).
#[test]
fn a_plate_rests_on_a_mesh_sphere_where_it_rests_on_the_sphere() {
    let (ball, sagitta) = mesh_ball(4);
    let h = 0.01;
    let field = DistanceField::around(&ball, h, 0.05).unwrap();
    let params = FemParams::new(TimeIntegrator::BackwardEuler).with_rayleigh(0.01);
    let half = 0.1;
    let run = |mesh: bool| {
        let plate =
            box_mesh([-half, -half, RADIUS + 0.005], [2.0 * half, 2.0 * half, 0.02], [6, 6, 1]).unwrap();
        let soft = Material::new(MaterialModel::StableNeoHookean, 2e4, 0.3, 1000.0).unwrap();
        let mut model = FemModel::new(plate, soft).unwrap().with_gravity(EARTH_GRAVITY);
        for v in 0..model.vertices() {
            model.pin(v, [true, true, false]).unwrap();
        }
        if mesh {
            model.add_mesh_obstacle(field.clone(), 1e6, 0.3).unwrap();
        } else {
            let sphere = Obstacle::Sphere { center: [0.0; 3], radius: RADIUS };
            model.add_obstacle_with_friction(sphere, 1e6, 0.3).unwrap();
        }
        settle(model, params, 0.01, 60)
    };
    let (analytic, meshed) = (run(false), run(true));
    // Bent over the sphere: the corners below the centre.
    let z = |x: &[f64], v: usize| x[3 * v + 2];
    let (centre, corner) = (3 * 7 + 3, 0);
    assert!(z(&analytic.x, centre) - z(&analytic.x, corner) > 0.005, "{:?}", &analytic.x[..3]);
    assert!((z(&analytic.x, centre) - RADIUS).abs() < 1e-3);
    let n_z = (1.0 - 2.0 * half * half / (RADIUS * RADIUS)).sqrt();
    let bound = (sagitta + h * h / (8.0 * RADIUS)) / n_z;
    let apart = largest_difference(&analytic.x, &meshed.x);
    assert!(apart <= bound, "{apart} apart, bound {bound} (sagitta {sagitta})");
}

/// The symplectic Euler step projects vertices onto the mesh sphere: at rest none ends deeper in
/// the field than what a step's projection leaves (a resting vertex sinks `g dt^2` in a step,
/// and moving it out by that along the unit normal leaves a fraction of it where the
/// interpolated gradient is not of unit length), and so none deeper in the analytic sphere than
/// the sagitta and the interpolation error.
#[test]
fn explicit_steps_keep_vertices_out_of_a_mesh_sphere() {
    let (ball, sagitta) = mesh_ball(4);
    let h = 0.02;
    let field = DistanceField::around(&ball, h, 0.05).unwrap();
    let mut model = cube(RADIUS + 0.02);
    model.add_mesh_obstacle(field.clone(), 1e6, 0.3).unwrap();
    let dt = 2e-4;
    let state = settle(model, FemParams::new(TimeIntegrator::SymplecticEuler), dt, 2000);
    let sink = 9.81 * dt * dt;
    for p in state.x.chunks(3) {
        let x = DVec3::from_slice(p);
        let phi = field.sample(x).map_or(f64::INFINITY, |s| s.distance);
        assert!(phi >= -sink, "vertex inside the mesh: phi = {phi}");
        assert!(x.length() >= RADIUS - sagitta - h * h / (8.0 * RADIUS) - sink, "{x}");
    }
}

/// On a flat face the field is exact (the distance to a plane is linear, and so is its trilinear
/// interpolation): a cube resting on a mesh box's top face sits where it sits on the analytic
/// box, to the Newton tolerance.
#[test]
fn a_cube_rests_on_a_mesh_box_where_it_rests_on_the_box() {
    let (lo, hi) = ([-0.3, -0.3, 0.0], [0.3, 0.3, 0.2]);
    let field = DistanceField::around(&mesh_box(lo, hi), 0.02, 0.05).unwrap();
    for integrator in [TimeIntegrator::BackwardEuler, TimeIntegrator::SymplecticEuler] {
        let (dt, steps) = if integrator == TimeIntegrator::BackwardEuler { (0.01, 40) } else { (2e-4, 1000) };
        let run = |mesh: bool| {
            let mut model = cube(0.21);
            if mesh {
                model.add_mesh_obstacle(field.clone(), 1e6, 0.4).unwrap();
            } else {
                let table = Obstacle::Box { center: [0.0, 0.0, 0.1], half_extents: [0.3, 0.3, 0.1] };
                model.add_obstacle_with_friction(table, 1e6, 0.4).unwrap();
            }
            settle(model, FemParams::new(integrator).with_rayleigh(0.01), dt, steps)
        };
        let (analytic, meshed) = (run(false), run(true));
        let bottom = analytic.x.chunks(3).map(|p| p[2]).fold(f64::INFINITY, f64::min);
        assert!((bottom - 0.2).abs() < 1e-3, "{integrator:?}: resting on the top: lowest z {bottom}");
        let apart = largest_difference(&analytic.x, &meshed.x);
        assert!(apart <= 1e-6, "{integrator:?}: {apart} apart");
    }
}

/// A cube sliding and settling on a mesh sphere with friction gives the same bits on 1, 2 and 4
/// threads, in both integrators.
#[test]
fn mesh_contact_is_bitwise_identical_for_any_thread_count() {
    let (ball, _) = mesh_ball(3);
    let field = DistanceField::around(&ball, 0.03, 0.05).unwrap();
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| {
            let mut out = Vec::new();
            for (integrator, dt, steps) in
                [(TimeIntegrator::BackwardEuler, 0.01, 20), (TimeIntegrator::SymplecticEuler, 2e-4, 300)]
            {
                let mut model = cube(RADIUS - 0.005);
                model.add_mesh_obstacle(field.clone(), 1e6, 0.3).unwrap();
                let mut sim = FemSimulation::new(model, FemParams::new(integrator)).unwrap();
                let mut state = sim.rest_state();
                state.v.chunks_mut(3).for_each(|v| v[0] = 0.5);
                for _ in 0..steps {
                    sim.step(&mut state, dt).unwrap();
                }
                out.extend(state.x.iter().chain(&state.v).map(|v| v.to_bits()));
            }
            out
        })
    };
    let one = run(1);
    for threads in [2, 4] {
        assert!(run(threads) == one, "{threads} threads differ from 1");
    }
}

/// `add_mesh_obstacle` refuses a bad stiffness or friction coefficient, naming it, and adds
/// nothing.
#[test]
fn bad_mesh_obstacle_parameters_are_named() {
    let field = DistanceField::around(&mesh_box([0.0; 3], [1.0; 3]), 0.1, 0.0).unwrap();
    let mut model = cube(2.0);
    for (stiffness, friction, name) in [
        (0.0, 0.0, "contact stiffness"),
        (f64::NAN, 0.0, "contact stiffness"),
        (1e5, -0.1, "friction"),
        (1e5, f64::INFINITY, "friction"),
    ] {
        let err = model.add_mesh_obstacle(field.clone(), stiffness, friction).unwrap_err();
        assert!(matches!(err, crate::FemError::BadParameter { name: n, .. } if n == name), "{err}");
    }
    assert!(model.mesh_obstacles().is_empty() && model.contact_stiffness() == 0.0);
}

/// Through the `fem` kind: a body drops onto a mesh box of `obstacle_meshes` and rests on its
/// top, as on the same box in `obstacles`; each refusal names the field and the file.
#[test]
fn the_scene_files_obstacle_meshes() {
    let dir = folder("obstacle-meshes");
    std::fs::write(dir.join("block.obj"), cube_obj(1.0, &[])).expect("obj");
    std::fs::write(dir.join("holed.obj"), cube_obj(1.0, &[7])).expect("obj");
    std::fs::copy(testdata().join("cube_v41.msh"), dir.join("cube_v41.msh")).expect("msh");
    let build = |value: serde_json::Value| (KIND.build)(&value, &BuildContext { base: Some(&dir) });
    // A refusal as the command line prints it: `field `...`: ` and the message.
    let refused = |value: serde_json::Value| build(value).err().expect("refused").to_string();
    let body = serde_json::json!({
        "mesh": "cube_v41.msh",
        "material": { "young": 5e4, "poisson": 0.3, "density": 1000.0 },
    });
    // The unit block from x = -0.75, y = -0.1, its top at z = 0.3, under the whole body (x from
    // -0.3 to -0.2, y from 0.01 to 0.71, its bottom at z = 1/3).
    let block = serde_json::json!({ "mesh": "block.obj", "translate": [-0.75, -0.1, -0.7], "cell": 0.025 });
    let with = |key: &str, value: serde_json::Value| {
        let mut b = block.clone();
        b[key] = value;
        b
    };
    let scene = |meshes: serde_json::Value| serde_json::json!({ "bodies": [body], "obstacle_meshes": meshes, "rayleigh": 0.01 });
    // The picture draws the block's twelve triangles where it is placed, its height (z in the
    // scene file) along y in the picture.
    let drawn = build(scene(serde_json::json!([block]))).expect("builds").context().mesh_props;
    assert!(drawn.len() == 1 && drawn[0].triangles.len() == 12, "{drawn:?}");
    let lowest = drawn[0].positions.iter().map(|p| p[1]).fold(f64::INFINITY, f64::min);
    assert_eq!(lowest, block["translate"][2].as_f64().unwrap());
    let rest = |params: serde_json::Value| {
        let mut s = build(params).expect("builds");
        for _ in 0..60 {
            s.step(1.0 / 120.0).expect("steps");
        }
        let mut frame = Frame::default();
        s.frame(&mut frame);
        frame.points
    };
    let on_mesh = rest(scene(serde_json::json!([block])));
    let boxed =
        serde_json::json!([{ "box": { "center": [-0.25, 0.4, -0.2], "half_extents": [0.5, 0.5, 0.5] } }]);
    let on_box = rest(serde_json::json!({ "bodies": [body], "obstacles": boxed, "rayleigh": 0.01 }));
    // The frames' y is the scene's z.
    let bottom = on_mesh.chunks(3).map(|p| p[1]).fold(f64::INFINITY, f64::min);
    assert!((bottom - 0.3).abs() < 1e-3, "resting on the block's top: {bottom}");
    assert!(largest_difference(&on_mesh, &on_box) <= 1e-6);

    // The file's refusals are anim-io's `read_closed_surface`'s and the cell's anim-core's
    // `ObstacleMesh::field`'s, tested there: here, that they name the kind's field and the file.
    for (table, field, words) in [
        (with("mesh", "holed.obj".into()), "obstacle_meshes[1].mesh", ["holed.obj", "edge ("]),
        (with("cell", 0.0.into()), "obstacle_meshes[1].cell", ["block.obj", "positive"]),
        (with("scale", 0.0.into()), "obstacle_meshes[1].scale", ["scale", "positive"]),
        (with("shape", 1.0.into()), "obstacle_meshes[1]", ["unknown field", "shape"]),
    ] {
        let m = refused(scene(serde_json::json!([block, table])));
        assert!(m.starts_with(&format!("field `{field}")) && words.iter().all(|w| m.contains(w)), "{m}");
    }
    let m = refused(serde_json::json!({ "preset": "soft-cube-drop", "obstacle_meshes": [block] }));
    assert!(m.starts_with("field `obstacle_meshes`: ") && m.contains("bodies"), "{m}");
}
