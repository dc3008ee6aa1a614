//! Unit tests: the dihedral angle's sign, linear momentum over a run with every solver, XPBD's
//! static stretch against the closed form, contacts (rest, friction, restitution), the global
//! volume, attachments to moving bodies, input errors and NaN detection. Gradients against finite
//! differences, momentum of each projection and determinism across thread counts are conformance
//! cases (`cases`, run by `tests/cases.rs`).

use crate::collide::{BodyMotion, Collider, KinematicBody, Pose, Shape};
use crate::constraint::{AttachTarget, ConstraintFunction, ConstraintParams};
use crate::{
    Bending, BuildError, Chain, Cloth, EARTH_GRAVITY, InputError, MeshMass, MeshParams, Method, PbdBuilder,
    PbdError, PbdParams, PbdSimulation, SolverKind, TetMeshParams, scenes, shapes,
};
use anim_core::glam::DVec3;
use anim_core::integrate::State;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

#[test]
fn dihedral_angle_is_signed_and_zero_when_flat() {
    let mut b = PbdBuilder::new();
    for p in [[0.5, 1.0, 0.0], [0.5, -1.0, 0.0], [0.0, 0.0, 0.0], [1.0, 0.0, 0.0]] {
        b.particle(p, 1.0);
    }
    let j = b.dihedral([0, 1, 2, 3], ConstraintParams::rigid());
    let k = b.isometric_bending([0, 1, 2, 3], ConstraintParams::rigid());
    let model = b.build().expect("builds");
    let mut x = model.rest_state().x;
    assert!(model.evaluate(j, &x, 0.0).expect("regular").0.abs() < 1e-15);
    // Flat rest: Bergou's curvature vector vanishes, so C = 0 and its gradient is undefined.
    let ConstraintFunction::IsometricBending(iso) = &model.constraints()[k].function else { panic!("kind") };
    assert!(iso.rest.abs() < 1e-15 && model.evaluate(k, &x, 0.0).is_none());
    assert!(iso.weights.iter().sum::<f64>().abs() < 1e-14, "weights {:?}", iso.weights);
    // Lift p0 by 0.1 at distance 1 from the edge: the angle changes by atan(0.1).
    x[2] = 0.1;
    let c = model.evaluate(j, &x, 0.0).expect("regular").0;
    assert!((c - 0.1f64.atan()).abs() < 1e-12, "angle {c}");
    x[2] = -0.1;
    let c = model.evaluate(j, &x, 0.0).expect("regular").0;
    assert!((c + 0.1f64.atan()).abs() < 1e-12, "angle {c}");
}

/// Over a run of a free cloth with every internal constraint kind, unequal masses and random
/// velocities, the linear momentum stays at its initial value to round-off.
#[test]
fn linear_momentum_is_conserved_over_a_run() {
    let mut b = PbdBuilder::new();
    b.cloth(&Cloth {
        nx: 6,
        ny: 6,
        origin: [0.0, 0.0, 0.0],
        u: [1.0, 0.0, 0.0],
        v: [0.0, 1.0, 0.0],
        particle_mass: 0.1,
        stretch: ConstraintParams::with_compliance(1e-4),
        bending: Bending::Dihedral(ConstraintParams::with_compliance(0.1)),
    })
    .expect("cloth");
    let model = b.build().expect("builds");
    // Unequal masses: rebuild with masses from 0.01 to 1.
    let mut b2 = PbdBuilder::new();
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    for p in model.rest_positions() {
        b2.particle(*p, 10f64.powf(rng.random_range(-2.0..0.0)));
    }
    for c in model.constraints() {
        match &c.function {
            ConstraintFunction::Distance { particles: [i, j], .. } => {
                b2.distance(*i, *j, c.params);
            }
            ConstraintFunction::DihedralBending { particles, .. } => {
                b2.dihedral(*particles, c.params);
            }
            _ => {}
        }
    }
    let model = b2.build().expect("builds");
    for solver in SolverKind::ALL {
        let mut state = model.rest_state();
        for v in state.v.iter_mut() {
            *v = rng.random_range(-1.0..1.0);
        }
        let p0 = DVec3::from_array(model.linear_momentum(&state.v));
        let mut sim =
            PbdSimulation::new(model.clone(), PbdParams::new(Method::Xpbd, solver, 5, 2)).expect("params");
        let (steps, h) = (100, 1.0 / 120.0);
        sim.run(&mut state, 2.0 * h, steps).expect("runs");
        let p1 = DVec3::from_array(model.linear_momentum(&state.v));
        // Round-off: each substep forms v = (p - x) / h, an error of about eps sum m |x| / h.
        let scale: f64 = model
            .particles()
            .iter()
            .enumerate()
            .map(|(i, part)| {
                part.mass * (state.x[3 * i].abs() + state.x[3 * i + 1].abs() + state.x[3 * i + 2].abs())
            })
            .sum::<f64>()
            / h;
        let bound = 4.0 * f64::EPSILON * scale * (2 * steps) as f64;
        assert!((p1 - p0).length() < bound, "{solver:?}: momentum {p0} -> {p1} (round-off bound {bound:e})");
    }
}

