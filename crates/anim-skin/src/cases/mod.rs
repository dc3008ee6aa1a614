//! anim-skin's cases (feature `cases`): posed glTF vertices against an independent numpy
//! reference, DQS against LBS on rigid single-influence vertices, glTF interpolation against
//! hand-computed values, the twisted cylinder's volume under LBS and DQS (the candy-wrapper
//! collapse), its determinism across thread counts and its looped clip as a soak run. Study: the
//! twisted cylinder rebound to chains of 2 to 33 twist joints, skinned by LBS and DQS at three
//! mesh sizes, shape error against the exact twist against the time of one skinning pass.
//!
//! Run in quick mode by the lib test this module declares (`anim_core::quick_cases_test!`)
//! and by `cargo xtask conformance`, `stability` and `report`.

mod conformance;
mod study;
mod threads_and_loop;

use anim_core::cases::{Check, ConformanceCase, Judge, Registry, SoakCase, Study};
use std::path::{Path, PathBuf};

const CRATE: &str = "anim-skin";
const NUMPY: &str = "numpy + pygltflib, crates/anim-skin/testdata/reference.py";

/// Registers the crate's conformance checks, soak run and study.
pub fn register(r: &mut Registry) {
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "glTF posed vertices vs numpy reference",
        run: Box::new(|_| conformance::gltf_reference()),
    });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "DQS equals LBS on rigid single-influence vertices",
        run: Box::new(|_| conformance::dqs_vs_lbs()),
    });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "glTF interpolation step/linear/cubic by hand",
        run: Box::new(|_| conformance::interpolation()),
    });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "twisted cylinder volume, LBS vs DQS",
        run: Box::new(|_| conformance::candy_wrapper()),
    });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "determinism: twisted cylinder (LBS and DQS) on 1, 2, 4 threads",
        run: Box::new(threads_and_loop::skin_cylinder),
    });
    r.studies.push(Study {
        crate_name: CRATE,
        name: "LBS vs DQS by twist-joint count",
        run: study::twist_study,
    });
    r.soak.push(SoakCase {
        crate_name: CRATE,
        name: "twisted cylinder, DQS, clip looped 500 times",
        bound: "every pose identical to its first cycle, bit for bit; volume within 2% of rest",
        run: threads_and_loop::skin_loop,
    });
}

fn testdata(file: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("testdata").join(file)
}

fn check(
    case: &str,
    metric: String,
    measured: f64,
    tolerance: f64,
    judge: Judge,
    source: &'static str,
) -> Check {
    Check { crate_name: CRATE, case: case.into(), metric, measured, reference: 0.0, tolerance, judge, source }
}

anim_core::quick_cases_test!(crate::cases::register);
