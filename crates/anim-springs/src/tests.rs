//! Tests against independent references: closed forms, finite differences, a second algorithm.

use crate::analytic::{HangingChain, TwoParticleSpring};
use crate::*;
use anim_core::integrate::{
    IntegratorKind, MechanicalSystem, NewtonParams, SecondOrderSystem, State, study::advance,
};
use anim_core::linalg::{CsrMatrix, LinearSolverKind};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn tight() -> NewtonParams {
    NewtonParams::with_tolerance(1e-13)
}

fn run_kind(net: &mut SpringNetwork, state: &mut State, kind: IntegratorKind, dt: f64, steps: usize) {
    let mut integ = kind.build_with::<SpringNetwork>(net.dof(), tight(), LinearSolverKind::Cg);
    advance(integ.as_mut(), net, state, dt, steps).unwrap();
}

// ---------------------------------------------------------------- two-particle spring

#[test]
fn two_particle_spring_matches_the_analytic_solution() {
    let case = TwoParticleSpring::example();
    let mut net = case.network().unwrap();
    let t_end = 1.3 * case.period();
    for (kind, steps, tol) in [
        (IntegratorKind::Rk4, 400, 1e-8),
        (IntegratorKind::VelocityVerlet, 4000, 1e-4),
        (IntegratorKind::ImplicitMidpoint, 4000, 1e-4),
    ] {
        let mut state = case.initial_state();
        run_kind(&mut net, &mut state, kind, t_end / steps as f64, steps);
        let (x, v) = case.exact(state.t);
        let err = state
            .x
            .iter()
            .zip(&x)
            .chain(state.v.iter().zip(&v))
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(err < tol, "{}: error {err:e}", kind.label());
    }
}

#[test]
fn damped_two_particle_spring_matches_the_analytic_solution() {
    let case = TwoParticleSpring { damping: 0.8, ..TwoParticleSpring::example() };
    let mut net = case.network().unwrap();
    let mut state = case.initial_state();
    let steps = 2000;
    run_kind(&mut net, &mut state, IntegratorKind::Rk4, 2.0 * case.period() / steps as f64, steps);
    let (x, v) = case.exact(state.t);
    let err =
        state.x.iter().zip(&x).chain(state.v.iter().zip(&v)).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    assert!(err < 1e-9, "error {err:e}");
    // The damping really acts: the amplitude has decayed.
    let (x0, _) = case.exact(0.0);
    let stretch = |x: &[f64]| {
        ((x[0] - x[3]).powi(2) + (x[1] - x[4]).powi(2) + (x[2] - x[5]).powi(2)).sqrt() - case.rest_length
    };
    assert!(stretch(&state.x).abs() < 0.5 * stretch(&x0).abs());
}

// ---------------------------------------------------------------- Jacobians

/// A random network of `n` particles: random springs (rest lengths from 0.5 to 1.5 times the
/// current length, so about half are compressed), one zero-length spring, damping, a ground plane
/// and a sphere that some particles penetrate, random velocities. Resampled until no particle
/// lies within 1e-3 of a collider surface (the contact force has a kink there).
fn random_network(rng: &mut ChaCha8Rng, n: usize, colliders: bool) -> (SpringNetwork, Vec<f64>, Vec<f64>) {
    loop {
        let mut b = NetworkBuilder::new();
        b.gravity([0.3, -0.2, -9.81]);
        let pos: Vec<[f64; 3]> = (0..n)
            .map(|_| [rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-0.3..1.0)])
            .collect();
        for p in &pos {
            b.particle(*p, rng.random_range(0.5..2.0));
        }
        for i in 0..n {
            for j in i + 1..n {
                if rng.random_bool(0.6) {
                    let d = ((pos[i][0] - pos[j][0]).powi(2)
                        + (pos[i][1] - pos[j][1]).powi(2)
                        + (pos[i][2] - pos[j][2]).powi(2))
                    .sqrt();
                    let rest = d * rng.random_range(0.5..1.5);
                    b.spring_with_rest_length(
                        i,
                        j,
                        rest,
                        SpringParams::new(rng.random_range(1.0..10.0), rng.random_range(0.0..0.5)),
                    );
                }
            }
        }
        b.spring_with_rest_length(0, n - 1, 0.0, SpringParams::new(3.0, 0.2));
        if colliders {
            b.collider(Collider::ground(0.0, 50.0).with_damping(0.3).with_friction(0.7).with_smoothing(0.05));
            b.collider(Collider::sphere([0.2, 0.1, 0.4], 0.6, 40.0).with_damping(0.2).with_friction(0.5));
        }
        let net = b.build().unwrap();
        let near = net.model().rest_positions().iter().any(|p| {
            let ground = p[2].abs() < 1e-3;
            let r = ((p[0] - 0.2).powi(2) + (p[1] - 0.1).powi(2) + (p[2] - 0.4).powi(2)).sqrt();
            colliders && (ground || (r - 0.6).abs() < 1e-3)
        });
        if near {
            continue;
        }
        let x: Vec<f64> = pos.iter().flatten().copied().collect();
        let v: Vec<f64> = (0..3 * n).map(|_| rng.random_range(-1.0..1.0)).collect();
        return (net, x, v);
    }
}

/// Column `k` of `c_x K + c_v D` through `jacobian_apply`.
fn jacobian_dense(net: &SpringNetwork, c_x: f64, c_v: f64) -> Vec<Vec<f64>> {
    let n = net.dof();
    let mut cols = vec![vec![0.0; n]; n];
    let mut e = vec![0.0; n];
    for k in 0..n {
        e[k] = 1.0;
        net.jacobian_apply(c_x, c_v, &e, &mut cols[k]);
        e[k] = 0.0;
    }
    // Transpose into rows.
    (0..n).map(|r| (0..n).map(|c| cols[c][r]).collect()).collect()
}

