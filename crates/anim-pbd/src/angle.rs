//! The angle of a dihedral constraint without a call into the C library: `atan2(y, x)` for
//! `x > 0, |y| <= x` (an angle in `[-pi/4, pi/4]`, every bending stencil bent by less than a
//! quarter turn from its rest angle) by the rational approximation of the Cephes library
//! (Moshier 1989, `atan.c`: `atan t = t + t z P(z) / Q(z)`, `z = t^2`, on `|t| <= 0.66`, and
//! `pi/4 + atan((t - 1) / (t + 1))` above), within two units in the last place of the correctly
//! rounded angle; every other argument goes to [`f64::atan2`].

use std::f64::consts::FRAC_PI_4;

/// Numerator coefficients of Cephes' `atan`, highest degree first (as published, to more digits
/// than a double holds).
#[allow(clippy::excessive_precision)]
const P: [f64; 5] = [
    -8.750_608_600_031_904_122_785e-1,
    -1.615_753_718_733_365_076_637e1,
    -7.500_855_792_314_704_667_340e1,
    -1.228_866_684_490_136_173_410e2,
    -6.485_021_904_942_025_371_773e1,
];
/// Denominator coefficients (leading 1 implied), highest degree first.
#[allow(clippy::excessive_precision)]
const Q: [f64; 5] = [
    2.485_846_490_142_306_297_962e1,
    1.650_270_098_316_988_542_046e2,
    4.328_810_604_912_902_668_951e2,
    4.853_903_996_359_136_964_868e2,
    1.945_506_571_482_613_964_425e2,
];
/// The part of `pi/4` below `FRAC_PI_4`'s last bit (Cephes' `MOREBITS / 2`).
#[allow(clippy::excessive_precision)]
const PI_4_LO: f64 = 0.5 * 6.123_233_995_736_765_886_130e-17;

/// `atan t` for `|t| <= 0.66`.
#[inline(always)]
fn atan_small(t: f64) -> f64 {
    let z = t * t;
    let p = (((P[0] * z + P[1]) * z + P[2]) * z + P[3]) * z + P[4];
    let q = ((((z + Q[0]) * z + Q[1]) * z + Q[2]) * z + Q[3]) * z + Q[4];
    t * (z * p / q) + t
}

/// `atan2(y, x)`, fast for `x > 0, |y| <= x` (see the module docs).
#[inline(always)]
pub(crate) fn atan2(y: f64, x: f64) -> f64 {
    let a = y.abs();
    if !(x > 0.0 && a <= x && x < f64::INFINITY) {
        return y.atan2(x);
    }
    let t = a / x;
    let r = if t <= 0.66 { atan_small(t) } else { FRAC_PI_4 + (atan_small((a - x) / (a + x)) + PI_4_LO) };
    r.copysign(y)
}

#[cfg(test)]
mod tests {
    use super::atan2;

    /// Units in the last place between `a` and `b`.
    fn ulps(a: f64, b: f64) -> u64 {
        let key = |v: f64| {
            let i = v.to_bits() as i64;
            if i < 0 { i64::MIN - i } else { i }
        };
        key(a).abs_diff(key(b))
    }

    #[test]
    fn agrees_with_the_c_library_within_two_ulps() {
        // Every ratio on a fine grid of [-1, 1], at several magnitudes, plus the branch points.
        let mut worst = 0;
        for scale in [1e-300, 1e-8, 1.0, 3.7, 1e12, 1e300] {
            for k in -20_000..=20_000 {
                let y = scale * (k as f64 / 20_000.0) * 0.999_999_7;
                let x = scale;
                let (fast, lib) = (atan2(y, x), y.atan2(x));
                worst = worst.max(ulps(fast, lib));
            }
        }
        for t in [0.66, 0.66 + 1e-16, 0.659_999_999_999_999_9, 1.0, 1e-310, 0.0, -0.0] {
            worst = worst.max(ulps(atan2(t, 1.0), t.atan2(1.0)));
        }
        assert!(worst <= 2, "largest difference {worst} ulps");
        assert_eq!(atan2(1.0, 1.0), std::f64::consts::FRAC_PI_4);
    }

    #[test]
    fn other_quadrants_and_specials_match_the_c_library() {
        for (y, x) in
            [(2.0, 1.0), (-3.0, 0.5), (1.0, -1.0), (0.0, -1.0), (-0.0, -1.0), (1.0, 0.0), (0.0, 0.0)]
        {
            assert_eq!(atan2(y, x).to_bits(), y.atan2(x).to_bits(), "atan2({y}, {x})");
        }
        assert!(atan2(f64::NAN, 1.0).is_nan());
        assert!(atan2(1.0, f64::NAN).is_nan());
        assert_eq!(atan2(1.0, f64::INFINITY), 0.0);
    }
}
