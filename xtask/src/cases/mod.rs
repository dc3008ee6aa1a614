//! Cases per crate. Each module registers its conformance checks, hard cases and studies.

pub mod core;
pub mod io;
pub mod pbd;
pub mod rigid;
pub mod skin;
pub mod springs;
