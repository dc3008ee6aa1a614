//! `cargo xtask bench --peers`, anim-mpm part.

pub fn run() -> bool {
    true
}
