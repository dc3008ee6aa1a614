//! 10-node bodies in the time steppers: the consistent and lumped masses against an independent
//! quadrature, momentum conservation, a cantilever's first bending frequency against
//! Euler-Bernoulli theory, the energy behaviour of both integrators, boundary conditions and
//! contact, and thread-count determinism.

use crate::boundary::{Motion, Obstacle};
use crate::generate::{TET10_EDGES, box_mesh, quadratic};
use crate::material::{Material, MaterialModel};
use crate::mesh::TetMesh;
use crate::model::{EARTH_GRAVITY, ElementOrder, FemModel, MassKind};
use crate::sim::{FemParams, FemSimulation, LinearSolverChoice, TimeIntegrator};
use anim_core::integrate::State;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn material(model: MaterialModel) -> Material {
    Material::new(model, 1e5, 0.3, 1000.0).unwrap()
}

fn perturbed(x: &[f64], scale: f64, seed: u64) -> Vec<f64> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    x.iter().map(|v| v + scale * rng.random_range(-1.0..1.0)).collect()
}

/// The 10 shape functions at barycentric coordinates `l`, written out independently of the
/// crate's mass table.
fn shape(l: [f64; 4]) -> [f64; 10] {
    let mut n = [0.0; 10];
    for a in 0..4 {
        n[a] = l[a] * (2.0 * l[a] - 1.0);
    }
    for (k, [a, b]) in TET10_EDGES.iter().enumerate() {
        n[4 + k] = 4.0 * l[*a] * l[*b];
    }
    n
}

/// 5-point Gauss-Legendre on [0, 1].
fn gauss5() -> [(f64, f64); 5] {
    let x = [
        0.0,
        -0.538_469_310_105_683_1,
        0.538_469_310_105_683_1,
        -0.906_179_845_938_664,
        0.906_179_845_938_664,
    ];
    let w = [
        0.568_888_888_888_888_9,
        0.478_628_670_499_366_5,
        0.478_628_670_499_366_5,
        0.236_926_885_056_189_1,
        0.236_926_885_056_189_1,
    ];
    std::array::from_fn(|i| (0.5 * (x[i] + 1.0), 0.5 * w[i]))
}

/// `int_ref f(L) dL` over the reference tetrahedron (volume 1/6) by the collapsed (Duffy)
/// product rule `L1 = u, L2 = v (1 - u), L3 = w (1 - u)(1 - v)`, Jacobian `(1 - u)^2 (1 - v)`:
/// 125 points, exact for polynomials of degree 7.
fn reference_integral(f: impl Fn([f64; 4]) -> f64) -> f64 {
    let g = gauss5();
    let mut s = 0.0;
    for &(u, wu) in &g {
        for &(v, wv) in &g {
            for &(w, ww) in &g {
                let l1 = u;
                let l2 = v * (1.0 - u);
                let l3 = w * (1.0 - u) * (1.0 - v);
                let jac = (1.0 - u) * (1.0 - u) * (1.0 - v);
                s += wu * wv * ww * jac * f([1.0 - l1 - l2 - l3, l1, l2, l3]);
            }
        }
    }
    s
}