/// Central finite differences of the force in `x` (`wrt_x`) or `v`.
fn fd_jacobian(net: &mut SpringNetwork, x: &[f64], v: &[f64], wrt_x: bool) -> Vec<Vec<f64>> {
    let n = net.dof();
    let h = 1e-6;
    let mut rows = vec![vec![0.0; n]; n];
    let (mut fp, mut fm) = (vec![0.0; n], vec![0.0; n]);
    for k in 0..n {
        let (mut xp, mut vp) = (x.to_vec(), v.to_vec());
        let (mut xm, mut vm) = (x.to_vec(), v.to_vec());
        if wrt_x {
            xp[k] += h;
            xm[k] -= h;
        } else {
            vp[k] += h;
            vm[k] -= h;
        }
        net.force(0.0, &xp, &vp, &mut fp);
        net.force(0.0, &xm, &vm, &mut fm);
        for r in 0..n {
            rows[r][k] = (fp[r] - fm[r]) / (2.0 * h);
        }
    }
    rows
}

fn max_rel_diff(a: &[Vec<f64>], b: &[Vec<f64>]) -> f64 {
    let scale = a.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
    a.iter().flatten().zip(b.iter().flatten()).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max) / scale
}

#[test]
fn exact_jacobians_match_central_finite_differences() {
    let mut rng = ChaCha8Rng::seed_from_u64(42);
    let mut compressed = 0;
    for trial in 0..20 {
        let (mut net, x, v) = random_network(&mut rng, 6, trial % 2 == 0);
        compressed += net
            .springs()
            .iter()
            .filter(|s| {
                let d = (0..3).map(|c| (x[3 * s.i + c] - x[3 * s.j + c]).powi(2)).sum::<f64>().sqrt();
                d < s.rest_length
            })
            .count();
        net.set_jacobian_mode(JacobianMode::Exact);
        net.linearize(0.0, &x, &v);
        let k = jacobian_dense(&net, 1.0, 0.0);
        let d = jacobian_dense(&net, 0.0, 1.0);
        let k_fd = fd_jacobian(&mut net, &x, &v, true);
        let d_fd = fd_jacobian(&mut net, &x, &v, false);
        let (ek, ed) = (max_rel_diff(&k, &k_fd), max_rel_diff(&d, &d_fd));
        assert!(ek < 1e-7, "trial {trial}: K differs from finite differences by {ek:e}");
        assert!(ed < 1e-7, "trial {trial}: D differs from finite differences by {ed:e}");
        // Sanity: the comparison is not vacuous.
        assert!(k.iter().flatten().any(|v| v.abs() > 1.0));
    }
    assert!(compressed > 20, "only {compressed} compressed springs sampled");
}

/// Eigenvalues of a dense symmetric matrix by cyclic Jacobi rotations.
fn symmetric_eigenvalues(mut a: Vec<Vec<f64>>) -> Vec<f64> {
    let n = a.len();
    for _sweep in 0..100 {
        let off: f64 = (0..n)
            .flat_map(|i| (0..n).filter(move |&j| j != i).map(move |j| (i, j)))
            .map(|(i, j)| a[i][j] * a[i][j])
            .sum();
        if off < 1e-30 {
            break;
        }
        for p in 0..n {
            for q in p + 1..n {
                if a[p][q].abs() < 1e-300 {
                    continue;
                }
                let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
                let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
                let t = if theta == 0.0 { 1.0 } else { t };
                let c = 1.0 / (t * t + 1.0).sqrt();
                let s = t * c;
                for k in 0..n {
                    let (akp, akq) = (a[k][p], a[k][q]);
                    a[k][p] = c * akp - s * akq;
                    a[k][q] = s * akp + c * akq;
                }
                for k in 0..n {
                    let (apk, aqk) = (a[p][k], a[q][k]);
                    a[p][k] = c * apk - s * aqk;
                    a[q][k] = s * apk + c * aqk;
                }
            }
        }
    }
    (0..n).map(|i| a[i][i]).collect()
}

#[test]
fn definite_jacobians_are_symmetric_negative_semidefinite() {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let mut exact_had_positive = 0;
    for trial in 0..20 {
        let (mut net, x, v) = random_network(&mut rng, 6, trial % 2 == 0);
        net.linearize(0.0, &x, &v);
        for (c_x, c_v) in [(1.0, 0.0), (0.0, 1.0), (0.7, 0.3)] {
            let j = jacobian_dense(&net, c_x, c_v);
            let scale = j.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
            for r in 0..j.len() {
                for c in 0..j.len() {
                    assert!((j[r][c] - j[c][r]).abs() <= 1e-14 * scale, "trial {trial}: not symmetric");
                }
            }
            let max_eig = symmetric_eigenvalues(j).into_iter().fold(f64::NEG_INFINITY, f64::max);
            assert!(max_eig <= 1e-12 * scale, "trial {trial}: eigenvalue {max_eig:e} > 0");
        }
        // Without the fix, compressed springs make K indefinite (on the symmetric part).
        net.set_jacobian_mode(JacobianMode::Exact);
        net.linearize(0.0, &x, &vec![0.0; x.len()]);
        let k = jacobian_dense(&net, 1.0, 0.0);
        let sym: Vec<Vec<f64>> =
            (0..k.len()).map(|r| (0..k.len()).map(|c| 0.5 * (k[r][c] + k[c][r])).collect()).collect();
        if symmetric_eigenvalues(sym).into_iter().fold(f64::NEG_INFINITY, f64::max) > 1e-9 {
            exact_had_positive += 1;
        }
    }
    assert!(exact_had_positive >= 10, "the exact K was indefinite in only {exact_had_positive} of 20 trials");
}

