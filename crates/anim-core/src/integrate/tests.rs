//! Tests of the integrators against analytic solutions and against each other.

use super::study::{advance, fit_order};
use super::systems::{HarmonicOscillator, KeplerOrbit, LinearChain};
use super::*;
use crate::linalg::LinearSolverKind;

#[test]
fn kinds_agree_with_their_integrators() {
    for kind in IntegratorKind::ALL {
        let integ = kind.build::<HarmonicOscillator>(1);
        assert_eq!(integ.order(), kind.order(), "{}", kind.label());
        assert_eq!(integ.symplectic(), kind.is_symplectic(), "{}", kind.label());
    }
}

#[test]
fn kepler_exact_solution_satisfies_the_equations_of_motion() {
    // Independent check of the reference: energy -1/2, angular momentum sqrt(1 - e^2), and the
    // acceleration by central differences of the exact velocity equals -x / |x|^3.
    let orbit = KeplerOrbit::ellipse(0.7);
    for k in 0..50 {
        let t = 0.37 * k as f64;
        let (x, v) = orbit.exact(t);
        assert!((orbit.energy_of(&x, &v) + 0.5).abs() < 1e-13);
        assert!((KeplerOrbit::angular_momentum(&x, &v) - (1.0f64 - 0.49).sqrt()).abs() < 1e-13);
        let h = 1e-5;
        let (_, vp) = orbit.exact(t + h);
        let (_, vm) = orbit.exact(t - h);
        let r3 = (x[0] * x[0] + x[1] * x[1]).powf(1.5);
        for i in 0..2 {
            let acc = (vp[i] - vm[i]) / (2.0 * h);
            assert!((acc + x[i] / r3).abs() < 1e-7, "t = {t}: {acc} vs {}", -x[i] / r3);
        }
    }
}

#[test]
fn symplectic_methods_keep_energy_bounded_and_explicit_euler_gains_energy() {
    let steps = 100_000;
    let dt = 0.05;
    for kind in IntegratorKind::ALL {
        let mut sys = HarmonicOscillator::new(1.0, 1.0);
        let mut state = State::new(vec![1.0], vec![0.0]);
        let mut integ = kind.build(1);
        let e0 = 0.5;
        let mut max_err_first = 0.0f64;
        let mut max_err_last = 0.0f64;
        for i in 0..steps {
            integ.step(&mut sys, &mut state, dt).unwrap();
            let err = (sys.energy(state.t, &state.x, &state.v).unwrap() - e0).abs();
            if i < steps / 10 {
                max_err_first = max_err_first.max(err);
            } else if i >= steps - steps / 10 {
                max_err_last = max_err_last.max(err);
            }
        }
        let label = kind.label();
        if integ.symplectic() {
            // Bounded: the error over the last tenth is no larger than over the first tenth.
            assert!(
                max_err_last <= 1.05 * max_err_first + 1e-12,
                "{label}: {max_err_first} then {max_err_last}"
            );
            assert!(max_err_last < 0.05, "{label}: energy error {max_err_last}");
        }
        match kind {
            IntegratorKind::ExplicitEuler => {
                // (1 + h^2)^n growth: the energy is far from bounded.
                assert!(max_err_last > 100.0 * max_err_first, "{label}: {max_err_first} then {max_err_last}")
            }
            IntegratorKind::BackwardEuler => assert!(state.x[0].abs() < 1e-3, "{label} must dissipate"),
            _ => {}
        }
    }
}

#[test]
fn implicit_midpoint_conserves_linear_oscillator_energy_at_large_steps() {
    let mut sys = HarmonicOscillator::new(2.0, 50.0); // omega = 5
    let mut state = State::new(vec![0.3], vec![-1.0]);
    let e0 = sys.energy(0.0, &state.x, &state.v).unwrap();
    let mut integ =
        IntegratorKind::ImplicitMidpoint.build_with(1, NewtonParams::default(), LinearSolverKind::Cg);
    for _ in 0..1000 {
        integ.step(&mut sys, &mut state, 1.0).unwrap(); // omega h = 5: far past any explicit bound
    }
    let e = sys.energy(0.0, &state.x, &state.v).unwrap();
    assert!(((e - e0) / e0).abs() < 1e-10, "relative energy error {}", (e - e0) / e0);
}

