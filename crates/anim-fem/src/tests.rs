//! Cross-checks of the whole crate: forces and stiffness against finite differences of the
//! energy, the patch test, momentum conservation, thread-count determinism, boundary conditions,
//! contact and error reporting.

use crate::FemError;
use crate::boundary::{Motion, Obstacle};
use crate::generate::{box_mesh, quadratic};
use crate::material::{Material, MaterialModel};
use crate::model::{EARTH_GRAVITY, FemModel, MassKind};
use crate::newton::{ElasticBody, assemble_stiffness};
use crate::quadratic::QuadraticModel;
use crate::sim::{FemParams, FemSimulation, LinearSolverChoice, TimeIntegrator};
use anim_core::solver::Solver;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn material(model: MaterialModel) -> Material {
    Material::new(model, 1e5, 0.3, 1000.0).unwrap()
}

fn perturbed(x: &[f64], scale: f64, seed: u64) -> Vec<f64> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    x.iter().map(|v| v + scale * rng.random_range(-1.0..1.0)).collect()
}

/// Central-difference check of an element's gradient and Hessian against its energy.
fn check_element_derivatives<B: ElasticBody>(body: &B, x: &[f64], nodes: &[usize], e: usize) {
    let ne = 3 * body.per_element();
    let mut g = vec![0.0; ne];
    let mut h = vec![0.0; ne * ne];
    body.element(e, x, Some(&mut g), Some(&mut h), false);
    let eps = 1e-6;
    let mut xp = x.to_vec();
    let scale_g = g.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let scale_h = h.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    for (a, &v) in nodes.iter().enumerate() {
        for i in 0..3 {
            let d = 3 * v + i;
            let orig = xp[d];
            xp[d] = orig + eps;
            let ep = body.element(e, &xp, None, None, false);
            let mut gp = vec![0.0; ne];
            body.element(e, &xp, Some(&mut gp), None, false);
            xp[d] = orig - eps;
            let em = body.element(e, &xp, None, None, false);
            let mut gm = vec![0.0; ne];
            body.element(e, &xp, Some(&mut gm), None, false);
            xp[d] = orig;
            let fd = (ep - em) / (2.0 * eps);
            assert!(
                (fd - g[3 * a + i]).abs() <= 1e-6 * scale_g,
                "gradient ({a},{i}): {fd} vs {}",
                g[3 * a + i]
            );
            for r in 0..ne {
                let fdh = (gp[r] - gm[r]) / (2.0 * eps);
                let an = h[r * ne + 3 * a + i];
                assert!((fdh - an).abs() <= 1e-6 * scale_h, "hessian ({r},{a},{i}): {fdh} vs {an}");
            }
        }
    }
}

#[test]
fn linear_tet_forces_and_stiffness_match_finite_differences() {
    let mesh = box_mesh([0.0; 3], [1.0, 0.5, 0.5], [2, 1, 1]).unwrap();
    for model in MaterialModel::ALL {
        let m = FemModel::new(mesh.clone(), material(model)).unwrap();
        let x = perturbed(&m.rest_positions(), 0.08, 7);
        for e in [0, 5, 11] {
            check_element_derivatives(&m, &x, &m.mesh().tets[e], e);
        }
    }
}

#[test]
fn quadratic_tet_forces_and_stiffness_match_finite_differences() {
    let mesh = quadratic(&box_mesh([0.0; 3], [1.0; 3], [1, 1, 1]).unwrap());
    for model in [MaterialModel::NeoHookean, MaterialModel::StableNeoHookean, MaterialModel::FixedCorotated] {
        let m = QuadraticModel::new(mesh.clone(), material(model)).unwrap();
        let x = perturbed(&m.rest_positions(), 0.04, 3);
        let nodes = m.mesh().elements[2];
        check_element_derivatives(&m, &x, &nodes, 2);
    }
}