#[test]
fn definite_fix_changes_the_jacobian_but_not_the_force() {
    // One compressed spring: the fix clamps the transverse stiffness to 0.
    let mut b = NetworkBuilder::new();
    b.particle([0.0, 0.0, 0.0], 1.0);
    b.particle([0.5, 0.0, 0.0], 1.0);
    b.spring_with_rest_length(0, 1, 1.0, SpringParams::new(10.0, 0.0));
    let mut net = b.build().unwrap();
    let (x, v) = (net.rest_state().x, vec![0.0; 6]);
    let mut f = [vec![0.0; 6], vec![0.0; 6]];
    let mut k = Vec::new();
    for (m, mode) in [JacobianMode::Definite, JacobianMode::Exact].into_iter().enumerate() {
        net.set_jacobian_mode(mode);
        net.force(0.0, &x, &v, &mut f[m]);
        net.linearize(0.0, &x, &v);
        k.push(jacobian_dense(&net, 1.0, 0.0));
    }
    assert_eq!(f[0], f[1]);
    assert_eq!(f[0][0], -5.0); // f = -k (L - l) n, n = (x0 - x1)/L = -x: pushes particle 0 to -x
    // Transverse yy entry of the (0, 0) block: definite 0, exact -k (1 - l/L) = +10.
    assert_eq!(k[0][1][1], 0.0);
    assert!((k[1][1][1] - 10.0).abs() < 1e-12);
    // Along the spring both are -k.
    assert!((k[0][0][0] + 10.0).abs() < 1e-12 && (k[1][0][0] + 10.0).abs() < 1e-12);
}

#[test]
fn assembled_jacobian_matches_matrix_free_and_keeps_its_pattern() {
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    for (trial, mode) in [JacobianMode::Definite, JacobianMode::Exact].into_iter().enumerate() {
        let (mut net, x, v) = random_network(&mut rng, 8, true);
        net.set_jacobian_mode(mode);
        net.linearize(0.0, &x, &v);
        let mut m = CsrMatrix::default();
        let (c_x, c_v) = (0.37, 1.3);
        assert!(net.jacobian_assemble(c_x, c_v, &mut m));
        let ptr = m.col_idx().as_ptr();
        let dx: Vec<f64> = (0..net.dof()).map(|_| rng.random_range(-1.0..1.0)).collect();
        let (mut y_free, mut y_csr) = (vec![0.0; net.dof()], vec![0.0; net.dof()]);
        net.jacobian_apply(c_x, c_v, &dx, &mut y_free);
        m.mul_vec(&dx, &mut y_csr);
        let scale = y_free.iter().fold(0.0f64, |a, b| a.max(b.abs()));
        let err = y_free.iter().zip(&y_csr).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        assert!(err <= 1e-13 * scale, "trial {trial}: assembled and matrix-free differ by {err:e}");
        let mut diag = vec![0.0; net.dof()];
        assert!(net.jacobian_diagonal(c_x, c_v, &mut diag));
        for (r, d) in diag.iter().enumerate() {
            assert!((m.get(r, r).unwrap_or(0.0) - d).abs() <= 1e-13 * scale);
        }
        if mode == JacobianMode::Definite {
            assert!(m.is_symmetric(1e-14 * scale));
        }
        // A second assembly rewrites the values in place.
        net.linearize(0.0, &v, &x);
        assert!(net.jacobian_assemble(2.0, 0.5, &mut m));
        assert_eq!(m.col_idx().as_ptr(), ptr, "the pattern was reallocated");
        // A matrix with a foreign pattern is replaced by ours.
        let mut foreign = CsrMatrix::identity(net.dof());
        assert!(net.jacobian_assemble(2.0, 0.5, &mut foreign));
        assert_eq!(foreign, m);
    }
}

// ---------------------------------------------------------------- statics, conservation

#[test]
fn hanging_chain_rests_at_the_analytic_stretch() {
    let chain = HangingChain {
        count: 12,
        mass: 0.05,
        stiffness: 40.0,
        damping: 0.5,
        rest_length: 0.1,
        gravity: 9.81,
    };
    let mut net = chain.network().unwrap();
    let mut state = net.rest_state();
    let exact = chain.equilibrium();
    // Backward Euler with damping, run to rest (its fixed point is exactly f(x) = 0, v = 0).
    let mut integ = IntegratorKind::BackwardEuler.build_with::<SpringNetwork>(
        net.dof(),
        NewtonParams::with_tolerance(1e-12),
        LinearSolverKind::Cholesky,
    );
    let mut steps = 0;
    loop {
        integ.step(&mut net, &mut state, 0.05).unwrap();
        steps += 1;
        let vmax = state.v.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        if vmax < 1e-13 || steps > 20_000 {
            break;
        }
    }
    let err = state.x.iter().zip(&exact).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    let rel = err / chain.total_stretch();
    assert!(rel < 1e-9, "relative stretch error {rel:e} after {steps} steps");
    // And the spring forces balance gravity: the bottom spring carries one weight.
    let bottom = net.springs().last().unwrap();
    let len = (state.x[3 * bottom.j + 2] - state.x[3 * bottom.i + 2]).abs();
    assert!(((len - chain.rest_length) * chain.stiffness - chain.mass * chain.gravity).abs() < 1e-9);
}

