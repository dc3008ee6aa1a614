//! The Paden-Kahan subproblems (Murray, Li & Sastry, *A Mathematical Introduction to
//! Robotic Manipulation*, ch. 2.3 and 3.3): the three geometric problems that analytic inverse
//! kinematics reduces to.
//!
//! Each rotation is about a line through the point `r` with unit direction `ω` (a zero-pitch
//! twist `ξ = (-ω × r, ω)`); `u = p - r`, `v = q - r`, and `x' = x - ω ωᵀ x` is the projection
//! onto the plane normal to `ω`.
//!
//! | problem | find | solution |
//! | --- | --- | --- |
//! | 1 | `θ` with `e^{ξ̂θ} p = q` | `θ = atan2(ωᵀ(u' × v'), u'ᵀ v')` if `ωᵀu = ωᵀv` and `‖u'‖ = ‖v'‖` |
//! | 2 | `θ₁, θ₂` with `e^{ξ̂₁θ₁} e^{ξ̂₂θ₂} p = q`, axes meeting at `r` | the intermediate point `c = r + αω₁ + βω₂ ± γ(ω₁ × ω₂)`, then subproblem 1 twice |
//! | 3 | `θ` with `‖e^{ξ̂θ} p - q‖ = δ` | `θ = θ₀ ± acos((‖u'‖² + ‖v'‖² - δ'²) / (2‖u'‖‖v'‖))`, `δ'² = δ² - (ωᵀ(p - q))²` |
//!
//! with, in subproblem 2 (`c₁₂ = ω₁ᵀω₂`),
//!
//! ```text
//! α  = (c₁₂ ω₂ᵀu - ω₁ᵀv) / (c₁₂² - 1)
//! β  = (c₁₂ ω₁ᵀv - ω₂ᵀu) / (c₁₂² - 1)
//! γ² = (‖u‖² - α² - β² - 2αβ c₁₂) / ‖ω₁ × ω₂‖²
//! ```
//!
//! # Every branch, and what is returned
//!
//! Nothing here returns NaN: no solution is `None`, and infinitely many are a tagged
//! representative. `tol` is an absolute length tolerance (metres for a robot; `1e-9` suits
//! metre-sized problems in `f64`):
//!
//! - **Subproblem 1**: [`Sp1::One`]; [`Sp1::Any`] when `p` is on the axis and `q = p` (every
//!   angle works); `None` when the heights along `ω` or the distances from the axis differ by
//!   more than `tol` (including `p` on the axis and `q` off it).
//! - **Subproblem 2**: [`Sp2::Two`] when `γ² > 0`; [`Sp2::One`] at tangency (`γ² = 0`, or
//!   rounding made it slightly negative, within `tol`); `None` when `‖u‖ ≠ ‖v‖` or `γ² < 0`.
//!   Degenerate inputs give [`Sp2::Degenerate`] with a representative pair (free angles set to 0)
//!   and what is free ([`Sp2Freedom`]): parallel (hence coincident) axes, where only
//!   `θ₁ ± θ₂` is determined; `p` on axis 2 (`θ₂` free); `q` on axis 1 (`θ₁` free); `p = q = r`
//!   (both free).
//! - **Subproblem 3**: [`Sp3::Two`] inside the reachable band
//!   `|‖u'‖ - ‖v'‖| < δ' < ‖u'‖ + ‖v'‖`; [`Sp3::One`] on its edges (the point swings through the
//!   nearest or farthest position); `None` outside it or when `|ωᵀ(p - q)| > δ`; [`Sp3::Any`]
//!   when `p` or `q` is on the axis and the (then constant) distance equals `δ`.
//!
//! Angles are in `(-π, π]`.

use std::f64::consts::PI;

use anim_core::glam::DVec3;

/// The default length tolerance of the subproblems: `1e-9` (for metre-sized problems).
pub const DEFAULT_TOL: f64 = 1e-9;

/// Solutions of subproblem 1.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Sp1 {
    /// The unique angle.
    One(f64),
    /// Every angle solves it (`p = q` on the axis).
    Any,
}