/// XPBD's promise (Macklin et al. 2016): a hanging chain settles at the static stretch `alpha T` of every
/// link whatever the iteration count and time step.
#[test]
fn xpbd_chain_static_stretch() {
    let (n, m, l, alpha, g) = (6usize, 1.0, 1.0, 1e-2, 9.81);
    for (iters, dt) in [(5, 1.0 / 30.0), (20, 1.0 / 60.0)] {
        let mut b = PbdBuilder::new();
        b.gravity([0.0, 0.0, -g]);
        let r = b
            .chain(&Chain {
                count: n + 1,
                start: [0.0; 3],
                end: [0.0, 0.0, -(n as f64) * l],
                mass: m,
                stretch: ConstraintParams::with_compliance(alpha).damping(5.0),
            })
            .expect("chain");
        b.pin(r.start);
        let model = b.build().expect("builds");
        let mut state = model.rest_state();
        let mut sim =
            PbdSimulation::new(model, PbdParams::new(Method::Xpbd, SolverKind::GaussSeidel, iters, 1))
                .expect("ok");
        sim.run(&mut state, dt, (150.0 / dt) as usize).expect("runs");
        let mut z = 0.0;
        let total = alpha * m * g * (n * (n + 1) / 2) as f64;
        for j in 1..=n {
            z -= l + alpha * (n - j + 1) as f64 * m * g;
            let err = (state.x[3 * j + 2] - z).abs() / total;
            assert!(
                err < 1e-3,
                "iterations {iters}, dt {dt}: particle {j} off by {err} of the total stretch"
            );
        }
    }
}

#[test]
fn particle_comes_to_rest_on_the_ground_at_its_thickness() {
    for method in [Method::Pbd, Method::Xpbd] {
        let mut b = PbdBuilder::new();
        b.gravity(EARTH_GRAVITY);
        b.particle([0.0, 0.0, 1.0], 1.0);
        b.collider(Collider::ground(0.0).with_thickness(0.05).with_restitution(0.5));
        let model = b.build().expect("builds");
        let mut state = model.rest_state();
        let mut sim =
            PbdSimulation::new(model, PbdParams::new(method, SolverKind::GaussSeidel, 3, 1)).expect("ok");
        sim.run(&mut state, 1.0 / 120.0, 1200).expect("runs");
        assert!((state.x[2] - 0.05).abs() < 1e-9, "{method:?}: z = {}", state.x[2]);
        assert!(state.v[2].abs() < 1e-9, "{method:?}: vz = {}", state.v[2]);
    }
}

