//! The steppers of `anim_rigid::sim`: orders of accuracy measured, agreement with anim-core's
//! integrators on Euclidean trees, conservation laws of the free body, the Dzhanibekov flip and
//! its period, energy balance with torques and damping, joint limits, failure handling.

#![allow(clippy::unwrap_used, clippy::expect_used)] // integration tests: a failed unwrap is a failed test

mod common;

use anim_core::glam::DVec3;
use anim_core::integrate::{IntegratorKind, State};
use anim_core::lie::Se3;
use anim_core::solver::Solver;
use anim_rigid::scenes::{self, euler_top_period, pendulum_chain_model, t_handle_model};
use anim_rigid::sim::{ArticulatedSystem, RigidIntegrator, RigidSimulation, RigidState, SimError, SimParams};
use anim_rigid::{
    Axis, Data, Inertia, JointLimits, JointType, Model, ModelBuilder, config, spatial_momentum,
};

fn run(sim: &mut RigidSimulation, state: &mut RigidState, dt: f64, steps: usize) {
    for _ in 0..steps {
        sim.step(state, dt).unwrap();
    }
}

fn spinning_body(integrator: RigidIntegrator) -> (RigidSimulation, RigidState) {
    let scene = scenes::t_handle().unwrap();
    let sim = RigidSimulation::new(scene.model, scene.params, integrator).unwrap();
    let state = sim.initial_state(scene.state.q, scene.state.v).unwrap();
    (sim, state)
}

/// Distance between two states of the same model: configuration difference on the manifold and
/// velocity difference.
fn state_distance(model: &Model, a: &RigidState, b: &RigidState) -> f64 {
    let d = config::difference(model, &a.q, &b.q);
    let dv = a.v.iter().zip(&b.v).fold(0.0_f64, |m, (x, y)| m.max((x - y).abs()));
    d.iter().fold(dv, |m, x| m.max(x.abs()))
}

/// Measured order: log2 of the error ratio between steps h and h/2, against a reference at h/64.
fn measured_order(
    integrator: RigidIntegrator,
    make: &dyn Fn(RigidIntegrator) -> (RigidSimulation, RigidState),
    t_end: f64,
    h: f64,
) -> f64 {
    let solve = |integrator, dt: f64| {
        let (mut sim, mut state) = make(integrator);
        run(&mut sim, &mut state, dt, (t_end / dt).round() as usize);
        (sim.model().clone(), state)
    };
    let (model, reference) = solve(RigidIntegrator::Rk4, h / 64.0);
    let (_, coarse) = solve(integrator, h);
    let (_, fine) = solve(integrator, h / 2.0);
    let (e1, e2) = (state_distance(&model, &coarse, &reference), state_distance(&model, &fine, &reference));
    eprintln!("{}: errors {e1:.3e} (h), {e2:.3e} (h/2)", integrator.label());
    (e1 / e2).log2()
}

#[test]
fn steppers_reach_their_order_on_a_spinning_body_and_a_chain() {
    let chain = |integrator| {
        let model = pendulum_chain_model(&[0.3, 0.2, 0.25, 0.1], 0.2).unwrap();
        let sim = RigidSimulation::new(model, SimParams::default(), integrator).unwrap();
        let state = sim.initial_state(vec![0.2, -0.4, 0.3, 0.5], vec![0.5, 0.0, -1.0, 0.3]).unwrap();
        (sim, state)
    };
    for (integrator, order) in [
        (RigidIntegrator::ExplicitEuler, 1.0),
        (RigidIntegrator::SymplecticEuler, 1.0),
        (RigidIntegrator::ImplicitMidpoint, 2.0),
        (RigidIntegrator::Rk4, 4.0),
    ] {
        let p = measured_order(integrator, &spinning_body, 0.5, 0.01);
        assert!((p - order).abs() < 0.25, "{} on the free body: order {p:.2}", integrator.label());
        let p = measured_order(integrator, &chain, 0.5, 2e-3);
        assert!((p - order).abs() < 0.25, "{} on the chain: order {p:.2}", integrator.label());
    }
    let p = measured_order(RigidIntegrator::FreeBodyMidpoint, &spinning_body, 0.5, 0.01);
    assert!((p - 2.0).abs() < 0.25, "free-body midpoint: order {p:.2}");
}

