//! Hard cases: the inversion-robust models on inverted and degenerate `F`, and Neo-Hookean
//! reporting its undefined region.

use super::lame;
use crate::nalgebra::Vector3;
use crate::{FixedCorotated, Hyperelastic, Mat, NeoHookean, StableNeoHookean};
use anim_core::cases::{Ctx, Outcome};

/// Degenerate and inverted deformation gradients of the hard cases.
fn hard_fs() -> Vec<(&'static str, Mat<f64, 3>)> {
    vec![
        ("F = 0", Mat::<f64, 3>::zeros()),
        ("det F = 0 (flattened)", Mat::<f64, 3>::from_diagonal(&Vector3::new(1.0, 1.0, 0.0))),
        ("rank 1", Mat::<f64, 3>::from_diagonal(&Vector3::new(1.5, 0.0, 0.0))),
        ("reflection diag(1, 1, -1)", Mat::<f64, 3>::from_diagonal(&Vector3::new(1.0, 1.0, -1.0))),
        ("point reflection -I", -Mat::<f64, 3>::identity()),
        ("inverted diag(2, 0.5, -0.1)", Mat::<f64, 3>::from_diagonal(&Vector3::new(2.0, 0.5, -0.1))),
        ("compressed 1e-6 I", Mat::<f64, 3>::identity() * 1e-6),
    ]
}

pub(super) fn inversion_robust(_ctx: &Ctx) -> Outcome {
    let lame = lame();
    let mut worst_p = 0.0f64;
    for (what, f) in hard_fs() {
        let f2 = Mat::<f64, 2>::from_fn(|i, j| {
            f[(i, j)] * if (i, j) == (1, 1) { f[(2, 2)].signum() } else { 1.0 }
        });
        for (name, e, p, t, e2, p2) in [
            (
                "FixedCorotated",
                FixedCorotated.energy(&lame, &f),
                FixedCorotated.pk1(&lame, &f),
                FixedCorotated.dpdf(&lame, &f),
                FixedCorotated.energy(&lame, &f2),
                FixedCorotated.pk1(&lame, &f2),
            ),
            (
                "StableNeoHookean",
                StableNeoHookean.energy(&lame, &f),
                StableNeoHookean.pk1(&lame, &f),
                StableNeoHookean.dpdf(&lame, &f),
                StableNeoHookean.energy(&lame, &f2),
                StableNeoHookean.pk1(&lame, &f2),
            ),
        ] {
            let finite = e.is_finite()
                && p.iter().all(|x| x.is_finite())
                && t.is_finite()
                && e2.is_finite()
                && p2.iter().all(|x| x.is_finite());
            if !finite {
                return Outcome::Diverged(format!("{name}: non-finite output at {what}"));
            }
            worst_p = worst_p.max(p.norm() / (lame.mu + lame.lambda));
        }
    }
    // Inverted elements are pushed back towards det F > 0: P_22 < 0 at sigma_2 < 0.
    let f = Mat::<f64, 3>::from_diagonal(&Vector3::new(1.0, 1.0, -0.5));
    let (pf, ps) = (FixedCorotated.pk1(&lame, &f)[(2, 2)], StableNeoHookean.pk1(&lame, &f)[(2, 2)]);
    if !(pf < 0.0 && ps < 0.0) {
        return Outcome::Diverged(format!("inverted element not restored: P_22 = {pf}, {ps}"));
    }
    Outcome::Stable(format!(
        "finite psi, P, dP/dF (3D) and psi, P (2D) at {} degenerate/inverted F; max ‖P‖/(mu + lambda) = {worst_p:.3}; restoring P_22 = {pf:.0} (FCR), {ps:.0} (SNH) at sigma = (1, 1, -0.5)",
        hard_fs().len()
    ))
}

pub(super) fn neo_hookean_inverted(_ctx: &Ctx) -> Outcome {
    let lame = lame();
    let mut reported = 0;
    for (what, f) in hard_fs() {
        let defined = NeoHookean::is_defined(&f);
        let (e, p) = (NeoHookean.energy(&lame, &f), NeoHookean.pk1(&lame, &f));
        if defined {
            if !e.is_finite() {
                return Outcome::Diverged(format!("non-finite energy at {what} although det F > 0"));
            }
        } else if e.is_finite() || p.iter().any(|x| x.is_finite()) {
            return Outcome::Diverged(format!("finite output at {what} outside the domain det F > 0"));
        } else {
            reported += 1;
        }
    }
    Outcome::Rejected(format!(
        "all {reported} F with det F <= 0 reported as psi = +inf, P = NaN; the barely positive 1e-6 I (det 1e-18) stays finite"
    ))
}