#[test]
fn restitution_sets_the_bounce_speed() {
    let e = 0.6;
    let mut b = PbdBuilder::new();
    b.gravity(EARTH_GRAVITY);
    b.particle([0.0, 0.0, 1.0], 1.0);
    b.collider(Collider::ground(0.0).with_restitution(e));
    let model = b.build().expect("builds");
    let mut state = model.rest_state();
    let dt = 1e-4;
    let mut sim =
        PbdSimulation::new(model, PbdParams::new(Method::Xpbd, SolverKind::GaussSeidel, 1, 1)).expect("ok");
    let mut before = 0.0;
    for _ in 0..20_000 {
        let vz = state.v[2];
        sim.advance(&mut state, dt).expect("step");
        if vz < 0.0 && state.v[2] > 0.0 {
            before = vz;
            break;
        }
    }
    let impact = -(2.0 * 9.81 * 1.0f64).sqrt();
    assert!((before - impact).abs() < 1e-2, "impact speed {before} vs {impact}");
    // The normal velocity before the solve includes that step's gravity.
    let vn_pre = before - 9.81 * dt;
    assert!((state.v[2] + e * vn_pre).abs() < 1e-12, "bounce {} vs {}", state.v[2], -e * vn_pre);
}

/// A particle sliding on the ground at 2 m/s with kinetic friction 0.25 stops after
/// `v^2 / (2 mu g)`; on a 20-degree slope with static friction 0.5 (> tan 20 deg) it sticks.
#[test]
fn kinetic_and_static_friction() {
    let (v0, mu) = (2.0, 0.25);
    let mut b = PbdBuilder::new();
    b.gravity(EARTH_GRAVITY);
    b.particle([0.0, 0.0, 0.0], 1.0);
    b.collider(Collider::ground(0.0).with_friction(mu, mu));
    let model = b.build().expect("builds");
    let mut state = model.rest_state();
    state.v[0] = v0;
    let dt = 1e-3;
    let mut sim =
        PbdSimulation::new(model, PbdParams::new(Method::Xpbd, SolverKind::GaussSeidel, 1, 1)).expect("ok");
    sim.run(&mut state, dt, 2000).expect("runs");
    let expected = v0 * v0 / (2.0 * mu * 9.81);
    assert!(state.v[0].abs() < 1e-12, "still moving: {}", state.v[0]);
    // First-order in dt: the stopping distance is within a few steps' travel.
    assert!((state.x[0] - expected).abs() < 5.0 * v0 * dt, "stopped at {} vs {expected}", state.x[0]);

    let angle = 20f64.to_radians();
    let n = [-angle.sin(), 0.0, angle.cos()];
    let mut b = PbdBuilder::new();
    b.gravity(EARTH_GRAVITY);
    b.particle([0.0, 0.0, 0.0], 1.0);
    b.collider(Collider::new(Shape::Plane { point: [0.0; 3], normal: n }).with_friction(0.5, 0.4));
    let model = b.build().expect("builds");
    let mut state = model.rest_state();
    let mut sim =
        PbdSimulation::new(model, PbdParams::new(Method::Xpbd, SolverKind::GaussSeidel, 2, 1)).expect("ok");
    sim.run(&mut state, 1.0 / 60.0, 300).expect("runs");
    let moved = DVec3::new(state.x[0], state.x[1], state.x[2]).length();
    assert!(moved < 1e-3, "slid {moved} m on a slope below the friction angle");
    // Without friction it slides.
    let mut b = PbdBuilder::new();
    b.gravity(EARTH_GRAVITY);
    b.particle([0.0, 0.0, 0.0], 1.0);
    b.collider(Collider::new(Shape::Plane { point: [0.0; 3], normal: n }).with_friction(0.3, 0.3));
    let model = b.build().expect("builds");
    let mut state = model.rest_state();
    let mut sim =
        PbdSimulation::new(model, PbdParams::new(Method::Xpbd, SolverKind::GaussSeidel, 2, 1)).expect("ok");
    sim.run(&mut state, 1.0 / 60.0, 60).expect("runs");
    // Downhill is -x.
    assert!(state.x[0] < -0.1, "did not slide with mu = 0.3 < tan 20 deg: x = {}", state.x[0]);
}

