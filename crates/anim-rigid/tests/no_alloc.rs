//! The architecture invariant "no solver allocates inside `step`" and "no algorithm allocates":
//! after a first call, RNEA, the bias and gravity terms, both forms of CRBA, both forms of ABA, the Cholesky
//! forward dynamics, the energies and momentum, and a simulation step with every stepper (torques,
//! damping and limits on) perform no heap allocation. Counted by a wrapping global allocator, so
//! this file is its own test binary.

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use anim_core::alloc_count::CountingAllocator;

use anim_core::solver::Solver;
use anim_rigid::config::neutral;
use anim_rigid::scenes;
use anim_rigid::sim::{RigidIntegrator, RigidSimulation, SimParams};
use anim_rigid::{
    Data, aba, aba_local, aba_world, crba, crba_local, crba_world, forward_dynamics_cholesky,
    gravity_torques, kinetic_energy, nonlinear_effects, potential_energy, rnea, spatial_momentum,
};

#[global_allocator]
static ALLOC: CountingAllocator = CountingAllocator::new();

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

#[test]
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
