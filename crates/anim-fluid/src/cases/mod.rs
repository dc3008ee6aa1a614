//! anim-fluid's cases (feature `cases`): Stam's solver against a compiled C transcription of
//! his routines (bit for bit at N = 64 and 128); divergence after projection for every
//! pressure solver (2D with an obstacle, 3D); Taylor-Green decay against `exp(-2 nu k^2 t)` at
//! N = 128 per advection scheme and splitting (advect-then-project, advection-reflection); the
//! lid-driven cavity at Re = 100 against Ghia, Ghia and Shin (1982) per resolution and scheme;
//! determinism across thread counts; hard cases (CFL 10, huge forces, empty and 1-cell grids,
//! non-positive parameters, NaN sources); the CFL-10 soak run; work-precision studies of the
//! pressure solvers (divergence residual and Ghia error against wall time).
//!
//! Run in quick mode by the lib test this module declares (`anim_core::quick_cases_test!`)
//! and by `cargo xtask conformance`, `stability` and `report`.

mod conformance;
mod ghia;
mod hard_cases;
mod stam_c;
mod study;

pub use stam_c::compile_c;
pub use study::ghia_study_problem;

use anim_core::cases::{
    Check, ConformanceCase, Ctx, Judge, Outcome, Registry, SoakCase, StabilityCase, Study, StudyUse,
};

const CRATE: &str = "anim-fluid";

/// Registers the crate's conformance checks, hard cases, soak run and studies.
pub fn register(r: &mut Registry) {
    for (name, run) in [
        ("Stam's solver vs its C transcription, bit for bit", stam_c::stam_bitwise as fn(&Ctx) -> Vec<Check>),
        ("divergence after projection per pressure solver", conformance::divergence),
        ("Taylor-Green vortex decay (N = 128; 64 in --quick)", conformance::taylor_green),
        ("lid-driven cavity Re = 100 vs Ghia et al. 1982", ghia::ghia),
        ("MAC solver determinism across thread counts", conformance::determinism),
    ] {
        r.conformance.push(ConformanceCase { crate_name: CRATE, name, run: Box::new(run) });
    }
    let stable = || Outcome::Stable(String::new());
    let rejected = || Outcome::Rejected(String::new());
    let diverged = || Outcome::Diverged(String::new());
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "smoke at CFL 10 (semi-Lagrangian)",
        expected: stable,
        run: hard_cases::cfl10,
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "buoyancy force of 1e6",
        expected: stable,
        run: hard_cases::huge_force,
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "empty grid",
        expected: rejected,
        run: hard_cases::empty_grid,
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "1-cell grid",
        expected: rejected,
        run: hard_cases::one_cell,
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "non-positive dt, h, viscosity, tolerance",
        expected: rejected,
        run: hard_cases::non_positive,
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "NaN source (Stam and MAC)",
        expected: diverged,
        run: hard_cases::nan_source,
    });
    r.studies.push(Study {
        crate_name: CRATE,
        name: "pressure solvers: divergence residual vs time",
        run: study::study_divergence,
    });
    r.studies.push(Study {
        crate_name: CRATE,
        name: "pressure solvers: Ghia error vs time",
        run: study::study_ghia,
    });
    r.studies.push(Study {
        crate_name: CRATE,
        name: "advection and splitting: Taylor-Green error vs time",
        run: study::study_taylor_green,
    });
    r.study_uses.push(StudyUse {
        problem: study::ghia_study_problem,
        ..StudyUse::scene("fluid_cavity_ghia", "fluid/lid-driven-cavity", None)
    });
    r.study_uses.push(StudyUse::scene("fluid_pressure_divergence", "fluid/smoke-plume-3d", None));
    r.soak.push(SoakCase {
        crate_name: CRATE,
        name: "vortex in a box at CFL 10, semi-Lagrangian, 64x64 MAC",
        bound: "kinetic energy never above its initial value; density within [0, 1]",
        run: hard_cases::soak_cfl10,
    });
}

fn check(
    case: &str,
    metric: String,
    measured: f64,
    reference: f64,
    tolerance: f64,
    judge: Judge,
    source: &'static str,
) -> Check {
    Check { crate_name: CRATE, case: case.into(), metric, measured, reference, tolerance, judge, source }
}

anim_core::quick_cases_test!(crate::cases::register);