#[test]
fn momentum_is_conserved_without_gravity_and_pins() {
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let (net, x, v) = {
        let (net, x, v) = random_network(&mut rng, 7, false);
        let mut b = NetworkBuilder::new();
        for (p, part) in net.particles().iter().enumerate() {
            b.particle([x[3 * p], x[3 * p + 1], x[3 * p + 2]], part.mass);
        }
        for s in net.springs() {
            b.spring_with_rest_length(s.i, s.j, s.rest_length, SpringParams::new(s.stiffness, s.damping));
        }
        (b.build().unwrap(), x, v)
    };
    for kind in IntegratorKind::ALL {
        let mut net = net.clone();
        let mut state = State::new(x.clone(), v.clone());
        let p0 = net.linear_momentum(&state.v);
        let l0 = net.angular_momentum(&state.x, &state.v);
        run_kind(&mut net, &mut state, kind, 1e-3, 300);
        let p1 = net.linear_momentum(&state.v);
        let dp = (0..3).map(|c| (p1[c] - p0[c]).abs()).fold(0.0, f64::max);
        // Position Verlet and leapfrog derive velocities from position differences divided by
        // dt: their rounding floor is about M eps max|x| / dt = 1e-11 here, not M eps max|v|.
        let floor = if matches!(kind, IntegratorKind::PositionVerlet | IntegratorKind::Leapfrog) {
            net.total_mass() * 16.0 * f64::EPSILON * 3.0 / 1e-3
        } else {
            1e-12
        };
        assert!(dp < floor, "{}: linear momentum drifted by {dp:e}", kind.label());
        if matches!(kind, IntegratorKind::SymplecticEuler | IntegratorKind::VelocityVerlet) {
            let l1 = net.angular_momentum(&state.x, &state.v);
            let dl = (0..3).map(|c| (l1[c] - l0[c]).abs()).fold(0.0, f64::max);
            assert!(dl < 1e-12, "{}: angular momentum drifted by {dl:e}", kind.label());
        }
    }
}

#[test]
fn undamped_energy_is_conserved_by_velocity_verlet() {
    let case = TwoParticleSpring::example();
    let mut net = case.network().unwrap();
    let mut state = case.initial_state();
    let e0 = net.energy(0.0, &state.x, &state.v).unwrap();
    let mut integ = IntegratorKind::VelocityVerlet.build::<SpringNetwork>(6);
    let mut worst = 0.0f64;
    for _ in 0..20_000 {
        integ.step(&mut net, &mut state, case.period() / 200.0).unwrap();
        worst = worst.max((net.energy(0.0, &state.x, &state.v).unwrap() - e0).abs());
    }
    // Energy of the relative motion k s0^2/2 + mu s0'^2/2 plus the centre's kinetic energy.
    let mu = case.reduced_mass();
    let vc2: f64 = case.center_velocity.iter().map(|c| c * c).sum();
    let expected = 0.5 * case.stiffness * case.stretch.powi(2)
        + 0.5 * mu * case.stretch_rate.powi(2)
        + 0.5 * (case.m1 + case.m2) * vc2;
    assert!((e0 - expected).abs() < 1e-14);
    assert!(worst < 1e-3 * e0, "energy error {worst:e} of {e0}");
}

// ---------------------------------------------------------------- determinism

fn run_in_pool(
    threads: usize,
    kind: IntegratorKind,
    linear: LinearSolverKind,
    steps: usize,
    dt: f64,
) -> State {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
    pool.install(|| {
        let scene = scenes::hanging_cloth(Some(48)).unwrap();
        let mut net = scene.network;
        let mut state = scene.state;
        assert!(net.num_particles() > network::PARALLEL_THRESHOLD);
        let mut integ = kind.build_with::<SpringNetwork>(net.dof(), scenes::animation_newton(), linear);
        advance(integ.as_mut(), &mut net, &mut state, dt, steps).unwrap();
        // Energies are reduced in parallel too.
        let e = net.energy(state.t, &state.x, &state.v).unwrap();
        state.v.push(e);
        state
    })
}

#[test]
fn results_are_bitwise_identical_for_1_2_and_4_threads() {
    for (kind, linear, steps, dt) in [
        (IntegratorKind::SymplecticEuler, LinearSolverKind::Cg, 40, 1e-4),
        (IntegratorKind::BackwardEuler, LinearSolverKind::JacobiPcg, 3, 0.01),
        (IntegratorKind::BackwardEuler, LinearSolverKind::Cholesky, 2, 0.01),
    ] {
        let one = run_in_pool(1, kind, linear, steps, dt);
        for threads in [2, 4] {
            let other = run_in_pool(threads, kind, linear, steps, dt);
            let same = one
                .x
                .iter()
                .zip(&other.x)
                .chain(one.v.iter().zip(&other.v))
                .all(|(a, b)| a.to_bits() == b.to_bits());
            assert!(same, "{} / {linear:?}: {threads} threads differ from 1", kind.label());
        }
        // The run moved: the test compares something.
        assert!(one.x.iter().zip(&scenes::hanging_cloth(Some(48)).unwrap().state.x).any(|(a, b)| a != b));
    }
}

// ---------------------------------------------------------------- degenerate springs, divergence