#[test]
fn patch_test_reproduces_a_linear_field() {
    // A distorted 3x3x3 patch: interior vertices moved, boundary vertices on u = A X + b.
    let mesh = box_mesh([0.0; 3], [1.0; 3], [3, 3, 3]).unwrap();
    let interior = |p: [f64; 3]| p.iter().all(|&c| c > 1e-9 && c < 1.0 - 1e-9);
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let mut distorted = mesh.clone();
    for p in distorted.positions.iter_mut() {
        if interior(*p) {
            for c in p.iter_mut() {
                *c += 0.08 * rng.random_range(-1.0..1.0);
            }
        }
    }
    let a = [[1.05, 0.02, -0.01], [0.03, 0.97, 0.04], [-0.02, 0.01, 1.02]];
    let b = [0.1, -0.2, 0.05];
    let affine = |p: [f64; 3]| [0, 1, 2].map(|i| a[i][0] * p[0] + a[i][1] * p[1] + a[i][2] * p[2] + b[i]);
    for model in [MaterialModel::NeoHookean, MaterialModel::StVenantKirchhoff, MaterialModel::FixedCorotated]
    {
        let mut m = FemModel::new(distorted.clone(), material(model)).unwrap();
        let boundary = m.vertices_where(|p| !interior(p));
        m.pin_vertices(&boundary).unwrap();
        // Initial guess: the affine map plus noise on the interior vertices.
        let mut x = m.rest_positions();
        for v in 0..m.vertices() {
            x[3 * v..3 * v + 3].copy_from_slice(&affine(m.mesh().positions[v]));
        }
        let noisy = perturbed(&x, 0.02, 12);
        for v in 0..m.vertices() {
            if !boundary.contains(&v) {
                x[3 * v..3 * v + 3].copy_from_slice(&noisy[3 * v..3 * v + 3]);
            }
        }
        let mut sim = FemSimulation::new(m, FemParams::default().with_newton_tolerance(1e-14)).unwrap();
        sim.solve_static(&mut x, 1).unwrap();
        for v in 0..sim.model().vertices() {
            let want = affine(sim.model().mesh().positions[v]);
            for c in 0..3 {
                assert!((x[3 * v + c] - want[c]).abs() < 1e-10, "{model:?} vertex {v}");
            }
        }
        // Constant stress: every element has the same F = A, interior forces cancel.
        let mut f = vec![0.0; x.len()];
        sim.internal_forces(&x, &mut f).unwrap();
        let p_scale = sim.model().material().lame.mu;
        for v in 0..sim.model().vertices() {
            if interior(sim.model().mesh().positions[v]) {
                for c in 0..3 {
                    assert!(f[3 * v + c].abs() < 1e-9 * p_scale, "residual {}", f[3 * v + c]);
                }
            }
        }
    }
}

#[test]
fn explicit_steps_conserve_momentum_of_a_free_body() {
    let mesh = box_mesh([0.0; 3], [1.0, 0.4, 0.3], [4, 2, 2]).unwrap();
    let m = FemModel::new(mesh, material(MaterialModel::StableNeoHookean)).unwrap();
    let mut sim = FemSimulation::new(m, FemParams::new(TimeIntegrator::SymplecticEuler)).unwrap();
    let mut state = sim.rest_state();
    state.x = perturbed(&state.x, 0.02, 9);
    state.v = perturbed(&vec![0.0; state.v.len()], 0.5, 10);
    let (p0, l0) = sim.momentum(&state);
    let mut last = None;
    for _ in 0..50 {
        last = Some(sim.step(&mut state, 1e-4).unwrap());
    }
    let r = last.unwrap();
    let (p, _) = (r.linear_momentum.unwrap(), r.angular_momentum.unwrap());
    for c in 0..3 {
        assert!((p[c] - p0[c]).abs() < 1e-12, "linear momentum drift {} ", p[c] - p0[c]);
    }
    // Symplectic Euler conserves angular momentum of central-free internal forces up to O(dt)
    // per step in x x v (the position update uses v_{n+1}); check it stays close.
    let (_, l) = sim.momentum(&state);
    for c in 0..3 {
        assert!((l[c] - l0[c]).abs() < 1e-3 * (1.0 + l0[c].abs()), "angular momentum {l:?} vs {l0:?}");
    }
}

#[test]
fn assembly_is_bitwise_identical_for_any_thread_count() {
    let mesh = box_mesh([0.0; 3], [2.0, 0.5, 0.5], [16, 4, 4]).unwrap();
    let m = FemModel::new(mesh, material(MaterialModel::FixedCorotated)).unwrap();
    let x = perturbed(&m.rest_positions(), 0.05, 1);
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| {
            let mut k = m.assembly().matrix();
            let mut buf = vec![0.0; 144 * m.elements()];
            assemble_stiffness(&m, m.assembly(), &x, true, &mut buf, &mut k);
            let mut sim = FemSimulation::new(m.clone(), FemParams::default()).unwrap();
            let mut f = vec![0.0; x.len()];
            sim.internal_forces(&x, &mut f).unwrap();
            let mut state = sim.rest_state();
            state.x = x.clone();
            sim.step(&mut state, 1e-2).unwrap();
            (
                k.values().iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
                f.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
                state.x.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
            )
        })
    };
    let one = run(1);
    for t in [2, 3, 4] {
        assert!(run(t) == one, "{t} threads differ from 1");
    }
}

