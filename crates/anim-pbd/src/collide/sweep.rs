//! Continuous contact against a mesh collider: where a particle's path over a substep first comes
//! within contact distance of the surface, found by conservative advancement through the
//! collider's distance field.
//!
//! A particle whose predicted position `p` lies beyond a surface thinner than its motion (a
//! plate of 1 cm crossed at 20 m/s in a substep of 1/240 s moves 8 cm) has no contact at `p`
//! that would stop it: the closest surface point of `p` is on the far side, and its normal
//! pushes the particle on through. Following the segment `x -> p` instead finds the first
//! point `y` with `phi(y) <= thickness`, on the near side; the contact built there
//! (`q = y - phi(y) n(y)`, the constraint `n . (p - q) >= thickness`) stops the particle where
//! it would have touched, as continuous collision detection does for cloth (Bridson, Fedkiw and
//! Anderson 2002, "Robust treatment of collisions, contact and friction for cloth animation")
//! and as a speculative contact does in games (Catto, "Continuous collision", GDC 2013): a
//! constraint from the start of the motion, inactive unless the predicted position breaks it.
//!
//! The march is conservative advancement (Mirtich 1996; Zhang et al. 2006) on the field: from
//! the segment's start, each step advances by `(phi(y) - thickness) / L`, where `L = sqrt(3)`
//! bounds the slope of the trilinear interpolant (each component of its gradient is a mean of
//! difference quotients of node values of a distance, at most 1 where the field is exact), so a
//! step cannot carry the point past the surface grown by the thickness. It stops at the first
//! point within [`TOUCH`] spacings of that surface, at the end of the segment, or after
//! [`MARCH_STEPS`] steps (a path that grazes the surface, slowing the march: the point reached
//! is still outside, and its contact is a speculative one). A head-on approach from any distance
//! closes `1 - 1/sqrt(3)` of the remaining gap per step, 0.42: 32 steps take a gap of 10 km to
//! below a micrometre.

use anim_core::glam::DVec3;
use anim_core::surface::DistanceField;

/// The most steps of one march.
pub(crate) const MARCH_STEPS: usize = 32;

/// The stopping distance of the march beyond the thickness, in spacings of the field.
pub(crate) const TOUCH: f64 = 1e-3;

/// A bound on the slope of the field's trilinear interpolant.
const SLOPE: f64 = 1.732_050_807_568_877_2;

/// The first point of the segment `a -> b` (in the field's frame) within `reach` (the
/// thickness) of the surface, by conservative advancement through `field` (see the
/// [module](self)); `None` when the segment, clipped to the field's lattice, stays farther away,
/// which the first step tells for a particle whose motion is shorter than its distance to the
/// surface over `sqrt(3)`. The point returned lies in the lattice.
#[must_use]
pub(crate) fn first_touch(field: &DistanceField, a: DVec3, b: DVec3, reach: f64) -> Option<DVec3> {
    let (lo, hi) = (field.origin(), field.far_corner());
    let d = b - a;
    // The part of the segment inside the lattice's box: [s0, s1] (slabs).
    let (mut s0, mut s1) = (0.0f64, 1.0f64);
    for k in 0..3 {
        if d[k] == 0.0 {
            if !(a[k] >= lo[k] && a[k] <= hi[k]) {
                return None;
            }
        } else {
            let (t0, t1) = ((lo[k] - a[k]) / d[k], (hi[k] - a[k]) / d[k]);
            s0 = s0.max(t0.min(t1));
            s1 = s1.min(t0.max(t1));
        }
    }
    if !(s0 <= s1) {
        return None;
    }
    let len = d.length();
    let stop = reach + TOUCH * field.spacing();
    let mut s = s0;
    let mut y = (a + s * d).clamp(lo, hi);
    for _ in 0..MARCH_STEPS {
        let phi = field.sample(y)?.distance;
        if phi <= stop {
            return Some(y);
        }
        // No point of the rest of the segment, `(s1 - s) len` long, comes closer than
        // `phi - L (s1 - s) len`: the march ends without a touch.
        let advance = (phi - reach) / (SLOPE * len);
        if s + advance >= s1 {
            return None;
        }
        s += advance;
        y = (a + s * d).clamp(lo, hi);
    }
    Some(y)
}
