//! The analytic PSD projection of the corotated and stable Neo-Hookean tangents against the
//! numerical eigenvalue clamping.

use super::{FlatVec, KINDS, check, lame, sample};
use crate::{CorotatedLinear, FixedCorotated, Hyperelastic, StableNeoHookean};
use anim_core::cases::{Check, Ctx, Judge};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

pub(super) fn psd_projection(ctx: &Ctx) -> Vec<Check> {
    let samples = if ctx.quick { 20 } else { 200 };
    let lame = lame();
    let mut out = Vec::new();
    let mut rng = ChaCha8Rng::seed_from_u64(940);
    let mut worst = [0.0f64; 6];
    let mut min_eig = 0.0f64;
    for kind in KINDS {
        for _ in 0..samples {
            let f3 = sample::<3>(kind, &mut rng);
            let f2 = sample::<2>(kind, &mut rng);
            for (k, (a, n)) in [
                (
                    FixedCorotated.dpdf_psd(&lame, &f3).to_flat_vec(),
                    FixedCorotated.dpdf(&lame, &f3).project_psd(),
                ),
                (
                    CorotatedLinear.dpdf_psd(&lame, &f3).to_flat_vec(),
                    CorotatedLinear.dpdf(&lame, &f3).project_psd(),
                ),
                (
                    StableNeoHookean.dpdf_psd(&lame, &f3).to_flat_vec(),
                    StableNeoHookean.dpdf(&lame, &f3).project_psd(),
                ),
            ]
            .into_iter()
            .enumerate()
            {
                let nm = n.to_matrix();
                let ev = nm.symmetric_eigenvalues();
                min_eig = min_eig.min(ev.iter().copied().fold(f64::INFINITY, f64::min) / nm.norm());
                let nf = n.to_flat_vec();
                let d = a.iter().zip(&nf).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max) / nm.norm();
                worst[k] = worst[k].max(d);
            }
            for (k, (a, n)) in [
                (FixedCorotated.dpdf_psd(&lame, &f2), FixedCorotated.dpdf(&lame, &f2).project_psd()),
                (CorotatedLinear.dpdf_psd(&lame, &f2), CorotatedLinear.dpdf(&lame, &f2).project_psd()),
                (StableNeoHookean.dpdf_psd(&lame, &f2), StableNeoHookean.dpdf(&lame, &f2).project_psd()),
            ]
            .into_iter()
            .enumerate()
            {
                let d = (a.to_matrix() - n.to_matrix()).norm() / n.to_matrix().norm();
                worst[3 + k] = worst[3 + k].max(d);
            }
        }
    }
    for (k, label) in [
        "FixedCorotated 3D",
        "CorotatedLinear 3D",
        "StableNeoHookean 3D",
        "FixedCorotated 2D",
        "CorotatedLinear 2D",
        "StableNeoHookean 2D",
    ]
    .iter()
    .enumerate()
    {
        out.push(check(
            format!("{label}, {} F of all kinds", 6 * samples),
            "max |analytic projection - clamped eigendecomposition| / |H+|",
            worst[k],
            1e-9,
            Judge::AtMost,
            "Smith, de Goes & Kim 2019 eigensystem vs nalgebra SymmetricEigen",
        ));
    }
    let mut c = check(
        "all projected 3D tangents".into(),
        "min eigenvalue / |H+|",
        min_eig,
        1e-12,
        Judge::Near,
        "PSD after projection (rounding only)",
    );
    c.reference = 0.0;
    out.push(c);
    out
}