#[test]
fn stiffness_is_symmetric_and_matches_force_differences() {
    let mesh = box_mesh([0.0; 3], [1.0, 0.5, 0.5], [3, 2, 2]).unwrap();
    let m = FemModel::new(mesh, material(MaterialModel::NeoHookean)).unwrap();
    let x = perturbed(&m.rest_positions(), 0.03, 2);
    let mut k = m.assembly().matrix();
    let mut buf = vec![0.0; 144 * m.elements()];
    assemble_stiffness(&m, m.assembly(), &x, false, &mut buf, &mut k);
    assert!(k.is_symmetric(1e-9 * k.values().iter().fold(0.0f64, |s, v| s.max(v.abs()))));
    // K = -df/dx: compare one column with a central difference of the global forces.
    let mut sim = FemSimulation::new(m, FemParams::default()).unwrap();
    let n = x.len();
    let d = 7;
    let eps = 1e-6;
    let (mut fp, mut fm) = (vec![0.0; n], vec![0.0; n]);
    let mut xp = x.clone();
    xp[d] += eps;
    sim.internal_forces(&xp, &mut fp).unwrap();
    xp[d] -= 2.0 * eps;
    sim.internal_forces(&xp, &mut fm).unwrap();
    let dense = k.to_dense();
    let scale = dense.iter().flatten().fold(0.0f64, |s, v| s.max(v.abs()));
    for r in 0..n {
        let fd = -(fp[r] - fm[r]) / (2.0 * eps);
        assert!((fd - dense[r][d]).abs() < 1e-6 * scale, "K[{r}][{d}] {} vs {fd}", dense[r][d]);
    }
}

#[test]
fn mass_matrices_carry_the_total_mass() {
    let mesh = box_mesh([0.0; 3], [2.0, 1.0, 0.5], [3, 2, 2]).unwrap();
    let m = FemModel::new(mesh, material(MaterialModel::Linear)).unwrap();
    let total: f64 = m.lumped_mass().iter().sum();
    assert!((total - 1000.0).abs() < 1e-9);
    // Consistent mass: v^T M v for a uniform velocity is the total mass times |v|^2.
    let ones: Vec<f64> = (0..3 * m.vertices()).map(|d| if d % 3 == 0 { 1.0 } else { 0.0 }).collect();
    let mut mv = vec![0.0; ones.len()];
    m.consistent_mass().mul_vec(&ones, &mut mv);
    assert!((anim_core::linalg::dot(&ones, &mv) - 1000.0).abs() < 1e-9);
}

#[test]
fn implicit_step_with_gravity_and_ground_contact() {
    let mesh = box_mesh([0.0, 0.0, 0.05], [0.2; 3], [2, 2, 2]).unwrap();
    for mass in [MassKind::Lumped, MassKind::Consistent] {
        let mut m = FemModel::new(mesh.clone(), material(MaterialModel::StableNeoHookean))
            .unwrap()
            .with_gravity(EARTH_GRAVITY)
            .with_mass(mass);
        m.add_obstacle(Obstacle::ground(0.0), 1e6).unwrap();
        for solver in LinearSolverChoice::ALL {
            let params = FemParams::default().with_linear_solver(solver).with_rayleigh(0.01);
            let mut sim = FemSimulation::new(m.clone(), params).unwrap();
            let mut state = sim.rest_state();
            for _ in 0..40 {
                sim.step(&mut state, 0.01).unwrap();
            }
            let zmin = state.x.chunks(3).map(|p| p[2]).fold(f64::INFINITY, f64::min);
            // Resting on the ground: penetration bounded by the penalty (m g / kappa ~ 1e-5).
            assert!(zmin > -1e-3 && zmin < 5e-3, "{mass:?} {solver:?}: zmin {zmin}");
        }
    }
}