#[test]
fn linearized_beta_blend_is_the_closed_form_formula() {
    // On a linear system one Newton iteration from (x0, v0) is the linearised scheme
    // (1 + beta h^2 k / m) v1 = v0 + h f(x0) / m, x1 = x0 + h v1, in closed form.
    let (m, k, h) = (0.5, 8.0, 0.1);
    for beta in [0.0, 0.25, 0.5, 1.0] {
        let mut sys = HarmonicOscillator::new(m, k);
        let mut state = State::new(vec![0.7], vec![-0.2]);
        let mut integ = IntegratorKind::BetaBlend { beta }.build_with(
            1,
            NewtonParams::linearized(),
            LinearSolverKind::Cg,
        );
        let (x0, v0) = (state.x[0], state.v[0]);
        integ.step(&mut sys, &mut state, h).unwrap();
        let v1 = (v0 - h * k * x0 / m) / (1.0 + beta * h * h * k / m);
        let x1 = x0 + h * v1;
        assert!((state.v[0] - v1).abs() < 1e-13, "beta {beta}: {} vs {v1}", state.v[0]);
        assert!((state.x[0] - x1).abs() < 1e-13, "beta {beta}: {} vs {x1}", state.x[0]);
    }
}

#[test]
#[cfg(feature = "faer")]
fn beta_zero_is_symplectic_euler_and_beta_one_is_backward_euler() {
    let run = |kind: IntegratorKind| {
        let mut sys = KeplerOrbit::ellipse(0.3);
        let (x0, v0) = sys.initial();
        let mut state = State::new(x0.to_vec(), v0.to_vec());
        let mut integ = kind.build_with(2, NewtonParams::with_tolerance(1e-14), LinearSolverKind::Cholesky);
        advance(integ.as_mut(), &mut sys, &mut state, 0.01, 200).unwrap();
        state
    };
    let a = run(IntegratorKind::BetaBlend { beta: 0.0 });
    let b = run(IntegratorKind::SymplecticEuler);
    for i in 0..2 {
        assert!((a.x[i] - b.x[i]).abs() < 1e-14 && (a.v[i] - b.v[i]).abs() < 1e-14);
    }
    let c = run(IntegratorKind::BetaBlend { beta: 1.0 });
    let d = run(IntegratorKind::BackwardEuler);
    assert_eq!(c, d);
}

#[test]
fn backward_euler_solves_its_nonlinear_equation() {
    // v1 = v0 + h a(x0 + h v1) must hold to Newton tolerance on the nonlinear orbit.
    let mut sys = KeplerOrbit::ellipse(0.6);
    let (x0, v0) = sys.initial();
    let mut state = State::new(x0.to_vec(), v0.to_vec());
    let h = 0.05;
    let mut integ = IntegratorKind::BackwardEuler.build_with(
        2,
        NewtonParams::with_tolerance(1e-13),
        LinearSolverKind::Cg,
    );
    let info = integ.step(&mut sys, &mut state, h).unwrap();
    assert!(info.newton_iterations >= 2, "a nonlinear force needs more than one Newton iteration");
    let mut a = [0.0; 2];
    sys.acceleration(h, &state.x, &state.v, &mut a);
    for i in 0..2 {
        assert!((state.v[i] - (v0[i] + h * a[i])).abs() < 1e-12);
        assert!((state.x[i] - (x0[i] + h * state.v[i])).abs() < 1e-15);
    }
}

#[test]
#[cfg(feature = "faer")]
fn every_linear_solver_gives_the_same_implicit_step() {
    let mut results = Vec::new();
    for linear in LinearSolverKind::ALL {
        let mut sys = LinearChain::new(6, 1.0, 100.0, 0.1, 9.81).with_damping(0.5);
        let mut state = sys.rest_state();
        let mut integ =
            IntegratorKind::BackwardEuler.build_with(sys.dof(), NewtonParams::with_tolerance(1e-12), linear);
        advance(integ.as_mut(), &mut sys, &mut state, 0.02, 20).unwrap();
        results.push((linear, state));
    }
    let (_, reference) = &results[results.len() - 1];
    for (linear, state) in &results {
        let diff = state.x.iter().zip(&reference.x).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        assert!(diff < 1e-8, "{linear:?} differs from Cholesky by {diff}");
    }
}