#[test]
fn lie_steppers_reduce_to_anim_core_integrators_on_euclidean_trees() {
    let model = common::ur5();
    let q0 = vec![0.3, -1.0, 1.2, 0.5, 0.8, 0.1];
    let v0 = vec![0.5, -0.2, 0.1, 1.0, -0.7, 0.3];
    for (ours, theirs) in [
        (RigidIntegrator::SymplecticEuler, IntegratorKind::SymplecticEuler),
        (RigidIntegrator::Rk4, IntegratorKind::Rk4),
    ] {
        let mut sim = RigidSimulation::new(model.clone(), SimParams::default(), ours).unwrap();
        let mut state = sim.initial_state(q0.clone(), v0.clone()).unwrap();
        let mut system = ArticulatedSystem::new(model.clone(), SimParams::default()).unwrap();
        let mut core_state = State::new(q0.clone(), v0.clone());
        let mut integrator = theirs.build_explicit::<ArticulatedSystem>(model.nv()).unwrap();
        for _ in 0..200 {
            sim.step(&mut state, 1e-3).unwrap();
            integrator.step(&mut system, &mut core_state, 1e-3).unwrap();
        }
        let dq = state.q.iter().zip(&core_state.x).fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
        let dv = state.v.iter().zip(&core_state.v).fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
        eprintln!("{}: |q - q_core| {dq:.1e}, |v - v_core| {dv:.1e}", ours.label());
        assert!(dq < 1e-12 && dv < 1e-11, "{}: {dq:e} {dv:e}", ours.label());
    }
}

fn invariants(sim: &mut RigidSimulation, state: &RigidState) -> (f64, DVec3) {
    let e = sim.energy(state);
    let h = sim.system_mut().momentum_of(&state.q, &state.v);
    (e, h.angular)
}

#[test]
fn free_body_midpoint_conserves_energy_and_angular_momentum() {
    let (mut sim, mut state) = spinning_body(RigidIntegrator::FreeBodyMidpoint);
    let (e0, l0) = invariants(&mut sim, &state);
    let (mut de, mut dl) = (0.0_f64, 0.0_f64);
    for _ in 0..20 {
        run(&mut sim, &mut state, 1e-3, 500);
        let (e, l) = invariants(&mut sim, &state);
        de = de.max((e - e0).abs() / e0);
        dl = dl.max((l - l0).length() / l0.length());
    }
    eprintln!("free-body midpoint, 1e4 steps: energy drift {de:.2e}, angular momentum drift {dl:.2e}");
    // Exact in exact arithmetic: what remains is rounding, below 1e-15 per step (the measured
    // drift grows linearly by about 7e-17 per step: Newton stops at the rounding floor).
    assert!(de < 1e4 * 1e-15 && dl < 1e4 * 1e-15, "{de:e} {dl:e}");
}

#[test]
fn t_handle_flips_with_the_period_of_euler_s_top() {
    let (model, moments) = t_handle_model().unwrap();
    let scene = scenes::t_handle().unwrap();
    let w0 = DVec3::new(scene.state.v[3], scene.state.v[4], scene.state.v[5]);
    let axis = (0..3).max_by(|&a, &b| w0[a].abs().total_cmp(&w0[b].abs())).unwrap();
    let period = euler_top_period(moments, w0).unwrap();
    let (mut sim, mut state) = spinning_body(RigidIntegrator::FreeBodyMidpoint);
    assert_eq!(sim.model().nv(), model.nv());
    // Times at which the spin component along the intermediate axis crosses zero downwards.
    let dt = 1e-3;
    let mut crossings = Vec::new();
    let mut prev = state.v[3 + axis];
    let mut min_component = f64::INFINITY;
    while state.t < 3.0 * period {
        sim.step(&mut state, dt).unwrap();
        let w = state.v[3 + axis];
        min_component = min_component.min(w);
        if prev > 0.0 && w <= 0.0 {
            crossings.push(state.t - dt * w / (w - prev));
        }
        prev = w;
    }
    eprintln!(
        "T-handle: analytic period {period:.6} s, downward crossings at {crossings:?}, min spin {min_component:.3}"
    );
    assert!(min_component < -9.9, "the spin axis flips over: {min_component}");
    assert!(crossings.len() >= 2);
    let measured = crossings[crossings.len() - 1] - crossings[crossings.len() - 2];
    assert!((measured - period).abs() < 1e-3 * period, "period {measured} vs {period}");
}

