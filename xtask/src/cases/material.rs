//! anim-material: every model's stress `P` against central differences of its energy and its
//! `dP/dF` against central differences of `P`, over a fixed ChaCha-seeded set of deformation
//! gradients (general, pure rotations, stretches with repeated values, near-singular `det F ~
//! 1e-3`, inverted, `det F = 0`); rotation invariance; zero stress at rest and under rotation;
//! agreement with linear elasticity at small strain (tangent at `F = I` and the `O(eps^2)` order
//! of the stress difference); f32 against f64; the analytic PSD projection against the
//! numerical one. Hard cases: the inversion-robust models on inverted and degenerate `F`, and
//! Neo-Hookean reporting its undefined region.

use crate::registry::{Check, ConformanceCase, Ctx, Judge, Outcome, Registry, StabilityCase};
use anim_material::nalgebra::{Rotation2, Rotation3, SVector, Vector3};
use anim_material::{
    CorotatedLinear, FixedCorotated, Hyperelastic, Lame, LinearElastic, Mat, NeoHookean, StVenantKirchhoff,
    StableNeoHookean, Tangent, svd,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

const CRATE: &str = "anim-material";

pub fn register(r: &mut Registry) {
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "P and dP/dF vs finite differences",
        run: Box::new(finite_differences),
    });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "rotation invariance",
        run: Box::new(invariance),
    });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "rest state and small-strain agreement with linear elasticity",
        run: Box::new(small_strain),
    });
    r.conformance.push(ConformanceCase { crate_name: CRATE, name: "f32 vs f64", run: Box::new(precision) });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "analytic PSD projection vs eigenvalue clamping",
        run: Box::new(psd_projection),
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "stable Neo-Hookean and fixed corotated on inverted and degenerate F",
        expected: || Outcome::Stable(String::new()),
        run: inversion_robust,
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "Neo-Hookean reports det F <= 0 as non-finite",
        expected: || Outcome::Rejected(String::new()),
        run: neo_hookean_inverted,
    });
}

/// E = 1e4, nu = 0.3.
fn lame() -> Lame<f64> {
    Lame::from_young_poisson(1e4, 0.3).unwrap_or(Lame { mu: f64::NAN, lambda: f64::NAN })
}

fn rotation<const D: usize>(rng: &mut ChaCha8Rng) -> Mat<f64, D> {
    if D == 2 {
        let r = Rotation2::new(rng.random_range(-std::f64::consts::PI..std::f64::consts::PI));
        Mat::<f64, D>::from_fn(|i, j| r.matrix()[(i, j)])
    } else {
        let axis: Vector3<f64> = Vector3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        );
        let r = Rotation3::new(axis * (3.0 / axis.norm().max(1e-3)) * rng.random_range(0.0..1.0));
        Mat::<f64, D>::from_fn(|i, j| r.matrix()[(i, j)])
    }
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Kind {
    General,
    Rotation,
    Stretch,
    NearSingular,
    Inverted,
    Degenerate,
}

const KINDS: [Kind; 6] =
    [Kind::General, Kind::Rotation, Kind::Stretch, Kind::NearSingular, Kind::Inverted, Kind::Degenerate];

fn sample<const D: usize>(kind: Kind, rng: &mut ChaCha8Rng) -> Mat<f64, D> {
    let mut s = SVector::<f64, D>::from_fn(|_, _| rng.random_range(0.5..2.0));
    let (r1, r2) = (rotation::<D>(rng), rotation::<D>(rng));
    match kind {
        Kind::General => r1 * Mat::from_diagonal(&s) * r2.transpose(),
        Kind::Rotation => r1,
        Kind::Stretch => {
            if rng.random_bool(0.5) {
                s[1] = s[0];
            }
            Mat::from_diagonal(&s)
        }
        Kind::NearSingular => {
            s[D - 1] = 1e-3;
            r1 * Mat::from_diagonal(&s) * r2.transpose()
        }
        Kind::Inverted => {
            // sigma_{d-2} + sigma_{d-1} kept away from 0 (the corotated R is not differentiable there).
            // The negative value is the smallest in magnitude, so the others are >= 1.
            for k in 0..D - 1 {
                s[k] = rng.random_range(1.0..2.0);
            }
            s[D - 1] = -rng.random_range(0.05..0.6);
            r1 * Mat::from_diagonal(&s) * r2.transpose()
        }
        Kind::Degenerate => {
            s[D - 1] = 0.0;
            r1 * Mat::from_diagonal(&s) * r2.transpose()
        }
    }
}

