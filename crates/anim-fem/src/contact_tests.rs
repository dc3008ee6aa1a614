//! Contact scenes checked against analytic references and conservation laws.

use crate::FemError;
use crate::boundary::Obstacle;
use crate::friction;
use crate::generate::box_mesh;
use crate::material::{Material, MaterialModel};
use crate::model::{EARTH_GRAVITY, ElementOrder, FemModel};
use crate::scenes;
use crate::sim::{FemParams, FemSimulation, TimeIntegrator};
use anim_core::integrate::State;
use anim_core::solver::Solver;

/// FNV-1a over the bits of every position and velocity coordinate.
fn state_hash(state: &State) -> u64 {
    let mut h = 0xcbf2_9ce4_8422_2325_u64;
    for v in state.x.iter().chain(&state.v) {
        for b in v.to_bits().to_le_bytes() {
            h ^= u64::from(b);
            h = h.wrapping_mul(0x0000_0100_0000_01b3);
        }
    }
    h
}

/// The soft cube drop (resolution 3), thrown sideways at 1 m/s, through its landing with either
/// integrator; the ground is added by `add_obstacle` or, when `explicit_mu` is set, by
/// `add_obstacle_with_friction` with that coefficient. Returns the final state, the total
/// horizontal momentum at the start and its largest change over the run, and the total mass.
fn thrown_cube(
    integrator: TimeIntegrator,
    dt: f64,
    steps: usize,
    explicit_mu: Option<f64>,
) -> (State, [f64; 2], f64) {
    let mut scene = scenes::soft_cube_drop(3).unwrap();
    if let Some(mu) = explicit_mu {
        let mesh = scene.model.mesh().clone();
        let mut model = FemModel::new(mesh, *scene.model.material()).unwrap().with_gravity(EARTH_GRAVITY);
        model.add_obstacle_with_friction(Obstacle::ground(0.0), 1e7, mu).unwrap();
        scene.model = model;
    }
    for v in scene.state.v.chunks_mut(3) {
        v[0] += 1.0;
    }
    scene.params = FemParams { integrator, ..scene.params };
    let (mut sim, mut state) = scene.into_simulation().unwrap();
    let mass: f64 = sim.model().lumped_mass().iter().sum();
    let p0 = sim.momentum(&state).0;
    let mut change = [0.0f64; 2];
    let mut zmin = f64::INFINITY;
    for _ in 0..steps {
        sim.step(&mut state, dt).unwrap();
        zmin = state.x.chunks(3).map(|p| p[2]).fold(zmin, f64::min);
        let p = sim.momentum(&state).0;
        for c in 0..2 {
            change[c] = change[c].max((p[c] - p0[c]).abs());
        }
    }
    assert!(zmin < 1e-3, "the cube has not landed: lowest z {zmin}");
    (state, change, mass)
}

/// Frictionless contact (`add_obstacle`, and `mu = 0` given explicitly) pushes only along the
/// ground's normal: the cube's horizontal momentum is that of its throw through the landing
/// (exactly for the explicit projection, to the Newton tolerance for backward Euler), and the
/// two ways of asking for no friction give the same bits.
#[test]
fn frictionless_contact_keeps_horizontal_momentum() {
    for (integrator, dt, steps, bound) in [
        (TimeIntegrator::SymplecticEuler, 2e-4, 3000, 1e-12),
        (TimeIntegrator::BackwardEuler, 1.0 / 120.0, 60, 1e-6),
    ] {
        let (a, change, mass) = thrown_cube(integrator, dt, steps, None);
        let (b, _, _) = thrown_cube(integrator, dt, steps, Some(0.0));
        assert_eq!(state_hash(&a), state_hash(&b), "{integrator:?}");
        // Momentum scale: the mass at the throw speed of 1 m/s.
        let rel = change[0].max(change[1]) / mass;
        assert!(rel <= bound, "{integrator:?}: horizontal momentum changed by {rel:e} of m * 1 m/s");
        // With friction the ground does take horizontal momentum.
        let (_, change_mu, _) = thrown_cube(integrator, dt, steps, Some(0.5));
        assert!(
            change_mu[0] / mass > 1e-3,
            "{integrator:?}: friction removed only {:e}",
            change_mu[0] / mass
        );
    }
}