#[test]
fn explicit_contact_projection_keeps_vertices_out_of_a_sphere() {
    let mesh = box_mesh([-0.1, -0.1, 0.6], [0.2; 3], [2, 2, 2]).unwrap();
    let mut m =
        FemModel::new(mesh, material(MaterialModel::FixedCorotated)).unwrap().with_gravity(EARTH_GRAVITY);
    m.add_obstacle(Obstacle::Sphere { center: [0.0, 0.0, 0.0], radius: 0.5 }, 1e6).unwrap();
    let mut sim = FemSimulation::new(m, FemParams::new(TimeIntegrator::SymplecticEuler)).unwrap();
    let mut state = sim.rest_state();
    for _ in 0..3000 {
        sim.step(&mut state, 2e-4).unwrap();
    }
    for p in state.x.chunks(3) {
        let r = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
        assert!(r >= 0.5 - 1e-12, "vertex inside the sphere: r = {r}");
    }
}

#[test]
fn kinematic_vertices_follow_their_motion() {
    let mesh = box_mesh([0.0; 3], [1.0, 0.2, 0.2], [5, 1, 1]).unwrap();
    let mut m = FemModel::new(mesh, material(MaterialModel::StableNeoHookean)).unwrap();
    let left = m.vertices_where(|p| p[0] < 1e-9);
    let right = m.vertices_where(|p| p[0] > 1.0 - 1e-9);
    m.pin_vertices(&left).unwrap();
    let motion = Motion::Rotate { center: [1.0, 0.1, 0.1], axis: [1.0, 0.0, 0.0], angular_velocity: 1.0 };
    m.add_kinematic(&right, motion).unwrap();
    let rest = m.mesh().positions.clone();
    let mut sim = FemSimulation::new(m, FemParams::default()).unwrap();
    let mut state = sim.rest_state();
    for _ in 0..10 {
        sim.step(&mut state, 0.05).unwrap();
    }
    for &v in &right {
        let want = motion.position(rest[v], 0.5);
        for c in 0..3 {
            assert!((state.x[3 * v + c] - want[c]).abs() < 1e-12);
        }
    }
    for &v in &left {
        for c in 0..3 {
            assert_eq!(state.x[3 * v + c], rest[v][c]);
        }
    }
}

#[test]
fn errors_name_the_cause() {
    let mesh = box_mesh([0.0; 3], [1.0; 3], [1, 1, 1]).unwrap();
    assert!(matches!(Material::new(MaterialModel::NeoHookean, -1.0, 0.3, 1.0), Err(FemError::Material(_))));
    assert!(matches!(Material::new(MaterialModel::NeoHookean, 1.0, 0.5, 1.0), Err(FemError::Material(_))));
    assert!(matches!(
        Material::new(MaterialModel::NeoHookean, 1.0, 0.3, 0.0),
        Err(FemError::BadParameter { name: "density", .. })
    ));
    let mut m = FemModel::new(mesh.clone(), material(MaterialModel::NeoHookean)).unwrap();
    assert!(matches!(m.pin(99, [true; 3]), Err(FemError::BoundaryVertexOutOfRange { vertex: 99, .. })));
    let mut sim = FemSimulation::new(m, FemParams::new(TimeIntegrator::SymplecticEuler)).unwrap();
    let mut state = sim.rest_state();
    assert!(matches!(sim.step(&mut state, 0.0), Err(FemError::BadParameter { name: "dt", .. })));
    state.x.pop();
    assert!(matches!(sim.step(&mut state, 0.1), Err(FemError::StateSize { .. })));
    // An inverted element under Neo-Hookean: named, state left unchanged.
    let mut state = sim.rest_state();
    let tet = sim.model().mesh().tets[3];
    for c in 0..3 {
        state.x[3 * tet[0] + c] = 0.5 * state.x[3 * tet[1] + c] + 0.5 * state.x[3 * tet[2] + c];
    }
    let before = state.x.clone();
    let err = sim.step(&mut state, 1e-3).unwrap_err();
    assert!(matches!(err, FemError::NonFiniteElement { step: 0, .. }), "{err}");
    assert_eq!(state.x, before);
    assert!(matches!(
        FemSimulation::new(
            FemModel::new(mesh, material(MaterialModel::Linear)).unwrap(),
            FemParams::default().with_newton_tolerance(0.0)
        ),
        Err(FemError::BadParameter { name: "newton_tolerance", .. })
    ));
}

