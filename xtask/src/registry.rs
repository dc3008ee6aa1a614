//! The case registry: conformance checks, stability cases, soak runs and work-precision studies.
//!
//! The types live in `anim_core::cases` (feature `cases`), so that each crate registers its own
//! cases next to its code; this module re-exports them for the suites, the report and the few
//! workspace-wide cases that xtask itself keeps.

pub use anim_core::cases::*;