/// A 0.1 m cube of 6 tetrahedra (1 kg, E = 1 MPa) resting on the plane through the origin
/// tilted by `theta` about the y axis (normal `(sin, 0, cos)`), gravity straight down, with
/// friction `mu`.
fn block_on_incline(theta: f64, mu: f64, integrator: TimeIntegrator, eps_v: f64) -> (FemSimulation, State) {
    block_on_incline_of(ElementOrder::Linear, theta, mu, integrator, eps_v)
}

/// [`block_on_incline`] of linear or 10-node tetrahedra.
fn block_on_incline_of(
    order: ElementOrder,
    theta: f64,
    mu: f64,
    integrator: TimeIntegrator,
    eps_v: f64,
) -> (FemSimulation, State) {
    let mut mesh = box_mesh([0.0; 3], [0.1; 3], [1, 1, 1]).unwrap();
    let (s, c) = theta.sin_cos();
    for p in &mut mesh.positions {
        *p = [c * p[0] + s * p[2], p[1], -s * p[0] + c * p[2]];
    }
    let material = Material::new(MaterialModel::StableNeoHookean, 1e6, 0.3, 1000.0).unwrap();
    let mut model = FemModel::with_order(mesh, material, order).unwrap().with_gravity(EARTH_GRAVITY);
    model
        .add_obstacle_with_friction(Obstacle::Plane { point: [0.0; 3], normal: [s, 0.0, c] }, 1e6, mu)
        .unwrap();
    let params = FemParams::new(integrator).with_friction_eps_v(eps_v);
    let sim = FemSimulation::new(model, params).unwrap();
    let state = sim.rest_state();
    (sim, state)
}

/// Position of the centre of mass along the downhill direction `(cos, 0, -sin)`.
fn downhill(sim: &FemSimulation, state: &State, theta: f64) -> f64 {
    let (s, c) = theta.sin_cos();
    let m = sim.model().lumped_mass();
    let total: f64 = m.iter().sum();
    state.x.chunks(3).zip(m).map(|(p, mi)| mi * (c * p[0] - s * p[2])).sum::<f64>() / total
}

/// Runs `duration` seconds; returns the downhill centre-of-mass positions after every step.
/// Newton converges within 10 iterations at every step (4 at most measured).
fn run(sim: &mut FemSimulation, state: &mut State, theta: f64, dt: f64, duration: f64) -> Vec<(f64, f64)> {
    let steps = (duration / dt).round() as usize;
    let mut out = Vec::with_capacity(steps + 1);
    out.push((state.t, downhill(sim, state, theta)));
    for _ in 0..steps {
        let report = sim.step(state, dt).unwrap();
        assert!(report.iterations <= 10, "{} Newton iterations", report.iterations);
        out.push((state.t, downhill(sim, state, theta)));
    }
    out
}

/// Least-squares fit of `s(t) = s0 + v0 t + a t^2 / 2` to the samples with `t >= from`;
/// returns `a`.
fn fitted_acceleration(samples: &[(f64, f64)], from: f64) -> f64 {
    // Normal equations of the basis (1, t, t^2 / 2).
    let mut ata = [[0.0; 3]; 3];
    let mut atb = [0.0; 3];
    for &(t, s) in samples.iter().filter(|(t, _)| *t >= from) {
        let row = [1.0, t, 0.5 * t * t];
        for i in 0..3 {
            atb[i] += row[i] * s;
            for j in 0..3 {
                ata[i][j] += row[i] * row[j];
            }
        }
    }
    let m = anim_material::nalgebra::Matrix3::from_fn(|i, j| ata[i][j]);
    let b = anim_material::nalgebra::Vector3::from(atb);
    let coef = m.lu().solve(&b).unwrap();
    coef[2]
}

fn integrators() -> [(TimeIntegrator, f64); 2] {
    [(TimeIntegrator::BackwardEuler, 0.005), (TimeIntegrator::SymplecticEuler, 1e-4)]
}