#[test]
fn zero_length_and_coincident_springs_never_give_nan() {
    let mut b = NetworkBuilder::new();
    b.gravity(EARTH_GRAVITY);
    let a = b.particle([0.0, 0.0, 0.0], 1.0);
    let c = b.particle([0.0, 0.0, 0.0], 1.0); // coincident with a
    let d = b.particle([1.0, 0.0, 0.0], 1.0);
    let e = b.particle([1.0, 0.0, 0.0], 1.0); // coincident with d
    b.pin(a);
    b.spring_with_rest_length(a, c, 0.1, SpringParams::new(100.0, 1.0)); // positive rest, zero length
    b.spring_with_rest_length(d, e, 0.0, SpringParams::new(100.0, 1.0)); // zero rest, zero length
    b.spring(c, d, SpringParams::new(100.0, 1.0));
    let mut net = b.build().unwrap();
    let state0 = net.rest_state();
    let mut f = vec![0.0; net.dof()];
    net.force(0.0, &state0.x, &state0.v, &mut f);
    assert!(f.iter().all(|v| v.is_finite()));
    // The pair (a, c) coincides now and at rest: the direction falls back to +x, and the spring
    // pushes c (its second particle) along -x with |f| = k l = 10.
    assert_eq!((f[3], f[4]), (-10.0, 0.0), "{f:?}");
    // The zero-length pair (d, e) is at rest: no force but gravity.
    assert_eq!((f[6], f[9]), (0.0, 0.0));
    for mode in [JacobianMode::Definite, JacobianMode::Exact] {
        net.set_jacobian_mode(mode);
        net.linearize(0.0, &state0.x, &state0.v);
        let j = jacobian_dense(&net, 1.0, 1.0);
        assert!(j.iter().flatten().all(|v| v.is_finite()), "{mode:?}");
    }
    net.set_jacobian_mode(JacobianMode::Definite);
    for kind in IntegratorKind::ALL {
        let mut state = state0.clone();
        let mut n2 = net.clone();
        // Two coincident particles joined by a spring of positive rest length repel with k l in a
        // direction that turns by O(1) as they separate (transverse stiffness k (l/L - 1) is
        // huge at small L, and the definite Jacobian leaves it out): Newton converges only
        // linearly in the first step, so allow it more iterations than the default 20.
        let mut newton = NewtonParams::default();
        newton.max_iterations = 200;
        let mut integ = kind.build_with::<SpringNetwork>(n2.dof(), newton, LinearSolverKind::Cg);
        for step in 0..200 {
            if let Err(e) = integ.step(&mut n2, &mut state, 1e-3) {
                panic!("{} step {step}: {e}", kind.label());
            }
        }
        assert!(state.x.iter().chain(&state.v).all(|v| v.is_finite()), "{}", kind.label());
        // The coincident pair with positive rest length separated.
        let sep = (0..3).map(|k| (state.x[3 + k] - state.x[k]).powi(2)).sum::<f64>().sqrt();
        assert!(sep > 1e-3, "{}: separation {sep}", kind.label());
    }
}

#[test]
fn a_diverging_explicit_run_is_stopped_with_the_step_and_spring() {
    let chain = HangingChain {
        count: 10,
        mass: 0.01,
        stiffness: 100.0,
        damping: 0.0,
        rest_length: 0.1,
        gravity: 9.81,
    };
    let net = chain.network().unwrap();
    let mut state = net.rest_state();
    state.x[5] -= 0.01; // excite the chain
    let dt = 3.0 * (chain.mass / chain.stiffness).sqrt(); // far beyond dt ~ sqrt(m/k)
    let mut sim = SpringSimulation::new(
        net,
        IntegratorKind::SymplecticEuler,
        NewtonParams::default(),
        LinearSolverKind::Cg,
    )
    .unwrap();
    let mut last_good = state.clone();
    let err = loop {
        match sim.advance(&mut state, dt) {
            Ok(_) => last_good = state.clone(),
            Err(e) => break e,
        }
        assert!(sim.steps() < 10_000, "never diverged");
    };
    match err {
        SpringError::Diverged { step, spring, ratio, bound, .. } => {
            assert_eq!(step, sim.steps());
            assert!(spring < 9 && ratio > bound);
        }
        other => panic!("expected Diverged, got {other}"),
    }
    assert_eq!(state, last_good, "the failed step changed the state");
    assert!(state.x.iter().all(|v| v.is_finite()));
}

#[test]
fn an_overflowing_force_is_reported_by_particle_and_the_step_undone() {
    // k = 1e308 is finite, but the force it gives overflows as soon as a spring stretches by
    // more than about 1.8: step 0 falls by g dt^2, step 1 flings particle 1 up by ~1e297, and
    // the force of step 2 on particle 1 (both of its springs stretched ~1e297 along z) is
    // infinite along z and `inf * 0 = NaN` along x and y. Positions are checked first, so the
    // report is the position of particle 1, component x, value NaN. Velocity Verlet evaluates
    // the force at the drifted position within the step, so it flings particle 1 in step 0
    // (v ~ 2.5e299) and overflows in step 1, where the drifted positions (~5e296) are still
    // finite but the closing half kick is not: velocity of particle 1, component x.
    let chain =
        HangingChain { count: 3, mass: 1.0, stiffness: 1e308, damping: 0.0, rest_length: 0.1, gravity: 9.81 };
    use anim_core::diagnostics::{Component, Field};
    for (kind, step, field) in [
        (IntegratorKind::SymplecticEuler, 2, Field::Position),
        (IntegratorKind::VelocityVerlet, 1, Field::Velocity),
    ] {
        let net = chain.network().unwrap();
        let mut state = net.rest_state();
        let mut sim = SpringSimulation::new(net, kind, NewtonParams::default(), LinearSolverKind::Cg)
            .unwrap()
            .with_max_stretch(f64::INFINITY);
        let mut failed = None;
        for _ in 0..10 {
            let before = state.clone();
            // The memory is a checkpoint's (feature `serde`); without it only the state is compared.
            #[cfg(feature = "serde")]
            let memory = sim.memory();
            #[cfg(not(feature = "serde"))]
            let memory = ();
            if let Err(e) = sim.advance(&mut state, 1e-3) {
                failed = Some((e, before, memory));
                break;
            }
        }
        #[cfg_attr(not(feature = "serde"), expect(unused_variables))]
        let Some((err, before, memory)) = failed else { panic!("{}: never overflowed", kind.label()) };
        let bits = |s: &State| s.x.iter().chain(&s.v).chain([&s.t]).map(|v| v.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&state), bits(&before), "{}: the failed step changed the state", kind.label());
        #[cfg(feature = "serde")]
        assert_eq!(sim.memory(), memory, "{}: the failed step changed the memory", kind.label());
        let msg = err.to_string();
        match err {
            SpringError::NonFinite(nf) => {
                let old = if field == Field::Position { &before.x } else { &before.v };
                assert_eq!(nf.step, step, "{msg}");
                assert_eq!(sim.steps(), step);
                assert_eq!(nf.element.kind, "particle");
                assert_eq!(nf.element.index, 1, "{msg}");
                assert_eq!(nf.element.component, Component::Axis(0), "{msg}");
                assert_eq!(nf.field, field, "{msg}");
                assert!(nf.value.is_nan(), "{msg}");
                assert_eq!(nf.dof, 3, "{msg}");
                assert_eq!(nf.last_finite, old[3], "{msg}");
                assert_eq!(*nf.last_finite_element, old[3..6], "{msg}");
                assert!(old[5].abs() > 1e296, "particle 1 was flung along z: {msg}");
                let head = format!(
                    "anim-springs: step {step}: non-finite {field} of particle 1, component x (value NaN)"
                );
                assert!(msg.starts_with(&head), "{msg}");
            }
            other => panic!("{}: expected NonFinite, got {other}", kind.label()),
        }
    }
}

