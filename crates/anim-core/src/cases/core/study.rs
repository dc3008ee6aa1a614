//! Work-precision studies of every integrator on the oscillator and the Kepler orbit.

use super::{kepler_run, oscillator_run};
use crate::cases::{Ctx, Point, Series, StudyResult, median_seconds};
use crate::integrate::IntegratorKind;
use std::f64::consts::PI;

fn study(
    ctx: &Ctx,
    title: &str,
    slug: &str,
    error_label: &str,
    steps_for: impl Fn(IntegratorKind) -> Vec<usize>,
    run: impl Fn(IntegratorKind, usize) -> f64,
    horizon: f64,
) -> StudyResult {
    let (batches, min_batch) = if ctx.quick { (3, 0.002) } else { (7, 0.02) };
    let series = IntegratorKind::ALL
        .iter()
        .map(|&kind| {
            let points = steps_for(kind)
                .into_iter()
                .map(|n| {
                    let error = run(kind, n);
                    let seconds = median_seconds(batches, min_batch, || {
                        std::hint::black_box(run(kind, n));
                    });
                    Point { param: horizon / n as f64, seconds, error }
                })
                .collect();
            Series { label: kind.label(), points }
        })
        .collect();
    StudyResult {
        title: title.into(),
        slug: slug.into(),
        error_label: error_label.into(),
        param_label: "dt".into(),
        series,
    }
}

/// Simulated time of the oscillator study (`m = k = 1`, so 10.3 periods), the horizon its
/// cheapest-method table holds for.
pub const OSCILLATOR_HORIZON: f64 = 20.6 * PI;

/// Simulated time of the Kepler study (`a = mu = 1`, period `2 pi`: 1.3 orbits).
pub const KEPLER_HORIZON: f64 = 2.6 * PI;

pub(super) fn oscillator_study(ctx: &Ctx) -> StudyResult {
    let n = if ctx.quick { 4 } else { 8 };
    study(
        ctx,
        "Harmonic oscillator, 10.3 periods: error of (x, v) against the exact solution",
        "core-oscillator",
        "|(x, v) - exact| at t = 20.6 pi",
        |_| (0..n).map(|i| 100usize << i).collect(),
        |kind, steps| oscillator_run(kind, steps, OSCILLATOR_HORIZON / (2.0 * PI)),
        OSCILLATOR_HORIZON,
    )
}

pub(super) fn kepler_study(ctx: &Ctx) -> StudyResult {
    let n = if ctx.quick { 4 } else { 8 };
    study(
        ctx,
        "Kepler orbit e = 0.5, 1.3 orbits: position error against Kepler's equation",
        "core-kepler",
        "|x - exact| at t = 2.6 pi",
        |_| (0..n).map(|i| 250usize << i).collect(),
        |kind, steps| kepler_run(kind, steps, KEPLER_HORIZON / (2.0 * PI)),
        KEPLER_HORIZON,
    )
}