/// Contacts with every shape, on a moving body too: nothing ends up inside.
#[test]
fn particles_stay_outside_every_shape() {
    let mut b = PbdBuilder::new();
    b.gravity(EARTH_GRAVITY);
    let body = b.body(KinematicBody::new(
        Pose::from_translation([0.0, 0.0, 0.0]),
        BodyMotion::Constant { velocity: [0.2, 0.0, 0.0], angular_velocity: [0.0, 0.0, 1.0] },
    ));
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    for _ in 0..200 {
        b.particle(
            [rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(0.5..2.0)],
            0.01,
        );
    }
    b.collider(Collider::sphere([0.5, 0.5, 0.4], 0.3).with_friction(0.3, 0.2));
    b.collider(Collider::cuboid([-0.5, 0.0, 0.3], [0.3, 0.2, 0.3]).on_body(body).with_friction(0.3, 0.2));
    b.collider(Collider::capsule([0.0, -0.8, 0.5], [0.0, 0.8, 0.5], 0.1).with_restitution(0.5));
    b.collider(Collider::ground(0.0).with_friction(0.5, 0.5));
    let model = b.build().expect("builds");
    let mut state = model.rest_state();
    let mut sim =
        PbdSimulation::new(model.clone(), PbdParams::new(Method::Xpbd, SolverKind::ColoredGaussSeidel, 3, 2))
            .expect("ok");
    let dt = 1.0 / 60.0;
    for step in 0..180 {
        sim.advance(&mut state, dt).expect("runs");
        let t = state.t;
        for (ci, c) in model.colliders().iter().enumerate() {
            let pose = c.body.map_or(Pose::IDENTITY, |b| model.bodies()[b].pose_at(t));
            for i in 0..model.num_particles() {
                let p = DVec3::new(state.x[3 * i], state.x[3 * i + 1], state.x[3 * i + 2]);
                let (d, _) = c.shape.signed_distance(pose.inverse_apply(p));
                assert!(d > -1e-9, "step {step}: particle {i} is {d} inside collider {ci}");
            }
        }
    }
}

#[test]
fn global_volume_inflates_a_balloon() {
    let (unit, tris) = shapes::icosphere(2);
    let mut b = PbdBuilder::new();
    let r = b
        .triangle_mesh(
            &unit,
            &tris,
            &MeshParams {
                mass: MeshMass::PerVertex(0.01),
                stretch: ConstraintParams::with_compliance(1e-2),
                bending: Bending::None,
            },
        )
        .expect("mesh");
    let shifted: Vec<[usize; 3]> = tris.iter().map(|t| t.map(|i| r.start + i)).collect();
    let j = b.global_volume(&shifted, 1.5, ConstraintParams::rigid());
    let model = b.build().expect("builds");
    let ConstraintFunction::GlobalVolume { mesh, rest_volume, .. } = model.constraints()[j].function else {
        panic!("not a volume");
    };
    for solver in SolverKind::ALL {
        let mut state = model.rest_state();
        // Jacobi scales each correction by 1/7 here (6 edges and the volume meet at a vertex).
        let iters = if solver == SolverKind::Jacobi { 100 } else { 20 };
        let mut sim = PbdSimulation::new(model.clone(), PbdParams::new(Method::Xpbd, solver, iters, 1))
            .expect("params");
        sim.run(&mut state, 1.0 / 60.0, 120).expect("runs");
        let v = model.volume_mesh(mesh).volume(&state.x);
        assert!((v / rest_volume - 1.5).abs() < 2e-2, "{solver:?}: volume ratio {}", v / rest_volume);
    }
}

#[test]
fn attachment_follows_a_moving_body() {
    let mut b = PbdBuilder::new();
    b.gravity(EARTH_GRAVITY);
    let body = b.body(KinematicBody::new(
        Pose::from_translation([0.0, 0.0, 1.0]),
        BodyMotion::Oscillate { amplitude: [0.3, 0.0, 0.0], frequency: 1.0 },
    ));
    let r = b
        .chain(&Chain {
            count: 5,
            start: [0.0, 0.0, 1.0],
            end: [0.0, 0.0, 0.6],
            mass: 0.01,
            stretch: ConstraintParams::rigid(),
        })
        .expect("chain");
    b.attach(r.start, AttachTarget::Body { body, local: [0.0; 3] }, 0.0, ConstraintParams::rigid());
    let model = b.build().expect("builds");
    let mut state = model.rest_state();
    let mut sim =
        PbdSimulation::new(model.clone(), PbdParams::new(Method::Xpbd, SolverKind::GaussSeidel, 10, 2))
            .expect("ok");
    for _ in 0..50 {
        sim.advance(&mut state, 1.0 / 60.0).expect("runs");
        let target = model.bodies()[body].pose_at(state.t).position;
        let p = DVec3::new(state.x[0], state.x[1], state.x[2]);
        assert!((p - target).length() < 1e-9, "attached particle {p} vs {target}");
    }
}