// ---------------------------------------------------------------- builders

#[test]
fn cloth_lattice_and_mesh_have_the_expected_springs() {
    let n = 128;
    let scene = scenes::benchmark_cloth(n).unwrap();
    let structural = 2 * n * (n - 1);
    let shear = 2 * (n - 1) * (n - 1);
    let bending = 2 * n * (n - 2);
    assert_eq!(scene.network.num_springs(), structural + shear + bending);
    assert_eq!(scene.network.num_springs(), 97_026);
    assert_eq!(scene.network.triangles().len(), 2 * (n - 1) * (n - 1));
    let count = |k: SpringKind| scene.network.springs().iter().filter(|s| s.kind == k).count();
    assert_eq!(
        (count(SpringKind::Structural), count(SpringKind::Shear), count(SpringKind::Bending)),
        (structural, shear, bending)
    );

    let mut b = NetworkBuilder::new();
    let p = SpringParams::new(1.0, 0.0);
    b.lattice(&Lattice {
        n: [3, 4, 5],
        origin: [0.0; 3],
        spacing: 0.1,
        mass: 1.0,
        edge: p,
        face_diagonal: Some(p),
        body_diagonal: Some(p),
    })
    .unwrap();
    let net = b.build().unwrap();
    let (x, y, z) = (3, 4, 5);
    let edges = (x - 1) * y * z + x * (y - 1) * z + x * y * (z - 1);
    let faces = 2 * ((x - 1) * (y - 1) * z + (x - 1) * y * (z - 1) + x * (y - 1) * (z - 1));
    let bodies = 4 * (x - 1) * (y - 1) * (z - 1);
    assert_eq!(net.num_springs(), edges + faces + bodies);
    assert_eq!(net.triangles().len(), 4 * ((x - 1) * (y - 1) + (x - 1) * (z - 1) + (y - 1) * (z - 1)));
    assert!((net.total_mass() - 1.0).abs() < 1e-12);

    // A mesh made of the cloth's triangles: every unique edge is a spring (structural + one
    // diagonal per quad), and bending springs cross every interior edge.
    let cloth = scenes::hanging_cloth(Some(5)).unwrap().network;
    let mut b = NetworkBuilder::new();
    let tris = cloth.triangles().to_vec();
    b.mesh(
        cloth.model().rest_positions(),
        &tris,
        &MeshSprings { mass: MeshMass::AreaDensity(0.2), edge: p, bending: Some(p) },
    )
    .unwrap();
    let mesh = b.build().unwrap();
    let m = 5;
    let unique_edges = 2 * m * (m - 1) + (m - 1) * (m - 1);
    let interior = unique_edges - 4 * (m - 1);
    assert_eq!(mesh.num_springs(), unique_edges + interior);
    assert!((mesh.total_mass() - 0.2).abs() < 1e-12, "area-lumped mass {}", mesh.total_mass());
}

