//! Cases per crate. Each module registers its conformance checks, hard cases and studies.

pub mod determinism;
pub mod flip;
pub mod fluid;
pub mod presets;
pub mod skin;
pub mod soak;

/// The registry of every crate's cases: what each crate registers itself (`anim::cases()`), then
/// the cases still kept here, then the suites that run on every registered preset.
pub fn all() -> crate::registry::Registry {
    let mut r = anim::cases();
    skin::register(&mut r);
    fluid::register(&mut r);
    flip::register(&mut r);
    determinism::register(&mut r);
    soak::register(&mut r);
    presets::register(&mut r);
    r
}
