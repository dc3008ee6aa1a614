//! Analytic IK (spherical wrist, UR type) and numerical IK.

#![allow(clippy::unwrap_used, clippy::expect_used)] // integration tests: a failed unwrap is a failed test

mod common;

use anim_core::glam::DVec3;
use anim_core::lie::Se3;
use anim_rigid::config::{random_configuration, within_limits};
use anim_rigid::ik::pose_error;
use anim_rigid::{
    AnalyticIk, AnalyticIkKind, Data, IkError, IkParams, Model, NumericalIk, frames_forward_kinematics,
};
use common::{panda, puma, se3_err, ur5};

fn se3_close(a: &Se3, b: &Se3) -> bool {
    se3_err(a, b) < 1e-14
}
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn fk(model: &Model, q: &[f64], f: usize) -> Se3 {
    let mut data = Data::new(model);
    frames_forward_kinematics(model, &mut data, q);
    data.frame_placements[f]
}

fn check_analytic(model: &Model, frame: &str, expected_kind: AnalyticIkKind, seed: u64) {
    let f = model.frame_id(frame).unwrap();
    let ik = AnalyticIk::new(model, f).unwrap();
    assert_eq!(ik.kind(), expected_kind);
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut eights = 0;
    for _ in 0..300 {
        let q: Vec<f64> = random_configuration(model, &mut || rng.random::<f64>())
            .iter()
            .map(|x| anim_rigid::paden_kahan::wrap_angle(*x))
            .collect();
        let target = fk(model, &q, f);
        let sols = ik.solve(&target);
        assert!(!sols.is_empty(), "no solution for a reachable target");
        assert!(sols.len() <= 8);
        if sols.len() == 8 {
            eights += 1;
        }
        for s in &sols {
            let (dp, dr) = pose_error(&fk(model, &s.q, f), &target);
            assert!(dp < 1e-10 && dr < 1e-10, "solution misses by {dp:e} m, {dr:e} rad");
            assert!(s.residual < 1e-10);
        }
        // The generating configuration is among the solutions.
        let found = sols.iter().any(|s| {
            s.q.iter().zip(&q).all(|(a, b)| anim_rigid::paden_kahan::wrap_angle(a - b).abs() < 1e-6)
        });
        assert!(found, "the generating configuration is not among {} solutions", sols.len());
    }
    assert!(eights > 200, "8 solutions in only {eights} of 300 random poses");
}

#[test]
fn puma_like_arm_all_solutions() {
    check_analytic(&puma(), "tool", AnalyticIkKind::SphericalWrist, 21);
}

#[test]
fn ur5_all_solutions() {
    check_analytic(&ur5(), "tool0", AnalyticIkKind::UrType, 22);
    check_analytic(&ur5(), "ee_link", AnalyticIkKind::UrType, 23);
}

#[test]
fn analytic_ik_rejects_other_chains() {
    let model = panda();
    let f = model.frame_id("panda_hand_tcp").unwrap();
    assert!(matches!(AnalyticIk::new(&model, f), Err(IkError::NotSixRevolute { found: 7, .. })));
}

#[test]
fn analytic_ik_unreachable_is_empty() {
    for (model, frame) in [(puma(), "tool"), (ur5(), "tool0")] {
        let f = model.frame_id(frame).unwrap();
        let ik = AnalyticIk::new(&model, f).unwrap();
        let far = Se3::from_translation(DVec3::new(3.0, 0.0, 0.5));
        assert!(ik.solve(&far).is_empty());
    }
}

#[test]
fn analytic_ik_at_singularities() {
    // Wrist aligned (θ5 = 0): θ4 and θ6 only fixed in sum; one representative per arm branch.
    let model = puma();
    let f = model.frame_id("tool").unwrap();
    let ik = AnalyticIk::new(&model, f).unwrap();
    let q = vec![0.3, -0.4, 0.9, 0.7, 0.0, -0.2];
    let target = fk(&model, &q, f);
    let sols = ik.solve(&target);
    assert!(!sols.is_empty());
    assert!(sols.iter().any(|s| s.singular));
    for s in &sols {
        let (dp, dr) = pose_error(&fk(&model, &s.q, f), &target);
        assert!(dp < 1e-9 && dr < 1e-9, "{dp:e} {dr:e}");
    }
    // UR5 with the wrist singular (θ5 = 0) and the elbow straight (θ3 = 0).
    let model = ur5();
    let f = model.frame_id("tool0").unwrap();
    let ik = AnalyticIk::new(&model, f).unwrap();
    for q in [vec![0.3, -1.0, 0.0, 0.5, 0.8, 0.1], vec![0.3, -1.0, 1.0, 0.5, 0.0, 0.1]] {
        let target = fk(&model, &q, f);
        let sols = ik.solve(&target);
        assert!(!sols.is_empty(), "{q:?}");
        for s in &sols {
            let (dp, dr) = pose_error(&fk(&model, &s.q, f), &target);
            assert!(dp < 1e-9 && dr < 1e-9, "{q:?}: {dp:e} {dr:e}");
        }
    }
}