#[test]
fn builder_errors_name_the_element() {
    let p = SpringParams::new(1.0, 0.0);
    let two = || {
        let mut b = NetworkBuilder::new();
        b.particle([0.0; 3], 1.0);
        b.particle([1.0, 0.0, 0.0], 1.0);
        b
    };
    assert_eq!(NetworkBuilder::new().build().unwrap_err(), BuildError::Input(InputError::NoParticles));
    let mut b = two();
    b.spring(0, 5, p);
    assert_eq!(b.build().unwrap_err(), BuildError::SpringIndex { spring: 0, index: 5, particles: 2 });
    let mut b = two();
    b.spring(0, 1, p).spring(1, 1, p);
    assert_eq!(b.build().unwrap_err(), BuildError::SelfSpring { spring: 1, particle: 1 });
    let mut b = two();
    b.spring(0, 1, SpringParams::new(0.0, 0.0));
    assert!(matches!(b.build().unwrap_err(), BuildError::BadStiffness { spring: 0, .. }));
    let mut b = two();
    b.spring(0, 1, SpringParams::new(f64::NAN, 0.0));
    assert!(matches!(b.build().unwrap_err(), BuildError::BadStiffness { spring: 0, .. }));
    let mut b = two();
    b.spring(0, 1, SpringParams::new(1.0, -1.0));
    assert!(matches!(b.build().unwrap_err(), BuildError::BadDamping { spring: 0, .. }));
    let mut b = two();
    b.spring_with_rest_length(0, 1, -1.0, p);
    assert!(matches!(b.build().unwrap_err(), BuildError::BadRestLength { spring: 0, .. }));
    let mut b = two();
    b.particle([0.0; 3], 0.0);
    assert!(matches!(b.build().unwrap_err(), BuildError::Input(InputError::BadMass { particle: 2, .. })));
    let mut b = two();
    b.particle([f64::INFINITY, 0.0, 0.0], 1.0);
    assert!(matches!(
        b.build().unwrap_err(),
        BuildError::Input(InputError::NonFinitePosition { particle: 2, .. })
    ));
    let mut b = two();
    b.pin(0).pin(9);
    assert_eq!(
        b.build().unwrap_err(),
        BuildError::Input(InputError::PinIndex { pin: 1, index: 9, particles: 2 })
    );
    let mut b = two();
    b.triangle([0, 1, 2]);
    assert!(matches!(
        b.build().unwrap_err(),
        BuildError::Input(InputError::TriangleIndex { triangle: 0, index: 2, .. })
    ));
    let mut b = two();
    b.gravity([0.0, f64::NAN, 0.0]);
    assert!(matches!(b.build().unwrap_err(), BuildError::Input(InputError::NonFiniteGravity { .. })));
    let mut b = two();
    b.collider(Collider::sphere([0.0; 3], -1.0, 1.0));
    assert!(matches!(b.build().unwrap_err(), BuildError::Input(InputError::BadCollider { collider: 0, .. })));
    let mut b = two();
    b.collider(Collider {
        shape: Shape::Plane { point: [0.0; 3], normal: [0.0; 3] },
        ..Collider::ground(0.0, 1.0)
    });
    assert!(matches!(b.build().unwrap_err(), BuildError::Input(InputError::BadCollider { collider: 0, .. })));
    // A bad box or capsule is refused, naming the collider and the shape.
    for (shape, name) in [
        (Shape::Box { center: [0.0; 3], half_extents: [1.0, 0.0, 1.0] }, "box"),
        (Shape::Capsule { a: [0.0; 3], b: [0.0; 3], radius: 0.5 }, "capsule"),
    ] {
        let mut b = two();
        b.collider(Collider::ground(-1.0, 1.0));
        b.collider(Collider { shape, ..Collider::ground(0.0, 1.0) });
        let err = b.build().unwrap_err();
        assert!(matches!(err, BuildError::Input(InputError::BadCollider { collider: 1, .. })), "{err:?}");
        let message = err.to_string();
        assert!(message.starts_with("collider 1: ") && message.contains(name), "{message}");
    }

    // Shapes.
    let cloth = Cloth {
        nx: 1,
        ny: 3,
        origin: [0.0; 3],
        u: [1.0, 0.0, 0.0],
        v: [0.0, 1.0, 0.0],
        mass: 1.0,
        structural: p,
        shear: None,
        bending: None,
    };
    assert!(matches!(
        NetworkBuilder::new().cloth(&cloth).unwrap_err(),
        BuildError::Input(InputError::BadParameter { name: "nx", .. })
    ));
    let parallel = Cloth { nx: 3, v: [2.0, 0.0, 0.0], ..cloth };
    assert!(matches!(
        NetworkBuilder::new().cloth(&parallel).unwrap_err(),
        BuildError::Input(InputError::BadParameter { name: "v", .. })
    ));
    let chain = Chain { count: 3, start: [0.0; 3], end: [0.0; 3], mass: 1.0, spring: p };
    assert!(matches!(
        NetworkBuilder::new().chain(&chain).unwrap_err(),
        BuildError::Input(InputError::BadParameter { name: "end", .. })
    ));
    let lattice = Lattice {
        n: [2, 2, 2],
        origin: [0.0; 3],
        spacing: 0.0,
        mass: 1.0,
        edge: p,
        face_diagonal: None,
        body_diagonal: None,
    };
    assert!(matches!(
        NetworkBuilder::new().lattice(&lattice).unwrap_err(),
        BuildError::Input(InputError::BadParameter { name: "spacing", .. })
    ));

    // Meshes.
    let pos = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [2.0, 0.0, 0.0], [0.0, 0.0, 1.0]];
    let ms = MeshSprings { mass: MeshMass::AreaDensity(1.0), edge: p, bending: Some(p) };
    let err = |tris: &[[usize; 3]]| NetworkBuilder::new().mesh(&pos, tris, &ms).unwrap_err();
    assert!(matches!(
        err(&[[0, 1, 7]]),
        BuildError::Input(InputError::TriangleIndex { triangle: 0, index: 7, .. })
    ));
    assert!(matches!(
        err(&[[0, 1, 2], [0, 0, 2]]),
        BuildError::Input(InputError::DegenerateTriangle { triangle: 1, reason: "repeated vertex", .. })
    ));
    assert!(matches!(
        err(&[[0, 1, 3]]),
        BuildError::Input(InputError::DegenerateTriangle { triangle: 0, reason: "zero area", .. })
    ));
    assert!(matches!(err(&[[0, 1, 2]]), BuildError::Input(InputError::IsolatedVertex { vertex: 3, .. })));
    assert!(matches!(err(&[]), BuildError::Input(InputError::BadParameter { name: "triangles", .. })));
    let three = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 1.0, 1.0]];
    let e = NetworkBuilder::new().mesh(&three, &[[0, 1, 2], [1, 0, 3], [0, 1, 4]], &ms).unwrap_err();
    assert_eq!(e, BuildError::Input(InputError::NonManifoldEdge { a: 0, b: 1, triangles: 3 }));
    let e = NetworkBuilder::new().mesh(&three[..3], &[[0, 1, 2], [1, 0, 2]], &ms).unwrap_err();
    assert!(matches!(e, BuildError::DuplicateTriangle { .. }), "{e}");
    // Messages name the element.
    assert!(BuildError::BadStiffness { spring: 17, stiffness: -1.0 }.to_string().contains("spring 17"));
}