#[test]
fn tet_mesh_keeps_its_volume_on_the_ground() {
    let (pos, tets) = shapes::tet_box([3, 3, 3], [0.0, 0.0, 0.5], 0.1);
    let mut b = PbdBuilder::new();
    b.gravity(EARTH_GRAVITY);
    b.tet_mesh(
        &pos,
        &tets,
        &TetMeshParams {
            mass: MeshMass::Density(500.0),
            stretch: Some(ConstraintParams::with_compliance(1e-4)),
            volume: Some(ConstraintParams::rigid()),
        },
    )
    .expect("tets");
    b.collider(Collider::ground(0.0).with_friction(0.5, 0.5));
    let model = b.build().expect("builds");
    assert_eq!(model.tets().len(), 6 * 27);
    // The surface of a 3x3x3 box of cells: 6 faces x 9 squares x 2 triangles.
    assert_eq!(model.triangles().len(), 108);
    let mut state = model.rest_state();
    let mut sim = PbdSimulation::new(
        model.clone(),
        PbdParams::new(Method::Xpbd, SolverKind::ColoredGaussSeidel, 10, 2),
    )
    .expect("ok");
    sim.run(&mut state, 1.0 / 60.0, 120).expect("runs");
    let lowest = state.x.chunks_exact(3).map(|p| p[2]).fold(f64::INFINITY, f64::min);
    assert!(lowest > -1e-9 && lowest < 0.01, "lowest point {lowest}");
    let vol: f64 = model
        .tets()
        .iter()
        .map(|t| crate::constraint::tet_volume(t.map(|i| crate::constraint::load(&state.x, i))).0)
        .sum();
    assert!((vol / 0.027 - 1.0).abs() < 1e-3, "volume {vol} vs 0.027");
}

