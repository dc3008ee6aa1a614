//! The crate's conformance checks (feature `cases`): run by its own tests in quick mode and by
//! `cargo xtask conformance`. anim-io has no hard cases, soak runs or studies.

mod meshio;

use meshio::meshio_round_trip;

use anim_core::cases::{ConformanceCase, Registry};

const CRATE: &str = "anim-io";

/// Registers the crate's cases: what its writers produce, read back by meshio.
pub fn register(r: &mut Registry) {
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "VTK/PLY/OBJ written, read back by meshio",
        run: Box::new(meshio_round_trip),
    });
}

anim_core::quick_cases_test!(crate::cases::register);