#[test]
fn mesh_from_obj_builds_a_network() {
    let obj = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n";
    let mesh = TriangleMesh::from_obj(obj).unwrap();
    let mut b = NetworkBuilder::new();
    let p = SpringParams::new(10.0, 0.0);
    b.mesh(
        &mesh.positions,
        &mesh.triangles,
        &MeshSprings { mass: MeshMass::PerVertex(0.1), edge: p, bending: Some(p) },
    )
    .unwrap();
    let net = b.build().unwrap();
    // 5 unique edges (4 sides + 1 diagonal) and one bending spring across the diagonal.
    assert_eq!(net.num_springs(), 6);
    let bend = net.springs().iter().find(|s| s.kind == SpringKind::Bending).unwrap();
    assert_eq!((bend.i, bend.j), (1, 3));
    assert!((bend.rest_length - 2f64.sqrt()).abs() < 1e-15);
}

// ---------------------------------------------------------------- contact, scenes

#[test]
fn a_particle_rests_on_the_ground_at_the_penalty_depth() {
    let mut b = NetworkBuilder::new();
    b.gravity(EARTH_GRAVITY);
    b.particle([0.3, 0.0, 0.05], 0.2);
    b.collider(Collider::ground(0.0, 1000.0).with_damping(0.5).with_friction(1.0).with_smoothing(1e-3));
    let mut net = b.build().unwrap();
    let mut state = net.rest_state();
    state.v[0] = 1.0; // sliding: friction must stop it
    let mut integ = IntegratorKind::BackwardEuler.build_with::<SpringNetwork>(
        3,
        NewtonParams::with_tolerance(1e-12),
        LinearSolverKind::Cholesky,
    );
    advance(integ.as_mut(), &mut net, &mut state, 0.005, 2000).unwrap();
    // phi(p) = k_c (p - delta/2) = m g.
    let depth = 0.2 * 9.81 / 1000.0 + 0.5e-3;
    assert!((state.x[2] + depth).abs() < 1e-9, "z = {}, expected {}", state.x[2], -depth);
    assert!(state.v.iter().all(|v| v.abs() < 1e-6), "still moving: {:?}", state.v);
    assert!(state.x[0] > 0.3, "friction acts against motion, it does not reverse it");
}

#[test]
fn a_sphere_pushes_particles_out() {
    let mut b = NetworkBuilder::new();
    b.particle([0.0, 0.0, 0.9], 1.0);
    b.collider(Collider::sphere([0.0, 0.0, 0.0], 1.0, 100.0));
    let mut net = b.build().unwrap();
    let s = net.rest_state();
    let mut f = vec![0.0; 3];
    net.force(0.0, &s.x, &s.v, &mut f);
    assert!((f[2] - 100.0 * 0.1).abs() < 1e-12 && f[0] == 0.0 && f[1] == 0.0);
    let e = net.energy_parts(&s.x, &s.v);
    assert!((e.contact - 0.5 * 100.0 * 0.01).abs() < 1e-12);
}

#[test]
fn every_scene_runs_with_its_suggested_integrator() {
    for name in scenes::NAMES {
        let res = if name == "benchmark-cloth" { Some(16) } else { None };
        let scene = scenes::by_name(name, res).unwrap().unwrap();
        let steps = if name == "benchmark-cloth" { 50 } else { 40 };
        let dt = scene.dt;
        let (mut sim, mut state) = scene.into_simulation().unwrap();
        let e0 = sim.network_mut().energy_parts(&state.x, &state.v).total();
        use anim_core::solver::Solver;
        let mut report = None;
        for _ in 0..steps {
            report = Some(sim.step(&mut state, dt).unwrap());
        }
        let report = report.unwrap();
        assert!(report.energy.unwrap() <= e0 + 1e-9 * e0.abs().max(1.0), "{name}: energy grew");
        assert!(report.linear_momentum.is_some());
        // Everything fell.
        let z0: f64 = sim.network().model().rest_positions().iter().map(|p| p[2]).sum();
        let z: f64 = state.x.chunks_exact(3).map(|p| p[2]).sum();
        assert!(name == "jelly-drop" || z < z0, "{name}: did not fall");
    }
    assert!(scenes::by_name("nope", None).is_none());
    assert!(scenes::hanging_cloth(Some(1)).is_err());
}

#[test]
fn jelly_lands_and_stays_above_the_ground() {
    let scene = scenes::jelly_drop(Some(4)).unwrap();
    let steps = (1.2 / scene.dt) as usize;
    let dt = scene.dt;
    let (mut sim, mut state) = scene.into_simulation().unwrap();
    let mut lowest = f64::INFINITY;
    for _ in 0..steps {
        sim.advance(&mut state, dt).unwrap();
        lowest = lowest.min(state.x.chunks_exact(3).map(|p| p[2]).fold(f64::INFINITY, f64::min));
    }
    // It reached the ground (penetration of a few millimetres at impact, no tunnelling).
    assert!(lowest < 0.0 && lowest > -0.02, "lowest point {lowest}");
    let vz: f64 = state.v.chunks_exact(3).map(|v| v[2].abs()).fold(0.0, f64::max);
    assert!(vz < 0.5, "still bouncing hard: {vz}");
}