#[test]
fn consistent_mass_of_one_affine_tet10_matches_a_degree_7_quadrature() {
    // A skewed tetrahedron: the mass must scale with its volume only.
    let corners = [[0.1, 0.0, 0.2], [1.3, 0.2, -0.1], [0.4, 0.9, 0.3], [0.2, 0.3, 1.1]];
    let lin = TetMesh { positions: corners.to_vec(), tets: vec![[0, 1, 2, 3]] };
    let rho = 1000.0;
    let m = FemModel::quadratic(quadratic(&lin), material(MaterialModel::NeoHookean)).unwrap();
    let el = m.quadratic_elements().unwrap()[0];
    let volume = crate::mesh::signed_volume6(corners[0], corners[1], corners[2], corners[3]) / 6.0;
    let mass = m.consistent_mass();
    let mut total = 0.0;
    for a in 0..10 {
        for b in 0..10 {
            // rho int N_a N_b dV = rho 6 V int_ref N_a N_b.
            let want = rho * 6.0 * volume * reference_integral(|l| shape(l)[a] * shape(l)[b]);
            for i in 0..3 {
                let got = mass.get(3 * el[a] + i, 3 * el[b] + i).unwrap();
                assert!((got - want).abs() < 1e-12 * rho * volume, "M[{a}][{b}] = {got}, quadrature {want}");
                // No coupling between components.
                let off = mass.get(3 * el[a] + i, 3 * el[b] + (i + 1) % 3).unwrap();
                assert_eq!(off, 0.0);
            }
            total += mass.get(3 * el[a], 3 * el[b]).unwrap();
        }
    }
    assert!((total - rho * volume).abs() < 1e-12 * rho * volume, "total {total} vs rho V {}", rho * volume);
    // HRZ lumping: positive, proportional to the diagonal, summing to rho V.
    let lumped = m.lumped_mass();
    let sum: f64 = lumped.iter().sum();
    assert!((sum - rho * volume).abs() < 1e-12 * rho * volume);
    let ratio = lumped[el[0]] / mass.get(3 * el[0], 3 * el[0]).unwrap();
    for a in 0..10 {
        assert!(lumped[el[a]] > 0.0, "node {a}: {}", lumped[el[a]]);
        let r = lumped[el[a]] / mass.get(3 * el[a], 3 * el[a]).unwrap();
        assert!((r - ratio).abs() < 1e-12 * ratio, "node {a}: M_L / M_aa = {r} vs {ratio}");
    }
    // Plain row-sum lumping would give negative corner masses: the reason for HRZ.
    let row: f64 = (0..10).map(|b| mass.get(3 * el[0], 3 * el[b]).unwrap()).sum();
    assert!(row < 0.0);
}

#[test]
fn masses_of_a_tet10_mesh_carry_the_total_mass() {
    let mesh = box_mesh([0.0; 3], [2.0, 1.0, 0.5], [3, 2, 2]).unwrap();
    let m = FemModel::with_order(mesh, material(MaterialModel::Linear), ElementOrder::Quadratic).unwrap();
    assert_eq!(m.order(), ElementOrder::Quadratic);
    let total: f64 = m.lumped_mass().iter().sum();
    assert!((total - 1000.0).abs() < 1e-9, "{total}");
    assert!(m.lumped_mass().iter().all(|&x| x > 0.0));
    let ones: Vec<f64> = (0..3 * m.vertices()).map(|d| if d % 3 == 2 { 1.0 } else { 0.0 }).collect();
    let mut mv = vec![0.0; ones.len()];
    m.consistent_mass().mul_vec(&ones, &mut mv);
    assert!((anim_core::linalg::dot(&ones, &mv) - 1000.0).abs() < 1e-9);
}

#[test]
fn a_free_tet10_body_falls_with_g_under_either_mass() {
    // Gravity weights: lumped masses with lumped mass, row sums of M with consistent mass, so
    // that M^-1 f = g at every node (the row sums are negative at the corners).
    let mesh = box_mesh([0.0; 3], [0.4, 0.3, 0.2], [2, 2, 1]).unwrap();
    for kind in [MassKind::Lumped, MassKind::Consistent] {
        let m = FemModel::with_order(
            mesh.clone(),
            material(MaterialModel::StableNeoHookean),
            ElementOrder::Quadratic,
        )
        .unwrap()
        .with_mass(kind)
        .with_gravity(EARTH_GRAVITY);
        let mut sim = FemSimulation::new(m, FemParams::new(TimeIntegrator::SymplecticEuler)).unwrap();
        let mut state = sim.rest_state();
        let dt = 1e-4;
        sim.advance(&mut state, dt).unwrap();
        for (d, v) in state.v.iter().enumerate() {
            let want = dt * EARTH_GRAVITY[d % 3];
            assert!((v - want).abs() < 1e-9 * dt * 9.81, "{kind:?} dof {d}: {v} vs {want}");
        }
    }
}

