//! The conformance checks of every model: `P` and `dP/dF` against finite differences, rotation
//! invariance, the rest state and small-strain agreement with linear elasticity, f32 against f64.

use super::{AllImpls, FlatVec, KINDS, Kind, check, fd_errors, lame, rotation, sample};
use crate::{Hyperelastic, Lame, LinearElastic, Mat};
use anim_core::cases::{Check, Ctx, Judge};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

pub(super) fn finite_differences(ctx: &Ctx) -> Vec<Check> {
    let per_kind = if ctx.quick { 10 } else { 100 };
    fn run<M: AllImpls>(m: M, name: &str, inv: bool, per_kind: usize) -> Vec<Check> {
        fn one<M: Hyperelastic<f64, D>, const D: usize>(
            m: &M,
            name: &str,
            inv: bool,
            per_kind: usize,
        ) -> Vec<Check> {
            let lame = lame();
            let mut rng = ChaCha8Rng::seed_from_u64(900 + D as u64);
            let (mut wp, mut wt, mut n) = (0.0f64, 0.0f64, 0);
            for kind in KINDS {
                if !inv && matches!(kind, Kind::Inverted | Kind::Degenerate) {
                    continue;
                }
                for _ in 0..per_kind {
                    let f = sample::<D>(kind, &mut rng);
                    let (p, t) = fd_errors(m, &lame, &f);
                    wp = wp.max(p);
                    wt = wt.max(t);
                    n += 1;
                }
            }
            let kinds = if inv { "incl. inverted and det F = 0" } else { "det F > 0 only" };
            let src = "4th-order central differences, h = 1e-3 min(1, max(|sigma_min|, 1e-3))";
            vec![
                check(
                    format!("{name} {D}D, {n} F ({kinds})"),
                    "max |P - FD psi| / max(|P|, mu + lambda)",
                    wp,
                    1e-6,
                    Judge::AtMost,
                    src,
                ),
                check(
                    format!("{name} {D}D, {n} F ({kinds})"),
                    "max |dP/dF - FD P| / max(|dP/dF|, mu + lambda)",
                    wt,
                    1e-6,
                    Judge::AtMost,
                    src,
                ),
            ]
        }
        let mut v = one::<M, 2>(&m, name, inv, per_kind);
        v.extend(one::<M, 3>(&m, name, inv, per_kind));
        v
    }
    per_model!(run, per_kind)
}

pub(super) fn invariance(ctx: &Ctx) -> Vec<Check> {
    let per_kind = if ctx.quick { 20 } else { 200 };
    fn run<M: AllImpls>(m: M, name: &str, inv: bool, per_kind: usize) -> Vec<Check> {
        fn one<M: Hyperelastic<f64, D>, const D: usize>(
            m: &M,
            name: &str,
            inv: bool,
            per_kind: usize,
        ) -> Vec<Check> {
            let lame = lame();
            let scale = lame.mu + lame.lambda;
            let mut rng = ChaCha8Rng::seed_from_u64(910 + D as u64);
            let (mut de, mut dp) = (0.0f64, 0.0f64);
            for kind in KINDS {
                if !inv && matches!(kind, Kind::Inverted | Kind::Degenerate) {
                    continue;
                }
                for _ in 0..per_kind {
                    let f = sample::<D>(kind, &mut rng);
                    let q = rotation::<D>(&mut rng);
                    let e0 = m.energy(&lame, &f);
                    de = de.max((e0 - m.energy(&lame, &(q * f))).abs() / e0.abs().max(scale));
                    let p0 = m.pk1(&lame, &f);
                    dp = dp.max((q * p0 - m.pk1(&lame, &(q * f))).norm() / p0.norm().max(scale));
                }
            }
            if name == "LinearElastic" {
                // Small strain is not frame invariant: the violation must be visible.
                return vec![check(
                    format!("{name} {D}D (not invariant by design)"),
                    "max |psi(QF) - psi(F)| / max(|psi|, mu + lambda)",
                    de,
                    1e-2,
                    Judge::AtLeast,
                    "Sifakis & Barbič 2012: small strain cannot guarantee rotational invariance",
                )];
            }
            vec![
                check(
                    format!("{name} {D}D"),
                    "max |psi(QF) - psi(F)| / max(|psi|, mu + lambda)",
                    de,
                    1e-12,
                    Judge::AtMost,
                    "frame indifference, random rotations Q",
                ),
                check(
                    format!("{name} {D}D"),
                    "max |P(QF) - Q P(F)| / max(|P|, mu + lambda)",
                    dp,
                    1e-12,
                    Judge::AtMost,
                    "frame indifference, random rotations Q",
                ),
            ]
        }
        let mut v = one::<M, 2>(&m, name, inv, per_kind);
        v.extend(one::<M, 3>(&m, name, inv, per_kind));
        v
    }
    per_model!(run, per_kind)
}

