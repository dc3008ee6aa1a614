//! The work-precision study of anim-pbd: the hanging cloth stepped for 0.5 s by PBD and XPBD,
//! spending the work either on Gauss-Seidel iterations (one substep) or on substeps (one
//! iteration each, Macklin et al. 2019, "Small steps in physics simulation"), its position and
//! stretch errors measured against a converged XPBD run. XPBD converges to the material its
//! compliances define; PBD's stiffness depends on the iteration count, so it converges elsewhere.

use crate::{ConstraintFunction, Method, PbdModel, PbdParams, PbdSimulation, SolverKind};
use anim_core::cases::{Ctx, Point, Series, StudyResult, median_seconds};

/// Simulated time of the study (s), the horizon its cheapest-method table holds for.
pub const STUDY_T: f64 = 0.5;
const STUDY_DT: f64 = 1.0 / 60.0;

/// The study cloth: anim-pbd's `hanging-cloth` preset (`n x n`, 0.5 m, 0.1 kg, pinned at two
/// corners, stiff distances (`alpha = 1e-7` m/N; PBD `k = 1`), soft isometric bending
/// (`alpha = 5`; PBD `k = 0.1`)), which `anim run --tolerance` maps to this study.
fn study_model(n: usize) -> Option<PbdModel> {
    crate::scenes::hanging_cloth(Some(n)).ok().map(|s| s.model)
}

/// The study cloth's side in particles.
fn study_side(quick: bool) -> usize {
    if quick { 8 } else { 14 }
}

/// The study problem's parameters `anim run --tolerance` transfers from: the cloth's side `n`
/// and the step `dt` (s).
pub fn study_problem(quick: bool) -> Vec<(&'static str, f64)> {
    vec![("n", study_side(quick) as f64), ("dt", STUDY_DT)]
}

fn study_run(model: &PbdModel, method: Method, iters: usize, subs: usize) -> Option<Vec<f64>> {
    let mut state = model.rest_state();
    let mut sim =
        PbdSimulation::new(model.clone(), PbdParams::new(method, SolverKind::GaussSeidel, iters, subs))
            .ok()?;
    sim.run(&mut state, STUDY_DT, (STUDY_T / STUDY_DT).round() as usize).ok()?;
    Some(state.x)
}

/// Mean relative stretch `|C_j| / l_j` of the distance constraints.
fn mean_strain(model: &PbdModel, x: &[f64]) -> f64 {
    let (mut s, mut k) = (0.0, 0);
    for c in model.constraints() {
        if let ConstraintFunction::Distance { particles: [i, j], rest_length } = c.function {
            let d = ((x[3 * i] - x[3 * j]).powi(2)
                + (x[3 * i + 1] - x[3 * j + 1]).powi(2)
                + (x[3 * i + 2] - x[3 * j + 2]).powi(2))
            .sqrt();
            s += (d - rest_length).abs() / rest_length;
            k += 1;
        }
    }
    s / k.max(1) as f64
}

fn cloth_study(ctx: &Ctx, constraint_error: bool) -> StudyResult {
    let n = study_side(ctx.quick);
    let (batches, min_batch) = if ctx.quick { (3, 0.002) } else { (5, 0.02) };
    let sweep: Vec<usize> = if ctx.quick { vec![1, 4, 16] } else { vec![1, 2, 4, 8, 16, 32, 64] };
    let model = study_model(n);
    // The converged reference: XPBD with 512 substeps of 4 iterations (256 x 4 in quick mode).
    let reference =
        model.as_ref().and_then(|m| study_run(m, Method::Xpbd, 4, if ctx.quick { 256 } else { 512 }));
    let x0 = model.as_ref().map(|m| m.rest_state().x).unwrap_or_default();
    let error = |x: &Option<Vec<f64>>| -> f64 {
        match (&model, &reference, x) {
            (Some(m), Some(r), Some(x)) => {
                if constraint_error {
                    (mean_strain(m, x) - mean_strain(m, r)).abs()
                } else {
                    let num: f64 = x.iter().zip(r).map(|(a, b)| (a - b) * (a - b)).sum::<f64>().sqrt();
                    let den: f64 = r.iter().zip(&x0).map(|(a, b)| (a - b) * (a - b)).sum::<f64>().sqrt();
                    num / den
                }
            }
            _ => f64::NAN,
        }
    };
    let mut series = Vec::new();
    for method in [Method::Xpbd, Method::Pbd] {
        for substeps in [false, true] {
            let label = format!(
                "{method:?} {}",
                if substeps { "substeps (1 iteration)" } else { "iterations (1 substep)" }
            );
            let points = sweep
                .iter()
                .map(|&k| {
                    let (it, sub) = if substeps { (1, k) } else { (k, 1) };
                    let x = model.as_ref().and_then(|m| study_run(m, method, it, sub));
                    let err = error(&x);
                    let seconds = match &model {
                        Some(m) if err.is_finite() => median_seconds(batches, min_batch, || {
                            std::hint::black_box(study_run(m, method, it, sub));
                        }),
                        _ => f64::NAN,
                    };
                    Point { param: k as f64, seconds, error: err }
                })
                .collect();
            series.push(Series { label, points });
        }
    }
    let (title, slug, error_label) = if constraint_error {
        (
            format!(
                "Hanging cloth {n}x{n}, 0.5 s at dt = 1/60: stretch error against a converged XPBD run (512 substeps x 4 iterations); PBD stiffness is k = 1 (stretch), 0.1 (bending)"
            ),
            "pbd-cloth-constraint",
            "|mean |C_j|/l_j - reference| (distance constraints)",
        )
    } else {
        (
            format!(
                "Hanging cloth {n}x{n}, 0.5 s at dt = 1/60: position error against a converged XPBD run (512 substeps x 4 iterations); PBD converges to a different, iteration-dependent material"
            ),
            "pbd-cloth-position",
            "|x - x_ref| / |x_ref - x_0| at t = 0.5 s",
        )
    };
    StudyResult {
        title,
        slug: slug.into(),
        error_label: error_label.into(),
        param_label: "iterations or substeps".into(),
        series,
    }
}

pub(super) fn cloth_position_study(ctx: &Ctx) -> StudyResult {
    cloth_study(ctx, false)
}

pub(super) fn cloth_constraint_study(ctx: &Ctx) -> StudyResult {
    cloth_study(ctx, true)
}