#[test]
fn numerical_ik_converges_on_the_panda() {
    let model = panda();
    let f = model.frame_id("panda_hand_tcp").unwrap();
    let mut ik = NumericalIk::new(&model, f, IkParams::default());
    let q_mid = ik.mid_configuration(&model);
    let mut rng = ChaCha8Rng::seed_from_u64(31);
    let mut successes = 0;
    for _ in 0..200 {
        let q = random_configuration(&model, &mut || rng.random::<f64>());
        let target = fk(&model, &q, f);
        let report = ik.solve(&model, &target, &q_mid);
        assert!(report.error.is_finite());
        assert!(within_limits(&model, &report.q, 0.0));
        if report.success {
            successes += 1;
            assert!(report.position_error < 1e-9 && report.rotation_error < 1e-9);
            let (dp, _) = pose_error(&fk(&model, &report.q, f), &target);
            assert!(dp < 1e-9);
        }
    }
    assert!(successes >= 198, "only {successes}/200 converged");
}

#[test]
fn numerical_ik_unreachable_reports_closest_pose() {
    let model = panda();
    let f = model.frame_id("panda_hand_tcp").unwrap();
    let mut ik = NumericalIk::new(&model, f, IkParams::default());
    let q0 = ik.mid_configuration(&model);
    let target = Se3::from_translation(DVec3::new(2.0, 0.0, 0.5));
    let report = ik.solve(&model, &target, &q0);
    assert!(!report.success);
    assert!(report.error.is_finite() && report.error > 0.5);
    // The closest pose found is at least as close (in the same error measure) as any of 2000
    // random configurations, and is where the report says it is.
    let mut data = Data::new(&model);
    let err_of = |q: &[f64], data: &mut Data| {
        frames_forward_kinematics(&model, data, q);
        let e = (data.frame_placements[f].inverse() * target).log();
        (e.v.length_squared() + e.w.length_squared()).sqrt()
    };
    let mut rng = ChaCha8Rng::seed_from_u64(34);
    for _ in 0..2000 {
        let q = random_configuration(&model, &mut || rng.random::<f64>());
        assert!(report.error <= err_of(&q, &mut data) + 1e-12);
    }
    assert!((report.error - err_of(&report.q, &mut data)).abs() < 1e-12);
    assert!(se3_close(&report.placement, &fk(&model, &report.q, f)));
    // Non-finite targets are failures with infinite error, never NaN.
    let bad = Se3::from_translation(DVec3::new(f64::NAN, 0.0, 0.0));
    let report = ik.solve(&model, &bad, &q0);
    assert!(!report.success && report.error == f64::INFINITY);
    assert!(report.q.iter().all(|x| x.is_finite()));
}

#[test]
fn numerical_ik_nullspace_moves_toward_mid_range() {
    // The same target solved with and without the null-space objective: with it, the solution
    // is closer to the middle of the joint ranges.
    let model = panda();
    let f = model.frame_id("panda_hand_tcp").unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(33);
    let mut with = NumericalIk::new(&model, f, IkParams::default());
    let mut params = IkParams::default();
    params.nullspace_gain = 0.0;
    let mut without = NumericalIk::new(&model, f, params);
    let mid = with.mid_configuration(&model);
    let dist = |q: &[f64]| -> f64 {
        model.joints()[1..]
            .iter()
            .map(|j| {
                let half = 0.5 * (j.limits.upper - j.limits.lower);
                ((q[j.idx_q] - mid[j.idx_q]) / half).powi(2)
            })
            .sum()
    };
    let (mut closer, mut total) = (0, 0);
    for _ in 0..40 {
        let q = random_configuration(&model, &mut || rng.random::<f64>());
        let target = fk(&model, &q, f);
        // Start from another random configuration so that the solver travels.
        let start = random_configuration(&model, &mut || rng.random::<f64>());
        let a = with.solve(&model, &target, &start);
        let b = without.solve(&model, &target, &start);
        if a.success && b.success {
            total += 1;
            if dist(&a.q) < dist(&b.q) {
                closer += 1;
            }
        }
    }
    eprintln!("nullspace: closer in {closer} of {total}");
    assert!(total >= 35 && closer * 4 >= total * 3, "closer in {closer} of {total}");
}
