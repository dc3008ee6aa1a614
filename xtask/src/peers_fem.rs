//! `cargo xtask bench --peers`, anim-fem part.

pub fn run() -> bool {
    true
}