/// A free 10-node body with random positions and velocities.
fn free_body(kind: MassKind) -> (FemSimulation, State, FemParams) {
    let mesh = box_mesh([0.0; 3], [0.6, 0.3, 0.3], [2, 1, 1]).unwrap();
    let m = FemModel::quadratic(quadratic(&mesh), material(MaterialModel::StableNeoHookean))
        .unwrap()
        .with_mass(kind);
    let params = FemParams::new(TimeIntegrator::SymplecticEuler);
    let sim = FemSimulation::new(m, params).unwrap();
    let mut state = sim.rest_state();
    state.x = perturbed(&state.x, 0.01, 3);
    state.v = perturbed(&vec![0.0; state.v.len()], 0.3, 4);
    (sim, state, params)
}

fn close3(a: [f64; 3], b: [f64; 3], tol: f64) -> bool {
    (0..3).all(|c| (a[c] - b[c]).abs() <= tol)
}

#[test]
fn symplectic_euler_conserves_momentum_of_a_free_tet10_body() {
    // x_{n+1} x M v_{n+1} summed = x_n x (M v_n + dt f(x_n)) summed: with internal forces free
    // of net force and torque, symplectic Euler conserves both momenta to rounding.
    for kind in [MassKind::Lumped, MassKind::Consistent] {
        let (mut sim, mut state, _) = free_body(kind);
        let (p0, l0) = sim.momentum(&state);
        let scale = p0.iter().chain(&l0).fold(0.0f64, |s, v| s.max(v.abs()));
        for _ in 0..200 {
            sim.advance(&mut state, 2e-5).unwrap();
        }
        let (p, l) = sim.momentum(&state);
        assert!(close3(p, p0, 1e-10 * scale), "{kind:?}: p {p:?} vs {p0:?}");
        assert!(close3(l, l0, 1e-10 * scale), "{kind:?}: L {l:?} vs {l0:?}");
        // The body did move and deform.
        assert!(sim.model().elastic_energy(&state.x) > 0.0);
    }
}

#[test]
fn backward_euler_conserves_momentum_of_a_free_tet10_body() {
    // Backward Euler: M (v_{n+1} - v_n) = dt f(x_{n+1}), x_{n+1} = x_n + dt v_{n+1}, so linear
    // momentum is conserved and angular momentum changes by exactly dt sum_i v_{n+1,i} x (M v_n)_i
    // (not zero: the method does not conserve it); both checked with a tight Newton tolerance and
    // the exact Hessian (no definiteness projection), so that the last update leaves a residual
    // of its square.
    for kind in [MassKind::Lumped, MassKind::Consistent] {
        let (sim, mut state, params) = free_body(kind);
        let model = sim.model().clone();
        let mut sim = FemSimulation::new(
            model,
            FemParams { integrator: TimeIntegrator::BackwardEuler, ..params }
                .with_newton_tolerance(1e-10)
                .with_projection(false)
                .with_linear_solver(LinearSolverChoice::Ldlt),
        )
        .unwrap();
        let dt = 1e-3;
        let (p0, _) = sim.momentum(&state);
        let scale = sim.momentum(&state).1.iter().chain(&p0).fold(0.0f64, |s, v| s.max(v.abs()));
        let mut drift = 0.0f64;
        for _ in 0..20 {
            let (_, l_n) = sim.momentum(&state);
            let v_n = state.v.clone();
            let mut mv = vec![0.0; v_n.len()];
            match kind {
                MassKind::Lumped => {
                    for (d, o) in mv.iter_mut().enumerate() {
                        *o = sim.model().lumped_mass()[d / 3] * v_n[d];
                    }
                }
                MassKind::Consistent => sim.model().consistent_mass().mul_vec(&v_n, &mut mv),
            }
            sim.advance(&mut state, dt).unwrap();
            let mut cross = [0.0; 3];
            for i in 0..v_n.len() / 3 {
                let (a, b) = (&state.v[3 * i..3 * i + 3], &mv[3 * i..3 * i + 3]);
                cross[0] += a[1] * b[2] - a[2] * b[1];
                cross[1] += a[2] * b[0] - a[0] * b[2];
                cross[2] += a[0] * b[1] - a[1] * b[0];
            }
            let (_, l) = sim.momentum(&state);
            let want = [0, 1, 2].map(|c| l_n[c] + dt * cross[c]);
            assert!(close3(l, want, 1e-11 * scale), "{kind:?}: L {l:?} vs {want:?}");
            drift = drift.max((0..3).map(|c| (l[c] - l_n[c]).abs()).fold(0.0, f64::max));
        }
        let (p, _) = sim.momentum(&state);
        assert!(close3(p, p0, 1e-11 * scale), "{kind:?}: p {p:?} vs {p0:?}");
        // The identity is not trivially satisfied: L itself moves by more than the tolerance.
        assert!(drift > 1e-6 * scale, "{kind:?}: {drift}");
    }
}

