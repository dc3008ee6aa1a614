//! `cargo xtask bench --peers`, anim-fluid part.

pub fn run() -> bool {
    true
}