pub(super) fn small_strain(ctx: &Ctx) -> Vec<Check> {
    let samples = if ctx.quick { 10 } else { 100 };
    fn run<M: AllImpls>(m: M, name: &str, _inv: bool, samples: usize) -> Vec<Check> {
        fn one<M: Hyperelastic<f64, D>, const D: usize>(m: &M, name: &str, samples: usize) -> Vec<Check> {
            let lame = lame();
            let scale = lame.mu + lame.lambda;
            let id = Mat::<f64, D>::identity();
            let mut out = Vec::new();
            let mut rng = ChaCha8Rng::seed_from_u64(920 + D as u64);
            let mut rest = m.energy(&lame, &id).abs().max(m.pk1(&lame, &id).norm()) / lame.mu;
            if name != "LinearElastic" {
                for _ in 0..samples {
                    let q = rotation::<D>(&mut rng);
                    rest = rest.max(m.pk1(&lame, &q).norm() / lame.mu);
                }
            }
            out.push(check(
                format!("{name} {D}D"),
                if name == "LinearElastic" {
                    "max(|psi(I)|, |P(I)|) / mu"
                } else {
                    "max(|psi(I)|, |P(I)|, |P(Q)|) / mu"
                },
                rest,
                1e-11,
                Judge::AtMost,
                "psi(I) = 0, P(I) = 0; P(Q) = 0 for rotations",
            ));
            if name == "LinearElastic" {
                return out;
            }
            let (t, tl) = (m.dpdf(&lame, &id), LinearElastic.dpdf(&lame, &id));
            let diff = (t.to_flat_vec().iter().zip(tl.to_flat_vec()).map(|(a, b)| (a - b).abs()))
                .fold(0.0f64, f64::max)
                / scale;
            out.push(check(
                format!("{name} {D}D"),
                "max |dP/dF(I) - C_linear| / (mu + lambda)",
                diff,
                1e-12,
                Judge::AtMost,
                "linear elasticity, Sifakis & Barbič 2012",
            ));
            // Order of the stress difference: P(I + eps H) - P_lin(I + eps H) = O(eps^2).
            let mut orders = Vec::new();
            for _ in 0..samples {
                let h = Mat::<f64, D>::from_fn(|_, _| rng.random_range(-1.0..1.0));
                let err = |eps: f64| {
                    let f = id + h * eps;
                    (m.pk1(&lame, &f) - LinearElastic.pk1(&lame, &f)).norm()
                };
                orders.push((err(1e-3) / err(1e-4)).log10());
            }
            orders.sort_by(f64::total_cmp);
            let mut c = check(
                format!("{name} {D}D, {samples} directions H, eps 1e-3 -> 1e-4"),
                "min observed order of |P - P_linear|",
                orders[0],
                0.1,
                Judge::Near,
                "first-order agreement: the difference is O(eps^2)",
            );
            c.reference = 2.0;
            out.push(c);
            out
        }
        let mut v = one::<M, 2>(&m, name, samples);
        v.extend(one::<M, 3>(&m, name, samples));
        v
    }
    per_model!(run, samples)
}

pub(super) fn precision(ctx: &Ctx) -> Vec<Check> {
    let samples = if ctx.quick { 30 } else { 300 };
    fn run<M: AllImpls>(m: M, name: &str, _inv: bool, samples: usize) -> Vec<Check> {
        fn one<M: Hyperelastic<f64, D> + Hyperelastic<f32, D>, const D: usize>(
            m: &M,
            name: &str,
            samples: usize,
        ) -> Vec<Check> {
            let l = lame();
            let l32 = Lame::<f32> { mu: l.mu as f32, lambda: l.lambda as f32 };
            let l64 = Lame::<f64> { mu: f64::from(l32.mu), lambda: f64::from(l32.lambda) };
            let scale = l64.mu + l64.lambda;
            let mut rng = ChaCha8Rng::seed_from_u64(930 + D as u64);
            let mut worst = 0.0f64;
            for kind in [Kind::General, Kind::Rotation, Kind::Stretch] {
                for _ in 0..samples {
                    let f32m = sample::<D>(kind, &mut rng).map(|x| x as f32);
                    let f = f32m.map(f64::from);
                    let p = Hyperelastic::<f64, D>::pk1(m, &l64, &f);
                    let p32 = Hyperelastic::<f32, D>::pk1(m, &l32, &f32m).map(f64::from);
                    let t = Hyperelastic::<f64, D>::dpdf(m, &l64, &f).to_flat_vec();
                    let t32 = Hyperelastic::<f32, D>::dpdf(m, &l32, &f32m).to_flat_vec();
                    let e = Hyperelastic::<f64, D>::energy(m, &l64, &f);
                    let e32 = f64::from(Hyperelastic::<f32, D>::energy(m, &l32, &f32m));
                    worst = worst
                        .max((e - e32).abs() / e.abs().max(scale))
                        .max((p - p32).norm() / p.norm().max(scale))
                        .max(t.iter().zip(&t32).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max) / scale);
                }
            }
            vec![check(
                format!("{name} {D}D, {} F with det F > 0", 3 * samples),
                "max relative |f32 - f64| over psi, P, dP/dF",
                worst,
                2e-5,
                Judge::AtMost,
                "f64 evaluation on the same f32 input; eps_f32 = 1.2e-7",
            )]
        }
        let mut v = one::<M, 2>(&m, name, samples);
        v.extend(one::<M, 3>(&m, name, samples));
        v
    }
    per_model!(run, samples)
}
