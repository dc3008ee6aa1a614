//! The crate's conformance checks, hard cases, soak runs and studies (feature `cases`): run by
//! its own tests in quick mode and by `cargo xtask conformance`, `stability` and `report`.
//!
//! Kinematics (`kinematics`): frame placements, Jacobians and their time derivatives against
//! Pinocchio on the Panda and the UR5; Jacobians against finite differences; the three forms of
//! forward kinematics; Paden-Kahan subproblems on random solvable instances; analytic IK
//! solutions reproducing their targets. Hard cases of inverse kinematics (`ik`): IK at
//! singularities, unreachable targets, workspace-boundary targets, and the numerical IK success
//! rate on the Panda. Dynamics (`dynamics`): RNEA, CRBA, ABA against Pinocchio, cross-checks,
//! steppers, the T-handle, their hard cases and the work-precision study. The example-robot-data
//! collection (`collection`): FK, world Jacobians, RNEA, CRBA and ABA of every robot on a fixed
//! and a floating base against Pinocchio. Coupled (mimic) joints against Pinocchio on the robots
//! that have them (`mimic`). Determinism of the
//! Panda swing across thread counts (`determinism`) and a soak run of the pendulum chain
//! (`soak`).

pub mod collection;
mod determinism;
mod dynamics;
mod ik;
mod kinematics;
mod mimic;
mod soak;

use std::path::{Path, PathBuf};

use crate::{Jacobian, Model, ReferenceFrame, UrdfOptions, load_urdf};
use anim_core::cases::{Check, ConformanceCase, Judge, Outcome, Registry, StabilityCase, nan_max};
use anim_core::glam::{DMat3, DVec3};
use anim_core::lie::Se3;
use serde_json::Value;

const CRATE: &str = "anim-rigid";
const PINOCCHIO: &str = "Pinocchio 4.1.0 via crates/anim-rigid/testdata/make_pinocchio_reference.py";

/// Registers the crate's cases: kinematics conformance and hard cases, then the dynamics ones
/// and the steppers' study, the determinism check and the pendulum-chain soak run, in that order.
pub fn register(r: &mut Registry) {
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "placements and Jacobians vs Pinocchio (Panda, UR5)",
        run: Box::new(kinematics::pinocchio),
    });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "Jacobians vs finite differences of FK",
        run: Box::new(kinematics::jacobian_fd),
    });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "FK three ways agree",
        run: Box::new(kinematics::fk_three_ways),
    });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "Paden-Kahan subproblems on random solvable instances",
        run: Box::new(kinematics::paden_kahan),
    });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "analytic IK solutions reproduce targets",
        run: Box::new(kinematics::analytic_ik),
    });

    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "UR5 analytic IK, wrist aligned (theta5 = 0)",
        expected: || Outcome::Stable(String::new()),
        run: |_| ik::ur5_singular(&[0.3, -1.0, 1.2, 0.5, 0.0, 0.1]),
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "UR5 analytic IK, elbow straight (theta3 = 0, workspace boundary)",
        expected: || Outcome::Stable(String::new()),
        run: |_| ik::ur5_singular(&[0.3, -1.0, 0.0, 0.5, 0.8, 0.1]),
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "PUMA-like analytic IK, wrist aligned (theta5 = 0)",
        expected: || Outcome::Stable(String::new()),
        run: |_| ik::puma_singular(),
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "analytic IK, unreachable target (3 m away)",
        expected: || Outcome::Rejected(String::new()),
        run: |_| ik::analytic_unreachable(),
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "Panda numerical IK, unreachable target (2 m away): failure with the closest pose",
        expected: || Outcome::Rejected(String::new()),
        run: |_| ik::panda_unreachable(),
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "Panda numerical IK near singularities (elbow at its limit, wrist aligned)",
        expected: || Outcome::Stable(String::new()),
        run: |_| ik::panda_singular(),
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "Panda numerical IK at the workspace boundary (arm stretched)",
        expected: || Outcome::Stable(String::new()),
        run: |_| ik::panda_boundary(),
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "Panda numerical IK success rate, random reachable targets",
        expected: || Outcome::Stable(String::new()),
        run: ik::panda_success_rate,
    });
    dynamics::register(r);
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "example-robot-data collection vs Pinocchio (66 URDFs, fixed and floating base): FK, Jacobians, RNEA, CRBA, ABA",
        run: Box::new(collection::pinocchio_collection),
    });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "coupled (mimic) joints vs Pinocchio mimic=True (Panda, Baxter, PR2, TIAGo Pro)",
        run: Box::new(mimic::pinocchio_mimic),
    });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "determinism: Panda swing on 1, 2, 4 threads",
        run: Box::new(determinism::panda),
    });
    r.soak.push(soak::CHAIN);
}

fn testdata(file: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("testdata").join(file)
}

fn panda() -> Result<Model, String> {
    let options =
        UrdfOptions::default().lock_joint("panda_finger_joint1", 0.0).lock_joint("panda_finger_joint2", 0.0);
    load_urdf(testdata("panda.urdf"), &options).map_err(|e| e.to_string())
}

fn ur5() -> Result<Model, String> {
    load_urdf(testdata("ur5_robot.urdf"), &UrdfOptions::default()).map_err(|e| e.to_string())
}

fn puma() -> Result<Model, String> {
    load_urdf(testdata("puma_like.urdf"), &UrdfOptions::default()).map_err(|e| e.to_string())
}

fn check(
    case: &str,
    metric: &str,
    measured: f64,
    tolerance: f64,
    judge: Judge,
    source: &'static str,
) -> Check {
    Check {
        crate_name: CRATE,
        case: case.to_string(),
        metric: metric.to_string(),
        measured,
        reference: 0.0,
        tolerance,
        judge,
        source,
    }
}

fn failed(case: &str, why: &str) -> Vec<Check> {
    vec![Check::could_not_run(CRATE, case, why)]
}

fn floats(v: &Value) -> Vec<f64> {
    v.as_array().map(|a| a.iter().filter_map(Value::as_f64).collect()).unwrap_or_default()
}

fn se3_of(v: &Value) -> Se3 {
    let a = floats(v);
    if a.len() != 12 {
        return Se3::new(DMat3::from_diagonal(DVec3::splat(f64::NAN)), DVec3::NAN);
    }
    let r = DMat3::from_cols(
        DVec3::new(a[0], a[3], a[6]),
        DVec3::new(a[1], a[4], a[7]),
        DVec3::new(a[2], a[5], a[8]),
    );
    Se3::new(r, DVec3::new(a[9], a[10], a[11]))
}

fn se3_err(a: &Se3, b: &Se3) -> f64 {
    let r = (a.rotation - b.rotation).to_cols_array().iter().fold(0.0_f64, |m, e| nan_max(m, e.abs()));
    let t = (a.translation - b.translation).to_array().iter().fold(0.0_f64, |m, e| nan_max(m, e.abs()));
    nan_max(r, t)
}

fn jac_err(j: &Jacobian, reference: &Value) -> f64 {
    let r = floats(reference);
    let n = j.ncols();
    if r.len() != 6 * n {
        return f64::NAN;
    }
    let mut m = 0.0_f64;
    for row in 0..6 {
        for c in 0..n {
            m = nan_max(m, (j[(row, c)] - r[row * n + c]).abs());
        }
    }
    m
}

fn rf_of(name: &str) -> ReferenceFrame {
    match name {
        "WORLD" => ReferenceFrame::World,
        "LOCAL" => ReferenceFrame::Local,
        _ => ReferenceFrame::LocalWorldAligned,
    }
}

anim_core::quick_cases_test!(crate::cases::register);
