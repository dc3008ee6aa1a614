//! `cargo xtask bench --peers`: our per-step time against peer libraries on the same problem,
//! same integrator and same thread count, measured side by side in one run.
//!
//! One module per crate compared (`springs`, `rigid`, `pbd`, `fem`, `mpm`, `fluid`, `flip`),
//! each with a `run` that prints its table, checks that both codes computed the same motion where
//! they can, and records its ratios `ours / theirs` with [`ratios::record`]; `cargo xtask bench`
//! calls them and merges the ratios into `docs/report/peers.csv` ([`ratios`]). The peer codes are
//! the scripts and C/C++ programs under `xtask/peers/`.

pub mod fem;
pub mod flip;
pub mod fluid;
pub mod mpm;
pub mod pbd;
pub mod ratios;
pub mod rigid;
pub mod rigid_mujoco;
pub mod springs;

/// A time in nanoseconds as table text: ns, us, ms or s (`?` when not finite).
pub fn human(ns: f64) -> String {
    if !ns.is_finite() {
        "?".into()
    } else if ns < 1e3 {
        format!("{ns:.0} ns")
    } else if ns < 1e6 {
        format!("{:.2} us", ns / 1e3)
    } else if ns < 1e9 {
        format!("{:.2} ms", ns / 1e6)
    } else {
        format!("{:.2} s", ns / 1e9)
    }
}