/// Cantilever 1 m x 0.1 m x 0.1 m, E = 10 MPa, rho = 1000, clamped at x = 0, on the coarse
/// 10 x 1 x 1 box mesh: released from the static deflection under a small tip traction
/// (1e-4 m), the frequency of the tip's vertical oscillation (symplectic Euler, lumped mass).
fn cantilever_frequency(order: ElementOrder) -> f64 {
    let (e_mod, nu, rho) = (1e7, 0.3, 1000.0);
    let mesh = box_mesh([0.0, -0.05, -0.05], [1.0, 0.1, 0.1], [10, 1, 1]).unwrap();
    let mat = Material::new(MaterialModel::StableNeoHookean, e_mod, nu, rho).unwrap();
    let build = |traction: f64| {
        let mut m = FemModel::with_order(mesh.clone(), mat, order).unwrap();
        let clamp = m.vertices_where(|p| p[0] < 1e-9);
        m.pin_vertices(&clamp).unwrap();
        m.add_traction(|c| c[0] > 1.0 - 1e-9, [0.0, 0.0, traction]);
        m
    };
    // Tip force 0.025 N: Euler-Bernoulli tip deflection F L^3 / (3 E I) = 1e-4 m.
    let mut loaded =
        FemSimulation::new(build(-2.5), FemParams::default().with_newton_tolerance(1e-12)).unwrap();
    let mut x = loaded.model().rest_positions();
    loaded.solve_static(&mut x, 1).unwrap();
    let model = build(0.0);
    let tip = model.vertices_where(|p| p[0] > 1.0 - 1e-9);
    let rest = model.rest_positions();
    let dt = match order {
        ElementOrder::Linear => 5e-5,
        ElementOrder::Quadratic => 5e-5,
    };
    let params = FemParams::new(TimeIntegrator::SymplecticEuler).with_energy_report(false);
    let mut sim = FemSimulation::new(model, params).unwrap();
    let mut state = sim.rest_state();
    state.x = x;
    let tip_z =
        |s: &State| tip.iter().map(|&v| s.x[3 * v + 2] - rest[3 * v + 2]).sum::<f64>() / tip.len() as f64;
    let mut crossings = Vec::new();
    let mut prev = tip_z(&state);
    assert!(prev < -1e-5, "static tip deflection {prev}");
    let steps = (1.5 / dt) as usize;
    for k in 0..steps {
        sim.advance(&mut state, dt).unwrap();
        let z = tip_z(&state);
        if (prev < 0.0) != (z < 0.0) {
            crossings.push((k as f64 + prev / (prev - z)) * dt);
        }
        prev = z;
    }
    assert!(crossings.len() >= 3, "{crossings:?}");
    let half_periods = (crossings.len() - 1) as f64;
    half_periods / (2.0 * (crossings[crossings.len() - 1] - crossings[0]))
}

