//! Cases per crate. Each module registers its conformance checks, hard cases and studies.

pub mod core;
pub mod determinism;
pub mod fem;
pub mod flip;
pub mod fluid;
pub mod io;
pub mod material;
pub mod mpm;
pub mod pbd;
pub mod presets;
pub mod rigid;
pub mod skin;
pub mod soak;
pub mod springs;