#[test]
fn bad_input_is_rejected_naming_the_element() {
    let two = || {
        let mut b = PbdBuilder::new();
        b.particle([0.0; 3], 1.0);
        b.particle([1.0, 0.0, 0.0], 1.0);
        b
    };
    let mut b = two();
    b.particle([0.0, 1.0, 0.0], -1.0);
    assert_eq!(b.build().unwrap_err(), BuildError::Input(InputError::BadMass { particle: 2, mass: -1.0 }));
    let mut b = two();
    b.distance(0, 5, ConstraintParams::rigid());
    assert!(matches!(b.build(), Err(BuildError::ConstraintIndex { constraint: 0, index: 5, .. })));
    let mut b = two();
    b.distance(0, 1, ConstraintParams::rigid());
    b.distance(0, 1, ConstraintParams::with_stiffness(1.5));
    assert!(matches!(b.build(), Err(BuildError::BadStiffness { constraint: 1, value, .. }) if value == 1.5));
    let mut b = two();
    b.distance(0, 1, ConstraintParams::with_compliance(-1e-3));
    let e = b.build().unwrap_err();
    assert!(matches!(e, BuildError::BadCompliance { constraint: 0, .. }));
    assert!(e.to_string().contains("constraint 0") && e.to_string().contains("compliance"), "{e}");
    let mut b = two();
    b.distance(1, 1, ConstraintParams::rigid());
    assert!(matches!(b.build(), Err(BuildError::RepeatedIndex { constraint: 0, particle: 1, .. })));
    // A zero-area bending stencil (p0 on the edge line).
    let mut b = two();
    b.particle([0.5, 0.0, 0.0], 1.0);
    b.particle([0.5, 1.0, 0.0], 1.0);
    b.dihedral([2, 3, 0, 1], ConstraintParams::rigid());
    let e = b.build().unwrap_err();
    assert!(matches!(e, BuildError::DegenerateRest { constraint: 0, .. }), "{e}");
    let mut b = two();
    b.particle([0.5, 0.0, 0.0], 1.0);
    b.particle([0.5, 1.0, 0.0], 1.0);
    b.isometric_bending([2, 3, 0, 1], ConstraintParams::rigid());
    assert!(matches!(b.build(), Err(BuildError::DegenerateRest { constraint: 0, .. })));
    // A flat tetrahedron.
    let mut b = two();
    b.particle([0.0, 1.0, 0.0], 1.0);
    b.particle([1.0, 1.0, 0.0], 1.0);
    b.tet_volume([0, 1, 2, 3], ConstraintParams::rigid());
    assert!(matches!(b.build(), Err(BuildError::DegenerateRest { constraint: 0, .. })));
    let e = PbdBuilder::new()
        .tet_mesh(
            &[[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]],
            &[[0, 1, 2, 3]],
            &TetMeshParams { mass: MeshMass::PerVertex(1.0), stretch: None, volume: None },
        )
        .unwrap_err();
    assert!(matches!(e, BuildError::DegenerateTet { tet: 0, .. }), "{e}");
    // An open mesh cannot hold a volume.
    let mut b = two();
    b.particle([0.0, 1.0, 0.0], 1.0);
    b.particle([0.0, 0.0, 1.0], 1.0);
    b.global_volume(&[[0, 1, 2], [0, 1, 3], [1, 2, 3]], 1.0, ConstraintParams::rigid());
    assert!(matches!(b.build(), Err(BuildError::BadVolumeMesh { .. })));
    let mut b = two();
    b.collider(Collider::sphere([0.0; 3], -1.0));
    assert!(matches!(b.build(), Err(BuildError::Input(InputError::BadCollider { collider: 0, .. }))));
    // A non-finite mesh vertex is reported as such (not as a zero-area triangle), numbered after
    // the particles already there.
    let mesh = MeshParams {
        mass: MeshMass::PerVertex(0.01),
        stretch: ConstraintParams::rigid(),
        bending: Bending::None,
    };
    let nan = [0.0, f64::NAN, 0.0];
    let e = two().triangle_mesh(&[[0.0; 3], [1.0, 0.0, 0.0], nan], &[[0, 1, 2]], &mesh).unwrap_err();
    assert!(
        matches!(e, BuildError::Input(InputError::NonFinitePosition { particle: 4, position })
            if position[1].is_nan()),
        "{e}"
    );
    let mut b = two();
    b.attach(0, AttachTarget::Body { body: 3, local: [0.0; 3] }, 0.0, ConstraintParams::rigid());
    assert!(matches!(b.build(), Err(BuildError::BodyIndex { constraint: 0, body: 3, .. })));
    // Bad settings.
    let model = two().build().expect("builds");
    let bad = PbdParams::new(Method::Pbd, SolverKind::GaussSeidel, 0, 1);
    assert!(matches!(
        PbdSimulation::new(model.clone(), bad),
        Err(PbdError::BadParameter { name: "iterations", .. })
    ));
    let mut sim = PbdSimulation::new(model.clone(), PbdParams::default()).expect("ok");
    let mut state = model.rest_state();
    assert!(matches!(sim.advance(&mut state, -1.0), Err(PbdError::BadTimeStep { .. })));
}