#[test]
fn tet10_cantilever_frequency_matches_euler_bernoulli_where_tet4_locks() {
    // f1 = (1.875^2 / 2 pi) sqrt(E I / (rho A L^4)), I = h^4 / 12, A = h^2.
    let (e_mod, rho, h, l) = (1e7f64, 1000.0f64, 0.1f64, 1.0f64);
    let f_eb = 1.875_104_068_711_961f64.powi(2) / (2.0 * std::f64::consts::PI)
        * (e_mod * h.powi(4) / 12.0 / (rho * h * h * l.powi(4))).sqrt();
    let f10 = cantilever_frequency(ElementOrder::Quadratic);
    let f4 = cantilever_frequency(ElementOrder::Linear);
    eprintln!("cantilever f1: Euler-Bernoulli {f_eb:.4} Hz, tet10 {f10:.4} Hz, tet4 {f4:.4} Hz");
    assert!((f10 - f_eb).abs() < 0.03 * f_eb, "tet10 {f10} Hz vs Euler-Bernoulli {f_eb} Hz");
    assert!(f4 > 1.3 * f_eb, "tet4 {f4} Hz should lock (Euler-Bernoulli {f_eb} Hz)");
}

/// A clamped 10-node beam set swinging by an initial velocity, no gravity.
fn swinging_beam(params: FemParams, kind: MassKind) -> (FemSimulation, State) {
    let mesh = box_mesh([0.0, -0.05, -0.05], [0.5, 0.1, 0.1], [5, 1, 1]).unwrap();
    let mat = Material::new(MaterialModel::StableNeoHookean, 1e6, 0.3, 1000.0).unwrap();
    let mut m = FemModel::with_order(mesh, mat, ElementOrder::Quadratic).unwrap().with_mass(kind);
    let clamp = m.vertices_where(|p| p[0] < 1e-9);
    m.pin_vertices(&clamp).unwrap();
    let sim = FemSimulation::new(m, params).unwrap();
    let mut state = sim.rest_state();
    let rest = sim.model().rest_positions();
    for i in 0..state.v.len() / 3 {
        let s = rest[3 * i] / 0.5;
        state.v[3 * i + 2] = 0.5 * s * s;
    }
    (sim, state)
}

#[test]
fn symplectic_euler_energy_stays_bounded_on_tet10() {
    for kind in [MassKind::Lumped, MassKind::Consistent] {
        let (mut sim, mut state) = swinging_beam(FemParams::new(TimeIntegrator::SymplecticEuler), kind);
        let e0 = sim.total_energy(&state);
        let steps = 4000;
        let (mut first, mut second) = (0.0f64, 0.0f64);
        for k in 0..steps {
            let r = sim.advance(&mut state, 1e-4).unwrap();
            let dev = (r.energy.unwrap() - e0).abs() / e0;
            if k < steps / 2 { first = first.max(dev) } else { second = second.max(dev) }
        }
        eprintln!(
            "symplectic Euler {kind:?}: max relative energy error {first:e} (first half), {second:e} (second half)"
        );
        // Symplectic: the energy error oscillates at O(omega dt) without a trend (0.4 s, about
        // one period of the first mode).
        // omega_1 dt = 12.8 rad/s x 1e-4 s = 1.3e-3.
        assert!(first < 5e-3 && second < 5e-3, "{kind:?}: relative energy error {first}, {second}");
        assert!(second < 2.0 * first + 1e-4, "{kind:?}: energy error grows {first} -> {second}");
    }
}

#[test]
fn backward_euler_energy_decreases_monotonically_on_tet10() {
    for kind in [MassKind::Lumped, MassKind::Consistent] {
        let params = FemParams::new(TimeIntegrator::BackwardEuler).with_newton_tolerance(1e-12);
        let (mut sim, mut state) = swinging_beam(params, kind);
        let e0 = sim.total_energy(&state);
        let mut last = e0;
        for k in 0..100 {
            let e = sim.advance(&mut state, 2e-3).unwrap().energy.unwrap();
            assert!(e <= last + 1e-12 * e0, "{kind:?} step {k}: energy rose {last} -> {e}");
            last = e;
        }
        // The first mode (Euler-Bernoulli omega_1 = 12.8 rad/s) loses the energy factor
        // 1 / (1 + (omega_1 dt)^2) per step, 0.936 over 100 steps; higher modes lose more.
        assert!(last < 0.95 * e0, "{kind:?}: {last} vs {e0}");
    }
}