#[test]
#[cfg(not(feature = "faer"))]
fn without_faer_the_direct_solver_reports_it_is_unavailable() {
    use crate::integrate::IntegrateError;
    use crate::linalg::SolveError;
    assert!(!LinearSolverKind::Cholesky.is_available());
    assert!(
        LinearSolverKind::ALL.iter().filter(|k| **k != LinearSolverKind::Cholesky).all(|k| k.is_available())
    );
    let mut sys = LinearChain::new(6, 1.0, 100.0, 0.1, 9.81);
    let mut state = sys.rest_state();
    let mut integ = IntegratorKind::BackwardEuler.build_with(
        sys.dof(),
        NewtonParams::default(),
        LinearSolverKind::Cholesky,
    );
    let err = integ.step(&mut sys, &mut state, 0.02).unwrap_err();
    let text = err.to_string();
    assert!(text.contains("anim-core was built without its `faer` feature"), "{text}");
    assert!(
        matches!(
            err,
            IntegrateError::LinearSolve { source: SolveError::Unavailable { feature: "faer", .. }, .. }
        ),
        "{err:?}"
    );
}

#[test]
fn fixed_degrees_of_freedom_do_not_move() {
    for kind in IntegratorKind::ALL {
        for linear in [LinearSolverKind::JacobiPcg, LinearSolverKind::GaussSeidel] {
            let mut sys = LinearChain::new(4, 1.0, 50.0, 0.1, 9.81);
            let mut state = sys.rest_state();
            let mut integ = kind.build_with(sys.dof(), NewtonParams::default(), linear);
            advance(integ.as_mut(), &mut sys, &mut state, 0.01, 50).unwrap();
            assert_eq!(state.x[0], 0.0, "{}", kind.label());
            assert_eq!(state.v[0], 0.0, "{}", kind.label());
            assert!(state.x[3] < -0.3 - 1e-3, "{}: the free end must fall, x = {:?}", kind.label(), state.x);
        }
    }
}

#[test]
fn non_finite_state_is_reported_and_the_state_kept() {
    struct Blowup;
    impl SecondOrderSystem for Blowup {
        fn dof(&self) -> usize {
            3
        }
        fn acceleration(&mut self, _t: f64, x: &[f64], _v: &[f64], a: &mut [f64]) {
            a[0] = 0.0;
            a[1] = if x[1] > 1.0 { f64::INFINITY } else { 1.0 };
            a[2] = 0.0;
        }
    }
    let bits = |s: &State| {
        let mut b = vec![s.t.to_bits()];
        b.extend(s.x.iter().chain(&s.v).map(|v| v.to_bits()));
        b
    };
    for kind in IntegratorKind::ALL.into_iter().filter(|k| !k.is_implicit()) {
        // Twice: once stepping straight into the blow-up, once with the state changed by the
        // caller just before it (the multistep methods then restart, rebuilding their history).
        for nudge in [false, true] {
            let mut integ = kind.build_explicit::<Blowup>(3).unwrap();
            let mut state = State::new(vec![0.0, 0.9, 0.0], vec![0.0, 1.0, 0.0]);
            let mut err = None;
            let mut completed = 0u64;
            for _ in 0..100 {
                if nudge && state.x[1] + 0.1 * state.v[1] > 1.0 {
                    state.v[0] += 0.25;
                }
                let before = state.clone();
                #[cfg(feature = "serde")]
                let memory = integ.memory();
                match integ.step(&mut Blowup, &mut state, 0.1) {
                    Ok(_) => completed += 1,
                    Err(e) => {
                        let label = kind.label();
                        assert_eq!(bits(&state), bits(&before), "{label}: state changed on error");
                        #[cfg(feature = "serde")]
                        assert_eq!(integ.memory(), memory, "{label}: memory changed on error");
                        err = Some(e);
                        break;
                    }
                }
            }
            match err {
                Some(IntegrateError::NonFinite(nf)) => {
                    let label = kind.label();
                    assert_eq!(nf.dof, 1, "{label}");
                    assert_eq!(nf.step, completed, "{label}");
                    assert_eq!(nf.origin, "anim-core", "{label}");
                    let msg = nf.to_string();
                    assert!(msg.starts_with(&format!("anim-core: step {completed}: non-finite ")), "{msg}");
                    assert!(msg.contains("degree of freedom 1"), "{msg}");
                }
                other => panic!("{}: expected NonFinite, got {other:?}", kind.label()),
            }
        }
    }
}