impl Sp1 {
    /// The angle, with `0` standing for [`Sp1::Any`].
    #[must_use]
    pub fn angle(&self) -> f64 {
        match *self {
            Sp1::One(t) => t,
            Sp1::Any => 0.0,
        }
    }
}

/// Which angles of a degenerate subproblem 2 are free.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Sp2Freedom {
    /// `θ₁` is free (`q` is on axis 1); `θ₂` is determined.
    Theta1,
    /// `θ₂` is free (`p` is on axis 2); `θ₁` is determined.
    Theta2,
    /// Both are free (`p = q = r`).
    Both,
    /// The axes coincide with the same direction: only `θ₁ + θ₂` is determined.
    Sum,
    /// The axes coincide with opposite directions: only `θ₁ - θ₂` is determined.
    Difference,
}

/// Solutions of subproblem 2, as `(θ₁, θ₂)` pairs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Sp2 {
    /// Two distinct solutions.
    Two((f64, f64), (f64, f64)),
    /// One solution (tangency: the two circles touch).
    One((f64, f64)),
    /// Infinitely many; `representative` is one of them, with free angles set to `0`.
    Degenerate {
        /// One solution.
        representative: (f64, f64),
        /// What is free.
        freedom: Sp2Freedom,
    },
}

impl Sp2 {
    /// The distinct solutions (the representative for a degenerate problem).
    #[must_use]
    pub fn solutions(&self) -> Vec<(f64, f64)> {
        match *self {
            Sp2::Two(a, b) => vec![a, b],
            Sp2::One(a) => vec![a],
            Sp2::Degenerate { representative, .. } => vec![representative],
        }
    }
}

/// Solutions of subproblem 3.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Sp3 {
    /// Two distinct angles.
    Two(f64, f64),
    /// One angle (the distance is the smallest or largest reachable).
    One(f64),
    /// Every angle solves it (`p` or `q` on the axis at the right distance).
    Any,
}

impl Sp3 {
    /// The distinct angles (`0` for [`Sp3::Any`]).
    #[must_use]
    pub fn solutions(&self) -> Vec<f64> {
        match *self {
            Sp3::Two(a, b) => vec![a, b],
            Sp3::One(a) => vec![a],
            Sp3::Any => vec![0.0],
        }
    }
}

/// `e^{ξ̂θ} p` for the rotation by `theta` about the line through `r` along the unit `w`.
#[must_use]
pub fn rotate_about(w: DVec3, r: DVec3, theta: f64, p: DVec3) -> DVec3 {
    let u = p - r;
    let (s, c) = theta.sin_cos();
    r + u * c + w.cross(u) * s + w * (w.dot(u) * (1.0 - c))
}

/// The unit vector of `w`, or `None` when it is zero or not finite.
fn unit(w: DVec3) -> Option<DVec3> {
    let n = w.length();
    (n.is_finite() && n > 0.0).then(|| w / n)
}

/// Wraps an angle into `(-π, π]`.
#[must_use]
pub fn wrap_angle(t: f64) -> f64 {
    let mut a = t.rem_euclid(2.0 * PI);
    if a > PI {
        a -= 2.0 * PI;
    }
    a
}

/// The angle taking the plane vector `a` to `b` about `w` (both normal to `w`, nonzero).
fn plane_angle(w: DVec3, a: DVec3, b: DVec3) -> f64 {
    w.dot(a.cross(b)).atan2(a.dot(b))
}

/// Subproblem 1: the angle `θ` of the rotation about the axis through `r` along `w` that takes
/// `p` to `q`. See the [module documentation](self) for the branches.
#[must_use]
pub fn subproblem1(w: DVec3, r: DVec3, p: DVec3, q: DVec3, tol: f64) -> Option<Sp1> {
    let w = unit(w)?;
    let (u, v) = (p - r, q - r);
    if (w.dot(u) - w.dot(v)).abs() > tol {
        return None;
    }
    let up = u - w * w.dot(u);
    let vp = v - w * w.dot(v);
    let (nu, nv) = (up.length(), vp.length());
    if (nu - nv).abs() > tol {
        return None;
    }
    if nu <= tol || nv <= tol {
        return Some(Sp1::Any);
    }
    Some(Sp1::One(plane_angle(w, up, vp)))
}

