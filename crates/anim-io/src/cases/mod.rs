//! The crate's conformance checks, hard cases, soak runs and studies (feature `cases`): run by
//! its own tests in quick mode and by `cargo xtask conformance`, `stability` and `report`.

use anim_core::cases::Registry;

/// Registers the crate's cases.
pub fn register(_r: &mut Registry) {}
