//! The suites xtask runs over every registered preset. Each crate's own conformance checks,
//! hard cases, soak runs and studies live in the crate (its `cases` module, feature `cases`) and
//! reach xtask through `anim::cases()`.

pub mod examples;
pub mod presets;

/// The registry of every crate's cases (`anim::cases()`), then the suites that run on every
/// registered preset and on every example scene file.
pub fn all() -> crate::registry::Registry {
    let mut r = anim::cases();
    presets::register(&mut r);
    examples::register(&mut r);
    r
}