/// Static friction: with `tan(theta) = 0.36 < mu = 0.5` the block stays.
///
/// Backward Euler: under a tangential load `F < mu lambda` the smoothed friction force
/// `mu lambda f1(y)` balances `F` at a step displacement `y = eps_v dt (1 - sqrt(1 - F /
/// (mu lambda)))` (`crate::friction`); with `F / lambda = tan(theta)` at every contact vertex of
/// a block at rest the block creeps at `eps_v (1 - sqrt(1 - tan(theta) / mu)) = 0.478 eps_v`
/// (checked within 5% over 0.5-1 s, for two `eps_v`, with Newton converged far below the creep
/// step). Over 1 s it moves less than `eps_v x 1 s`
/// plus the landing transient: the first step, with no lagged normal force yet, slides
/// `g sin(theta) dt^2` and reaches `g sin(theta) dt`, which friction stops within
/// `(g sin(theta) dt)^2 / (2 g (mu cos(theta) - sin(theta)))`, and the block's elastic shear
/// moves its centre by `m g sin(theta) / (A G) h / 2` (`A = h^2`, `G = E / (2 (1 + nu))`).
///
/// Symplectic Euler, with a little Rayleigh damping (`gamma = 1e-3` s) so that the landing
/// vibrations die out: the contact vertices stick exactly once landed (no tangential motion over
/// 0.1-1 s), and the centre of mass moves by less than that elastic shear (doubled for the
/// overshoot of a suddenly applied load). Undamped, the block keeps vibrating and its contact
/// vertices slip by about 1e-5 m in that time, as vibrating contacts do.
///
/// Without friction the block would slide `g sin(theta) / 2 = 1.7 m` in 1 s.
#[test]
fn a_block_sticks_on_an_incline_below_the_friction_angle() {
    let theta = 20f64.to_radians();
    let (sin, cos) = theta.sin_cos();
    let mu = 0.5;
    let g = -EARTH_GRAVITY[2];
    let dt = 0.005;
    let creep = 1.0 - (1.0 - theta.tan() / mu).sqrt();
    let (h, e, nu) = (0.1, 1e6, 0.3);
    let shear = g * sin / (h * h * e / (2.0 * (1.0 + nu))) * h / 2.0;
    let landing = g * sin * dt * dt + (g * sin * dt).powi(2) / (2.0 * g * (mu * cos - sin));
    for eps_v in [friction::DEFAULT_EPS_V, 1e-4] {
        let (mut sim, mut state) = block_on_incline(theta, mu, TimeIntegrator::BackwardEuler, eps_v);
        // The creep step (2.4e-7 m for eps_v = 1e-4) is of the order of the default Newton
        // tolerance (1e-6 x the 0.17 m diagonal): solve well below it.
        let p = sim.params().with_newton_tolerance(1e-10);
        sim.set_params(p).unwrap();
        let samples = run(&mut sim, &mut state, theta, dt, 1.0);
        let moved = samples[200].1 - samples[0].1;
        let speed = (samples[200].1 - samples[100].1) / 0.5;
        let bound = eps_v * 1.0 + landing + shear;
        assert!(moved.abs() < bound, "eps_v {eps_v}: moved {moved} m in 1 s");
        assert!((speed / (creep * eps_v) - 1.0).abs() < 0.05, "eps_v {eps_v}: creep {speed} m/s");
    }
    let (mut sim, mut state) = block_on_incline(theta, mu, TimeIntegrator::SymplecticEuler, 1e-3);
    let p = sim.params().with_rayleigh(1e-3);
    sim.set_params(p).unwrap();
    let bottom = sim.model().vertices_where(|p| p[0] * sin + p[2] * cos < 1e-9);
    assert_eq!(bottom.len(), 4);
    let start = downhill(&sim, &state, theta);
    let _ = run(&mut sim, &mut state, theta, 1e-4, 0.1);
    let landed = state.x.clone();
    let samples = run(&mut sim, &mut state, theta, 1e-4, 0.9);
    for &v in &bottom {
        let d = cos * (state.x[3 * v] - landed[3 * v]) - sin * (state.x[3 * v + 2] - landed[3 * v + 2]);
        assert!(d.abs() < 1e-12, "contact vertex {v} slid {d} m");
    }
    let moved = samples.iter().map(|(_, x)| (x - start).abs()).fold(0.0, f64::max);
    assert!(moved < 2.0 * shear, "moved {moved} m");
}