#[test]
fn implicit_methods_name_a_non_finite_force() {
    // A chain whose spring force overflows: K = 1e308 times a unit stretch is finite, twice
    // that is not; the implicit methods must name the degree of freedom, not just fail.
    for kind in IntegratorKind::ALL.into_iter().filter(IntegratorKind::is_implicit) {
        let mut sys = LinearChain::new(3, 1.0, 1.5e308, 1.0, 0.0);
        let mut state = sys.rest_state();
        state.x[2] += 2.0;
        let before = state.clone();
        let mut integ = kind.build(sys.dof());
        #[cfg(feature = "serde")]
        let memory = integ.memory();
        let err = integ.step(&mut sys, &mut state, 1e-3).unwrap_err();
        assert_eq!(state, before, "{}", kind.label());
        #[cfg(feature = "serde")]
        assert_eq!(integ.memory(), memory, "{}", kind.label());
        match err {
            IntegrateError::NonFinite(nf) => {
                assert_eq!(nf.step, 0, "{}", kind.label());
                assert_eq!(nf.dof, 1, "{}: {nf}", kind.label());
                assert!(nf.to_string().starts_with("anim-core: step 0: non-finite"), "{nf}");
            }
            other => panic!("{}: expected NonFinite, got {other}", kind.label()),
        }
    }
}

#[test]
fn bad_inputs_are_errors() {
    let mut sys = HarmonicOscillator::new(1.0, 1.0);
    let mut integ = IntegratorKind::Rk4.build(1);
    let mut state = State::new(vec![1.0], vec![0.0]);
    for dt in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        assert!(matches!(integ.step(&mut sys, &mut state, dt), Err(IntegrateError::BadTimeStep { .. })));
    }
    let mut wrong = State::new(vec![1.0, 2.0], vec![0.0, 0.0]);
    assert!(matches!(integ.step(&mut sys, &mut wrong, 0.1), Err(IntegrateError::DimensionMismatch { .. })));
    assert!(IntegratorKind::BetaBlend { beta: 1.5 }.validate().is_err());
    assert!(IntegratorKind::BetaBlend { beta: 0.5 }.validate().is_ok());
}

#[test]
fn multistep_methods_restart_after_an_outside_change() {
    for kind in [IntegratorKind::PositionVerlet, IntegratorKind::Leapfrog, IntegratorKind::VelocityVerlet] {
        let mut sys = HarmonicOscillator::new(1.0, 4.0);
        let mut state = State::new(vec![1.0], vec![0.0]);
        let mut integ = kind.build(1);
        advance(integ.as_mut(), &mut sys, &mut state, 0.01, 10).unwrap();
        // Teleport: the next step must equal a fresh integrator's first step from here.
        state.x[0] = -0.5;
        state.v[0] = 2.0;
        let mut fresh_state = state.clone();
        integ.step(&mut sys, &mut state, 0.01).unwrap();
        let mut fresh = kind.build(1);
        fresh.step(&mut sys, &mut fresh_state, 0.01).unwrap();
        assert_eq!(state, fresh_state, "{}", kind.label());
    }
}

