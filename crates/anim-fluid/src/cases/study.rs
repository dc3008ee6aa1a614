//! Work-precision studies: the pressure solvers' divergence residual and Ghia error against
//! wall time, and the advection schemes and splittings on the Taylor-Green vortex.

use super::conformance::{divergent_field, taylor_green_run};
use super::ghia::{cavity_run, ghia_errors};
use crate::advection::{Advection, Splitting};
use crate::pressure::PressureMethod;
use anim_core::cases::{Ctx, Point, Series, StudyResult, median_seconds};
use std::time::Instant;

pub(super) fn study_divergence(ctx: &Ctx) -> StudyResult {
    let sizes: &[usize] = if ctx.quick { &[64, 128] } else { &[64, 128, 256, 512] };
    let tols = [1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-8];
    let mut series = Vec::new();
    for method in PressureMethod::ALL {
        for &n in sizes {
            let mut points = Vec::new();
            for &tol in &tols {
                // Quick mode: slow solvers stop at a smaller cap and time budget (a tolerance they
                // do not reach ends their series), so the quick report stays within minutes.
                let (cap, budget) = if ctx.quick { (20_000, 2.0) } else { (200_000, 20.0) };
                let Ok((f0, s0)) = divergent_field(n, 2, method, tol, cap) else { continue };
                let mut residual = f64::NAN;
                let mut iterations = 0;
                let mut budget_ok = true;
                let secs = median_seconds(if ctx.quick { 1 } else { 3 }, 0.0, || {
                    let (mut f, mut s) = (f0.clone(), s0.clone());
                    let t = Instant::now();
                    if let Ok(info) = f.advance(&mut s, 1e-3) {
                        residual = info.pressure.residual;
                        iterations = info.pressure.iterations;
                    }
                    budget_ok = t.elapsed().as_secs_f64() < budget;
                });
                let _ = iterations;
                let reached = residual.is_finite() && residual <= tol * 1.0001;
                if reached {
                    points.push(Point { param: tol, seconds: secs, error: residual });
                }
                if !budget_ok || (ctx.quick && !reached) {
                    break;
                }
            }
            series.push(Series { label: format!("{} N={n}", method.name()), points });
        }
    }
    StudyResult {
        title: "anim-fluid: pressure projection, relative divergence residual vs wall time (2D box with a sphere)".into(),
        slug: "fluid_pressure_divergence".into(),
        error_label: "relative residual max|b - A p| / max|b|".into(),
        param_label: "tolerance".into(),
        series,
    }
}

/// Pressure-solver tolerance of the cavity study.
const GHIA_STUDY_PRESSURE_TOLERANCE: f64 = 1e-5;

/// The cavity study's parameters `anim run --tolerance` uses: its pressure tolerance.
pub fn ghia_study_problem(_quick: bool) -> Vec<(&'static str, f64)> {
    vec![("pressure_tolerance", GHIA_STUDY_PRESSURE_TOLERANCE)]
}

pub(super) fn study_ghia(ctx: &Ctx) -> StudyResult {
    let sizes: &[usize] = if ctx.quick { &[16, 32] } else { &[16, 32, 64] };
    let mut series = Vec::new();
    for method in PressureMethod::ALL {
        let mut points = Vec::new();
        for &n in sizes {
            let t = Instant::now();
            if let Ok((f, s, _)) = cavity_run(n, Advection::MacCormack, method, GHIA_STUDY_PRESSURE_TOLERANCE)
            {
                let (eu, ev) = ghia_errors(&f, &s);
                points.push(Point { param: n as f64, seconds: t.elapsed().as_secs_f64(), error: eu.max(ev) });
            }
        }
        series.push(Series { label: method.name().into(), points });
    }
    StudyResult {
        title: "anim-fluid: lid-driven cavity Re = 100, max error vs Ghia 1982 against wall time (to steady state)".into(),
        slug: "fluid_cavity_ghia".into(),
        error_label: "max |error| over Ghia's centreline points".into(),
        param_label: "N".into(),
        series,
    }
}

/// Every advection scheme under both splittings on the Taylor-Green vortex (`nu = 0.01`, to
/// `t = 1`, MGPCG to 1e-10), swept over the CFL number at a fixed grid: the amplitude's
/// relative error against `exp(-2 nu pi^2 t)` against the wall time of the run.
pub(super) fn study_taylor_green(ctx: &Ctx) -> StudyResult {
    let (n, cfls): (usize, &[f64]) =
        if ctx.quick { (32, &[1.0, 2.0, 4.0]) } else { (64, &[0.5, 1.0, 2.0, 4.0]) };
    let mut series = Vec::new();
    for splitting in Splitting::ALL {
        for advection in Advection::ALL {
            let mut points = Vec::new();
            for &cfl in cfls {
                let t = Instant::now();
                if let Ok((a, exact)) = taylor_green_run(n, advection, splitting, 0.01, 1.0, cfl) {
                    points.push(Point {
                        param: cfl,
                        seconds: t.elapsed().as_secs_f64(),
                        error: (a / exact - 1.0).abs(),
                    });
                }
            }
            series.push(Series { label: format!("{} {}", advection.name(), splitting.name()), points });
        }
    }
    StudyResult {
        title: format!(
            "anim-fluid: Taylor-Green vortex at N = {n}, amplitude error at t = 1 against wall time, per advection scheme and splitting"
        ),
        slug: "fluid_taylor_green".into(),
        error_label: "|A / A_exact - 1|".into(),
        param_label: "CFL".into(),
        series,
    }
}