/// Kinetic friction: with `tan(theta) = 0.58 > mu = 0.3` the centre of mass accelerates at
/// `g (sin(theta) - mu cos(theta)) = 2.356 m/s^2` (a rigid block on a rough incline); the
/// frictionless block at `g sin(theta)`. Fitted over 0.2-1 s (after landing transients).
#[test]
fn a_block_slides_down_an_incline_at_the_coulomb_acceleration() {
    let theta = 30f64.to_radians();
    let g = -EARTH_GRAVITY[2];
    for order in [ElementOrder::Linear, ElementOrder::Quadratic] {
        for mu in [0.3, 0.0] {
            let want = g * (theta.sin() - mu * theta.cos());
            for (integrator, dt) in integrators() {
                let (mut sim, mut state) =
                    block_on_incline_of(order, theta, mu, integrator, friction::DEFAULT_EPS_V);
                let samples = run(&mut sim, &mut state, theta, dt, 1.0);
                let a = fitted_acceleration(&samples, 0.2);
                assert!(
                    (a / want - 1.0).abs() < 0.03,
                    "{order:?} {integrator:?} mu {mu}: a = {a}, want {want}"
                );
            }
        }
    }
}

/// The friction terms are summed in a fixed order: a sliding and sticking block gives the same
/// bits on one and on two threads.
#[test]
fn friction_is_bitwise_identical_for_any_thread_count() {
    let theta = 30f64.to_radians();
    let mut hashes = Vec::new();
    for threads in [1, 2] {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        hashes.push(pool.install(|| {
            let mut out = Vec::new();
            for (integrator, dt) in integrators() {
                let (mut sim, mut state) = block_on_incline(theta, 0.3, integrator, 1e-3);
                let _ = run(&mut sim, &mut state, theta, dt, 0.05);
                out.push(state_hash(&state));
            }
            out
        }));
    }
    assert_eq!(hashes[0], hashes[1]);
}

#[test]
fn bad_friction_input_is_named() {
    let mesh = box_mesh([0.0; 3], [0.1; 3], [1, 1, 1]).unwrap();
    let material = Material::new(MaterialModel::StableNeoHookean, 1e6, 0.3, 1000.0).unwrap();
    let mut model = FemModel::new(mesh, material).unwrap();
    for mu in [-0.1, f64::NAN, f64::INFINITY] {
        let err = model.add_obstacle_with_friction(Obstacle::ground(0.0), 1e6, mu).unwrap_err();
        assert!(matches!(err, FemError::BadParameter { name: "friction", .. }), "{err}");
        assert!(err.to_string().contains("`friction`"), "{err}");
    }
    assert!(model.obstacles().is_empty() && model.obstacle_friction().is_empty());
    model.add_obstacle_with_friction(Obstacle::ground(0.0), 1e6, 0.4).unwrap();
    model.add_obstacle(Obstacle::Sphere { center: [0.0; 3], radius: 1.0 }, 1e6).unwrap();
    assert_eq!(model.obstacle_friction(), &[0.4, 0.0]);
    // Invalid shapes are refused naming the obstacle.
    for (shape, words) in [
        (Obstacle::Sphere { center: [0.0; 3], radius: -1.0 }, "sphere radius"),
        (Obstacle::Plane { point: [0.0; 3], normal: [0.0; 3] }, "plane normal"),
        (Obstacle::Box { center: [0.0; 3], half_extents: [1.0, 0.0, 1.0] }, "box half extents"),
        (Obstacle::Capsule { a: [0.0; 3], b: [0.0; 3], radius: 0.5 }, "capsule ends coincide"),
    ] {
        let err = model.add_obstacle(shape, 1e6).unwrap_err();
        assert!(matches!(err, FemError::BadObstacle { obstacle: 2, .. }), "{err}");
        assert!(err.to_string().starts_with("obstacle 2: ") && err.to_string().contains(words), "{err}");
    }
    assert_eq!(model.obstacles().len(), 2);
    for eps_v in [0.0, -1.0, f64::NAN] {
        let err =
            FemSimulation::new(model.clone(), FemParams::default().with_friction_eps_v(eps_v)).unwrap_err();
        assert!(matches!(err, FemError::BadParameter { name: "friction_eps_v", .. }), "{err}");
    }
}