#[test]
fn tet10_kinematic_nodes_contact_and_tractions() {
    let mesh = box_mesh([0.0, -0.05, 0.45], [0.5, 0.1, 0.1], [5, 1, 1]).unwrap();
    let mat = Material::new(MaterialModel::FixedCorotated, 1e6, 0.3, 1000.0).unwrap();
    // Traction: the loaded area and total force; corner nodes of the face get nothing.
    let mut m = FemModel::with_order(mesh.clone(), mat, ElementOrder::Quadratic).unwrap();
    let area = m.add_traction(|c| c[0] > 0.5 - 1e-9, [0.0, 0.0, -10.0]);
    assert!((area - 0.01).abs() < 1e-15);
    let mut f = vec![0.0; 3 * m.vertices()];
    m.external_force(1.0, &mut f);
    let total: f64 = f.iter().skip(2).step_by(3).sum();
    assert!((total + 0.1).abs() < 1e-14, "{total}");
    for v in m.vertices_where(|p| p[0] > 0.5 - 1e-9) {
        if v < mesh.positions.len() {
            assert_eq!(f[3 * v + 2], 0.0, "corner {v}");
        }
    }
    // Kinematic end (edge nodes too) turning about the bar axis, the other end pinned, both
    // integrators.
    for integrator in [TimeIntegrator::SymplecticEuler, TimeIntegrator::BackwardEuler] {
        let mut m = FemModel::with_order(mesh.clone(), mat, ElementOrder::Quadratic).unwrap();
        let left = m.vertices_where(|p| p[0] < 1e-9);
        let right = m.vertices_where(|p| p[0] > 0.5 - 1e-9);
        assert_eq!(right.len(), 9, "4 corners and 5 edge nodes on the end face");
        m.pin_vertices(&left).unwrap();
        let motion = Motion::Rotate { center: [0.5, 0.0, 0.5], axis: [1.0, 0.0, 0.0], angular_velocity: 2.0 };
        m.add_kinematic(&right, motion).unwrap();
        let dt = if integrator == TimeIntegrator::SymplecticEuler { 1e-4 } else { 1e-3 };
        let mut sim = FemSimulation::new(m, FemParams::new(integrator).with_rayleigh(1e-3)).unwrap();
        let mut state = sim.rest_state();
        let rest = sim.model().rest_positions();
        let steps = (0.05 / dt) as usize;
        for _ in 0..steps {
            sim.advance(&mut state, dt).unwrap();
        }
        for &v in &right {
            let p = motion.position([rest[3 * v], rest[3 * v + 1], rest[3 * v + 2]], state.t);
            assert!(
                close3([state.x[3 * v], state.x[3 * v + 1], state.x[3 * v + 2]], p, 1e-12),
                "{integrator:?} {v}"
            );
        }
        for &v in &left {
            assert_eq!(&state.x[3 * v..3 * v + 3], &rest[3 * v..3 * v + 3]);
        }
        // The middle of the bar turned, less than the end.
        let mid = sim.model().vertices_where(|p| (p[0] - 0.25).abs() < 1e-9 && p[1] > 0.0 && p[2] > 0.5);
        let dy = state.x[3 * mid[0] + 1] - rest[3 * mid[0] + 1];
        assert!(dy < -1e-5, "{integrator:?}: {dy}");
    }
    // Contact: a 10-node cube dropped on the ground stays above it (explicit projection) or
    // within the penalty depth (implicit), and rests there.
    let cube = box_mesh([-0.05, -0.05, 0.02], [0.1, 0.1, 0.1], [1, 1, 1]).unwrap();
    let soft = Material::new(MaterialModel::StableNeoHookean, 1e5, 0.3, 1000.0).unwrap();
    for integrator in [TimeIntegrator::SymplecticEuler, TimeIntegrator::BackwardEuler] {
        let mut m = FemModel::with_order(cube.clone(), soft, ElementOrder::Quadratic)
            .unwrap()
            .with_gravity(EARTH_GRAVITY);
        m.add_obstacle(Obstacle::ground(0.0), 1e6).unwrap();
        let dt = if integrator == TimeIntegrator::SymplecticEuler { 5e-5 } else { 2e-3 };
        let mut sim = FemSimulation::new(m, FemParams::new(integrator).with_rayleigh(2e-3)).unwrap();
        let mut state = sim.rest_state();
        let mut lowest = f64::INFINITY;
        for _ in 0..(0.3 / dt) as usize {
            sim.advance(&mut state, dt).unwrap();
            lowest = state.x.iter().skip(2).step_by(3).fold(lowest, |a, &z| a.min(z));
        }
        // Penalty depth of the resting weight: m g / kappa over the bottom nodes, 1e-3 m at most.
        let floor = if integrator == TimeIntegrator::SymplecticEuler { 0.0 } else { -1e-3 };
        assert!(lowest >= floor, "{integrator:?}: lowest z {lowest}");
        let bottom = state.x.iter().skip(2).step_by(3).fold(f64::INFINITY, |a, &z| a.min(z));
        assert!(bottom < 1e-3, "{integrator:?}: the cube reached the ground ({bottom})");
    }
}