#[test]
fn explicit_integrators_are_exact_on_constant_acceleration() {
    // x'' = g: Verlet, leapfrog, velocity Verlet, midpoint and RK4 are exact; Euler is not.
    struct Fall;
    impl SecondOrderSystem for Fall {
        fn dof(&self) -> usize {
            1
        }
        fn acceleration(&mut self, _t: f64, _x: &[f64], _v: &[f64], a: &mut [f64]) {
            a[0] = -9.81;
        }
    }
    for kind in [
        IntegratorKind::PositionVerlet,
        IntegratorKind::Leapfrog,
        IntegratorKind::VelocityVerlet,
        IntegratorKind::Rk4,
    ] {
        let mut integ = kind.build_explicit::<Fall>(1).unwrap();
        let mut state = State::new(vec![2.0], vec![1.5]);
        advance(integ.as_mut(), &mut Fall, &mut state, 0.1, 10).unwrap();
        let x = 2.0 + 1.5 - 0.5 * 9.81;
        let v = 1.5 - 9.81;
        assert!(
            (state.x[0] - x).abs() < 1e-12 && (state.v[0] - v).abs() < 1e-12,
            "{}: {state:?}",
            kind.label()
        );
    }
}

#[test]
fn damped_oscillator_reference_matches_its_ode() {
    for c in [0.5, 4.0, 9.0] {
        // m = 1, k = 4: critical damping at c = 4.
        let sys = HarmonicOscillator::damped(1.0, 4.0, c);
        for k in 1..20 {
            let t = 0.13 * k as f64;
            let h = 1e-5;
            let (x, v) = sys.exact(0.8, -0.3, t);
            let (xp, vp) = sys.exact(0.8, -0.3, t + h);
            let (xm, vm) = sys.exact(0.8, -0.3, t - h);
            assert!(((xp - xm) / (2.0 * h) - v).abs() < 1e-8);
            let acc = (vp - vm) / (2.0 * h);
            assert!((acc - (-4.0 * x - c * v)).abs() < 1e-7, "c = {c}, t = {t}");
        }
    }
}

#[test]
fn damped_oscillator_converges_with_implicit_methods() {
    // Exercises the damping Jacobian D in the Newton matrix.
    let sys0 = HarmonicOscillator::damped(1.0, 4.0, 0.8);
    for (kind, order) in [(IntegratorKind::BackwardEuler, 1.0), (IntegratorKind::ImplicitMidpoint, 2.0)] {
        let mut dts = Vec::new();
        let mut errs = Vec::new();
        for n in [200usize, 400, 800, 1600] {
            let mut sys = sys0;
            let mut state = State::new(vec![1.0], vec![0.0]);
            let mut integ =
                kind.build_with(1, NewtonParams::with_tolerance(1e-13), LinearSolverKind::JacobiPcg);
            let dt = 5.0 / n as f64;
            advance(integ.as_mut(), &mut sys, &mut state, dt, n).unwrap();
            let (xe, _) = sys.exact(1.0, 0.0, 5.0);
            dts.push(dt);
            errs.push((state.x[0] - xe).abs());
        }
        let measured = fit_order(&dts, &errs);
        assert!((measured - order).abs() < 0.15, "{}: {measured}", kind.label());
    }
}

#[test]
#[cfg(feature = "faer")]
fn chain_settles_to_its_analytic_equilibrium_under_backward_euler() {
    // Backward Euler dissipates: a damped chain run long enough rests at the static solution.
    let mut sys = LinearChain::new(10, 0.2, 400.0, 0.1, 9.81).with_damping(2.0);
    let mut state = sys.rest_state();
    let mut integ =
        IntegratorKind::BackwardEuler.build_with(10, NewtonParams::default(), LinearSolverKind::Cholesky);
    advance(integ.as_mut(), &mut sys, &mut state, 0.05, 4000).unwrap();
    let eq = sys.equilibrium();
    for i in 0..10 {
        assert!((state.x[i] - eq[i]).abs() < 1e-9, "mass {i}: {} vs {}", state.x[i], eq[i]);
    }
    // The bottom spring carries one weight: stretch m g / k.
    assert!(((eq[8] - eq[9]) - (0.1 + 0.2 * 9.81 / 400.0)).abs() < 1e-15);
}

