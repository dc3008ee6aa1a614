//! Cases per crate. Each module registers its conformance checks, hard cases and studies.

pub mod core;
pub mod determinism;
pub mod fem;
pub mod io;
pub mod material;
pub mod mpm;
pub mod pbd;
pub mod presets;
pub mod rigid;
pub mod soak;
pub mod springs;

/// The registry of every crate's cases: what each crate registers itself (`anim::cases()`), then
/// the cases still kept here, then the suites that run on every registered preset.
pub fn all() -> crate::registry::Registry {
    let mut r = anim::cases();
    self::core::register(&mut r);
    io::register(&mut r);
    springs::register(&mut r);
    rigid::register(&mut r);
    pbd::register(&mut r);
    material::register(&mut r);
    fem::register(&mut r);
    mpm::register(&mut r);
    determinism::register(&mut r);
    soak::register(&mut r);
    presets::register(&mut r);
    r
}