fn fd4<R>(g: impl Fn(f64) -> R, h: f64) -> R
where
    R: std::ops::Sub<Output = R> + std::ops::Mul<f64, Output = R> + Copy,
{
    ((g(h) - g(-h)) * 8.0 - (g(2.0 * h) - g(-2.0 * h))) * (1.0 / (12.0 * h))
}

/// (P vs FD psi, dP/dF vs FD P), relative to `max(|analytic|, mu + lambda)`.
fn fd_errors<M: Hyperelastic<f64, D>, const D: usize>(
    m: &M,
    lame: &Lame<f64>,
    f: &Mat<f64, D>,
) -> (f64, f64) {
    let scale = lame.mu + lame.lambda.abs();
    let h = 1e-3 * svd(f).sigma[D - 1].abs().clamp(1e-3, 1.0);
    let p = m.pk1(lame, f);
    let t = m.dpdf(lame, f);
    let mut p_fd = Mat::<f64, D>::zeros();
    let mut t_err = 0.0f64;
    for k in 0..D {
        for l in 0..D {
            let mut e = Mat::<f64, D>::zeros();
            e[(k, l)] = 1.0;
            p_fd[(k, l)] = fd4(|x| m.energy(lame, &(f + e * x)), h);
            let col = fd4(|x| m.pk1(lame, &(f + e * x)), h);
            t_err = t_err.max((t.d[k][l] - col).norm());
        }
    }
    ((p - p_fd).norm() / p.norm().max(scale), t_err / t.norm().max(scale))
}

trait AllImpls:
    Hyperelastic<f64, 2> + Hyperelastic<f64, 3> + Hyperelastic<f32, 2> + Hyperelastic<f32, 3> + Copy
{
}
impl<M: Hyperelastic<f64, 2> + Hyperelastic<f64, 3> + Hyperelastic<f32, 2> + Hyperelastic<f32, 3> + Copy>
    AllImpls for M
{
}

/// Calls `$f(model, name, defined_under_inversion)` for every model.
macro_rules! per_model {
    ($f:ident, $($arg:expr),*) => {{
        let mut out = Vec::new();
        out.extend($f(LinearElastic, "LinearElastic", true, $($arg),*));
        out.extend($f(StVenantKirchhoff, "StVenantKirchhoff", true, $($arg),*));
        out.extend($f(CorotatedLinear, "CorotatedLinear", true, $($arg),*));
        out.extend($f(NeoHookean, "NeoHookean", false, $($arg),*));
        out.extend($f(FixedCorotated, "FixedCorotated", true, $($arg),*));
        out.extend($f(StableNeoHookean, "StableNeoHookean", true, $($arg),*));
        out
    }};
}

fn check(
    case: String,
    metric: &str,
    measured: f64,
    tolerance: f64,
    judge: Judge,
    source: &'static str,
) -> Check {
    Check {
        crate_name: CRATE,
        case,
        // '|' would split a Markdown table cell: norms are written with '‖'.
        metric: metric.replace('|', "‖"),
        measured,
        reference: 0.0,
        tolerance,
        judge,
        source,
    }
}

fn finite_differences(ctx: &Ctx) -> Vec<Check> {
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

fn invariance(ctx: &Ctx) -> Vec<Check> {
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
                    "seed 5.1: small strain cannot guarantee rotational invariance",
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

fn small_strain(ctx: &Ctx) -> Vec<Check> {
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
                "psi(I) = 0, P(I) = 0; P(Q) = 0 for rotations (REFERENCES.md)",
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
                "linear elasticity, seed 5.1",
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

trait FlatVec {
    fn to_flat_vec(&self) -> Vec<f64>;
}
impl<T: anim_material::Scalar, const D: usize> FlatVec for Tangent<T, D> {
    fn to_flat_vec(&self) -> Vec<f64> {
        self.d.iter().flatten().flat_map(|m| m.iter().map(|x| x.to_f64_lossless())).collect()
    }
}

fn precision(ctx: &Ctx) -> Vec<Check> {
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

fn psd_projection(ctx: &Ctx) -> Vec<Check> {
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

fn inversion_robust(_ctx: &Ctx) -> Outcome {
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

fn neo_hookean_inverted(_ctx: &Ctx) -> Outcome {
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
