//! Interpolation of rotations given as unit quaternions: spherical linear interpolation (slerp,
//! Shoemake, *Animating rotation with quaternion curves*, SIGGRAPH 1985), which moves at constant
//! angular speed along the great arc between two quaternions:
//!
//! ```text
//! slerp(a, b, t) = sin((1 - t) theta) / sin(theta) a + sin(t theta) / sin(theta) b
//! ```
//!
//! with `theta` the angle between `a` and `b` as 4-vectors. `q` and `-q` are the same rotation:
//! taking the one of `b`, `-b` nearer to `a` gives the shorter of the two arcs, the rotation by
//! the smaller angle. Clips interpolate rotation keys with it (module `clip`) and
//! `Pose::blend` mixes rotations with it.

use anim_core::glam::{DQuat, DVec4};

/// Spherical linear interpolation along the shorter arc: `b` is negated when `a . b < 0`, and
/// `t = 0` returns `a`, `t = 1` returns `b` (or `-b`). The angle is computed as
/// `2 atan2(|a - b|, |a + b|)`, accurate at small angles; below `1e-9` rad it falls back to a
/// normalised lerp.
#[must_use]
pub fn slerp(a: DQuat, b: DQuat, t: f64) -> DQuat {
    let (a4, mut b4) = (DVec4::from(a), DVec4::from(b));
    if a4.dot(b4) < 0.0 {
        b4 = -b4;
    }
    let theta = 2.0 * (a4 - b4).length().atan2((a4 + b4).length());
    let r = if theta < 1e-9 {
        a4.lerp(b4, t).normalize()
    } else {
        let s = theta.sin();
        (((1.0 - t) * theta).sin() / s) * a4 + ((t * theta).sin() / s) * b4
    };
    DQuat::from_vec4(r)
}
