//! anim-material: every model's stress `P` against central differences of its energy and its
//! `dP/dF` against central differences of `P`, over a fixed ChaCha-seeded set of deformation
//! gradients (general, pure rotations, stretches with repeated values, near-singular `det F ~
//! 1e-3`, inverted, `det F = 0`); rotation invariance; zero stress at rest and under rotation;
//! agreement with linear elasticity at small strain (tangent at `F = I` and the `O(eps^2)` order
//! of the stress difference); f32 against f64; the analytic PSD projection against the
//! numerical one. Hard cases: the inversion-robust models on inverted and degenerate `F`, and
//! Neo-Hookean reporting its undefined region.

/// Calls `$f(model, name, defined_under_inversion)` for every model.
macro_rules! per_model {
    ($f:ident, $($arg:expr),*) => {{
        let mut out = Vec::new();
        out.extend($f($crate::LinearElastic, "LinearElastic", true, $($arg),*));
        out.extend($f($crate::StVenantKirchhoff, "StVenantKirchhoff", true, $($arg),*));
        out.extend($f($crate::CorotatedLinear, "CorotatedLinear", true, $($arg),*));
        out.extend($f($crate::NeoHookean, "NeoHookean", false, $($arg),*));
        out.extend($f($crate::FixedCorotated, "FixedCorotated", true, $($arg),*));
        out.extend($f($crate::StableNeoHookean, "StableNeoHookean", true, $($arg),*));
        out
    }};
}

mod conformance;
mod hard_cases;
mod projection;

use crate::samples::{KINDS, Kind, lame, rotation, sample};
use crate::{Hyperelastic, Lame, Mat, Tangent, svd};
use anim_core::cases::{Check, ConformanceCase, Judge, Outcome, Registry, StabilityCase};
use conformance::{finite_differences, invariance, precision, small_strain};
use hard_cases::{inversion_robust, neo_hookean_inverted};
use projection::psd_projection;

const CRATE: &str = "anim-material";

/// Registers the crate's conformance checks and hard cases, in the order the suites print them.
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

/// The tangent's entries as f64, in a fixed order.
trait FlatVec {
    fn to_flat_vec(&self) -> Vec<f64>;
}
impl<T: crate::Scalar, const D: usize> FlatVec for Tangent<T, D> {
    fn to_flat_vec(&self) -> Vec<f64> {
        self.d.iter().flatten().flat_map(|m| m.iter().map(|x| x.to_f64_lossless())).collect()
    }
}

anim_core::quick_cases_test!(crate::cases::register);