#[test]
fn energy_changes_by_the_work_of_torques_damping_and_limits() {
    // A UR5 with torques, damping and a limit it runs into: E(T) - E(0) = ∫ power dt.
    let mut model = common::ur5();
    let lower = model.joint(2).limits.lower;
    assert!(lower.is_finite());
    let params = SimParams::default()
        .with_damping(0.3)
        .with_torque(vec![2.0, -5.0, 1.0, 0.5, -0.2, 0.1])
        .with_limits(2000.0, 3.0);
    model.set_gravity(DVec3::new(0.0, 0.0, -9.81));
    let mut sim = RigidSimulation::new(model, params, RigidIntegrator::Rk4).unwrap();
    // Start near the lower limit of joint 2, moving into it.
    let mut state = sim
        .initial_state(vec![0.0, lower + 0.05, 0.5, 0.0, 0.3, 0.0], vec![0.0, -1.5, 0.0, 0.0, 0.0, 0.0])
        .unwrap();
    let dt = 1e-4;
    let e0 = sim.energy(&state);
    let mut work = 0.0;
    let mut p_prev = sim.system().power(&state.q, &state.v);
    let mut deepest = 0.0_f64;
    for _ in 0..5000 {
        sim.step(&mut state, dt).unwrap();
        let p = sim.system().power(&state.q, &state.v);
        work += 0.5 * dt * (p + p_prev);
        p_prev = p;
        deepest = deepest.min(state.q[1] - lower);
    }
    let e1 = sim.energy(&state);
    eprintln!("UR5: E1 - E0 = {:.6e}, work = {work:.6e}, deepest limit penetration {deepest:.2e}", e1 - e0);
    assert!(deepest < 0.0, "the joint reached its limit");
    assert!(((e1 - e0) - work).abs() < 1e-4 * work.abs().max(1.0), "{} vs {work}", e1 - e0);
}

#[test]
fn a_torque_against_a_limit_settles_at_the_penalty_deflection() {
    // One hinge, no gravity, a constant torque of 10 N·m pushing it past its upper limit of
    // 0.5 rad: the penalty k = 1000 balances it at δ = τ/k = 0.01 rad.
    let mut b = ModelBuilder::new("hinge");
    b.gravity(DVec3::ZERO).unwrap();
    let j = b
        .add_joint(0, "hinge", JointType::Revolute(Axis::Z), Se3::IDENTITY, JointLimits::position(-0.5, 0.5))
        .unwrap();
    b.append_body(
        j,
        &Inertia::new(1.0, DVec3::X * 0.3, anim_core::glam::DMat3::IDENTITY * 0.01),
        &Se3::IDENTITY,
    )
    .unwrap();
    let model = b.build();
    let params = SimParams::default().with_torque(vec![10.0]).with_limits(1000.0, 20.0).with_damping(0.5);
    let mut sim = RigidSimulation::new(model, params, RigidIntegrator::ImplicitMidpoint).unwrap();
    let mut state = sim.initial_state(vec![0.0], vec![0.0]).unwrap();
    run(&mut sim, &mut state, 1e-3, 5000);
    eprintln!("hinge at rest at q = {:.8}, v = {:.2e}", state.q[0], state.v[0]);
    assert!((state.q[0] - 0.51).abs() < 1e-6, "{}", state.q[0]);
    assert!(state.v[0].abs() < 1e-6);
}

