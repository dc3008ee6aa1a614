//! anim-flip's cases (feature `cases`): the incompressible particle fluid (PIC / FLIP / APIC on a
//! MAC grid). Conformance: fluid volume over 10 s of sloshing, divergence after every projection
//! against the solver tolerance, angular momentum of a rotating disk over the transfers (APIC
//! keeps it, PIC does not), the 2D dam-break surge front against Martin & Moyce (1952) (anim-mpm's
//! table), and the dam break's determinism across thread counts. Hard cases: CFL 10 (large steps
//! split into adaptive substeps) and particles driven into an obstacle (pushed out, counted).
//! Study: the dam break's surge-front error against wall time for PIC, FLIP and APIC and for
//! anim-mpm's weakly compressible fluid, each at several resolutions (why the feature brings in
//! anim-mpm).
//!
//! Run in quick mode by the lib test this module declares (`anim_core::quick_cases_test!`)
//! and by `cargo xtask conformance`, `stability` and `report`.

mod conformance;
mod dam_break;
mod hard_cases;
mod roofline;

pub use dam_break::{DAM_BREAK_SLUG, DAM_BREAK_TOLERANCES};

use anim_core::cases::{ConformanceCase, Outcome, Registry, StabilityCase, Study, StudyUse};

const CRATE: &str = "anim-flip";

/// Registers the crate's conformance checks, hard cases and study.
pub fn register(r: &mut Registry) {
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "FLIP fluid volume over 10 s",
        run: Box::new(conformance::volume),
    });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "FLIP divergence after projection",
        run: Box::new(conformance::divergence),
    });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "FLIP rotating disk angular momentum over transfers",
        run: Box::new(conformance::angular_momentum),
    });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "FLIP dam break vs Martin & Moyce (1952)",
        run: Box::new(dam_break::dam_break_case),
    });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "determinism: 2D dam break (APIC) on 1, 2, 4 threads",
        run: Box::new(hard_cases::flip_dam_break),
    });
    let stable = || Outcome::Stable(String::new());
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "FLIP dam break at CFL 10 (adaptive substeps)",
        expected: stable,
        run: hard_cases::cfl_ten,
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "FLIP particles driven into a solid obstacle",
        expected: stable,
        run: hard_cases::into_obstacle,
    });
    r.studies.push(Study {
        crate_name: CRATE,
        name: "PIC/FLIP/APIC and MPM dam break",
        run: dam_break::dam_break_study,
    });
    // No scene picks from it; its tables add the 5% the experiment's scatter allows.
    r.study_uses.push(StudyUse {
        study: DAM_BREAK_SLUG,
        scene: None,
        horizon: None,
        problem: anim_core::cases::no_problem,
        extra_tolerances: DAM_BREAK_TOLERANCES,
    });
    roofline::register(r);
}

anim_core::quick_cases_test!(crate::cases::register);
