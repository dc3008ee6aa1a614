//! The architecture invariant "no solver allocates inside `step`" and "no algorithm allocates":
//! after a first call, RNEA, the bias and gravity terms, both forms of CRBA, both forms of ABA, the Cholesky
//! forward dynamics, the energies and momentum, and a simulation step with every stepper (torques,
//! damping and limits on) perform no heap allocation; the same, with kinematics and Jacobians,
//! for a model with coupled (mimic) joints. Counted by a wrapping global allocator, so
//! this file is its own test binary.

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use anim_core::alloc_count::CountingAllocator;

use anim_core::solver::Solver;
use anim_rigid::config::neutral;
use anim_rigid::scenes;
use anim_rigid::sim::{RigidIntegrator, RigidSimulation, SimParams};
use anim_rigid::{
    Data, Jacobian, ReferenceFrame, UrdfOptions, aba, aba_local, aba_world, compute_joint_jacobians,
    compute_joint_jacobians_time_variation, crba, crba_local, crba_world, forward_dynamics,
    forward_dynamics_cholesky, forward_kinematics, frame_jacobian, frame_jacobian_time_variation,
    gravity_torques, joint_jacobian, kinetic_energy, nonlinear_effects, parse_urdf, potential_energy, rnea,
    spatial_momentum,
};

#[global_allocator]
static ALLOC: CountingAllocator = CountingAllocator::new();

/// The counter sees every thread, the test harness's included (it allocates when it reports a
/// test's end), so this file has a single test running the two parts one after the other.
#[test]
fn nothing_allocates_after_the_first_call() {
    algorithms_and_steps_do_not_allocate();
    coupled_models_do_not_allocate();
}

/// Allocations in five calls of `f` after a first one. The counter sees every thread of the
/// process, the test harness's included, which can allocate at any time under load; code that
/// allocates does so in every block, so up to three blocks of five calls are counted and the
/// first clean one ends the count (0), else the last block's count is returned.
fn counted(mut f: impl FnMut()) -> usize {
    f();
    let mut n = 0;
    for _ in 0..3 {
        n = ALLOC.count(|| {
            for _ in 0..5 {
                f();
            }
        });
        if n == 0 {
            break;
        }
    }
    n
}

fn algorithms_and_steps_do_not_allocate() {
    for model in [common::panda(), common::mixed_massive(), common::chain32()] {
        let mut data = Data::new(&model);
        let q = neutral(&model);
        let v: Vec<f64> = (0..model.nv()).map(|k| 0.1 * k as f64).collect();
        let a = v.clone();
        let n = counted(|| {
            let _ = rnea(&model, &mut data, &q, &v, &a);
            let _ = nonlinear_effects(&model, &mut data, &q, &v);
            let _ = gravity_torques(&model, &mut data, &q);
            let _ = crba(&model, &mut data, &q);
            let _ = crba_local(&model, &mut data, &q);
            let _ = crba_world(&model, &mut data, &q);
            let _ = aba(&model, &mut data, &q, &v, &a);
            let _ = aba_local(&model, &mut data, &q, &v, &a);
            let _ = aba_world(&model, &mut data, &q, &v, &a);
            let _ = forward_dynamics_cholesky(&model, &mut data, &q, &v, &a).unwrap();
            let _ = forward_dynamics(&model, &mut data, &q, &v, &a);
            let _ = kinetic_energy(&model, &mut data, &q, &v) + potential_energy(&model, &mut data, &q);
            let _ = spatial_momentum(&model, &mut data, &q, &v);
        });
        assert_eq!(n, 0, "{}: {n} allocations in the dynamics algorithms", model.name());
        for integrator in RigidIntegrator::ALL {
            if integrator == RigidIntegrator::FreeBodyMidpoint {
                continue;
            }
            let params = SimParams::default().with_damping(0.1).with_torque(vec![0.5; model.nv()]);
            let mut sim = RigidSimulation::new(model.clone(), params, integrator).unwrap();
            let mut state = sim.initial_state(q.clone(), v.clone()).unwrap();
            let n = counted(|| {
                sim.step(&mut state, 1e-3).unwrap();
            });
            assert_eq!(n, 0, "{} / {}: {n} allocations in 5 steps", model.name(), integrator.label());
        }
    }
    let scene = scenes::t_handle().unwrap();
    let (mut sim, mut state) = scene.into_simulation().unwrap();
    let n = counted(|| {
        sim.step(&mut state, 1e-3).unwrap();
    });
    assert_eq!(n, 0, "free-body midpoint: {n} allocations in 5 steps");
}

fn coupled_models_do_not_allocate() {
    use std::io::Read;
    let path = common::testdata("robots/pr2_description/urdf/pr2.urdf.gz");
    let mut text = String::new();
    flate2::read::GzDecoder::new(std::fs::File::open(path).unwrap()).read_to_string(&mut text).unwrap();
    let model = parse_urdf(&text, &UrdfOptions::default().couple_mimic_joints(true)).unwrap();
    assert!(!model.mimic_joints().is_empty());
    let mut data = Data::new(&model);
    let q: Vec<f64> = (0..model.nq()).map(|k| 0.1 * (k as f64).sin()).collect();
    let v: Vec<f64> = (0..model.nv()).map(|k| 0.1 * k as f64).collect();
    let frame = model.frame_id("r_gripper_r_finger_tip_link").unwrap();
    let joint = model.frame(frame).parent_joint;
    let mut out = Jacobian::zeros(model.nv());
    let n = counted(|| {
        forward_kinematics(&model, &mut data, &q);
        compute_joint_jacobians(&model, &mut data, &q);
        joint_jacobian(&model, &data, joint, ReferenceFrame::World, &mut out);
        frame_jacobian(&model, &data, frame, ReferenceFrame::Local, &mut out);
        compute_joint_jacobians_time_variation(&model, &mut data, &q, &v);
        frame_jacobian_time_variation(&model, &data, frame, ReferenceFrame::LocalWorldAligned, &mut out);
        let _ = rnea(&model, &mut data, &q, &v, &v);
        let _ = nonlinear_effects(&model, &mut data, &q, &v);
        let _ = gravity_torques(&model, &mut data, &q);
        let _ = crba(&model, &mut data, &q);
        let _ = forward_dynamics_cholesky(&model, &mut data, &q, &v, &v).unwrap();
        let _ = kinetic_energy(&model, &mut data, &q, &v) + potential_energy(&model, &mut data, &q);
        let _ = spatial_momentum(&model, &mut data, &q, &v);
    });
    assert_eq!(n, 0, "coupled PR2: {n} allocations in the algorithms");
    for integrator in RigidIntegrator::ALL {
        if integrator == RigidIntegrator::FreeBodyMidpoint {
            continue;
        }
        let params = SimParams::default().with_damping(0.1).with_torque(vec![0.5; model.nv()]);
        let mut sim = RigidSimulation::new(model.clone(), params, integrator).unwrap();
        let mut state = sim.initial_state(q.clone(), v.clone()).unwrap();
        let n = counted(|| {
            sim.step(&mut state, 1e-4).unwrap();
        });
        assert_eq!(n, 0, "coupled PR2 / {}: {n} allocations in 5 steps", integrator.label());
    }
}