#[test]
fn explicit_divergence_is_reported_not_silent() {
    // A stiff body with a step far above its stability limit blows up; the step that produces
    // a non-finite value reports it.
    let mesh = box_mesh([0.0; 3], [1.0; 3], [2, 2, 2]).unwrap();
    let m =
        FemModel::new(mesh, Material::new(MaterialModel::StVenantKirchhoff, 1e9, 0.3, 1.0).unwrap()).unwrap();
    let mut sim = FemSimulation::new(m, FemParams::new(TimeIntegrator::SymplecticEuler)).unwrap();
    let mut state = sim.rest_state();
    state.x = perturbed(&state.x, 0.01, 4);
    let mut failed = None;
    for _ in 0..2000 {
        if let Err(e) = sim.step(&mut state, 1e-2) {
            failed = Some(e);
            break;
        }
    }
    let e = failed.expect("the step should diverge");
    assert!(matches!(e, FemError::NonFiniteState { .. } | FemError::NonFiniteElement { .. }), "{e}");
    assert!(state.x.iter().all(|v| v.is_finite()));
}

#[test]
fn an_overflowing_load_is_reported_by_vertex_and_the_step_undone() {
    // A finite load of f64::MAX on a vertex of a feather-light box (density 1e-6, vertex masses
    // of order 1e-8 kg): its acceleration overflows, and so its velocity and position.
    let mesh = box_mesh([0.0; 3], [1.0; 3], [2, 2, 2]).unwrap();
    let mut m =
        FemModel::new(mesh, Material::new(MaterialModel::NeoHookean, 1e5, 0.3, 1e-6).unwrap()).unwrap();
    let vertex = 7;
    m.add_nodal_force(vertex, [0.0, 0.0, f64::MAX]).unwrap();
    let mut sim = FemSimulation::new(m, FemParams::new(TimeIntegrator::SymplecticEuler)).unwrap();
    let mut state = sim.rest_state();
    let before = state.clone();
    let memory = sim.memory();
    let err = sim.step(&mut state, 1e-3).unwrap_err();
    let bits = |s: &anim_core::integrate::State| {
        s.x.iter().chain(&s.v).chain([&s.t]).map(|v| v.to_bits()).collect::<Vec<_>>()
    };
    assert_eq!(bits(&state), bits(&before), "the failed step changed the state");
    assert_eq!(sim.memory(), memory, "the failed step changed the memory");
    let msg = err.to_string();
    assert!(msg.starts_with("anim-fem: step 0: non-finite position of vertex 7, component z"), "{msg}");
    match err {
        FemError::NonFiniteState { step, field, vertex: v, component, value, last_finite } => {
            assert_eq!(step, 0);
            assert_eq!(field, crate::error::StateField::Position);
            assert_eq!(v, vertex);
            assert_eq!(component, 2);
            assert_eq!(value, f64::INFINITY);
            assert_eq!(last_finite.to_vec(), before.x[3 * vertex..3 * vertex + 3].to_vec());
        }
        other => panic!("expected NonFiniteState, got {other}"),
    }
}

/// The nodal strain of a uniform stretch by `s` along x is `(s^2 - 1) / 2` at every node (the
/// Green-Lagrange strain `diag((s^2 - 1) / 2, 0, 0)`), and 0 after a rigid rotation.
#[test]
fn nodal_strain_is_the_green_strain_of_a_uniform_stretch_and_zero_for_a_rotation() {
    let mesh = box_mesh([0.0; 3], [1.0, 0.5, 0.5], [3, 2, 2]).unwrap();
    let m = FemModel::new(mesh, material(MaterialModel::NeoHookean)).unwrap();
    let rest = m.rest_positions();
    let s = 1.2;
    let stretched: Vec<f64> =
        rest.iter().enumerate().map(|(i, &x)| if i % 3 == 0 { s * x } else { x }).collect();
    let mut strain = Vec::new();
    m.nodal_strain(&stretched, &mut strain);
    assert_eq!(strain.len(), m.vertices());
    let expected = (s * s - 1.0) / 2.0;
    assert!(strain.iter().all(|e| (e - expected).abs() < 1e-12), "{strain:?} vs {expected}");
    // A quarter turn about z: (x, y, z) -> (-y, x, z).
    let turned: Vec<f64> = rest.chunks_exact(3).flat_map(|p| [-p[1], p[0], p[2]]).collect();
    m.nodal_strain(&turned, &mut strain);
    assert!(strain.iter().all(|e| e.abs() < 1e-12), "{strain:?}");
}
