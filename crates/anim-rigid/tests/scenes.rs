//! The built-in scenes run their whole duration with their own stepper: finite, energy reported
//! every step and kept where nothing dissipates, momentum of the free T-handle kept, the segments
//! to draw have finite end points.

#![allow(clippy::unwrap_used, clippy::expect_used)] // integration tests: a failed unwrap is a failed test

use anim_core::solver::Solver;
use anim_rigid::scenes::{self, NAMES};

#[test]
fn every_scene_runs_its_duration() {
    for name in NAMES {
        let scene = scenes::by_name(name).unwrap().unwrap();
        let (dt, steps, segments) = (scene.dt, scene.steps(), scene.segments.clone());
        let (mut sim, mut state) = scene.into_simulation().unwrap();
        let e0 = sim.energy(&state);
        let l0 = sim.system_mut().momentum_of(&state.q, &state.v);
        let (mut drift, mut max_kinetic, mut iterations) = (0.0_f64, 0.0_f64, 0usize);
        let start = std::time::Instant::now();
        for _ in 0..steps {
            let report = sim.step(&mut state, dt).unwrap();
            let e = report.energy.unwrap();
            drift = drift.max((e - e0).abs());
            iterations += report.iterations;
            max_kinetic = max_kinetic.max(sim.system_mut().energy_of(&state.q, &state.v).kinetic);
        }
        let seconds = start.elapsed().as_secs_f64();
        let l1 = sim.system_mut().momentum_of(&state.q, &state.v);
        eprintln!(
            "{name}: {steps} steps in {seconds:.2} s, max |E - E0| = {drift:.3e} J, max kinetic {max_kinetic:.3} J, {:.2} Newton iterations per step",
            iterations as f64 / steps as f64
        );
        assert!(state.q.iter().chain(&state.v).all(|x| x.is_finite()));
        let mut lines = Vec::new();
        let (model, data) = sim.system_mut().model_and_data();
        scenes::segment_points(model, data, &state.q, &segments, &mut lines);
        assert!(lines.iter().flatten().all(|p| p.is_finite()));
        let mut joints = Vec::new();
        scenes::joint_positions(model, data, &state.q, &mut joints);
        assert_eq!(joints.len(), model.njoints());
        match name {
            // Nothing dissipates in the chain and the T-handle: the energy stays.
            "pendulum-chain" => assert!(drift < 1e-3 * max_kinetic, "{drift} vs {max_kinetic}"),
            "t-handle" => {
                // Rounding only: below 1e-15 of the energy per step.
                assert!(drift < steps as f64 * 1e-15 * e0, "{drift}");
                let dl = (l1.angular - l0.angular).length() / l0.angular.length();
                assert!(dl < 1e-11, "{dl}");
            }
            // The Panda runs into its limits, whose penalty damps: the energy can only fall.
            _ => assert!(sim.energy(&state) <= e0 + 1e-6, "{} > {e0}", sim.energy(&state)),
        }
    }
}