/// Subproblem 2: angles `θ₁, θ₂` with `e^{ξ̂₁θ₁} e^{ξ̂₂θ₂} p = q` for rotations about the axes
/// along `w1` and `w2` through their common point `r`. See the [module documentation](self).
#[must_use]
pub fn subproblem2(w1: DVec3, w2: DVec3, r: DVec3, p: DVec3, q: DVec3, tol: f64) -> Option<Sp2> {
    let (w1, w2) = (unit(w1)?, unit(w2)?);
    let (u, v) = (p - r, q - r);
    let (nu, nv) = (u.length(), v.length());
    if (nu - nv).abs() > tol {
        return None;
    }
    if nu <= tol {
        // p = q = r: both angles free.
        return Some(Sp2::Degenerate { representative: (0.0, 0.0), freedom: Sp2Freedom::Both });
    }
    let cross = w1.cross(w2);
    let s2 = cross.length_squared();
    if s2 < 1e-18 {
        // Coincident axes: e^{ξ₁θ₁} e^{ξ₂θ₂} = e^{ξ₁(θ₁ ± θ₂)}.
        let same = w1.dot(w2) > 0.0;
        let freedom = if same { Sp2Freedom::Sum } else { Sp2Freedom::Difference };
        return match subproblem1(w1, r, p, q, tol)? {
            Sp1::One(phi) => Some(Sp2::Degenerate { representative: (phi, 0.0), freedom }),
            Sp1::Any => Some(Sp2::Degenerate { representative: (0.0, 0.0), freedom: Sp2Freedom::Both }),
        };
    }
    let c12 = w1.dot(w2);
    let (w2u, w1v) = (w2.dot(u), w1.dot(v));
    let den = c12 * c12 - 1.0;
    let alpha = (c12 * w2u - w1v) / den;
    let beta = (c12 * w1v - w2u) / den;
    let base = w1 * alpha + w2 * beta;
    let gamma2 = (u.length_squared() - base.length_squared()) / s2;
    // A length error of `tol` in u moves γ² by about 2‖u‖ tol / ‖ω₁ × ω₂‖².
    let gamma2_tol = 2.0 * tol * (nu + tol) / s2;
    if gamma2 < -gamma2_tol {
        return None;
    }
    let solve = |z: DVec3| -> Option<((f64, f64), bool, bool)> {
        let c = r + z;
        // e^{ξ₂θ₂} p = c and e^{ξ₁θ₁} c = q.
        let t2 = subproblem1(w2, r, p, c, tol)?;
        let t1 = subproblem1(w1, r, c, q, tol)?;
        Some(((t1.angle(), t2.angle()), t1 == Sp1::Any, t2 == Sp1::Any))
    };
    if gamma2 <= 0.0 {
        let (pair, free1, free2) = solve(base)?;
        return Some(match (free1, free2) {
            (true, true) => Sp2::Degenerate { representative: pair, freedom: Sp2Freedom::Both },
            (true, false) => Sp2::Degenerate { representative: pair, freedom: Sp2Freedom::Theta1 },
            (false, true) => Sp2::Degenerate { representative: pair, freedom: Sp2Freedom::Theta2 },
            (false, false) => Sp2::One(pair),
        });
    }
    let gamma = gamma2.sqrt();
    let (a, fa1, fa2) = solve(base + cross * gamma)?;
    let (b, fb1, fb2) = solve(base - cross * gamma)?;
    if fa1 || fa2 || fb1 || fb2 {
        // p on axis 2 or q on axis 1 with γ > 0 cannot happen for consistent input; report the
        // freedom of the first solution.
        let freedom = if fa1 || fb1 { Sp2Freedom::Theta1 } else { Sp2Freedom::Theta2 };
        return Some(Sp2::Degenerate { representative: a, freedom });
    }
    Some(Sp2::Two(a, b))
}