#[test]
fn chain_jacobian_matches_finite_differences_and_its_assembly() {
    let mut sys = LinearChain::new(5, 1.0, 30.0, 0.1, 9.81).with_damping(0.7);
    let x: Vec<f64> = (0..5).map(|i| -0.11 * i as f64 + 0.01 * (i * i) as f64).collect();
    let v: Vec<f64> = (0..5).map(|i| 0.3 - 0.1 * i as f64).collect();
    sys.linearize(0.0, &x, &v);
    let mut assembled = crate::linalg::CsrMatrix::default();
    assert!(sys.jacobian_assemble(1.0, 0.0, &mut assembled));
    let h = 1e-6;
    for j in 0..5 {
        let mut e = vec![0.0; 5];
        e[j] = 1.0;
        let mut jk = vec![0.0; 5];
        sys.jacobian_apply(1.0, 0.0, &e, &mut jk);
        let (mut xp, mut xm) = (x.clone(), x.clone());
        xp[j] += h;
        xm[j] -= h;
        let (mut fp, mut fm) = (vec![0.0; 5], vec![0.0; 5]);
        sys.force(0.0, &xp, &v, &mut fp);
        sys.force(0.0, &xm, &v, &mut fm);
        for i in 0..5 {
            let fd = (fp[i] - fm[i]) / (2.0 * h);
            assert!((fd - jk[i]).abs() < 1e-6, "K[{i}][{j}]: fd {fd}, apply {}", jk[i]);
            assert!((assembled.get(i, j).unwrap_or(0.0) - jk[i]).abs() < 1e-15);
        }
        // Damping Jacobian by finite differences in v.
        let mut jd = vec![0.0; 5];
        sys.jacobian_apply(0.0, 1.0, &e, &mut jd);
        let (mut vp, mut vm) = (v.clone(), v.clone());
        vp[j] += h;
        vm[j] -= h;
        sys.force(0.0, &x, &vp, &mut fp);
        sys.force(0.0, &x, &vm, &mut fm);
        for i in 0..5 {
            assert!(((fp[i] - fm[i]) / (2.0 * h) - jd[i]).abs() < 1e-6);
        }
    }
}

#[test]
fn large_systems_take_the_parallel_path_with_identical_results_for_any_thread_count() {
    // 40 000 degrees of freedom: above the threshold of the chunked parallel update loops.
    let run = |threads: usize, kind: IntegratorKind| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| {
            let mut sys = LinearChain::new(40_000, 0.01, 100.0, 0.01, 9.81);
            let mut state = sys.rest_state();
            for (i, v) in state.v.iter_mut().enumerate() {
                *v = ((i % 13) as f64 - 6.0) * 1e-3;
            }
            let mut integ = kind.build(40_000);
            advance(integ.as_mut(), &mut sys, &mut state, 1e-3, 20).unwrap();
            state
        })
    };
    for kind in
        [IntegratorKind::ExplicitEuler, IntegratorKind::SymplecticEuler, IntegratorKind::VelocityVerlet]
    {
        let one = run(1, kind);
        let four = run(4, kind);
        assert!(one.x.iter().zip(&four.x).all(|(a, b)| a.to_bits() == b.to_bits()), "{}", kind.label());
        assert!(one.v.iter().zip(&four.v).all(|(a, b)| a.to_bits() == b.to_bits()), "{}", kind.label());
        assert!(one.x[39_999] < -399.99, "{}: the chain must have sagged", kind.label());
    }
}