#[test]
fn tet10_steps_are_bitwise_identical_for_any_thread_count_and_solvers_agree() {
    let mesh = box_mesh([0.0, -0.1, -0.1], [1.0, 0.2, 0.2], [12, 4, 4]).unwrap();
    let mat = Material::new(MaterialModel::StableNeoHookean, 1e6, 0.3, 1000.0).unwrap();
    let mut m = FemModel::with_order(mesh, mat, ElementOrder::Quadratic).unwrap().with_gravity(EARTH_GRAVITY);
    let clamp = m.vertices_where(|p| p[0] < 1e-9);
    m.pin_vertices(&clamp).unwrap();
    assert!(3 * m.vertices() > 4096 && m.elements() > 256, "large enough to run in parallel");
    let start = perturbed(&m.rest_positions(), 1e-3, 8);
    let run = |threads: usize, params: FemParams, kind: MassKind, dt: f64, steps: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| {
            let mut sim = FemSimulation::new(m.clone().with_mass(kind), params).unwrap();
            let mut state = sim.rest_state();
            state.x.copy_from_slice(&start);
            for &v in &clamp {
                state.x[3 * v..3 * v + 3].copy_from_slice(&sim.model().mesh().positions[v]);
            }
            for _ in 0..steps {
                sim.advance(&mut state, dt).unwrap();
            }
            state
        })
    };
    let bits = |s: &State| s.x.iter().chain(&s.v).map(|v| v.to_bits()).collect::<Vec<_>>();
    for kind in [MassKind::Lumped, MassKind::Consistent] {
        let explicit = FemParams::new(TimeIntegrator::SymplecticEuler).with_rayleigh(1e-4);
        let one = bits(&run(1, explicit, kind, 1e-5, 3));
        assert!(bits(&run(4, explicit, kind, 1e-5, 3)) == one, "{kind:?} explicit: 4 threads differ");
    }
    let mut results = Vec::new();
    for solver in LinearSolverChoice::ALL {
        let implicit = FemParams::new(TimeIntegrator::BackwardEuler)
            .with_linear_solver(solver)
            .with_rayleigh(1e-3)
            .with_newton_tolerance(1e-10);
        let one = run(1, implicit, MassKind::Consistent, 1e-2, 1);
        assert!(
            bits(&run(3, implicit, MassKind::Consistent, 1e-2, 1)) == bits(&one),
            "{solver:?}: 3 threads differ"
        );
        results.push(one);
    }
    // The three linear solvers find the same step (to the Newton tolerance).
    for r in &results[1..] {
        let diff = r.x.iter().zip(&results[0].x).fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(diff < 1e-8, "{diff}");
    }
}