#[test]
fn a_nan_is_reported_with_step_and_constraint_and_the_state_kept() {
    let mut b = PbdBuilder::new();
    b.gravity(EARTH_GRAVITY);
    let r = b
        .chain(&Chain {
            count: 4,
            start: [0.0; 3],
            end: [0.3, 0.0, 0.0],
            mass: 0.1,
            stretch: ConstraintParams::with_compliance(1e-6),
        })
        .expect("chain");
    b.pin(r.start);
    let model = b.build().expect("builds");
    let mut state = model.rest_state();
    let mut sim = PbdSimulation::new(model, PbdParams::default()).expect("ok");
    sim.run(&mut state, 0.01, 3).expect("runs");
    let before = state.clone();
    sim.set_external_force(2, [f64::NAN, 0.0, 0.0]);
    let e = sim.advance(&mut state, 0.01).unwrap_err();
    match e {
        PbdError::NonFinite { step, constraint, .. } => {
            assert_eq!(step, 3);
            assert_eq!(constraint.map(|c| c.0), Some(1), "{e}");
        }
        ref other => panic!("unexpected {other}"),
    }
    assert_eq!(state.x, before.x);
    assert_eq!(state.v, before.v);
    assert!(e.to_string().contains("step 3") && e.to_string().contains("constraint 1"), "{e}");
}

/// An infinite external force (the API accepts any value) on a free particle: the report names
/// the crate, the step, the particle, its component and last finite value, and the state and the
/// simulation's memory are bit for bit what they were before the step.
#[test]
fn an_infinite_force_is_reported_by_particle_and_the_step_undone() {
    let mut b = PbdBuilder::new();
    b.gravity(EARTH_GRAVITY);
    let r = b
        .chain(&Chain {
            count: 4,
            start: [0.0; 3],
            end: [0.3, 0.0, 0.0],
            mass: 0.1,
            stretch: ConstraintParams::with_compliance(1e-6),
        })
        .expect("chain");
    b.pin(r.start);
    // A kinematic body with a pending target: the target is part of the memory a failed step keeps.
    let body = b.body(KinematicBody::new(
        Pose::from_translation([0.0, 0.0, 1.0]),
        BodyMotion::Oscillate { amplitude: [0.3, 0.0, 0.0], frequency: 1.0 },
    ));
    let model = b.build().expect("builds");
    let mut state = model.rest_state();
    let mut sim = PbdSimulation::new(model, PbdParams::default()).expect("ok");
    sim.run(&mut state, 0.01, 5).expect("runs");
    sim.set_body_target(body, Pose::from_translation([0.1, 0.0, 1.0]));
    sim.set_external_force(3, [0.0, 0.0, f64::NEG_INFINITY]);
    let before = state.clone();
    #[cfg(feature = "serde")]
    let memory = sim.memory();
    let e = sim.advance(&mut state, 0.01).unwrap_err();
    let bits = |s: &State| s.x.iter().chain(&s.v).chain([&s.t]).map(|v| v.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&state), bits(&before), "the failed step changed the state");
    #[cfg(feature = "serde")]
    assert_eq!(sim.memory(), memory, "the failed step changed the memory");
    assert_eq!(sim.steps(), 5);
    let msg = e.to_string();
    assert!(msg.starts_with("anim-pbd: step 5: non-finite "), "{msg}");
    match e {
        PbdError::NonFinite { step, field, particle, component, value, last_finite, .. } => {
            assert_eq!(step, 5);
            // The force drives particle 3's predicted position to -inf along z; the distance
            // constraint to particle 2 then has a NaN gradient, and its update is skipped, so
            // particle 3 is the only non-finite one and positions are checked first.
            assert_eq!(field, "position", "{msg}");
            assert_eq!(particle, 3, "{msg}");
            assert_eq!(component, Some(2), "{msg}");
            assert_eq!(value, f64::NEG_INFINITY, "{msg}");
            assert_eq!(last_finite.to_vec(), before.x[9..12].to_vec(), "{msg}");
            let head = "anim-pbd: step 5: non-finite position of particle 3, component z (value -inf)";
            assert!(msg.starts_with(head), "{msg}");
        }
        other => panic!("unexpected {other}"),
    }
    // With the force removed the step goes through and uses up the pending target.
    sim.set_external_force(3, [0.0; 3]);
    sim.advance(&mut state, 0.01).expect("recovers");
    assert_eq!(sim.steps(), 6);
    #[cfg(feature = "serde")]
    assert!(sim.memory()["targets"][body].is_null(), "{}", sim.memory());
}