#[test]
fn line_search_rescues_newton_on_a_saturating_spring() {
    // A saturating spring x'' = -100 atan(x), one backward-Euler step of h = 1 from x0 = 3:
    // Newton on an arctangent overshoots further each iteration (the classic divergent case);
    // with backtracking on ||g|| it converges, and the answer satisfies the backward-Euler
    // equation v1 = v0 + h a(x0 + h v1).
    struct Duffing {
        k: f64,
    }
    impl SecondOrderSystem for Duffing {
        fn dof(&self) -> usize {
            1
        }
        fn acceleration(&mut self, _t: f64, x: &[f64], _v: &[f64], a: &mut [f64]) {
            a[0] = -100.0 * x[0].atan();
        }
    }
    impl MechanicalSystem for Duffing {
        fn inverse_mass(&self, w: &mut [f64]) {
            w[0] = 1.0;
        }
        fn force(&mut self, t: f64, x: &[f64], v: &[f64], f: &mut [f64]) {
            self.acceleration(t, x, v, f);
        }
        fn linearize(&mut self, _t: f64, x: &[f64], _v: &[f64]) {
            self.k = -100.0 / (1.0 + x[0] * x[0]);
        }
        fn jacobian_apply(&self, c_x: f64, _c_v: f64, dx: &[f64], out: &mut [f64]) {
            out[0] = c_x * self.k * dx[0];
        }
    }
    let mut report = Vec::new();
    for line_search in [false, true] {
        let mut params = NewtonParams::with_tolerance(1e-12);
        params.line_search = line_search;
        let mut integ = BetaBlend::new(1.0, params, LinearSolverKind::Cg.build(params.linear), 1);
        let mut sys = Duffing { k: 0.0 };
        let mut state = State::new(vec![3.0], vec![0.0]);
        let (x0, v0, h) = (state.x[0], state.v[0], 1.0);
        let result = Integrator::<Duffing>::step(&mut integ, &mut sys, &mut state, h);
        report.push((line_search, result.clone().map(|i| i.newton_iterations)));
        if !line_search {
            assert!(result.is_err(), "plain Newton was expected to fail here: {result:?}");
        } else {
            let info = result.unwrap();
            let mut a = [0.0];
            sys.acceleration(0.0, &[x0 + h * state.v[0]], &[0.0], &mut a);
            assert!((state.v[0] - (v0 + h * a[0])).abs() < 1e-9 * (1.0 + state.v[0].abs()), "{info:?}");
        }
    }
    println!("atan spring, h = 1, x0 = 3: {report:?}");
}

#[cfg(feature = "serde")]
#[test]
fn a_run_resumed_from_saved_memory_and_state_is_bitwise_identical() {
    // A damped, nonlinear-free chain with a non-trivial initial velocity; each method runs 7
    // steps, saves its memory and the state through JSON text (as a checkpoint file does), and a
    // fresh integrator continues 9 more steps from them.
    let setup = || {
        let sys = LinearChain::new(12, 0.02, 80.0, 0.05, 9.81);
        let mut state = sys.rest_state();
        for (i, v) in state.v.iter_mut().enumerate() {
            *v = ((i % 5) as f64 - 2.0) * 0.1;
        }
        (sys, state)
    };
    let dt = 2e-3;
    for kind in IntegratorKind::ALL {
        let (mut sys, mut state) = setup();
        let mut integ = kind.build(sys.dof());
        advance(integ.as_mut(), &mut sys, &mut state, dt, 7).unwrap();
        let saved_state = serde_json::to_string(&state).unwrap();
        let saved_memory = serde_json::to_string(&integ.memory()).unwrap();
        advance(integ.as_mut(), &mut sys, &mut state, dt, 9).unwrap();

        let (mut sys2, _) = setup();
        let mut resumed: State = serde_json::from_str(&saved_state).unwrap();
        let mut integ2 = kind.build(sys2.dof());
        integ2.restore_memory(&serde_json::from_str(&saved_memory).unwrap()).unwrap();
        advance(integ2.as_mut(), &mut sys2, &mut resumed, dt, 9).unwrap();
        let same = |a: &[f64], b: &[f64]| a.iter().zip(b).all(|(p, q)| p.to_bits() == q.to_bits());
        assert!(same(&state.x, &resumed.x) && same(&state.v, &resumed.v), "{}", kind.label());
        assert_eq!(state.t.to_bits(), resumed.t.to_bits(), "{}", kind.label());
        assert_eq!(integ.memory(), integ2.memory(), "{}", kind.label());
    }
    // A memory of another method is refused with the method named.
    let verlet = IntegratorKind::PositionVerlet.build::<LinearChain>(36);
    let err = IntegratorKind::Leapfrog.build::<LinearChain>(36).restore_memory(&verlet.memory()).unwrap_err();
    assert!(err.to_string().contains("leapfrog") && err.to_string().contains("position-verlet"), "{err}");
    let euler = IntegratorKind::ExplicitEuler.build::<LinearChain>(36);
    assert!(
        IntegratorKind::SymplecticEuler.build::<LinearChain>(36).restore_memory(&euler.memory()).is_err()
    );
}
