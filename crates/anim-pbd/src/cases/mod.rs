//! The crate's conformance checks, hard cases, soak runs and studies (feature `cases`): run by
//! its own tests in quick mode and by `cargo xtask conformance`, `stability` and `report`.
//!
//! XPBD's static stretch of a hanging chain for every iteration count and time step,
//! PBD's effective stiffness against both, momentum conservation of every internal constraint
//! with unequal masses, constraint gradients against finite differences, determinism across
//! thread counts (`conformance`, on the chain of `chain`; the cloth drape, over the analytic
//! sphere and over a mesh sphere, on 1, 2 and 4 threads: `determinism`); hard cases (1000:1 mass ratio, 10x
//! over-stretch, pins next to free particles, zero compliance, coincident and degenerate
//! stencils, bad input, an injected NaN: `hard_cases`; particles and a cloth thrown at a 1 cm
//! mesh plate at 20-50 m/s and faster, held by continuous contact: `thin_plate`); a work-precision study on the hanging
//! cloth (PBD vs XPBD, iterations vs substeps: `study`); and the timed runs of
//! `cargo xtask bench --peers` (`peer`); a soak run of the cloth drape (`soak`).

mod chain;
mod conformance;
mod determinism;
mod hard_cases;
mod peer;
mod roofline;
mod soak;
mod study;
mod thin_plate;

use anim_core::cases::{ConformanceCase, Outcome, Registry, StabilityCase, Study, StudyUse};
use conformance::{CRATE, determinism, gradients, momentum, pbd_stiffness, xpbd_chain};
use hard_cases::{
    coincident, degenerate_rest, injected_nan, invalid_input, mass_ratio, over_stretched, pins_next_to_free,
    zero_compliance,
};
use study::{cloth_constraint_study, cloth_position_study};

pub use peer::{PeerRun, peer_cloth, thread_rounds};
pub use study::{STUDY_T, study_problem};

/// Registers the crate's cases: conformance, hard cases, studies, the determinism checks of the
/// drape (over the analytic and over a mesh sphere) and its soak run, in that order.
pub fn register(r: &mut Registry) {
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "XPBD hanging chain static stretch",
        run: Box::new(xpbd_chain),
    });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "PBD effective stiffness vs iterations and dt",
        run: Box::new(pbd_stiffness),
    });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "PBD/XPBD momentum with unequal masses",
        run: Box::new(momentum),
    });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "PBD constraint gradients vs finite differences",
        run: Box::new(gradients),
    });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "PBD determinism across thread counts",
        run: Box::new(determinism),
    });

    let stable = || Outcome::Stable(String::new());
    let rejected = || Outcome::Rejected(String::new());
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "PBD chain with a 1000:1 mass ratio",
        expected: stable,
        run: mass_ratio,
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "PBD chain started at 10x its rest length",
        expected: stable,
        run: over_stretched,
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "PBD pinned particles next to free ones",
        expected: stable,
        run: pins_next_to_free,
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "PBD zero compliance cloth at dt = 1/30 s",
        expected: stable,
        run: zero_compliance,
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "PBD coincident vertices and stencils collapsed at run time",
        expected: stable,
        run: coincident,
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "PBD zero-area bending stencil at rest",
        expected: rejected,
        run: degenerate_rest,
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "PBD invalid input (mass, k, compliance, index)",
        expected: rejected,
        run: invalid_input,
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "PBD particles and a cloth thrown at a 1 cm mesh plate at 20-50 m/s",
        expected: stable,
        run: thin_plate::thin_mesh_plate,
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "PBD NaN injected by an external force",
        expected: || Outcome::Diverged(String::new()),
        run: injected_nan,
    });

    r.studies.push(Study {
        crate_name: CRATE,
        name: "PBD hanging cloth: position error",
        run: cloth_position_study,
    });
    r.studies.push(Study {
        crate_name: CRATE,
        name: "PBD hanging cloth: constraint error",
        run: cloth_constraint_study,
    });
    r.study_uses.push(StudyUse {
        problem: study_problem,
        ..StudyUse::scene("pbd-cloth-position", "pbd/hanging-cloth", Some(STUDY_T))
    });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "determinism: cloth drape on 1, 2, 4 threads",
        run: Box::new(determinism::drape),
    });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "determinism: cloth drape on a mesh sphere on 1, 2, 4 threads",
        run: Box::new(determinism::drape_on_mesh),
    });
    r.soak.push(soak::DRAPE);
    roofline::register(r);
}

anim_core::quick_cases_test!(crate::cases::register);