#[test]
fn a_failed_step_leaves_the_state_unchanged() {
    // A massless leaf body makes ABA divide by zero: the step reports a non-finite value.
    let mut b = ModelBuilder::new("bad");
    let j = b.add_joint(0, "a", JointType::Revolute(Axis::Y), Se3::IDENTITY, JointLimits::UNBOUNDED).unwrap();
    b.append_body(j, &Inertia::new(1.0, DVec3::X, anim_core::glam::DMat3::IDENTITY), &Se3::IDENTITY).unwrap();
    b.add_joint(
        j,
        "b",
        JointType::Revolute(Axis::Y),
        Se3::from_translation(DVec3::X),
        JointLimits::UNBOUNDED,
    )
    .unwrap();
    let model = b.build();
    let mut sim =
        RigidSimulation::new(model, SimParams::default(), RigidIntegrator::SymplecticEuler).unwrap();
    let mut state = sim.initial_state(vec![0.1, 0.2], vec![0.0, 0.0]).unwrap();
    let before = state.clone();
    let err = sim.step(&mut state, 1e-3).unwrap_err();
    assert!(matches!(err, SimError::NonFinite(_)), "{err}");
    assert_eq!(state, before);
    assert!(matches!(sim.step(&mut state, -1.0), Err(SimError::BadTimeStep { .. })));
    assert!(matches!(
        sim.step(&mut RigidState::new(vec![0.0], vec![0.0]), 1e-3),
        Err(SimError::StateMismatch { .. })
    ));
    assert_eq!(state, before);
}

#[test]
fn bad_parameters_and_unsupported_models_are_rejected() {
    let model = common::ur5();
    let bad = SimParams::default().with_damping(-1.0);
    assert!(matches!(
        RigidSimulation::new(model.clone(), bad, RigidIntegrator::Rk4),
        Err(SimError::BadParameter { .. })
    ));
    let bad = SimParams::default().with_torque(vec![1.0; 3]);
    assert!(matches!(
        RigidSimulation::new(model.clone(), bad, RigidIntegrator::Rk4),
        Err(SimError::BadParameter { .. })
    ));
    assert!(matches!(
        RigidSimulation::new(model.clone(), SimParams::default(), RigidIntegrator::FreeBodyMidpoint),
        Err(SimError::Unsupported { .. })
    ));
    let sim = RigidSimulation::new(model, SimParams::default(), RigidIntegrator::Rk4).unwrap();
    assert!(sim.initial_state(vec![f64::NAN; 6], vec![0.0; 6]).is_err());
    let (free, _) = t_handle_model().unwrap();
    let sim = RigidSimulation::new(free, SimParams::default(), RigidIntegrator::Rk4).unwrap();
    assert!(sim.initial_state(vec![0.0; 7], vec![0.0; 6]).is_err(), "zero quaternion");
}

#[test]
fn floating_chain_steppers_conserve_momentum_without_gravity() {
    // The mixed tree (free base, spherical, prismatic, revolute joints) floating without gravity
    // and without torques: every stepper conserves linear momentum exactly in the limit; the
    // second- and fourth-order ones to their truncation error.
    let mut model = common::mixed_massive();
    model.set_gravity(DVec3::ZERO);
    let params = SimParams::default().with_limits(0.0, 0.0);
    for integrator in [RigidIntegrator::Rk4, RigidIntegrator::ImplicitMidpoint] {
        let mut sim = RigidSimulation::new(model.clone(), params.clone(), integrator).unwrap();
        let mut q = config::neutral(&model);
        q[0] = 0.2;
        let mut v = vec![0.0; model.nv()];
        for (k, x) in v.iter_mut().enumerate() {
            *x = 0.3 * ((k as f64) * 1.7).sin();
        }
        let mut state = sim.initial_state(q, v).unwrap();
        let mut data = Data::new(&model);
        let h0 = spatial_momentum(&model, &mut data, &state.q, &state.v);
        let e0 = sim.energy(&state);
        run(&mut sim, &mut state, 1e-3, 1000);
        let h1 = spatial_momentum(&model, &mut data, &state.q, &state.v);
        let e1 = sim.energy(&state);
        let dh = (h1 - h0).linear.length().max((h1 - h0).angular.length())
            / h0.angular.length().max(h0.linear.length());
        eprintln!(
            "mixed tree, {}: momentum drift {dh:.2e}, energy drift {:.2e}",
            integrator.label(),
            (e1 - e0).abs() / e0
        );
        assert!(dh < 1e-6, "{}: {dh:e}", integrator.label());
        assert!((e1 - e0).abs() < 1e-5 * e0, "{}", integrator.label());
    }
}