/// Subproblem 3: angles `θ` of the rotation about the axis through `r` along `w` that put `p`
/// at distance `delta` from `q`. See the [module documentation](self).
#[must_use]
pub fn subproblem3(w: DVec3, r: DVec3, p: DVec3, q: DVec3, delta: f64, tol: f64) -> Option<Sp3> {
    let w = unit(w)?;
    if !(delta >= 0.0) || !delta.is_finite() {
        return None;
    }
    let (u, v) = (p - r, q - r);
    let h = w.dot(p - q);
    let dp2 = delta * delta - h * h;
    // δ' < 0 beyond tolerance: the heights along ω already differ by more than δ.
    if dp2 < -2.0 * tol * (delta + tol) {
        return None;
    }
    let dp = dp2.max(0.0).sqrt();
    let up = u - w * w.dot(u);
    let vp = v - w * w.dot(v);
    let (nu, nv) = (up.length(), vp.length());
    if nu <= tol || nv <= tol {
        // The distance does not depend on θ: ‖u' - v'‖ with one of them zero.
        let d = (nu * nu + nv * nv).sqrt();
        return ((d - dp).abs() <= tol).then_some(Sp3::Any);
    }
    let theta0 = plane_angle(w, up, vp);
    let (lo, hi) = ((nu - nv).abs(), nu + nv);
    if dp < lo - tol || dp > hi + tol {
        return None;
    }
    let cos_phi = (nu * nu + nv * nv - dp * dp) / (2.0 * nu * nv);
    if cos_phi >= 1.0 {
        return Some(Sp3::One(wrap_angle(theta0)));
    }
    if cos_phi <= -1.0 {
        return Some(Sp3::One(wrap_angle(theta0 + PI)));
    }
    let phi = cos_phi.acos();
    Some(Sp3::Two(wrap_angle(theta0 - phi), wrap_angle(theta0 + phi)))
}

