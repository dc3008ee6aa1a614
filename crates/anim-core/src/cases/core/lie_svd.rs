//! Lie-group identities (SO(3), SE(3) exp and log) and the 3x3 SVD on random and degenerate
//! matrices.

use super::CRATE;
use crate::cases::{Check, Ctx, Judge};
use crate::lie::{Se3, Twist, so3};
use crate::linalg::{svd3, svd3_f32};
use glam::{DMat3, DVec3, Mat3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::f64::consts::PI;

fn random_unit(rng: &mut ChaCha8Rng) -> DVec3 {
    loop {
        let v =
            DVec3::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
        let n = v.length();
        if n > 1e-3 && n <= 1.0 {
            return v / n;
        }
    }
}

fn frob(m: DMat3) -> f64 {
    m.to_cols_array().iter().map(|x| x * x).sum::<f64>().sqrt()
}

pub(super) fn lie_identities(_ctx: &Ctx) -> Vec<Check> {
    let samples = 100_000;
    let mut rng = ChaCha8Rng::seed_from_u64(0x11e);
    let mut exp_log = 0.0f64;
    let mut log_exp = 0.0f64;
    let mut se3_round = 0.0f64;
    for _ in 0..samples {
        let w = random_unit(&mut rng) * rng.random_range(0.0..PI);
        let r = so3::exp(w);
        exp_log = exp_log.max(frob(so3::exp(so3::log(r)) - r));
        if w.length() < PI - 1e-6 {
            log_exp = log_exp.max((so3::log(r) - w).length());
        }
        let xi = Twist::new(
            DVec3::new(rng.random_range(-2.0..2.0), rng.random_range(-2.0..2.0), rng.random_range(-2.0..2.0)),
            w,
        );
        let back = Se3::exp(xi).log();
        se3_round = se3_round.max((back.v - xi.v).length().max((back.w - xi.w).length()));
    }
    let mut edge = 0.0f64;
    let axes = [
        DVec3::X,
        DVec3::Y,
        DVec3::Z,
        DVec3::new(1.0, 1.0, 0.0).normalize(),
        DVec3::new(1.0, -2.0, 3.0).normalize(),
    ];
    for axis in axes {
        for angle in [0.0, 1e-12, 1e-9, 1e-6, 1.0, PI - 1e-6, PI - 1e-9, PI] {
            let r = so3::exp(axis * angle);
            edge = edge.max(frob(so3::exp(so3::log(r)) - r));
        }
    }
    let mk = |case: &str, metric: &str, measured: f64| Check {
        crate_name: CRATE,
        case: case.into(),
        metric: metric.into(),
        measured,
        reference: 0.0,
        tolerance: 1e-12,
        judge: Judge::AtMost,
        source: "group identity",
    };
    vec![
        mk("SO(3) exp(log R) = R, 1e5 random", "max Frobenius error", exp_log),
        mk(
            "SO(3) exp(log R) = R, angles 0, 1e-12, 1e-9, 1e-6, pi-1e-6, pi-1e-9, pi",
            "max Frobenius error",
            edge,
        ),
        mk("SO(3) log(exp w) = w, |w| < pi, 1e5 random", "max |error|", log_exp),
        mk("SE(3) log(exp xi) = xi, 1e5 random", "max |error|", se3_round),
    ]
}

#[derive(Clone, Copy)]
enum Category {
    Random,
    Rank2,
    Rank1,
    Repeated,
    Reflected,
    NearIdentity,
}

const CATEGORIES: [(Category, &str); 6] = [
    (Category::Random, "random"),
    (Category::Rank2, "rank 2"),
    (Category::Rank1, "rank 1"),
    (Category::Repeated, "repeated singular values"),
    (Category::Reflected, "reflected (det < 0)"),
    (Category::NearIdentity, "near identity"),
];

fn sample_matrix(rng: &mut ChaCha8Rng, cat: Category) -> DMat3 {
    let rot = |rng: &mut ChaCha8Rng| so3::exp(random_unit(rng) * rng.random_range(0.0..PI));
    let (u, v) = (rot(rng), rot(rng));
    let mut s =
        DVec3::new(rng.random_range(0.1..3.0), rng.random_range(0.1..3.0), rng.random_range(0.1..3.0));
    match cat {
        Category::Random => {
            return DMat3::from_cols_array(&std::array::from_fn(|_| rng.random_range(-1.0..1.0)));
        }
        Category::Rank2 => s.z = 0.0,
        Category::Rank1 => {
            s.y = 0.0;
            s.z = 0.0
        }
        Category::Repeated => {
            s.y = s.x;
            if rng.random_bool(0.5) {
                s.z = s.x;
            }
        }
        Category::Reflected => s.z = -s.z,
        Category::NearIdentity => {
            return DMat3::IDENTITY
                + DMat3::from_cols_array(&std::array::from_fn(|_| rng.random_range(-1e-6..1e-6)));
        }
    }
    u * DMat3::from_diagonal(s) * v.transpose()
}

pub(super) fn svd_checks(_ctx: &Ctx) -> Vec<Check> {
    let samples = 20_000;
    let mut rng = ChaCha8Rng::seed_from_u64(0x5_7D);
    let mut checks = Vec::new();
    for (cat, name) in CATEGORIES {
        let (mut e64, mut e32, mut orth, mut bad_det) = (0.0f64, 0.0f64, 0.0f64, 0usize);
        for _ in 0..samples {
            let a = sample_matrix(&mut rng, cat);
            let s = svd3(a);
            let rec = s.u * DMat3::from_diagonal(s.sigma) * s.v.transpose();
            e64 = e64.max(frob(rec - a) / frob(a).max(1e-300));
            orth = orth
                .max(frob(s.u.transpose() * s.u - DMat3::IDENTITY))
                .max(frob(s.v.transpose() * s.v - DMat3::IDENTITY));
            if (s.u.determinant() - 1.0).abs() > 1e-9 || (s.v.determinant() - 1.0).abs() > 1e-9 {
                bad_det += 1;
            }
            let af = a.as_mat3();
            let sf = svd3_f32(af);
            let recf = sf.u * Mat3::from_diagonal(sf.sigma) * sf.v.transpose();
            let errf = (recf - af).to_cols_array().iter().map(|x| x * x).sum::<f32>().sqrt()
                / af.to_cols_array().iter().map(|x| x * x).sum::<f32>().sqrt().max(1e-30);
            e32 = e32.max(f64::from(errf));
        }
        let mk = |metric: &str, measured: f64, tol: f64| Check {
            crate_name: CRATE,
            case: format!("SVD {name}, {samples} samples"),
            metric: metric.into(),
            measured,
            reference: 0.0,
            tolerance: tol,
            judge: Judge::AtMost,
            source: "A = U S V^T, U, V proper rotations",
        };
        checks.push(mk("f64 max relative reconstruction error", e64, 1e-12));
        checks.push(mk("f64 max |U^T U - I|, |V^T V - I|", orth, 1e-12));
        checks.push(mk("f64 count det U or det V != +1", bad_det as f64, 0.0));
        checks.push(mk("f32 max relative reconstruction error", e32, 1e-5));
    }
    checks
}
