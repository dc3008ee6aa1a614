//! Cases per crate. Each module registers its conformance checks, hard cases and studies.

pub mod determinism;
pub mod fem;
pub mod flip;
pub mod fluid;
pub mod io;
pub mod material;
pub mod mpm;
pub mod presets;
pub mod skin;
pub mod soak;

/// The registry of every crate's cases: what each crate registers itself (`anim::cases()`), then
/// the cases still kept here, then the suites that run on every registered preset.
pub fn all() -> crate::registry::Registry {
    let mut r = anim::cases();
    io::register(&mut r);
    skin::register(&mut r);
    material::register(&mut r);
    fem::register(&mut r);
    mpm::register(&mut r);
    fluid::register(&mut r);
    flip::register(&mut r);
    determinism::register(&mut r);
    soak::register(&mut r);
    presets::register(&mut r);
    r
}