/// A companion of subproblem 3 used by the UR-type inverse kinematics: angles `θ` of the
/// rotation about the axis through `r` along `w` that bring `p` onto the plane `nᵀx = d`
/// (`n` a unit normal). Writing `e^{ξ̂θ} p = r + u_∥ + cos θ u' + sin θ (ω × u')`, the condition
/// is `A cos θ + B sin θ = C` with `A = nᵀu'`, `B = nᵀ(ω × u')`, `C = d - nᵀ(r + u_∥)`, so
/// `θ = atan2(B, A) ± acos(C / √(A² + B²))`.
///
/// [`Sp3::Two`] inside, [`Sp3::One`] at tangency (`|C| = √(A² + B²)`, within `tol`), `None`
/// beyond, and [`Sp3::Any`] when the circle lies in a plane parallel to `nᵀx = d` at distance
/// within `tol` (`A = B = 0`).
#[must_use]
pub fn subproblem_plane(w: DVec3, r: DVec3, p: DVec3, n: DVec3, d: f64, tol: f64) -> Option<Sp3> {
    let (w, n) = (unit(w)?, unit(n)?);
    if !d.is_finite() {
        return None;
    }
    let u = p - r;
    let u_par = w * w.dot(u);
    let up = u - u_par;
    let a = n.dot(up);
    let b = n.dot(w.cross(up));
    let c = d - n.dot(r + u_par);
    let rho = a.hypot(b);
    if rho <= tol {
        return (c.abs() <= tol).then_some(Sp3::Any);
    }
    if c.abs() > rho + tol {
        return None;
    }
    let theta0 = b.atan2(a);
    let ratio = c / rho;
    if ratio >= 1.0 {
        return Some(Sp3::One(wrap_angle(theta0)));
    }
    if ratio <= -1.0 {
        return Some(Sp3::One(wrap_angle(theta0 + PI)));
    }
    let phi = ratio.acos();
    Some(Sp3::Two(wrap_angle(theta0 - phi), wrap_angle(theta0 + phi)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn rand_unit(rng: &mut ChaCha8Rng) -> DVec3 {
        loop {
            let v = DVec3::new(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
            );
            if v.length() > 0.1 && v.length() < 1.0 {
                return v.normalize();
            }
        }
    }

    fn rand_point(rng: &mut ChaCha8Rng) -> DVec3 {
        DVec3::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0))
    }

    #[test]
    fn sp1_random_solvable() {
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        for _ in 0..2000 {
            let (w, r, p) = (rand_unit(&mut rng), rand_point(&mut rng), rand_point(&mut rng));
            let theta = rng.random_range(-PI..PI);
            let q = rotate_about(w, r, theta, p);
            let Some(Sp1::One(t)) = subproblem1(w, r, p, q, DEFAULT_TOL) else { panic!("unsolved") };
            assert!((rotate_about(w, r, t, p) - q).length() < 1e-12);
            assert!((wrap_angle(t - theta)).abs() < 1e-9);
        }
    }

    #[test]
    fn sp1_branches() {
        let (w, r) = (DVec3::Z, DVec3::ZERO);
        // Point on the axis, q = p: any angle.
        assert_eq!(subproblem1(w, r, DVec3::Z, DVec3::Z, DEFAULT_TOL), Some(Sp1::Any));
        // Point on the axis, q elsewhere: none.
        assert_eq!(subproblem1(w, r, DVec3::Z, DVec3::X, DEFAULT_TOL), None);
        // Different heights or radii: none.
        assert_eq!(subproblem1(w, r, DVec3::X, DVec3::new(0.0, 1.0, 0.5), DEFAULT_TOL), None);
        assert_eq!(subproblem1(w, r, DVec3::X, DVec3::Y * 2.0, DEFAULT_TOL), None);
        // Half turn.
        let Some(Sp1::One(t)) = subproblem1(w, r, DVec3::X, -DVec3::X, DEFAULT_TOL) else { panic!() };
        assert!((t.abs() - PI).abs() < 1e-15);
        // A zero axis is no problem to solve.
        assert_eq!(subproblem1(DVec3::ZERO, r, DVec3::X, DVec3::X, DEFAULT_TOL), None);
    }

    fn sp2_residual(w1: DVec3, w2: DVec3, r: DVec3, p: DVec3, q: DVec3, (t1, t2): (f64, f64)) -> f64 {
        (rotate_about(w1, r, t1, rotate_about(w2, r, t2, p)) - q).length()
    }

    #[test]
    fn sp2_random_solvable_two_solutions() {
        let mut rng = ChaCha8Rng::seed_from_u64(2);
        let mut twos = 0;
        for _ in 0..2000 {
            let (w1, w2, r, p) =
                (rand_unit(&mut rng), rand_unit(&mut rng), rand_point(&mut rng), rand_point(&mut rng));
            let (a, b) = (rng.random_range(-PI..PI), rng.random_range(-PI..PI));
            let q = rotate_about(w1, r, a, rotate_about(w2, r, b, p));
            let sol = subproblem2(w1, w2, r, p, q, DEFAULT_TOL).expect("solvable");
            let sols = sol.solutions();
            if matches!(sol, Sp2::Two(..)) {
                twos += 1;
            }
            for s in &sols {
                assert!(sp2_residual(w1, w2, r, p, q, *s) < 1e-10, "{sol:?}");
            }
            // The generating pair is one of the solutions (unless tangent, where both coincide).
            assert!(
                sols.iter().any(|s| wrap_angle(s.0 - a).abs() < 1e-6 && wrap_angle(s.1 - b).abs() < 1e-6)
            );
        }
        assert!(twos > 1900);
    }

    #[test]
    fn sp2_branches() {
        let r = DVec3::ZERO;
        let (w1, w2) = (DVec3::Z, DVec3::X);
        // Tangency: p on the cone of axis 2 touches the cone of axis 1 in one point.
        // Rotating p = (0, 1, 0) about x sweeps the circle y² + z² = 1 in the x = 0 plane;
        // rotating q = (1, 0, 0) about z sweeps the circle x² + y² = 1 in z = 0; they touch at
        // (0, ±1, 0): two solutions. A tangent case: p = (0, 0, 1) about x gives the same circle;
        // q = (0, 0, 1) on axis 1: θ₁ free.
        let s = subproblem2(w1, w2, r, DVec3::Z, DVec3::Z, DEFAULT_TOL).unwrap();
        assert!(matches!(s, Sp2::Degenerate { freedom: Sp2Freedom::Theta1, .. }), "{s:?}");
        assert!(sp2_residual(w1, w2, r, DVec3::Z, DVec3::Z, s.solutions()[0]) < 1e-15);
        // p on axis 2: θ₂ free.
        let q = rotate_about(w1, r, 0.7, DVec3::X);
        let s = subproblem2(w1, w2, r, DVec3::X, q, DEFAULT_TOL).unwrap();
        assert!(matches!(s, Sp2::Degenerate { freedom: Sp2Freedom::Theta2, .. }), "{s:?}");
        assert!(sp2_residual(w1, w2, r, DVec3::X, q, s.solutions()[0]) < 1e-15);
        // True tangency (γ = 0): the intermediate point c = αω₁ + βω₂ lies in the plane of the
        // axes. On the cone of ω₂ through p: ω₂ᵀc = ω₂ᵀp =: b and ‖c‖ = ‖p‖, which gives
        // α² (1 - c₁₂²) = ‖p‖² - b², β = b - α c₁₂.
        let w2b = DVec3::new(1.0, 0.0, 1.0).normalize();
        let p = DVec3::new(0.3, 0.5, -0.2);
        let (c12, b) = (w1.dot(w2b), w2b.dot(p));
        let alpha = ((p.length_squared() - b * b) / (1.0 - c12 * c12)).sqrt();
        let c = w1 * alpha + w2b * (b - alpha * c12);
        let q = rotate_about(w1, r, 1.1, c);
        let s = subproblem2(w1, w2b, r, p, q, DEFAULT_TOL).unwrap();
        assert!(matches!(s, Sp2::One(_)), "{s:?}");
        assert!(sp2_residual(w1, w2b, r, p, q, s.solutions()[0]) < 1e-12, "{s:?}");
        // Nudged outward by 1e-6, it has no solution; inward, two.
        let out = rotate_about(w1, r, 1.1, c + w1.cross(w2b).normalize() * 0.0 + w1 * 1e-6);
        let out = r + (out - r).normalize() * p.length();
        assert!(!matches!(subproblem2(w1, w2b, r, p, out, DEFAULT_TOL), Some(Sp2::One(_))));
        // Unreachable: q at the wrong distance from r.
        assert_eq!(subproblem2(w1, w2, r, DVec3::X, DVec3::Y * 2.0, DEFAULT_TOL), None);
        // Unreachable: circles do not meet (p's circle about x is y² + z² = 1 at x = 0; q on
        // the circle x² + y² = 0.36, z = 0.8 about z: meets where y = ±0.6... use x offset).
        let p = DVec3::new(0.8, 0.6, 0.0); // circle about x: x = 0.8, y² + z² = 0.36
        let q = DVec3::new(0.0, 0.0, 1.0); // on axis 1, at height 1: only (0, 0, 1)
        assert_eq!(subproblem2(w1, w2, r, p, q, DEFAULT_TOL), None);
        // Coincident axes: only the sum is determined.
        let q = rotate_about(w1, r, 0.9, DVec3::X);
        let s = subproblem2(w1, w1, r, DVec3::X, q, DEFAULT_TOL).unwrap();
        assert!(matches!(s, Sp2::Degenerate { freedom: Sp2Freedom::Sum, .. }));
        assert!(sp2_residual(w1, w1, r, DVec3::X, q, s.solutions()[0]) < 1e-15);
        let s = subproblem2(w1, -w1, r, DVec3::X, q, DEFAULT_TOL).unwrap();
        assert!(matches!(s, Sp2::Degenerate { freedom: Sp2Freedom::Difference, .. }));
        assert!(sp2_residual(w1, -w1, r, DVec3::X, q, s.solutions()[0]) < 1e-15);
        // Both free.
        let s = subproblem2(w1, w2, r, r, r, DEFAULT_TOL).unwrap();
        assert!(matches!(s, Sp2::Degenerate { freedom: Sp2Freedom::Both, .. }));
    }

    #[test]
    fn plane_subproblem_random_and_branches() {
        let mut rng = ChaCha8Rng::seed_from_u64(4);
        for _ in 0..2000 {
            let (w, r, p, n) =
                (rand_unit(&mut rng), rand_point(&mut rng), rand_point(&mut rng), rand_unit(&mut rng));
            let theta = rng.random_range(-PI..PI);
            let d = n.dot(rotate_about(w, r, theta, p));
            let s = subproblem_plane(w, r, p, n, d, DEFAULT_TOL).expect("solvable");
            for t in s.solutions() {
                assert!((n.dot(rotate_about(w, r, t, p)) - d).abs() < 1e-10, "{s:?}");
            }
            assert!(s.solutions().iter().any(|t| wrap_angle(t - theta).abs() < 1e-6));
        }
        // Circle of radius 1 about z in the plane z = 0; plane x = d.
        let (w, r, p) = (DVec3::Z, DVec3::ZERO, DVec3::X);
        assert!(
            matches!(subproblem_plane(w, r, p, DVec3::X, 1.0, DEFAULT_TOL), Some(Sp3::One(t)) if t.abs() < 1e-15)
        );
        assert!(matches!(subproblem_plane(w, r, p, DVec3::X, 0.5, DEFAULT_TOL), Some(Sp3::Two(..))));
        assert_eq!(subproblem_plane(w, r, p, DVec3::X, 1.5, DEFAULT_TOL), None);
        // Plane parallel to the circle.
        assert_eq!(subproblem_plane(w, r, p, DVec3::Z, 0.0, DEFAULT_TOL), Some(Sp3::Any));
        assert_eq!(subproblem_plane(w, r, p, DVec3::Z, 0.1, DEFAULT_TOL), None);
    }

    #[test]
    fn sp3_random_and_branches() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        for _ in 0..2000 {
            let (w, r, p, q) =
                (rand_unit(&mut rng), rand_point(&mut rng), rand_point(&mut rng), rand_point(&mut rng));
            let theta = rng.random_range(-PI..PI);
            let delta = (rotate_about(w, r, theta, p) - q).length();
            let s = subproblem3(w, r, p, q, delta, DEFAULT_TOL).expect("solvable");
            for t in s.solutions() {
                assert!(((rotate_about(w, r, t, p) - q).length() - delta).abs() < 1e-10, "{s:?}");
            }
            assert!(s.solutions().iter().any(|t| wrap_angle(t - theta).abs() < 1e-6));
        }
        let (w, r) = (DVec3::Z, DVec3::ZERO);
        let (p, q) = (DVec3::X, DVec3::X * 3.0);
        // Band [2, 4]: edges give one solution, outside none.
        assert!(matches!(subproblem3(w, r, p, q, 2.0, DEFAULT_TOL), Some(Sp3::One(t)) if t.abs() < 1e-15));
        assert!(
            matches!(subproblem3(w, r, p, q, 4.0, DEFAULT_TOL), Some(Sp3::One(t)) if (t.abs() - PI).abs() < 1e-15)
        );
        assert!(matches!(subproblem3(w, r, p, q, 3.0, DEFAULT_TOL), Some(Sp3::Two(..))));
        assert_eq!(subproblem3(w, r, p, q, 1.9, DEFAULT_TOL), None);
        assert_eq!(subproblem3(w, r, p, q, 4.1, DEFAULT_TOL), None);
        // Height difference larger than δ.
        assert_eq!(subproblem3(w, r, p, DVec3::new(3.0, 0.0, 5.0), 4.0, DEFAULT_TOL), None);
        // p on the axis: distance constant = √10 from q = (3, 0, 0) at p = (0, 0, 1).
        assert_eq!(subproblem3(w, r, DVec3::Z, q, 10f64.sqrt(), DEFAULT_TOL), Some(Sp3::Any));
        assert_eq!(subproblem3(w, r, DVec3::Z, q, 3.0, DEFAULT_TOL), None);
        // Negative or NaN distance.
        assert_eq!(subproblem3(w, r, p, q, -1.0, DEFAULT_TOL), None);
        assert_eq!(subproblem3(w, r, p, q, f64::NAN, DEFAULT_TOL), None);
    }
}
