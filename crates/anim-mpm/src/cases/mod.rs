//! anim-mpm: conservation of mass, momentum and angular momentum by the transfers (APIC and
//! MLS-MPM, quadratic and cubic, 2D and 3D), determinism across thread counts, a resting elastic
//! block over 10 s, two colliding elastic disks, and the 2D dam break against Martin & Moyce
//! (1952); hard cases (CFL above 1, particles leaving the domain, extreme snow compression,
//! zero-mass nodes, an injected divergence, bad input, a block thrown at a 1 cm mesh plate); the dam-break work-precision study
//! (resolution and particles per cell, APIC vs MLS-MPM, quadratic vs cubic); and the timed runs
//! of `cargo xtask bench --peers`.
//!
//! The soak run (`cargo xtask stability --long`) steps the three-materials scene.

mod bodies;
mod conservation;
mod dam_break;
mod determinism;
mod hard_cases;
mod peers;
mod roofline;
mod soak;
mod thin_plate;

pub use dam_break::{DamBreak, MARTIN_MOYCE, dam_break, front_errors, shifted_errors};
pub use peers::{PeerRun, peer_benchmark};

use anim_core::cases::{ConformanceCase, Outcome, Registry, SoakCase, StabilityCase, Study, StudyUse};
use bodies::{colliding_disks, resting_block};
use conservation::conservation;
use dam_break::{dam_break_case, dam_break_study};
use determinism::determinism;
use hard_cases::{
    divergence, high_cfl, invalid_input, leaving_domain, snow_compression, wall_impact, zero_mass_nodes,
};

const CRATE: &str = "anim-mpm";

/// Registers the crate's conformance checks, hard cases, study and soak run, in the order the
/// suites print them.
pub fn register(r: &mut Registry) {
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "MPM transfer conservation",
        run: Box::new(conservation),
    });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "MPM determinism across thread counts",
        run: Box::new(determinism),
    });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "MPM resting elastic block",
        run: Box::new(resting_block),
    });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "MPM colliding elastic disks",
        run: Box::new(colliding_disks),
    });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "MPM dam break vs Martin & Moyce (1952)",
        run: Box::new(dam_break_case),
    });

    let stable = || Outcome::Stable(String::new());
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "MPM CFL above 1 (adaptive substeps)",
        expected: stable,
        run: high_cfl,
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "MPM soft block (E 1e4) hitting a wall at 40 m/s",
        expected: || Outcome::Diverged(String::new()),
        run: wall_impact,
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "MPM elastic block thrown at a 1 cm mesh plate at 20 and 50 m/s",
        expected: || Outcome::Stable(String::new()),
        run: thin_plate::thin_mesh_plate,
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "MPM particles leaving the domain",
        expected: stable,
        run: leaving_domain,
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "MPM extreme snow compression",
        expected: stable,
        run: snow_compression,
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "MPM zero-mass grid nodes",
        expected: stable,
        run: zero_mass_nodes,
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "MPM divergence (overflowing deformation)",
        expected: || Outcome::Diverged(String::new()),
        run: divergence,
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "MPM invalid input",
        expected: || Outcome::Rejected(String::new()),
        run: invalid_input,
    });

    r.studies.push(Study { crate_name: CRATE, name: "MPM dam break surge front", run: dam_break_study });
    r.study_uses.push(StudyUse::scene("mpm_dam_break", "mpm/dam-break-2d", None));
    r.soak.push(SoakCase {
        crate_name: CRATE,
        name: "three materials (elastic, snow, fluid) in a box, MLS-MPM, 64 cells",
        bound: "kinetic + gravitational energy never above its initial value",
        run: soak::mpm_three_materials,
    });
    roofline::register(r);
}

anim_core::quick_cases_test!(crate::cases::register);