/// Degenerate configurations at run time: coincident particles, a stencil folded flat onto its
/// edge, both ends pinned: no NaN.
#[test]
fn degenerate_configurations_stay_finite() {
    let mut b = PbdBuilder::new();
    b.gravity(EARTH_GRAVITY);
    for p in [
        [0.5, 1.0, 0.0],
        [0.5, -1.0, 0.0],
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [2.0, 0.0, 1.0],
        [3.0, 0.0, 1.0],
    ] {
        b.particle(p, 1.0);
    }
    b.pin(4).pin(5);
    b.distance(4, 5, ConstraintParams::rigid());
    b.distance(0, 1, ConstraintParams::rigid());
    b.dihedral([0, 1, 2, 3], ConstraintParams::with_compliance(0.1));
    b.isometric_bending([0, 1, 2, 3], ConstraintParams::with_compliance(0.1));
    b.tet_volume([0, 1, 2, 4], ConstraintParams::rigid());
    let model = b.build().expect("builds");
    let mut state = model.rest_state();
    // Collapse everything: 0 and 1 onto the edge midpoint, 2 onto 3.
    for i in [0, 1] {
        state.x[3 * i..3 * i + 3].copy_from_slice(&[0.5, 0.0, 0.0]);
    }
    state.x[6..9].copy_from_slice(&[1.0, 0.0, 0.0]);
    for method in [Method::Pbd, Method::Xpbd] {
        for solver in SolverKind::ALL {
            let mut s = state.clone();
            let mut sim =
                PbdSimulation::new(model.clone(), PbdParams::new(method, solver, 5, 1)).expect("ok");
            sim.run(&mut s, 1.0 / 60.0, 30).expect("no NaN");
            assert!(s.x.iter().chain(&s.v).all(|v| v.is_finite()));
        }
    }
}

#[test]
fn substeps_beat_iterations_on_a_long_rope() {
    let scene = scenes::rope(Some(50)).expect("scene");
    let err = |iters: usize, subs: usize| {
        let mut sim = PbdSimulation::new(
            scene.model.clone(),
            PbdParams::new(Method::Xpbd, SolverKind::GaussSeidel, iters, subs),
        )
        .expect("ok");
        let mut state: State = scene.state.clone();
        sim.run(&mut state, 1.0 / 60.0, 30).expect("runs");
        sim.max_violation(&state.x)
    };
    let (iters, subs) = (err(16, 1), err(1, 16));
    assert!(subs < iters, "16 substeps: {subs}, 16 iterations: {iters}");
}

#[test]
fn every_scene_runs() {
    for name in scenes::NAMES {
        let scene = scenes::by_name(name, None).expect("known").expect("builds");
        let dt = scene.dt;
        let (mut sim, mut state) = scene.into_simulation().expect("params");
        for _ in 0..5 {
            anim_core::solver::Solver::step(&mut sim, &mut state, dt)
                .unwrap_or_else(|e| panic!("{name}: {e}"));
        }
    }
    assert!(scenes::by_name("nope", None).is_none());
    assert!(matches!(
        scenes::by_name("rope", Some(1)),
        Some(Err(BuildError::Input(InputError::BadParameter { .. })))
    ));
}

#[test]
fn icosphere_and_tet_surface_are_closed() {
    let (p, t) = shapes::icosphere(2);
    assert_eq!((p.len(), t.len()), (162, 320));
    let (pos, tets) = shapes::tet_blob([0.0; 3], 0.25, 5);
    let surf = shapes::tet_surface(&pos, &tets);
    let mut b = PbdBuilder::new();
    for q in &pos {
        b.particle(*q, 1.0);
    }
    b.global_volume(&surf, 1.0, ConstraintParams::rigid());
    let model = b.build().expect("the blob's surface is closed and outward");
    let x = model.rest_state().x;
    let tv: f64 =
        tets.iter().map(|t| crate::constraint::tet_volume(t.map(|i| crate::constraint::load(&x, i))).0).sum();
    assert!((model.volume_mesh(0).volume(&x) - tv).abs() < 1e-12 * tv);
}