#[test]
fn every_scene_steps_with_tet10_elements() {
    for name in crate::scenes::NAMES {
        let scene =
            crate::scenes::by_name_with_order(name, Some(1), ElementOrder::Quadratic).unwrap().unwrap();
        assert_eq!(scene.model.order(), ElementOrder::Quadratic);
        let linear = crate::scenes::by_name(name, Some(1)).unwrap().unwrap();
        assert_eq!(linear.model.order(), ElementOrder::Linear);
        assert!(scene.model.vertices() > linear.model.vertices(), "{name}: edge nodes added");
        let dt = scene.dt;
        let (mut sim, mut state) = scene.into_simulation().unwrap();
        let x0 = state.x.clone();
        for _ in 0..3 {
            sim.advance(&mut state, dt).unwrap();
        }
        let moved = state.x.iter().zip(&x0).fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(moved > 1e-6 && moved < 0.1, "{name}: largest displacement {moved}");
    }
}

#[test]
fn bad_tet10_meshes_name_the_element_and_node() {
    let lin = box_mesh([0.0; 3], [1.0; 3], [1, 1, 1]).unwrap();
    let good = quadratic(&lin);
    let mat = material(MaterialModel::NeoHookean);
    // An edge node off its edge's midpoint.
    let mut curved = good.clone();
    let node = curved.elements[2][7];
    curved.positions[node][0] += 0.01;
    match FemModel::quadratic(curved, mat) {
        Err(e @ crate::FemError::CurvedElement { node: n, .. }) => {
            assert_eq!(n, node);
            let msg = e.to_string();
            assert!(msg.contains(&format!("edge node {node}")) && msg.contains("10-node element"), "{msg}");
        }
        other => panic!("expected CurvedElement, got {other:?}"),
    }
    // An edge node index past the end.
    let mut out = good.clone();
    out.elements[3][5] = 10_000;
    assert!(matches!(
        FemModel::quadratic(out, mat),
        Err(crate::FemError::VertexOutOfRange { element: 3, vertex: 10_000, .. })
    ));
    // An inverted corner tetrahedron.
    let mut inverted = good;
    inverted.elements[1].swap(0, 1);
    assert!(matches!(
        FemModel::quadratic(inverted, mat),
        Err(crate::FemError::InvertedElement { element: 1, .. })
    ));
}

#[test]
fn tet10_patch_test_and_centroid_deformation_gradient() {
    // An affine map x = A X + c of every node: F = A at every quadrature point (so the forces
    // of interior nodes vanish for a homogeneous stress) and at the centroid reported by
    // `deformation_gradient`.
    let mesh = box_mesh([0.0; 3], [1.0, 0.5, 0.5], [2, 2, 2]).unwrap();
    let m = FemModel::with_order(mesh, material(MaterialModel::NeoHookean), ElementOrder::Quadratic).unwrap();
    let a = anim_material::nalgebra::Matrix3::new(1.1, 0.2, 0.0, -0.1, 0.95, 0.05, 0.03, 0.0, 1.2);
    let x: Vec<f64> = m
        .mesh()
        .positions
        .iter()
        .flat_map(|p| {
            let q = a * anim_material::nalgebra::Vector3::from(*p);
            [q[0] + 0.3, q[1] - 0.2, q[2] + 0.1]
        })
        .collect();
    for e in 0..m.elements() {
        assert!((m.deformation_gradient(e, &x) - a).norm() < 1e-13, "element {e}");
    }
    let mut sim = FemSimulation::new(m, FemParams::default()).unwrap();
    let mut f = vec![0.0; x.len()];
    sim.internal_forces(&x, &mut f).unwrap();
    let scale = f.iter().fold(0.0f64, |s, v| s.max(v.abs()));
    let interior = sim.model().vertices_where(|p| {
        p[0] > 1e-9
            && p[0] < 1.0 - 1e-9
            && p[1] > 1e-9
            && p[1] < 0.5 - 1e-9
            && p[2] > 1e-9
            && p[2] < 0.5 - 1e-9
    });
    assert!(!interior.is_empty());
    for v in interior {
        for c in 0..3 {
            assert!(f[3 * v + c].abs() < 1e-12 * scale, "node {v}: {}", f[3 * v + c]);
        }
    }
}
