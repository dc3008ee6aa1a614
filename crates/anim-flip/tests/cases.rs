//! The crate's conformance checks and hard cases, in quick mode (`--features cases`); `cargo
//! xtask conformance` and `stability` run the same cases in full.

#[test]
fn conformance_and_hard_cases_pass_in_quick_mode() {
    let failures = anim_core::cases::quick_failures(anim_flip::cases::register);
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
